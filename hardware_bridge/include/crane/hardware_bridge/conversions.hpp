#pragma once
// Raw board registers <-> SI units, for the lab crane of H. M. Omar, "Control of Gantry and Tower
// Cranes", Virginia Tech 2003, section 4.1 (the same sensor model as
// plant/include/crane/plant/drives_and_sensors.hpp, which the tests cross-check):
//   - analog outputs: unsigned codes 0..maxdata spread linearly over [min_volts, max_volts], the
//     convention of comedilib (comedi_to_phys): volts = min_volts + code * (max - min) / maxdata;
//   - encoders: counter registers `counter_bits` wide that wrap; CounterUnwrapper turns successive
//     readings into a continuous signed count, EncoderScaling turns counts into [m] and [rad].
//
// Errors: constructors throw common::ConfigError naming the field, value and bound; conversions are
// noexcept and allocation-free.

#include <array>
#include <cstdint>

#include "crane/common/crane_parameters.hpp"
#include "crane/common/crane_signals.hpp"
#include "crane/hardware_bridge/board_channels.hpp"

namespace crane::hardware_bridge {

/// Range of one analog output channel as the driver reports it (comedi_get_range and
/// comedi_get_maxdata): code 0 is min_volts, code maxdata is max_volts, linear in between.
struct AnalogRange {
  double min_volts{-10.0};      // [V] voltage of code 0
  double max_volts{10.0};       // [V] voltage of code maxdata
  std::uint32_t maxdata{8191};  // [code] largest code, > 0
};

/// True if both bounds are finite, min_volts < max_volts and maxdata > 0 (the precondition of the
/// conversions below).
[[nodiscard]] bool is_valid(const AnalogRange& range) noexcept;

/// Voltage step of one code [V/code]: (max_volts - min_volts) / maxdata.
[[nodiscard]] double code_step_volts(const AnalogRange& range) noexcept;

/// DAC code of `volts` [V]: clamped to [min_volts, max_volts], rounded to the nearest code
/// (halves up), in [0, maxdata]. NaN gives the code of 0 V (0 V clamped into the range);
/// +-Inf give the end codes. Precondition: is_valid(range) (asserted).
[[nodiscard]] std::uint32_t volts_to_code(double volts, const AnalogRange& range) noexcept;

/// Voltage [V] of a DAC code: min_volts + min(code, maxdata) * code_step_volts(range).
/// Precondition: is_valid(range) (asserted).
[[nodiscard]] double code_to_volts(std::uint32_t code, const AnalogRange& range) noexcept;

/// The plant's DAC (drives_and_sensors.hpp: dac_bits signed codes c in [-2^(bits-1), 2^(bits-1) - 1],
/// voltage c * step with step = dac_range / 2^(bits-1)) written as an unsigned comedi-style range:
/// code = c + 2^(bits-1), min_volts = -dac_range, max_volts = dac_range - step,
/// maxdata = 2^dac_bits - 1. For 13 bits over +-10 V: [-10, 9.99755859375] V, maxdata 8191, step
/// 2.44140625 mV. Every code then decodes to exactly the plant's voltage, and 0 V is a code (4096).
/// This is the range the emulated (shm) board reports. Precondition: 1 <= dac_bits <= 31,
/// dac_range > 0 (common::validate(CraneParameters) checks both).
[[nodiscard]] AnalogRange plant_dac_range(const common::CraneParameters& crane) noexcept;

/// Register value `counter_bits` [bit] wide of a signed count: count & (2^counter_bits - 1),
/// what a wrapping hardware counter (and the emulated board) holds. 1 <= counter_bits <= 32.
[[nodiscard]] std::uint32_t counter_register_value(std::int64_t encoder_counts, int counter_bits) noexcept;

/// Two's-complement reading of the low `counter_bits` bits of `raw`: in
/// [-2^(counter_bits-1), 2^(counter_bits-1) - 1]. 1 <= counter_bits <= 32.
[[nodiscard]] std::int64_t sign_extend(std::uint32_t raw, int counter_bits) noexcept;

/// Continuous signed 64-bit count from successive readings of one wrapping counter register.
///
/// Origin: the first reading after construction or reset() is taken as an absolute signed value,
/// sign_extend(raw, counter_bits), since the emulated board (and a counter cleared at power-up)
/// holds `signed count & mask`. After that, each reading adds the delta from the previous one taken
/// modulo 2^counter_bits into [-2^(counter_bits-1), 2^(counter_bits-1) - 1]: correct as long as the
/// counter moves by less than 2^(counter_bits-1) counts between two readings (24 bits: 8.4 million
/// counts = 13 m of trolley travel per sample). Bits of `raw` above counter_bits are ignored.
class CounterUnwrapper {
 public:
  /// Throws common::ConfigError ("counter_bits = 40 is out of range: must be in [2, 32]").
  explicit CounterUnwrapper(int counter_bits);

  /// Feeds one register reading and returns the continuous count. noexcept, no allocation.
  [[nodiscard]] std::int64_t update(std::uint32_t raw) noexcept;

  /// The count after the last update() (0 before the first).
  [[nodiscard]] std::int64_t count() const noexcept { return count_; }
  /// True once a reading has set the origin.
  [[nodiscard]] bool has_origin() const noexcept { return has_origin_; }
  /// Forgets the origin: the next reading is taken as an absolute value again.
  void reset() noexcept;
  [[nodiscard]] int counter_bits() const noexcept { return counter_bits_; }

 private:
  int counter_bits_;
  std::uint64_t mask_;   // 2^counter_bits - 1
  std::uint64_t last_raw_{0};
  std::int64_t count_{0};
  bool has_origin_{false};
};

/// Encoder resolutions of the lab crane (section 4.1), identical to the plant's
/// (plant/src/drives_and_sensors.cpp):
///   trolley [m/count]   = 2 pi leadscrew_pitch / (4 motor_encoder_lines)
///   slew    [rad/count] = 2 pi / (4 motor_encoder_lines slew_gear_ratio)
///   swing   [rad/count] = 2 pi / (4 swing_encoder_lines)
///   bridge  [m/count]   = the trolley's (overhead crane): the same motor encoder lines and travel
///                         per motor radian, as the plant's DrivesAndSensors::measure_bridge()
/// (quadrature x4; leadscrew_pitch in [m/rad]; slew_gear_ratio motor revolutions per jib revolution).
/// Counts -> position is counts * resolution, as the plant's encoder_counts_to_position().
class EncoderScaling {
 public:
  /// Validates `crane` (common::validate, fields prefixed "crane."); throws common::ConfigError.
  explicit EncoderScaling(const common::CraneParameters& crane);

  [[nodiscard]] double trolley_resolution() const noexcept { return trolley_resolution_; }  // [m/count]
  [[nodiscard]] double slew_resolution() const noexcept { return slew_resolution_; }        // [rad/count]
  [[nodiscard]] double swing_resolution() const noexcept { return swing_resolution_; }      // [rad/count]
  [[nodiscard]] double bridge_resolution() const noexcept { return trolley_resolution_; }   // [m/count]
  /// Resolution of one counter: [m/count] for the trolley and the bridge, [rad/count] for the others.
  [[nodiscard]] double resolution(CounterChannel channel) const noexcept;

  [[nodiscard]] double trolley_position(std::int64_t encoder_counts) const noexcept;  // [m]
  [[nodiscard]] double slew_angle(std::int64_t encoder_counts) const noexcept;        // [rad]
  [[nodiscard]] double swing_angle(std::int64_t encoder_counts) const noexcept;       // [rad]
  [[nodiscard]] double bridge_position(std::int64_t encoder_counts) const noexcept;   // [m]

  /// Measurement from the continuous counts (indexed by CounterChannel; the bridge's gives
  /// bridge_position, 0 on a crane without a bridge, whose board reads that counter as 0). The
  /// crane has no hoist encoder: `cable_length` [m] is passed through.
  [[nodiscard]] common::CraneMeasurement measurement(const std::array<std::int64_t, kCounterCount>& encoder_counts,
                                                     double cable_length) const noexcept;

 private:
  double trolley_resolution_;  // [m/count]
  double slew_resolution_;     // [rad/count]
  double swing_resolution_;    // [rad/count]
};

}  // namespace crane::hardware_bridge
