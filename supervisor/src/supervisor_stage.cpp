#include "crane/supervisor/supervisor_stage.hpp"

#include "crane/config/yaml_section.hpp"
#include "crane/supervisor/actuation_gate.hpp"

namespace crane::supervisor {

SupervisorParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  SupervisorParams p;
  p.sample_period = facts.sample_period;
  p.voltage_limit = facts.voltage_limit;
  p.trolley_min = s.number("trolley_min", -100.0, 100.0);
  p.trolley_max = s.number("trolley_max", -100.0, 100.0);
  p.trolley_approach_margin = s.number("trolley_approach_margin", 0.0, 100.0);
  p.trolley_stop_margin = s.number("trolley_stop_margin", 0.0, 100.0);
  p.trolley_approach_speed = s.number("trolley_approach_speed", 0.0, 100.0);
  p.trolley_max_speed = s.number("trolley_max_speed", 1e-3, 100.0);
  p.slew_enabled = facts.crane_kind == common::CraneKind::tower;
  if (p.slew_enabled) {  // elsewhere these are unknown fields
    p.slew_min = s.number("slew_min", -100.0, 100.0);
    p.slew_max = s.number("slew_max", -100.0, 100.0);
    p.slew_approach_margin = s.number("slew_approach_margin", 0.0, 100.0);
    p.slew_stop_margin = s.number("slew_stop_margin", 0.0, 100.0);
    p.slew_approach_rate = s.number("slew_approach_rate", 0.0, 100.0);
    p.slew_max_rate = s.number("slew_max_rate", 1e-3, 100.0);
  }
  p.bridge_enabled = facts.crane_kind == common::CraneKind::overhead;
  if (p.bridge_enabled) {  // elsewhere these are unknown fields
    p.bridge_min = s.number("bridge_min", -1000.0, 1000.0);
    p.bridge_max = s.number("bridge_max", -1000.0, 1000.0);
    p.bridge_approach_margin = s.number("bridge_approach_margin", 0.0, 1000.0);
    p.bridge_stop_margin = s.number("bridge_stop_margin", 0.0, 1000.0);
    p.bridge_approach_speed = s.number("bridge_approach_speed", 0.0, 100.0);
    p.bridge_max_speed = s.number("bridge_max_speed", 1e-3, 100.0);
  }
  p.approach_voltage_limit = s.number("approach_voltage_limit", 0.0, 100.0);
  p.max_voltage_rate = s.number("max_voltage_rate", 1.0, 1e6);
  p.max_swing = s.number("max_swing", 0.01, 1.5);
  p.stage_timeout = s.number("stage_timeout", 0.005, 5.0);
  p.stage_dead_timeout = s.number("stage_dead_timeout", p.stage_timeout, 60.0);
  p.arm_on_start = s.flag("arm_on_start");
  p.trolley_braking_deceleration = s.number("trolley_braking_deceleration", 1e-3, 1e3);
  if (p.slew_enabled) p.slew_braking_deceleration = s.number("slew_braking_deceleration", 1e-3, 1e3);
  p.zone_stop_delay_periods = s.number("zone_stop_delay_periods", 0.0, 3.0);
  p.zone_approach_margin = s.number("zone_approach_margin", 0.0, 10.0);
  p.zone_brake_margin = s.number("zone_brake_margin", 0.0, 1.0);
  s.finish();
  p.site = facts.site;
  p.gravity = facts.crane.gravity;
  validate(p);
  return p;
}

ActuationGateParams read_actuation_params(config::YamlSection& s, const common::StackFacts& facts) {
  ActuationGateParams p;
  p.sample_period = facts.sample_period;
  p.max_drive_voltage = facts.voltage_limit;
  p.watchdog_timeout = s.number("watchdog_timeout", facts.sample_period, 1.0);
  p.status_timeout = s.number("status_timeout", facts.sample_period, 1.0);
  p.hoist_speed_limit = s.number("hoist_speed_limit", 1e-3, 100.0);
  s.finish();
  validate(p);
  return p;
}

SupervisorStage::SupervisorStage(const SupervisorParams& params) : core_(params) {}

void SupervisorStage::step(const SupervisorCycle& cycle, protocol::SupervisorStatus& status) noexcept {
  static const protocol::SensorSample kNoSensors{};
  static const protocol::ActuatorCommand kNoActuators{};
  const protocol::SensorSample& sensors = cycle.sensors != nullptr ? *cycle.sensors : kNoSensors;
  const protocol::ActuatorCommand& actuators = cycle.actuators != nullptr ? *cycle.actuators : kNoActuators;
  SupervisorInput& in = input_;
  in = SupervisorInput{};
  in.stages = cycle.stages;
  in.sensors_valid = cycle.sensors != nullptr;
  in.sensor_seq = sensors.header.seq;
  // A hardware bridge stamps a sample when it read the encoders, on cycles that jitter in realtime;
  // a simulated plant's samples are sample_period apart (and a board-paced bridge's, in lockstep).
  if (cycle.realtime && sensors.source == protocol::SensorSample::SOURCE_HARDWARE_BRIDGE) {
    in.sensor_time = static_cast<double>(sensors.header.stamp.sec) + 1e-9 * static_cast<double>(sensors.header.stamp.nanosec);
  }
  in.sensor_source = sensors.source;
  in.trolley_position = sensors.trolley_position;
  in.slew_angle = sensors.slew_angle;
  in.bridge_position = sensors.bridge_position;
  in.swing_in_plane = sensors.swing_in_plane;
  in.swing_out_of_plane = sensors.swing_out_of_plane;
  in.cable_length = sensors.cable_length;
  in.limit_switches = sensors.limit_switches;
  in.emergency_stop_input = sensors.emergency_stop_input;
  in.brakes_engaged = sensors.brakes_engaged;
  in.actuators_valid = cycle.actuators != nullptr;
  in.actuator_seq = actuators.header.seq;
  in.trolley_voltage = actuators.trolley_voltage;
  in.slew_voltage = actuators.slew_voltage;
  in.bridge_voltage = actuators.bridge_voltage;
  in.sensor_writers = cycle.sensor_writers;
  in.actuator_writers = cycle.actuator_writers;
  in.nonfinite_seen = cycle.nonfinite_seen;
  in.site = cycle.site;
  in.site_unheard = cycle.site_unheard;
  in.move_in_progress = cycle.reference != nullptr && cycle.reference->phase == protocol::Reference::PHASE_MOVING;
  command_handled_ = cycle.command != nullptr;
  if (command_handled_ && cycle.command->command >= protocol::SupervisorCommand::COMMAND_ARM &&
      cycle.command->command <= protocol::SupervisorCommand::COMMAND_DISABLE_ZONE) {
    in.command = static_cast<Command>(cycle.command->command);
    in.command_operating_mode = cycle.command->operating_mode;
    in.command_zone = cycle.command->zone;
  }
  core_.step(in, output_);
  if (command_handled_) {
    last_request_id_ = cycle.command->request_id;
    last_request_result_ = output_.command_refused ? protocol::SupervisorStatus::RESULT_REFUSED
                                                   : protocol::SupervisorStatus::RESULT_ACCEPTED;
  }
  const SupervisorOutput& out = output_;
  status.header.seq = sensors.header.seq;
  status.header.origin = sensors.header.origin;
  status.mode = static_cast<std::uint8_t>(out.mode);
  status.motion_enabled = out.motion_enabled;
  status.brakes_released = out.brakes_released;
  status.active_faults = out.active_faults;
  status.latched_faults = out.latched_faults;
  status.fault_count = out.fault_count;
  status.stages_alive = out.stages_alive;
  status.nonfinite_rejected = cycle.nonfinite_rejected;
  status.trolley_voltage_limit = out.trolley_voltage_limit;
  status.slew_voltage_limit = out.slew_voltage_limit;
  status.bridge_voltage_limit = out.bridge_voltage_limit;
  status.warnings = out.warnings;
  status.last_fault = out.last_fault;
  status.last_fault_seq = out.last_fault_seq;
  status.trolley_velocity = out.trolley_velocity;
  status.slew_rate = out.slew_rate;
  status.bridge_velocity = out.bridge_velocity;
  status.last_request_id = last_request_id_;
  status.last_request_result = last_request_result_;
  status.operating_mode = out.operating_mode;
  status.zones_enabled = out.zones_enabled;
  status.max_swing = core_.params().max_swing;
}

}  // namespace crane::supervisor
