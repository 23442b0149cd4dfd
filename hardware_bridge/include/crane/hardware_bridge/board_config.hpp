#pragma once
// Configuration of the interface board: register width and, for a comedilib device, where each
// function sits (subdevice, channel, bit). A plain struct; the YAML loader fills it.
//
// The defaults describe a generic board (counters on subdevice 0, analog outputs on 1, digital
// outputs on 2, digital inputs on 3); set them from `comedi_board_info` of the real board. The
// emulated (shm) board uses only counter_bits: its registers use the logical layout of
// board_channels.hpp.
//
// `axes` (board_axes(crane.kind)) selects which channels exist: the slew's entries of the arrays
// below are used, validated and checked against the driver on a tower crane only, the bridge's on
// an overhead crane only (board_channels.hpp, uses()).

#include <array>

#include "crane/hardware_bridge/board_channels.hpp"

namespace crane::hardware_bridge {

/// One comedi channel: subdevice index and channel index within it.
struct ComediChannel {
  int subdevice{0};  // [-] comedi subdevice index, >= 0
  int channel{0};    // [-] channel within the subdevice, >= 0
};

struct BoardConfig {
  int counter_bits{24};  // [bit] width of the counter registers (they wrap), in [2, 32]
  /// The slew's channels are used on a tower crane, the bridge's (counter, analog output, brake
  /// line, runway limit switches) on an overhead crane; elsewhere they are ignored.
  BoardAxes axes{kTowerCraneAxes};

  /// Counter of each encoder, indexed by CounterChannel (some boards have one subdevice per counter).
  std::array<ComediChannel, kCounterCount> counters{{{0, 0}, {0, 1}, {0, 2}, {0, 3}, {0, 4}}};

  int analog_output_subdevice{1};  // [-] comedi subdevice of the analog outputs
  std::array<int, kAnalogOutputCount> analog_output_channels{0, 1, 2, 3};  // indexed by AnalogOutput, distinct
  int analog_output_range{0};      // [-] comedi range index used for every analog output, >= 0

  int digital_output_subdevice{2};  // [-] DO or DIO subdevice
  std::array<int, kDigitalOutputCount> digital_output_bits{0, 1, 2, 3, 4};  // [bit] indexed by DigitalOutput, 0..31, distinct
  int digital_input_subdevice{3};   // [-] DI or DIO subdevice (may equal digital_output_subdevice)
  std::array<int, kDigitalInputCount> digital_input_bits{0, 1, 2, 3, 4, 5, 6};  // [bit] indexed by DigitalInput, 0..31, distinct
  /// true: an input reads 0 when active (normally closed contacts: a broken wire reads as an
  /// emergency stop / a reached limit, the fail-safe wiring).
  bool digital_inputs_active_low{true};
};

/// Throws common::ConfigError naming the field (prefixed by `prefix`), the value and the bound, for
/// the channels the crane uses (axes):
/// counter_bits outside [2, 32]; a negative subdevice, channel or range index; a bit outside
/// [0, 31]; two analog outputs on the same channel; two counters on the same subdevice/channel; two
/// functions on the same digital bit (inputs and outputs sharing one subdevice included).
void validate(const BoardConfig& config, const char* prefix = "board");

}  // namespace crane::hardware_bridge
