// Simulator facade: exact sample landing, configuration errors, non-finite input, hoist kinematics.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <limits>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/plant/tower_crane_model.hpp"
#include "crane/plant/hybrid_integrator.hpp"

namespace crane::plant {
namespace {

void expect_config_error(const SimulatorParameters& p, const std::string& field) {
  try {
    CraneSimulator sim(p);
    ADD_FAILURE() << "no ConfigError for " << field;
  } catch (const common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
  }
}

TEST(Configuration, BadParametersThrowNamingTheField) {
  SimulatorParameters p;
  p.sample_period = 0.0;
  expect_config_error(p, "simulator.sample_period");
  p = {};
  p.integrator.relative_tolerance = std::nan("");
  expect_config_error(p, "simulator.integrator.relative_tolerance");
  p = {};
  p.crane.load_mass = -1.0;
  expect_config_error(p, "simulator.crane.load_mass");
  p = {};
  p.crane.slew_friction.coulomb_positive = -0.1;
  expect_config_error(p, "simulator.crane.slew_friction.coulomb_positive");
  p = {};
  p.crane.max_cable_length = 0.1;
  expect_config_error(p, "simulator.crane.max_cable_length");
  p = {};
  p.initial_state.cable_length = 5.0;
  expect_config_error(p, "simulator.initial_state.cable_length");
  p = {};
  p.initial_state.swing_in_plane = 2.0;
  expect_config_error(p, "simulator.initial_state.swing_in_plane");
  p = {};
  p.hoist_max_acceleration = 0.0;
  expect_config_error(p, "simulator.hoist_max_acceleration");
}

TEST(Sampling, LandsExactlyOnEverySampleTimeAcrossEvents) {
  // Integrator level: arbitrary end times are hit bit-exactly even when friction events (a stick at
  // 0.426 s) fall inside an interval.
  common::CraneParameters crane;
  const TowerCraneModel model(crane);
  const double torque_per_volt = crane.jib_inertia * crane.slew_drive_gain;
  HybridIntegrator integrator(model,
                             AxisFrictionModel(crane.trolley_friction, crane.trolley_drive_mass * crane.trolley_drive_gain, 0.0),
                             AxisFrictionModel(crane.slew_friction, torque_per_volt, 0.0), IntegratorSettings{});
  ModelState s;
  s.velocity[kSlewIndex] = 0.5;
  integrator.reset(0.0, s, 1.0, 0.0);
  double end = 0.0;
  for (int k = 1; k <= 100; ++k) {
    end = 0.0137 * k;
    ASSERT_EQ(integrator.advance_to(end, SampleInput{}), IntegrationStatus::ok);
    ASSERT_EQ(integrator.time(), end);
  }
  EXPECT_EQ(integrator.friction_event_count(), 1);
  EXPECT_EQ(integrator.advance_to(end, SampleInput{}), IntegrationStatus::invalid_request);

  // Simulator level: time is k * sample_period, state changes every sample.
  CraneSimulator sim(SimulatorParameters{});
  for (int k = 1; k <= 50; ++k) {
    ASSERT_EQ(sim.step(DriveInput{3.0, 0.0, 0.0, false}), common::StepStatus::ok);
    ASSERT_EQ(sim.time(), k * 0.01);
  }
  EXPECT_GT(sim.state().trolley_position, 0.0);
}

TEST(Input, NonFiniteInputIsRejectedAndSafeInputApplied) {
  CraneSimulator sim(SimulatorParameters{});
  ASSERT_EQ(sim.step(DriveInput{5.0, 5.0, 0.0, false}), common::StepStatus::ok);
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(sim.step(DriveInput{std::nan(""), 1.0, 0.0, false}), common::StepStatus::rejected_nonfinite);
  SimulatorOutput out = sim.output();
  EXPECT_EQ(out.applied_trolley_voltage, 0.0);
  EXPECT_EQ(out.applied_slew_voltage, 0.0);
  EXPECT_TRUE(out.brakes_engaged);
  EXPECT_EQ(sim.step(DriveInput{0.0, 0.0, inf, false}), common::StepStatus::rejected_nonfinite);
  EXPECT_EQ(sim.step(DriveInput{0.0, 0.0, 0.0, false}), common::StepStatus::ok);
  EXPECT_TRUE(std::isfinite(sim.state().trolley_position));
  // The brakes held during the rejected samples: both axes stopped within the first of them.
  EXPECT_EQ(sim.state().trolley_velocity, 0.0);
  EXPECT_EQ(sim.state().slew_rate, 0.0);
}

TEST(Hoist, RateLimitedSpeedCommandAndLengthLimits) {
  // a_max = 0.5 m/s^2, command 0.2 m/s: the rate ramps for 0.4 s, so after 2 s
  //   L = L0 + 0.2 * 2 - 0.2^2 / (2 * 0.5) = L0 + 0.36.
  SimulatorParameters p;
  CraneSimulator sim(p);
  for (int k = 0; k < 200; ++k) ASSERT_EQ(sim.step(DriveInput{0.0, 0.0, 0.2, true}), common::StepStatus::ok);
  EXPECT_NEAR(sim.state().cable_length, 1.36, 1e-7);  // L is integrated by the solver (atol 1e-11/step)
  EXPECT_NEAR(sim.output().applied_hoist_speed, 0.2, 1e-12);
  // Keep lowering: the length stops at max_cable_length (up to a discrete overshoot).
  for (int k = 0; k < 2000; ++k) ASSERT_EQ(sim.step(DriveInput{0.0, 0.0, 0.5, true}), common::StepStatus::ok);
  EXPECT_NEAR(sim.state().cable_length, p.crane.max_cable_length, p.hoist_max_acceleration * 0.01 * 0.01);
  EXPECT_EQ(sim.state().cable_length_rate, 0.0);
  EXPECT_EQ(sim.integrator_failure_count(), 0);
}

// Property test: seeded random drive commands (held 0.05-0.5 s, +-3 V, brakes toggling, hoist
// moving) never make the integrator fail, keep the state finite and the swing bounded, and a stuck
// axis always reports exactly zero velocity. Reports the worst step time (not a benchmark).
constexpr int kRandomRunSeconds = 60;

TEST(Robustness, RandomDriveCommandsNeverFailTheIntegrator) {
  CraneSimulator sim(SimulatorParameters{});
  std::mt19937 rng(1234);
  std::uniform_real_distribution<double> voltage(-3.0, 3.0), hold(0.05, 0.5), hoist(-0.3, 0.3);
  std::bernoulli_distribution brake(0.2);
  DriveInput input;
  double next_change = 0.0, worst_step_seconds = 0.0, worst_swing = 0.0;
  while (sim.time() < kRandomRunSeconds) {
    if (sim.time() >= next_change) {
      input = DriveInput{voltage(rng), voltage(rng), hoist(rng), brake(rng)};
      next_change = sim.time() + hold(rng);
    }
    const auto start = std::chrono::steady_clock::now();
    const common::StepStatus status = sim.step(input);
    worst_step_seconds = std::max(worst_step_seconds,
                                  std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    ASSERT_EQ(status, common::StepStatus::ok) << "t=" << sim.time();
    const PlantState& s = sim.state();
    ASSERT_TRUE(std::isfinite(s.trolley_position) && std::isfinite(s.slew_rate) && std::isfinite(s.swing_in_plane));
    worst_swing = std::max({worst_swing, std::abs(s.swing_in_plane), std::abs(s.swing_out_of_plane)});
    ASSERT_LT(std::abs(s.swing_out_of_plane), 1.4);  // away from the coordinate singularity theta = pi/2
    if (sim.axis_mode(FrictionAxis::trolley) == AxisMode::stuck) {
      ASSERT_EQ(s.trolley_velocity, 0.0);
    }
    if (sim.axis_mode(FrictionAxis::slew) == AxisMode::stuck) {
      ASSERT_EQ(s.slew_rate, 0.0);
    }
  }
  EXPECT_EQ(sim.integrator_failure_count(), 0);
  EXPECT_GT(sim.friction_event_count(), 10);
  std::printf("%d s: %ld friction events, largest swing %.3f rad, worst step %.3f ms\n", kRandomRunSeconds,
              sim.friction_event_count(), worst_swing, 1e3 * worst_step_seconds);
}

TEST(Reset, RestartsAtGivenStateAndTimeZero) {
  CraneSimulator sim(SimulatorParameters{});
  for (int k = 0; k < 10; ++k) ASSERT_EQ(sim.step(DriveInput{4.0, 0.0, 0.0, false}), common::StepStatus::ok);
  PlantState s;
  s.trolley_position = 0.4;
  s.swing_in_plane = 0.1;
  sim.reset(s);
  EXPECT_EQ(sim.time(), 0.0);
  EXPECT_EQ(sim.state().trolley_position, 0.4);
  EXPECT_EQ(sim.state().swing_in_plane, 0.1);
  s.cable_length = -1.0;
  EXPECT_THROW(sim.reset(s), common::ConfigError);
}

}  // namespace
}  // namespace crane::plant
