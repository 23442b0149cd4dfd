#pragma once
// The actuation gate: the last safety check between the command chain and the drives, one piece
// of code for the simulated plant and the hardware bridge alike. One call per cycle turns the
// latest actuator command and supervisor status into what the drives get. Pure: no clock (the
// cycle instant and arrival times come in as [s] on one monotonic timeline), no I/O, no threads.
//
// Rules, checked in this order each cycle; the first that holds puts the drives in the safe state
// (0 V, 0 m/s, every brake engaged, drives disabled) and names the reason:
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
// current limit for that axis (and max_drive_voltage), the hoist speed as commanded, brakes
// released and drives enabled.
//
// Rule H (hold): what is applied at cycle instant t stays on the drives until the next cycle,
// t + T (T = sample_period). An input that arrived at time a may be used at t only if it is still
// within its timeout at the end of that hold:  (t - a) + T <= timeout + 1e-9.  Hence the drives
// never rest on an input older than its timeout, and the safe state comes at the first cycle
// instant t > a + timeout - T, which lies in (a + timeout - T, a + timeout]. At 100 Hz with
// watchdog_timeout = 30 ms, a command arriving exactly at cycle instant t_k is applied at t_k,
// t_k + 10 ms and t_k + 20 ms and replaced by the safe state at t_k + 30 ms. NaN times count as
// too old. In lockstep the timeline is simulated time (cycle k at k T) and every command and status
// of the cycle arrives at its instant: they are always fresh.
//
// Command validation (where the command enters): a command with a NaN/Inf field or arrival time is
// rejected (rejected_commands.non_finite); one with |voltage| > max_drive_voltage or |hoist_speed| >
// hoist_speed_limit is rejected (rejected_commands.out_of_range). A rejected command changes
// nothing: it does not refresh the watchdog, the last valid command stays in force.
//
// Errors: the constructor throws common::ConfigError naming the field, value and bound. step()
// never throws and never allocates.

#include <cstdint>

#include "crane/common/crane_signals.hpp"
#include "crane/common/stack_facts.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::supervisor {

struct ActuationGateParams {
  double sample_period{0.01};       // [s] T, time between step() calls, in (0, 1]
  double watchdog_timeout{0.030};   // [s] oldest command the drives may still be driven by, in [T, 1]
  double status_timeout{0.030};     // [s] oldest supervisor status motion may rest on, in [T, 1]
  double max_drive_voltage{10.0};   // [V] hard range of the drive commands, in (0, 1000]
  double hoist_speed_limit{0.5};    // [m/s] hard range of the hoist speed command, > 0
};

/// Throws common::ConfigError naming the field (prefixed by `prefix`), the value and the bound.
void validate(const ActuationGateParams& params, const char* prefix = "actuation");

/// Reads the `actuation:` block: watchdog_timeout, status_timeout [s] in [T, 1], hoist_speed_limit
/// [m/s] in [1e-3, 100]; T and the drive voltage limit from facts. Throws common::ConfigError.
[[nodiscard]] ActuationGateParams read_actuation_params(config::YamlSection& block, const common::StackFacts& facts);

/// What the gate uses of the supervisor's status (SupervisorStatus).
struct SupervisorPermit {
  bool motion_enabled{false};
  bool brakes_released{false};
  double trolley_voltage_limit{0.0};  // [V] current magnitude limit on the trolley drive, >= 0
  double slew_voltage_limit{0.0};     // [V] current magnitude limit on the slew drive, >= 0
  double bridge_voltage_limit{0.0};   // [V] current magnitude limit on the bridge drive (overhead crane), >= 0
};

struct GateInput {
  double time{0.0};                   // [s] this cycle instant t (monotonic timeline)
  bool command_received{false};       // a new actuator command arrived for this cycle
  common::DriveCommand command{};     // [V], [V], [m/s] valid only if command_received
  double command_arrival_time{0.0};   // [s] when `command` arrived
  bool status_received{false};        // a supervisor status was ever received; `status` is the latest
  SupervisorPermit status{};
  double status_arrival_time{0.0};    // [s] when `status` arrived
  bool emergency_stop_pressed{false}; // the emergency-stop input this cycle
};

/// Why the drives are in the safe state (none: the command is applied).
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
struct GateCounters {
  std::uint64_t cycles{0};
  std::uint64_t accepted_commands{0};
  RejectedCommandCounts rejected_commands{};
  std::uint64_t clamped_cycles{0};  // cycles whose applied command was limited (the bridge adds its DAC range)
  std::uint64_t safe_cycles{0};     // cycles in the safe state, any reason
  std::uint64_t watchdog_trips{0};  // entries into the watchdog safe state
  std::uint64_t emergency_stop_cycles{0};
};

struct GateOutput {
  SafeStateReason reason{SafeStateReason::no_command_yet};
  common::DriveCommand drive{};      // [V], [V], [m/s] to apply (0 in the safe state)
  bool brakes_engaged{true};         // = reason != none
  bool clamped{false};               // a drive voltage was limited by the supervisor's limit
  CommandStatus command_status{CommandStatus::none_received};
};

class ActuationGate {
 public:
  /// Throws common::ConfigError for invalid params.
  explicit ActuationGate(const ActuationGateParams& params);

  /// One cycle (rules in the file comment). Fills `output` completely. noexcept, no allocation.
  void step(const GateInput& input, GateOutput& output) noexcept;

  /// Forgets the last command, the latched emergency stop and the last reason (counters are kept).
  void reset() noexcept;

  [[nodiscard]] const GateCounters& counters() const noexcept { return counters_; }
  /// For the bridge, which clamps once more to its DAC range.
  void count_clamped() noexcept { ++counters_.clamped_cycles; }
  [[nodiscard]] const ActuationGateParams& params() const noexcept { return params_; }
  /// [s] arrival time of the last valid command (the watchdog's reference); 0 before the first.
  [[nodiscard]] double last_command_arrival() const noexcept { return last_command_arrival_; }

 private:
  [[nodiscard]] SafeStateReason safe_state_reason(const GateInput& input) const noexcept;
  [[nodiscard]] bool within_timeout(double now, double arrival, double timeout) const noexcept;

  ActuationGateParams params_;
  GateCounters counters_{};
  bool have_command_{false};
  common::DriveCommand last_command_{};
  double last_command_arrival_{0.0};  // [s]
  bool emergency_stop_latched_{false};
  double last_emergency_stop_time_{0.0};  // [s] last cycle with the input pressed
  SafeStateReason last_reason_{SafeStateReason::no_command_yet};
};

}  // namespace crane::supervisor

#include "crane/protocol/messages.hpp"

namespace crane::supervisor {

/// What the gate takes of a SupervisorStatus.
[[nodiscard]] inline SupervisorPermit permit_of(const protocol::SupervisorStatus& status) noexcept {
  return {status.motion_enabled, status.brakes_released, status.trolley_voltage_limit, status.slew_voltage_limit,
          status.bridge_voltage_limit};
}

/// The drive command an ActuatorCommand carries.
[[nodiscard]] inline common::DriveCommand drive_command_of(const protocol::ActuatorCommand& command) noexcept {
  return {command.trolley_voltage, command.slew_voltage, command.hoist_speed, command.bridge_voltage};
}

/// Lockstep (docs/architecture.md, "The 100 Hz cycle"), the one place of its rules for the plant,
/// the hardware bridge on the board's clock and the in-process runner:
///  - cycle k is gated by the supervisor's status of cycle gating_cycle(k) = k - 1 (cycle 0: of 0);
///  - it runs when that status and the actuator command of cycle k are both there, or when the
///    status reports a dead stage (stage_silent latched: the command will never come): braked;
///  - its timeline is simulated time, t = k T, and both arrived at t (they are the cycle's own).
[[nodiscard]] constexpr std::uint64_t gating_cycle(std::uint64_t cycle) noexcept { return cycle == 0 ? 0 : cycle - 1; }
[[nodiscard]] inline bool lockstep_may_run(bool have_command, const protocol::SupervisorStatus& gating) noexcept {
  return have_command || (gating.latched_faults & protocol::SupervisorStatus::FAULT_STAGE_SILENT) != 0;
}
/// The gate's input for lockstep cycle `cycle` (command nullptr: none, see lockstep_may_run).
[[nodiscard]] inline GateInput lockstep_gate_input(std::uint64_t cycle, double sample_period,
                                                   const protocol::ActuatorCommand* command,
                                                   const protocol::SupervisorStatus& gating,
                                                   bool emergency_stop_pressed = false) noexcept {
  GateInput in;
  in.time = static_cast<double>(cycle) * sample_period;
  in.command_received = command != nullptr;
  if (command != nullptr) in.command = drive_command_of(*command);
  in.command_arrival_time = in.time;
  in.status_received = true;
  in.status = permit_of(gating);
  in.status_arrival_time = in.time;
  in.emergency_stop_pressed = emergency_stop_pressed;
  return in;
}

}  // namespace crane::supervisor
