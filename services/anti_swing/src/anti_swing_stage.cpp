#include "crane/anti_swing/anti_swing_stage.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "crane/common/protocol_signals.hpp"
#include "crane/common/validation.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::anti_swing {

namespace {

using Core = std::variant<AntiSwing, anti_swing_analysis::FuzzyAntiSwing, anti_swing_analysis::DelayedTrajectoryAntiSwing>;

Core make_core(const AntiSwingStageParams& params) {
  const AntiSwingParams& cfg = params.anti_swing;
  switch (params.law) {
    case AntiSwingLaw::fuzzy: {
      anti_swing_analysis::FuzzyAntiSwingParams p;
      p.gravity = cfg.gravity;
      p.min_cable_length = cfg.min_cable_length;
      p.max_cable_length = cfg.max_cable_length;
      p.slew_enabled = cfg.slew_enabled;
      return Core(std::in_place_type<anti_swing_analysis::FuzzyAntiSwing>, p);
    }
    case AntiSwingLaw::delay2: {
      anti_swing_analysis::DelayedTrajectoryAntiSwingParams p;
      p.sample_period = cfg.sample_period;
      p.gravity = cfg.gravity;
      p.min_cable_length = cfg.min_cable_length;
      p.max_cable_length = cfg.max_cable_length;
      p.slew_enabled = cfg.slew_enabled;
      return Core(std::in_place_type<anti_swing_analysis::DelayedTrajectoryAntiSwing>, p);
    }
    case AntiSwingLaw::none:
    case AntiSwingLaw::pd:
    case AntiSwingLaw::delay1: break;
  }
  auto p = cfg;
  p.kind = params.law == AntiSwingLaw::none ? AntiSwingKind::none
           : params.law == AntiSwingLaw::pd ? AntiSwingKind::pd
                                            : AntiSwingKind::delayed_feedback;
  return Core(std::in_place_type<AntiSwing>, p);
}

}  // namespace

std::string_view law_name(AntiSwingLaw law) noexcept {
  return protocol::code_name(protocol::AntiSwingCommand::kCodes, "CONTROLLER", static_cast<std::uint64_t>(law));
}

AntiSwingLaw law_from_name(std::string_view name, std::string_view field) {
  std::string choices;
  for (const auto& code : protocol::AntiSwingCommand::kCodes) {
    if (code.group != "CONTROLLER") continue;
    if (code.name == name) return static_cast<AntiSwingLaw>(code.value);
    choices += (choices.empty() ? "" : ", ") + std::string(code.name);
  }
  throw common::ConfigError(std::string(field) + " = '" + std::string(name) + "' is not one of: " + choices);
}

AntiSwingStageParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  AntiSwingStageParams p;
  p.law = law_from_name(s.text("controller"), s.field("controller"));
  auto& a = p.anti_swing;
  a.pd_proportional_gain = s.number("pd_proportional_gain", -1000.0, 1000.0);
  a.pd_derivative_gain = s.number("pd_derivative_gain", -1000.0, 1000.0);
  a.delay_gain = s.number("delay_gain", -1000.0, 1000.0);
  a.normalized_delay = s.number("normalized_delay", 1e-3, 5.0);
  a.slew_enabled = s.flag("slew_enabled");
  {
    config::YamlSection g = s.child("short_cable");
    a.short_cable.enabled = g.flag("enabled");
    a.short_cable.short_length = g.number("short_length", 1e-3, 100.0);
    a.short_cable.full_gain_length = g.number("full_gain_length", 1e-3, 100.0);
    a.short_cable.gain = g.number("delay_gain", -1000.0, 1000.0);
    g.finish();
  }
  p.fade_periods = s.number("fade_periods", kMinFadePeriods, kMaxFadePeriods);
  s.finish();
  a.sample_period = facts.sample_period;
  a.gravity = facts.crane.gravity;
  a.min_cable_length = facts.crane.min_cable_length;
  a.max_cable_length = facts.crane.max_cable_length;
  p.bridge = facts.crane_kind == common::CraneKind::overhead;
  AntiSwingStage{p};  // the law's own invariants, same message format
  return p;
}

bool feedback_in_mode(std::uint8_t operating_mode) noexcept {
  return operating_mode != protocol::SupervisorStatus::OPERATION_MAINTENANCE;
}

AntiSwingStage::AntiSwingStage(const AntiSwingStageParams& params)
    : law_(params.law), core_(make_core(params)), swing_(params.anti_swing), fade_periods_(params.fade_periods) {
  common::require_in_range("anti_swing.fade_periods", params.fade_periods, kMinFadePeriods, kMaxFadePeriods);
  if (params.bridge) {
    AntiSwingStageParams bridge = params;
    bridge.anti_swing.slew_enabled = false;  // the bridge's gantry view has no slew
    bridge_core_.emplace(make_core(bridge));
  }
}

AntiSwingStage::Result AntiSwingStage::run(Core& core, const protocol::CraneState& estimate) noexcept {
  const auto current = common::to_estimate(estimate);
  Result r;
  if (auto* a = std::get_if<AntiSwing>(&core)) {
    r.status = a->step(current, r.action);
  } else if (auto* f = std::get_if<anti_swing_analysis::FuzzyAntiSwing>(&core)) {
    r.status = f->step(current, r.action);
  } else if (auto* d = std::get_if<anti_swing_analysis::DelayedTrajectoryAntiSwing>(&core)) {
    r.status = d->step(current, r.correction);
  }
  if (r.status != common::StepStatus::ok && r.status != common::StepStatus::rejected_nonfinite) {
    r.action = {};  // not_ready: every field 0, the safe value
    r.correction = {};
  }
  return r;
}

common::StepStatus AntiSwingStage::step(const protocol::CraneState& estimate, const protocol::SupervisorStatus* status,
                                        protocol::AntiSwingCommand& command) noexcept {
  using Status = protocol::SupervisorStatus;
  if (!protocol::all_finite(estimate)) return common::StepStatus::rejected_nonfinite;
  const Result r = run(core_, estimate);
  if (r.status == common::StepStatus::rejected_nonfinite) return r.status;
  if (status != nullptr && status->operating_mode >= Status::OPERATION_MANUAL &&
      status->operating_mode <= Status::OPERATION_MAINTENANCE) {
    operating_mode_ = status->operating_mode;
  }
  // The share of the law's output moves toward 1 (or 0 in MAINTENANCE) by T_s / (fade_periods T) a
  // cycle, T the swing period at the measured cable length; it reaches 1 and 0 exactly.
  const double cable_length = std::clamp(estimate.cable_length, swing_.min_cable_length, swing_.max_cable_length);
  const double period = 2.0 * std::numbers::pi * std::sqrt(cable_length / swing_.gravity);  // T [s]
  const double fade = swing_.sample_period / (fade_periods_ * period);
  engagement_ = feedback_in_mode(operating_mode_) ? std::min(1.0, engagement_ + fade) : std::max(0.0, engagement_ - fade);
  const double g = engagement_;
  command.controller = static_cast<std::uint8_t>(law_);
  command.trolley_action = g * r.action.trolley_action;
  command.slew_action = g * r.action.slew_action;
  command.trolley_reference_correction = g * r.correction.trolley_position_correction;
  command.trolley_reference_rate_correction = g * r.correction.trolley_velocity_correction;
  command.slew_reference_correction = g * r.correction.slew_angle_correction;
  command.slew_reference_rate_correction = g * r.correction.slew_rate_correction;
  if (bridge_core_) {
    const Result b = run(*bridge_core_, common::bridge_view(estimate));
    command.bridge_action = g * b.action.trolley_action;
    command.bridge_reference_correction = g * b.correction.trolley_position_correction;
    command.bridge_reference_rate_correction = g * b.correction.trolley_velocity_correction;
  }
  common::same_cycle(estimate.header, command.header);
  return r.status;
}

}  // namespace crane::anti_swing
