#pragma once
// The crane's encoder/DAC/digital-IO interface board (H. M. Omar, "Control of Gantry and Tower
// Cranes", Virginia Tech 2003, section 4.1), behind one abstract interface:
//   - 5 encoder counters (CounterChannel; the fifth is the overhead crane's bridge), raw registers
//     counter_bits wide that wrap;
//   - 4 analog outputs (AnalogOutput; the fourth is the bridge's) written as unsigned DAC codes
//     0..maxdata over the range the driver reports (conversions.hpp converts volts <-> codes);
//   - digital outputs and inputs as logical words (board_channels.hpp): 1 = energized / active.
// A Board converts nothing: codes in, raw counts out. Implementations: ComediBoard (comedilib
// device, comedi_board.hpp) and ShmBoard (the emulated board in shared memory, shm_board.hpp).
//
// Opening a board writes nothing to it: the caller writes safe outputs (BridgeCore::safe_outputs()
// or safe_board_outputs()) right after opening, and again on exit and from its signal handlers.
//
// Errors: any driver or device failure throws BoardError, whose message names the device, the
// subdevice/channel (or shared-memory segment) and the driver's message. The node treats it as
// fatal (safe outputs, exit). A Board is used from one thread; it is not copyable.

#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <string>

#include "crane/hardware_bridge/board_channels.hpp"
#include "crane/hardware_bridge/board_config.hpp"
#include "crane/hardware_bridge/conversions.hpp"

namespace crane::hardware_bridge {

/// A device or driver failure (missing device or segment, failed read/write, a configured
/// subdevice/channel the driver does not have).
class BoardError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Everything written to the board in one write_outputs() call.
struct BoardOutputs {
  /// [code] DAC code of each analog output, indexed by AnalogOutput, 0..maxdata of that channel's
  /// AnalogRange. CAUTION: code 0 is min_volts (-10 V on a bipolar board), not 0 V; start from
  /// safe_board_outputs() rather than a default-constructed value.
  std::array<std::uint32_t, kAnalogOutputCount> dac_codes{};
  /// Logical digital output word, bit(DigitalOutput) set = energized; 0 = all brakes engaged and
  /// the drives disabled (the safe state).
  std::uint32_t digital_outputs{0};

  friend bool operator==(const BoardOutputs&, const BoardOutputs&) = default;
};

class Board {
 public:
  Board() = default;
  Board(const Board&) = delete;
  Board& operator=(const Board&) = delete;
  virtual ~Board() = default;

  /// Reads the counter registers, indexed by CounterChannel, each masked to counter_bits()
  /// (they wrap; CounterUnwrapper makes them continuous). Throws BoardError.
  virtual void read_counters(std::array<std::uint32_t, kCounterCount>& raw_counts) = 0;

  /// Writes the DAC codes and the digital output word together. Codes above the channel's
  /// maxdata are clamped to maxdata. Throws BoardError.
  virtual void write_outputs(const BoardOutputs& outputs) = 0;

  /// Logical digital input word: bit(DigitalInput) set = active (after the polarity of
  /// BoardConfig::digital_inputs_active_low); bits above kDigitalInputCount are 0. Throws BoardError.
  [[nodiscard]] virtual std::uint32_t read_digital_inputs() = 0;

  /// [bit] width of the counter registers.
  [[nodiscard]] virtual int counter_bits() const noexcept = 0;

  /// Range and maxdata of one analog output as the driver reported them at open. noexcept.
  [[nodiscard]] virtual AnalogRange analog_range(AnalogOutput channel) const noexcept = 0;

  /// One line for logs: the URI, the device and its channel map.
  [[nodiscard]] virtual std::string describe() const = 0;

  /// The ranges, indexed by AnalogOutput.
  [[nodiscard]] std::array<AnalogRange, kAnalogOutputCount> analog_ranges() const noexcept;
};

/// 0 V on each analog output (volts_to_code(0, range)) and every digital output 0.
[[nodiscard]] BoardOutputs safe_board_outputs(const std::array<AnalogRange, kAnalogOutputCount>& ranges) noexcept;

/// Opens a board from a URI:
///   comedi:/dev/comediN   a comedilib device (ComediBoard over the real libcomedi), N = 0, 1, ...
///   shm:NAME              the emulated board in shared memory /crane_board_NAME (ShmBoard); NAME of
///                         1..200 letters, digits, '_' or '-'.
/// Validates `config` first. Throws common::ConfigError for an invalid config or a malformed URI (the
/// message names the URI and the accepted forms), BoardError if the device or segment cannot be
/// opened or does not match `config`.
[[nodiscard]] std::unique_ptr<Board> open_board(const std::string& uri, const BoardConfig& config);

}  // namespace crane::hardware_bridge
