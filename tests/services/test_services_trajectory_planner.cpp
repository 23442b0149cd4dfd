// Tests of the trajectory planner core: trapezoid (3.43) against the maneuvers (3.54)-(3.55), and
// the swing-aware kinds (ZV, ZVD, EI shapers, time-optimal) through the planner.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
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

TEST(TrajectoryPlanner, TinyLimitsGiveAMoveTooLongToPlan) {
  // Found by the topic-gates fuzzer (tests/fuzz): a goal with trolley max_velocity = 1.6e-311 m/s
  // (positive, finite, accepted before) planned a move of Inf duration; its reference carried
  // move_duration = Inf, which the next node's NaN/Inf gate drops every cycle.
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  const auto here = at(0.5, 0.0, 1.0);
  ASSERT_EQ(planner.hold(here), tp::GoalStatus::accepted);
  tp::MoveGoal g;
  g.trolley_target = 0.75;
  g.trolley_limits.max_velocity = 1.6296927674613291e-311;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_invalid_limits);
  // The bound: trapezoid over d = 0.25 m at v, a = 0.9929 m/s^2 lasts d/v + v/a (3.43):
  // v = d/700 -> 700.0004 s > kMaxMoveDuration = 600 s (refused); v = d/500 -> 500.0005 s (planned).
  ASSERT_EQ(tp::kMaxMoveDuration, 600.0);
  g.trolley_limits.max_velocity = 0.25 / 700.0;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_invalid_limits);
  g.trolley_limits.max_velocity = 0.25 / 500.0;
  ASSERT_EQ(planner.start_move(g, here), tp::GoalStatus::accepted);
  EXPECT_NEAR(planner.move_duration(), 500.0 + (0.25 / 500.0) / 0.9929, 1e-9);
}

TEST(TrajectoryPlanner, TimeOptimalGoalWithATinyAccelerationLimitIsRefusedAtOnce) {
  // Found by the topic-gates fuzzer (tests/fuzz): max_acceleration = 1e-300 m/s^2 made the
  // swing-free trapezoid family count k = 1, 2, ... towards 1e150 (past 2^53, k += 1 stops changing
  // k): start_move() never returned. Now the family is computed from k >= sqrt(z/a)/T and dropped
  // beyond 1e9 periods; the goal is refused (no profile, or longer than kMaxMoveDuration).
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  const auto here = at(0.5, 0.0, 1.0);
  ASSERT_EQ(planner.hold(here), tp::GoalStatus::accepted);
  tp::MoveGoal g;
  g.profile = tp::ProfileKind::time_optimal;
  g.trolley_target = 0.75;
  g.trolley_limits.max_acceleration = 1e-300;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::rejected_invalid_limits);
  // Ordinary limits still plan (the time-optimal cases of (3.54) are checked below).
  g.trolley_limits.max_acceleration = 0.9929;
  EXPECT_EQ(planner.start_move(g, here), tp::GoalStatus::accepted);
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

// ---- Swing-aware profiles through the planner: zv, zvd, ei (ShapedProfile) and time_optimal ----

namespace {
// The (3.54)-(3.55) move from x = 0.25 m, gamma = 0 to x = 1 m, gamma = pi/2 with L = 1 m.
tp::MoveGoal swing_goal(tp::ProfileKind kind, std::uint64_t id = 11) {
  tp::MoveGoal goal;
  goal.request_id = id;
  goal.profile = kind;
  goal.trolley_target = 1.0;
  goal.slew_target = std::numbers::pi / 2.0;
  goal.cable_target = 1.0;
  return goal;
}

tp::ShaperParams shaper_for(tp::ProfileKind kind, double length,
                            const tp::TrajectoryPlannerParams& params = {}) {
  tp::ShaperParams shaper;
  shaper.kind = kind == tp::ProfileKind::zv    ? tp::ShaperKind::zv
                : kind == tp::ProfileKind::zvd ? tp::ShaperKind::zvd
                                               : tp::ShaperKind::ei;
  shaper.natural_frequency = std::sqrt(params.gravity / length);
  shaper.damping_ratio = params.swing_damping_ratio;
  shaper.vibration_tolerance = params.ei_vibration_tolerance;
  return shaper;
}

// The duration the profile classes give on their own for the goal's trolley and slew axes.
double expected_duration(tp::ProfileKind kind, const tp::MoveGoal& goal, const CraneStateEstimate& from,
                         const tp::TrajectoryPlannerParams& params = {}) {
  const double w = std::sqrt(params.gravity / from.cable_length);
  double trolley = 0.0, slew = 0.0;
  if (kind == tp::ProfileKind::time_optimal) {
    trolley = tp::TimeOptimalProfile(from.trolley_position, goal.trolley_target, goal.trolley_limits, w).duration();
    slew = tp::TimeOptimalProfile(from.slew_angle, goal.slew_target, goal.slew_limits, w).duration();
  } else {
    const auto shaper = shaper_for(kind, from.cable_length, params);
    trolley = tp::ShapedProfile(from.trolley_position, goal.trolley_target, goal.trolley_limits, shaper).duration();
    slew = tp::ShapedProfile(from.slew_angle, goal.slew_target, goal.slew_limits, shaper).duration();
  }
  const double cable = tp::TrapezoidProfile(from.cable_length, goal.cable_target, goal.cable_limits).duration();
  return std::max({trolley, slew, cable});
}

bool within(const crane::common::AxisReference& r, const tp::AxisLimits& limits) {
  return std::abs(r.velocity) <= limits.max_velocity * (1 + 1e-9) &&
         std::abs(r.acceleration) <= limits.max_acceleration * (1 + 1e-9);
}

// Runs the planner to arrival on a 1 ms grid, checking the limits on the way. Returns the steps.
int run_to_arrival(tp::TrajectoryPlanner& planner, const tp::MoveGoal& goal, tp::PlannerOutput& out) {
  int steps = 0;
  do {
    EXPECT_EQ(planner.step(0.001, out), StepStatus::ok);
    EXPECT_TRUE(within(out.reference.trolley, goal.trolley_limits)) << "t = " << out.time_in_move;
    EXPECT_TRUE(within(out.reference.slew, goal.slew_limits)) << "t = " << out.time_in_move;
    EXPECT_TRUE(within(out.reference.cable_length, goal.cable_limits)) << "t = " << out.time_in_move;
    ++steps;
  } while (out.phase == tp::MovePhase::moving && steps < 100000);
  return steps;
}
}  // namespace

TEST(TrajectoryPlanner, SwingAwareKindsReachTargetsAtRest) {
  for (const auto kind : {tp::ProfileKind::zv, tp::ProfileKind::zvd, tp::ProfileKind::ei,
                          tp::ProfileKind::time_optimal}) {
    SCOPED_TRACE(static_cast<int>(kind));
    tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
    const auto from = at(0.25, 0.0, 1.0);
    const auto goal = swing_goal(kind);
    ASSERT_EQ(planner.start_move(goal, from), tp::GoalStatus::accepted);
    tp::PlannerOutput out;
    run_to_arrival(planner, goal, out);
    EXPECT_EQ(out.phase, tp::MovePhase::arrived);
    EXPECT_EQ(out.request_id, 11u);
    EXPECT_NEAR(out.move_duration, expected_duration(kind, goal, from), 1e-12);
    EXPECT_GE(out.time_in_move, out.move_duration);
    EXPECT_NEAR(out.reference.trolley.position, 1.0, 1e-12);
    EXPECT_NEAR(out.reference.slew.position, std::numbers::pi / 2.0, 1e-12);
    EXPECT_NEAR(out.reference.cable_length.position, 1.0, 1e-12);
    EXPECT_EQ(out.reference.trolley.velocity, 0.0);
    EXPECT_EQ(out.reference.slew.velocity, 0.0);
    EXPECT_EQ(out.reference.trolley.acceleration, 0.0);
    EXPECT_EQ(out.reference.slew.acceleration, 0.0);
  }
}

TEST(TrajectoryPlanner, ZvAddsHalfASwingPeriod) {
  // ZV delays the (3.54)/(3.55) trapezoids (t_f = 2.0072 s) by T/2, T = 2 pi sqrt(L/g), L = 1 m.
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  const auto goal = swing_goal(tp::ProfileKind::zv);
  ASSERT_EQ(planner.start_move(goal, at(0.25, 0.0, 1.0)), tp::GoalStatus::accepted);
  tp::PlannerOutput out;
  ASSERT_EQ(planner.step(0.0, out), StepStatus::ok);
  const double trapezoid = 0.75 / 0.4982 + 0.4982 / 0.9929;  // the slower of the two axes
  EXPECT_NEAR(out.move_duration, trapezoid + kPeriodL1 / 2.0, 1e-12);
  // ZVD and EI add a full period.
  ASSERT_EQ(planner.start_move(swing_goal(tp::ProfileKind::zvd, 12), at(0.25, 0.0, 1.0)),
            tp::GoalStatus::accepted);
  ASSERT_EQ(planner.step(0.0, out), StepStatus::ok);
  EXPECT_NEAR(out.move_duration, trapezoid + kPeriodL1, 1e-12);
}

TEST(TrajectoryPlanner, SwingFrequencyFollowsCableLength) {
  // L = 2.5 m: T = 2 pi sqrt(2.5/9.8); the hoist (1 m -> 2.5 m) uses the trapezoid.
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  const auto from = at(0.25, 0.0, 2.5);
  auto goal = swing_goal(tp::ProfileKind::zv);
  goal.slew_target = 0.0;
  goal.cable_target = 2.5;
  ASSERT_EQ(planner.start_move(goal, from), tp::GoalStatus::accepted);
  tp::PlannerOutput out;
  ASSERT_EQ(planner.step(0.0, out), StepStatus::ok);
  const double period = 2.0 * std::numbers::pi * std::sqrt(2.5 / 9.8);
  EXPECT_NEAR(out.move_duration, 0.75 / 0.4982 + 0.4982 / 0.9929 + period / 2.0, 1e-12);
}

TEST(TrajectoryPlanner, HoistUsesTrapezoidForSwingAwareKinds) {
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  const auto from = at(0.5, 0.0, 1.0);
  auto goal = swing_goal(tp::ProfileKind::time_optimal);
  goal.trolley_target = 0.5;
  goal.slew_target = 0.0;
  goal.cable_target = 2.0;  // hoist only
  ASSERT_EQ(planner.start_move(goal, from), tp::GoalStatus::accepted);
  tp::PlannerOutput out;
  run_to_arrival(planner, goal, out);
  EXPECT_NEAR(out.move_duration, tp::TrapezoidProfile(1.0, 2.0, goal.cable_limits).duration(), 1e-12);
  EXPECT_NEAR(out.reference.cable_length.position, 2.0, 1e-12);
  EXPECT_EQ(out.reference.trolley.position, 0.5);
}

TEST(TrajectoryPlanner, TimeOptimalTrolleyManeuver354) {
  // Trolley alone, (3.54) limits, L = 1 m: the time-optimal swing-free move takes 2.2543 s.
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  auto goal = swing_goal(tp::ProfileKind::time_optimal);
  goal.slew_target = 0.0;
  ASSERT_EQ(planner.start_move(goal, at(0.25, 0.0, 1.0)), tp::GoalStatus::accepted);
  tp::PlannerOutput out;
  run_to_arrival(planner, goal, out);
  EXPECT_NEAR(out.move_duration, 2.2543, 1e-3);
  EXPECT_EQ(out.phase, tp::MovePhase::arrived);
  EXPECT_NEAR(out.reference.trolley.position, 1.0, 1e-12);
  EXPECT_EQ(out.reference.trolley.velocity, 0.0);
}

TEST(TrajectoryPlanner, ShaperUsesDampingAndTolerance) {
  tp::TrajectoryPlannerParams params;
  params.swing_damping_ratio = 0.1;
  params.ei_vibration_tolerance = 0.1;
  params.gravity = 9.81;
  for (const auto kind : {tp::ProfileKind::zv, tp::ProfileKind::zvd, tp::ProfileKind::ei}) {
    SCOPED_TRACE(static_cast<int>(kind));
    tp::TrajectoryPlanner planner(params);
    const auto from = at(0.25, 0.0, 1.5);
    const auto goal = swing_goal(kind);
    ASSERT_EQ(planner.start_move(goal, from), tp::GoalStatus::accepted);
    tp::PlannerOutput out;
    run_to_arrival(planner, goal, out);
    EXPECT_NEAR(out.move_duration, expected_duration(kind, goal, from, params), 1e-12);
    EXPECT_NEAR(out.reference.trolley.position, 1.0, 1e-12);
  }
}

TEST(TrajectoryPlanner, RejectedGoalLeavesRunningMoveUntouched) {
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  ASSERT_EQ(planner.start_move(swing_goal(tp::ProfileKind::zvd, 5), at(0.25, 0.0, 1.0)),
            tp::GoalStatus::accepted);
  tp::PlannerOutput out;
  for (int k = 0; k < 500; ++k) ASSERT_EQ(planner.step(0.001, out), StepStatus::ok);
  const tp::TrajectoryPlanner reference_planner = planner;  // the move as it would continue

  // A failed plan: a non-positive measured cable length gives no swing frequency.
  const auto bad_state = at(0.5, 0.2, 0.0);
  for (const auto kind : {tp::ProfileKind::zv, tp::ProfileKind::zvd, tp::ProfileKind::ei,
                          tp::ProfileKind::time_optimal}) {
    EXPECT_EQ(planner.start_move(swing_goal(kind, 6), bad_state), tp::GoalStatus::rejected_invalid_limits);
  }
  // Non-positive limits for a swing-aware kind.
  auto goal = swing_goal(tp::ProfileKind::time_optimal, 7);
  goal.slew_limits.max_velocity = -1.0;
  EXPECT_EQ(planner.start_move(goal, at(0.5, 0.2, 1.0)), tp::GoalStatus::rejected_invalid_limits);
  goal = swing_goal(tp::ProfileKind::ei, 8);
  goal.cable_limits.max_acceleration = 0.0;
  EXPECT_EQ(planner.start_move(goal, at(0.5, 0.2, 1.0)), tp::GoalStatus::rejected_invalid_limits);
  // A value outside the enum (e.g. cast from an unknown wire code).
  goal = swing_goal(static_cast<tp::ProfileKind>(42), 9);
  EXPECT_EQ(planner.start_move(goal, at(0.5, 0.2, 1.0)), tp::GoalStatus::rejected_unknown_profile);
  // Out of range for a swing-aware kind.
  goal = swing_goal(tp::ProfileKind::zv, 10);
  goal.trolley_target = 5.0;
  EXPECT_EQ(planner.start_move(goal, at(0.5, 0.2, 1.0)), tp::GoalStatus::rejected_trolley_out_of_range);

  tp::TrajectoryPlanner continued = reference_planner;
  tp::PlannerOutput expected;
  for (int k = 0; k < 4000; ++k) {  // ZVD move: 2 x 2.007 s
    ASSERT_EQ(planner.step(0.001, out), StepStatus::ok);
    ASSERT_EQ(continued.step(0.001, expected), StepStatus::ok);
    ASSERT_EQ(out.request_id, 5u);
    ASSERT_EQ(out.phase, expected.phase);
    ASSERT_EQ(out.time_in_move, expected.time_in_move);
    ASSERT_EQ(out.move_duration, expected.move_duration);
    ASSERT_EQ(out.reference.trolley.position, expected.reference.trolley.position);
    ASSERT_EQ(out.reference.slew.position, expected.reference.slew.position);
    ASSERT_EQ(out.reference.cable_length.position, expected.reference.cable_length.position);
  }
  EXPECT_EQ(out.phase, tp::MovePhase::arrived);
  EXPECT_EQ(out.reference.trolley.position, 1.0);
}

TEST(TrajectoryPlanner, BadSwingParamsThrowNamingField) {
  auto expect_throw = [](const tp::TrajectoryPlannerParams& p, const std::string& field) {
    try {
      tp::TrajectoryPlanner planner(p);
      FAIL() << "no throw for " << field;
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find("trajectory_planner." + field), std::string::npos)
          << error.what();
    }
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  tp::TrajectoryPlannerParams p;
  for (const double bad : {-0.01, 0.31, nan}) {
    p = {};
    p.swing_damping_ratio = bad;
    expect_throw(p, "swing_damping_ratio");
  }
  for (const double bad : {0.0, -0.05, 0.21, nan}) {
    p = {};
    p.ei_vibration_tolerance = bad;
    expect_throw(p, "ei_vibration_tolerance");
  }
  for (const double bad : {0.0, -9.8, nan, std::numeric_limits<double>::infinity()}) {
    p = {};
    p.gravity = bad;
    expect_throw(p, "gravity");
  }
  // The bounds themselves are accepted.
  p = {};
  p.swing_damping_ratio = 0.3;
  p.ei_vibration_tolerance = 0.2;
  EXPECT_NO_THROW(tp::TrajectoryPlanner{p});
}

// ---- Waypoints: a chain of rest-to-rest segments ----

TEST(TrajectoryPlannerWaypoints, PassesThroughEachWaypointAtRestAndEndsAtTheTarget) {
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  crane::common::CraneStateEstimate current;
  current.trolley_position = 0.25;
  current.cable_length = 1.0;
  tp::MoveGoal goal;
  goal.profile = tp::ProfileKind::zv;
  goal.trolley_target = 1.0;
  goal.slew_target = 0.0;
  goal.cable_target = 1.0;
  goal.waypoint_count = 2;
  goal.waypoints[0] = {0.6, 0.5, 1.0};
  goal.waypoints[1] = {0.4, 0.5, 1.4};  // back along the jib while lowering the load
  ASSERT_EQ(planner.start_move(goal, current), tp::GoalStatus::accepted);

  // Independent durations: each segment alone, from the previous targets.
  auto single = [](double x0, double x1, double g0, double g1, double l0, double l1) {
    tp::TrajectoryPlanner p(tp::TrajectoryPlannerParams{});
    crane::common::CraneStateEstimate s;
    s.trolley_position = x0;
    s.slew_angle = g0;
    s.cable_length = l0;
    tp::MoveGoal g;
    g.profile = tp::ProfileKind::zv;
    g.trolley_target = x1;
    g.slew_target = g1;
    g.cable_target = l1;
    EXPECT_EQ(p.start_move(g, s), tp::GoalStatus::accepted);
    tp::PlannerOutput o;
    EXPECT_EQ(p.step(0.0, o), crane::common::StepStatus::ok);
    return o.move_duration;
  };
  const double d1 = single(0.25, 0.6, 0.0, 0.5, 1.0, 1.0);
  const double d2 = single(0.6, 0.4, 0.5, 0.5, 1.0, 1.4);
  const double d3 = single(0.4, 1.0, 0.5, 0.0, 1.4, 1.0);
  tp::PlannerOutput out;
  ASSERT_EQ(planner.step(0.0, out), crane::common::StepStatus::ok);
  EXPECT_NEAR(out.move_duration, d1 + d2 + d3, 1e-12);

  // At the end of each segment: at the waypoint, at rest.
  ASSERT_EQ(planner.step(d1, out), crane::common::StepStatus::ok);
  EXPECT_NEAR(out.reference.trolley.position, 0.6, 1e-9);
  EXPECT_NEAR(out.reference.slew.position, 0.5, 1e-9);
  EXPECT_NEAR(out.reference.trolley.velocity, 0.0, 1e-9);
  EXPECT_EQ(out.phase, tp::MovePhase::moving);
  ASSERT_EQ(planner.step(d2, out), crane::common::StepStatus::ok);
  EXPECT_NEAR(out.reference.trolley.position, 0.4, 1e-9);
  EXPECT_NEAR(out.reference.cable_length.position, 1.4, 1e-9);
  ASSERT_EQ(planner.step(d3, out), crane::common::StepStatus::ok);
  EXPECT_EQ(out.phase, tp::MovePhase::arrived);
  EXPECT_DOUBLE_EQ(out.reference.trolley.position, 1.0);
  EXPECT_DOUBLE_EQ(out.reference.slew.position, 0.0);
  EXPECT_DOUBLE_EQ(out.reference.cable_length.position, 1.0);
}

TEST(TrajectoryPlannerWaypoints, BadWaypointsAreRejectedAndTheRunningMoveContinues) {
  tp::TrajectoryPlanner planner(tp::TrajectoryPlannerParams{});
  crane::common::CraneStateEstimate current;
  current.trolley_position = 0.25;
  current.cable_length = 1.0;
  tp::MoveGoal goal;
  goal.trolley_target = 1.0;
  ASSERT_EQ(planner.start_move(goal, current), tp::GoalStatus::accepted);
  tp::PlannerOutput before;
  ASSERT_EQ(planner.step(0.5, before), crane::common::StepStatus::ok);

  tp::MoveGoal bad = goal;
  bad.request_id = 2;
  bad.waypoint_count = 1;
  bad.waypoints[0] = {1.5, 0.0, 1.0};  // beyond trolley_max_position 1.2
  EXPECT_EQ(planner.start_move(bad, current), tp::GoalStatus::rejected_waypoint);
  bad.waypoints[0] = {0.5, std::numeric_limits<double>::quiet_NaN(), 1.0};
  EXPECT_EQ(planner.start_move(bad, current), tp::GoalStatus::rejected_waypoint);
  bad.waypoints[0] = {0.5, 0.0, 0.1};  // below cable_min_length 0.2
  EXPECT_EQ(planner.start_move(bad, current), tp::GoalStatus::rejected_waypoint);
  bad.waypoints[0] = {0.5, 0.0, 1.0};
  bad.waypoint_count = tp::kMaxWaypoints + 1;
  EXPECT_EQ(planner.start_move(bad, current), tp::GoalStatus::rejected_waypoint);

  tp::PlannerOutput after;
  ASSERT_EQ(planner.step(0.0, after), crane::common::StepStatus::ok);
  EXPECT_EQ(after.request_id, before.request_id);
  EXPECT_DOUBLE_EQ(after.reference.trolley.position, before.reference.trolley.position);
}
