// Tests of friction compensation (3.1)-(3.5) with the coefficients (4.12)-(4.16).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"

namespace fc = crane::friction_compensation;
using crane::common::StepStatus;

namespace {
fc::FrictionCompensationInput input(double trolley_velocity_raw, double trolley_voltage,
                                    double slew_rate = 0.0, double slew_voltage = 0.0) {
  fc::FrictionCompensationInput in;
  in.estimate.trolley_velocity_raw = trolley_velocity_raw;
  in.estimate.trolley_velocity = 123.0;  // must not be used for the trolley by default
  in.estimate.slew_rate = slew_rate;
  in.estimate.slew_rate_raw = 456.0;     // must not be used for the slew by default
  in.command.trolley_voltage = trolley_voltage;
  in.command.slew_voltage = slew_voltage;
  return in;
}
}  // namespace

TEST(FrictionCompensation, TrolleyPositiveVelocity) {
  // v = 0.2 > d_s: F/K_m = c+ + b+ v = 0.9 + 1.5*0.2 = 1.2 V (4.12), with the motion.
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  fc::FrictionCompensationOutput out;
  ASSERT_EQ(comp.step(input(0.2, 0.5), out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, 1.2, 1e-12);
  EXPECT_NEAR(out.command.trolley_voltage, 1.7, 1e-12);
}

TEST(FrictionCompensation, TrolleyNegativeVelocity) {
  // v = -0.2: -(c- + b- |v|) = -(1.2 + 6*0.2) = -2.4 V.
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  fc::FrictionCompensationOutput out;
  ASSERT_EQ(comp.step(input(-0.2, -0.5), out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, -2.4, 1e-12);
  EXPECT_NEAR(out.command.trolley_voltage, -2.9, 1e-12);
}

TEST(FrictionCompensation, StictionInZeroVelocityBand) {
  // |v| < d_s: f_sh + f_s tanh(A V), f_s = (1.0+1.2)/2 = 1.1, f_sh = (1.0-1.2)/2 = -0.1:
  // large +V -> +1.0 = fs+/K_m, large -V -> -1.2 = -fs-/K_m (4.13); V = 0 -> f_sh = -0.1.
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  fc::FrictionCompensationOutput out;
  ASSERT_EQ(comp.step(input(0.0, 2.0), out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, 1.0, 1e-9);
  ASSERT_EQ(comp.step(input(0.005, -2.0), out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, -1.2, 1e-9);
  ASSERT_EQ(comp.step(input(0.0, 0.0), out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, -0.1, 1e-12);
  // Hand value inside the slope: V = 0.01, A = 20: -0.1 + 1.1 tanh(0.2) = 0.117004
  ASSERT_EQ(comp.step(input(0.0, 0.01), out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, -0.1 + 1.1 * std::tanh(0.2), 1e-12);
  // Slew (4.15): large +V -> 0.7, large -V -> -0.6.
  ASSERT_EQ(comp.step(input(0.0, 0.0, 0.0, 3.0), out), StepStatus::ok);
  EXPECT_NEAR(out.slew_friction, 0.7, 1e-9);
  ASSERT_EQ(comp.step(input(0.0, 0.0, 0.0, -3.0), out), StepStatus::ok);
  EXPECT_NEAR(out.slew_friction, -0.6, 1e-9);
}

// The follower's sliding friction reduction (LinearCommand.sliding_friction_reduction): the sliding
// part (3.1) scaled by 1 - r on every axis outside the zero-velocity band, the stiction part (3.2)
// kept; outside [0, 1] refused with the safe output.
TEST(FrictionCompensation, TheSlidingReductionScalesTheSlidingPartAndKeepsStiction) {
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  fc::FrictionCompensationOutput out;
  auto in = input(0.2, 0.5, 0.0, 3.0);  // trolley sliding, slew at rest
  in.sliding_friction_reduction = 0.25;
  ASSERT_EQ(comp.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, 0.75 * 1.2, 1e-12);      // (4.12): 0.9 + 1.5 x 0.2
  EXPECT_NEAR(out.command.trolley_voltage, 0.5 + 0.9, 1e-12);
  EXPECT_NEAR(out.slew_friction, 0.7, 1e-9);                 // stiction (4.15), whole
  in.sliding_friction_reduction = 1.0;
  ASSERT_EQ(comp.step(in, out), StepStatus::ok);
  EXPECT_EQ(out.trolley_friction, 0.0);
  for (const double bad : {-0.1, 1.01, std::nan("")}) {
    in.sliding_friction_reduction = bad;
    ASSERT_EQ(comp.step(in, out), StepStatus::rejected_nonfinite) << bad;
    EXPECT_EQ(out.command.trolley_voltage, 0.0);
    EXPECT_EQ(out.command.slew_voltage, 0.0);
  }
}

// The follower's friction factor at the target (LinearCommand.friction_factor, the plant's friction
// over the model's as the tracking stage estimates it): the stiction part (3.2) at rest multiplied by
// it, the sliding part kept by min(1, (1 - r) f); 0 leaves the compensation as configured; negative,
// NaN or above 100 refused with the safe output.
TEST(FrictionCompensation, TheFrictionFactorScalesStictionAndTheSlidingPartKept) {
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  fc::FrictionCompensationOutput out;
  auto in = input(0.2, 0.5, 0.0, 3.0);  // trolley sliding, slew at rest
  in.sliding_friction_reduction = 0.3;
  in.friction_factor = 1.3;
  ASSERT_EQ(comp.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, 0.7 * 1.3 * 1.2, 1e-12);  // (4.12): 0.9 + 1.5 x 0.2
  EXPECT_NEAR(out.slew_friction, 1.3 * 0.7, 1e-9);            // stiction (4.15) x 1.3
  in.friction_factor = 2.0;                                   // the sliding part at most whole
  ASSERT_EQ(comp.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, 1.2, 1e-12);
  EXPECT_NEAR(out.slew_friction, 2.0 * 0.7, 1e-9);
  in.friction_factor = 0.0;  // unset: only the reduction
  ASSERT_EQ(comp.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, 0.7 * 1.2, 1e-12);
  EXPECT_NEAR(out.slew_friction, 0.7, 1e-9);
  for (const double bad : {-0.1, 100.5, std::nan(""), std::numeric_limits<double>::infinity()}) {
    in.friction_factor = bad;
    ASSERT_EQ(comp.step(in, out), StepStatus::rejected_nonfinite) << bad;
    EXPECT_EQ(out.command.trolley_voltage, 0.0);
    EXPECT_EQ(out.command.slew_voltage, 0.0);
  }
}

TEST(FrictionCompensation, SlewUsesFilteredRateByDefault) {
  // Slew rate 0.5 rad/s (filtered): c+ + b+ w = 0.7 + 1.5*0.5 = 1.45 V (4.16); -0.5: -(0.6+0.025).
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  fc::FrictionCompensationOutput out;
  ASSERT_EQ(comp.step(input(0.0, 0.0, 0.5, 1.0), out), StepStatus::ok);
  EXPECT_NEAR(out.slew_friction, 1.45, 1e-12);
  ASSERT_EQ(comp.step(input(0.0, 0.0, -0.5, 1.0), out), StepStatus::ok);
  EXPECT_NEAR(out.slew_friction, -0.625, 1e-12);
  // Switch the trolley to the filtered velocity (123 m/s in the fixture): saturates.
  fc::FrictionCompensationParams p;
  p.trolley.velocity_source = fc::VelocitySource::filtered;
  fc::FrictionCompensation filtered(p);
  ASSERT_EQ(filtered.step(input(0.0, 0.0), out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_friction, 0.9 + 1.5 * 123.0, 1e-9);
  EXPECT_EQ(out.command.trolley_voltage, 10.0);
  EXPECT_TRUE(out.trolley_saturated);
}

TEST(FrictionCompensation, DisabledPassesThroughAndClamps) {
  fc::FrictionCompensationParams p;
  p.enabled = false;
  fc::FrictionCompensation comp(p);
  fc::FrictionCompensationOutput out;
  auto in = input(0.3, 0.7, 0.2, -12.0);
  in.command.hoist_speed = 0.1;
  ASSERT_EQ(comp.step(in, out), StepStatus::ok);
  EXPECT_EQ(out.command.trolley_voltage, 0.7);
  EXPECT_EQ(out.trolley_friction, 0.0);
  EXPECT_EQ(out.command.slew_voltage, -10.0);
  EXPECT_TRUE(out.slew_saturated);
  EXPECT_EQ(out.command.hoist_speed, 0.1);
}

TEST(FrictionCompensation, NonFiniteRejected) {
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  fc::FrictionCompensationOutput out;
  EXPECT_EQ(comp.step(input(std::numeric_limits<double>::quiet_NaN(), 1.0), out),
            StepStatus::rejected_nonfinite);
  EXPECT_EQ(out.command.trolley_voltage, 0.0);
  EXPECT_EQ(comp.step(input(0.0, std::numeric_limits<double>::infinity()), out),
            StepStatus::rejected_nonfinite);
  // A NaN in a velocity the configuration does not use is ignored (slew_rate_raw here).
  auto in = input(0.0, 1.0);
  in.estimate.slew_rate_raw = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(comp.step(in, out), StepStatus::ok);
}

TEST(FrictionCompensation, OverflowOfFiniteInputsGivesTheSafeOutput) {
  // Found by the topic-gates fuzzer (tests/fuzz, regression-compensation-overflowing-friction): a
  // foreign CraneState_ flagged the slew friction as re-estimated with a viscous coefficient of
  // 8e283 V s/rad, every coefficient finite and >= 0, and a slew rate of -1.6e202 rad/s: b- |v| is
  // Inf, so the stage wrote slew_friction_voltage = -Inf with status ok before the fix (the clamp
  // passed -10 V on, the next node's gate refuses the sample).
  fc::FrictionCompensation comp(fc::FrictionCompensationParams{});
  auto in = input(0.0, 1.0, -1.6e202, 0.5);
  crane::common::AxisFriction absurd = fc::FrictionCompensationParams{}.slew.friction;
  absurd.viscous_negative = 8e283;
  in.slew_friction = absurd;
  fc::FrictionCompensationOutput out;
  out.command.slew_voltage = 3.0;
  EXPECT_EQ(comp.step(in, out), StepStatus::rejected_nonfinite);
  EXPECT_EQ(out.command.trolley_voltage, 0.0);
  EXPECT_EQ(out.command.slew_voltage, 0.0);
  EXPECT_EQ(out.slew_friction, 0.0);
  // The same estimate at a plausible rate is an ordinary step: large but finite, clamped.
  in.estimate.slew_rate = -0.2;
  ASSERT_EQ(comp.step(in, out), StepStatus::ok);
  EXPECT_TRUE(std::isfinite(out.slew_friction));
  EXPECT_EQ(out.command.slew_voltage, -fc::FrictionCompensationParams{}.voltage_limit);
}

TEST(FrictionCompensation, BadParamsThrowNamingField) {
  auto expect_throw = [](const fc::FrictionCompensationParams& p, const std::string& field) {
    try {
      fc::FrictionCompensation comp(p);
      FAIL() << "no throw for " << field;
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
    }
  };
  fc::FrictionCompensationParams p;
  p.trolley.friction.coulomb_positive = -0.1;
  expect_throw(p, "trolley.friction.coulomb_positive");
  p = {};
  p.slew.stiction_slope = 0.0;
  expect_throw(p, "slew.stiction_slope");
  p = {};
  p.trolley.zero_velocity_band = std::numeric_limits<double>::quiet_NaN();
  expect_throw(p, "trolley.zero_velocity_band");
  p = {};
  p.voltage_limit = -1.0;
  expect_throw(p, "voltage_limit");
}
