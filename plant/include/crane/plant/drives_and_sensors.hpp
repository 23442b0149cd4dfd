#pragma once
// Drive electronics and sensors of the lab tower crane (Omar 2003, section 4.1):
//   - analog outputs: clamp to +-dac_range [V], then quantize to dac_bits over that span
//     (13 bits over +-10 V: 8192 codes, 2.44 mV per code); codes are signed, two's complement
//     style: code in [-2^(bits-1), 2^(bits-1) - 1], voltage = code * step. Round to nearest.
//   - motor encoders: motor_encoder_lines per revolution, read in quadrature (x4). The trolley
//     motor drives a leadscrew of pitch leadscrew_pitch [m/rad]; the slew motor turns the jib
//     through a gear of ratio slew_gear_ratio (motor revolutions per jib revolution).
//   - swing encoders: swing_encoder_lines per revolution, quadrature (x4), on phi and theta.
// Position -> counts is floor(position / resolution) (an incremental encoder counts the edges
// passed since zero), with a 1e-9-count guard so that counts -> position -> counts is the identity
// despite rounding; counts -> position is counts * resolution (the lower edge of the count).
// The cable length has no encoder in the dissertation's setup: it is reported unquantized.
//
// Errors: the constructor validates the parameters (common::validate) and throws
// common::ConfigError; conversions are noexcept (non-finite inputs map to code/count 0).

#include <cstdint>

#include "crane/common/crane_parameters.hpp"
#include "crane/common/crane_signals.hpp"

namespace crane::plant {

/// Signed DAC code of `voltage` [V]: clamp to +-dac_range, round to the nearest code, clamp to
/// [-2^(dac_bits-1), 2^(dac_bits-1) - 1]. NaN gives 0. Preconditions: 1 <= dac_bits <= 30, dac_range > 0.
[[nodiscard]] std::int32_t voltage_to_dac_code(double voltage, int dac_bits, double dac_range) noexcept;
/// Voltage [V] of a signed DAC code: code * 2 dac_range / 2^dac_bits.
[[nodiscard]] double dac_code_to_voltage(std::int32_t dac_code, int dac_bits, double dac_range) noexcept;

/// floor(position / resolution) with a 1e-9-count guard; saturates at +-2^62, NaN gives 0.
/// `position` [m] or [rad], `resolution` [m/count] or [rad/count] > 0.
[[nodiscard]] std::int64_t position_to_encoder_counts(double position, double resolution) noexcept;
/// counts * resolution [m] or [rad].
[[nodiscard]] double encoder_counts_to_position(std::int64_t encoder_counts, double resolution) noexcept;

class DrivesAndSensors {
 public:
  /// Throws common::ConfigError (field names prefixed "crane.") for invalid parameters.
  explicit DrivesAndSensors(const common::CraneParameters& parameters);

  [[nodiscard]] std::int32_t voltage_to_dac_code(double voltage) const noexcept;
  [[nodiscard]] double dac_code_to_voltage(std::int32_t dac_code) const noexcept;
  /// The voltage the drive actually receives for a commanded `voltage` [V].
  [[nodiscard]] double applied_voltage(double voltage) const noexcept;
  [[nodiscard]] double dac_step_voltage() const noexcept;  // [V/code]

  [[nodiscard]] double trolley_resolution() const noexcept { return trolley_resolution_; }  // [m/count]
  [[nodiscard]] double slew_resolution() const noexcept { return slew_resolution_; }        // [rad/count]
  [[nodiscard]] double swing_resolution() const noexcept { return swing_resolution_; }      // [rad/count]
  /// [m/count] an overhead crane's bridge encoder: the trolley's (see measure_bridge()).
  [[nodiscard]] double bridge_resolution() const noexcept { return trolley_resolution_; }

  [[nodiscard]] std::int64_t trolley_position_to_encoder_counts(double trolley_position) const noexcept;
  [[nodiscard]] double trolley_encoder_counts_to_position(std::int64_t encoder_counts) const noexcept;  // [m]
  [[nodiscard]] std::int64_t slew_angle_to_encoder_counts(double slew_angle) const noexcept;
  [[nodiscard]] double slew_encoder_counts_to_angle(std::int64_t encoder_counts) const noexcept;  // [rad]
  [[nodiscard]] std::int64_t swing_angle_to_encoder_counts(double swing_angle) const noexcept;
  [[nodiscard]] double swing_encoder_counts_to_angle(std::int64_t encoder_counts) const noexcept;  // [rad]

  /// An overhead crane's bridge position [m], quantized by an encoder like the trolley's (same lines
  /// and travel per motor radian, crane.motor_encoder_lines and crane.leadscrew_pitch).
  [[nodiscard]] double measure_bridge(double bridge_position) const noexcept;
  /// Quantized measurement of the true positions [m, rad, rad, rad], cable length [m] passed through.
  [[nodiscard]] common::CraneMeasurement measure(double trolley_position, double slew_angle, double swing_in_plane,
                                                 double swing_out_of_plane, double cable_length) const noexcept;

 private:
  int dac_bits_;
  double dac_range_;           // [V]
  double trolley_resolution_;  // [m/count]
  double slew_resolution_;     // [rad/count]
  double swing_resolution_;    // [rad/count]
};

}  // namespace crane::plant
