// tracking process: joins rt/crane/state/estimate, rt/crane/planner/reference and
// rt/crane/control/anti_swing of the same cycle -> TrackingStage (PD tracking (3.40)-(3.42) with
// the voltage mapping (3.37)-(3.38), or gain-scheduling state feedback (3.19)/(3.26); the registry
// in tracking_stage.hpp) -> rt/crane/control/linear.
#include <array>

#include "crane/runtime/stage_node.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"
#include "crane/tracking/tracking_stage.hpp"

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
                       "tracking | gain_scheduling_partial (3.19) | gain_scheduling_full (3.26) (default tracking)");
        app.add_flag("--acceleration-feedforward", *feedforward,
                     "tracking law: add the reference acceleration to the PD action (beyond (3.40))");
      },
      [controller_name, feedforward](runtime::StageContext& ctx) -> std::function<void()> {
        auto params = ctx.config.read("tracking", tracking::read_params);
        // The PD law's momentum balance lags as the estimator's rates (tracking_stage.hpp).
        params.estimator = ctx.config.read("state_estimator", state_estimator::read_params).estimator;
        params.law = tracking::law_from_name(*controller_name, "--controller");
        params.tracking.acceleration_feedforward = *feedforward;
        auto stage = std::make_shared<tracking::TrackingStage>(params);
        // The estimate of cycle k does not wake this stage: the reference and the anti-swing action
        // of k are computed from it, so they arrive after it (the loop's 5 ms poll covers the rest).
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(nullptr));
        auto references = std::shared_ptr(ctx.participant.make_reader<tp::Reference>(&ctx.wakeup));
        auto actions = std::shared_ptr(ctx.participant.make_reader<tp::AntiSwing>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::LinearCommand>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto state = std::make_shared<protocol::CraneState>();
        auto reference = std::make_shared<protocol::Reference>();
        auto action = std::make_shared<protocol::AntiSwingCommand>();
        auto fresh = std::make_shared<std::array<bool, 3>>(std::array<bool, 3>{false, false, false});
        auto out = std::make_shared<protocol::LinearCommand>();
        return [=, &ctx] {
          auto take = [&](auto& reader, auto& latest, bool& flag) {
            while (runtime::take_plain(reader, latest, ctx.counters)) flag = true;
          };
          take(*states, *state, (*fresh)[0]);
          take(*references, *reference, (*fresh)[1]);
          take(*actions, *action, (*fresh)[2]);
          const auto seq = state->header.seq;
          const bool complete = (*fresh)[0] && (*fresh)[1] && (*fresh)[2] && reference->header.seq == seq &&
                                action->header.seq == seq;
          if (!complete) return;
          *fresh = {false, false, false};
          switch (watch->classify(seq, ctx.counters)) {
            case runtime::CycleKind::stale: return;
            case runtime::CycleKind::repeat: break;  // answered again from *out, the controller untouched
            case runtime::CycleKind::new_cycle:
              ++ctx.counters.cycles;
              if (stage->step(*state, *reference, *action, *out) != common::StepStatus::ok) {
                ++ctx.counters.nonfinite_rejected;
              }
              watch->answered(seq);
              break;
          }
          out->header.origin = state->header.origin;  // a re-offer may carry a newer origin
          runtime::write_plain(*writer, *out);
          runtime::record_latency(ctx.latency, out->header);
        };
      });
}
