#pragma once
// The in-process runner: the same stage objects the processes run (state estimator, trajectory
// planner, anti-swing, tracking, friction compensation, supervisor) and the plant stage, composed
// in one thread with no DDS, cycle by cycle in the data-flow order of the lockstep stack
// (docs/architecture.md, "The 100 Hz cycle"):
//
//   cycle k:  plant.sample()  -> estimator -> planner (the goal, waiting for its start cycle)
//             -> anti-swing -> tracking -> friction compensation -> actuators(k)
//             (the planner and the anti-swing law with the status of k-1: the operating mode)
//             -> supervisor(k): every stage fresh, one writer each -> status(k)
//             -> plant.step(actuators(k), gated by status(k-1); cycle 0 by status(0))
//
// Because every stage computes each cycle from the same inputs as over DDS, a run gives the DDS
// lockstep demo's CSV and table (tests/integration checks it to the printed digit); it only drops
// the transport. Used by crane_sim (the demo maneuvers, the mismatch sweep) and tests/closed_loop.

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "crane/optimal_control/planned_move.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"
#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

namespace crane::stack {

/// The whole stack in one thread, one cycle per step(): the composition run_in_process and the
/// operator tests (manual mode, stops, zones) share. The plant starts at rest at the configured
/// crane, trolley at `initial_trolley_position` [m], jib at `initial_slew_angle` [rad].
/// Plans a minimum-time goal (trajectory_planner_stage.hpp, plan_request): its path, or null when
/// it cannot (the goal then runs the time-optimal profile).
using MovePlanner =
    std::function<std::shared_ptr<const trajectory_planner::PlannedPath>(const trajectory_planner::PlanRequest&)>;

/// The planner node's way (trajectory_planner_node.cpp): optimal_control::plan_minimum_time_move of
/// the request on `config` with `planning`; null when the bound is not solved or the request is one
/// it cannot take (common::ConfigError): the goal then runs the time-optimal profile.
[[nodiscard]] MovePlanner planner_node_way(const StackConfig& config, const optimal_control::MovePlanning& planning = {});

struct InProcessOptions {
  bool friction_compensation{true};
  ControllerChoice controller{};
  plant::PlantMismatch mismatch{};
  double initial_trolley_position{0.25};  // [m]
  double initial_slew_angle{0.0};         // [rad]
  double initial_bridge_position{0.0};    // [m] overhead crane
  // How a minimum-time goal (PROFILE_MINIMUM_TIME) is planned when the planner asks (empty: the
  // planner node's way, optimal_control::plan_minimum_time_move with MovePlanning{}).
  MovePlanner plan_move{};
  // A stalled command chain, for fault tests: from cycle `lost_commands_from` on, for
  // `lost_commands` cycles, no actuator command reaches the plant (the stages still run); the
  // plant's actuation gate holds the last one, then its command watchdog brakes (actuation_gate.hpp).
  std::uint64_t lost_commands_from{0};
  std::uint64_t lost_commands{0};
  // A starved machine's chain, for fault tests: each cycle's command is lost with this probability
  // [0, 1] (seeded, independent per cycle; late past the plant's deadline), in addition to the
  // window above. Throws std::invalid_argument outside [0, 1].
  double lost_command_probability{0.0};
  std::uint64_t lost_command_seed{1};
};

/// The plant stage of a run: the configured simulator and actuation gate, at rest at the options'
/// initial trolley position [m], slew angle [rad] and bridge position [m], with their mismatch.
[[nodiscard]] plant::PlantStageParams plant_stage_params(const StackConfig& cfg, const InProcessOptions& options);

class InProcessStack {
 public:
  /// Throws common::ConfigError for invalid params.
  InProcessStack(const StackConfig& config, const InProcessOptions& options);
  ~InProcessStack();
  InProcessStack(const InProcessStack&) = delete;
  InProcessStack& operator=(const InProcessStack&) = delete;

  /// One cycle k: the sensors of k through the chain (the planner with these goals, stop requests
  /// and operator speeds; the planner and the anti-swing stage with the supervisor status of cycle
  /// k - 1), the supervisor with `command` (nullptr: none), then the plant over [k, k+1) gated by
  /// the status of k - 1. Throws std::runtime_error naming the cycle when the estimator or the
  /// planner refuses its input.
  void step(std::span<const protocol::MoveRequest> goals = {}, std::span<const protocol::OperatorSpeed> speeds = {},
            const protocol::SupervisorCommand* command = nullptr);

  [[nodiscard]] std::uint64_t cycle() const noexcept;             // cycles stepped
  [[nodiscard]] const protocol::SensorSample& sensors() const noexcept;       // of the last cycle
  [[nodiscard]] const protocol::SensorSample& next_sensors() const noexcept;  // sampled after it
  [[nodiscard]] const protocol::CraneState& estimate() const noexcept;        // of the last cycle
  [[nodiscard]] const protocol::Reference& reference() const noexcept;
  [[nodiscard]] const protocol::AntiSwingCommand& anti_swing() const noexcept;  // of the last cycle
  [[nodiscard]] const protocol::LinearCommand& linear() const noexcept;
  [[nodiscard]] const protocol::ActuatorCommand& actuators() const noexcept;
  [[nodiscard]] const protocol::SupervisorStatus& status() const noexcept;
  [[nodiscard]] const trajectory_planner::TrajectoryPlannerStage& planner() const noexcept;
  [[nodiscard]] const plant::PlantStage& plant() const noexcept;
  [[nodiscard]] std::uint64_t plant_step_failures() const noexcept;

 private:
  struct Stages;
  std::unique_ptr<Stages> stages_;
};

struct InProcessRun {
  ManeuverConfig maneuver;
  bool friction_compensation{true};
  ControllerChoice controller{};
  std::uint8_t profile{protocol::MoveRequest::PROFILE_TRAPEZOID};
  plant::PlantMismatch mismatch{};
  std::uint64_t start_cycle{kMoveStartCycle};  // the move request's header.seq (> 0)
  std::uint32_t request_id{1};
  // A move made first, unmeasured, from its initial positions (where the crane starts) to its
  // targets, which must be the maneuver's start, with its own limits and a trapezoid profile (the
  // maneuver's duration); then the maneuver, measured: a move after one with the same load, what
  // the online estimate has learnt from (docs/architecture.md, "Online estimation"). The first move
  // may not hoist (std::invalid_argument); with the minimum-time profile it is planned by plan_move.
  std::optional<ManeuverConfig> first_move;
  std::uint8_t first_move_profile{protocol::MoveRequest::PROFILE_TRAPEZOID};
  // Keep the plant's drive input and true state of every cycle (InProcessResult::plant_inputs,
  // plant_states): the convergence study's replay (convergence_study.hpp).
  bool record_plant{false};
  MovePlanner plan_move{};  // InProcessOptions::plan_move
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
  std::uint64_t unsolved_plans{0};   // minimum-time goals the planner ran as the time-optimal profile, no plan
                                     // solved (TrajectoryPlannerStage::unsolved_plans; a first move's included)
  plant::IntegratorWork integrator_work;  // the plant's integrator over the whole run
  // With InProcessRun::record_plant, from cycle 0 (rest and a first move included): the input the
  // plant held over cycle k (after the actuation gate) and its true state at the end of it, and
  // the plant's parameters (the mismatch applied; its initial state is the state before cycle 0).
  std::vector<plant::DriveInput> plant_inputs;
  std::vector<plant::PlantState> plant_states;
  plant::SimulatorParameters plant_parameters;
};

/// Runs `run` on `config`. Throws std::runtime_error naming the cycle when the goal is refused or
/// the move never starts, common::ConfigError for invalid params.
[[nodiscard]] InProcessResult run_in_process(const StackConfig& config, const InProcessRun& run);

}  // namespace crane::stack
