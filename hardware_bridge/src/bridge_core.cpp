#include "crane/hardware_bridge/bridge_core.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::hardware_bridge {

void validate(const BridgeParams& params, const char* prefix) {
  supervisor::validate(params.gate, "actuation");
  common::require_greater(std::string(prefix) + ".hoist_speed_per_volt", params.hoist_speed_per_volt, 0.0);
}

BridgeCore::BridgeCore(const BridgeParams& params, const std::array<AnalogRange, kAnalogOutputCount>& ranges)
    : params_(params), ranges_(ranges), gate_((validate(params), params.gate)) {
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    if (!uses(params_.axes, static_cast<AnalogOutput>(i))) continue;
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

void BridgeCore::reset() noexcept { gate_.reset(); }

CommandStatus BridgeCore::step(const BridgeInput& input, BridgeOutput& output) noexcept {
  gate_.step(input, gate_output_);
  const SafeStateReason reason = gate_output_.reason;
  output.safe_state_reason = reason;
  output.clamped = false;
  if (reason == SafeStateReason::none) {
    const common::DriveCommand& drive = gate_output_.drive;
    const double hoist = drive.hoist_speed / params_.hoist_speed_per_volt;  // [V]
    const std::array<double, kAnalogOutputCount> volts{drive.trolley_voltage, drive.slew_voltage, hoist,
                                                       drive.bridge_voltage};
    output.board = safe_outputs_;  // an output the crane does not use stays at 0 V
    bool range_clamped = false;
    for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
      if (!uses(params_.axes, static_cast<AnalogOutput>(i))) continue;
      range_clamped = range_clamped || volts[i] < ranges_[i].min_volts || volts[i] > ranges_[i].max_volts;
      output.board.dac_codes[i] = volts_to_code(volts[i], ranges_[i]);
    }
    output.board.digital_outputs = all_outputs_energized(params_.axes);
    output.clamped = gate_output_.clamped || range_clamped;
    output.brakes_engaged = false;
    if (range_clamped && !gate_output_.clamped) gate_.count_clamped();
  } else {
    output.board = safe_outputs_;
    output.brakes_engaged = true;
  }
  output.applied_trolley_voltage =
      code_to_volts(output.board.dac_codes[index(AnalogOutput::trolley_drive)], ranges_[index(AnalogOutput::trolley_drive)]);
  output.applied_slew_voltage =
      params_.axes.slew ? code_to_volts(output.board.dac_codes[index(AnalogOutput::slew_drive)],
                                        ranges_[index(AnalogOutput::slew_drive)])
                        : 0.0;
  output.applied_hoist_speed =
      code_to_volts(output.board.dac_codes[index(AnalogOutput::hoist_speed)], ranges_[index(AnalogOutput::hoist_speed)]) *
      params_.hoist_speed_per_volt;
  output.applied_bridge_voltage =
      params_.axes.bridge ? code_to_volts(output.board.dac_codes[index(AnalogOutput::bridge_drive)],
                                          ranges_[index(AnalogOutput::bridge_drive)])
                          : 0.0;
  output.counters = gate_.counters();
  return gate_output_.command_status;
}

}  // namespace crane::hardware_bridge
