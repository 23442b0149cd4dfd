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
  if (facts.crane_kind == common::CraneKind::overhead) {  // elsewhere friction_compensation.bridge is unknown
    p.bridge = read_axis(s.child("bridge"), facts.bridge.friction);
  }
  s.finish();
  p.voltage_limit = facts.voltage_limit;
  FrictionCompensation{p};
  return p;
}

FrictionCompensationStage::FrictionCompensationStage(const FrictionCompensationParams& params)
    : compensation_(params) {
  if (params.bridge) {
    FrictionCompensationParams bridge = params;
    bridge.trolley = *params.bridge;
    bridge.bridge.reset();
    bridge_.emplace(bridge);
  }
}

common::StepStatus FrictionCompensationStage::step(const protocol::CraneState& estimate,
                                                   const protocol::LinearCommand& linear,
                                                   protocol::ActuatorCommand& command) const noexcept {
  FrictionCompensationInput in;
  in.estimate = common::to_estimate(estimate);
  in.command.trolley_voltage = linear.trolley_voltage;
  in.command.slew_voltage = linear.slew_voltage;
  in.command.hoist_speed = linear.hoist_speed;
  in.sliding_friction_reduction = linear.sliding_friction_reduction;
  in.friction_factor = linear.friction_factor;
  // The friction re-estimated online, where the estimator released it (crane::adaptation).
  if ((estimate.adaptation & protocol::CraneState::ADAPTATION_TROLLEY_FRICTION_ADAPTED) != 0) {
    in.trolley_friction = common::trolley_friction_in_use(estimate);
  }
  if ((estimate.adaptation & protocol::CraneState::ADAPTATION_SLEW_FRICTION_ADAPTED) != 0) {
    in.slew_friction = common::slew_friction_in_use(estimate);
  }
  FrictionCompensationOutput result;
  auto status = compensation_.step(in, result);
  command.trolley_voltage = result.command.trolley_voltage;
  command.slew_voltage = result.command.slew_voltage;
  command.hoist_speed = result.command.hoist_speed;
  command.trolley_friction_voltage = result.trolley_friction;
  command.slew_friction_voltage = result.slew_friction;
  if (bridge_) {
    FrictionCompensationInput b;
    b.estimate = common::to_estimate(common::bridge_view(estimate));
    b.command.trolley_voltage = linear.bridge_voltage;
    b.sliding_friction_reduction = linear.sliding_friction_reduction;
    b.friction_factor = linear.friction_factor;
    FrictionCompensationOutput bridge;
    const auto bridge_status = bridge_->step(b, bridge);
    command.bridge_voltage = bridge.command.trolley_voltage;
    command.bridge_friction_voltage = bridge.trolley_friction;
    if (status == common::StepStatus::ok) status = bridge_status;
  }
  common::same_cycle(linear.header, command.header);
  return status;
}

}  // namespace crane::friction_compensation
