#pragma once
// The in-process runner: the same stage objects the processes run (state estimator, trajectory
// planner, anti-swing, tracking, friction compensation, supervisor) and the plant stage, composed
// in one thread with no DDS, cycle by cycle in the data-flow order of the lockstep stack
// (docs/architecture.md, "The 100 Hz cycle"):
//
//   cycle k:  plant.sample()  -> estimator -> planner (the goal, waiting for its start cycle)
//             -> anti-swing -> tracking -> friction compensation -> actuators(k)
//             -> supervisor(k): every stage fresh, one writer each -> status(k)
//             -> plant.step(actuators(k), gated by status(k-1); cycle 0 by status(0))
//
// Because every stage computes each cycle from the same inputs as over DDS, a run gives the DDS
// lockstep demo's CSV and table (tests/integration checks it to the printed digit); it only drops
// the transport. Used by crane_sim (the demo maneuvers, the mismatch sweep) and tests/closed_loop.

#include <cstdint>
#include <vector>

#include "crane/plant/plant_stage.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace crane::stack {

struct InProcessRun {
  ManeuverConfig maneuver;
  bool friction_compensation{true};
  ControllerChoice controller{};
  std::uint8_t profile{protocol::MoveRequest::PROFILE_TRAPEZOID};
  plant::PlantMismatch mismatch{};
  std::uint64_t start_cycle{kMoveStartCycle};  // the move request's header.seq (> 0)
  std::uint32_t request_id{1};
};

struct InProcessResult {
  std::vector<CycleRecord> records;  // the move's cycles, start_cycle .. start_cycle + duration / T
  ManeuverMetrics metrics;
  double swing_period{0.0};          // [s] at the target cable length
  std::uint64_t cycles{0};           // plant cycles simulated (rest included)
  std::uint64_t braked_cycles{0};    // cycles of the move with the brakes on
  std::uint64_t plant_step_failures{0};
  long friction_events{0};
  std::uint32_t latched_faults{0};   // the supervisor's at the end
};

/// Runs `run` on `config`. Throws std::runtime_error naming the cycle when the goal is refused or
/// the move never starts, common::ConfigError for invalid params.
[[nodiscard]] InProcessResult run_in_process(const StackConfig& config, const InProcessRun& run);

}  // namespace crane::stack
