#pragma once
// A demo maneuver run by the follower of its minimum-time trajectory (optimal_control/
// trajectory_follower.hpp; issue 32, item 2; docs/optimal_control.md), in one process, on the
// stack's own stage objects where the follower does not replace them:
//
//   cycle k:  plant.sample() -> state estimator -> the reference with the follower's law of
//             cycle k (TrajectoryFollower::law, in place of the planner's; no anti-swing stage)
//             -> tracking (law `follower`) -> friction compensation (the law's sliding friction
//             reduction) -> actuators(k) -> supervisor(k) -> plant.step(actuators(k), gated by
//             status(k - 1))
//
// in the order and with the gating of the in-process stack (in_process_stack.hpp); the move starts
// at kMoveStartCycle like the demo's. The bound is solved on the controllers' model (the configured
// crane, rigid: crane:, no hook or rope) with the limits of stack::bound_problem; the plant is the
// configured one with `mismatch` applied, so the follower is measured against a crane it does not
// know exactly. The DDS stack cannot run it yet: the planner does not solve the bound
// (docs/optimal_control.md, "The law on the wire", says what remains).
//
// Errors: common::ConfigError for invalid params (the bound's, the follower's); std::runtime_error
// when the bound is not solved or the estimator refuses a sample.

#include <cstdint>
#include <optional>
#include <vector>

#include "crane/optimal_control/minimum_time.hpp"
#include "crane/optimal_control/trajectory_follower.hpp"
#include "crane/plant/plant_stage.hpp"
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
};

struct FollowerResult {
  optimal_control::MinimumTimeResult bound;  // T* and the trajectory followed
  std::vector<CycleRecord> records;          // the move's cycles, from its start, maneuver.duration long
  ManeuverMetrics metrics;
  double swing_period{0.0};                  // [s] at the target cable length
  std::uint32_t latched_faults{0};           // the supervisor's at the end (FAULT_* bits)
  std::uint64_t braked_cycles{0};            // cycles of the move with the brakes on
  double follower_setup_seconds{0.0};        // [s] wall time of the gains (linearization and Riccati)
};

/// The bound's problem on the controllers' model: bound_problem (maneuver_bound.hpp) on the
/// configured crane, rigid (no hook, no rope: the follower's model), with `intervals` intervals.
[[nodiscard]] optimal_control::MinimumTimeProblem follower_problem(const StackConfig& config,
                                                                   const ManeuverConfig& maneuver, int intervals);

/// Runs `run` on `config` (see the header).
[[nodiscard]] FollowerResult run_follower(const StackConfig& config, const FollowerRun& run);

}  // namespace crane::stack
