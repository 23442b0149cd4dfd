#pragma once
// Channels of the crane's interface board, as in the dissertation's lab setup (H. M. Omar, "Control
// of Gantry and Tower Cranes", Virginia Tech 2003, section 4.1): quadrature encoder counters,
// analog outputs and a few digital lines. Every crane has the trolley's counter, drive, brake line
// and limit switches, the two swing encoders, the hoist's output and brake line, the drive enable
// and the emergency stop; a tower crane adds its slew's (counter, drive, brake line, limit
// switches), an overhead (bridge) crane its bridge's (counter, drive, brake line, runway limit
// switches), a gantry crane neither (BoardAxes, one per crane.kind: board_axes() of
// bridge_config.hpp). The configuration of a crane names exactly its channels; the board is never
// asked for the others (uses()).
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

/// The axes beside the trolley, the swings and the hoist whose channels a crane's board has.
struct BoardAxes {
  bool slew{true};     // tower crane: the slew's counter, drive, brake line and limit switches
  bool bridge{false};  // overhead crane: the bridge's counter, drive, brake line and runway limit switches
  friend constexpr bool operator==(BoardAxes, BoardAxes) = default;
};
inline constexpr BoardAxes kTowerCraneAxes{true, false};
inline constexpr BoardAxes kGantryCraneAxes{false, false};
inline constexpr BoardAxes kOverheadCraneAxes{false, true};

/// Whether a crane with `axes` has the channel (the board is asked for it, the configuration names it).
[[nodiscard]] constexpr bool uses(BoardAxes axes, CounterChannel channel) noexcept {
  return channel == CounterChannel::slew_motor ? axes.slew : channel == CounterChannel::bridge_motor ? axes.bridge : true;
}
[[nodiscard]] constexpr bool uses(BoardAxes axes, AnalogOutput channel) noexcept {
  return channel == AnalogOutput::slew_drive ? axes.slew : channel == AnalogOutput::bridge_drive ? axes.bridge : true;
}
[[nodiscard]] constexpr bool uses(BoardAxes axes, DigitalOutput line) noexcept {
  return line == DigitalOutput::brake_release_slew     ? axes.slew
         : line == DigitalOutput::brake_release_bridge ? axes.bridge
                                                       : true;
}
[[nodiscard]] constexpr bool uses(BoardAxes axes, DigitalInput line) noexcept {
  return line == DigitalInput::slew_min_limit || line == DigitalInput::slew_max_limit       ? axes.slew
         : line == DigitalInput::bridge_min_limit || line == DigitalInput::bridge_max_limit ? axes.bridge
                                                                                             : true;
}

/// Every brake of the crane released and the drives enabled: the bits of the output lines it uses.
[[nodiscard]] constexpr std::uint32_t all_outputs_energized(BoardAxes axes) noexcept {
  std::uint32_t word = 0;
  for (std::size_t i = 0; i < kDigitalOutputCount; ++i) {
    if (uses(axes, static_cast<DigitalOutput>(i))) word |= 1U << i;
  }
  return word;
}
/// The brake lines of the crane's travel axes (trolley, slew, bridge: the hoist's is its own).
[[nodiscard]] constexpr std::uint32_t travel_brake_lines(BoardAxes axes) noexcept {
  return all_outputs_energized(axes) & ~(bit(DigitalOutput::brake_release_hoist) | bit(DigitalOutput::drive_enable));
}
/// Mask of the defined bits of a logical input word.
inline constexpr std::uint32_t kAllInputsMask = (1U << kDigitalInputCount) - 1U;
static_assert(kLimitSwitchMask == (kAllInputsMask & ~bit(DigitalInput::emergency_stop)),
              "every input but the emergency stop is a limit switch");
/// The limit switches a crane has: kLimitSwitchMask without the slew's or the bridge's where it has none.
[[nodiscard]] constexpr std::uint32_t limit_switch_mask(BoardAxes axes) noexcept {
  std::uint32_t mask = 0;
  for (std::size_t i = 0; i < kDigitalInputCount; ++i) {
    if (uses(axes, static_cast<DigitalInput>(i))) mask |= 1U << i;
  }
  return mask & kLimitSwitchMask;
}

/// snake_case names for messages ("trolley_motor", ...); "unknown" for an invalid value.
[[nodiscard]] const char* channel_name(CounterChannel channel) noexcept;
[[nodiscard]] const char* channel_name(AnalogOutput channel) noexcept;
[[nodiscard]] const char* line_name(DigitalOutput line) noexcept;
[[nodiscard]] const char* line_name(DigitalInput line) noexcept;

}  // namespace crane::hardware_bridge
