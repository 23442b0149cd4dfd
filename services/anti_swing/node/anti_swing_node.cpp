// anti_swing process: rt/crane/state/estimate and rt/crane/safety/status (the operating mode:
// no anti-swing in MAINTENANCE) -> AntiSwingStage (the laws of section 3.3.2, the registry and the
// mode's rule in anti_swing_stage.hpp) -> rt/crane/control/anti_swing, once per cycle, same seq and
// origin. --controller overrides the configuration's anti_swing.controller.
#include <optional>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/runtime/stage_node.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  auto controller_name = std::make_shared<std::string>();
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::anti_swing,
      "anti_swing: swing damping action, PD (3.45), delayed feedback (3.47)/(3.50) or fuzzy, from the state "
      "estimate",
      [controller_name](CLI::App& app) {
        app.add_option("--controller", *controller_name,
                       "anti-swing law: none | pd | delay1 (3.47) | delay2 (3.50) | fuzzy (default: the "
                       "configuration's anti_swing.controller)");
      },
      [controller_name](runtime::StageContext& ctx) -> std::function<void()> {
        auto params = ctx.config.read("anti_swing", anti_swing::read_params);
        if (!controller_name->empty()) params.law = anti_swing::law_from_name(*controller_name, "--controller");
        auto stage = std::make_shared<anti_swing::AntiSwingStage>(params);
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(&ctx.wakeup));
        auto safety = std::shared_ptr(ctx.participant.make_reader<tp::SafetyStatus>(nullptr));
        auto status = std::make_shared<std::optional<protocol::SupervisorStatus>>();
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::AntiSwing>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto out = std::make_shared<protocol::AntiSwingCommand>();
        return [=, &ctx] {
          protocol::CraneState state;
          while (runtime::take_plain(*states, state, ctx.counters)) {
            const auto seq = state.header.seq;
            switch (watch->classify(seq, ctx.counters)) {
              case runtime::CycleKind::stale: continue;
              case runtime::CycleKind::repeat: break;  // answered again from *out, the law untouched
              case runtime::CycleKind::new_cycle: {
                // The latest supervisor status: its operating mode switches the law's output.
                protocol::SupervisorStatus latest;
                while (runtime::take_plain(*safety, latest, ctx.counters)) *status = latest;
                if (stage->step(state, status->has_value() ? &**status : nullptr, *out) ==
                    common::StepStatus::rejected_nonfinite) {
                  ++ctx.counters.nonfinite_rejected;
                  continue;
                }
                ++ctx.counters.cycles;
                watch->answered(seq);
                break;
              }
            }
            out->header.origin = state.header.origin;  // a re-offer may carry a newer origin
            runtime::write_plain(*writer, *out);
            runtime::record_latency(ctx.latency, out->header);
          }
        };
      });
}
