#include "crane/hardware_bridge/bridge_core.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::hardware_bridge {

namespace {

// Tolerance of the hold rule against rounding of cycle instants (k * T in floating point).
constexpr double kTimeTolerance = 1e-9;  // [s]

std::string field(const char* prefix, const char* name) { return std::string(prefix) + "." + name; }

bool finite_permit(const SupervisorPermit& status) noexcept {
  return std::isfinite(status.trolley_voltage_limit) && std::isfinite(status.slew_voltage_limit) &&
         status.trolley_voltage_limit >= 0.0 && status.slew_voltage_limit >= 0.0;
}

bool permits_motion(const SupervisorPermit& status) noexcept { return status.motion_enabled && status.brakes_released; }

}  // namespace

void validate(const BridgeParams& params, const char* prefix) {
  common::require_greater(field(prefix, "sample_period"), params.sample_period, 0.0);
  common::require_in_range(field(prefix, "sample_period"), params.sample_period, 0.0, 1.0);
  common::require_in_range(field(prefix, "watchdog_timeout"), params.watchdog_timeout, params.sample_period, 1.0);
  common::require_in_range(field(prefix, "status_timeout"), params.status_timeout, params.sample_period, 1.0);
  common::require_greater(field(prefix, "max_drive_voltage"), params.max_drive_voltage, 0.0);
  common::require_in_range(field(prefix, "max_drive_voltage"), params.max_drive_voltage, 0.0, 1000.0);
  common::require_greater(field(prefix, "hoist_speed_limit"), params.hoist_speed_limit, 0.0);
  common::require_greater(field(prefix, "hoist_speed_per_volt"), params.hoist_speed_per_volt, 0.0);
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

BridgeCore::BridgeCore(const BridgeParams& params, const std::array<AnalogRange, kAnalogOutputCount>& ranges)
    : params_(params), ranges_(ranges) {
  validate(params_);
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    const AnalogRange& range = ranges_[i];
    const std::string name = std::string("analog_range.") + channel_name(static_cast<AnalogOutput>(i));
    if (!is_valid(range)) {
      throw common::ConfigError(name + " = [" + common::format_value(range.min_volts) + ", " +
                                common::format_value(range.max_volts) + "] V, maxdata " +
                                std::to_string(range.maxdata) +
                                " is out of range: must be finite with min_volts < max_volts and maxdata > 0");
    }
    common::require_at_least(name + ".max_volts", range.max_volts, 0.0);  // 0 V, the safe output, must be a code
    if (range.min_volts > 0.0) {
      throw common::ConfigError(name + ".min_volts = " + common::format_value(range.min_volts) +
                                " is out of range: must be <= 0");
    }
  }
  safe_outputs_ = safe_board_outputs(ranges_);
}

void BridgeCore::reset() noexcept {
  have_command_ = false;
  last_command_ = common::DriveCommand{};
  last_command_arrival_ = 0.0;
  emergency_stop_latched_ = false;
  last_emergency_stop_time_ = 0.0;
  last_reason_ = SafeStateReason::no_command_yet;
}

bool BridgeCore::within_timeout(double now, double arrival, double timeout) const noexcept {
  // Rule H: still within `timeout` at the end of the hold, now + T. Written so that NaN is "too old".
  return (now - arrival) + params_.sample_period <= timeout + kTimeTolerance;
}

SafeStateReason BridgeCore::safe_state_reason(const BridgeInput& input) const noexcept {
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

CommandStatus BridgeCore::step(const BridgeInput& input, BridgeOutput& output) noexcept {
  ++counters_.cycles;

  // 1. Validate the command where it enters.
  CommandStatus status = CommandStatus::none_received;
  if (input.command_received) {
    const common::DriveCommand& command = input.command;
    if (!std::isfinite(command.trolley_voltage) || !std::isfinite(command.slew_voltage) ||
        !std::isfinite(command.hoist_speed) || !std::isfinite(input.command_arrival_time)) {
      status = CommandStatus::rejected_non_finite;
      ++counters_.rejected_commands.non_finite;
    } else if (std::abs(command.trolley_voltage) > params_.max_drive_voltage ||
               std::abs(command.slew_voltage) > params_.max_drive_voltage ||
               std::abs(command.hoist_speed) > params_.hoist_speed_limit) {
      status = CommandStatus::rejected_out_of_range;
      ++counters_.rejected_commands.out_of_range;
    } else {
      status = CommandStatus::accepted;
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
  output.safe_state_reason = reason;
  output.clamped = false;
  if (reason == SafeStateReason::none) {
    const double trolley_limit = std::min(input.status.trolley_voltage_limit, params_.max_drive_voltage);
    const double slew_limit = std::min(input.status.slew_voltage_limit, params_.max_drive_voltage);
    const double trolley = std::clamp(last_command_.trolley_voltage, -trolley_limit, trolley_limit);
    const double slew = std::clamp(last_command_.slew_voltage, -slew_limit, slew_limit);
    const double hoist = last_command_.hoist_speed / params_.hoist_speed_per_volt;  // [V]
    const std::array<double, kAnalogOutputCount> volts{trolley, slew, hoist};
    bool clamped = trolley != last_command_.trolley_voltage || slew != last_command_.slew_voltage;
    for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
      clamped = clamped || volts[i] < ranges_[i].min_volts || volts[i] > ranges_[i].max_volts;
      output.board.dac_codes[i] = volts_to_code(volts[i], ranges_[i]);
    }
    output.board.digital_outputs = kAllOutputsEnergized;
    output.clamped = clamped;
    output.brakes_engaged = false;
    if (clamped) ++counters_.clamped_cycles;
  } else {
    output.board = safe_outputs_;
    output.brakes_engaged = true;
    ++counters_.safe_cycles;
    if (reason == SafeStateReason::watchdog && last_reason_ != SafeStateReason::watchdog) ++counters_.watchdog_trips;
    if (reason == SafeStateReason::emergency_stop) ++counters_.emergency_stop_cycles;
  }
  last_reason_ = reason;

  output.applied_trolley_voltage =
      code_to_volts(output.board.dac_codes[index(AnalogOutput::trolley_drive)], ranges_[index(AnalogOutput::trolley_drive)]);
  output.applied_slew_voltage =
      code_to_volts(output.board.dac_codes[index(AnalogOutput::slew_drive)], ranges_[index(AnalogOutput::slew_drive)]);
  output.applied_hoist_speed =
      code_to_volts(output.board.dac_codes[index(AnalogOutput::hoist_speed)], ranges_[index(AnalogOutput::hoist_speed)]) *
      params_.hoist_speed_per_volt;
  output.counters = counters_;
  return status;
}

}  // namespace crane::hardware_bridge
