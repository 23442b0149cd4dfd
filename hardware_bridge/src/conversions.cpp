#include "crane/hardware_bridge/conversions.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>

#include "crane/common/validation.hpp"

namespace crane::hardware_bridge {

namespace {
constexpr double kQuadrature = 4.0;  // counted edges per encoder line
}  // namespace

bool is_valid(const AnalogRange& range) noexcept {
  return std::isfinite(range.min_volts) && std::isfinite(range.max_volts) && range.min_volts < range.max_volts &&
         range.maxdata > 0;
}

double code_step_volts(const AnalogRange& range) noexcept {
  return (range.max_volts - range.min_volts) / static_cast<double>(range.maxdata);
}

std::uint32_t volts_to_code(double volts, const AnalogRange& range) noexcept {
  assert(is_valid(range));
  const double target = std::isnan(volts) ? 0.0 : volts;
  const double clamped = std::clamp(target, range.min_volts, range.max_volts);
  const double maxdata = static_cast<double>(range.maxdata);
  const double code = std::clamp(std::round((clamped - range.min_volts) / code_step_volts(range)), 0.0, maxdata);
  return static_cast<std::uint32_t>(code);
}

double code_to_volts(std::uint32_t code, const AnalogRange& range) noexcept {
  assert(is_valid(range));
  const std::uint32_t bounded = std::min(code, range.maxdata);
  if (bounded == range.maxdata) return range.max_volts;  // exact at the top, whatever the rounding of the step
  return range.min_volts + static_cast<double>(bounded) * code_step_volts(range);
}

AnalogRange plant_dac_range(const common::CraneParameters& crane) noexcept {
  // Plant (drives_and_sensors.cpp): signed code c in [-2^(bits-1), 2^(bits-1) - 1], V = c * step.
  const double half_codes = std::ldexp(1.0, crane.dac_bits - 1);
  const double step = crane.dac_range / half_codes;
  AnalogRange range;
  range.min_volts = -crane.dac_range;
  range.max_volts = crane.dac_range - step;
  range.maxdata = static_cast<std::uint32_t>(2.0 * half_codes - 1.0);
  return range;
}

std::uint32_t counter_register_value(std::int64_t encoder_counts, int counter_bits) noexcept {
  const std::uint64_t mask = (std::uint64_t{1} << counter_bits) - 1U;
  return static_cast<std::uint32_t>(static_cast<std::uint64_t>(encoder_counts) & mask);
}

std::int64_t sign_extend(std::uint32_t raw, int counter_bits) noexcept {
  const std::uint64_t modulus = std::uint64_t{1} << counter_bits;
  const std::uint64_t value = static_cast<std::uint64_t>(raw) & (modulus - 1U);
  const auto signed_value = static_cast<std::int64_t>(value);
  return value >= modulus / 2U ? signed_value - static_cast<std::int64_t>(modulus) : signed_value;
}

CounterUnwrapper::CounterUnwrapper(int counter_bits) : counter_bits_(counter_bits) {
  common::require_in_range("counter_bits", static_cast<double>(counter_bits), 2.0, 32.0);
  mask_ = (std::uint64_t{1} << counter_bits) - 1U;
}

std::int64_t CounterUnwrapper::update(std::uint32_t raw) noexcept {
  const std::uint64_t value = static_cast<std::uint64_t>(raw) & mask_;
  if (!has_origin_) {
    count_ = sign_extend(raw, counter_bits_);
    has_origin_ = true;
  } else {
    // Delta modulo 2^bits, read as a signed counter_bits value: the shortest way around.
    count_ += sign_extend(static_cast<std::uint32_t>((value - last_raw_) & mask_), counter_bits_);
  }
  last_raw_ = value;
  return count_;
}

void CounterUnwrapper::reset() noexcept {
  has_origin_ = false;
  last_raw_ = 0;
  count_ = 0;
}

EncoderScaling::EncoderScaling(const common::CraneParameters& crane) {
  common::validate(crane, "crane");
  const double motor_counts_per_revolution = kQuadrature * static_cast<double>(crane.motor_encoder_lines);
  const double swing_counts_per_revolution = kQuadrature * static_cast<double>(crane.swing_encoder_lines);
  // One motor revolution (2 pi rad) moves the trolley 2 pi * leadscrew_pitch [m].
  trolley_resolution_ = 2.0 * std::numbers::pi * crane.leadscrew_pitch / motor_counts_per_revolution;
  // One jib revolution is slew_gear_ratio motor revolutions.
  slew_resolution_ = 2.0 * std::numbers::pi / (motor_counts_per_revolution * crane.slew_gear_ratio);
  swing_resolution_ = 2.0 * std::numbers::pi / swing_counts_per_revolution;
}

double EncoderScaling::resolution(CounterChannel channel) const noexcept {
  switch (channel) {
    case CounterChannel::trolley_motor: return trolley_resolution_;
    case CounterChannel::bridge_motor: return bridge_resolution();
    case CounterChannel::slew_motor: return slew_resolution_;
    case CounterChannel::swing_in_plane:
    case CounterChannel::swing_out_of_plane: return swing_resolution_;
  }
  return swing_resolution_;
}

double EncoderScaling::trolley_position(std::int64_t encoder_counts) const noexcept {
  return static_cast<double>(encoder_counts) * trolley_resolution_;
}

double EncoderScaling::slew_angle(std::int64_t encoder_counts) const noexcept {
  return static_cast<double>(encoder_counts) * slew_resolution_;
}

double EncoderScaling::swing_angle(std::int64_t encoder_counts) const noexcept {
  return static_cast<double>(encoder_counts) * swing_resolution_;
}

double EncoderScaling::bridge_position(std::int64_t encoder_counts) const noexcept {
  return static_cast<double>(encoder_counts) * bridge_resolution();
}

common::CraneMeasurement EncoderScaling::measurement(const std::array<std::int64_t, kCounterCount>& encoder_counts,
                                                     double cable_length) const noexcept {
  common::CraneMeasurement m;
  m.trolley_position = trolley_position(encoder_counts[index(CounterChannel::trolley_motor)]);
  m.slew_angle = slew_angle(encoder_counts[index(CounterChannel::slew_motor)]);
  m.swing_in_plane = swing_angle(encoder_counts[index(CounterChannel::swing_in_plane)]);
  m.swing_out_of_plane = swing_angle(encoder_counts[index(CounterChannel::swing_out_of_plane)]);
  m.bridge_position = bridge_position(encoder_counts[index(CounterChannel::bridge_motor)]);
  m.cable_length = cable_length;
  return m;
}

}  // namespace crane::hardware_bridge
