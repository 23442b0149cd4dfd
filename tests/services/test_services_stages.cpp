// The stage objects of the planner, anti-swing and tracking processes, on protocol messages (no
// DDS): the planner's goal rules and its feedback (MoveStatus, like a ROS 2 action's), the
// anti-swing law registry, the tracking stage's (3.50) reference correction.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <string>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <vector>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/common/protocol_signals.hpp"
#include "crane/common/validation.hpp"
#include "crane/config/yaml_section.hpp"
#include "crane/friction_compensation/friction_compensation_stage.hpp"
#include "crane/state_estimator/state_estimator.hpp"
#include "crane/tracking/tracking_stage.hpp"
#include "crane/trajectory_planner/planned_path.hpp"
#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

namespace {

using namespace crane;
using Feedback = protocol::MoveStatus;
using Request = protocol::MoveRequest;

protocol::CraneState at_rest(std::uint64_t seq, double x = 0.25) {
  protocol::CraneState s;
  s.header.seq = seq;
  s.trolley_position = x;
  s.cable_length = 1.0;
  return s;
}

Request trolley_goal(std::uint32_t id, double target, std::uint64_t start = 0) {
  Request r;
  r.header.seq = start;
  r.request_id = id;
  r.profile = Request::PROFILE_TRAPEZOID;
  r.axes = Request::AXIS_TROLLEY;
  r.trolley_target = target;
  return r;
}

// Runs cycles from `first` to `last`, the goals given at their cycle; collects every feedback.
std::vector<Feedback> run(trajectory_planner::TrajectoryPlannerStage& stage, std::uint64_t first, std::uint64_t last,
                          const std::vector<std::pair<std::uint64_t, Request>>& goals) {
  std::vector<Feedback> feedback;
  protocol::Reference reference;
  for (std::uint64_t k = first; k <= last; ++k) {
    std::vector<Request> now;
    for (const auto& [cycle, goal] : goals) {
      if (cycle == k) now.push_back(goal);
    }
    EXPECT_EQ(stage.step(at_rest(k), now, reference), common::StepStatus::ok);
    for (const auto& f : stage.move_statuses()) feedback.push_back(f);
  }
  return feedback;
}

trajectory_planner::TrajectoryPlannerStage lab_planner() {
  trajectory_planner::TrajectoryPlannerParams p;  // trolley [0.1, 1.2] m
  return trajectory_planner::TrajectoryPlannerStage(p, 0.01);
}

TEST(PlannerStage, AGoalOutOfRangeIsRejectedWithTheValueAndTheBound) {
  auto stage = lab_planner();
  const auto feedback = run(stage, 0, 2, {{1, trolley_goal(5, 1.5)}});
  ASSERT_EQ(feedback.size(), 1U);
  EXPECT_EQ(feedback[0].request_id, 5U);
  EXPECT_EQ(feedback[0].result, Feedback::RESULT_REJECTED);
  EXPECT_EQ(feedback[0].reason, Feedback::REASON_TROLLEY_RANGE);
  EXPECT_EQ(feedback[0].value, 1.5);
  EXPECT_EQ(feedback[0].bound_min, 0.1);
  EXPECT_EQ(feedback[0].bound_max, 1.2);
  EXPECT_EQ(feedback[0].header.seq, 1U);
}

// A stop that names the slew (the site link's, when the trolley's own stop would run past its goal:
// docs/site.md): the trolley runs on along its profile, cycle for cycle the reference of the move
// never stopped, and rests at its target; the slew stops as it does in a stop of every axis. A stop
// naming no axis, or every one, stops every axis (the trolley then runs past its target), and so
// does one on a move with a waypoint still ahead.
TEST(PlannerStage, AStopNamingTheSlewLetsTheTrolleyRunOnToItsTarget) {
  Request goal = trolley_goal(1, 0.6);
  goal.axes |= Request::AXIS_SLEW;
  goal.slew_target = 2.5;
  const auto stop_of = [](std::uint8_t axes) {
    Request r;
    r.request_id = 2;
    r.command = Request::COMMAND_STOP;
    r.axes = axes;
    return r;
  };
  constexpr std::uint64_t kStop = 101;  // 1.0 s into the move: the trolley (0.35 m) decelerates
  struct Run {
    trajectory_planner::TrajectoryPlannerStage stage = lab_planner();
    std::vector<protocol::Reference> references;
    std::vector<Feedback> feedback;
  };
  const auto run_with = [&](std::optional<Request> stop, const Request& move) {
    Run r;
    protocol::Reference reference;
    for (std::uint64_t k = 0; k < 700; ++k) {
      std::vector<Request> now;
      if (k == 1) now.push_back(move);
      if (k == kStop && stop) now.push_back(*stop);
      EXPECT_EQ(r.stage.step(at_rest(k), now, reference), common::StepStatus::ok);
      r.references.push_back(reference);
      for (const auto& f : r.stage.move_statuses()) r.feedback.push_back(f);
    }
    return r;
  };
  const Run free = run_with(std::nullopt, goal);
  const Run slew = run_with(stop_of(Request::AXIS_SLEW), goal);
  const Run every = run_with(stop_of(0), goal);
  const Run named = run_with(stop_of(Request::AXIS_TROLLEY | Request::AXIS_SLEW | Request::AXIS_HOIST), goal);
  ASSERT_LT(free.references[kStop].trolley_position, 0.6);
  ASSERT_GT(free.references[kStop].trolley_velocity, 0.1);
  for (std::size_t k = 0; k < free.references.size(); ++k) {
    EXPECT_EQ(slew.references[k].trolley_position, free.references[k].trolley_position) << k;
    EXPECT_EQ(slew.references[k].trolley_velocity, free.references[k].trolley_velocity) << k;
    EXPECT_EQ(slew.references[k].trolley_acceleration, free.references[k].trolley_acceleration) << k;
    EXPECT_EQ(slew.references[k].slew_angle, every.references[k].slew_angle) << k;
    EXPECT_EQ(slew.references[k].slew_rate, every.references[k].slew_rate) << k;
    EXPECT_EQ(named.references[k].trolley_position, every.references[k].trolley_position) << k;
    EXPECT_EQ(named.references[k].slew_angle, every.references[k].slew_angle) << k;
  }
  const auto& last = slew.references.back();
  EXPECT_EQ(last.trolley_position, 0.6);
  EXPECT_GT(every.references.back().trolley_position, 0.6 + 0.05) << "a stop of every axis runs past the target";
  EXPECT_LT(last.slew_angle, 2.0);
  EXPECT_EQ(last.phase, protocol::Reference::PHASE_HOLDING);
  // The stop's feedback: stopping, resting where each axis ends (the trolley at its target); then
  // arrived; the goal aborted (stopped).
  bool stopping = false, arrived = false, aborted = false;
  for (const auto& f : slew.feedback) {
    if (f.request_id == 2 && f.result == Feedback::RESULT_STOPPING) {
      stopping = true;
      EXPECT_EQ(f.rest_trolley_position, 0.6);
      EXPECT_NEAR(f.rest_slew_angle, last.slew_angle, 1e-9);
    }
    arrived = arrived || (f.request_id == 2 && f.result == Feedback::RESULT_ARRIVED);
    aborted = aborted || (f.request_id == 1 && f.result == Feedback::RESULT_ABORTED && f.reason == Feedback::REASON_STOPPED);
  }
  EXPECT_TRUE(stopping);
  EXPECT_TRUE(arrived);
  EXPECT_TRUE(aborted);

  // A waypoint ahead: every axis stops.
  Request via = goal;
  via.waypoint_count = 1;
  via.waypoint_trolley[0] = 0.9;
  via.waypoint_slew[0] = 0.5;
  via.waypoint_cable_length[0] = 1.0;
  const Run via_slew = run_with(stop_of(Request::AXIS_SLEW), via);
  const Run via_every = run_with(stop_of(0), via);
  for (std::size_t k = 0; k < via_slew.references.size(); ++k) {
    EXPECT_EQ(via_slew.references[k].trolley_position, via_every.references[k].trolley_position) << k;
  }
}

TEST(PlannerStage, AMoveReportsWaitingMovingEveryTenCyclesAndArrived) {
  auto stage = lab_planner();
  const auto feedback = run(stage, 0, 400, {{2, trolley_goal(7, 0.55, 10)}});
  ASSERT_GE(feedback.size(), 3U);
  EXPECT_EQ(feedback.front().result, Feedback::RESULT_WAITING);
  EXPECT_EQ(feedback.front().header.seq, 2U);
  std::vector<std::uint64_t> moving;
  for (const auto& f : feedback) {
    EXPECT_EQ(f.request_id, 7U);
    if (f.result == Feedback::RESULT_MOVING) moving.push_back(f.header.seq);
  }
  ASSERT_GE(moving.size(), 2U);
  EXPECT_EQ(moving[0], 10U);  // at its start cycle
  for (std::size_t i = 1; i < moving.size(); ++i) EXPECT_EQ(moving[i] - moving[i - 1], 10U);
  EXPECT_EQ(feedback.back().result, Feedback::RESULT_ARRIVED);
  EXPECT_NEAR(feedback.back().trolley_to_go, 0.0, 1e-12);
  EXPECT_GT(feedback.back().move_duration, 0.5);
  // The distance to go shrinks as the move goes.
  EXPECT_NEAR(feedback[1].trolley_to_go, 0.30, 1e-3);
}

// The minimum-time profile (PROFILE_MINIMUM_TIME, planned_path.hpp): a path handed over by the
// caller (here a synthetic one: the trolley 0.25 -> 0.35 m in 10 cycles, each sample's law marked by
// its feedforward = 100 + k) runs sample by sample, the reference carrying each cycle's law and then
// the hold at the end; without a plan the goal runs the time-optimal profile.
std::shared_ptr<const trajectory_planner::PlannedPath> synthetic_path() {
  auto path = std::make_shared<trajectory_planner::PlannedPath>();
  constexpr std::size_t n = 11;
  path->sample_period = 0.01;
  path->minimum_time = 0.095;
  for (std::size_t k = 0; k < n; ++k) {
    const double x = 0.25 + 0.01 * static_cast<double>(k);
    const double v = k + 1 < n ? 1.0 : 0.0;
    path->trolley.push_back({x, v, 0.0});
    path->slew.push_back({});
    path->cable.push_back({1.0, 0.0, 0.0});
    common::TrajectoryFeedback law;
    law.position = {x, 0.001 * static_cast<double>(k), 0.0, 0.0};
    law.velocity = {v, 0.0, 0.0, 0.0};
    law.feedforward = {100.0 + static_cast<double>(k), 0.0};
    law.gain[0] = 30.0;
    law.sliding_friction_reduction = k + 1 < n ? 0.5 : 0.25;
    path->laws.push_back(law);
  }
  return path;
}

Request minimum_time_goal(std::uint32_t id, double target, std::uint64_t start = 0) {
  Request r = trolley_goal(id, target, start);
  r.profile = Request::PROFILE_MINIMUM_TIME;
  return r;
}

protocol::SupervisorStatus with_sway_limit(std::uint64_t seq) {
  protocol::SupervisorStatus st;
  st.header.seq = seq;
  st.mode = protocol::SupervisorStatus::MODE_OPERATING;
  st.operating_mode = protocol::SupervisorStatus::OPERATION_FULLAUTOMATIC;
  st.max_swing = 0.6;
  return st;
}

// A planner that has heard the supervisor's sway limit, stepped at rest one cycle at a time.
struct HeardPlanner {
  trajectory_planner::TrajectoryPlannerStage stage = lab_planner();
  protocol::Reference reference;
  protocol::SupervisorStatus status = with_sway_limit(0);
  void step(std::uint64_t k, std::span<const Request> goals = {}) {
    const auto state = at_rest(k);
    EXPECT_EQ(stage.step(trajectory_planner::PlannerCycle{&state, goals, {}, &status}, reference), common::StepStatus::ok);
  }
};

// The pendulum a plan swings (PlanRequest::swing): the state estimator's learnt one while it is
// confident and swings over the move's cable span (a L + c > 0 at its shorter cable, here 1.0 m: the
// goal does not hoist; a and c in the manual block's ranges), the configured trajectory_planner.manual
// one otherwise. The planner's shortest cable, 0.3 m, does not bound a learnt pendulum. A plan on the
// configured pendulum is robust to its length (robust_length_range, here 0.2, with its margin); one
// on the learnt pendulum is not.
TEST(PlannerStage, AMinimumTimePlanSwingsTheLearntPendulumWhenItSwingsOverTheMove) {
  trajectory_planner::TrajectoryPlannerParams params;
  params.cable_min_length = 0.3;
  params.robust_length_range = 0.2;
  params.robust_margin = 0.15;
  params.manual.swing_length_scale = 0.995;  // a calibration: the lab crane's hook
  params.manual.swing_length_offset = 0.257;
  struct Case {
    bool confident;
    double scale, offset;
    double expected_scale, expected_offset;
  };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const Case c : {Case{true, 1.0, 0.2, 1.0, 0.2},          // learnt: planned
                       Case{false, 1.0, 0.2, 0.995, 0.257},      // not confident: the configured
                       Case{true, 1.0, -1.0, 0.995, 0.257},      // a L + c = 0 at the move's 1.0 m
                       Case{true, 1.0, -0.99, 1.0, -0.99},       // 1 cm of pendulum there (none at 0.3 m)
                       Case{true, 0.5, -0.2, 0.5, -0.2},         // 0.3 m at 1.0 m, none at 0.3 m
                       Case{true, 12.0, 0.0, 0.995, 0.257},      // a out of [0.1, 10]
                       Case{true, 1.0, 10.5, 0.995, 0.257},      // c out of [-1, 10]
                       Case{true, nan, 0.2, 0.995, 0.257}}) {    // NaN: the estimate is refused first
    trajectory_planner::TrajectoryPlannerStage stage(params, 0.01);
    protocol::Reference reference;
    const protocol::SupervisorStatus status = with_sway_limit(0);
    const Request goal = minimum_time_goal(3, 0.35);
    for (std::uint64_t k = 0; k <= 1; ++k) {
      auto state = at_rest(k);
      state.swing_length_confident = c.confident;
      state.swing_length_scale = c.scale;
      state.swing_length_offset = c.offset;
      const auto step = stage.step(trajectory_planner::PlannerCycle{&state, k == 1 ? std::span(&goal, 1)
                                                                                  : std::span<const Request>(),
                                                                    {}, &status},
                                   reference);
      if (std::isnan(c.scale)) {
        EXPECT_EQ(step, common::StepStatus::rejected_nonfinite);
        state.swing_length_scale = 1.0;  // the next estimate is whole again, not confident
        state.swing_length_confident = false;
        ASSERT_EQ(stage.step(trajectory_planner::PlannerCycle{&state, k == 1 ? std::span(&goal, 1)
                                                                             : std::span<const Request>(),
                                                              {}, &status},
                             reference),
                  common::StepStatus::ok);
      }
    }
    ASSERT_TRUE(stage.plan_request().has_value()) << c.scale << " " << c.offset;
    EXPECT_EQ(stage.plan_request()->swing.scale, c.expected_scale) << c.scale << " " << c.offset;
    EXPECT_EQ(stage.plan_request()->swing.offset, c.expected_offset) << c.scale << " " << c.offset;
    const bool learnt = c.expected_offset != 0.257;
    EXPECT_EQ(stage.plan_request()->robust_length_range, learnt ? 0.0 : 0.2) << c.scale << " " << c.offset;
    EXPECT_EQ(stage.plan_request()->robust_margin, 0.15);
  }
}

// Robust near the mast only (TrajectoryPlannerParams::robust_within_radius): a plan on the configured
// pendulum whose trolley ends within the radius (the bound included) is robust, one further out or
// on a learnt pendulum is not; a radius of 0 makes every plan on the configured pendulum robust.
TEST(PlannerStage, ARobustPlanNearTheMastOnly) {
  trajectory_planner::TrajectoryPlannerParams params;
  params.robust_length_range = 0.2;
  params.robust_margin = 0.15;
  const trajectory_planner::EquivalentPendulum configured{};
  const auto range_of = [&](double radius, double target, bool learnt) {
    params.robust_within_radius = radius;
    trajectory_planner::PlanRequest r;
    r.trolley_target = target;
    trajectory_planner::plan_on_pendulum(r, configured, learnt, params);
    EXPECT_EQ(r.robust_margin, 0.15);
    return r.robust_length_range;
  };
  EXPECT_EQ(range_of(0.5, 0.3, false), 0.2);
  EXPECT_EQ(range_of(0.5, 0.5, false), 0.2);
  EXPECT_EQ(range_of(0.5, 0.51, false), 0.0);
  EXPECT_EQ(range_of(0.5, 0.3, true), 0.0);
  EXPECT_EQ(range_of(0.0, 1.0, false), 0.2);
  EXPECT_EQ(range_of(0.0, 1.0, true), 0.0);
}

TEST(PlannerStage, AMinimumTimeGoalHoldsForItsPlanThenRunsItsPathWithItsLaw) {
  HeardPlanner p;
  auto& [stage, reference, status] = p;
  const auto step = [&p](std::uint64_t k, std::span<const Request> goals = {}) { p.step(k, goals); };
  step(0);
  const Request goal = minimum_time_goal(3, 0.35);
  step(1, std::span(&goal, 1));
  ASSERT_TRUE(stage.plan_request().has_value());
  const auto& request = *stage.plan_request();
  EXPECT_EQ(request.request_id, 3U);
  EXPECT_EQ(request.trolley_from, 0.25);
  EXPECT_EQ(request.trolley_target, 0.35);
  EXPECT_EQ(request.max_swing, 0.6);
  EXPECT_EQ(request.trolley_limits.max_velocity, 0.4982);  // the planner's rated speed: the request gave 0
  ASSERT_FALSE(stage.move_statuses().empty());
  EXPECT_EQ(stage.move_statuses().back().result, Feedback::RESULT_WAITING);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_HOLDING);
  EXPECT_FALSE(reference.feedback_law);
  step(2);  // no plan yet: it holds
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_HOLDING);
  stage.provide_plan(request.sequence + 1, synthetic_path());  // another request: ignored
  step(3);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_HOLDING);
  stage.provide_plan(request.sequence, synthetic_path());
  for (std::uint64_t k = 4; k <= 13; ++k) {
    step(k);
    const double sample = static_cast<double>(k - 3);  // the first cycle of a move is at t = T_s
    ASSERT_TRUE(reference.feedback_law) << k;
    EXPECT_EQ(reference.request_id, 3U);
    EXPECT_EQ(reference.trolley_feedforward_voltage, 100.0 + sample) << k;
    EXPECT_NEAR(reference.trolley_position, 0.25 + 0.01 * sample, 1e-12) << k;
    EXPECT_NEAR(reference.swing_in_plane, 0.001 * sample, 1e-12) << k;
    EXPECT_EQ(reference.feedback_gain[0], 30.0);
    EXPECT_EQ(reference.move_duration, 0.095);  // T*
  }
  EXPECT_EQ(reference.sliding_friction_reduction, 0.25);  // the last sample: the hold's law
  step(14);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_ARRIVED);
  EXPECT_TRUE(reference.feedback_law);  // the hold at the target goes on
  EXPECT_EQ(reference.trolley_feedforward_voltage, 110.0);
  EXPECT_EQ(stage.unsolved_plans(), 0U);

  // A new trapezoid goal replaces the plan: no law on its reference.
  const Request next = trolley_goal(4, 0.5);
  step(15, std::span(&next, 1));
  EXPECT_FALSE(reference.feedback_law);
  EXPECT_EQ(reference.sliding_friction_reduction, 0.0);
  EXPECT_EQ(reference.feedback_gain[0], 0.0);
}

TEST(PlannerStage, AMinimumTimeGoalWithoutAPlanRunsTheTimeOptimalProfile) {
  HeardPlanner p;
  auto& [stage, reference, status] = p;
  const auto step = [&p](std::uint64_t k, std::span<const Request> goals = {}) { p.step(k, goals); };
  step(0);
  const Request goal = minimum_time_goal(5, 0.55);
  step(1, std::span(&goal, 1));
  stage.provide_plan(stage.plan_request()->sequence, nullptr);  // not solved
  step(2);
  EXPECT_EQ(stage.unsolved_plans(), 1U);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_MOVING);
  EXPECT_FALSE(reference.feedback_law);
  // The time-optimal profile's duration for 0.3 m at the rated limits.
  auto time_optimal = lab_planner();
  protocol::Reference expected;
  Request same = goal;
  same.profile = Request::PROFILE_TIME_OPTIMAL;
  (void)time_optimal.step(at_rest(0), {}, expected);
  (void)time_optimal.step(at_rest(1), std::span(&same, 1), expected);
  EXPECT_EQ(reference.move_duration, expected.move_duration);

  // With no supervisor status heard (no sway limit), the goal runs the time-optimal profile at once.
  auto unheard = lab_planner();
  (void)unheard.step(at_rest(0), {}, reference);
  const Request other = minimum_time_goal(6, 0.55);
  (void)unheard.step(at_rest(1), std::span(&other, 1), reference);
  EXPECT_FALSE(unheard.plan_request().has_value());
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_MOVING);
  EXPECT_FALSE(reference.feedback_law);
  EXPECT_EQ(unheard.unsolved_plans(), 1U);  // counted: the node warns (a trapezoid goal is not counted)
  const Request trapezoid = trolley_goal(7, 0.3);
  (void)unheard.step(at_rest(2), std::span(&trapezoid, 1), reference);
  EXPECT_EQ(unheard.unsolved_plans(), 1U);
}

TEST(PlannerStage, AMinimumTimeGoalWaitingForItsCycleIsPlannedAheadAndStartsOnTime) {
  HeardPlanner p;
  auto& [stage, reference, status] = p;
  const auto step = [&p](std::uint64_t k, std::span<const Request> goals = {}) { p.step(k, goals); };
  step(0);
  const Request goal = minimum_time_goal(8, 0.35, 20);
  step(1, std::span(&goal, 1));
  ASSERT_TRUE(stage.plan_request().has_value());  // asked at once, while it waits
  stage.provide_plan(stage.plan_request()->sequence, synthetic_path());
  for (std::uint64_t k = 2; k < 20; ++k) {
    step(k);
    EXPECT_EQ(reference.phase, protocol::Reference::PHASE_HOLDING) << k;
  }
  step(20);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_MOVING);
  EXPECT_TRUE(reference.feedback_law);
  EXPECT_EQ(reference.trolley_feedforward_voltage, 101.0);

  // A stop while it runs: the law is dropped, the speed reference stops the crane.
  Request stop;
  stop.request_id = 9;
  stop.command = Request::COMMAND_STOP;
  step(21, std::span(&stop, 1));
  EXPECT_FALSE(reference.feedback_law);
  EXPECT_EQ(reference.request_id, 9U);

  // A newer goal replaces one that waits for its plan: reported aborted (replaced).
  const Request waiting = minimum_time_goal(10, 0.6);
  for (std::uint64_t k = 22; k < 400; ++k) step(k);  // the stop comes to rest
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_HOLDING);
  step(400, std::span(&waiting, 1));
  ASSERT_TRUE(stage.plan_request().has_value());
  const Request newer = trolley_goal(11, 0.3);
  step(401, std::span(&newer, 1));
  EXPECT_FALSE(stage.plan_request().has_value());
  bool aborted = false;
  for (const auto& f : stage.move_statuses()) {
    aborted = aborted || (f.request_id == 10U && f.result == Feedback::RESULT_ABORTED && f.reason == Feedback::REASON_REPLACED);
  }
  EXPECT_TRUE(aborted);
}

// Over DDS the goal can arrive before the planner has heard the supervisor (another vendor's
// discovery is slower): it is planned as soon as the sway limit is heard, and still starts on time.
TEST(PlannerStage, AWaitingMinimumTimeGoalIsPlannedOnceTheSwayLimitIsHeard) {
  auto stage = lab_planner();
  protocol::Reference reference;
  const Request goal = minimum_time_goal(4, 0.35, 30);
  (void)stage.step(at_rest(0), {}, reference);
  (void)stage.step(at_rest(1), std::span(&goal, 1), reference);  // no status yet
  EXPECT_FALSE(stage.plan_request().has_value());
  const auto status = with_sway_limit(5);
  for (std::uint64_t k = 2; k < 30; ++k) {
    const auto state = at_rest(k);
    (void)stage.step(trajectory_planner::PlannerCycle{&state, {}, {}, k >= 5 ? &status : nullptr}, reference);
    if (k == 4) {
      EXPECT_FALSE(stage.plan_request().has_value());
    }
    if (k == 5) {
      ASSERT_TRUE(stage.plan_request().has_value());
      stage.provide_plan(stage.plan_request()->sequence, synthetic_path());
    }
  }
  const auto state = at_rest(30);
  ASSERT_EQ(stage.step(trajectory_planner::PlannerCycle{&state, {}, {}, &status}, reference), common::StepStatus::ok);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_MOVING);
  EXPECT_TRUE(reference.feedback_law);
}

// A plan request cancelled meanwhile (a change of operating mode) and asked again for the same goal
// is a new request: an answer to the old one is ignored, the crane does not wait for it for ever.
TEST(PlannerStage, AGoalAskedAgainIsANewPlanRequest) {
  HeardPlanner p;
  auto& [stage, reference, status] = p;
  const auto step = [&p](std::uint64_t k, std::span<const Request> goals = {}) { p.step(k, goals); };
  step(0);
  const Request goal = minimum_time_goal(12, 0.35, 20);
  step(1, std::span(&goal, 1));
  ASSERT_TRUE(stage.plan_request().has_value());
  const std::uint64_t first = stage.plan_request()->sequence;
  status.operating_mode = protocol::SupervisorStatus::OPERATION_SEMIAUTOMATIC;
  step(2);  // the mode change cancels the request; the goal, still waiting, is asked again
  ASSERT_TRUE(stage.plan_request().has_value());
  EXPECT_EQ(stage.plan_request()->request_id, 12U);
  EXPECT_NE(stage.plan_request()->sequence, first);
  stage.provide_plan(first, synthetic_path());  // the old request's answer
  for (std::uint64_t k = 3; k < 20; ++k) step(k);
  step(20);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_HOLDING);  // it waits for the new answer
  stage.provide_plan(stage.plan_request()->sequence, synthetic_path());
  step(21);
  EXPECT_EQ(reference.phase, protocol::Reference::PHASE_MOVING);
  EXPECT_TRUE(reference.feedback_law);
}

TEST(PlannedPath, RefusesBadShapesAndClampsItsSamples) {
  auto good = *synthetic_path();
  EXPECT_TRUE(good.valid());
  EXPECT_EQ(good.index(-1.0), 0U);
  EXPECT_EQ(good.index(0.034), 3U);
  EXPECT_EQ(good.index(1e300), 10U);
  EXPECT_NEAR(good.duration(), 0.1, 1e-15);
  auto shorter = good;
  shorter.laws.pop_back();
  EXPECT_FALSE(shorter.valid());
  auto nan = good;
  nan.laws[3].gain[5] = std::nan("");
  EXPECT_FALSE(nan.valid());
  auto reduction = good;
  reduction.laws[0].sliding_friction_reduction = 2.0;
  EXPECT_FALSE(reduction.valid());
  trajectory_planner::TrajectoryPlanner planner{trajectory_planner::TrajectoryPlannerParams{}};
  EXPECT_EQ(planner.start_planned(1, nullptr), trajectory_planner::GoalStatus::rejected_nonfinite);
  EXPECT_EQ(planner.start_planned(1, std::make_shared<const trajectory_planner::PlannedPath>(nan)),
            trajectory_planner::GoalStatus::rejected_nonfinite);
  EXPECT_EQ(planner.start_planned(1, std::make_shared<const trajectory_planner::PlannedPath>(good), true),
            trajectory_planner::GoalStatus::rejected_nonfinite);  // no bridge in it
  ASSERT_EQ(planner.start_planned(1, std::make_shared<const trajectory_planner::PlannedPath>(good)),
            trajectory_planner::GoalStatus::accepted);
  trajectory_planner::PlannerOutput out;
  ASSERT_EQ(planner.step(0.02, out), common::StepStatus::ok);
  EXPECT_NEAR(out.reference.trolley.position, 0.27, 1e-12);
  EXPECT_EQ(out.reference.trolley.velocity, 1.0);
  for (int i = 0; i < 20; ++i) (void)planner.step(0.01, out);
  EXPECT_EQ(out.phase, trajectory_planner::MovePhase::arrived);
  EXPECT_NEAR(out.reference.trolley.position, 0.35, 1e-12);
  EXPECT_EQ(out.reference.trolley.velocity, 0.0);
}

// A client that resends a waiting request (it may have missed the first answer: crane_demo's
// readiness probe) hears WAITING again each time; the request still starts once, at its cycle.
TEST(PlannerStage, AResentWaitingRequestIsReportedWaitingAgain) {
  auto stage = lab_planner();
  const auto request = trolley_goal(7, 0.55, 40);
  const auto feedback = run(stage, 0, 60, {{2, request}, {12, request}, {22, request}});
  std::vector<std::uint64_t> waiting;
  int started = 0;
  for (const auto& f : feedback) {
    EXPECT_EQ(f.request_id, 7U);
    if (f.result == Feedback::RESULT_WAITING) waiting.push_back(f.header.seq);
    if (f.result == Feedback::RESULT_MOVING && f.header.seq == 40U) ++started;
  }
  EXPECT_EQ(waiting, (std::vector<std::uint64_t>{2, 12, 22}));
  EXPECT_EQ(started, 1);
}

TEST(PlannerStage, ANewerRequestAbortsTheRunningOneAndAnOlderIdIsIgnored) {
  auto stage = lab_planner();
  const auto feedback = run(stage, 0, 30, {{1, trolley_goal(7, 1.0)}, {15, trolley_goal(8, 0.5)}, {20, trolley_goal(6, 0.9)}});
  bool aborted = false, ignored_reported = false;
  for (const auto& f : feedback) {
    if (f.request_id == 7 && f.result == Feedback::RESULT_ABORTED) {
      aborted = true;
      EXPECT_EQ(f.reason, Feedback::REASON_REPLACED);
      EXPECT_EQ(f.header.seq, 15U);
    }
    ignored_reported = ignored_reported || f.request_id == 6;
  }
  EXPECT_TRUE(aborted);
  EXPECT_FALSE(ignored_reported) << "a request id not above the last one is a repeat: no feedback";
}

TEST(AntiSwingStage, TheLawRegistryNamesAreTheIdlCodes) {
  for (const char* name : {"none", "pd", "delay1", "delay2", "fuzzy"}) {
    const auto law = anti_swing::law_from_name(name);
    EXPECT_EQ(anti_swing::law_name(law), name);
    anti_swing::AntiSwingStageParams p;
    p.law = law;
    anti_swing::AntiSwingStage stage(p);
    protocol::AntiSwingCommand out;
    auto state = at_rest(3);
    state.swing_in_plane = 0.01;
    EXPECT_NE(stage.step(state, out), common::StepStatus::rejected_nonfinite) << name;
    EXPECT_EQ(out.controller, static_cast<std::uint8_t>(law)) << name;
    EXPECT_EQ(out.header.seq, 3U);
  }
  EXPECT_THROW((void)anti_swing::law_from_name("delayed_feedback"), common::ConfigError);
}

// A free swing at L = 1 m (T = 2 pi sqrt(1 / 9.8) = 2.007 s): 0.1 rad in plane, 0.05 rad out of plane.
protocol::CraneState swinging(std::uint64_t seq) {
  auto s = at_rest(seq, 0.6);
  const double w = std::sqrt(9.8 / 1.0), t = 0.01 * static_cast<double>(seq);
  s.swing_in_plane = 0.1 * std::sin(w * t);
  s.swing_in_plane_rate = 0.1 * w * std::cos(w * t);
  s.swing_out_of_plane = 0.05 * std::cos(w * t);
  s.swing_out_of_plane_rate = -0.05 * w * std::sin(w * t);
  return s;
}

// Every output of the law: actions, reference corrections, the bridge's.
std::array<double, 9> outputs_of(const protocol::AntiSwingCommand& c) {
  return {c.trolley_action, c.slew_action, c.trolley_reference_correction, c.trolley_reference_rate_correction,
          c.slew_reference_correction, c.slew_reference_rate_correction, c.bridge_action, c.bridge_reference_correction,
          c.bridge_reference_rate_correction};
}

// MAINTENANCE (OPC 40020: no anti-swing) from the supervisor's status: every law's output fades to
// exactly 0 within one swing period (fade_periods 1) and stays 0 while the law keeps running; the
// mode holds when no new status comes and an unknown code changes nothing. Leaving MAINTENANCE at
// the worst moment (the largest output of the law), the output fades back in: no cycle changes it
// by more than the law's own largest change in a cycle plus |output| T_s / T, far below the step an
// instant switch makes, and one swing period later it is the law's to the bit.
TEST(AntiSwingStage, MaintenanceSwitchesTheFeedbackOffAndLeavingItFadesItBackWithoutAJump) {
  using Status = protocol::SupervisorStatus;
  using Law = anti_swing::AntiSwingLaw;
  constexpr std::uint64_t kCycles = 2500, kEnter = 500;
  const double period = 2.0 * std::numbers::pi * std::sqrt(1.0 / 9.8), dt = 0.01;
  const auto fade_cycles = static_cast<std::uint64_t>(std::ceil(period / dt));  // 201
  for (const Law law : {Law::pd, Law::delay1, Law::delay2, Law::fuzzy}) {
    const auto name = std::string(anti_swing::law_name(law));
    anti_swing::AntiSwingStageParams p;
    p.law = law;
    p.bridge = true;  // the bridge's outputs (its gantry view: the out-of-plane swing) too
    anti_swing::AntiSwingStage ungated(p), gated(p);
    std::vector<std::array<double, 9>> u(kCycles), g(kCycles);
    std::vector<double> engagement(kCycles);
    protocol::AntiSwingCommand out;
    for (std::uint64_t k = 0; k < kCycles; ++k) {
      ASSERT_NE(ungated.step(swinging(k), out), common::StepStatus::rejected_nonfinite);
      u[k] = outputs_of(out);
    }
    // Back to MANUAL at the largest output between cycles 1400 and 1700: the worst moment.
    std::uint64_t leave = 1400;
    const auto largest = [](const std::array<double, 9>& a) {
      double m = 0.0;
      for (const double v : a) m = std::max(m, std::abs(v));
      return m;
    };
    for (std::uint64_t k = 1400; k < 1700; ++k) {
      if (largest(u[k]) > largest(u[leave])) leave = k;
    }
    ASSERT_GT(largest(u[leave]), 0.0) << name;
    Status manual, maintenance, unknown;
    manual.operating_mode = Status::OPERATION_MANUAL;
    maintenance.operating_mode = Status::OPERATION_MAINTENANCE;
    unknown.operating_mode = 99;
    for (std::uint64_t k = 0; k < kCycles; ++k) {
      const Status* status = k < kEnter ? &manual : k < leave ? &maintenance : &manual;
      if (k > kEnter && k < leave && k % 2 == 1) status = nullptr;  // no new status: the mode holds
      if (k == 900) status = &unknown;
      ASSERT_NE(gated.step(swinging(k), status, out), common::StepStatus::rejected_nonfinite);
      g[k] = outputs_of(out);
      engagement[k] = gated.engagement();
      if (k == 1000) {
        EXPECT_EQ(gated.operating_mode(), Status::OPERATION_MAINTENANCE) << name;
      }
    }
    // Before: the law's, to the bit. The fade out: linear, 0 after one swing period.
    for (std::uint64_t k = 0; k < kEnter; ++k) ASSERT_EQ(g[k], u[k]) << name << " cycle " << k;
    EXPECT_GT(engagement[kEnter + fade_cycles - 2], 0.0) << name;
    EXPECT_EQ(engagement[kEnter + fade_cycles - 1], 0.0) << name;
    for (std::uint64_t k = kEnter + fade_cycles - 1; k < leave; ++k) {
      for (const double v : g[k]) ASSERT_EQ(v, 0.0) << name << ": MAINTENANCE, cycle " << k;
    }
    // Leaving: the largest change in a cycle against the law's own and an instant switch's.
    std::array<double, 9> jump{}, own{}, amplitude{};
    for (std::size_t i = 0; i < 9; ++i) {
      for (std::uint64_t k = leave; k < leave + fade_cycles + 10; ++k) {
        jump[i] = std::max(jump[i], std::abs(g[k][i] - g[k - 1][i]));
        own[i] = std::max(own[i], std::abs(u[k][i] - u[k - 1][i]));
        amplitude[i] = std::max(amplitude[i], std::abs(u[k][i]));
      }
      EXPECT_LE(jump[i], own[i] + amplitude[i] * dt / period + 1e-12) << name << " output " << i;
    }
    // The output largest at the switch: an instant switch would step it by all of it in one cycle.
    std::size_t shown = 0;
    for (std::size_t i = 0; i < 9; ++i) {
      if (std::abs(u[leave][i]) > std::abs(u[leave][shown])) shown = i;
    }
    EXPECT_LT(jump[shown], 0.1 * std::abs(u[leave][shown])) << name << " output " << shown << ": an instant switch";
    std::printf("%s: leaving MAINTENANCE at cycle %llu (output %zu: %.4f): largest change in a cycle %.5f (the law's "
                "own %.5f, an instant switch %.4f); the law's output again from cycle %llu\n",
                name.c_str(), static_cast<unsigned long long>(leave), shown, u[leave][shown], jump[shown], own[shown],
                std::abs(u[leave][shown]), static_cast<unsigned long long>(leave + fade_cycles - 1));
    for (std::uint64_t k = leave + fade_cycles - 1; k < kCycles; ++k) ASSERT_EQ(g[k], u[k]) << name << " cycle " << k;
    EXPECT_EQ(gated.engagement(), 1.0) << name;
  }
}

// Masoud's configuration (3.50): the anti-swing command's reference corrections move the reference
// the tracking PD follows; a correction of the position by d equals a reference d further.
TEST(TrackingStage, ReferenceCorrectionsOfDelay2AreAddedToTheReference) {
  tracking::TrackingStage stage{tracking::TrackingStageParams{}};
  auto state = at_rest(4, 0.5);
  protocol::Reference reference;
  reference.trolley_position = 0.6;
  reference.cable_length = 1.0;
  protocol::AntiSwingCommand corrected;
  corrected.trolley_reference_correction = 0.05;
  protocol::LinearCommand with_correction, moved_reference;
  ASSERT_EQ(stage.step(state, reference, corrected, with_correction), common::StepStatus::ok);
  reference.trolley_position = 0.65;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, moved_reference), common::StepStatus::ok);
  EXPECT_DOUBLE_EQ(with_correction.trolley_voltage, moved_reference.trolley_voltage);
  EXPECT_GT(with_correction.trolley_voltage, 0.0);
  EXPECT_EQ(with_correction.header.seq, 4U);
}

// The online estimate (crane::adaptation) in the tracking stage: a confident payload replaces m_t in
// (3.37), V_x = (1/K_mx)[(L/T^2) V_bar_x + m_t g phi]; at rest on the reference only the swing term
// is left, so 3.0 kg instead of the default params' m_t = 0.09 adds (3 kg / M - 0.09) g phi / K_mx
// = (3/22.222 - 0.09)(9.8)(0.1)/2 V.
TEST(TrackingStage, AConfidentPayloadEstimateReplacesTheConfiguredMass) {
  tracking::TrackingStage stage{tracking::TrackingStageParams{}};
  auto state = at_rest(5, 0.5);
  state.swing_in_plane = 0.1;
  protocol::Reference reference;
  reference.trolley_position = 0.5;
  reference.cable_length = 1.0;
  protocol::LinearCommand configured, estimated, not_confident, absurd;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, configured), common::StepStatus::ok);
  state.payload_mass = 3.0;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, not_confident), common::StepStatus::ok);
  EXPECT_EQ(not_confident.trolley_voltage, configured.trolley_voltage);  // not confident: configured
  state.payload_confident = true;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, estimated), common::StepStatus::ok);
  EXPECT_NEAR(estimated.trolley_voltage - configured.trolley_voltage, (3.0 / 22.222 - 0.09) * 9.8 * 0.1 / 2.0, 1e-12);
  // Fail safe: a payload the gain schedule cannot use falls back to the configured load.
  tracking::TrackingStageParams scheduled;
  scheduled.law = tracking::TrackingLaw::gain_scheduling_partial;
  tracking::TrackingStage schedule{scheduled};
  state.payload_mass = 1e308;
  ASSERT_EQ(schedule.step(state, reference, protocol::AntiSwingCommand{}, absurd), common::StepStatus::ok);
  EXPECT_TRUE(std::isfinite(absurd.trolley_voltage) && std::isfinite(absurd.slew_voltage));
}

// The tracking stage's params from its YAML block on `facts`, with the follower law.
tracking::TrackingStageParams follower_stage_params(const common::StackFacts& facts) {
  const auto yaml = YAML::Load("{proportional_gain: 100.0, derivative_gain: 20.0, min_radius: 0.1, slew_enabled: true, estimate_friction_factor: false}");
  config::YamlSection block(yaml, "tracking");
  tracking::TrackingStageParams params = tracking::read_params(block, facts);
  params.law = tracking::TrackingLaw::follower;
  return params;
}

// The tracking law `follower` applies the feedback law the reference carries (Reference.feedback_law,
// the minimum-time follower's; trajectory_feedback.hpp): u = feedforward - K (z - z_ref), by hand
// here for a gain with one entry in each block, on the slew (tower) and on the bridge (overhead).
TEST(TrackingStage, TheFollowerLawAppliesTheFeedforwardAndGainTheReferenceCarries) {
  tracking::TrackingStageParams params;
  params.law = tracking::TrackingLaw::follower;
  tracking::TrackingStage stage{params};
  EXPECT_EQ(tracking::law_from_name("follower"), tracking::TrackingLaw::follower);
  auto state = at_rest(9, 0.52);
  state.trolley_velocity = 0.31;
  state.slew_angle = 0.2;
  state.slew_rate = 0.4;
  state.swing_in_plane = 0.03;
  state.swing_out_of_plane = -0.01;
  state.swing_out_of_plane_rate = 0.05;
  common::TrajectoryFeedback law;
  law.position = {0.5, 0.02, 0.25, 0.0};
  law.velocity = {0.3, 0.0, 0.35, 0.0};
  law.feedforward = {1.5, -0.7};
  law.gain[0] = 40.0;       // trolley row: V/m on the trolley position
  law.gain[1] = -12.0;      // V/rad on the in-plane swing
  law.gain[4] = 8.0;        // V s/m on the trolley speed
  law.gain[8 + 2] = 30.0;   // slew row: V/rad on the slew angle
  law.gain[8 + 7] = 5.0;    // V s/rad on the out-of-plane swing rate
  law.sliding_friction_reduction = 0.5;
  protocol::Reference reference;
  reference.cable_length = 1.0;
  reference.cable_length_rate = 0.02;
  common::set_trajectory_feedback(law, false, reference);
  EXPECT_EQ(reference.slew_angle, 0.25);
  protocol::LinearCommand command;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
  EXPECT_NEAR(command.trolley_voltage, 1.5 - (40.0 * 0.02 - 12.0 * 0.01 + 8.0 * 0.01), 1e-12);
  EXPECT_NEAR(command.slew_voltage, -0.7 - (30.0 * -0.05 + 5.0 * 0.05), 1e-12);
  EXPECT_EQ(command.hoist_speed, 0.02);
  EXPECT_EQ(command.sliding_friction_reduction, 0.5);
  EXPECT_EQ(command.header.seq, 9U);

  // The voltage limit clamps.
  reference.trolley_feedforward_voltage = 50.0;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
  EXPECT_EQ(command.trolley_voltage, params.tracking.voltage_limit);

  // A reduction outside [0, 1], or a NaN in the law: 0 V, refused.
  reference.trolley_feedforward_voltage = 1.5;
  reference.sliding_friction_reduction = 1.5;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::rejected_nonfinite);
  EXPECT_EQ(command.trolley_voltage, 0.0);
  EXPECT_EQ(command.slew_voltage, 0.0);
  reference.sliding_friction_reduction = 0.5;
  reference.feedback_gain[3] = std::nan("");
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::rejected_nonfinite);
  EXPECT_EQ(command.trolley_voltage, 0.0);

  // A reference without a law (holding, a stop, manual motion) is tracked by the PD law.
  reference.feedback_law = false;
  tracking::TrackingStage pd{tracking::TrackingStageParams{}};
  protocol::LinearCommand by_pd;
  const protocol::AntiSwingCommand action{};
  ASSERT_EQ(stage.step(state, reference, action, command), common::StepStatus::ok);
  ASSERT_EQ(pd.step(state, reference, action, by_pd), common::StepStatus::ok);
  EXPECT_EQ(command.trolley_voltage, by_pd.trolley_voltage);
  EXPECT_EQ(command.slew_voltage, by_pd.slew_voltage);
  EXPECT_EQ(command.sliding_friction_reduction, 0.0);
}

// The factor handed along a move: 1 until the estimate has rows enough (cycle `first_estimate`,
// recorded here the first time `factor` leaves 1), then toward `target` at 1/s, 0.01 a cycle.
void expect_ramp_to(double target, int k, double factor, int& first_estimate) {
  if (first_estimate < 0 && factor != 1.0) first_estimate = k;
  if (first_estimate >= 0) {
    EXPECT_NEAR(factor, std::min(target, 1.0 + 0.01 * (k - first_estimate + 1)), 1e-6) << k;
  }
}

// Along a move the follower's stage estimates the plant's friction over the model's from its own
// feedback (friction_factor_estimate.hpp) and hands it, every cycle, to the friction compensation
// (LinearCommand_.friction_factor), which scales its stiction and the sliding part it keeps by it:
// here the feedback is made (by the trolley's position error against a gain of 40 V/m) what a
// plant with 30 % more friction leaves to it, 0.3 F(v_ref) + 0.05 a_ref less what the compensation
// adds with the factor it was handed.
TEST(TrackingStage, TheFollowerHandsTheCompensationTheFrictionFactorItEstimatesAlongTheMove) {
  const common::StackFacts facts;
  tracking::TrackingStage stage{follower_stage_params(facts)};
  const common::AxisFriction& friction = facts.crane.trolley_friction;
  protocol::Reference reference;
  reference.cable_length = 1.0;
  reference.request_id = 4;
  common::TrajectoryFeedback law;
  law.gain[0] = 40.0;  // [V/m]
  law.sliding_friction_reduction = 0.5;  // along the trajectory
  protocol::LinearCommand command;
  double applied = 1.0;  // the factor the compensation applied to the last command
  int first_estimate = -1;
  for (int k = 0; k < 200; ++k) {
    const double t = 0.01 * k;
    law.position[0] = 0.3 + 0.2 * (1.0 - std::cos(std::numbers::pi * t / 2.0));
    law.velocity[0] = 0.1 * std::numbers::pi * std::sin(std::numbers::pi * t / 2.0);
    const double acceleration = 0.05 * std::numbers::pi * std::numbers::pi * std::cos(std::numbers::pi * t / 2.0);
    common::set_trajectory_feedback(law, false, reference);
    reference.trolley_acceleration = acceleration;
    const double sliding = friction.coulomb_positive + friction.viscous_positive * law.velocity[0];  // (3.1), v > 0
    // The plant has 30 % more friction than the model. Of it, the compensation supplies what the
    // factor it was handed adds to the half it keeps (min(1, 0.5 f) - 0.5 of F), the feedback the rest.
    const double compensated = std::min(1.0, 0.5 * applied) - 0.5;
    const double feedback = (0.3 - compensated) * sliding + 0.05 * acceleration;
    auto state = at_rest(static_cast<std::uint64_t>(k + 1), law.position[0] - feedback / 40.0);
    state.trolley_velocity = law.velocity[0];
    ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
    EXPECT_NEAR(command.trolley_voltage, feedback, 1e-9);
    EXPECT_EQ(command.sliding_friction_reduction, 0.5) << "along the move, as the law says";
    // The model's friction (1) until the move has 20 rows (from k = 11, where v_ref >= 0.05 m/s),
    // then toward the estimate, 1.3, at 1/s (0.01 a cycle), and 1.3 from then on: the rows add back
    // what the compensation took over, so the estimate does not drift toward 1 as the feedback shrinks.
    expect_ramp_to(1.3, k, command.friction_factor, first_estimate);
    applied = command.friction_factor;
  }
  EXPECT_EQ(first_estimate, 30);
  // At the target (the reference at rest): f = 1.3 with the hold's reduction, also once the planner
  // holds (request 0); the compensation then keeps min(1, 0.7 x 1.3) of its sliding part.
  ASSERT_NEAR(applied, 1.3, 1e-6);
  law.velocity = {};
  law.sliding_friction_reduction = 0.3;
  common::set_trajectory_feedback(law, false, reference);
  reference.trolley_acceleration = 0.0;
  for (const std::uint32_t request : {4U, 0U}) {
    reference.request_id = request;
    ASSERT_EQ(stage.step(at_rest(300, law.position[0]), reference, protocol::AntiSwingCommand{}, command),
              common::StepStatus::ok);
    EXPECT_EQ(command.sliding_friction_reduction, 0.3) << request;
    EXPECT_NEAR(command.friction_factor, 1.3, 1e-6) << request;
  }
  // A new move starts with the model's friction (factor 1) until it has rows of its own (the PD
  // law's carries the last move's; ThePdLawEstimatesTheFrictionFactorWhenConfiguredAndCarriesItToTheNextMove).
  reference.request_id = 5;
  ASSERT_EQ(stage.step(at_rest(301, law.position[0]), reference, protocol::AntiSwingCommand{}, command),
            common::StepStatus::ok);
  EXPECT_EQ(command.friction_factor, 1.0);
  // A rate that is not a positive number is refused, naming the field.
  for (const double rate : {0.0, -1.0, std::numeric_limits<double>::infinity(), std::numeric_limits<double>::quiet_NaN()}) {
    auto bad = follower_stage_params(facts);
    bad.friction_factor_rate = rate;
    try {
      tracking::TrackingStage refused{bad};
      ADD_FAILURE() << rate << " accepted";
    } catch (const common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find("tracking.friction_factor_rate"), std::string::npos) << error.what();
    }
  }
}

// With tracking.estimate_friction_factor the PD law (`tracking`, delay1's) estimates the friction
// factor from the balance of the crane's momentum along the move (friction_momentum_balance.hpp),
// hands it along the move at 1/s at most and at the target as estimated, and carries it into the
// next move. Here the law drives a rigid trolley (the load hanging still: momentum (1 + m_t) x_dot
// / K_mx in volt-seconds) whose friction is 1.3 times the model's, compensated with the factor the
// stage hands, and sees it through the state estimator itself (section 4.3: its rates lag the
// trolley's, the balance's voltage side through the same lag). Without the setting (the
// dissertation's (3.5)) the factor stays unset (0).
TEST(TrackingStage, ThePdLawEstimatesTheFrictionFactorWhenConfiguredAndCarriesItToTheNextMove) {
  const common::StackFacts facts;
  const auto stage_params = [&](bool estimate) {
    const auto yaml = YAML::Load(std::string("{proportional_gain: 100.0, derivative_gain: 20.0, min_radius: 0.1, "
                                             "slew_enabled: true, estimate_friction_factor: ") +
                                 (estimate ? "true}" : "false}"));
    config::YamlSection block(yaml, "tracking");
    return tracking::read_params(block, facts);
  };
  tracking::TrackingStage stage{stage_params(true)};
  tracking::TrackingStage dissertation{stage_params(false)};
  state_estimator::StateEstimator estimator{stage_params(true).estimator};
  const common::AxisFriction& friction = facts.crane.trolley_friction;
  const auto model_friction = [&](double v) { return v > 0.0 ? friction.coulomb_positive + friction.viscous_positive * v : 0.0; };
  const double plant_factor = 1.3;
  const double acceleration_per_volt = facts.crane.trolley_drive_gain / (1.0 + facts.crane.mass_ratio());
  protocol::Reference reference;
  reference.cable_length = 1.0;
  reference.request_id = 4;
  protocol::LinearCommand command;
  protocol::LinearCommand unset;
  double x = 0.3;
  double v = 0.0;
  int first_estimate = -1;
  int first_sliding = -1;
  const int cycles = 500;
  for (int k = 0; k < cycles; ++k) {
    // A trapezoid as the planner's: 1 m/s^2 to 0.4 m/s, 1 s at it, 1 m/s^2 down; 0.3 -> 0.86 m.
    const double t = 0.01 * k;
    const double a = t < 0.4 ? 1.0 : t < 1.4 ? 0.0 : t < 1.8 ? -1.0 : 0.0;
    reference.trolley_acceleration = a;
    reference.trolley_position = t < 0.4   ? 0.3 + 0.5 * t * t
                                 : t < 1.4 ? 0.38 + 0.4 * (t - 0.4)
                                 : t < 1.8 ? 0.78 + 0.4 * (t - 1.4) - 0.5 * (t - 1.4) * (t - 1.4)
                                           : 0.86;
    reference.trolley_velocity = t < 0.4 ? t : t < 1.4 ? 0.4 : t < 1.8 ? 0.4 - (t - 1.4) : 0.0;
    common::CraneMeasurement measured;
    measured.trolley_position = x;
    common::CraneStateEstimate e;
    ASSERT_EQ(estimator.step(measured, e), common::StepStatus::ok);
    auto state = at_rest(static_cast<std::uint64_t>(k + 1), e.trolley_position);
    state.trolley_velocity = e.trolley_velocity;
    state.trolley_velocity_raw = e.trolley_velocity_raw;
    ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
    ASSERT_EQ(dissertation.step(state, reference, protocol::AntiSwingCommand{}, unset), common::StepStatus::ok);
    EXPECT_EQ(command.trolley_voltage, unset.trolley_voltage) << "the law's voltage is the dissertation's";
    EXPECT_EQ(unset.friction_factor, 0.0) << k;
    // 1 until 3 blocks of 0.5 s have slid (the measured speed 0.05 m/s or more), then toward the
    // estimate at 0.01 a cycle.
    if (first_sliding < 0 && e.trolley_velocity >= 0.05) first_sliding = k;
    if (first_estimate < 0 && command.friction_factor != 1.0) first_estimate = k;
    // The cycle on the plant: the compensation adds min(1, f) of the model's sliding friction on the
    // measured speed (the raw one, section 4.4.1), the plant's friction is 1.3 times the model's.
    const double compensation = std::min(1.0, command.friction_factor) * model_friction(e.trolley_velocity_raw);
    for (int i = 0; i < 100; ++i) {
      v = std::max(0.0, v + 1e-4 * acceleration_per_volt * (command.trolley_voltage + compensation - plant_factor * model_friction(v)));
      x += 1e-4 * v;
    }
  }
  std::printf("the PD law's estimate on the rigid trolley at friction x1.3: %.4f, first handed at cycle %d (sliding "
              "from %d)\n", command.friction_factor, first_estimate, first_sliding);
  EXPECT_EQ(first_estimate, first_sliding + 149) << "the third block's last cycle";
  EXPECT_NEAR(command.friction_factor, plant_factor, 0.01) << "at the target: the estimate";
  // Holding (request 0) and a new move with no travel of its own (the hoist alone) keep it.
  const double estimated = command.friction_factor;
  for (const std::uint32_t request : {4U, 0U, 5U}) {
    reference.request_id = request;
    reference.cable_length_rate = request == 5 ? 0.1 : 0.0;
    ASSERT_EQ(stage.step(at_rest(cycles + 1, reference.trolley_position), reference, protocol::AntiSwingCommand{}, command),
              common::StepStatus::ok);
    EXPECT_EQ(command.friction_factor, estimated) << request;
  }
  // The shipped configurations name the setting (a missing one is an error, as every field).
  const auto missing = YAML::Load("{proportional_gain: 100.0, derivative_gain: 20.0, min_radius: 0.1, slew_enabled: true}");
  config::YamlSection block(missing, "tracking");
  try {
    (void)tracking::read_params(block, facts);
    ADD_FAILURE() << "a block without estimate_friction_factor accepted";
  } catch (const common::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("tracking.estimate_friction_factor"), std::string::npos) << error.what();
  }
}

// At the target, the follower's hold adds the breakaway ramp (breakaway_ramp.hpp) to a drive the
// friction holds at rest off it: 7 mm past on the trolley, 40 V/m of gain; after 0.1 s at rest,
// 0.02 V more toward the target each cycle. The slew, on its target, gets none; a reference that
// moves forgets the ramp.
TEST(TrackingStage, TheFollowersHoldRampsADriveStuckOffTheTargetTowardIt) {
  tracking::TrackingStage stage{follower_stage_params(common::StackFacts{})};
  common::TrajectoryFeedback law;
  law.position = {0.5, 0.0, 0.3, 0.0};
  law.gain[0] = 40.0;      // [V/m]
  law.gain[8 + 2] = 30.0;  // [V/rad]
  protocol::Reference reference;
  reference.cable_length = 1.0;
  reference.request_id = 7;
  common::set_trajectory_feedback(law, false, reference);
  protocol::LinearCommand command;
  auto state = at_rest(1, 0.507);
  state.slew_angle = 0.3;
  for (int k = 1; k <= 20; ++k) {
    state.header.seq = static_cast<std::uint64_t>(k);
    ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
    const double ramp = k < 10 ? 0.0 : -0.02 * (k - 9);
    EXPECT_NEAR(command.trolley_voltage, -40.0 * 0.007 + ramp, 1e-9) << k;
    EXPECT_EQ(command.slew_voltage, 0.0) << k;
  }
  // The reference moves again (a new leg of the same request): the law's voltage alone, and back at
  // the target the ramp starts from nothing.
  law.velocity[0] = 0.1;
  common::set_trajectory_feedback(law, false, reference);
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
  EXPECT_NEAR(command.trolley_voltage, -40.0 * 0.007, 1e-9);
  law.velocity[0] = 0.0;
  common::set_trajectory_feedback(law, false, reference);
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
  EXPECT_NEAR(command.trolley_voltage, -40.0 * 0.007, 1e-9);
}

TEST(TrackingStage, TheFollowerLawDrivesTheBridgeOfAnOverheadCrane) {
  common::StackFacts overhead;
  overhead.crane_kind = common::CraneKind::overhead;
  overhead.bridge = common::BridgeParameters{50.0, 1.5, {1.0, 1.2, 0.5, 0.6, 0.7, 0.8}};
  const auto yaml = YAML::Load("{proportional_gain: 100.0, derivative_gain: 20.0, min_radius: 0.1, slew_enabled: false, estimate_friction_factor: false}");
  config::YamlSection block(yaml, "tracking");
  tracking::TrackingStageParams params = tracking::read_params(block, overhead);
  params.law = tracking::TrackingLaw::follower;
  tracking::TrackingStage stage{params};
  auto state = at_rest(3, 0.5);
  state.slew_angle = 7.0;  // not the second axis here
  state.bridge_position = 2.1;
  state.bridge_velocity = 0.1;
  common::TrajectoryFeedback law;
  law.position = {0.5, 0.0, 2.0, 0.0};
  law.feedforward = {0.0, 0.4};
  law.gain[8 + 2] = 10.0;
  law.gain[8 + 6] = 3.0;
  protocol::Reference reference;
  reference.cable_length = 1.0;
  common::set_trajectory_feedback(law, true, reference);
  EXPECT_EQ(reference.bridge_position, 2.0);
  EXPECT_EQ(reference.slew_angle, 0.0);
  protocol::LinearCommand command;
  ASSERT_EQ(stage.step(state, reference, protocol::AntiSwingCommand{}, command), common::StepStatus::ok);
  EXPECT_NEAR(command.bridge_voltage, 0.4 - (10.0 * 0.1 + 3.0 * 0.1), 1e-12);
  EXPECT_EQ(command.slew_voltage, 0.0);
  EXPECT_EQ(command.trolley_voltage, 0.0);
}

// The friction compensation stage takes an axis's friction from the estimate only while its
// ADAPTATION_*_FRICTION_ADAPTED bit is set: sliding at v = 0.1 m/s, F_f/K_m = c+ + b+ v (3.1).
TEST(FrictionCompensationStage, UsesTheReleasedFrictionOnlyWhileItsBitIsSet) {
  friction_compensation::FrictionCompensationStage stage{friction_compensation::FrictionCompensationParams{}};
  auto state = at_rest(6, 0.5);
  state.trolley_velocity_raw = 0.1;
  state.trolley_velocity = 0.1;
  auto released = common::CraneParameters{}.trolley_friction;
  released.coulomb_positive = 1.35;
  released.viscous_positive = 2.25;
  common::set_friction_in_use(released, common::CraneParameters{}.slew_friction, state);
  protocol::LinearCommand linear;
  protocol::ActuatorCommand without_bit, with_bit;
  ASSERT_EQ(stage.step(state, linear, without_bit), common::StepStatus::ok);
  EXPECT_NEAR(without_bit.trolley_friction_voltage, 0.9 + 1.5 * 0.1, 1e-12);  // (4.12)
  state.adaptation = protocol::CraneState::ADAPTATION_ENABLED | protocol::CraneState::ADAPTATION_TROLLEY_FRICTION_ADAPTED;
  ASSERT_EQ(stage.step(state, linear, with_bit), common::StepStatus::ok);
  EXPECT_NEAR(with_bit.trolley_friction_voltage, 1.35 + 2.25 * 0.1, 1e-12);
  // A negative coefficient is never used: the configured friction instead.
  state.trolley_friction_coulomb_positive = -1.0;
  ASSERT_EQ(stage.step(state, linear, with_bit), common::StepStatus::ok);
  EXPECT_NEAR(with_bit.trolley_friction_voltage, 0.9 + 1.5 * 0.1, 1e-12);
}

}  // namespace

namespace {

// The supervisor's warnings where a hard stop is not yet required (a limit approached too fast, a
// zone ahead, the site guard's lost link) are answered with the planner's soft stop: the goal is aborted naming the warning and
// the reference decelerates from where it was, without a jump, to rest.
TEST(PlannerStage, ASupervisorApproachWarningStopsTheGoalSoftly) {
  for (const std::uint32_t warning : {protocol::SupervisorStatus::WARNING_SPEED_LIMITED,
                                      protocol::SupervisorStatus::WARNING_ZONE_APPROACH,
                                      protocol::SupervisorStatus::WARNING_SITE}) {
    trajectory_planner::TrajectoryPlannerParams p;
    trajectory_planner::TrajectoryPlannerStage stage(p, 0.01);
    protocol::SupervisorStatus status;
    status.mode = protocol::SupervisorStatus::MODE_OPERATING;
    status.operating_mode = protocol::SupervisorStatus::OPERATION_FULLAUTOMATIC;
    protocol::Reference reference, previous;
    const Request goal = trolley_goal(1, 1.1);
    std::vector<Feedback> feedback;
    for (std::uint64_t k = 0; k < 800; ++k) {
      if (k == 100) status.warnings = warning;  // one cycle of warning, mid-move
      if (k == 101) status.warnings = 0;
      const auto estimate = at_rest(k);
      const trajectory_planner::PlannerCycle cycle{&estimate, k == 0 ? std::span(&goal, 1) : std::span<const Request>(),
                                                   {}, &status};
      ASSERT_EQ(stage.step(cycle, reference), common::StepStatus::ok);
      for (const auto& f : stage.move_statuses()) feedback.push_back(f);
      if (k > 0) {
        // Continuous: no jump of the reference at the hand-over (at most a cycle at full speed).
        EXPECT_LT(std::abs(reference.trolley_position - previous.trolley_position), 0.01) << "cycle " << k;
      }
      previous = reference;
    }
    bool aborted = false;
    for (const auto& f : feedback) {
      if (f.request_id == 1 && f.result == Feedback::RESULT_ABORTED) {
        aborted = true;
        EXPECT_EQ(f.reason, warning == protocol::SupervisorStatus::WARNING_ZONE_APPROACH ? Feedback::REASON_ZONE
                            : warning == protocol::SupervisorStatus::WARNING_SITE       ? Feedback::REASON_SITE
                                                                                         : Feedback::REASON_LIMIT_APPROACH);
      }
    }
    EXPECT_TRUE(aborted);
    EXPECT_LT(reference.trolley_position, 1.0) << "stopped short of the goal";
    EXPECT_EQ(reference.trolley_velocity, 0.0) << "at rest";
    EXPECT_FALSE(stage.under_speed_control());
  }
}

// The drives braked under way (WARNING_DRIVES_BRAKED): the goal pauses. The reference holds the
// measured position at once, while the brakes stay on and while the load still swings (above
// kResumeSwing); then the rest of the goal (the waypoint not yet passed, the target) starts from
// there with the same id, and arrives; no abort. Braked once the goal has arrived, the reference stays the arrived one (its request id and
// phase: what a client waits for). A stop request while paused ends the goal where it is.
TEST(PlannerStage, DrivesBrakedUnderWayPauseTheGoalWhereTheCraneStoppedAndGoOnWhenTheyOpen) {
  trajectory_planner::TrajectoryPlannerParams p;
  trajectory_planner::TrajectoryPlannerStage stage(p, 0.01);
  protocol::SupervisorStatus status;
  status.mode = protocol::SupervisorStatus::MODE_OPERATING;
  status.operating_mode = protocol::SupervisorStatus::OPERATION_FULLAUTOMATIC;
  protocol::Reference reference;
  Request goal = trolley_goal(1, 1.1);
  goal.waypoint_count = 1;  // out to 0.5 m first, then to 1.1 m
  goal.waypoint_trolley[0] = 0.5;
  goal.waypoint_slew[0] = 0.0;
  goal.waypoint_cable_length[0] = 1.0;
  std::vector<Feedback> feedback;
  double stopped_at = 0.0, furthest = 0.0, braked_at = 0.0;
  for (std::uint64_t k = 0; k < 1500; ++k) {
    auto estimate = at_rest(k);
    // The crane follows its reference, except while the brakes hold it (cycles 180-184, on the
    // second segment, and 1300-1319, after the goal arrived).
    const bool brakes = (k >= 180 && k < 185) || (k >= 1300 && k < 1320);
    if (k == 0) stopped_at = estimate.trolley_position;
    if (k > 0 && (!brakes || k == 180 || k == 1300)) stopped_at = reference.trolley_position;
    estimate.trolley_position = stopped_at;
    if (k == 180) braked_at = stopped_at;
    // The brakes' jolt swings the load: 3 deg until cycle 230, then settled; the hoist, which the
    // brakes do not hold, still coasts down until cycle 240.
    if (k >= 185 && k < 230) estimate.swing_in_plane = 0.05;
    if (k >= 185 && k < 240) estimate.cable_length_rate = 0.05;
    status.warnings = brakes ? protocol::SupervisorStatus::WARNING_DRIVES_BRAKED : 0U;
    const std::vector<Request> now = k == 0 ? std::vector<Request>{goal} : std::vector<Request>{};
    const trajectory_planner::PlannerCycle cycle{&estimate, now, {}, &status};
    ASSERT_EQ(stage.step(cycle, reference), common::StepStatus::ok);
    for (const auto& f : stage.move_statuses()) feedback.push_back(f);
    if (k >= 180 && k < 240) {  // held while braked, while the load still swings and the hoist moves
      EXPECT_NEAR(reference.trolley_position, braked_at, 1e-12) << "cycle " << k;
      EXPECT_EQ(reference.trolley_velocity, 0.0) << "cycle " << k;
    }
    if (k > 240 && k < 1300) {
      EXPECT_GE(reference.trolley_position, stopped_at - 1e-12) << "it goes on outward, never back to the waypoint";
      EXPECT_GE(reference.trolley_position, braked_at - 1e-12) << "cycle " << k;
    }
    furthest = std::max(furthest, reference.trolley_position);
    if (k >= 1200) {
      EXPECT_EQ(reference.phase, protocol::Reference::PHASE_ARRIVED) << "cycle " << k;
      EXPECT_EQ(reference.request_id, 1U) << "cycle " << k;
    }
  }
  std::printf("braked at %.3f m on the way from the waypoint (0.5 m) to 1.1 m\n", braked_at);
  EXPECT_GT(braked_at, 0.55) << "on the second segment";
  EXPECT_LT(braked_at, 1.0);
  bool arrived = false;
  for (const auto& f : feedback) {
    if (f.request_id != 1) continue;
    EXPECT_NE(f.result, Feedback::RESULT_ABORTED) << "paused, not aborted";
    arrived = arrived || f.result == Feedback::RESULT_ARRIVED;
  }
  EXPECT_TRUE(arrived);
  EXPECT_NEAR(reference.trolley_position, 1.1, 1e-9);
  EXPECT_LE(furthest, 1.1 + 1e-9);

  // Braked again on a new goal; a stop request while paused ends it there.
  const Request next = trolley_goal(2, 0.3);
  Request stop;
  stop.request_id = 3;
  stop.command = Request::COMMAND_STOP;
  feedback.clear();
  double held = 0.0;
  for (std::uint64_t k = 1500; k < 1800; ++k) {
    auto estimate = at_rest(k);
    if (k == 1560) held = reference.trolley_position;
    estimate.trolley_position = k < 1560 ? reference.trolley_position : held;
    status.warnings = k >= 1560 && k < 1600 ? protocol::SupervisorStatus::WARNING_DRIVES_BRAKED : 0U;
    const std::vector<Request> now = k == 1500 ? std::vector<Request>{next} : k == 1580 ? std::vector<Request>{stop}
                                                                                       : std::vector<Request>{};
    const trajectory_planner::PlannerCycle cycle{&estimate, now, {}, &status};
    ASSERT_EQ(stage.step(cycle, reference), common::StepStatus::ok);
    for (const auto& f : stage.move_statuses()) feedback.push_back(f);
  }
  bool stopped = false;
  for (const auto& f : feedback) {
    if (f.request_id == 2 && f.result == Feedback::RESULT_ABORTED) stopped = f.reason == Feedback::REASON_STOPPED;
    if (f.request_id == 2) {
      EXPECT_NE(f.result, Feedback::RESULT_ARRIVED);
    }
  }
  EXPECT_TRUE(stopped) << "the stop request ends the paused goal";
  EXPECT_NEAR(reference.trolley_position, held, 1e-12) << "where the brakes stopped it: the goal did not go on";
}

}  // namespace

namespace {

// An overhead crane's bridge through the stages (issue 18). The planner runs the bridge beside the
// trolley as one move (both start it or neither, arrived when both are), refuses a bridge target
// outside the runway naming the bound, and refuses AXIS_BRIDGE on a crane without a bridge.
trajectory_planner::TrajectoryPlannerParams overhead_planner_params() {
  trajectory_planner::TrajectoryPlannerParams p;  // trolley [0.1, 1.2] m
  p.bridge_enabled = true;
  p.bridge_min_position = 1.0;
  p.bridge_max_position = 9.0;
  p.manual.bridge = {0.5, 0.5, true};
  return p;
}

TEST(PlannerStageBridge, ABridgeGoalMovesTheBridgeAndArrivesWithTheTrolley) {
  trajectory_planner::TrajectoryPlannerStage stage(overhead_planner_params(), 0.01);
  Request goal = trolley_goal(1, 0.5);
  goal.axes |= Request::AXIS_BRIDGE;
  goal.bridge_target = 6.0;  // 4 m at 0.5 m/s, 0.5 m/s^2: 9 s; the trolley's 0.25 m: about 1 s
  protocol::Reference reference;
  std::vector<Feedback> feedback;
  double peak_bridge_speed = 0.0;
  for (std::uint64_t k = 0; k < 1200; ++k) {
    auto estimate = at_rest(k);
    estimate.bridge_position = k == 0 ? 2.0 : reference.bridge_position;  // follows its reference
    const std::vector<Request> now = k == 0 ? std::vector<Request>{goal} : std::vector<Request>{};
    ASSERT_EQ(stage.step(estimate, now, reference), common::StepStatus::ok);
    peak_bridge_speed = std::max(peak_bridge_speed, std::abs(reference.bridge_velocity));
    for (const auto& f : stage.move_statuses()) feedback.push_back(f);
  }
  EXPECT_DOUBLE_EQ(reference.bridge_position, 6.0);
  EXPECT_DOUBLE_EQ(reference.trolley_position, 0.5);
  EXPECT_NEAR(peak_bridge_speed, 0.5, 1e-9);
  ASSERT_FALSE(feedback.empty());
  EXPECT_EQ(feedback.back().result, Feedback::RESULT_ARRIVED);
  EXPECT_NEAR(feedback.back().move_duration, 4.0 / 0.5 + 0.5 / 0.5, 0.02);  // trapezoid: d/v + v/a
  EXPECT_DOUBLE_EQ(feedback.back().rest_bridge_position, 6.0);
  // Arrived no earlier than the bridge's reference came to rest.
  bool moving_after_trolley = false;
  for (const auto& f : feedback) moving_after_trolley = moving_after_trolley || (f.result == Feedback::RESULT_MOVING && f.time_in_move > 2.0);
  EXPECT_TRUE(moving_after_trolley);
}

TEST(PlannerStageBridge, ABridgeTargetOffTheRunwayIsRejectedAndNothingMoves) {
  trajectory_planner::TrajectoryPlannerStage stage(overhead_planner_params(), 0.01);
  Request goal = trolley_goal(1, 0.5);
  goal.axes |= Request::AXIS_BRIDGE;
  goal.bridge_target = 9.5;
  const auto feedback = run(stage, 0, 50, {{0, goal}});
  ASSERT_FALSE(feedback.empty());
  EXPECT_EQ(feedback.front().result, Feedback::RESULT_REJECTED);
  EXPECT_EQ(feedback.front().reason, Feedback::REASON_BRIDGE_RANGE);
  EXPECT_DOUBLE_EQ(feedback.front().value, 9.5);
  EXPECT_DOUBLE_EQ(feedback.front().bound_min, 1.0);
  EXPECT_DOUBLE_EQ(feedback.front().bound_max, 9.0);
  // The trolley part was not started either.
  protocol::Reference reference;
  ASSERT_EQ(stage.step(at_rest(51), {}, reference), common::StepStatus::ok);
  EXPECT_DOUBLE_EQ(reference.trolley_position, 0.25);

  auto tower = lab_planner();
  const auto refused = run(tower, 0, 5, {{0, goal}});
  ASSERT_FALSE(refused.empty());
  EXPECT_EQ(refused.front().reason, Feedback::REASON_BRIDGE_RANGE);
  EXPECT_EQ(refused.front().bound_min, 0.0);
  EXPECT_EQ(refused.front().bound_max, 0.0);
}

// The controller stages on an overhead crane compute the bridge's command with the trolley's law on
// the bridge's gantry view: the same numbers as a crane whose trolley has the bridge's drive,
// position, velocity and (sign-flipped) swing.
TEST(StagesBridge, TheBridgeGetsTheTrolleyLawOfItsGantryView) {
  common::CraneParameters crane;
  common::BridgeParameters bridge{50.0, 1.5, {1.0, 1.2, 0.5, 0.6, 0.7, 0.8}};
  common::StackFacts overhead;
  overhead.crane = crane;
  overhead.crane_kind = common::CraneKind::overhead;
  overhead.bridge = bridge;
  common::StackFacts gantry;
  gantry.crane = common::bridge_as_trolley(crane, bridge);
  gantry.crane_kind = common::CraneKind::gantry;

  protocol::CraneState state = at_rest(7, 0.6);
  state.bridge_position = 3.0;
  state.bridge_velocity = 0.2;
  state.bridge_velocity_raw = 0.21;
  state.swing_out_of_plane = 0.03;
  state.swing_out_of_plane_rate = -0.1;
  state.payload_mass = crane.load_mass;
  protocol::CraneState view = state;  // what a gantry whose trolley is the bridge would measure
  view.trolley_position = 3.0;
  view.trolley_velocity = 0.2;
  view.trolley_velocity_raw = 0.21;
  view.swing_in_plane = -0.03;
  view.swing_in_plane_rate = 0.1;
  view.swing_out_of_plane = view.swing_out_of_plane_rate = 0.0;

  // Anti-swing (PD, so that one cycle gives an action).
  anti_swing::AntiSwingStageParams ap;
  ap.law = anti_swing::AntiSwingLaw::pd;
  ap.anti_swing.slew_enabled = false;
  ap.bridge = true;
  anti_swing::AntiSwingStage overhead_swing(ap);
  ap.bridge = false;
  anti_swing::AntiSwingStage gantry_swing(ap);
  protocol::AntiSwingCommand a_overhead, a_gantry;
  ASSERT_EQ(overhead_swing.step(state, a_overhead), common::StepStatus::ok);
  ASSERT_EQ(gantry_swing.step(view, a_gantry), common::StepStatus::ok);
  EXPECT_NE(a_gantry.trolley_action, 0.0);
  EXPECT_DOUBLE_EQ(a_overhead.bridge_action, a_gantry.trolley_action);

  // Tracking, from the configuration readers of both facts.
  tracking::TrackingStageParams tp_overhead, tp_gantry;
  {
    const auto yaml = YAML::Load("{proportional_gain: 100.0, derivative_gain: 20.0, min_radius: 0.1, slew_enabled: false, estimate_friction_factor: false}");
    config::YamlSection s1(yaml, "tracking");
    tp_overhead = tracking::read_params(s1, overhead);
    config::YamlSection s2(yaml, "tracking");
    tp_gantry = tracking::read_params(s2, gantry);
  }
  ASSERT_TRUE(tp_overhead.bridge);
  tracking::TrackingStage t_overhead(tp_overhead), t_gantry(tp_gantry);
  protocol::Reference ref;
  ref.header.seq = 7;
  ref.trolley_position = 0.6;
  ref.bridge_position = 3.5;
  ref.bridge_velocity = 0.3;
  protocol::Reference ref_view = ref;
  ref_view.trolley_position = 3.5;
  ref_view.trolley_velocity = 0.3;
  protocol::AntiSwingCommand swing_view = a_gantry;
  protocol::LinearCommand l_overhead, l_gantry;
  ASSERT_EQ(t_overhead.step(state, ref, a_overhead, l_overhead), common::StepStatus::ok);
  ASSERT_EQ(t_gantry.step(view, ref_view, swing_view, l_gantry), common::StepStatus::ok);
  EXPECT_NE(l_gantry.trolley_voltage, 0.0);
  EXPECT_DOUBLE_EQ(l_overhead.bridge_voltage, l_gantry.trolley_voltage);
  EXPECT_DOUBLE_EQ(l_overhead.bridge_tracking_action, l_gantry.trolley_tracking_action);

  // Friction compensation with the bridge's friction.
  friction_compensation::FrictionCompensationParams fp;
  fp.trolley.friction = bridge.friction;
  friction_compensation::FrictionCompensationStage f_gantry(fp);
  fp.trolley.friction = crane.trolley_friction;
  fp.bridge = fp.trolley;
  fp.bridge->friction = bridge.friction;
  friction_compensation::FrictionCompensationStage f_overhead(fp);
  protocol::ActuatorCommand u_overhead, u_gantry;
  ASSERT_EQ(f_overhead.step(state, l_overhead, u_overhead), common::StepStatus::ok);
  ASSERT_EQ(f_gantry.step(view, l_gantry, u_gantry), common::StepStatus::ok);
  EXPECT_NE(u_gantry.trolley_friction_voltage, 0.0);
  EXPECT_DOUBLE_EQ(u_overhead.bridge_voltage, u_gantry.trolley_voltage);
  EXPECT_DOUBLE_EQ(u_overhead.bridge_friction_voltage, u_gantry.trolley_friction_voltage);
}

}  // namespace
