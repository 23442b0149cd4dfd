// friction_compensation process: joins rt/crane/control/linear and rt/crane/state/estimate of the
// same cycle -> u = V + F_f/K_m (3.5) -> rt/crane/hw/actuators. `--disable` passes V through
// unchanged (the dissertation's "without friction compensation" runs, figures 4.19-4.22).
#include <optional>

#include "crane/friction_compensation/friction_compensation.hpp"
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
        auto params = ctx.config.friction_compensation;
        if (disable) params.enabled = false;
        auto compensator = std::make_shared<friction_compensation::FrictionCompensation>(params);
        // The estimate of cycle k does not wake this stage: the linear command of k is computed from
        // it two stages later, so it arrives after it (the loop's 5 ms poll covers the rest).
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(nullptr));
        auto commands = std::shared_ptr(ctx.participant.make_reader<tp::LinearCommand>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::Actuators>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        // The estimate of cycle k arrives before the linear command of cycle k (it is one of its
        // inputs), so keep a few recent estimates to join by seq.
        auto recent = std::make_shared<std::array<tp::msgs::CraneState_, 8>>();
        auto out = std::make_shared<tp::msgs::ActuatorCommand_>();
        // The linear command of cycle k may overtake the estimate of cycle k (they travel on
        // different topics), so a command waits here until its estimate arrives.
        auto pending = std::make_shared<std::optional<tp::msgs::LinearCommand_>>();
        return [=, &ctx] {
          tp::msgs::CraneState_ state;
          while (runtime::take_finite(*states, state, ctx.counters)) {
            (*recent)[state.header().seq() % recent->size()] = state;
          }
          tp::msgs::LinearCommand_ command;
          while (runtime::take_finite(*commands, command, ctx.counters)) {
            *pending = command;
          }
          if (!pending->has_value()) return;
          const auto seq = (*pending)->header().seq();
          const auto& matching = (*recent)[seq % recent->size()];
          if (matching.header().seq() != seq) return;  // its estimate is still on the way
          const tp::msgs::LinearCommand_ linear = **pending;
          pending->reset();
          switch (watch->classify(seq, ctx.counters)) {
            case runtime::CycleKind::stale: return;
            case runtime::CycleKind::repeat: break;  // answered again from *out, the compensator untouched
            case runtime::CycleKind::new_cycle: {
              ++ctx.counters.cycles;
              friction_compensation::FrictionCompensationInput in;
              in.estimate = runtime::to_estimate(matching);
              in.command.trolley_voltage = linear.trolley_voltage();
              in.command.slew_voltage = linear.slew_voltage();
              in.command.hoist_speed = linear.hoist_speed();
              friction_compensation::FrictionCompensationOutput result;
              if (compensator->step(in, result) != common::StepStatus::ok) ++ctx.counters.nonfinite_rejected;
              out->trolley_voltage(result.command.trolley_voltage);
              out->slew_voltage(result.command.slew_voltage);
              out->hoist_speed(result.command.hoist_speed);
              out->trolley_friction_voltage(result.trolley_friction);
              out->slew_friction_voltage(result.slew_friction);
              watch->answered(seq);
              break;
            }
          }
          runtime::stamp_header(out->header(), seq, linear.header().origin());
          writer->write(*out);
          runtime::record_latency(ctx.latency, out->header());
        };
      });
}
