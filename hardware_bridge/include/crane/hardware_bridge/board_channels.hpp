#pragma once
// Channels of the crane's interface board, as in the dissertation's lab setup (H. M. Omar, "Control
// of Gantry and Tower Cranes", Virginia Tech 2003, section 4.1): four quadrature encoder counters,
// three analog outputs and a few digital lines; an overhead (bridge) crane adds its bridge axis: a
// fifth counter, a fourth analog output, a brake line and two runway limit switches.
//
// The bridge's channels are the last of each kind, so a crane uses the first N of each
// (counter_count(), analog_output_count(), digital_output_count(), digital_input_count() of
// `bridge_axis`): every channel on an overhead crane (crane.kind: overhead), all but the bridge's
// on a tower or gantry crane, whose configuration has no bridge entries and whose board is never
// asked for them.
//
// Digital lines are exchanged with the Board as *logical* words: bit number = the enumerator's
// value, 1 = active (an output energized, an input pressed / a limit reached). Mapping to the
// physical bit numbers and the input polarity of a real board is the Board implementation's job
// (BoardConfig). Outputs are fail-safe: a 0 bit engages a brake / disables the drives, so the word
// 0 is the safe state.

#include <array>
#include <cstddef>
#include <cstdint>

namespace crane::hardware_bridge {

/// The encoder counters, in the order of every counter array of this library.
enum class CounterChannel : std::uint8_t {
  trolley_motor = 0,       // trolley motor encoder (leadscrew), position x
  slew_motor = 1,          // slew motor encoder (through the slew gear), angle gamma
  swing_in_plane = 2,      // swing encoder, phi
  swing_out_of_plane = 3,  // swing encoder, theta
  bridge_motor = 4,        // bridge motor encoder (overhead crane), position y
};
inline constexpr std::size_t kCounterCount = 5;

/// The analog outputs, in the order of BoardOutputs::dac_codes.
enum class AnalogOutput : std::uint8_t {
  trolley_drive = 0,  // trolley drive amplifier input [V]
  slew_drive = 1,     // slew drive amplifier input [V]
  hoist_speed = 2,    // hoist speed reference [V] (scaled by BridgeParams::hoist_speed_per_volt)
  bridge_drive = 3,   // bridge drive amplifier input [V] (overhead crane)
};
inline constexpr std::size_t kAnalogOutputCount = 4;

/// Digital outputs: logical bit numbers. 1 = energized; 0 = brake engaged / drives disabled.
enum class DigitalOutput : std::uint8_t {
  brake_release_trolley = 0,
  brake_release_slew = 1,
  brake_release_hoist = 2,
  drive_enable = 3,
  brake_release_bridge = 4,  // overhead crane
};
inline constexpr std::size_t kDigitalOutputCount = 5;

/// Digital inputs: logical bit numbers, 1 = active. The limit switches are laid out as
/// SensorSample_.limit_switches (idl/crane_msgs.idl: SWITCH_TROLLEY_MIN = 1 ... SWITCH_SLEW_MAX = 8,
/// SWITCH_BRIDGE_MIN = 32, SWITCH_BRIDGE_MAX = 64), so `word & kLimitSwitchMask` is that field; bit 4
/// (value 16) is the emergency stop, which that field leaves out.
enum class DigitalInput : std::uint8_t {
  trolley_min_limit = 0,
  trolley_max_limit = 1,
  slew_min_limit = 2,
  slew_max_limit = 3,
  emergency_stop = 4,  // emergency stop pressed
  bridge_min_limit = 5,  // overhead crane: runway end switches
  bridge_max_limit = 6,
};
inline constexpr std::size_t kDigitalInputCount = 7;
inline constexpr std::uint32_t kLimitSwitchMask = 0x6FU;

/// Position of a channel in the arrays of this library.
[[nodiscard]] constexpr std::size_t index(CounterChannel channel) noexcept { return static_cast<std::size_t>(channel); }
[[nodiscard]] constexpr std::size_t index(AnalogOutput channel) noexcept { return static_cast<std::size_t>(channel); }
[[nodiscard]] constexpr std::size_t index(DigitalOutput line) noexcept { return static_cast<std::size_t>(line); }
[[nodiscard]] constexpr std::size_t index(DigitalInput line) noexcept { return static_cast<std::size_t>(line); }

/// Mask of one line in a logical digital word.
[[nodiscard]] constexpr std::uint32_t bit(DigitalOutput line) noexcept { return 1U << static_cast<unsigned>(line); }
[[nodiscard]] constexpr std::uint32_t bit(DigitalInput line) noexcept { return 1U << static_cast<unsigned>(line); }

/// The channels of each kind a crane uses: the first N (the bridge's are the last of each kind).
[[nodiscard]] constexpr std::size_t counter_count(bool bridge_axis) noexcept {
  return bridge_axis ? kCounterCount : kCounterCount - 1;
}
[[nodiscard]] constexpr std::size_t analog_output_count(bool bridge_axis) noexcept {
  return bridge_axis ? kAnalogOutputCount : kAnalogOutputCount - 1;
}
[[nodiscard]] constexpr std::size_t digital_output_count(bool bridge_axis) noexcept {
  return bridge_axis ? kDigitalOutputCount : kDigitalOutputCount - 1;
}
[[nodiscard]] constexpr std::size_t digital_input_count(bool bridge_axis) noexcept {
  return bridge_axis ? kDigitalInputCount : kDigitalInputCount - 2;
}
static_assert(index(CounterChannel::bridge_motor) == kCounterCount - 1 &&
                  index(AnalogOutput::bridge_drive) == kAnalogOutputCount - 1 &&
                  index(DigitalOutput::brake_release_bridge) == kDigitalOutputCount - 1 &&
                  index(DigitalInput::bridge_min_limit) == kDigitalInputCount - 2 &&
                  index(DigitalInput::bridge_max_limit) == kDigitalInputCount - 1,
              "the bridge's channels are the last of each kind (counter_count() and the others rely on it)");

/// Every brake of the crane released and the drives enabled: the first digital_output_count(bridge_axis) bits.
[[nodiscard]] constexpr std::uint32_t all_outputs_energized(bool bridge_axis) noexcept {
  return (1U << digital_output_count(bridge_axis)) - 1U;
}
/// Mask of the defined bits of a logical input word.
inline constexpr std::uint32_t kAllInputsMask = (1U << kDigitalInputCount) - 1U;
static_assert(kLimitSwitchMask == (kAllInputsMask & ~bit(DigitalInput::emergency_stop)),
              "every input but the emergency stop is a limit switch");
/// The limit switches a crane has: kLimitSwitchMask without the bridge's on a crane without a bridge.
[[nodiscard]] constexpr std::uint32_t limit_switch_mask(bool bridge_axis) noexcept {
  return kLimitSwitchMask & ((1U << digital_input_count(bridge_axis)) - 1U);
}

/// snake_case names for messages ("trolley_motor", ...); "unknown" for an invalid value.
[[nodiscard]] const char* channel_name(CounterChannel channel) noexcept;
[[nodiscard]] const char* channel_name(AnalogOutput channel) noexcept;
[[nodiscard]] const char* line_name(DigitalOutput line) noexcept;
[[nodiscard]] const char* line_name(DigitalInput line) noexcept;

}  // namespace crane::hardware_bridge
