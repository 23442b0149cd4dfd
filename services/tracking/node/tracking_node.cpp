// tracking process: joins rt/crane/state/estimate, rt/crane/planner/reference and
// rt/crane/control/anti_swing of the same cycle -> PD tracking (3.40)-(3.42) with the voltage
// mapping (3.37)-(3.38) -> rt/crane/control/linear.
//
// --controller selects the law (default tracking):
//   tracking                 PD tracking plus the anti-swing action; the anti-swing message's
//                            reference corrections (Masoud's configuration (3.50)) are added to the
//                            trolley and slew reference position and velocity first
//   gain_scheduling_partial  gain-scheduling state feedback (3.19) on the reference position
//   gain_scheduling_full     gain-scheduling state feedback (3.26) on the reference position
// The gain-scheduling laws do not use the anti-swing message, but the stage still joins on it so
// the chain (and its timing) is the same for every controller.
#include "crane/gain_scheduling/gain_scheduling_controller.hpp"
#include "crane/runtime/stage_node.hpp"
#include "crane/tracking/tracking_controller.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  auto controller_name = std::make_shared<std::string>("tracking");
  auto feedforward = std::make_shared<bool>(false);
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::tracking,
      "tracking: PD tracking (3.40)-(3.42) plus the anti-swing action, mapped to drive voltages (3.37)-(3.38), "
      "or gain-scheduling state feedback (3.19)/(3.26)",
      [controller_name, feedforward](CLI::App& app) {
        app.add_option("--controller", *controller_name,
                       "tracking | gain_scheduling_partial (3.19) | gain_scheduling_full (3.26) (default tracking)")
            ->check(CLI::IsMember({"tracking", "gain_scheduling_partial", "gain_scheduling_full"}));
        app.add_flag("--acceleration-feedforward", *feedforward,
                     "tracking law: add the reference acceleration to the PD action (beyond (3.40))");
      },
      [controller_name, feedforward](runtime::StageContext& ctx) -> std::function<void()> {
        auto tracking_params = ctx.config.tracking;
        tracking_params.acceleration_feedforward = *feedforward;
        auto controller = std::make_shared<tracking::TrackingController>(tracking_params);
        std::shared_ptr<gain_scheduling::GainSchedulingController> scheduled;
        if (*controller_name != "tracking") {
          auto p = gain_scheduling::gain_scheduling_params_from(ctx.config.crane);
          p.kind = *controller_name == "gain_scheduling_full" ? gain_scheduling::FeedbackKind::full
                                                              : gain_scheduling::FeedbackKind::partial;
          p.voltage_limit = ctx.config.tracking.voltage_limit;
          p.slew_enabled = ctx.config.tracking.slew_enabled;
          scheduled = std::make_shared<gain_scheduling::GainSchedulingController>(p);
        }
        // The estimate of cycle k does not wake this stage: the reference and the anti-swing action
        // of k are computed from it, so they arrive after it (the loop's 5 ms poll covers the rest).
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(nullptr));
        auto references = std::shared_ptr(ctx.participant.make_reader<tp::Reference>(&ctx.wakeup));
        auto actions = std::shared_ptr(ctx.participant.make_reader<tp::AntiSwing>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::LinearCommand>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto state = std::make_shared<tp::msgs::CraneState_>();
        auto reference = std::make_shared<tp::msgs::Reference_>();
        auto action = std::make_shared<tp::msgs::AntiSwingCommand_>();
        auto fresh = std::make_shared<std::array<bool, 3>>(std::array<bool, 3>{false, false, false});
        auto out = std::make_shared<tp::msgs::LinearCommand_>();
        return [=, &ctx] {
          auto take = [&](auto& reader, auto& latest, bool& flag) {
            typename std::remove_reference_t<decltype(latest)> sample;
            while (runtime::take_finite(reader, sample, ctx.counters)) {
              latest = sample;
              flag = true;
            }
          };
          take(*states, *state, (*fresh)[0]);
          take(*references, *reference, (*fresh)[1]);
          take(*actions, *action, (*fresh)[2]);
          const auto seq = state->header().seq();
          const bool complete = (*fresh)[0] && (*fresh)[1] && (*fresh)[2] && reference->header().seq() == seq &&
                                action->header().seq() == seq;
          if (!complete) return;
          *fresh = {false, false, false};
          switch (watch->classify(seq, ctx.counters)) {
            case runtime::CycleKind::stale: return;
            case runtime::CycleKind::repeat: break;  // answered again from *out, the controller untouched
            case runtime::CycleKind::new_cycle: {
              ++ctx.counters.cycles;
              tracking::TrackingInput in;
              in.estimate = runtime::to_estimate(*state);
              in.reference = runtime::to_reference(*reference);
              tracking::TrackingOutput result;
              if (scheduled) {
                if (scheduled->step(in.estimate, in.reference, result.command) != common::StepStatus::ok) {
                  ++ctx.counters.nonfinite_rejected;
                }
              } else {
                in.reference.trolley.position += action->trolley_reference_correction();
                in.reference.trolley.velocity += action->trolley_reference_rate_correction();
                in.reference.slew.position += action->slew_reference_correction();
                in.reference.slew.velocity += action->slew_reference_rate_correction();
                in.trolley_anti_swing_action = action->trolley_action();
                in.slew_anti_swing_action = action->slew_action();
                if (controller->step(in, result) != common::StepStatus::ok) {
                  ++ctx.counters.nonfinite_rejected;
                }
              }
              out->trolley_voltage(result.command.trolley_voltage);
              out->slew_voltage(result.command.slew_voltage);
              out->hoist_speed(result.command.hoist_speed);
              out->trolley_tracking_action(result.trolley_tracking_action);
              out->slew_tracking_action(result.slew_tracking_action);
              watch->answered(seq);
              break;
            }
          }
          runtime::stamp_header(out->header(), seq, state->header().origin());
          writer->write(*out);
          runtime::record_latency(ctx.latency, out->header());
        };
      });
}
