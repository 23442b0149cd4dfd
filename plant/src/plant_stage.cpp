#include "crane/plant/plant_stage.hpp"

#include <cstdint>
#include <stdexcept>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/config/config_document.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::plant {

namespace {

common::AxisFriction scaled(common::AxisFriction f, double factor) {
  f.viscous_positive *= factor;
  f.viscous_negative *= factor;
  f.coulomb_positive *= factor;
  f.coulomb_negative *= factor;
  f.static_positive *= factor;
  f.static_negative *= factor;
  return f;
}

}  // namespace

void validate(const PlantMismatch& m) {
  common::require_in_range("plant.mismatch.cable_length_factor", m.cable_length_factor, 0.1, 10.0);
  common::require_in_range("plant.mismatch.load_mass_factor", m.load_mass_factor, 0.0, 10.0);
  common::require_in_range("plant.mismatch.friction_factor", m.friction_factor, 0.0, 10.0);
  common::require_in_range("plant.mismatch.sensor_delay_cycles", m.sensor_delay_cycles, 0, PlantStage::kMaxSensorDelay);
  common::require_in_range("plant.mismatch.friction_change_factor", m.friction_change_factor, 0.1, 10.0);
}

PlantMismatch mismatch_from_factors(std::span<const double> factors) {
  if (factors.size() != 3) {
    throw std::invalid_argument("plant mismatch: " + std::to_string(factors.size()) +
                                " factors given, 3 expected (cable length, load mass, friction)");
  }
  PlantMismatch m;
  m.cable_length_factor = factors[0];
  m.load_mass_factor = factors[1];
  m.friction_factor = factors[2];
  return m;
}

SimulatorParameters read_params(config::YamlSection& s, const common::StackFacts& facts) {
  SimulatorParameters p;
  p.kind = facts.crane_kind;
  p.bridge = facts.bridge;
  p.crane = facts.crane;
  p.sample_period = facts.sample_period;
  p.integrator.method = parse_integration_method(s.text("integrator"), s.field("integrator"));
  p.integrator.relative_tolerance = s.number("relative_tolerance", 1e-14, 1e-3);
  p.integrator.absolute_tolerance = s.number("absolute_tolerance", 1e-16, 1e-3);
  p.brake_holding_factor = s.number("brake_holding_factor", 1.0, 1000.0);
  p.hoist_max_acceleration = s.number("hoist_max_acceleration", 1e-3, 100.0);
  if (p.kind == PlantKind::tower) {  // elsewhere plant.hook, plant.wind and plant.rope are unknown fields
    config::YamlSection hook = s.child("hook");
    p.hook.enabled = hook.flag("enabled");
    p.hook.rigging_length = hook.number("rigging_length", 0.001, 10.0);
    p.hook.hook_mass = hook.number("hook_mass", 0.001, 1e4);
    hook.finish();
    config::YamlSection wind = s.child("wind");
    p.wind.enabled = wind.flag("enabled");
    p.wind.mean_force_x = wind.number("mean_force_x", -1e4, 1e4);
    p.wind.mean_force_y = wind.number("mean_force_y", -1e4, 1e4);
    p.wind.gust_force_std = wind.number("gust_force_std", 0.0, 1e4);
    p.wind.gust_time_constant = wind.number("gust_time_constant", 0.01, 1e4);
    p.wind.seed = static_cast<std::uint64_t>(wind.integer("seed", 0, 2147483647));
    wind.finish();
    config::YamlSection rope = s.child("rope");
    p.rope.enabled = rope.flag("enabled");
    p.rope.axial_stiffness = rope.number("axial_stiffness", 1.0, 1e10);
    p.rope.damping_ratio = rope.number("damping_ratio", 0.0, 1.0);
    rope.finish();
    if (p.rope.enabled && p.hook.enabled) {
      throw common::ConfigError(rope.field("enabled") + " = true needs plant.hook.enabled = false (an elastic rope "
                                "with a hook is not modelled)");
    }
    if (p.wind.enabled && !(p.crane.load_mass > 0.0)) {
      throw common::ConfigError(wind.field("enabled") + " = true needs crane.load_mass > 0 (is " +
                                std::to_string(p.crane.load_mass) + ")");
    }
  }
  s.finish();
  p.initial_state.cable_length = facts.crane.cable_length;
  // An elastic rope starts at its static stretch m g L / EA (at rest, no bounce).
  if (p.rope.enabled) {
    p.initial_state.rope_stretch = p.crane.load_mass * p.crane.gravity * p.crane.cable_length / p.rope.axial_stiffness;
  }
  return p;
}

SimulatorParameters simulated_truth(const SimulatorParameters& configured, const PlantMismatch& mismatch) {
  validate(mismatch);
  SimulatorParameters truth = configured;
  truth.crane.cable_length *= mismatch.cable_length_factor;
  truth.crane.load_mass *= mismatch.load_mass_factor;
  truth.crane.trolley_friction = scaled(truth.crane.trolley_friction, mismatch.friction_factor);
  truth.crane.slew_friction = scaled(truth.crane.slew_friction, mismatch.friction_factor);
  truth.initial_state.cable_length = truth.crane.cable_length;
  return truth;
}

PlantStage::PlantStage(const PlantStageParams& params)
    : mismatch_(params.mismatch),
      simulator_(simulated_truth(params.simulator, params.mismatch)),
      gate_(params.gate),
      cable_length_reading_factor_(1.0 / params.mismatch.cable_length_factor) {
  measurements_.fill(simulator_.output().measurement);  // at rest before cycle 0
  if (mismatch_.friction_change_factor != 1.0) {
    const auto& crane = simulator_.parameters().crane;
    changed_friction_ = simulator_.friction_models(scaled(crane.trolley_friction, mismatch_.friction_change_factor),
                                                   scaled(crane.slew_friction, mismatch_.friction_change_factor));
  }
}

void PlantStage::sample(protocol::SensorSample& s) const noexcept {
  const auto delay = static_cast<std::uint64_t>(mismatch_.sensor_delay_cycles);
  const std::uint64_t measured = cycle_ >= delay ? cycle_ - delay : 0;
  const common::CraneMeasurement& m =
      delay == 0 ? simulator_.output().measurement : measurements_[measured % measurements_.size()];
  const SimulatorOutput o = simulator_.output();
  s.header.seq = cycle_;
  s.source = protocol::SensorSample::SOURCE_PLANT;
  s.trolley_position = m.trolley_position;
  s.slew_angle = m.slew_angle;
  s.swing_in_plane = m.swing_in_plane;
  s.swing_out_of_plane = m.swing_out_of_plane;
  s.cable_length = m.cable_length * cable_length_reading_factor_;
  s.applied_trolley_voltage = o.applied_trolley_voltage;
  s.applied_slew_voltage = o.applied_slew_voltage;
  s.applied_hoist_speed = o.applied_hoist_speed;
  s.brakes_engaged = o.brakes_engaged;
  s.emergency_stop_input = false;
  s.limit_switches = 0;
  s.bridge_position = m.bridge_position;
  s.applied_bridge_voltage = o.applied_bridge_voltage;
}

void PlantStage::remember_measurement() noexcept {
  measurements_[cycle_ % measurements_.size()] = simulator_.output().measurement;
}

common::StepStatus PlantStage::step(const supervisor::GateInput& input) noexcept {
  gate_.step(input, gate_output_);
  drive_ = DriveInput{};  // 0 V, brakes engaged, then the gate's output
  drive_.trolley_voltage = gate_output_.drive.trolley_voltage;
  drive_.slew_voltage = gate_output_.drive.slew_voltage;
  drive_.bridge_voltage = gate_output_.drive.bridge_voltage;
  drive_.hoist_speed = gate_output_.drive.hoist_speed;
  drive_.brakes_engaged = gate_output_.brakes_engaged;
  if (changed_friction_ && cycle_ == mismatch_.friction_change_cycle) simulator_.set_friction(*changed_friction_);
  const auto status = simulator_.step(drive_);
  ++cycle_;
  remember_measurement();
  return status;
}

}  // namespace crane::plant
