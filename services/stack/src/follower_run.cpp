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
  const auto setup_start = std::chrono::steady_clock::now();
  const optimal_control::TrajectoryFollower follower(problem, result.bound, follower_params);
  const auto path = optimal_control::planned_path(follower, dt, cfg.facts.crane_kind == common::CraneKind::overhead,
                                                  result.bound.duration, cfg.trajectory_planner.manual);
  result.follower_setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();

  // The stack, the planner handed this path for the maneuver's request.
  InProcessRun stack_run;
  stack_run.maneuver = m;
  stack_run.friction_compensation = run.friction_compensation;
  stack_run.controller = choose_controller("follower", m, false);
  stack_run.profile = protocol::MoveRequest::PROFILE_MINIMUM_TIME;
  stack_run.mismatch = run.mismatch;
  stack_run.plan_move = [path](const trajectory_planner::PlanRequest&) { return path; };
  InProcessResult stack_result = run_in_process(cfg, stack_run);
  result.records = std::move(stack_result.records);
  result.metrics = stack_result.metrics;
  result.swing_period = stack_result.swing_period;
  result.latched_faults = stack_result.latched_faults;
  result.braked_cycles = stack_result.braked_cycles;
  return result;
}

}  // namespace crane::stack
