#pragma once
// A move planned by the minimum-time bound and followed in closed loop, for the planner stage's
// PROFILE_MINIMUM_TIME (trajectory_planner/planned_path.hpp; issue 32; docs/optimal_control.md):
// the request mapped onto the optimal control problem (in one place: the planner's goals, crane_sim
// bound and the comparison all call minimum_time_problem), solved by IPOPT, and turned into the
// planner's PlannedPath: the reference of every cycle and the follower's law
// (TrajectoryFollower::law) of every cycle, the last one the hold at the target.
//
// The problem of a request:
//   model          the controllers' model of the configured crane (facts: crane, kind, bridge), rigid
//   drive axes     from/target of the request, the planner's travel range, the request's rated
//                  speed and acceleration (the goal's: the move request's or the planner's rated ones)
//   hoist          the cable from/target, the planner's cable range, the request's hoist limits, each
//                  as the equivalent pendulum's length a L + c (the request's `swing`: the planner's
//                  calibrated manual.swing_length_scale a and swing_length_offset c, or the state
//                  estimator's online estimate; trajectory_planner::equivalent_swing_length; the
//                  rates times a): the swing the plan and its follower's gains are made for is that
//                  pendulum. 1 and 0 (uncalibrated): the cable length itself, to the bit. The range
//                  is the planner's where the pendulum is one down to its shortest cable, else
//                  (a learnt pendulum, trajectory_planner::swings_down_to) from the move's shorter
//                  cable up.
//   voltage        facts.voltage_limit, with the crane's friction (3.1)
//   swing          kBoundSwingFraction x the supervisor's sway limit (request.max_swing): a margin
//                  for the follower's tracking error and a mismatched plant
//
// Errors: minimum_time_problem throws common::ConfigError (optimal_control::validate: a request
// outside the ranges names the field and the bound: an equivalent length a L + c <= 0 is refused
// as minimum_time.hoist.min_position); plan_minimum_time_move returns null when IPOPT solves
// neither the bound nor its fixed-duration fallback (MinimumTimeResult::fallback, followed like the
// bound), and throws what the problem and the follower throw.

#include <memory>

#include "crane/common/stack_facts.hpp"
#include "crane/optimal_control/minimum_time.hpp"
#include "crane/optimal_control/trajectory_follower.hpp"
#include "crane/trajectory_planner/planned_path.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::optimal_control {

/// The bound's swing limit as a fraction of the supervisor's max_swing (see the header; with the
/// whole limit the overhead crane's 10 m trolley bound swung to 20 deg, the limit itself, and its
/// follower tripped it).
inline constexpr double kBoundSwingFraction = 0.5;

/// How a request is planned: the collocation intervals and the follower's weights (its
/// sample_period and voltage_limit are the facts').
struct MovePlanning {
  int intervals{200};
  FollowerParams follower{};
};

/// The problem of `request` (see the header).
[[nodiscard]] MinimumTimeProblem minimum_time_problem(const trajectory_planner::PlanRequest& request,
                                                      const common::StackFacts& facts,
                                                      const trajectory_planner::TrajectoryPlannerParams& planner,
                                                      int intervals);

/// The path of `request`: its bound solved and followed (see the header), or its fixed-duration
/// fallback; null when IPOPT solves neither. `bound`, when given, receives the solution (T*, the
/// solve time, `fallback`).
[[nodiscard]] std::shared_ptr<const trajectory_planner::PlannedPath> plan_minimum_time_move(
    const trajectory_planner::PlanRequest& request, const common::StackFacts& facts,
    const trajectory_planner::TrajectoryPlannerParams& planner, const MovePlanning& planning,
    MinimumTimeResult* bound = nullptr);

/// The path of `follower`, one sample per cycle (see the header), of a bound of duration
/// `minimum_time` [s]; `bridge`: the second axis is an overhead crane's bridge (else the slew). The
/// cable's reference is mapped back from the equivalent pendulum's length of `swing` (the request's,
/// as minimum_time_problem mapped it) to the hoist's.
[[nodiscard]] std::shared_ptr<const trajectory_planner::PlannedPath> planned_path(
    const TrajectoryFollower& follower, double sample_period, bool bridge, double minimum_time,
    const trajectory_planner::EquivalentPendulum& swing);

}  // namespace crane::optimal_control
