#pragma once
// The interface board through comedilib (https://www.comedi.org), behind a seam so it can be tested
// without hardware:
//   ComediApi            exactly the comedilib calls ComediBoard uses, one virtual each, with
//                        comedilib's return conventions (-1 / 0 / NULL on error, then
//                        comedi_errno() and comedi_strerror());
//   make_comedilib_api() the real implementation (the only code that includes comedilib.h);
//   ComediBoard          the Board: opens the device, checks the configured subdevices, channels and
//                        bits against what the driver reports, reads the analog output ranges and
//                        maxdata once, then reads counters and writes codes (converting nothing).
//                        Only the channels of the crane (BoardConfig::axes: the slew's on a tower
//                        crane, the bridge's on an overhead crane) are checked, read and written; a
//                        counter the crane does not have reads 0 and the range of such an analog
//                        output is the default one.
//
// The counters are read with comedi_data_read (range 0, AREF_GROUND); their counting mode
// (quadrature x4) is the driver's default or configured outside the bridge (no INSN_CONFIG here).
// Analog outputs use comedi_data_write (BoardConfig::analog_output_range, AREF_GROUND); digital lines
// comedi_dio_bitfield2 (base channel 0, so bits 0..31). On a DIO subdevice the configured bits are
// set to input/output with comedi_dio_config at open.

#include <cstdint>
#include <memory>
#include <string>

#include "crane/hardware_bridge/board.hpp"

namespace crane::hardware_bridge {

/// Opaque device handle (a comedi_t* in the real implementation).
struct ComediDevice;

/// Subdevice types, same values as comedilib's enum comedi_subdevice_type (COMEDI_SUBD_*).
enum class ComediSubdeviceType : int {
  unused = 0,
  analog_input = 1,
  analog_output = 2,
  digital_input = 3,
  digital_output = 4,
  digital_io = 5,
  counter = 6,
};
[[nodiscard]] const char* subdevice_type_name(int comedi_subdevice_type) noexcept;

/// A range as comedi_get_range() reports it.
struct ComediRange {
  double min{0.0};    // [unit] value of code 0
  double max{0.0};    // [unit] value of code maxdata
  unsigned unit{0};   // comedilib UNIT_*: kComediUnitVolt = volts
};
inline constexpr unsigned kComediUnitVolt = 0;   // UNIT_volt
inline constexpr unsigned kComediAnalogRefGround = 0;  // AREF_GROUND
inline constexpr unsigned kComediDioInput = 0;   // COMEDI_INPUT
inline constexpr unsigned kComediDioOutput = 1;  // COMEDI_OUTPUT

/// The comedilib calls ComediBoard makes. Return conventions are comedilib's; on failure the
/// reason is error_number() / error_string(). All calls may block on the device.
class ComediApi {
 public:
  ComediApi() = default;
  ComediApi(const ComediApi&) = delete;
  ComediApi& operator=(const ComediApi&) = delete;
  virtual ~ComediApi() = default;

  /// comedi_open: nullptr on failure.
  [[nodiscard]] virtual ComediDevice* open(const std::string& device_path) = 0;
  /// comedi_close: 0, or -1 on failure.
  virtual int close(ComediDevice* device) = 0;
  /// comedi_get_subdevice_type: a COMEDI_SUBD_* value, or -1 if the subdevice does not exist.
  [[nodiscard]] virtual int get_subdevice_type(ComediDevice* device, unsigned subdevice) = 0;
  /// comedi_get_n_channels: >= 0, or -1 if the subdevice does not exist.
  [[nodiscard]] virtual int get_n_channels(ComediDevice* device, unsigned subdevice) = 0;
  /// comedi_get_maxdata: > 0, or 0 on failure.
  [[nodiscard]] virtual std::uint32_t get_maxdata(ComediDevice* device, unsigned subdevice, unsigned channel) = 0;
  /// comedi_get_range: true and `range` filled, or false (NULL) on failure.
  [[nodiscard]] virtual bool get_range(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index,
                                       ComediRange& range) = 0;
  /// comedi_data_read: >= 0 (and `data` set), or -1 on failure.
  [[nodiscard]] virtual int data_read(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index,
                                      unsigned aref, std::uint32_t& data) = 0;
  /// comedi_data_write: >= 0, or -1 on failure.
  [[nodiscard]] virtual int data_write(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index,
                                       unsigned aref, std::uint32_t data) = 0;
  /// comedi_dio_config: >= 0, or -1 on failure. `direction` kComediDioInput or kComediDioOutput.
  [[nodiscard]] virtual int dio_config(ComediDevice* device, unsigned subdevice, unsigned channel,
                                       unsigned direction) = 0;
  /// comedi_dio_bitfield2: writes the bits of `bits` selected by `write_mask`, then sets `bits` to
  /// the state of the lines; >= 0, or -1 on failure.
  [[nodiscard]] virtual int dio_bitfield2(ComediDevice* device, unsigned subdevice, unsigned write_mask,
                                          unsigned& bits, unsigned base_channel) = 0;
  /// comedi_errno: the error of the last failed call.
  [[nodiscard]] virtual int error_number() = 0;
  /// comedi_strerror.
  [[nodiscard]] virtual std::string error_string(int error_number) = 0;
};

/// ComediApi over the real libcomedi.
[[nodiscard]] std::unique_ptr<ComediApi> make_comedilib_api();

class ComediBoard final : public Board {
 public:
  /// Opens `device_path` (e.g. "/dev/comedi0") through `api` (must not be null) and checks
  /// `config` (validate() first: common::ConfigError) against the driver; throws BoardError naming
  /// the device, subdevice, channel or bit and the driver's message if
  ///   - the device cannot be opened;
  ///   - a configured subdevice does not exist or has the wrong type (counter; analog output;
  ///     digital output or DIO; digital input or DIO);
  ///   - a configured channel or bit is >= the subdevice's number of channels;
  ///   - a counter's maxdata is not 2^counter_bits - 1;
  ///   - an analog output's range (analog_output_range) does not exist, is not in volts, is not
  ///     finite with min < max, or its maxdata is 0;
  ///   - comedi_dio_config fails on a DIO subdevice.
  /// The device is closed again if the constructor throws. Writes nothing to the outputs.
  ComediBoard(const std::string& device_path, const BoardConfig& config, std::unique_ptr<ComediApi> api);
  ~ComediBoard() override;

  /// One comedi_data_read per counter, masked to counter_bits. Throws BoardError.
  void read_counters(std::array<std::uint32_t, kCounterCount>& raw_counts) override;
  /// One comedi_data_write per analog output (codes clamped to maxdata), and one
  /// comedi_dio_bitfield2 with the configured output bits as write mask. Order: if the new digital
  /// word de-energizes a line that the last write energized, the digital word is written first
  /// (brakes engage before the voltages change); otherwise the codes first. Throws BoardError.
  void write_outputs(const BoardOutputs& outputs) override;
  /// One comedi_dio_bitfield2 (write mask 0), mapped to the logical word with the configured bits
  /// and polarity. Throws BoardError.
  [[nodiscard]] std::uint32_t read_digital_inputs() override;
  [[nodiscard]] int counter_bits() const noexcept override { return config_.counter_bits; }
  [[nodiscard]] AnalogRange analog_range(AnalogOutput channel) const noexcept override;
  [[nodiscard]] std::string describe() const override;

 private:
  void check_subdevice(int subdevice, const char* role, bool (*type_ok)(int), int& n_channels) const;
  [[noreturn]] void fail(const std::string& what) const;
  void close_device() noexcept;
  void write_digital_outputs(std::uint32_t logical_outputs);
  void write_analog_outputs(const BoardOutputs& outputs);

  std::string device_path_;
  BoardConfig config_;
  std::unique_ptr<ComediApi> api_;
  ComediDevice* device_{nullptr};
  std::uint32_t counter_mask_{0};
  std::array<AnalogRange, kAnalogOutputCount> ranges_{};
  unsigned digital_output_mask_{0};  // physical bits of the outputs
  // Logical word of the last successful write; unknown at open, so taken as all energized (the
  // first write of a safe word then writes the digital lines first).
  std::uint32_t last_digital_outputs_{all_outputs_energized(config_.axes)};
};

}  // namespace crane::hardware_bridge
