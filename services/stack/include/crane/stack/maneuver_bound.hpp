#pragma once
// The minimum-time bound of a demo maneuver on the configured crane (optimal_control/minimum_time.hpp;
// docs/optimal_control.md): the config mapped onto the optimal control problem, in one place for
// crane_sim bound, the benchmarks and the tests.
//
// What bounds the move, and from where:
//   the plant's model                  plant: and crane: (make_crane_dynamics, with the hook if enabled)
//   rated speed and acceleration       the maneuver's (3.54)/(3.55) limits, each capped by the
//                                      supervisor's overspeed (trolley_max_speed, slew_max_rate,
//                                      bridge_max_speed)
//   travel                             the planner's range (trajectory_planner.*_position/_angle,
//                                      the cable's min/max length)
//   hoist                              the planner's hoist limits (MoveGoal::cable_limits), the speed
//                                      capped by the actuation gate's hoist_speed_limit
//   drive voltage                      stack.voltage_limit, with the crane's friction (3.1)
//   swing                              optimal_control::kBoundSwingFraction x supervisor.max_swing
//                                      (planned_move.hpp, the planner's rule too): a margin for the
//                                      follower's tracking error and a mismatched plant, so that a
//                                      healthy crane on its bound never trips the sway limiter (with
//                                      the whole limit the overhead crane's 10 m trolley bound swung
//                                      to 20 deg, the limit itself, and its follower tripped it)
//
// Errors: common::ConfigError from optimal_control::validate (a maneuver outside the planner's
// range names the field and the bound).

#include <string>

#include "crane/optimal_control/minimum_time.hpp"
#include "crane/optimal_control/planned_move.hpp"
#include "crane/stack/stack_config.hpp"

namespace crane::stack {

/// The maneuver as the planner stage asks for its minimum-time plan, with the limits above (its rated
/// motion capped by the supervisor's overspeed, the hoist's by the actuation gate's, the
/// supervisor's sway limit); from the maneuver's initial positions and the configured cable, the
/// configured equivalent pendulum (trajectory_planner.manual).
[[nodiscard]] trajectory_planner::PlanRequest plan_request_of(const StackConfig& config, const ManeuverConfig& maneuver);

/// The problem of `maneuver` on `config`'s crane, on `intervals` collocation intervals:
/// optimal_control::minimum_time_problem of plan_request_of (the planner's mapping), on the plant's
/// model.
[[nodiscard]] optimal_control::MinimumTimeProblem bound_problem(const StackConfig& config,
                                                                const ManeuverConfig& maneuver, int intervals = 100);

}  // namespace crane::stack
