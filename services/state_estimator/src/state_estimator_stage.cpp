#include "crane/state_estimator/state_estimator_stage.hpp"

#include <cstdint>

#include "crane/common/protocol_signals.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::state_estimator {

namespace {

adaptation::OnlineAdaptationParams read_adaptation(config::YamlSection s, const common::StackFacts& facts) {
  adaptation::OnlineAdaptationParams a;
  a.crane = facts.crane;
  a.sample_period = facts.sample_period;
  a.enabled = s.flag("enabled");
  a.filter_cutoff = s.number("filter_cutoff", 1e-2, 0.45 / facts.sample_period);
  a.trolley_zero_velocity_band = s.number("trolley_zero_velocity_band", 0.0, 10.0);
  a.slew_zero_velocity_band = s.number("slew_zero_velocity_band", 0.0, 10.0);
  a.forgetting_factor = s.number("forgetting_factor", 0.9, 1.0);
  a.min_information = s.number("min_information", 1e-9, 1e9);
  a.max_condition = s.number("max_condition", 1.0, 1e12);
  a.solve_period = s.number("solve_period", facts.sample_period, 60.0);
  a.mass_relative_bound = s.number("mass_relative_bound", 1e-4, 1.0);
  a.min_mass = s.number("min_mass", 0.0, 1e6);
  a.max_mass = s.number("max_mass", 0.0, 1e6);
  a.adapt_friction = s.flag("adapt_friction");
  a.friction_relative_bound = s.number("friction_relative_bound", 1e-4, 10.0);
  a.min_friction_factor = s.number("min_friction_factor", 1e-3, 1.0);
  a.max_friction_factor = s.number("max_friction_factor", 1.0, 100.0);
  a.max_friction_rate = s.number("max_friction_rate", 1e-4, 100.0);
  config::YamlSection cycles = s.child("limit_cycle");
  a.limit_cycle.window = cycles.number("window", 0.1, 60.0);
  a.limit_cycle.rest_span = cycles.number("rest_span", 1e-6, 10.0);
  a.limit_cycle.min_voltage = cycles.number("min_voltage", 0.0, 10.0);
  a.limit_cycle.max_reversals = cycles.integer("max_reversals", 2, 1000);
  cycles.finish();
  s.finish();
  adaptation::validate(a);  // its cross-field invariants (max_mass > min_mass), same message format
  return a;
}

adaptation::SwingLengthParams read_swing_length(config::YamlSection s, const common::StackFacts& facts) {
  adaptation::SwingLengthParams p;
  p.sample_period = facts.sample_period;
  p.crane_kind = facts.crane_kind;
  p.crane = facts.crane;
  p.bridge = facts.bridge;
  p.enabled = s.flag("enabled");
  p.filter_cutoff = s.number("filter_cutoff", 1e-2, 0.45 / facts.sample_period);
  p.forgetting_factor = s.number("forgetting_factor", 0.9, 1.0);
  p.min_swing = s.number("min_swing", 0.0, 1.0);
  p.min_information = s.number("min_information", 1e-9, 1e9);
  p.max_condition = s.number("max_condition", 1.0, 1e12);
  p.solve_period = s.number("solve_period", facts.sample_period, 60.0);
  p.length_bound = s.number("length_bound", 1e-6, 10.0);
  p.scale_bound = s.number("scale_bound", 1e-6, 10.0);
  s.finish();
  adaptation::validate(p);
  return p;
}

}  // namespace

StateEstimatorStageParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  StateEstimatorStageParams stage;
  StateEstimatorParams& p = stage.estimator;
  p.sample_rate = 1.0 / facts.sample_period;
  p.cutoff_frequency = s.number("cutoff_frequency", 1e-3, 0.499 * p.sample_rate);
  stage.follower_cutoff_frequency = s.number("follower_cutoff_frequency", 1e-3, 0.499 * p.sample_rate);
  const auto kind = s.text("differentiator", {"backward", "al_alaoui_first_order", "al_alaoui_second_order"});
  p.differentiator = kind == "backward"                ? DifferentiatorKind::backward
                     : kind == "al_alaoui_first_order" ? DifferentiatorKind::al_alaoui_first_order
                                                       : DifferentiatorKind::al_alaoui_second_order;
  stage.adaptation = read_adaptation(s.child("adaptation"), facts);
  stage.swing_length = read_swing_length(s.child("swing_length"), facts);
  stage.bridge = facts.crane_kind == common::CraneKind::overhead;
  s.finish();
  StateEstimator{p};  // its own invariants, same message format
  return stage;
}

StateEstimatorStageParams for_follower(StateEstimatorStageParams params) {
  params.estimator.cutoff_frequency = params.follower_cutoff_frequency;
  return params;
}

StateEstimatorStage::StateEstimatorStage(const StateEstimatorStageParams& params)
    : estimator_(params.estimator), adaptation_(params.adaptation), swing_length_(params.swing_length) {
  if (params.bridge) bridge_estimator_.emplace(params.estimator);
}

common::StepStatus StateEstimatorStage::step(const protocol::SensorSample& sensors,
                                             protocol::CraneState& estimate) noexcept {
  if (!protocol::all_finite(sensors)) return common::StepStatus::rejected_nonfinite;
  const auto status = estimator_.step(common::to_measurement(sensors), scratch_);
  if (status != common::StepStatus::ok) return status;
  common::from_estimate(scratch_, estimate);
  if (bridge_estimator_) {
    common::CraneMeasurement bridge = common::to_measurement(sensors);
    bridge.trolley_position = sensors.bridge_position;
    if (bridge_estimator_->step(bridge, bridge_scratch_) == common::StepStatus::ok) {
      estimate.bridge_position = bridge_scratch_.trolley_position;
      estimate.bridge_velocity = bridge_scratch_.trolley_velocity;
      estimate.bridge_velocity_raw = bridge_scratch_.trolley_velocity_raw;
    }
  }
  adaptation::AdaptationInput in;
  in.trolley_position = sensors.trolley_position;
  in.slew_angle = sensors.slew_angle;
  in.swing_in_plane = sensors.swing_in_plane;
  in.swing_out_of_plane = sensors.swing_out_of_plane;
  in.applied_trolley_voltage = sensors.applied_trolley_voltage;
  in.applied_slew_voltage = sensors.applied_slew_voltage;
  in.brakes_engaged = sensors.brakes_engaged;
  adaptation_.step(in, adapted_);
  estimate.payload_mass = adapted_.payload_mass;
  estimate.payload_mass_bound = adapted_.payload_mass_bound;
  estimate.payload_confident = adapted_.payload_confident;
  using protocol::CraneState;
  estimate.adaptation = static_cast<std::uint8_t>(
      (adaptation_.params().enabled ? CraneState::ADAPTATION_ENABLED : 0) |
      (adapted_.trolley_friction_adapted ? CraneState::ADAPTATION_TROLLEY_FRICTION_ADAPTED : 0) |
      (adapted_.slew_friction_adapted ? CraneState::ADAPTATION_SLEW_FRICTION_ADAPTED : 0) |
      (adapted_.trolley_limit_cycle ? CraneState::ADAPTATION_TROLLEY_LIMIT_CYCLE : 0) |
      (adapted_.slew_limit_cycle ? CraneState::ADAPTATION_SLEW_LIMIT_CYCLE : 0));
  common::set_friction_in_use(adapted_.trolley_friction, adapted_.slew_friction, estimate);
  estimate.trolley_voltage_sign_changes = adapted_.trolley_voltage_sign_changes;
  estimate.slew_voltage_sign_changes = adapted_.slew_voltage_sign_changes;
  adaptation::SwingLengthInput swing;
  swing.trolley_position = sensors.trolley_position;
  swing.second_axis = bridge_estimator_ ? sensors.bridge_position : sensors.slew_angle;
  swing.swing_in_plane = sensors.swing_in_plane;
  swing.swing_out_of_plane = sensors.swing_out_of_plane;
  swing.cable_length = sensors.cable_length;
  swing.brakes_engaged = sensors.brakes_engaged;
  swing_length_.step(swing, pendulum_);
  estimate.swing_length_scale = pendulum_.scale;
  estimate.swing_length_offset = pendulum_.offset;
  estimate.swing_length_bound = pendulum_.length_bound;
  estimate.swing_length_confident = pendulum_.confident;
  common::same_cycle(sensors.header, estimate.header);
  return status;
}

}  // namespace crane::state_estimator
