// state_estimator process: rt/crane/hw/sensors -> StateEstimatorStage (section 4.3 filter and
// differentiator) -> rt/crane/state/estimate, once per sensor cycle, same seq and origin.
#include "crane/runtime/stage_node.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  auto follower = std::make_shared<bool>(false);
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::state_estimator,
      "state_estimator: Butterworth filter and Al-Alaoui differentiator (section 4.3) on the sensor stream",
      [follower](CLI::App& app) {
        app.add_flag("--follower-filter", *follower,
                     "the tracking law is the follower: filter at state_estimator.follower_cutoff_frequency");
      },
      [follower](runtime::StageContext& ctx) -> std::function<void()> {
        auto params = ctx.config.read("state_estimator", state_estimator::read_params);
        auto stage = std::make_shared<state_estimator::StateEstimatorStage>(
            *follower ? state_estimator::for_follower(params) : params);
        auto sensors = std::shared_ptr(ctx.participant.make_reader<tp::Sensors>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::StateEstimate>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto out = std::make_shared<protocol::CraneState>();
        return [=, &ctx] {
          protocol::SensorSample sample;
          while (runtime::take_plain(*sensors, sample, ctx.counters)) {
            switch (watch->classify(sample.header.seq, ctx.counters)) {
              case runtime::CycleKind::stale: continue;
              case runtime::CycleKind::repeat: break;  // answered again from *out, filters untouched
              case runtime::CycleKind::new_cycle:
                if (stage->step(sample, *out) != common::StepStatus::ok) {
                  ++ctx.counters.nonfinite_rejected;
                  continue;
                }
                ++ctx.counters.cycles;
                watch->answered(sample.header.seq);
                break;
            }
            out->header.origin = sample.header.origin;  // a re-offer may carry a newer origin
            runtime::write_plain(*writer, *out);
            runtime::record_latency(ctx.latency, out->header);
          }
        };
      });
}
