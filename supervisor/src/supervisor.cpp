#include "crane/supervisor/supervisor.hpp"

#include <bit>
#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::supervisor {

const char* stage_name(Stage stage) noexcept {
  switch (stage) {
    case Stage::sensors: return "sensors";
    case Stage::state_estimator: return "state_estimator";
    case Stage::trajectory_planner: return "trajectory_planner";
    case Stage::anti_swing: return "anti_swing";
    case Stage::tracking: return "tracking";
    case Stage::friction_compensation: return "friction_compensation";
  }
  return "unknown";
}

const char* mode_name(Mode mode) noexcept {
  switch (mode) {
    case Mode::starting: return "starting";
    case Mode::standby: return "standby";
    case Mode::ready: return "ready";
    case Mode::operating: return "operating";
    case Mode::fault: return "fault";
    case Mode::emergency_stop: return "emergency_stop";
  }
  return "unknown";
}

void validate(const SupervisorParams& p) {
  using common::require_in_range;
  require_in_range("supervisor.trolley_min", p.trolley_min, -100.0, 100.0);
  require_in_range("supervisor.trolley_max", p.trolley_max, p.trolley_min + 1e-3, 100.0);
  require_in_range("supervisor.voltage_limit", p.voltage_limit, 0.1, 100.0);
  require_in_range("supervisor.max_swing", p.max_swing, 0.01, 1.5);
  require_in_range("supervisor.stage_timeout", p.stage_timeout, 0.005, 5.0);
  require_in_range("supervisor.lockstep_stage_timeout", p.lockstep_stage_timeout, p.stage_timeout, 60.0);
}

Supervisor::Supervisor(const SupervisorParams& params) : params_(params) { validate(params_); }

void Supervisor::step(const SupervisorInput& in, SupervisorOutput& out) noexcept {
  std::uint32_t alive_mask = 0;
  for (std::size_t i = 0; i < kStageCount; ++i) {
    const auto& s = in.stages[i];
    if (s.alive && s.seconds_since_sample <= params_.stage_timeout) alive_mask |= 1U << i;
  }
  const std::uint32_t all_alive = (1U << kStageCount) - 1U;
  const bool chain_healthy = alive_mask == all_alive;

  std::uint32_t active = 0;
  // A stage that dies after the chain was up is a fault; during start-up it only keeps us waiting.
  if (!chain_healthy && mode_ != Mode::starting) active |= kFaultStageSilent;
  if (in.sensors_valid && std::isfinite(in.trolley_position) &&
      (in.trolley_position < params_.trolley_min || in.trolley_position > params_.trolley_max)) {
    active |= kFaultTrolleyTravel;
  }
  if (std::fabs(in.trolley_voltage) > params_.voltage_limit + 1e-9 ||
      std::fabs(in.slew_voltage) > params_.voltage_limit + 1e-9) {
    active |= kFaultVoltage;
  }
  if (in.sensors_valid &&
      (std::fabs(in.swing_in_plane) > params_.max_swing || std::fabs(in.swing_out_of_plane) > params_.max_swing)) {
    active |= kFaultSwing;
  }
  if (in.nonfinite_seen) active |= kFaultNonFinite;
  if (in.emergency_stop_input || in.command == Command::emergency_stop) active |= kFaultEmergencyStop;
  if (in.sensor_writers > 1) active |= kFaultMultipleSensorWriters;

  newly_raised_ = active & ~previous_active_;
  fault_count_ += static_cast<std::uint32_t>(std::popcount(newly_raised_));
  previous_active_ = active;
  latched_ |= active;

  switch (in.command) {
    case Command::arm: armed_ = true; break;
    case Command::disarm: armed_ = false; break;
    case Command::reset:
      // A reset clears latched faults only when nothing is active and the chain is healthy.
      if (active == 0 && chain_healthy) latched_ = 0;
      break;
    case Command::emergency_stop:
    case Command::none: break;
  }

  if (latched_ & kFaultEmergencyStop) {
    mode_ = Mode::emergency_stop;
  } else if (latched_ != 0) {
    mode_ = Mode::fault;
  } else if (!chain_healthy) {
    mode_ = Mode::starting;
  } else if (armed_ || params_.arm_on_start) {
    if (mode_ == Mode::starting && params_.arm_on_start) armed_ = true;
    mode_ = armed_ ? (in.move_in_progress ? Mode::operating : Mode::ready) : Mode::standby;
  } else {
    mode_ = Mode::standby;
  }

  const bool enabled = mode_ == Mode::ready || mode_ == Mode::operating;
  out.mode = mode_;
  out.motion_enabled = enabled;
  out.brakes_released = enabled;
  out.active_faults = active;
  out.latched_faults = latched_;
  out.fault_count = fault_count_;
  out.stages_alive = alive_mask;
}

}  // namespace crane::supervisor
