#include "crane/optimal_control/planned_move.hpp"

#include <algorithm>

#include "crane/plant/crane_simulator.hpp"

namespace crane::optimal_control {

MinimumTimeProblem minimum_time_problem(const trajectory_planner::PlanRequest& r, const common::StackFacts& facts,
                                        const trajectory_planner::TrajectoryPlannerParams& planner, int intervals) {
  MinimumTimeProblem problem;
  problem.model = plant::make_crane_dynamics(facts.crane_kind, facts.crane, facts.bridge);
  problem.trolley = {r.trolley_from,
                     r.trolley_target,
                     planner.trolley_min_position,
                     planner.trolley_max_position,
                     r.trolley_limits.max_velocity,
                     r.trolley_limits.max_acceleration};
  problem.trolley_friction = facts.crane.trolley_friction;
  if (facts.crane_kind == common::CraneKind::overhead) {
    problem.second = {r.bridge_from,
                      r.bridge_target,
                      planner.bridge_min_position,
                      planner.bridge_max_position,
                      r.bridge_limits.max_velocity,
                      r.bridge_limits.max_acceleration};
    problem.second_friction = facts.bridge.friction;
  } else {
    problem.second = {r.slew_from,
                      r.slew_target,
                      planner.slew_min_angle,
                      planner.slew_max_angle,
                      r.slew_limits.max_velocity,
                      r.slew_limits.max_acceleration};
    problem.second_friction = facts.crane.slew_friction;
  }
  // The pendulum the plan swings is the request's equivalent one (see the header): its length
  // a L + c, its rates a times the hoist's (the controllers' model is the rigid single pendulum,
  // no hook: a hook's rigging is what the offset takes in).
  // The hoist's range is the planner's where the pendulum is one down to its shortest cable, else
  // the move's own span (a learnt pendulum, trajectory_planner::swings_down_to).
  const trajectory_planner::EquivalentPendulum& swing = r.swing;
  const double scale = swing.scale;
  const double shortest = trajectory_planner::swings_down_to(swing, planner.cable_min_length)
                              ? planner.cable_min_length
                              : std::max(planner.cable_min_length, std::min(r.cable_from, r.cable_target));
  problem.hoist = {trajectory_planner::equivalent_swing_length(swing, r.cable_from),
                   trajectory_planner::equivalent_swing_length(swing, r.cable_target),
                   trajectory_planner::equivalent_swing_length(swing, shortest),
                   trajectory_planner::equivalent_swing_length(swing, planner.cable_max_length),
                   scale * r.cable_limits.max_velocity,
                   scale * r.cable_limits.max_acceleration};
  problem.voltage_limit = facts.voltage_limit;
  problem.max_swing = kBoundSwingFraction * r.max_swing;
  problem.intervals = intervals;
  if (r.robust_length_range > 0.0) {  // robust to the configured pendulum's length (planned_path.hpp)
    problem.detuned_pendulums = {1.0 - r.robust_length_range, 1.0 + r.robust_length_range};
    problem.least_effort_margin = r.robust_margin;
  }
  validate(problem);
  return problem;
}

std::shared_ptr<const trajectory_planner::PlannedPath> planned_path(const TrajectoryFollower& follower,
                                                                   double sample_period, bool bridge,
                                                                   double minimum_time,
                                                                   const trajectory_planner::EquivalentPendulum& swing) {
  auto path = std::make_shared<trajectory_planner::PlannedPath>();
  path->sample_period = sample_period;
  path->minimum_time = minimum_time;
  const std::size_t n = follower.samples() + 1;
  for (auto* axis : {&path->trolley, &path->slew, &path->cable}) axis->resize(n);
  if (bridge) path->bridge.resize(n);
  path->laws.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const TrajectoryNode& node = follower.node(k);
    const bool moving = follower.moving(k);
    path->laws[k] = follower.law(k);
    const common::TrajectoryFeedback& law = path->laws[k];
    path->trolley[k] = {law.position[0], law.velocity[0], moving ? node.trolley_acceleration : 0.0};
    const common::AxisReference second{law.position[2], law.velocity[2], moving ? node.second_acceleration : 0.0};
    (bridge ? path->bridge[k] : path->slew[k]) = second;
    // Back from the equivalent pendulum's length to the hoist's (1 L + 0: the same numbers).
    const double scale = swing.scale;
    path->cable[k] = {(node.cable_length - swing.offset) / scale, node.cable_length_rate / scale,
                      moving ? node.hoist_acceleration / scale : 0.0};
  }
  return path;
}

std::shared_ptr<const trajectory_planner::PlannedPath> plan_minimum_time_move(
    const trajectory_planner::PlanRequest& request, const common::StackFacts& facts,
    const trajectory_planner::TrajectoryPlannerParams& planner, const MovePlanning& planning, MinimumTimeResult* bound) {
  const MinimumTimeProblem problem = minimum_time_problem(request, facts, planner, planning.intervals);
  MinimumTimeResult result = solve_minimum_time(problem);
  if (bound != nullptr) *bound = result;
  if (!result.solved && !result.fallback) return nullptr;  // a fallback is followed like T*'s (minimum_time.hpp)
  FollowerParams params = planning.follower;
  params.sample_period = facts.sample_period;
  params.voltage_limit = facts.voltage_limit;
  const TrajectoryFollower follower(problem, result, params);
  return planned_path(follower, facts.sample_period, facts.crane_kind == common::CraneKind::overhead, result.duration,
                      request.swing);
}

}  // namespace crane::optimal_control
