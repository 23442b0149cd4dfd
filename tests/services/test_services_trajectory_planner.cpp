// Tests of the trajectory planner core: trapezoid (3.43) against the maneuvers (3.54)-(3.55).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace tp = crane::trajectory_planner;
using crane::common::CraneStateEstimate;
using crane::common::StepStatus;

namespace {
const double kPeriodL1 = 2.0 * std::numbers::pi * std::sqrt(1.0 / 9.8);  // T = 2.0071 s for L = 1 m

CraneStateEstimate at(double x, double gamma, double length) {
  CraneStateEstimate e;
  e.trolley_position = x;
  e.slew_angle = gamma;
  e.cable_length = length;
  return e;
}
}  // namespace

TEST(TrapezoidProfile, TrolleyManeuver354) {
  // (3.54): Z = 0.75 m, v_max = 0.4982, a_max = 0.9929 -> t_f = 0.75/0.4982 + 0.4982/0.9929
  // = 1.50542 + 0.50176 = 2.0072 s, one swing period T = 2 pi sqrt(1/9.8) = 2.0071 s.
  tp::TrapezoidProfile profile(0.25, 1.0, {0.4982, 0.9929});
  EXPECT_NEAR(profile.duration(), 0.75 / 0.4982 + 0.4982 / 0.9929, 1e-12);
  EXPECT_NEAR(profile.duration(), 2.0071, 2e-4);
  EXPECT_NEAR(profile.duration(), kPeriodL1, 2e-4);
  EXPECT_NEAR(profile.acceleration_time(), kPeriodL1 / 4.0, 2e-4);  // Delta t = T/4
  // And the inverse: the limits printed in (3.54) follow from Z, t_f = T, Delta t = T/4.
  const auto limits = tp::TrapezoidProfile::limits_for_duration(0.75, kPeriodL1, kPeriodL1 / 4.0);
  EXPECT_NEAR(limits.max_velocity, 0.4982, 5e-5);
  EXPECT_NEAR(limits.max_acceleration, 0.9929, 5e-5);
}

TEST(TrapezoidProfile, SlewManeuver355) {
  // (3.55): Z = 90 deg = pi/2, v_max = 1.0435 rad/s, a_max = 2.0796 rad/s^2 -> t_f = 1.5053 +
  // 0.5018 = 2.0071 s.
  tp::TrapezoidProfile profile(0.0, std::numbers::pi / 2.0, {1.0435, 2.0796});
  EXPECT_NEAR(profile.duration(), 2.0071, 2e-4);
  const auto limits =
      tp::TrapezoidProfile::limits_for_duration(std::numbers::pi / 2.0, kPeriodL1, kPeriodL1 / 4.0);
  EXPECT_NEAR(limits.max_velocity, 1.0435, 5e-5);
  EXPECT_NEAR(limits.max_acceleration, 2.0796, 5e-5);
}

TEST(TrapezoidProfile, TriangularWhenVelocityLimitNotReached) {
  // Z = 0.1 < v^2/a = 0.25: Delta t = sqrt(Z/a) = sqrt(0.1), t_f = 2 sqrt(0.1), peak sqrt(0.1).
  tp::TrapezoidProfile profile(1.0, 0.9, {0.5, 1.0});
  EXPECT_NEAR(profile.duration(), 2.0 * std::sqrt(0.1), 1e-12);
  EXPECT_NEAR(profile.peak_velocity(), std::sqrt(0.1), 1e-12);
  const auto mid = profile.sample(std::sqrt(0.1));
  EXPECT_NEAR(mid.position, 0.95, 1e-12);
  EXPECT_NEAR(mid.velocity, -std::sqrt(0.1), 1e-12);
}

TEST(TrapezoidProfile, RandomizedContinuityAndLimits) {
  // Seeded property test: position and velocity are continuous, |v| <= v_max, |a| <= a_max,
  // the endpoints are exact, and velocity integrates to the position (trapezoid rule).
  std::mt19937 rng(12345);
  std::uniform_real_distribution<double> pos(-3.0, 3.0), lim(0.05, 3.0);
  constexpr int kCases = 300;
  for (int c = 0; c < kCases; ++c) {
    const double start = pos(rng), target = pos(rng);
    const tp::AxisLimits limits{lim(rng), lim(rng)};
    tp::TrapezoidProfile profile(start, target, limits);
    const double tf = profile.duration();
    EXPECT_NEAR(profile.sample(0.0).position, start, 1e-12);
    EXPECT_NEAR(profile.sample(tf).position, target, 1e-12);
    EXPECT_NEAR(profile.sample(tf + 1.0).velocity, 0.0, 0.0);
    const int n = 2000;
    const double h = tf / n;
    auto previous = profile.sample(0.0);
    double integrated = start;
    for (int k = 1; k <= n; ++k) {
      const auto r = profile.sample(k * h);
      EXPECT_LE(std::abs(r.velocity), limits.max_velocity * (1 + 1e-12));
      EXPECT_LE(std::abs(r.acceleration), limits.max_acceleration * (1 + 1e-12));
      EXPECT_LE(std::abs(r.velocity - previous.velocity), limits.max_acceleration * h * (1 + 1e-9));
      integrated += 0.5 * h * (r.velocity + previous.velocity);
      previous = r;
    }
    // The trapezoid rule is exact on linear velocity pieces; only the two or four kinks of v(t)
    // inside a grid cell contribute, each at most a_max h^2/4.
    EXPECT_NEAR(integrated, target, 1e-9 + limits.max_acceleration * h * h);
  }
}

TEST(StepProfile, JumpsToTarget) {
  tp::StepProfile profile;
  profile.plan(0.8);
  EXPECT_EQ(profile.duration(), 0.0);
  EXPECT_EQ(profile.sample(0.0).position, 0.8);
  EXPECT_EQ(profile.sample(0.0).velocity, 0.0);
}

TEST(TrajectoryPlanner, MovePhasesAndReference) {
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  tp::PlannerOutput out;
  EXPECT_EQ(planner.step(0.01, out), StepStatus::not_ready);
  ASSERT_EQ(planner.hold(at(0.25, 0.0, 1.0)), tp::GoalStatus::accepted);
  ASSERT_EQ(planner.step(0.01, out), StepStatus::ok);
  EXPECT_EQ(out.phase, tp::MovePhase::holding);
  EXPECT_EQ(out.reference.trolley.position, 0.25);

  tp::MoveGoal goal;  // defaults: (3.54) and (3.55) limits
  goal.request_id = 7;
  goal.trolley_target = 1.0;
  goal.slew_target = std::numbers::pi / 2.0;
  goal.cable_target = 1.0;
  ASSERT_EQ(planner.start_move(goal, at(0.25, 0.0, 1.0)), tp::GoalStatus::accepted);
  int steps = 0;
  double last_x = 0.25;
  do {
    ASSERT_EQ(planner.step(0.01, out), StepStatus::ok);
    EXPECT_GE(out.reference.trolley.position, last_x - 1e-15);  // monotone
    last_x = out.reference.trolley.position;
    ++steps;
  } while (out.phase == tp::MovePhase::moving && steps < 1000);
  EXPECT_EQ(out.phase, tp::MovePhase::arrived);
  EXPECT_EQ(out.request_id, 7u);
  EXPECT_NEAR(out.move_duration, 2.0071, 2e-4);
  EXPECT_EQ(steps, 201);  // first t >= 2.0072 on a 0.01 s grid
  EXPECT_EQ(out.reference.trolley.position, 1.0);
  EXPECT_EQ(out.reference.slew.position, std::numbers::pi / 2.0);
  EXPECT_EQ(out.reference.trolley.velocity, 0.0);
}

TEST(TrajectoryPlanner, StepGoal) {
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  tp::MoveGoal goal;
  goal.profile = tp::ProfileKind::step;
  goal.trolley_target = 0.9;
  ASSERT_EQ(planner.start_move(goal, at(0.25, 0.0, 1.0)), tp::GoalStatus::accepted);
  tp::PlannerOutput out;
  ASSERT_EQ(planner.step(0.01, out), StepStatus::ok);
  EXPECT_EQ(out.phase, tp::MovePhase::arrived);
  EXPECT_EQ(out.reference.trolley.position, 0.9);
}

TEST(TrajectoryPlanner, InvalidGoalsRejectedAndIgnored) {
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  const auto here = at(0.5, 0.0, 1.0);
  ASSERT_EQ(planner.hold(here), tp::GoalStatus::accepted);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  tp::MoveGoal g;
  g.trolley_target = nan;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_nonfinite);
  g = {};
  g.trolley_limits.max_velocity = std::numeric_limits<double>::infinity();
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_nonfinite);
  g = {};
  g.trolley_target = 2.0;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_trolley_out_of_range);
  g = {};
  g.slew_target = 10.0;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_slew_out_of_range);
  g = {};
  g.cable_target = 0.05;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_cable_out_of_range);
  g = {};
  g.cable_limits.max_acceleration = 0.0;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_invalid_limits);
  EXPECT_EQ(planner.start_move(tp::MoveGoal{}, at(nan, 0.0, 1.0)), tp::GoalStatus::rejected_nonfinite);
  tp::PlannerOutput out;
  ASSERT_EQ(planner.step(0.01, out), StepStatus::ok);
  EXPECT_EQ(out.phase, tp::MovePhase::holding);  // nothing changed
  EXPECT_EQ(out.reference.trolley.position, 0.5);
  EXPECT_EQ(planner.step(nan, out), StepStatus::rejected_nonfinite);
  EXPECT_EQ(planner.step(-0.01, out), StepStatus::rejected_nonfinite);
}

TEST(TrajectoryPlanner, BadParamsThrowNamingField) {
  auto expect_throw = [](const tp::TrajectoryPlannerParams& p, const std::string& field) {
    try {
      tp::TrajectoryPlanner planner(p);
      FAIL() << "no throw for " << field;
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
    }
  };
  tp::TrajectoryPlannerParams p;
  p.trolley_max_position = 0.0;
  expect_throw(p, "trolley_max_position");
  p = {};
  p.cable_min_length = 0.0;
  expect_throw(p, "cable_min_length");
  p = {};
  p.slew_min_angle = std::numeric_limits<double>::quiet_NaN();
  expect_throw(p, "slew_min_angle");
  try {
    tp::TrapezoidProfile bad(0.0, 1.0, {0.0, 1.0});
    FAIL();
  } catch (const crane::common::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("max_velocity"), std::string::npos);
  }
}
