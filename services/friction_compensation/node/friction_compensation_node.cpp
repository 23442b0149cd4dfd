// friction_compensation process: joins rt/crane/control/linear and rt/crane/state/estimate of the
// same cycle -> FrictionCompensationStage, u = V + F_f/K_m (3.5) -> rt/crane/hw/actuators.
// `--disable` passes V through unchanged (the dissertation's "without friction compensation" runs,
// figures 4.19-4.22).
#include <array>
#include <optional>

#include "crane/friction_compensation/friction_compensation_stage.hpp"
#include "crane/runtime/stage_node.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  static bool disable = false;
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::friction_compensation,
      "friction_compensation: u = V + F_f/K_m (3.5) with the friction model (3.1)-(3.3)",
      [](CLI::App& app) { app.add_flag("--disable", disable, "pass the linear command through (no compensation)"); },
      [](runtime::StageContext& ctx) -> std::function<void()> {
        auto params = ctx.config.read("friction_compensation", friction_compensation::read_params);
        if (disable) params.enabled = false;
        auto stage = std::make_shared<friction_compensation::FrictionCompensationStage>(params);
        // The estimate of cycle k does not wake this stage: the linear command of k is computed from
        // it two stages later, so it arrives after it (the loop's 5 ms poll covers the rest).
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(nullptr));
        auto commands = std::shared_ptr(ctx.participant.make_reader<tp::LinearCommand>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::Actuators>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        // The estimate of cycle k arrives before the linear command of cycle k (it is one of its
        // inputs), so keep a few recent estimates to join by seq.
        auto recent = std::make_shared<std::array<protocol::CraneState, 8>>();
        auto out = std::make_shared<protocol::ActuatorCommand>();
        // The linear command of cycle k may overtake the estimate of cycle k (they travel on
        // different topics), so a command waits here until its estimate arrives.
        auto pending = std::make_shared<std::optional<protocol::LinearCommand>>();
        return [=, &ctx] {
          protocol::CraneState state;
          while (runtime::take_plain(*states, state, ctx.counters)) (*recent)[state.header.seq % recent->size()] = state;
          protocol::LinearCommand command;
          while (runtime::take_plain(*commands, command, ctx.counters)) *pending = command;
          if (!pending->has_value()) return;
          const auto seq = (*pending)->header.seq;
          const auto& matching = (*recent)[seq % recent->size()];
          if (matching.header.seq != seq) return;  // its estimate is still on the way
          const protocol::LinearCommand linear = **pending;
          pending->reset();
          switch (watch->classify(seq, ctx.counters)) {
            case runtime::CycleKind::stale: return;
            case runtime::CycleKind::repeat: break;  // answered again from *out, the compensator untouched
            case runtime::CycleKind::new_cycle:
              ++ctx.counters.cycles;
              if (stage->step(matching, linear, *out) != common::StepStatus::ok) ++ctx.counters.nonfinite_rejected;
              watch->answered(seq);
              break;
          }
          out->header.origin = linear.header.origin;  // a re-offer may carry a newer origin
          runtime::write_plain(*writer, *out);
          runtime::record_latency(ctx.latency, out->header);
        };
      });
}
