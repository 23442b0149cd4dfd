#pragma once
// Output logic of the hardware bridge and its fail-safe watchdog: one call per cycle turns the
// latest actuator command and supervisor status into the board outputs. Pure: no clock (the cycle
// instant and arrival times come in as [s] on one monotonic timeline), no I/O, no threads.
//
// Rules, checked in this order each cycle; the first that holds puts the outputs in the safe state
// (0 V on every analog output, every brake engaged, drives disabled: safe_outputs()) and names
// the reason:
//   1. emergency_stop: the emergency-stop input is pressed this cycle (immediately). It stays latched
//      until a supervisor status permitting motion arrives more than one sample_period after the
//      last cycle the input was seen pressed (so that status was computed after the supervisor saw
//      the stop in the sensor sample; the supervisor itself latches it until a reset).
//   2. supervisor_status_stale: no status received yet, or the latest is too old (rule H below with
//      status_timeout), or it carries a non-finite or negative voltage limit.
//   3. motion_disabled: the latest status says motion disabled or brakes not released.
//   4. no_command_yet: no valid command since construction or reset().
//   5. watchdog: the last valid command is too old (rule H with watchdog_timeout).
// Otherwise the last valid command is applied: each drive voltage clamped to +- the supervisor's
// current limit for that axis, then to the hardware range of its output; the hoist speed converted
// to volts (hoist_speed / hoist_speed_per_volt) and clamped to its output's range; brakes released
// and drives enabled (kAllOutputsEnergized).
//
// Rule H (hold): outputs written at cycle instant t stay on the board until the next cycle, t + T
// (T = sample_period). An input that arrived at time a may be used at t only if it is still within
// its timeout at the end of that hold:  (t - a) + T <= timeout + 1e-9.  Hence, with cycles every T,
// outputs never rest on an input older than its timeout, and the safe state is written at the first
// cycle instant t > a + timeout - T, which lies in (a + timeout - T, a + timeout]. At 100 Hz with
// watchdog_timeout = 30 ms, a command arriving exactly at cycle instant t_k is applied at t_k,
// t_k + 10 ms and t_k + 20 ms and replaced by the safe outputs at t_k + 30 ms; one arriving 2 ms
// before t_k is replaced at t_k + 20 ms (22 ms after its arrival). A cycle that comes late writes
// the safe state at that late instant. NaN times count as too old.
//
// Command validation (where the command enters): a command with a NaN/Inf field or arrival time is
// rejected (rejected_commands.non_finite); one with |voltage| > max_drive_voltage or |hoist_speed| >
// hoist_speed_limit is rejected (rejected_commands.out_of_range). A rejected command changes
// nothing: it does not refresh the watchdog, the last valid command stays in force.
//
// Errors: the constructor throws common::ConfigError naming the field, value and bound. step() and
// safe_outputs() never throw and never allocate.

#include <array>
#include <cstdint>

#include "crane/common/crane_signals.hpp"
#include "crane/hardware_bridge/board.hpp"
#include "crane/hardware_bridge/conversions.hpp"

namespace crane::hardware_bridge {

struct BridgeParams {
  double sample_period{0.01};         // [s] T, time between step() calls, in (0, 1]
  double watchdog_timeout{0.030};     // [s] oldest command that may still be on the outputs, in [T, 1]
  double status_timeout{0.030};       // [s] oldest supervisor status motion may rest on, in [T, 1]
  double max_drive_voltage{10.0};     // [V] hard range of the drive commands, in (0, 1000]
  double hoist_speed_limit{0.5};      // [m/s] hard range of the hoist speed command, > 0
  double hoist_speed_per_volt{0.05};  // [m/s/V] hoist speed per volt of the hoist output, > 0
};

/// Throws common::ConfigError naming the field (prefixed by `prefix`), the value and the bound.
void validate(const BridgeParams& params, const char* prefix = "hardware_bridge");

/// What the bridge uses of the supervisor's status (SupervisorStatus_).
struct SupervisorPermit {
  bool motion_enabled{false};
  bool brakes_released{false};
  double trolley_voltage_limit{0.0};  // [V] current magnitude limit on the trolley drive, >= 0
  double slew_voltage_limit{0.0};     // [V] current magnitude limit on the slew drive, >= 0
};

struct BridgeInput {
  double time{0.0};                   // [s] this cycle instant t (monotonic timeline)
  bool command_received{false};       // a new actuator command arrived for this cycle
  common::DriveCommand command{};     // [V], [V], [m/s] valid only if command_received
  double command_arrival_time{0.0};   // [s] when `command` arrived
  bool status_received{false};        // a supervisor status was ever received; `status` is the latest
  SupervisorPermit status{};
  double status_arrival_time{0.0};    // [s] when `status` arrived
  bool emergency_stop_pressed{false}; // the board's emergency-stop input this cycle
};

/// Why the outputs are in the safe state (none: the command is applied).
enum class SafeStateReason : std::uint8_t {
  none = 0,
  no_command_yet = 1,
  watchdog = 2,
  supervisor_status_stale = 3,
  motion_disabled = 4,
  emergency_stop = 5,
};
[[nodiscard]] const char* reason_name(SafeStateReason reason) noexcept;

/// What happened to this cycle's command.
enum class [[nodiscard]] CommandStatus : std::uint8_t {
  none_received = 0,
  accepted = 1,
  rejected_non_finite = 2,
  rejected_out_of_range = 3,
};

struct RejectedCommandCounts {
  std::uint64_t non_finite{0};    // a NaN/Inf field or arrival time
  std::uint64_t out_of_range{0};  // |voltage| > max_drive_voltage or |hoist_speed| > hoist_speed_limit
};

/// Since construction (reset() keeps them).
struct BridgeCounters {
  std::uint64_t cycles{0};
  std::uint64_t accepted_commands{0};
  RejectedCommandCounts rejected_commands{};
  std::uint64_t clamped_cycles{0};  // cycles whose applied command was limited
  std::uint64_t safe_cycles{0};     // cycles with safe outputs, any reason
  std::uint64_t watchdog_trips{0};  // entries into the watchdog safe state
  std::uint64_t emergency_stop_cycles{0};
};

struct BridgeOutput {
  BoardOutputs board{};               // write these this cycle
  SafeStateReason safe_state_reason{SafeStateReason::no_command_yet};
  bool clamped{false};                // the applied command was limited (supervisor limit or range)
  double applied_trolley_voltage{0.0};  // [V] the voltage of the code written
  double applied_slew_voltage{0.0};     // [V]
  double applied_hoist_speed{0.0};      // [m/s] the hoist output's voltage times hoist_speed_per_volt
  bool brakes_engaged{true};
  BridgeCounters counters{};
};

class BridgeCore {
 public:
  /// `ranges`: the board's analog output ranges (Board::analog_ranges()), indexed by AnalogOutput.
  /// Throws common::ConfigError for invalid params, or a range that is not valid (is_valid) or
  /// does not contain 0 V (the safe output), naming the channel ("analog_range.slew_drive ...").
  BridgeCore(const BridgeParams& params, const std::array<AnalogRange, kAnalogOutputCount>& ranges);

  /// One cycle (rules in the file comment). Fills `output` completely. noexcept, no allocation.
  CommandStatus step(const BridgeInput& input, BridgeOutput& output) noexcept;

  /// 0 V on every output, every brake engaged, drives disabled; precomputed, for start-up, exit and
  /// signal handlers.
  [[nodiscard]] const BoardOutputs& safe_outputs() const noexcept { return safe_outputs_; }

  /// Forgets the last command, the latched emergency stop and the last reason (counters are kept).
  void reset() noexcept;

  [[nodiscard]] const BridgeCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] const BridgeParams& params() const noexcept { return params_; }

 private:
  [[nodiscard]] SafeStateReason safe_state_reason(const BridgeInput& input) const noexcept;
  [[nodiscard]] bool within_timeout(double now, double arrival, double timeout) const noexcept;

  BridgeParams params_;
  std::array<AnalogRange, kAnalogOutputCount> ranges_;
  BoardOutputs safe_outputs_;
  BridgeCounters counters_{};
  bool have_command_{false};
  common::DriveCommand last_command_{};
  double last_command_arrival_{0.0};  // [s]
  bool emergency_stop_latched_{false};
  double last_emergency_stop_time_{0.0};  // [s] last cycle with the input pressed
  SafeStateReason last_reason_{SafeStateReason::no_command_yet};
};

}  // namespace crane::hardware_bridge
