#include "crane/friction_compensation/friction_compensation_stage.hpp"

#include "crane/common/protocol_signals.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::friction_compensation {

namespace {

AxisCompensationParams read_axis(config::YamlSection s, const common::AxisFriction& friction) {
  AxisCompensationParams a;
  a.friction = friction;
  a.zero_velocity_band = s.number("zero_velocity_band", 0.0, 10.0);
  a.stiction_slope = s.number("stiction_slope", 1e-3, 1e4);
  const auto source = s.text("velocity_source", {"raw", "filtered"});
  a.velocity_source = source == "raw" ? VelocitySource::raw : VelocitySource::filtered;
  s.finish();
  return a;
}

}  // namespace

FrictionCompensationParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  FrictionCompensationParams p;
  p.enabled = s.flag("enabled");
  // The compensator's friction model is the configured crane's, (4.12)-(4.16).
  p.trolley = read_axis(s.child("trolley"), facts.crane.trolley_friction);
  p.slew = read_axis(s.child("slew"), facts.crane.slew_friction);
  s.finish();
  p.voltage_limit = facts.voltage_limit;
  FrictionCompensation{p};
  return p;
}

FrictionCompensationStage::FrictionCompensationStage(const FrictionCompensationParams& params)
    : compensation_(params) {}

common::StepStatus FrictionCompensationStage::step(const protocol::CraneState& estimate,
                                                   const protocol::LinearCommand& linear,
                                                   protocol::ActuatorCommand& command) const noexcept {
  FrictionCompensationInput in;
  in.estimate = common::to_estimate(estimate);
  in.command.trolley_voltage = linear.trolley_voltage;
  in.command.slew_voltage = linear.slew_voltage;
  in.command.hoist_speed = linear.hoist_speed;
  // The friction re-estimated online, where the estimator released it (crane::adaptation).
  if ((estimate.adaptation & protocol::CraneState::ADAPTATION_TROLLEY_FRICTION_ADAPTED) != 0) {
    in.trolley_friction = common::trolley_friction_in_use(estimate);
  }
  if ((estimate.adaptation & protocol::CraneState::ADAPTATION_SLEW_FRICTION_ADAPTED) != 0) {
    in.slew_friction = common::slew_friction_in_use(estimate);
  }
  FrictionCompensationOutput result;
  const auto status = compensation_.step(in, result);
  command.trolley_voltage = result.command.trolley_voltage;
  command.slew_voltage = result.command.slew_voltage;
  command.hoist_speed = result.command.hoist_speed;
  command.trolley_friction_voltage = result.trolley_friction;
  command.slew_friction_voltage = result.slew_friction;
  common::same_cycle(linear.header, command.header);
  return status;
}

}  // namespace crane::friction_compensation
