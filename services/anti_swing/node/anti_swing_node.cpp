// anti_swing process: rt/crane/state/estimate -> anti-swing law (section 3.3.2) ->
// rt/crane/control/anti_swing, once per cycle, same seq and origin.
#include "crane/anti_swing/anti_swing.hpp"
#include "crane/runtime/stage_node.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::anti_swing,
      "anti_swing: swing damping action, PD (3.45) or delayed feedback (3.47), from the state estimate", {},
      [](runtime::StageContext& ctx) -> std::function<void()> {
        auto controller = std::make_shared<anti_swing::AntiSwing>(ctx.config.anti_swing);
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::AntiSwing>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto out = std::make_shared<tp::msgs::AntiSwingCommand_>();
        auto action = std::make_shared<anti_swing::AntiSwingOutput>();
        const auto kind = static_cast<std::uint8_t>(ctx.config.anti_swing.kind == anti_swing::AntiSwingKind::none ? 0
                                                    : ctx.config.anti_swing.kind == anti_swing::AntiSwingKind::pd ? 1
                                                                                                                 : 2);
        return [=, &ctx] {
          tp::msgs::CraneState_ state;
          while (runtime::take_finite(*states, state, ctx.counters)) {
            if (watch->advance(state.header().seq(), ctx.counters)) {
              // not_ready (delay line still filling) gives a zero action: that is the safe value.
              if (controller->step(runtime::to_estimate(state), *action) == common::StepStatus::rejected_nonfinite) {
                ++ctx.counters.nonfinite_rejected;
                continue;
              }
              ++ctx.counters.cycles;
            }
            out->controller(kind);
            out->trolley_action(action->trolley_action);
            out->slew_action(action->slew_action);
            runtime::stamp_header(out->header(), state.header().seq(), state.header().origin());
            writer->write(*out);
            runtime::record_latency(ctx.latency, out->header());
          }
        };
      });
}
