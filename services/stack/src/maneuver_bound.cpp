#include "crane/stack/maneuver_bound.hpp"

#include <algorithm>

#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::stack {

optimal_control::MinimumTimeProblem bound_problem(const StackConfig& config, const ManeuverConfig& maneuver,
                                                  int intervals) {
  const plant::SimulatorParameters& p = config.plant;
  const trajectory_planner::TrajectoryPlannerParams& planner = config.trajectory_planner;
  const supervisor::SupervisorParams& limits = config.supervisor;
  optimal_control::MinimumTimeProblem problem;
  problem.model = plant::make_crane_dynamics(p.kind, p.crane, p.bridge, p.hook, p.rope);
  problem.trolley = {maneuver.initial_trolley_position,
                     maneuver.trolley_target,
                     planner.trolley_min_position,
                     planner.trolley_max_position,
                     std::min(maneuver.trolley_max_velocity, limits.trolley_max_speed),
                     maneuver.trolley_max_acceleration};
  problem.trolley_friction = p.crane.trolley_friction;
  if (p.kind == common::CraneKind::overhead) {
    problem.second = {maneuver.initial_bridge_position,
                      maneuver.bridge_target,
                      planner.bridge_min_position,
                      planner.bridge_max_position,
                      std::min(maneuver.bridge_max_velocity, limits.bridge_max_speed),
                      maneuver.bridge_max_acceleration};
    problem.second_friction = p.bridge.friction;
  } else {
    problem.second = {maneuver.initial_slew_angle,
                      maneuver.slew_target,
                      planner.slew_min_angle,
                      planner.slew_max_angle,
                      std::min(maneuver.slew_max_velocity, limits.slew_max_rate),
                      maneuver.slew_max_acceleration};
    problem.second_friction = p.crane.slew_friction;
  }
  const trajectory_planner::AxisLimits hoist = trajectory_planner::MoveGoal{}.cable_limits;
  // The hoist's speed is also bounded by what the actuation gate accepts (a faster command is
  // rejected, and three in a row brake the crane).
  problem.hoist = {p.crane.cable_length,
                   maneuver.cable_length_target,
                   planner.cable_min_length,
                   planner.cable_max_length,
                   std::min(hoist.max_velocity, config.actuation.hoist_speed_limit),
                   hoist.max_acceleration};
  problem.voltage_limit = config.facts.voltage_limit;
  problem.max_swing = kBoundSwingFraction * limits.max_swing;
  problem.intervals = intervals;
  return problem;
}

}  // namespace crane::stack
