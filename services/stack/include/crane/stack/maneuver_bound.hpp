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
//   hoist                              the planner's hoist limits (MoveGoal::cable_limits)
//   drive voltage                      stack.voltage_limit, with the crane's friction (3.1)
//   swing                              supervisor.max_swing
//
// Errors: common::ConfigError from optimal_control::validate (a maneuver outside the planner's
// range names the field and the bound).

#include <string>

#include "crane/optimal_control/minimum_time.hpp"
#include "crane/stack/stack_config.hpp"

namespace crane::stack {

/// The problem of `maneuver` on `config`'s crane, on `intervals` collocation intervals.
[[nodiscard]] optimal_control::MinimumTimeProblem bound_problem(const StackConfig& config,
                                                                const ManeuverConfig& maneuver, int intervals = 100);

}  // namespace crane::stack
