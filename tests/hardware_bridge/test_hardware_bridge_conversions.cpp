// Board registers <-> SI units: counter unwrapping, encoder scaling and DAC codes, cross-checked
// against the plant's own sensor model (plant/src/drives_and_sensors.cpp, Omar 2003 section 4.1).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

#include "crane/common/validation.hpp"
#include "crane/hardware_bridge/conversions.hpp"
#include "crane/plant/drives_and_sensors.hpp"

namespace crane::hardware_bridge {
namespace {

constexpr int kRandomSamples = 20000;
constexpr int kRandomWalkSteps = 5000;

// A crane whose sensors differ from the lab crane in every parameter the scaling uses, so that a
// swapped or missing factor shows up.
common::CraneParameters odd_sensor_crane() {
  common::CraneParameters p;
  p.motor_encoder_lines = 1024;
  p.swing_encoder_lines = 2500;
  p.leadscrew_pitch = 0.005 / (2.0 * std::numbers::pi);  // 5 mm per revolution
  p.slew_gear_ratio = 30.0;
  return p;
}

// The bridge encoder of deploy/config/overhead_crane.yaml: 2000 lines, 5 mm of travel per motor radian.
common::CraneParameters overhead_crane() {
  common::CraneParameters p;
  p.motor_encoder_lines = 2000;
  p.leadscrew_pitch = 0.005;  // [m/rad]
  return p;
}

// ---------------------------------------------------------------------------------------------
// Counter registers

TEST(CounterRegister, MaskAndSignExtension) {
  // 24 bits: -1 is 0xFFFFFF; 2^23 - 1 the largest positive; 2^23 reads as -2^23.
  EXPECT_EQ(counter_register_value(-1, 24), 0xFFFFFFU);
  EXPECT_EQ(counter_register_value(16777216 + 5, 24), 5U);
  EXPECT_EQ(sign_extend(0xFFFFFFU, 24), -1);
  EXPECT_EQ(sign_extend(0x7FFFFFU, 24), 8388607);
  EXPECT_EQ(sign_extend(0x800000U, 24), -8388608);
  EXPECT_EQ(sign_extend(0xFF000005U, 24), 5);  // bits above 24 ignored
  EXPECT_EQ(sign_extend(0xFFFFFFFFU, 32), -1);
  EXPECT_EQ(sign_extend(0x80000000U, 32), -2147483648LL);
  std::mt19937_64 rng(3);
  std::uniform_int_distribution<std::int64_t> count(-(std::int64_t{1} << 23), (std::int64_t{1} << 23) - 1);
  for (int i = 0; i < kRandomSamples; ++i) {
    const std::int64_t n = count(rng);
    ASSERT_EQ(sign_extend(counter_register_value(n, 24), 24), n);
  }
}

TEST(CounterUnwrapper, FirstReadingIsTheSignExtendedValue) {
  CounterUnwrapper unwrapper(24);
  EXPECT_FALSE(unwrapper.has_origin());
  EXPECT_EQ(unwrapper.update(0xFFFFF0U), -16);
  EXPECT_TRUE(unwrapper.has_origin());
  unwrapper.reset();
  EXPECT_EQ(unwrapper.update(0x7FFFFFU), 8388607);
}

TEST(CounterUnwrapper, WrapsUpwardAndDownward) {
  CounterUnwrapper unwrapper(24);
  // Up through 0: -16 (0xFFFFF0) -> +16 (0x000010) is +32 counts.
  EXPECT_EQ(unwrapper.update(0xFFFFF0U), -16);
  EXPECT_EQ(unwrapper.update(0x000010U), 16);
  // Down through 0 again: 16 -> 0xFFFFEB = -21.
  EXPECT_EQ(unwrapper.update(0xFFFFEBU), -21);
  // Up through the register's top: from 2^23 - 8 to register 0x800008, i.e. +16 counts = 2^23 + 8,
  // a count the register itself cannot hold.
  unwrapper.reset();
  EXPECT_EQ(unwrapper.update(0x7FFFF8U), 8388600);
  EXPECT_EQ(unwrapper.update(0x800008U), 8388616);
  // Three full turns of the register in steps of 2^22 (the register repeats its values).
  std::int64_t expected = 8388616;
  std::uint32_t raw = 0x800008U;
  for (int i = 0; i < 12; ++i) {
    raw = (raw + (1U << 22)) & 0xFFFFFFU;
    expected += 1 << 22;
    ASSERT_EQ(unwrapper.update(raw), expected);
  }
  EXPECT_EQ(expected, 8388616 + 3 * 16777216);
  // And back down the same way.
  for (int i = 0; i < 24; ++i) {
    raw = (raw - (1U << 22)) & 0xFFFFFFU;
    expected -= 1 << 22;
    ASSERT_EQ(unwrapper.update(raw), expected);
  }
  EXPECT_EQ(expected, 8388616 - 3 * 16777216);
}

TEST(CounterUnwrapper, IgnoresBitsAboveTheCounterWidth) {
  CounterUnwrapper unwrapper(16);
  EXPECT_EQ(unwrapper.update(0xABCD0005U), 5);
  EXPECT_EQ(unwrapper.update(0x1234FFFFU), -1);
}

TEST(CounterUnwrapper, RejectsInvalidWidths) {
  EXPECT_THROW(CounterUnwrapper{1}, common::ConfigError);
  try {
    CounterUnwrapper unwrapper(33);
    FAIL() << "33 bits accepted";
  } catch (const common::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("counter_bits = 33"), std::string::npos) << error.what();
  }
}

// Random walks whose steps stay below half the register range: the unwrapped count equals the true
// count exactly, far beyond the register's own range.
TEST(CounterUnwrapper, RandomWalksMatchTheTrueCount) {
  for (const int bits : {3, 12, 16, 24, 32}) {
    std::mt19937_64 rng(static_cast<unsigned>(100 + bits));
    const std::int64_t half = std::int64_t{1} << (bits - 1);
    std::uniform_int_distribution<std::int64_t> start(-half, half - 1);
    std::uniform_int_distribution<std::int64_t> step(-(half - 1), half - 1);
    CounterUnwrapper unwrapper(bits);
    std::int64_t truth = start(rng);
    ASSERT_EQ(unwrapper.update(counter_register_value(truth, bits)), truth) << bits;
    std::int64_t largest = 0;
    for (int i = 0; i < kRandomWalkSteps; ++i) {
      // A drift makes the walk leave the register's range in one direction.
      truth += step(rng) / 2 + half / 3;
      largest = std::max(largest, std::abs(truth));
      ASSERT_EQ(unwrapper.update(counter_register_value(truth, bits)), truth) << "bits " << bits << " step " << i;
    }
    EXPECT_GT(largest, 100 * half) << "the walk should wrap the register many times";
  }
}

// ---------------------------------------------------------------------------------------------
// Encoder scaling against the plant

TEST(EncoderScaling, LabCraneResolutions) {
  const EncoderScaling scaling{common::CraneParameters{}};
  // Trolley: 2000 lines x4 = 8000 counts per motor revolution, 0.5 in = 12.7 mm per revolution.
  EXPECT_NEAR(scaling.trolley_resolution(), 0.0127 / 8000.0, 1e-18);
  // Slew: 8000 counts per motor revolution x 45 motor revolutions per jib revolution.
  EXPECT_NEAR(scaling.slew_resolution(), 2.0 * std::numbers::pi / (8000.0 * 45.0), 1e-18);
  // Swing: 6000 lines x4 = 24000 counts per revolution.
  EXPECT_NEAR(scaling.swing_resolution(), 2.0 * std::numbers::pi / 24000.0, 1e-18);
  EXPECT_EQ(scaling.resolution(CounterChannel::swing_out_of_plane), scaling.swing_resolution());
}

TEST(EncoderScaling, InvalidParametersThrow) {
  common::CraneParameters p;
  p.motor_encoder_lines = 0;
  EXPECT_THROW(EncoderScaling{p}, common::ConfigError);
}

TEST(EncoderScaling, AgreesWithThePlantForRandomPositions) {
  for (const common::CraneParameters& crane : {common::CraneParameters{}, odd_sensor_crane()}) {
    const plant::DrivesAndSensors io{crane};
    const EncoderScaling scaling{crane};
    EXPECT_DOUBLE_EQ(scaling.trolley_resolution(), io.trolley_resolution());
    EXPECT_DOUBLE_EQ(scaling.slew_resolution(), io.slew_resolution());
    EXPECT_DOUBLE_EQ(scaling.swing_resolution(), io.swing_resolution());
    EXPECT_DOUBLE_EQ(scaling.bridge_resolution(), io.bridge_resolution());
    EXPECT_EQ(scaling.resolution(CounterChannel::bridge_motor), scaling.bridge_resolution());

    std::mt19937 rng(17);
    std::uniform_real_distribution<double> trolley(-1.5, 3.0);             // [m]
    std::uniform_real_distribution<double> slew(-2.0 * std::numbers::pi, 2.0 * std::numbers::pi);  // [rad]
    std::uniform_real_distribution<double> swing(-0.6, 0.6);               // [rad]
    for (int i = 0; i < kRandomSamples; ++i) {
      const double x = trolley(rng);
      const double gamma = slew(rng);
      const double phi = swing(rng);
      const double theta = swing(rng);
      const double y = trolley(rng);  // [m] an overhead crane's bridge
      // The plant's counts, through 24-bit registers, unwrapped from a fresh origin.
      const std::array<std::int64_t, kCounterCount> plant_counts{
          io.trolley_position_to_encoder_counts(x), io.slew_angle_to_encoder_counts(gamma),
          io.swing_angle_to_encoder_counts(phi), io.swing_angle_to_encoder_counts(theta),
          plant::position_to_encoder_counts(y, io.bridge_resolution())};
      std::array<std::int64_t, kCounterCount> counts{};
      for (std::size_t c = 0; c < kCounterCount; ++c) {
        CounterUnwrapper unwrapper(24);
        counts[c] = unwrapper.update(counter_register_value(plant_counts[c], 24));
        ASSERT_EQ(counts[c], plant_counts[c]);
      }
      const common::CraneMeasurement expected = io.measure(x, gamma, phi, theta, 1.25);
      const common::CraneMeasurement got = scaling.measurement(counts, 1.25);
      ASSERT_DOUBLE_EQ(got.trolley_position, expected.trolley_position) << x;
      ASSERT_DOUBLE_EQ(got.slew_angle, expected.slew_angle) << gamma;
      ASSERT_DOUBLE_EQ(got.swing_in_plane, expected.swing_in_plane) << phi;
      ASSERT_DOUBLE_EQ(got.swing_out_of_plane, expected.swing_out_of_plane) << theta;
      ASSERT_DOUBLE_EQ(got.bridge_position, io.measure_bridge(y)) << y;
      ASSERT_EQ(got.cable_length, 1.25);
      // Independent bound: a count is the floor, so the measurement lies within one count below.
      ASSERT_LE(got.trolley_position, x + 1e-9 * scaling.trolley_resolution());
      ASSERT_GT(got.trolley_position, x - scaling.trolley_resolution());
    }
  }
}

// An overhead crane's bridge over its whole runway (deploy/config/overhead_crane.yaml: 60 m, 15.3
// million counts of 3.9 um, past the +-2^23 of a 24-bit register's first reading): through the 32-bit
// registers that configuration uses, the bridge's reading is the plant's measurement from any start;
// through 24-bit registers a start beyond 2^23 counts is taken as negative, the reason for 32 bits.
TEST(EncoderScaling, BridgeOverTheRunwayAgreesWithThePlant) {
  const auto c = overhead_crane();
  const plant::DrivesAndSensors io{c};
  const EncoderScaling scaling{c};
  const double resolution = scaling.bridge_resolution();
  EXPECT_DOUBLE_EQ(resolution, 2.0 * std::numbers::pi * c.leadscrew_pitch / (4.0 * c.motor_encoder_lines));
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> runway(0.0, 60.0);  // [m]
  std::uniform_real_distribution<double> step(-0.01, 0.01);  // [m] per sample: 1 m/s at 100 Hz
  for (int i = 0; i < kRandomSamples / 10; ++i) {
    CounterUnwrapper unwrapper(32);
    double y = runway(rng);
    for (int k = 0; k < 10; ++k, y += step(rng)) {
      const std::int64_t plant_counts = plant::position_to_encoder_counts(y, io.bridge_resolution());
      std::array<std::int64_t, kCounterCount> counts{};
      counts[index(CounterChannel::bridge_motor)] = unwrapper.update(counter_register_value(plant_counts, 32));
      const common::CraneMeasurement got = scaling.measurement(counts, 4.0);
      ASSERT_DOUBLE_EQ(got.bridge_position, io.measure_bridge(y)) << y;
      ASSERT_EQ(got.trolley_position, 0.0);
    }
  }
  // 40 m is 10.2 million counts: a 24-bit register's first reading cannot hold it.
  CounterUnwrapper narrow(24);
  const std::int64_t far = plant::position_to_encoder_counts(40.0, resolution);
  ASSERT_GT(far, std::int64_t{1} << 23);
  EXPECT_LT(scaling.bridge_position(narrow.update(counter_register_value(far, 24))), 0.0);
}

// A trolley travel of 1 m through a 12-bit register (it wraps about 150 times): the bridge's
// unwrapped, scaled reading follows the plant's measurement sample by sample.
TEST(EncoderScaling, ContinuousTravelThroughASmallWrappingRegister) {
  const common::CraneParameters crane;
  const plant::DrivesAndSensors io{crane};
  const EncoderScaling scaling{crane};
  constexpr int kBits = 12;
  CounterUnwrapper unwrapper(kBits);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.2e-3, 0.2e-3);  // [m]
  double x = 0.0;
  for (int k = 0; k <= 1000; ++k) {
    x = 1e-3 * k + (k == 0 ? 0.0 : jitter(rng));  // 1 mm per sample = 630 counts < 2^11
    const std::int64_t counts = io.trolley_position_to_encoder_counts(x);
    const std::int64_t unwrapped = unwrapper.update(counter_register_value(counts, kBits));
    ASSERT_EQ(unwrapped, counts) << k;
    ASSERT_EQ(scaling.trolley_position(unwrapped), io.measure(x, 0, 0, 0, 1).trolley_position);
  }
}

// ---------------------------------------------------------------------------------------------
// DAC codes

TEST(AnalogCodes, PlantRangeIsTheThirteenBitDac) {
  const AnalogRange range = plant_dac_range(common::CraneParameters{});
  // 13 bits over +-10 V: step 20/8192 V; code 0 = -10 V, code 8191 = 10 - step.
  const double step = 20.0 / 8192.0;
  EXPECT_EQ(range.min_volts, -10.0);
  EXPECT_EQ(range.max_volts, 10.0 - step);
  EXPECT_EQ(range.maxdata, 8191U);
  EXPECT_EQ(code_step_volts(range), step);
  EXPECT_EQ(volts_to_code(0.0, range), 4096U);
  EXPECT_EQ(code_to_volts(4096U, range), 0.0);
  EXPECT_EQ(volts_to_code(1.0, range), 4096U + 410U);  // 1 / 2.44140625e-3 = 409.6 -> 410
  EXPECT_EQ(volts_to_code(-1.0, range), 4096U - 410U);
  EXPECT_EQ(volts_to_code(std::nan(""), range), 4096U);
  EXPECT_EQ(volts_to_code(25.0, range), 8191U);
  EXPECT_EQ(volts_to_code(-25.0, range), 0U);
  EXPECT_EQ(volts_to_code(std::numeric_limits<double>::infinity(), range), 8191U);
  EXPECT_EQ(volts_to_code(-std::numeric_limits<double>::infinity(), range), 0U);
  EXPECT_EQ(code_to_volts(9000U, range), range.max_volts);  // codes above maxdata saturate
}

TEST(AnalogCodes, EveryPlantCodeDecodesToThePlantVoltage) {
  const common::CraneParameters crane;
  const plant::DrivesAndSensors io{crane};
  const AnalogRange range = plant_dac_range(crane);
  for (std::uint32_t code = 0; code <= range.maxdata; ++code) {
    const std::int32_t plant_code = static_cast<std::int32_t>(code) - 4096;
    ASSERT_EQ(code_to_volts(code, range), io.dac_code_to_voltage(plant_code)) << code;
    ASSERT_EQ(volts_to_code(code_to_volts(code, range), range), code) << code;
  }
}

// The voltage the plant applies for a commanded voltage v, and the voltage of the bridge's code for
// v, agree within one DAC step; they differ only where v is exactly halfway between two codes
// (round-half-up on the unsigned code vs. half-away-from-zero on the plant's signed code).
TEST(AnalogCodes, BridgeCodesMatchThePlantsAppliedVoltage) {
  const common::CraneParameters crane;
  const plant::DrivesAndSensors io{crane};
  const AnalogRange range = plant_dac_range(crane);
  const double step = io.dac_step_voltage();
  std::mt19937 rng(23);
  std::uniform_real_distribution<double> volts(-12.0, 12.0);
  for (int i = 0; i < kRandomSamples; ++i) {
    const double v = volts(rng);
    const double bridge = code_to_volts(volts_to_code(v, range), range);
    const double plant = io.applied_voltage(v);
    ASSERT_LE(std::abs(bridge - plant), step + 1e-12) << v;
    if (bridge != plant) {
      const double steps = v / step;
      ASSERT_NEAR(std::abs(steps - std::trunc(steps)), 0.5, 1e-6) << "differs off a tie at " << v;
    }
  }
  // The ties themselves: -0.5 step is code -1 for the plant, code 0 (0 V) for the bridge.
  EXPECT_EQ(io.applied_voltage(-0.5 * step), -step);
  EXPECT_EQ(code_to_volts(volts_to_code(-0.5 * step, range), range), 0.0);
}

TEST(AnalogCodes, ComediStyleRangesRoundTripWithinHalfAStep) {
  // A 12-bit board reporting [-10, 10] V over 0..4095 (comedi's usual bipolar range), a 16-bit
  // [-5, 5] V one and a unipolar [0, 5] V one.
  for (const AnalogRange range : {AnalogRange{-10.0, 10.0, 4095U}, AnalogRange{-5.0, 5.0, 65535U},
                                  AnalogRange{0.0, 5.0, 4095U}}) {
    ASSERT_TRUE(is_valid(range));
    const double step = (range.max_volts - range.min_volts) / static_cast<double>(range.maxdata);
    EXPECT_EQ(volts_to_code(range.min_volts, range), 0U);
    EXPECT_EQ(volts_to_code(range.max_volts, range), range.maxdata);
    EXPECT_EQ(code_to_volts(range.maxdata, range), range.max_volts);
    // NaN: the code nearest 0 V (clamped into the range).
    EXPECT_LE(std::abs(code_to_volts(volts_to_code(std::nan(""), range), range) - std::clamp(0.0, range.min_volts,
                                                                                              range.max_volts)),
              0.5 * step + 1e-12);
    std::mt19937 rng(29);
    std::uniform_real_distribution<double> volts(range.min_volts - 3.0, range.max_volts + 3.0);
    for (int i = 0; i < kRandomSamples; ++i) {
      const double v = volts(rng);
      const std::uint32_t code = volts_to_code(v, range);
      ASSERT_LE(code, range.maxdata);
      ASSERT_LE(std::abs(code_to_volts(code, range) - std::clamp(v, range.min_volts, range.max_volts)),
                0.5 * step + 1e-12)
          << v;
    }
  }
  // [-10, 10] over 4095: 0 V is not a code; the nearest is 2048 (2047.5 rounds up), +2.44 mV.
  const AnalogRange twelve_bit{-10.0, 10.0, 4095U};
  EXPECT_EQ(volts_to_code(0.0, twelve_bit), 2048U);
  EXPECT_NEAR(code_to_volts(2048U, twelve_bit), 10.0 / 4095.0, 1e-12);
}

TEST(AnalogCodes, ValidityOfRanges) {
  EXPECT_TRUE(is_valid(AnalogRange{}));
  EXPECT_FALSE(is_valid(AnalogRange{1.0, 1.0, 10U}));
  EXPECT_FALSE(is_valid(AnalogRange{-1.0, 1.0, 0U}));
  EXPECT_FALSE(is_valid(AnalogRange{std::nan(""), 1.0, 10U}));
}

}  // namespace
}  // namespace crane::hardware_bridge
