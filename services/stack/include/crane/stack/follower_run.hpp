#pragma once
// A demo maneuver run by the follower of its minimum-time trajectory (optimal_control/
// trajectory_follower.hpp; issue 32; docs/optimal_control.md) on the whole in-process stack
// (run_in_process, the stage objects the DDS processes run), controller `follower` with the
// profile minimum_time: the planner is handed the path of this run's bound (solved here on the
// controllers' model, or given: a comparison runs several plants on one bound, FollowerRun::bound)
// instead of solving it, and the tracking stage applies its law. The plant is the configured one
// with `mismatch` applied, so the follower is measured against a crane it does not know exactly.
// The DDS lockstep demo (`crane_demo --controller follower`) runs the same stages with the
// planner process solving the bound (integration.Controllers/SimMatchesDemo.*follower).
//
// With a first move (FollowerRun::first_move, learning_move): the crane makes that move first,
// minimum-time, then the maneuver, and the stack's planner plans both as the planner node does
// (optimal_control::plan_minimum_time_move with `intervals` and `follower`), each from what the
// state estimator knows when it is asked: the pendulum learnt in the first move
// (state_estimator.swing_length, when enabled) is the one the maneuver's plan swings.
//
// Errors: common::ConfigError for invalid params (the bound's, the follower's); std::runtime_error
// when the bound is not solved or the run fails (run_in_process).

#include <cstdint>
#include <optional>
#include <vector>

#include "crane/optimal_control/minimum_time.hpp"
#include "crane/optimal_control/planned_move.hpp"
#include "crane/optimal_control/trajectory_follower.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/stack/maneuver_bound.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace crane::stack {

struct FollowerRun {
  ManeuverConfig maneuver;
  bool friction_compensation{true};
  plant::PlantMismatch mismatch{};
  int intervals{200};                          // collocation intervals of the bound
  // The bound of follower_problem(config, maneuver, intervals), when solved already (a comparison
  // runs several plants on one bound); empty: solved here.
  std::optional<optimal_control::MinimumTimeResult> bound;
  // The law's weights and its hold at the target; sample_period and voltage_limit are the stack's.
  optimal_control::FollowerParams follower{};
  // A move made first, unmeasured (see the header; InProcessRun::first_move). `bound` is then only
  // the ratio's reference (FollowerResult::bound); the maneuver is planned in the stack.
  std::optional<ManeuverConfig> first_move;
};

struct FollowerResult {
  optimal_control::MinimumTimeResult bound;  // T* and the trajectory followed
  std::vector<CycleRecord> records;          // the move's cycles, from its start, maneuver.duration long
  ManeuverMetrics metrics;
  double swing_period{0.0};                  // [s] at the target cable length
  std::uint32_t latched_faults{0};           // the supervisor's at the end (FAULT_* bits)
  std::uint64_t braked_cycles{0};            // cycles of the move with the brakes on
  std::uint64_t unsolved_plans{0};           // InProcessResult::unsolved_plans
  double follower_setup_seconds{0.0};        // [s] wall time of the gains (linearization and Riccati)
  trajectory_planner::EquivalentPendulum planned_swing{};  // the pendulum the maneuver's plan swung
};

/// The move a run makes first to learn the load's swing (FollowerRun::first_move): the config's first
/// demo maneuver backwards, from its target to where `maneuver` starts (trolley, slew, bridge), at
/// the configured cable, with the demo's rated limits, recorded for `maneuver`'s duration. Throws
/// std::invalid_argument when the config has no demo maneuver.
[[nodiscard]] ManeuverConfig learning_move(const StackConfig& config, const ManeuverConfig& maneuver);

/// The bound's problem on the controllers' model: optimal_control::minimum_time_problem (the
/// planner's mapping) of plan_request_of, with `intervals` intervals.
[[nodiscard]] optimal_control::MinimumTimeProblem follower_problem(const StackConfig& config,
                                                                   const ManeuverConfig& maneuver, int intervals);

/// Runs `run` on `config` (see the header).
[[nodiscard]] FollowerResult run_follower(const StackConfig& config, const FollowerRun& run);

}  // namespace crane::stack
