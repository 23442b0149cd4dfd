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
            // A repeated cycle (the plant re-offering cycle 0 at start-up) is answered again
            // without feeding the filters twice.
            if (watch->advance(sample.header().seq(), ctx.counters)) {
              if (estimator->step(runtime::to_measurement(sample), *estimate) != common::StepStatus::ok) {
                ++ctx.counters.nonfinite_rejected;
                continue;
              }
              ++ctx.counters.cycles;
            }
            runtime::from_estimate(*estimate, *out);
            runtime::stamp_header(out->header(), sample.header().seq(), sample.header().origin());
            writer->write(*out);
            runtime::record_latency(ctx.latency, out->header());
          }
        };
      });
}
