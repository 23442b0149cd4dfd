// anti_swing process: rt/crane/state/estimate -> anti-swing law (section 3.3.2) ->
// rt/crane/control/anti_swing, once per cycle, same seq and origin.
//
// --controller selects the law (default: the configuration's anti_swing.kind):
//   none   action 0                                          (controller code 0)
//   pd     (3.45) V_xs = K_ps phi + K_ds T phi_dot           (code 1)
//   delay1 (3.47) V_xs = K_del phi(tau - tau_del)            (code 2)
//   delay2 (3.50) Masoud's configuration: the delayed swing corrects the reference the tracking PD
//          follows; the actions are 0 and the reference-correction fields are set (code 3)
//   fuzzy  figures 3.20-3.21, tables 3.7-3.8, (3.51)         (code 4)
// pd, delay1 and fuzzy use the gains, delay, gravity and cable-length range of the configuration's
// anti_swing block (fuzzy and delay2 keep their own dissertation defaults for their gains).
#include <variant>

#include "crane/anti_swing/anti_swing.hpp"
#include "crane/anti_swing_analysis/delayed_trajectory_anti_swing.hpp"
#include "crane/anti_swing_analysis/fuzzy_anti_swing.hpp"
#include "crane/runtime/stage_node.hpp"

namespace {

using namespace crane;

std::string default_controller(anti_swing::AntiSwingKind kind) {
  switch (kind) {
    case anti_swing::AntiSwingKind::none: return "none";
    case anti_swing::AntiSwingKind::pd: return "pd";
    case anti_swing::AntiSwingKind::delayed_feedback: return "delay1";
  }
  return "delay1";
}

// One of the three cores; step() fills the message's action and correction fields.
class AntiSwingLaw {
 public:
  AntiSwingLaw(const std::string& name, const anti_swing::AntiSwingParams& cfg) {
    if (name == "fuzzy") {
      anti_swing_analysis::FuzzyAntiSwingParams p;
      p.gravity = cfg.gravity;
      p.min_cable_length = cfg.min_cable_length;
      p.max_cable_length = cfg.max_cable_length;
      p.slew_enabled = cfg.slew_enabled;
      core_.emplace<anti_swing_analysis::FuzzyAntiSwing>(p);
      code_ = 4;
    } else if (name == "delay2") {
      anti_swing_analysis::DelayedTrajectoryAntiSwingParams p;
      p.sample_period = cfg.sample_period;
      p.gravity = cfg.gravity;
      p.min_cable_length = cfg.min_cable_length;
      p.max_cable_length = cfg.max_cable_length;
      p.slew_enabled = cfg.slew_enabled;
      core_.emplace<anti_swing_analysis::DelayedTrajectoryAntiSwing>(p);
      code_ = 3;
    } else {
      auto p = cfg;
      p.kind = name == "none" ? anti_swing::AntiSwingKind::none
               : name == "pd" ? anti_swing::AntiSwingKind::pd
                              : anti_swing::AntiSwingKind::delayed_feedback;
      core_.emplace<anti_swing::AntiSwing>(p);
      code_ = name == "none" ? 0 : name == "pd" ? 1 : 2;
    }
  }

  [[nodiscard]] std::uint8_t code() const noexcept { return code_; }

  /// not_ready (delay line still filling) leaves every field 0: that is the safe value.
  [[nodiscard]] common::StepStatus step(const common::CraneStateEstimate& estimate,
                                        transport::topics::msgs::AntiSwingCommand_& out) noexcept {
    common::StepStatus status = common::StepStatus::ok;
    anti_swing::AntiSwingOutput action;
    anti_swing_analysis::TrajectoryCorrection correction;
    if (auto* a = std::get_if<anti_swing::AntiSwing>(&core_)) {
      status = a->step(estimate, action);
    } else if (auto* f = std::get_if<anti_swing_analysis::FuzzyAntiSwing>(&core_)) {
      status = f->step(estimate, action);
    } else if (auto* d = std::get_if<anti_swing_analysis::DelayedTrajectoryAntiSwing>(&core_)) {
      status = d->step(estimate, correction);
    }
    if (status != common::StepStatus::ok) {
      action = {};
      correction = {};
    }
    out.controller(code_);
    out.trolley_action(action.trolley_action);
    out.slew_action(action.slew_action);
    out.trolley_reference_correction(correction.trolley_position_correction);
    out.trolley_reference_rate_correction(correction.trolley_velocity_correction);
    out.slew_reference_correction(correction.slew_angle_correction);
    out.slew_reference_rate_correction(correction.slew_rate_correction);
    return status;
  }

 private:
  std::variant<std::monostate, anti_swing::AntiSwing, anti_swing_analysis::FuzzyAntiSwing,
               anti_swing_analysis::DelayedTrajectoryAntiSwing>
      core_;
  std::uint8_t code_{0};
};

}  // namespace

int main(int argc, char** argv) {
  namespace tp = transport::topics;
  auto controller_name = std::make_shared<std::string>();
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::anti_swing,
      "anti_swing: swing damping action, PD (3.45), delayed feedback (3.47)/(3.50) or fuzzy, from the state "
      "estimate",
      [controller_name](CLI::App& app) {
        app.add_option("--controller", *controller_name,
                       "anti-swing law: none | pd | delay1 (3.47) | delay2 (3.50) | fuzzy (default: the "
                       "configuration's anti_swing.controller)")
            ->check(CLI::IsMember({"none", "pd", "delay1", "delay2", "fuzzy"}));
      },
      [controller_name](runtime::StageContext& ctx) -> std::function<void()> {
        const std::string name =
            controller_name->empty() ? default_controller(ctx.config.anti_swing.kind) : *controller_name;
        auto law = std::make_shared<AntiSwingLaw>(name, ctx.config.anti_swing);
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::AntiSwing>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto out = std::make_shared<tp::msgs::AntiSwingCommand_>();
        return [=, &ctx] {
          tp::msgs::CraneState_ state;
          while (runtime::take_finite(*states, state, ctx.counters)) {
            const auto seq = state.header().seq();
            switch (watch->classify(seq, ctx.counters)) {
              case runtime::CycleKind::stale: continue;
              case runtime::CycleKind::repeat: break;  // answered again from *out, the law untouched
              case runtime::CycleKind::new_cycle:
                if (law->step(runtime::to_estimate(state), *out) == common::StepStatus::rejected_nonfinite) {
                  ++ctx.counters.nonfinite_rejected;
                  continue;
                }
                ++ctx.counters.cycles;
                watch->answered(seq);
                break;
            }
            runtime::stamp_header(out->header(), seq, state.header().origin());
            writer->write(*out);
            runtime::record_latency(ctx.latency, out->header());
          }
        };
      });
}
