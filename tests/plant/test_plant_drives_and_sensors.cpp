// DAC quantization/saturation and encoder counting (section 4.1 of Omar 2003).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "crane/plant/drives_and_sensors.hpp"

namespace crane::plant {
namespace {

constexpr int kRandomSamples = 10000;

TEST(Dac, ThirteenBitsOverPlusMinusTenVolts) {
  const DrivesAndSensors io{common::CraneParameters{}};
  // 13 bits over 20 V: 8192 codes, step 20/8192 = 2.44140625 mV (exact in binary).
  EXPECT_DOUBLE_EQ(io.dac_step_voltage(), 20.0 / 8192.0);
  EXPECT_EQ(io.voltage_to_dac_code(0.0), 0);
  EXPECT_EQ(io.voltage_to_dac_code(1.0), 410);  // 1/0.00244140625 = 409.6 -> 410
  EXPECT_EQ(io.voltage_to_dac_code(-10.0), -4096);
  EXPECT_EQ(io.voltage_to_dac_code(10.0), 4095);   // +full scale is one code short
  EXPECT_EQ(io.voltage_to_dac_code(25.0), 4095);   // saturates
  EXPECT_EQ(io.voltage_to_dac_code(-25.0), -4096);
  EXPECT_EQ(io.voltage_to_dac_code(std::nan("")), 0);
  EXPECT_DOUBLE_EQ(io.dac_code_to_voltage(4095), 10.0 - 20.0 / 8192.0);
  EXPECT_DOUBLE_EQ(io.applied_voltage(-12.0), -10.0);
}

TEST(Dac, RoundTripAndHalfStepError) {
  const DrivesAndSensors io{common::CraneParameters{}};
  for (std::int32_t code = -4096; code <= 4095; ++code) {
    ASSERT_EQ(io.voltage_to_dac_code(io.dac_code_to_voltage(code)), code);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> voltage(-10.0, 10.0 - io.dac_step_voltage());
  for (int i = 0; i < kRandomSamples; ++i) {
    const double v = voltage(rng);
    ASSERT_LE(std::abs(io.applied_voltage(v) - v), 0.5 * io.dac_step_voltage() + 1e-15) << v;
  }
}

TEST(Encoders, ResolutionsFromLinesQuadratureGearAndPitch) {
  const common::CraneParameters p;
  const DrivesAndSensors io{p};
  // Trolley: 2000 lines x4 = 8000 counts per motor revolution; one revolution moves 0.5 in = 12.7 mm.
  EXPECT_NEAR(io.trolley_resolution(), 0.0127 / 8000.0, 1e-18);
  // Slew: 8000 counts per motor revolution x 45 motor revolutions per jib revolution.
  EXPECT_NEAR(io.slew_resolution(), 2.0 * std::numbers::pi / (8000.0 * 45.0), 1e-18);
  // Swing: 6000 lines x4 = 24000 counts per revolution.
  EXPECT_NEAR(io.swing_resolution(), 2.0 * std::numbers::pi / 24000.0, 1e-18);
  // 1 m of trolley travel = 1 / 1.5875e-6 = 629921.26 -> 629921 counts.
  EXPECT_EQ(io.trolley_position_to_encoder_counts(1.0), 629921);
  // floor for negative values: just below zero is count -1.
  EXPECT_EQ(io.swing_angle_to_encoder_counts(-0.5 * io.swing_resolution()), -1);
  EXPECT_EQ(io.swing_angle_to_encoder_counts(0.5 * io.swing_resolution()), 0);
}

TEST(Encoders, CountsRoundTripAndFloorConsistency) {
  const DrivesAndSensors io{common::CraneParameters{}};
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::int64_t> counts(-5'000'000, 5'000'000);
  std::uniform_real_distribution<double> position(-3.0, 3.0);
  for (int i = 0; i < kRandomSamples; ++i) {
    const std::int64_t n = counts(rng);
    ASSERT_EQ(io.trolley_position_to_encoder_counts(io.trolley_encoder_counts_to_position(n)), n);
    ASSERT_EQ(io.slew_angle_to_encoder_counts(io.slew_encoder_counts_to_angle(n)), n);
    ASSERT_EQ(io.swing_angle_to_encoder_counts(io.swing_encoder_counts_to_angle(n)), n);
    // position -> counts -> position lies within one count below the true value.
    const double x = position(rng);
    const double measured = io.trolley_encoder_counts_to_position(io.trolley_position_to_encoder_counts(x));
    ASSERT_LE(measured, x + 1e-9 * io.trolley_resolution());
    ASSERT_GT(measured, x - io.trolley_resolution());
  }
}

TEST(Encoders, MeasurementIsQuantized) {
  const DrivesAndSensors io{common::CraneParameters{}};
  const common::CraneMeasurement m = io.measure(0.123456789, 1.0, 0.05, -0.02, 1.3);
  EXPECT_EQ(m.trolley_position, io.trolley_encoder_counts_to_position(io.trolley_position_to_encoder_counts(0.123456789)));
  EXPECT_NE(m.trolley_position, 0.123456789);
  EXPECT_NEAR(m.slew_angle, 1.0, io.slew_resolution());
  EXPECT_NEAR(m.swing_in_plane, 0.05, io.swing_resolution());
  EXPECT_NEAR(m.swing_out_of_plane, -0.02, io.swing_resolution());
  EXPECT_EQ(m.cable_length, 1.3);
}

}  // namespace
}  // namespace crane::plant
