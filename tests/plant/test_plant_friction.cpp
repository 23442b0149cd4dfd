// Stick-slip friction (3.1)-(3.3) of the simulated plant against analytic solutions.
//
// Exact single-axis cases:
//  * Slew axis with the trolley at x = 0 and the load hanging still (phi = theta = 0): the load sits on
//    the slew axis, so c_gamma = e_z x r = 0 and the slew decouples exactly from the load; the
//    trolley sees no centrifugal force at x = 0 and stays stuck. The slew obeys
//      J_o gamma_dd = J_o K (V - c - b gamma_d)    (volt-equivalent coefficients, gamma_d > 0)
//    i.e. gamma_dd = K (V - c) - K b gamma_d.
//  * Trolley axis with a massless load (load_mass = 0): M x_dd = M K (V - c - b x_d).
// Slew friction (4.15)-(4.16): b+ = 1.5, b- = 0.05, c+ = 0.7, c- = 0.6, fs+ = 0.7, fs- = 0.6; K = 1.14.
// Trolley friction (4.12)-(4.13): b+ = 1.5, c+ = 0.9, fs+ = 1.0; K = 2.0.
#include <gtest/gtest.h>

#include <cmath>

#include "crane/common/validation.hpp"
#include "crane/plant/axis_friction.hpp"
#include "crane/plant/crane_simulator.hpp"

namespace crane::plant {
namespace {

SimulatorParameters slew_case(double slew_rate) {
  SimulatorParameters p;
  p.initial_state.slew_rate = slew_rate;
  return p;
}

DriveInput released(double trolley_voltage, double slew_voltage) {
  DriveInput in;
  in.trolley_voltage = trolley_voltage;
  in.slew_voltage = slew_voltage;
  in.brakes_engaged = false;
  return in;
}

TEST(AxisFrictionModel, SlidingForceOpposesMotionWithDirectionDependentCoefficients) {
  const common::AxisFriction f{1.5, 6.0, 0.9, 1.2, 1.0, 1.2};
  const double scale = 10.0;  // [N/V]
  const AxisFrictionModel model(f, scale, 500.0);
  // v = +0.1: -(c+ + b+ v) * scale = -(0.9 + 0.15) * 10
  EXPECT_DOUBLE_EQ(model.sliding_force(0.1, 1, false), -10.5);
  // v = -0.1: +(c- + b- |v|) * scale = (1.2 + 0.6) * 10
  EXPECT_DOUBLE_EQ(model.sliding_force(-0.1, -1, false), 18.0);
  EXPECT_DOUBLE_EQ(model.sliding_force(0.1, 1, true), -510.5);
  EXPECT_EQ(model.motion_at_rest(9.9, false), 0);    // below fs+ = 10 N
  EXPECT_EQ(model.motion_at_rest(10.1, false), 1);   // breaks away toward +
  EXPECT_EQ(model.motion_at_rest(-11.9, false), 0);  // fs- = 12 N
  EXPECT_EQ(model.motion_at_rest(-12.1, false), -1);
  EXPECT_EQ(model.motion_at_rest(400.0, true), 0);   // brake holds
  EXPECT_THROW((void)AxisFrictionModel(common::AxisFriction{-1, 0, 0, 0, 0, 0}, 1.0, 0.0, "f"), common::ConfigError);
}

TEST(StickSlip, SlewBelowBreakawayStaysExactlyStill) {
  CraneSimulator sim(slew_case(0.0));
  for (int k = 0; k < 200; ++k) ASSERT_EQ(sim.step(released(0.0, 0.65)), common::StepStatus::ok);
  EXPECT_LT(sim.output().applied_slew_voltage, 0.7);
  EXPECT_EQ(sim.state().slew_angle, 0.0);
  EXPECT_EQ(sim.state().slew_rate, 0.0);
  EXPECT_EQ(sim.axis_mode(FrictionAxis::slew), AxisMode::stuck);
  EXPECT_EQ(sim.friction_event_count(), 0);
}

TEST(StickSlip, SlewAboveBreakawayFollowsExponentialApproach) {
  // gamma_d(t) = ((V - c)/b) (1 - exp(-K b t)),  gamma(t) = ((V - c)/b) (t - (1 - exp(-K b t))/(K b))
  CraneSimulator sim(slew_case(0.0));
  const double K = 1.14, b = 1.5, c = 0.7;
  for (int k = 1; k <= 200; ++k) {
    ASSERT_EQ(sim.step(released(0.0, 2.0)), common::StepStatus::ok);
    const double V = sim.output().applied_slew_voltage;  // after the DAC: 2.0 rounds to 819 codes
    const double t = sim.time();
    const double rate = (V - c) / b * (1.0 - std::exp(-K * b * t));
    const double angle = (V - c) / b * (t - (1.0 - std::exp(-K * b * t)) / (K * b));
    ASSERT_NEAR(sim.state().slew_rate, rate, 1e-7) << "t=" << t;
    ASSERT_NEAR(sim.state().slew_angle, angle, 1e-7) << "t=" << t;
  }
  EXPECT_EQ(sim.friction_event_count(), 1);  // the breakaway
  EXPECT_EQ(sim.last_friction_event().new_mode, AxisMode::slipping_positive);
  EXPECT_EQ(sim.last_friction_event().time, 0.0);  // at the first sample boundary
  EXPECT_EQ(sim.state().trolley_position, 0.0);
  EXPECT_EQ(sim.state().swing_out_of_plane, 0.0);
}

TEST(StickSlip, DeceleratingSlewStopsAtPredictedTimeAndStaysStuck) {
  // gamma_dd = -K c - K b gamma_d from gamma_d(0) = w0:
  //   gamma_d(t) = (w0 + c/b) exp(-K b t) - c/b,  stop at t* = ln(1 + b w0 / c) / (K b)
  //   gamma(t*) = (w0 + c/b)(1 - exp(-K b t*))/(K b) - (c/b) t*
  const double K = 1.14, b = 1.5, c = 0.7, w0 = 0.5;
  const double t_stop = std::log(1.0 + b * w0 / c) / (K * b);  // 0.4259 s, inside a sample
  const double angle_stop = (w0 + c / b) * (1.0 - std::exp(-K * b * t_stop)) / (K * b) - c / b * t_stop;
  CraneSimulator sim(slew_case(w0));
  for (int k = 0; k < 300; ++k) {
    ASSERT_EQ(sim.step(released(0.0, 0.0)), common::StepStatus::ok);
    if (sim.time() > t_stop) {
      ASSERT_EQ(sim.state().slew_rate, 0.0) << "chatter at t=" << sim.time();
      ASSERT_NEAR(sim.state().slew_angle, angle_stop, 1e-8);
    }
  }
  EXPECT_EQ(sim.friction_event_count(), 1);  // one stick, no chatter
  EXPECT_EQ(sim.last_friction_event().axis, FrictionAxis::slew);
  EXPECT_EQ(sim.last_friction_event().new_mode, AxisMode::stuck);
  EXPECT_NEAR(sim.last_friction_event().time, t_stop, 1e-6);
  std::printf("stop time %.9f s, predicted %.9f s\n", sim.last_friction_event().time, t_stop);
}

TEST(StickSlip, SlewReversesThroughZeroWithoutSticking) {
  // w0 = 0.5 with V = -2 (beyond fs- = 0.6): gamma_dd = K (V - c+) - K b+ gamma_d until the zero at
  //   t0 = ln(1 + b+ w0 / (c+ - V)) / (K b+);
  // then with gamma_d < 0 the friction is +(c- + b- |gamma_d|): gamma_dd = K (V + c-) - K b- gamma_d,
  //   gamma_d(t) = ((V + c-)/b-) (1 - exp(-K b- (t - t0))).
  const double K = 1.14, b_pos = 1.5, c_pos = 0.7, b_neg = 0.05, c_neg = 0.6, w0 = 0.5;
  CraneSimulator sim(slew_case(w0));
  for (int k = 0; k < 100; ++k) ASSERT_EQ(sim.step(released(0.0, -2.0)), common::StepStatus::ok);
  const double V = sim.output().applied_slew_voltage;
  const double t0 = std::log(1.0 + b_pos * w0 / (c_pos - V)) / (K * b_pos);
  const double rate = (V + c_neg) / b_neg * (1.0 - std::exp(-K * b_neg * (sim.time() - t0)));
  EXPECT_NEAR(sim.state().slew_rate, rate, 1e-7);
  EXPECT_EQ(sim.friction_event_count(), 0);  // a reversal is not a stick/breakaway event
  EXPECT_EQ(sim.axis_mode(FrictionAxis::slew), AxisMode::slipping_negative);
}

TEST(StickSlip, TrolleyWithMasslessLoadBreaksAwayAboveStaticThreshold) {
  // x_d(t) = ((V - c+)/b+) (1 - exp(-K b+ t)) with K = 2, b+ = 1.5, c+ = 0.9; fs+ = 1.0.
  SimulatorParameters p;
  p.crane.load_mass = 0.0;
  {
    CraneSimulator sim(p);
    for (int k = 0; k < 100; ++k) ASSERT_EQ(sim.step(released(0.98, 0.0)), common::StepStatus::ok);
    EXPECT_EQ(sim.state().trolley_position, 0.0);
    EXPECT_EQ(sim.axis_mode(FrictionAxis::trolley), AxisMode::stuck);
  }
  CraneSimulator sim(p);
  const double K = 2.0, b = 1.5, c = 0.9;
  for (int k = 0; k < 100; ++k) ASSERT_EQ(sim.step(released(1.5, 0.0)), common::StepStatus::ok);
  const double V = sim.output().applied_trolley_voltage;
  EXPECT_NEAR(sim.state().trolley_velocity, (V - c) / b * (1.0 - std::exp(-K * b * sim.time())), 1e-7);
}

TEST(Brakes, MovingAxisDeceleratesThenLocks) {
  // Brake force = 20 x the full-scale drive torque: the slew at 0.5 rad/s stops within
  // 0.5 / (K (20*10 + c)) = 2.2 ms, then stays locked.
  CraneSimulator sim(slew_case(0.5));
  DriveInput braked;  // brakes engaged, 0 V
  ASSERT_EQ(sim.step(braked), common::StepStatus::ok);
  EXPECT_EQ(sim.state().slew_rate, 0.0);
  EXPECT_EQ(sim.axis_mode(FrictionAxis::slew), AxisMode::stuck);
  EXPECT_LT(sim.last_friction_event().time, 0.0025);
  const double held = sim.state().slew_angle;
  for (int k = 0; k < 100; ++k) ASSERT_EQ(sim.step(DriveInput{0.0, 10.0, 0.0, true}), common::StepStatus::ok);
  EXPECT_EQ(sim.state().slew_angle, held);  // full voltage cannot move a braked axis
  EXPECT_EQ(sim.friction_event_count(), 1);
}

}  // namespace
}  // namespace crane::plant
