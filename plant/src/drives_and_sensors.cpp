#include "crane/plant/drives_and_sensors.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace crane::plant {

namespace {
constexpr int kQuadrature = 4;  // edges per encoder line
constexpr double kCountGuard = 1e-9;
constexpr double kCountLimit = 4.611686018427387904e18;  // 2^62
}  // namespace

std::int32_t voltage_to_dac_code(double voltage, int dac_bits, double dac_range) noexcept {
  if (std::isnan(voltage)) return 0;
  const double clamped = std::clamp(voltage, -dac_range, dac_range);
  const double half_codes = std::ldexp(1.0, dac_bits - 1);
  const double step = dac_range / half_codes;
  const double code = std::clamp(std::round(clamped / step), -half_codes, half_codes - 1.0);
  return static_cast<std::int32_t>(code);
}

double dac_code_to_voltage(std::int32_t dac_code, int dac_bits, double dac_range) noexcept {
  return static_cast<double>(dac_code) * dac_range / std::ldexp(1.0, dac_bits - 1);
}

std::int64_t position_to_encoder_counts(double position, double resolution) noexcept {
  if (std::isnan(position)) return 0;
  const double counts = std::clamp(std::floor(position / resolution + kCountGuard), -kCountLimit, kCountLimit);
  return static_cast<std::int64_t>(counts);
}

double encoder_counts_to_position(std::int64_t encoder_counts, double resolution) noexcept {
  return static_cast<double>(encoder_counts) * resolution;
}

DrivesAndSensors::DrivesAndSensors(const common::CraneParameters& parameters)
    : dac_bits_(parameters.dac_bits), dac_range_(parameters.dac_range) {
  common::validate(parameters, "crane");
  const double counts_per_revolution_motor = kQuadrature * static_cast<double>(parameters.motor_encoder_lines);
  const double counts_per_revolution_swing = kQuadrature * static_cast<double>(parameters.swing_encoder_lines);
  // Trolley: one motor revolution (2 pi rad) moves the trolley 2 pi * pitch [m].
  trolley_resolution_ = 2.0 * std::numbers::pi * parameters.leadscrew_pitch / counts_per_revolution_motor;
  // Slew: one jib revolution is slew_gear_ratio motor revolutions.
  slew_resolution_ = 2.0 * std::numbers::pi / (counts_per_revolution_motor * parameters.slew_gear_ratio);
  swing_resolution_ = 2.0 * std::numbers::pi / counts_per_revolution_swing;
}

std::int32_t DrivesAndSensors::voltage_to_dac_code(double voltage) const noexcept {
  return plant::voltage_to_dac_code(voltage, dac_bits_, dac_range_);
}

double DrivesAndSensors::dac_code_to_voltage(std::int32_t dac_code) const noexcept {
  return plant::dac_code_to_voltage(dac_code, dac_bits_, dac_range_);
}

double DrivesAndSensors::applied_voltage(double voltage) const noexcept {
  return dac_code_to_voltage(voltage_to_dac_code(voltage));
}

double DrivesAndSensors::dac_step_voltage() const noexcept { return dac_range_ / std::ldexp(1.0, dac_bits_ - 1); }

std::int64_t DrivesAndSensors::trolley_position_to_encoder_counts(double trolley_position) const noexcept {
  return position_to_encoder_counts(trolley_position, trolley_resolution_);
}
double DrivesAndSensors::trolley_encoder_counts_to_position(std::int64_t encoder_counts) const noexcept {
  return encoder_counts_to_position(encoder_counts, trolley_resolution_);
}
std::int64_t DrivesAndSensors::slew_angle_to_encoder_counts(double slew_angle) const noexcept {
  return position_to_encoder_counts(slew_angle, slew_resolution_);
}
double DrivesAndSensors::slew_encoder_counts_to_angle(std::int64_t encoder_counts) const noexcept {
  return encoder_counts_to_position(encoder_counts, slew_resolution_);
}
std::int64_t DrivesAndSensors::swing_angle_to_encoder_counts(double swing_angle) const noexcept {
  return position_to_encoder_counts(swing_angle, swing_resolution_);
}
double DrivesAndSensors::swing_encoder_counts_to_angle(std::int64_t encoder_counts) const noexcept {
  return encoder_counts_to_position(encoder_counts, swing_resolution_);
}

common::CraneMeasurement DrivesAndSensors::measure(double trolley_position, double slew_angle, double swing_in_plane,
                                                   double swing_out_of_plane, double cable_length) const noexcept {
  common::CraneMeasurement m;
  m.trolley_position = trolley_encoder_counts_to_position(trolley_position_to_encoder_counts(trolley_position));
  m.slew_angle = slew_encoder_counts_to_angle(slew_angle_to_encoder_counts(slew_angle));
  m.swing_in_plane = swing_encoder_counts_to_angle(swing_angle_to_encoder_counts(swing_in_plane));
  m.swing_out_of_plane = swing_encoder_counts_to_angle(swing_angle_to_encoder_counts(swing_out_of_plane));
  m.cable_length = cable_length;
  return m;
}

double DrivesAndSensors::measure_bridge(double bridge_position) const noexcept {
  return encoder_counts_to_position(position_to_encoder_counts(bridge_position, bridge_resolution()),
                                    bridge_resolution());
}

}  // namespace crane::plant
