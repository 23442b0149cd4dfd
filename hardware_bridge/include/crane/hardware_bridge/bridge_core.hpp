#pragma once
// Output logic of the hardware bridge: one call per cycle turns the latest actuator command and
// supervisor status into the board outputs. The safety rules (emergency stop, stale status, motion
// disabled, no command, watchdog; command validation; clamping to the supervisor's limits) are the
// actuation gate's, supervisor/actuation_gate.hpp, which the simulated plant applies too: both
// behave the same under every fault. This adds what is the board's: the hoist speed converted to
// volts (hoist_speed / hoist_speed_per_volt), every output clamped to its DAC range and quantized,
// brakes released and drives enabled (all_outputs_energized(axes)), or the safe outputs (0 V on
// every analog output, every brake engaged, drives disabled: safe_outputs()). Only the crane's
// outputs are driven (BoardAxes): on a tower crane the slew's drive and brake line, on an overhead
// crane the bridge's (the gated bridge voltage to AnalogOutput::bridge_drive like the trolley's);
// an output the crane does not have stays at 0 V and its brake line at 0. Pure: no clock, no I/O,
// no threads.
//
// Errors: the constructor throws common::ConfigError naming the field, value and bound. step() and
// safe_outputs() never throw and never allocate.

#include <array>
#include <cstdint>

#include "crane/common/crane_signals.hpp"
#include "crane/hardware_bridge/board.hpp"
#include "crane/hardware_bridge/conversions.hpp"
#include "crane/supervisor/actuation_gate.hpp"

namespace crane::hardware_bridge {

struct BridgeParams {
  supervisor::ActuationGateParams gate{};  // the actuation gate (the `actuation:` block)
  double hoist_speed_per_volt{0.05};       // [m/s/V] hoist speed per volt of the hoist output, > 0
  BoardAxes axes{kTowerCraneAxes};         // the crane's axes: whose outputs and brake lines are driven
};

/// Throws common::ConfigError naming the field (the gate's prefixed "actuation", the rest by
/// `prefix`), the value and the bound.
void validate(const BridgeParams& params, const char* prefix = "hardware_bridge");

using supervisor::CommandStatus;
using supervisor::reason_name;
using supervisor::SafeStateReason;
using supervisor::SupervisorPermit;
using BridgeInput = supervisor::GateInput;
using BridgeCounters = supervisor::GateCounters;

struct BridgeOutput {
  BoardOutputs board{};               // write these this cycle
  SafeStateReason safe_state_reason{SafeStateReason::no_command_yet};
  bool clamped{false};                // the applied command was limited (supervisor limit or range)
  double applied_trolley_voltage{0.0};  // [V] the voltage of the code written
  double applied_slew_voltage{0.0};     // [V] (tower crane; 0 elsewhere)
  double applied_hoist_speed{0.0};      // [m/s] the hoist output's voltage times hoist_speed_per_volt
  double applied_bridge_voltage{0.0};   // [V] the voltage of the code written (overhead crane; 0 elsewhere)
  bool brakes_engaged{true};
  BridgeCounters counters{};
};

class BridgeCore {
 public:
  /// `ranges`: the board's analog output ranges (Board::analog_ranges()), indexed by AnalogOutput.
  /// Throws common::ConfigError for invalid params, or a range of a used output
  /// (uses(params.axes, ...)) that is not valid (is_valid) or does not contain 0 V (the safe
  /// output), naming the channel ("analog_range.slew_drive ..."). The range of an unused output
  /// (the bridge's on a tower crane) must be valid or default-constructed.
  BridgeCore(const BridgeParams& params, const std::array<AnalogRange, kAnalogOutputCount>& ranges);

  /// One cycle (rules in the file comment). Fills `output` completely. noexcept, no allocation.
  CommandStatus step(const BridgeInput& input, BridgeOutput& output) noexcept;

  /// 0 V on every output, every brake engaged, drives disabled; precomputed, for start-up, exit and
  /// signal handlers.
  [[nodiscard]] const BoardOutputs& safe_outputs() const noexcept { return safe_outputs_; }

  /// Forgets the last command, the latched emergency stop and the last reason (counters are kept).
  void reset() noexcept;

  [[nodiscard]] const BridgeCounters& counters() const noexcept { return gate_.counters(); }
  [[nodiscard]] const BridgeParams& params() const noexcept { return params_; }
  /// [s] arrival time of the last valid command, on the inputs' timeline (0 before the first).
  [[nodiscard]] double last_command_arrival() const noexcept { return gate_.last_command_arrival(); }

 private:
  BridgeParams params_;
  std::array<AnalogRange, kAnalogOutputCount> ranges_;
  BoardOutputs safe_outputs_;
  supervisor::ActuationGate gate_;
  supervisor::GateOutput gate_output_{};
};

}  // namespace crane::hardware_bridge
