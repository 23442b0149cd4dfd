#pragma once
// The plant's numerical error, measured: each demo run at the configured integrator settings
// against a reference (by default CVODE BDF at rtol 1e-12: another solver than the explicit
// Runge-Kutta default, cross-checked by Adams and Verner at 1e-12; docs/integration.md).
//
// Two comparisons per run, because the demo's figures come from a closed loop:
//   - integration error: the configured run's own drive inputs (after the actuation gate, one per
//     10 ms cycle, zero-order hold) replayed open loop on the plant at the reference settings; the
//     largest difference of the true states over the run is the integrator's error alone (the
//     same inputs, the same friction events up to their location);
//   - closed loop: the whole stack run again with the plant at the reference settings; the
//     difference of every figure the demo table prints (maneuver_run.hpp, printed_figures) says
//     how many of its printed digits the integration decides. An encoder count that flips at a
//     different cycle changes the commands from then on, so this difference can exceed the
//     integration error: it is the one the table must be judged by.

#include <string>
#include <vector>

#include "crane/plant/crane_simulator.hpp"
#include "crane/stack/in_process_stack.hpp"

namespace crane::stack {

/// Largest differences between two state histories of the same length (max over cycles and axes).
struct StateDifference {
  double position{0.0};          // [m] trolley, bridge, cable length
  double angle{0.0};             // [rad] slew, both swing angles
  double velocity{0.0};          // [m/s] trolley, bridge, hoist
  double angular_rate{0.0};      // [rad/s] slew and swing rates
};

/// Throws std::invalid_argument when the histories' lengths differ.
[[nodiscard]] StateDifference max_state_difference(const std::vector<plant::PlantState>& a,
                                                   const std::vector<plant::PlantState>& b);

/// The plant at `parameters` (initial state included) driven by `inputs`, one per sample; the
/// state after each step. Throws std::runtime_error naming the cycle when a step fails.
[[nodiscard]] std::vector<plant::PlantState> replay_plant(const plant::SimulatorParameters& parameters,
                                                          const std::vector<plant::DriveInput>& inputs);

/// One figure of the table row at two settings.
struct FigureComparison {
  std::string name;          // the table's column
  int decimals{0};           // as printed
  double at_settings{0.0};   // in the printed unit (NaN: "-")
  double at_reference{0.0};
  /// |at_settings - at_reference| <= half a unit of the last printed decimal (both "-" agree).
  [[nodiscard]] bool agrees() const noexcept;
};

struct ConvergenceCase {
  std::string maneuver;
  bool friction_compensation{true};
  std::vector<FigureComparison> figures;   // every printed figure of the row
  StateDifference integration_error;       // same inputs, reference plant
  StateDifference closed_loop_difference;  // stack re-run with the reference plant
  plant::IntegratorWork work;              // the configured integrator over the run
  plant::IntegratorWork reference_work;
  long friction_events{0};
  long reference_friction_events{0};
  [[nodiscard]] bool agrees() const noexcept;  // every figure agrees
};

/// Runs `runs` on `config` (its plant.integrator) and on the same config with `reference`.
/// Throws what run_in_process throws; std::invalid_argument for a run with a friction change
/// (plant.mismatch.friction_change_factor != 1: the replay does not carry it).
[[nodiscard]] std::vector<ConvergenceCase> run_convergence_study(const StackConfig& config,
                                                                 const std::vector<InProcessRun>& runs,
                                                                 const plant::IntegratorSettings& reference);

/// The reference of the study: CVODE BDF, rtol 1e-12, atol 1e-14.
[[nodiscard]] plant::IntegratorSettings reference_integrator_settings() noexcept;

}  // namespace crane::stack
