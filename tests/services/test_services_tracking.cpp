// Tests of the tracking controller core, (3.37)-(3.42).
#include <gtest/gtest.h>

#include <cmath>
#include <initializer_list>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/tracking/breakaway_ramp.hpp"
#include "crane/tracking/friction_factor_estimate.hpp"
#include "crane/tracking/friction_momentum_balance.hpp"
#include "crane/tracking/tracking_controller.hpp"

namespace tr = crane::tracking;
using crane::common::StepStatus;

namespace {
const double kT = 2.0 * std::numbers::pi * std::sqrt(1.0 / 9.8);  // 2.0071 s for L = 1 m
const double kT2 = kT * kT;                                        // 4.0284 s^2

tr::TrackingInput base_input() {
  tr::TrackingInput in;
  in.estimate.cable_length = 1.0;
  in.estimate.trolley_position = 0.5;
  in.reference.trolley.position = 0.5;
  in.estimate.slew_angle = 0.0;
  in.reference.slew.position = 0.0;
  return in;
}

// Each of `bad` set into the field by `set` is refused by FrictionFactorEstimate's constructor, the
// error naming `field`.
template <typename Set>
void expect_refused(std::initializer_list<double> bad, Set set, const std::string& field) {
  const crane::common::CraneParameters crane;
  for (const double value : bad) {
    tr::FrictionFactorParams p;
    set(p, value);
    try {
      tr::FrictionFactorEstimate refused(crane.trolley_friction, crane.slew_friction, p);
      ADD_FAILURE() << field << " = " << value << " accepted";
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
    }
  }
}
}  // namespace

TEST(TrackingController, TrolleyHandCase) {
  // L = 1, e = 0.01 m, e_dot = 0, phi = 0: V_xp = (1/L)(100*0.01) = 1 (3.40), V_bar_x = 1,
  // V_x = (1/K_mx)(L/T^2) V_bar_x = (1/2)(1/4.0284)(1) = 0.12412 V (3.37).
  tr::TrackingController controller(tr::TrackingParams{});
  auto in = base_input();
  in.reference.trolley.position = 0.51;
  tr::TrackingOutput out;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_tracking_action, 1.0, 1e-12);
  EXPECT_NEAR(out.command.trolley_voltage, 0.5 / kT2, 1e-12);
  EXPECT_NEAR(out.command.trolley_voltage, 0.12412, 1e-5);
  EXPECT_NEAR(out.swing_period, 2.0071, 1e-4);

  // Add phi = 0.05 rad: + m_t g phi / K_mx = 0.09*9.8*0.05/2 = 0.02205 V.
  in.estimate.swing_in_plane = 0.05;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.command.trolley_voltage, 0.5 / kT2 + 0.02205, 1e-12);

  // Velocity error 0.1 m/s, e = 0: V_xp = T K_dx e_dot / L = 2.0071*20*0.1 = 4.0142.
  in = base_input();
  in.reference.trolley.velocity = 0.1;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_tracking_action, kT * 20.0 * 0.1, 1e-12);

  // The anti-swing action adds in normalized units: V_bar_x = V_xp + V_xs.
  in = base_input();
  in.trolley_anti_swing_action = -9.0;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_normalized_action, -9.0, 1e-12);
  EXPECT_NEAR(out.command.trolley_voltage, 0.5 * -9.0 / kT2, 1e-12);
}

TEST(TrackingController, SlewHandCase338) {
  // L = 1, x = 0.9 m, gamma_ref - gamma = 0.01 rad, rates 0, theta = 0:
  // e_y_bar = -(x/L)(0.01) = -0.009, V_yp = 100*(-0.009) = -0.9,
  // V_gamma = (1/1.14)[-L(1 + 0.27*0.81)/(0.9 T^2)(-0.9)] = 1.2187/(1.14*4.0284) = 0.26538 V.
  tr::TrackingController controller(tr::TrackingParams{});
  auto in = base_input();
  in.estimate.trolley_position = 0.9;
  in.reference.trolley.position = 0.9;
  in.reference.slew.position = 0.01;
  tr::TrackingOutput out;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.slew_tracking_action, -0.9, 1e-12);
  const double expected = (1.0 + 0.27 * 0.81) / kT2 / 1.14;
  EXPECT_NEAR(out.command.slew_voltage, expected, 1e-12);
  EXPECT_NEAR(out.command.slew_voltage, 0.26538, 1e-5);

  // theta = 0.02 rad adds -m_r g x theta / K_mgamma = -0.28*9.8*0.9*0.02/1.14 = -0.043326 V
  // (x in metres, not x/L: with L = 2 the term is unchanged while (3.38)-as-printed would halve it).
  in.estimate.swing_out_of_plane = 0.02;
  in.reference.slew.position = 0.0;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.command.slew_voltage, -0.28 * 9.8 * 0.9 * 0.02 / 1.14, 1e-12);
  in.estimate.cable_length = 2.0;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_NEAR(out.command.slew_voltage, -0.28 * 9.8 * 0.9 * 0.02 / 1.14, 1e-12);
}

TEST(TrackingController, MinRadiusGuardAndClamp) {
  tr::TrackingController controller(tr::TrackingParams{});
  auto in = base_input();
  in.estimate.trolley_position = 0.0;  // on the slew axis: |x| floored at 0.1 m
  in.reference.trolley.position = 0.0;
  in.reference.slew.position = 0.01;
  tr::TrackingOutput out;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  // x = 0.1: V_yp = -100*0.1*0.01 = -0.1; V_gamma = (1+0.27*0.01)/(0.1 T^2)*0.1/1.14
  EXPECT_NEAR(out.command.slew_voltage, (1.0 + 0.27 * 0.01) / kT2 / 1.14, 1e-12);
  EXPECT_TRUE(std::isfinite(out.command.slew_voltage));

  in = base_input();
  in.reference.trolley.position = 1.5;  // e = 1 m -> V_x = 0.5*100/T^2 = 12.4 V > 10 V
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_EQ(out.command.trolley_voltage, 10.0);
  EXPECT_TRUE(out.trolley_saturated);
  in.reference.cable_length.velocity = -0.2;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_EQ(out.command.hoist_speed, -0.2);
}

TEST(TrackingController, NonFiniteRejected) {
  tr::TrackingController controller(tr::TrackingParams{});
  tr::TrackingOutput out;
  out.command.trolley_voltage = 3.0;
  auto in = base_input();
  in.estimate.swing_in_plane = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(controller.step(in, out), StepStatus::rejected_nonfinite);
  EXPECT_EQ(out.command.trolley_voltage, 0.0);
  in = base_input();
  in.slew_anti_swing_action = std::numeric_limits<double>::infinity();
  EXPECT_EQ(controller.step(in, out), StepStatus::rejected_nonfinite);
  in = base_input();
  in.reference.trolley.velocity = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(controller.step(in, out), StepStatus::rejected_nonfinite);
}

TEST(TrackingController, OverflowOfFiniteInputsGivesTheSafeOutput) {
  // Found by the topic-gates fuzzer (tests/fuzz): finite inputs every gate lets through, absurd in
  // size. x = 1e200 m: M_r x^2 = Inf in (3.38), so with the slew error e_y > 0 (V_bar_y > 0) the
  // feedback term -L (1 + M_r x^2)/(x T^2) V_bar_y is -Inf and the feedforward (1 + M_r x^2) gamma_ddot
  // is +Inf: V_gamma = NaN, which the clamp passed through as an "ok" voltage before the fix.
  tr::TrackingParams params;
  params.acceleration_feedforward = true;
  ASSERT_GT(params.trolley_inertia_ratio, 0.0);
  tr::TrackingController controller(params);
  auto in = base_input();
  in.estimate.trolley_position = 1e200;
  in.reference.trolley.position = 1e200;
  in.estimate.slew_angle = 0.1;  // e_y = -(x/L)(0 - 0.1) > 0
  in.reference.slew.acceleration = 1.0;
  tr::TrackingOutput out;
  out.command.trolley_voltage = 3.0;
  EXPECT_EQ(controller.step(in, out), StepStatus::rejected_nonfinite);
  EXPECT_EQ(out.command.trolley_voltage, 0.0);
  EXPECT_EQ(out.command.slew_voltage, 0.0);
  EXPECT_EQ(out.slew_tracking_action, 0.0);
  // The same crane a plausible distance out (x = 1 m) is an ordinary ok step with finite voltages.
  in.estimate.trolley_position = in.reference.trolley.position = 1.0;
  ASSERT_EQ(controller.step(in, out), StepStatus::ok);
  EXPECT_TRUE(std::isfinite(out.command.slew_voltage));
  EXPECT_NE(out.command.slew_voltage, 0.0);
}

TEST(TrackingController, BadParamsThrowNamingField) {
  auto expect_throw = [](const tr::TrackingParams& p, const std::string& field) {
    try {
      tr::TrackingController controller(p);
      FAIL() << "no throw for " << field;
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
    }
  };
  tr::TrackingParams p;
  p.trolley_drive_gain = 0.0;
  expect_throw(p, "trolley_drive_gain");
  p = {};
  p.min_radius = -1.0;
  expect_throw(p, "min_radius");
  p = {};
  p.proportional_gain = std::numeric_limits<double>::quiet_NaN();
  expect_throw(p, "proportional_gain");
  p = {};
  p.voltage_limit = 0.0;
  expect_throw(p, "voltage_limit");
}

TEST(TrackingController, ParamsFromCraneParameters) {
  const auto p = tr::tracking_params_from(crane::common::CraneParameters{});
  EXPECT_NEAR(p.mass_ratio, 0.09, 1e-4);
  EXPECT_NEAR(p.load_inertia_ratio, 0.28, 1e-3);
  EXPECT_NEAR(p.trolley_inertia_ratio, 0.27, 1e-3);
  EXPECT_EQ(p.trolley_drive_gain, 2.0);
  EXPECT_EQ(p.slew_drive_gain, 1.14);
}

// Acceleration feedforward (beyond (3.40)): the voltage grows by exactly a_ref / K_mx on the trolley
// and (1 + M_r x^2) gamma''_ref / K_mgamma on the slew, whatever the PD and anti-swing actions are.
TEST(TrackingController, AccelerationFeedforwardAddsTheReferenceAcceleration) {
  tr::TrackingParams params;
  params.voltage_limit = 1e3;  // no clamping in this comparison
  tr::TrackingParams with = params;
  with.acceleration_feedforward = true;
  const tr::TrackingController plain(params), feedforward(with);
  auto in = base_input();
  in.reference.trolley.acceleration = 0.9929;
  in.reference.slew.acceleration = -2.0796;
  in.estimate.trolley_position = 0.9;
  tr::TrackingOutput a, b;
  ASSERT_EQ(plain.step(in, a), crane::common::StepStatus::ok);
  ASSERT_EQ(feedforward.step(in, b), crane::common::StepStatus::ok);
  EXPECT_NEAR(b.command.trolley_voltage - a.command.trolley_voltage, 0.9929 / params.trolley_drive_gain, 1e-12);
  const double inertia = 1.0 + params.trolley_inertia_ratio * 0.9 * 0.9;
  EXPECT_NEAR(b.command.slew_voltage - a.command.slew_voltage, inertia * -2.0796 / params.slew_drive_gain, 1e-12);
  // Off by default: the dissertation's law.
  EXPECT_FALSE(tr::TrackingParams{}.acceleration_feedforward);
}

// The friction factor (friction_factor_estimate.hpp) from rows made by hand: the LQR's part of the
// voltage is (f - 1) F(v_ref) + c_j a_ref plus seeded noise, on both drive axes at once; f is
// recovered, an axis without rows (a gantry's second axis) leaves it solvable, too few rows give 1
// (or the prior a move was started with).
TEST(FrictionFactorEstimate, RecoversTheFrictionFactorFromTheFeedbackRows) {
  const crane::common::CraneParameters crane;
  // The model's sliding friction (3.1) by hand: c+ + b+ v, -c- + b- v.
  const auto sliding = [](const crane::common::AxisFriction& f, double v) {
    return v > 0.0 ? f.coulomb_positive + f.viscous_positive * v : -f.coulomb_negative + f.viscous_negative * v;
  };
  std::mt19937 random(7);
  std::normal_distribution<double> noise(0.0, 0.05);  // [V]
  for (const double f : {0.7, 1.0, 1.3}) {
    for (const bool second_axis : {true, false}) {
      tr::FrictionFactorEstimate estimate(crane.trolley_friction, crane.slew_friction);
      for (int k = 0; k < 250; ++k) {
        const double t = 0.01 * k;
        const double v = 0.4 * std::sin(std::numbers::pi * t / 2.5);      // [m/s] one direction, rest to rest
        const double a = 0.4 * std::numbers::pi / 2.5 * std::cos(std::numbers::pi * t / 2.5);
        const double u = (f - 1.0) * sliding(crane.trolley_friction, v) +
                         0.08 * a + noise(random);
        estimate.add(0, u, v, a);
        if (second_axis) {
          const double w = -0.9 * std::sin(std::numbers::pi * t / 2.5);  // [rad/s] the slew the other way
          const double b = -0.9 * std::numbers::pi / 2.5 * std::cos(std::numbers::pi * t / 2.5);
          estimate.add(1, (f - 1.0) * sliding(crane.slew_friction, w) - 0.3 * b +
                              noise(random), w, b);
        }
      }
      EXPECT_GT(estimate.rows(), 200);
      EXPECT_NEAR(estimate.factor(), f, 0.01) << "f " << f << " second axis " << second_axis;
    }
  }

  // Rows only where the reference slides, and finite; fewer than min_rows: the model's friction.
  tr::FrictionFactorEstimate sparse(crane.trolley_friction, crane.slew_friction);
  for (int k = 0; k < 100; ++k) sparse.add(0, 1.0, 0.01, 0.0);  // below min_reference_speed
  sparse.add(0, std::nan(""), 0.3, 0.0);
  sparse.add(1, 1.0, std::numeric_limits<double>::infinity(), 0.0);
  sparse.add(2, 1.0, 0.3, 0.0);  // no such axis
  EXPECT_EQ(sparse.rows(), 0);
  for (int k = 0; k < 19; ++k) sparse.add(0, 5.0, 0.3, 0.0);
  EXPECT_EQ(sparse.factor(), 1.0);
  sparse.add(0, 5.0, 0.3, 0.0);  // the 20th row: f = 1 + 5 / 1.35, clamped to max_factor
  EXPECT_EQ(sparse.factor(), tr::FrictionFactorParams{}.max_factor);
  sparse.reset();
  EXPECT_EQ(sparse.rows(), 0);
  EXPECT_EQ(sparse.factor(), 1.0);
  // A prior (the last move's factor) stands until the move has min_rows rows of its own, clamped to
  // [min_factor, max_factor]; not finite: the model's friction.
  sparse.reset(0.8);
  EXPECT_EQ(sparse.factor(), 0.8);
  for (int k = 0; k < 19; ++k) sparse.add(0, 0.0, 0.3, 0.0);
  EXPECT_EQ(sparse.factor(), 0.8);
  sparse.add(0, 0.0, 0.3, 0.0);  // the 20th row: no feedback left, f = 1
  EXPECT_NEAR(sparse.factor(), 1.0, 1e-12);
  sparse.reset(7.0);
  EXPECT_EQ(sparse.factor(), tr::FrictionFactorParams{}.max_factor);
  sparse.reset(0.1);
  EXPECT_EQ(sparse.factor(), tr::FrictionFactorParams{}.min_factor);
  sparse.reset(std::nan(""));
  EXPECT_EQ(sparse.factor(), 1.0);

  // Bad params name the field.
  const auto message = [&](const tr::FrictionFactorParams& p) {
    try {
      tr::FrictionFactorEstimate bad(crane.trolley_friction, crane.slew_friction, p);
    } catch (const crane::common::ConfigError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  tr::FrictionFactorParams p;
  p.min_rows = 2;
  EXPECT_NE(message(p).find("friction_factor.min_rows"), std::string::npos) << message(p);
  p = {};
  p.max_factor = 0.4;
  EXPECT_NE(message(p).find("friction_factor.max_factor"), std::string::npos) << message(p);
  p = {};
  p.min_reference_speed = 0.0;
  EXPECT_NE(message(p).find("friction_factor.min_reference_speed"), std::string::npos) << message(p);
}

// With max_standard_error (the PD law's estimate, tracking_stage.hpp) f is handed only once the rows
// know it: the standard error of theta_0 from their residuals, sigma^2 (Phi^T Phi)^-1_00. Rows of a
// plant of 0.7 with 1 V of noise (30 of them) leave the prior; 250 rows with 0.02 V give f.
TEST(FrictionFactorEstimate, AFactorNotKnownToWithinTheStandardErrorLeavesThePrior) {
  const crane::common::CraneParameters crane;
  tr::FrictionFactorParams params;
  params.max_standard_error = 0.06;
  const auto rows = [&](tr::FrictionFactorEstimate& estimate, int count, double sigma, unsigned seed) {
    std::mt19937 random(seed);
    std::normal_distribution<double> noise(0.0, sigma);
    for (int k = 0; k < count; ++k) {
      const double t = 0.01 * (k + 20);
      const double v = 0.4 * std::sin(std::numbers::pi * t / 2.5);
      const double a = 0.4 * std::numbers::pi / 2.5 * std::cos(std::numbers::pi * t / 2.5);
      const double f = crane.trolley_friction.coulomb_positive + crane.trolley_friction.viscous_positive * v;
      estimate.add(0, -0.3 * f + 0.08 * a + noise(random), v, a);
    }
  };
  tr::FrictionFactorEstimate noisy(crane.trolley_friction, crane.slew_friction, params);
  noisy.reset(0.9);
  rows(noisy, 30, 1.0, 3);
  EXPECT_EQ(noisy.rows(), 30);
  EXPECT_EQ(noisy.factor(), 0.9) << "not known: the prior";
  tr::FrictionFactorEstimate unchecked(crane.trolley_friction, crane.slew_friction);
  rows(unchecked, 30, 1.0, 3);
  EXPECT_NE(unchecked.factor(), 1.0) << "without the check the same rows give their f";
  tr::FrictionFactorEstimate quiet(crane.trolley_friction, crane.slew_friction, params);
  quiet.reset(0.9);
  rows(quiet, 230, 0.02, 5);
  EXPECT_NEAR(quiet.factor(), 0.7, 0.01);
  expect_refused({-0.1, std::numeric_limits<double>::quiet_NaN()},
                 [](tr::FrictionFactorParams& p, double v) { p.max_standard_error = v; },
                 "friction_factor.max_standard_error");
}

// With a resolution (the PD law's, 0.01) the factor is handed to the nearest multiple of it; a
// resolution outside [0, 0.1] is refused, naming it.
TEST(FrictionFactorEstimate, TheResolutionRoundsTheFactor) {
  const crane::common::CraneParameters crane;
  tr::FrictionFactorParams params;
  params.min_rows = 3;
  tr::FrictionFactorEstimate fine(crane.trolley_friction, crane.slew_friction, params);
  params.resolution = 0.01;
  tr::FrictionFactorEstimate rounded(crane.trolley_friction, crane.slew_friction, params);
  for (const double friction : {1.0, 2.0, 1.5}) {  // y = -0.0037 F: f = 0.9963
    fine.add_row(0, -0.0037 * friction, friction, 0.0);
    rounded.add_row(0, -0.0037 * friction, friction, 0.0);
  }
  EXPECT_NEAR(fine.factor(), 0.9963, 1e-9);
  EXPECT_NEAR(rounded.factor(), 1.0, 1e-12);
  // One more row, y = -0.6 V at F = 3 V: f = 1 - (0.0037 x 7.25 + 1.8) / 16.25 = 0.8876, handed 0.89.
  fine.add_row(0, -0.6, 3.0, 0.0);
  rounded.add_row(0, -0.6, 3.0, 0.0);
  EXPECT_NEAR(fine.factor(), 1.0 - (0.0037 * 7.25 + 1.8) / 16.25, 1e-9);
  EXPECT_NEAR(rounded.factor(), 0.89, 1e-12);
  expect_refused({-0.01, 0.2, std::numeric_limits<double>::quiet_NaN()},
                 [](tr::FrictionFactorParams& p, double v) { p.resolution = v; }, "friction_factor.resolution");
}

// The momentum balance's rows by hand, with the estimator's lag taken as none (B = G = 1): then
// H(z) = (z^-1 + z^-2)/2, a block sums T H[u] and H[F] and takes the momentum's change from the
// cycle before its first; a stretch's rest closes at its first cycle that does not slide; a
// non-finite input drops the open block; a bad block length is refused, naming it.
TEST(FrictionMomentumBalance, RowsByHand) {
  const crane::state_estimator::DiscreteTransferFunction none{};
  tr::FrictionMomentumBalance balance(none, none, 0.01, 3);
  // At rest before: u = 2 V, F = 0, p = 0.1 V s (initialises the filters on the first cycle).
  EXPECT_FALSE(balance.step(2.0, 0.0, 0.1, false));
  EXPECT_FALSE(balance.step(2.0, 0.0, 0.1, false));
  // Sliding: u = 4 V, F = 1 V from here; H delays them by 1.5 cycles.
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.2, true));  // H[u] = (2 + 2)/2, H[F] = 0
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.3, true));  // (4 + 2)/2, (1 + 0)/2
  const auto row = balance.step(4.0, 1.0, 0.4, true);  // (4 + 4)/2, 1
  ASSERT_TRUE(row);
  EXPECT_NEAR(row->balance, 0.01 * (2.0 + 3.0 + 4.0) - (0.4 - 0.1), 1e-12);
  EXPECT_NEAR(row->friction, 0.01 * (0.0 + 0.5 + 1.0), 1e-12);
  // Two more sliding cycles, then the stretch ends: a row of two, to the last sliding cycle's p.
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.5, true));
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.7, true));
  const auto rest = balance.step(4.0, 1.0, 9.0, false);
  ASSERT_TRUE(rest);
  EXPECT_NEAR(rest->balance, 0.01 * (4.0 + 4.0) - (0.7 - 0.4), 1e-12);
  EXPECT_NEAR(rest->friction, 0.02, 1e-12);
  // A NaN drops the open block: the cycles before it make no row.
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.1, true));
  EXPECT_FALSE(balance.step(4.0, 1.0, std::numeric_limits<double>::quiet_NaN(), true));
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.1, true));
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.1, true));
  EXPECT_TRUE(balance.step(4.0, 1.0, 0.1, true)) << "three cycles after the NaN";
  // So does a new move (drop_block).
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.1, true));
  balance.drop_block();
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.1, true));
  EXPECT_FALSE(balance.step(4.0, 1.0, 0.1, true));
  EXPECT_TRUE(balance.step(4.0, 1.0, 0.1, true));
  for (const int cycles : {0, -1}) {
    try {
      tr::FrictionMomentumBalance refused(none, none, 0.01, cycles);
      ADD_FAILURE() << cycles << " accepted";
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find("block_cycles"), std::string::npos) << error.what();
    }
  }
}

// The breakaway ramp by hand (breakaway_ramp.hpp): 100 Hz, deadband 3 mm, at rest below 5 mm/s for
// 0.1 s (10 cycles), then 2 V/s (0.02 V a cycle) toward the target, at most 1 V.
TEST(BreakawayRamp, RampsADriveStuckOffTheTargetTowardItAndForgetsItInsideTheBand) {
  tr::BreakawayRamp ramp{tr::BreakawayRampParams{}, 0.01};
  // Stuck 7 mm past the target: nothing for 9 cycles, then -0.02 V more each cycle.
  for (int k = 1; k <= 9; ++k) EXPECT_EQ(ramp.step(0, 0.007, 0.001), 0.0) << k;
  EXPECT_NEAR(ramp.step(0, 0.007, -0.001), -0.02, 1e-15);
  EXPECT_NEAR(ramp.step(0, 0.007, 0.0), -0.04, 1e-15);
  // The other axis is its own: short of the target on the slew, the ramp is positive.
  for (int k = 1; k <= 9; ++k) EXPECT_EQ(ramp.step(1, -0.004, 0.0), 0.0) << k;
  EXPECT_NEAR(ramp.step(1, -0.004, 0.0), 0.02, 1e-15);
  // Moving (>= 5 mm/s): held, and the rest count starts again.
  EXPECT_NEAR(ramp.step(0, 0.006, -0.02), -0.04, 1e-15);
  for (int k = 1; k <= 9; ++k) EXPECT_NEAR(ramp.step(0, 0.006, 0.0), -0.04, 1e-15) << k;
  EXPECT_NEAR(ramp.step(0, 0.006, 0.0), -0.06, 1e-15);
  // Clamped at 1 V.
  double r = 0.0;
  for (int k = 0; k < 100; ++k) r = ramp.step(0, 0.006, 0.0);
  EXPECT_EQ(r, -1.0);
  // Inside the band: 0, forgotten; outside again, 10 cycles at rest before it ramps.
  EXPECT_EQ(ramp.step(0, 0.0029, 0.0), 0.0);
  for (int k = 1; k <= 9; ++k) EXPECT_EQ(ramp.step(0, 0.006, 0.0), 0.0) << k;
  EXPECT_NEAR(ramp.step(0, 0.006, 0.0), -0.02, 1e-15);
  // A non-finite input resets the axis and gives 0 V; reset() forgets both axes.
  EXPECT_EQ(ramp.step(0, std::numeric_limits<double>::quiet_NaN(), 0.0), 0.0);
  EXPECT_EQ(ramp.step(0, 0.006, 0.0), 0.0);
  EXPECT_EQ(ramp.step(1, 0.006, std::numeric_limits<double>::infinity()), 0.0);
  ramp.reset();
  EXPECT_EQ(ramp.step(1, -0.004, 0.0), 0.0);
  EXPECT_EQ(ramp.step(2, 0.1, 0.0), 0.0) << "no third axis";

  // Bad params name the field.
  const auto message = [](const tr::BreakawayRampParams& p, double period) {
    try {
      tr::BreakawayRamp bad(p, period);
    } catch (const crane::common::ConfigError& error) {
      return std::string(error.what());
    }
    return std::string("no error");
  };
  tr::BreakawayRampParams p;
  p.deadband = 0.0;
  EXPECT_NE(message(p, 0.01).find("breakaway.deadband"), std::string::npos) << message(p, 0.01);
  p = {};
  p.rate = -1.0;
  EXPECT_NE(message(p, 0.01).find("breakaway.rate"), std::string::npos) << message(p, 0.01);
  p = {};
  p.limit = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(message(p, 0.01).find("breakaway.limit"), std::string::npos) << message(p, 0.01);
  p = {};
  p.rest_time = -0.1;
  EXPECT_NE(message(p, 0.01).find("breakaway.rest_time"), std::string::npos) << message(p, 0.01);
  EXPECT_NE(message({}, 0.0).find("breakaway.sample_period"), std::string::npos) << message({}, 0.0);
}
