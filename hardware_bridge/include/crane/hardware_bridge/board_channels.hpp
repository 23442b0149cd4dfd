#pragma once
// Channels of the crane's interface board, as in the dissertation's lab setup (H. M. Omar, "Control
// of Gantry and Tower Cranes", Virginia Tech 2003, section 4.1): four quadrature encoder counters,
// three analog outputs and a few digital lines.
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

/// The four encoder counters, in the order of every counter array of this library.
enum class CounterChannel : std::uint8_t {
  trolley_motor = 0,       // trolley motor encoder (leadscrew), position x
  slew_motor = 1,          // slew motor encoder (through the slew gear), angle gamma
  swing_in_plane = 2,      // swing encoder, phi
  swing_out_of_plane = 3,  // swing encoder, theta
};
inline constexpr std::size_t kCounterCount = 4;

/// The three analog outputs, in the order of BoardOutputs::dac_codes.
enum class AnalogOutput : std::uint8_t {
  trolley_drive = 0,  // trolley drive amplifier input [V]
  slew_drive = 1,     // slew drive amplifier input [V]
  hoist_speed = 2,    // hoist speed reference [V] (scaled by BridgeParams::hoist_speed_per_volt)
};
inline constexpr std::size_t kAnalogOutputCount = 3;

/// Digital outputs: logical bit numbers. 1 = energized; 0 = brake engaged / drives disabled.
enum class DigitalOutput : std::uint8_t {
  brake_release_trolley = 0,
  brake_release_slew = 1,
  brake_release_hoist = 2,
  drive_enable = 3,
};
inline constexpr std::size_t kDigitalOutputCount = 4;

/// Digital inputs: logical bit numbers, 1 = active. Bits 0..3 are laid out as
/// SensorSample_.limit_switches (idl/crane_msgs.idl), so `word & kLimitSwitchMask` is that field.
enum class DigitalInput : std::uint8_t {
  trolley_min_limit = 0,
  trolley_max_limit = 1,
  slew_min_limit = 2,
  slew_max_limit = 3,
  emergency_stop = 4,  // emergency stop pressed
};
inline constexpr std::size_t kDigitalInputCount = 5;
inline constexpr std::uint32_t kLimitSwitchMask = 0x0FU;

/// Position of a channel in the arrays of this library.
[[nodiscard]] constexpr std::size_t index(CounterChannel channel) noexcept { return static_cast<std::size_t>(channel); }
[[nodiscard]] constexpr std::size_t index(AnalogOutput channel) noexcept { return static_cast<std::size_t>(channel); }
[[nodiscard]] constexpr std::size_t index(DigitalOutput line) noexcept { return static_cast<std::size_t>(line); }
[[nodiscard]] constexpr std::size_t index(DigitalInput line) noexcept { return static_cast<std::size_t>(line); }

/// Mask of one line in a logical digital word.
[[nodiscard]] constexpr std::uint32_t bit(DigitalOutput line) noexcept { return 1U << static_cast<unsigned>(line); }
[[nodiscard]] constexpr std::uint32_t bit(DigitalInput line) noexcept { return 1U << static_cast<unsigned>(line); }

/// Every brake released and the drives enabled.
inline constexpr std::uint32_t kAllOutputsEnergized = bit(DigitalOutput::brake_release_trolley) |
                                                      bit(DigitalOutput::brake_release_slew) |
                                                      bit(DigitalOutput::brake_release_hoist) |
                                                      bit(DigitalOutput::drive_enable);
/// Mask of the defined bits of a logical input word.
inline constexpr std::uint32_t kAllInputsMask = (1U << kDigitalInputCount) - 1U;

/// snake_case names for messages ("trolley_motor", ...); "unknown" for an invalid value.
[[nodiscard]] const char* channel_name(CounterChannel channel) noexcept;
[[nodiscard]] const char* channel_name(AnalogOutput channel) noexcept;
[[nodiscard]] const char* line_name(DigitalOutput line) noexcept;
[[nodiscard]] const char* line_name(DigitalInput line) noexcept;

}  // namespace crane::hardware_bridge
