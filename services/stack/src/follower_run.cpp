#include "crane/stack/follower_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "crane/stack/in_process_stack.hpp"
#include "crane/stack/maneuver_bound.hpp"

namespace crane::stack {
namespace {

}  // namespace

optimal_control::MinimumTimeProblem follower_problem(const StackConfig& cfg, const ManeuverConfig& m, int intervals) {
  return optimal_control::minimum_time_problem(plan_request_of(cfg, m), cfg.facts, cfg.trajectory_planner, intervals);
}

ManeuverConfig learning_move(const StackConfig& cfg, const ManeuverConfig& m) {
  if (cfg.maneuvers.empty()) throw std::invalid_argument("learning move: the config has no demo maneuver");
  ManeuverConfig back = cfg.maneuvers.front();
  back.name = back.name + " backwards to " + m.name;
  back.initial_trolley_position = back.trolley_target;
  back.initial_slew_angle = back.slew_target;
  back.initial_bridge_position = back.bridge_target;
  back.trolley_target = m.initial_trolley_position;
  back.slew_target = m.initial_slew_angle;
  back.bridge_target = m.initial_bridge_position;
  back.cable_length_target = cfg.facts.crane.cable_length;
  back.duration = m.duration;
  return back;
}

FollowerResult run_follower(const StackConfig& cfg, const FollowerRun& run) {
  const ManeuverConfig& m = run.maneuver;
  const double dt = cfg.facts.sample_period;
  const optimal_control::MinimumTimeProblem problem = follower_problem(cfg, m, run.intervals);
  FollowerResult result;
  result.bound = run.bound ? *run.bound : optimal_control::solve_minimum_time(problem);
  if (!result.bound.solved) {
    throw std::runtime_error("follower run " + m.name + ": the bound was not solved (" + result.bound.status + ")");
  }
  optimal_control::FollowerParams follower_params = run.follower;
  follower_params.sample_period = dt;
  follower_params.voltage_limit = cfg.facts.voltage_limit;

  // The stack, its planner handed this run's path for the maneuver's request, or (after a first
  // move) planning each request itself.
  InProcessRun stack_run;
  stack_run.maneuver = m;
  stack_run.friction_compensation = run.friction_compensation;
  stack_run.controller = choose_controller("follower", m, false);
  stack_run.profile = protocol::MoveRequest::PROFILE_MINIMUM_TIME;
  stack_run.mismatch = run.mismatch;
  if (run.first_move) {
    stack_run.first_move = run.first_move;
    stack_run.first_move_profile = protocol::MoveRequest::PROFILE_MINIMUM_TIME;
    stack_run.plan_move = [plan = planner_node_way(cfg, {run.intervals, run.follower}),
                           &result](const trajectory_planner::PlanRequest& request) {
      result.planned_swing = request.swing;  // the last request is the maneuver's
      return plan(request);
    };
  } else {
    const auto setup_start = std::chrono::steady_clock::now();
    const optimal_control::TrajectoryFollower follower(problem, result.bound, follower_params);
    const auto path = optimal_control::planned_path(follower, dt, cfg.facts.crane_kind == common::CraneKind::overhead,
                                                    result.bound.duration, cfg.trajectory_planner.manual.pendulum());
    result.follower_setup_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();
    result.planned_swing = cfg.trajectory_planner.manual.pendulum();
    stack_run.plan_move = [path](const trajectory_planner::PlanRequest&) { return path; };
  }
  InProcessResult stack_result = run_in_process(cfg, stack_run);
  result.records = std::move(stack_result.records);
  result.metrics = stack_result.metrics;
  result.swing_period = stack_result.swing_period;
  result.latched_faults = stack_result.latched_faults;
  result.braked_cycles = stack_result.braked_cycles;
  result.unsolved_plans = stack_result.unsolved_plans;
  return result;
}

}  // namespace crane::stack
