// state_estimator process: rt/crane/hw/sensors -> section 4.3 filter and differentiator ->
// rt/crane/state/estimate, once per sensor cycle, same seq and origin.
#include "crane/runtime/stage_node.hpp"
#include "crane/state_estimator/state_estimator.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::state_estimator,
      "state_estimator: Butterworth filter and Al-Alaoui differentiator (section 4.3) on the sensor stream", {},
      [](runtime::StageContext& ctx) -> std::function<void()> {
        auto estimator = std::make_shared<state_estimator::StateEstimator>(ctx.config.state_estimator);
        auto sensors = std::shared_ptr(ctx.participant.make_reader<tp::Sensors>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::StateEstimate>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto out = std::make_shared<tp::msgs::CraneState_>();
        auto estimate = std::make_shared<common::CraneStateEstimate>();
        return [=, &ctx] {
          tp::msgs::SensorSample_ sample;
          while (runtime::take_finite(*sensors, sample, ctx.counters)) {
            const auto seq = sample.header().seq();
            switch (watch->classify(seq, ctx.counters)) {
              case runtime::CycleKind::stale: continue;
              case runtime::CycleKind::repeat: break;  // answered again from *out, filters untouched
              case runtime::CycleKind::new_cycle:
                if (estimator->step(runtime::to_measurement(sample), *estimate) != common::StepStatus::ok) {
                  ++ctx.counters.nonfinite_rejected;
                  continue;
                }
                ++ctx.counters.cycles;
                runtime::from_estimate(*estimate, *out);
                watch->answered(seq);
                break;
            }
            runtime::stamp_header(out->header(), seq, sample.header().origin());
            writer->write(*out);
            runtime::record_latency(ctx.latency, out->header());
          }
        };
      });
}
