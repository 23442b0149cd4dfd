#include "crane/supervisor/actuation_gate.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::supervisor {

namespace {

// Tolerance of the hold rule against rounding of cycle instants (k * T in floating point).
constexpr double kTimeTolerance = 1e-9;  // [s]

std::string field(const char* prefix, const char* name) { return std::string(prefix) + "." + name; }

bool finite_permit(const SupervisorPermit& status) noexcept {
  return std::isfinite(status.trolley_voltage_limit) && std::isfinite(status.slew_voltage_limit) &&
         std::isfinite(status.bridge_voltage_limit) && status.trolley_voltage_limit >= 0.0 &&
         status.slew_voltage_limit >= 0.0 && status.bridge_voltage_limit >= 0.0;
}

bool permits_motion(const SupervisorPermit& status) noexcept { return status.motion_enabled && status.brakes_released; }

}  // namespace

void validate(const ActuationGateParams& params, const char* prefix) {
  common::require_greater(field(prefix, "sample_period"), params.sample_period, 0.0);
  common::require_in_range(field(prefix, "sample_period"), params.sample_period, 0.0, 1.0);
  common::require_in_range(field(prefix, "watchdog_timeout"), params.watchdog_timeout, params.sample_period, 1.0);
  common::require_in_range(field(prefix, "status_timeout"), params.status_timeout, params.sample_period, 1.0);
  common::require_greater(field(prefix, "max_drive_voltage"), params.max_drive_voltage, 0.0);
  common::require_in_range(field(prefix, "max_drive_voltage"), params.max_drive_voltage, 0.0, 1000.0);
  common::require_greater(field(prefix, "hoist_speed_limit"), params.hoist_speed_limit, 0.0);
}

const char* reason_name(SafeStateReason reason) noexcept {
  switch (reason) {
    case SafeStateReason::none: return "none";
    case SafeStateReason::no_command_yet: return "no_command_yet";
    case SafeStateReason::watchdog: return "watchdog";
    case SafeStateReason::supervisor_status_stale: return "supervisor_status_stale";
    case SafeStateReason::motion_disabled: return "motion_disabled";
    case SafeStateReason::emergency_stop: return "emergency_stop";
  }
  return "unknown";
}

ActuationGate::ActuationGate(const ActuationGateParams& params) : params_(params) { validate(params_); }

void ActuationGate::reset() noexcept {
  have_command_ = false;
  last_command_ = common::DriveCommand{};
  last_command_arrival_ = 0.0;
  emergency_stop_latched_ = false;
  last_emergency_stop_time_ = 0.0;
  last_reason_ = SafeStateReason::no_command_yet;
}

bool ActuationGate::within_timeout(double now, double arrival, double timeout) const noexcept {
  // Rule H: still within `timeout` at the end of the hold, now + T. Written so that NaN is "too old".
  return (now - arrival) + params_.sample_period <= timeout + kTimeTolerance;
}

SafeStateReason ActuationGate::safe_state_reason(const GateInput& input) const noexcept {
  if (emergency_stop_latched_) return SafeStateReason::emergency_stop;
  if (!input.status_received || !finite_permit(input.status) ||
      !within_timeout(input.time, input.status_arrival_time, params_.status_timeout)) {
    return SafeStateReason::supervisor_status_stale;
  }
  if (!permits_motion(input.status)) return SafeStateReason::motion_disabled;
  if (!have_command_) return SafeStateReason::no_command_yet;
  if (!within_timeout(input.time, last_command_arrival_, params_.watchdog_timeout)) return SafeStateReason::watchdog;
  return SafeStateReason::none;
}

void ActuationGate::step(const GateInput& input, GateOutput& output) noexcept {
  ++counters_.cycles;

  // 1. Validate the command where it enters.
  output.command_status = CommandStatus::none_received;
  if (input.command_received) {
    const common::DriveCommand& command = input.command;
    if (!std::isfinite(command.trolley_voltage) || !std::isfinite(command.slew_voltage) ||
        !std::isfinite(command.bridge_voltage) || !std::isfinite(command.hoist_speed) ||
        !std::isfinite(input.command_arrival_time)) {
      output.command_status = CommandStatus::rejected_non_finite;
      ++counters_.rejected_commands.non_finite;
    } else if (std::abs(command.trolley_voltage) > params_.max_drive_voltage ||
               std::abs(command.slew_voltage) > params_.max_drive_voltage ||
               std::abs(command.bridge_voltage) > params_.max_drive_voltage ||
               std::abs(command.hoist_speed) > params_.hoist_speed_limit) {
      output.command_status = CommandStatus::rejected_out_of_range;
      ++counters_.rejected_commands.out_of_range;
    } else {
      output.command_status = CommandStatus::accepted;
      ++counters_.accepted_commands;
      have_command_ = true;
      last_command_ = command;
      last_command_arrival_ = input.command_arrival_time;
    }
  }

  // 2. Emergency stop: immediate; released by a permitting status computed after the stop was seen.
  if (input.emergency_stop_pressed) {
    emergency_stop_latched_ = true;
    last_emergency_stop_time_ = input.time;
  } else if (emergency_stop_latched_ && input.status_received && permits_motion(input.status) &&
             input.status_arrival_time > last_emergency_stop_time_ + params_.sample_period) {
    emergency_stop_latched_ = false;
  }

  // 3. Safe state or the (clamped) command.
  const SafeStateReason reason = safe_state_reason(input);
  output.reason = reason;
  output.clamped = false;
  if (reason == SafeStateReason::none) {
    const double trolley_limit = std::min(input.status.trolley_voltage_limit, params_.max_drive_voltage);
    const double slew_limit = std::min(input.status.slew_voltage_limit, params_.max_drive_voltage);
    const double bridge_limit = std::min(input.status.bridge_voltage_limit, params_.max_drive_voltage);
    output.drive.trolley_voltage = std::clamp(last_command_.trolley_voltage, -trolley_limit, trolley_limit);
    output.drive.slew_voltage = std::clamp(last_command_.slew_voltage, -slew_limit, slew_limit);
    output.drive.bridge_voltage = std::clamp(last_command_.bridge_voltage, -bridge_limit, bridge_limit);
    output.drive.hoist_speed = last_command_.hoist_speed;
    output.clamped = output.drive.trolley_voltage != last_command_.trolley_voltage ||
                     output.drive.slew_voltage != last_command_.slew_voltage ||
                     output.drive.bridge_voltage != last_command_.bridge_voltage;
    output.brakes_engaged = false;
    if (output.clamped) ++counters_.clamped_cycles;
  } else {
    output.drive = common::DriveCommand{};
    output.brakes_engaged = true;
    ++counters_.safe_cycles;
    if (reason == SafeStateReason::watchdog && last_reason_ != SafeStateReason::watchdog) ++counters_.watchdog_trips;
    if (reason == SafeStateReason::emergency_stop) ++counters_.emergency_stop_cycles;
  }
  last_reason_ = reason;
}

}  // namespace crane::supervisor
