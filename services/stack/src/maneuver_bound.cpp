#include "crane/stack/maneuver_bound.hpp"

#include <algorithm>

#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::stack {

trajectory_planner::PlanRequest plan_request_of(const StackConfig& cfg, const ManeuverConfig& m) {
  // The maneuver as the planner stage would ask for it, with the limits of the header: the
  // maneuver's rated motion capped by the supervisor's overspeed, the hoist by the actuation gate's.
  const supervisor::SupervisorParams& limits = cfg.supervisor;
  trajectory_planner::PlanRequest r;
  r.request_id = 1;
  r.trolley_from = m.initial_trolley_position;
  r.trolley_target = m.trolley_target;
  r.trolley_limits = {std::min(m.trolley_max_velocity, limits.trolley_max_speed), m.trolley_max_acceleration};
  r.slew_from = m.initial_slew_angle;
  r.slew_target = m.slew_target;
  r.slew_limits = {std::min(m.slew_max_velocity, limits.slew_max_rate), m.slew_max_acceleration};
  r.cable_from = cfg.facts.crane.cable_length;
  r.cable_target = m.cable_length_target;
  const trajectory_planner::AxisLimits hoist = trajectory_planner::MoveGoal{}.cable_limits;
  r.cable_limits = {std::min(hoist.max_velocity, cfg.actuation.hoist_speed_limit), hoist.max_acceleration};
  r.bridge = cfg.facts.crane_kind == common::CraneKind::overhead;
  r.bridge_from = m.initial_bridge_position;
  r.bridge_target = m.bridge_target;
  r.bridge_limits = {std::min(m.bridge_max_velocity, limits.bridge_max_speed), m.bridge_max_acceleration};
  r.max_swing = limits.max_swing;
  trajectory_planner::plan_on_pendulum(r, cfg.trajectory_planner.manual.pendulum(), false, cfg.trajectory_planner);
  return r;
}

optimal_control::MinimumTimeProblem bound_problem(const StackConfig& config, const ManeuverConfig& maneuver,
                                                  int intervals) {
  // The planner's mapping (minimum_time_problem), on the plant's model: the configured crane
  // (plant.crane is crane:) with its hook if enabled.
  optimal_control::MinimumTimeProblem problem = optimal_control::minimum_time_problem(
      plan_request_of(config, maneuver), config.facts, config.trajectory_planner, intervals);
  const plant::SimulatorParameters& p = config.plant;
  problem.model = plant::make_crane_dynamics(p.kind, p.crane, p.bridge, p.hook, p.rope);
  return problem;
}

}  // namespace crane::stack
