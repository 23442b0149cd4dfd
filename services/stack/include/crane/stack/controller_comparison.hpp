#pragma once
// The comparison of the controllers against the minimum-time bound (issue 32, item 3;
// docs/optimal_control.md, "The comparison"): for a move, T* of its bound (maneuver_bound.hpp, on
// the controllers' model: follower_run.hpp's follower_problem) and, for each controller, the
// settle time as a ratio to T*, the residual swing, the final position errors, the peak voltage
// and the supervisor's faults, on the nominal plant or on one whose cable length, load mass and
// friction differ from what the controllers assume.
//
// The controllers (compared_controllers(), in this order):
//   follower      the bound's trajectory followed by feedforward + time-varying LQR (follower_run.hpp)
//   delay1        the default: the dissertation's delayed swing feedback (3.47) on a trapezoid profile
//   delay2        the second delayed-feedback law (3.50) on a trapezoid profile
//   time_optimal  the time-optimal profile with no swing feedback (tracking PD with acceleration
//                 feedforward)
//   zv, zvd       the trapezoid shaped by ZV / ZVD (input shaping) with no swing feedback (tracking PD)
// every one with the friction compensation on, in the in-process stack's order and gating
// (in_process_stack.hpp), the settle criterion of the demo table (5 mm, 0.005 rad, 0.5 deg).
//
// Errors: std::invalid_argument for an unknown controller name, a count out of range or a crane
// whose planner range leaves no room for a move; std::runtime_error when a bound is not solved;
// common::ConfigError for an invalid config (the bound's validation names the field).

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "crane/optimal_control/minimum_time.hpp"
#include "crane/optimal_control/trajectory_follower.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace crane::stack {

struct ComparedController {
  std::string name;          // "follower", "delay1", ...
  bool follower{false};      // the bound's follower; otherwise the stack's planner and laws:
  std::string controller;    // choose_controller's name
  bool acceleration_feedforward{false};
  std::uint8_t profile{protocol::MoveRequest::PROFILE_TRAPEZOID};
};

/// The controllers of the header, in its order.
[[nodiscard]] std::vector<ComparedController> compared_controllers();

/// Those of compared_controllers() named in `names` (in the given order). std::invalid_argument
/// naming an unknown one.
[[nodiscard]] std::vector<ComparedController> compared_controllers(const std::vector<std::string>& names);

/// `count` (1..1000) seeded random point-to-point moves of `config`'s crane, each named
/// "random_<i>", starting where the crane rests (the configured cable length) and with the rated
/// limits of its first demo maneuver:
///   tower     trolley start and target anywhere in the planner's range, at least a fifth of it
///             apart; the jib from a random angle by 10-180 deg either way within the planner's
///             slew range;
///   gantry    the trolley as the tower's;
///   overhead  the trolley as the tower's and the bridge likewise in its range;
/// each with probability 1/4 hoisting to a cable length in [0.5, 1.5] x the configured one (within
/// the planner's cable range). Recorded for `record_factor` x the linear profile's time of the
/// move plus 10 swing periods at the target length, so that a controller at a few T* still has
/// its settle and residual-swing window inside the record.
[[nodiscard]] std::vector<ManeuverConfig> random_moves(const StackConfig& config, int count, std::uint64_t seed,
                                                        double record_factor = 4.0);

/// The moves a tool runs (crane_sim, crane_demo): `config`'s demo maneuvers (when `demo_maneuvers`)
/// and then `random_count` (0..1000) random_moves of `seed`; of those, the ones named in `names`
/// (all when empty), in the order just given, whatever the order of `names`. Throws
/// std::invalid_argument naming a name that is none of them ("--maneuver 'x' is neither a demo
/// maneuver of the configuration nor one of the 20 random moves (random_0 .. random_19, --moves)")
/// and what random_moves() throws.
[[nodiscard]] std::vector<ManeuverConfig> select_moves(const StackConfig& config, const std::vector<std::string>& names,
                                                        int random_count = 0, std::uint64_t seed = 1,
                                                        bool demo_maneuvers = true);

struct ControllerOutcome {
  std::string controller;
  trajectory_planner::EquivalentPendulum planned_swing{};  // the follower's plan's pendulum (FollowerResult)
  ManeuverMetrics metrics;
  double ratio{0.0};                 // settle_time / T* (NaN: never settled within the record)
  std::uint32_t latched_faults{0};   // the supervisor's FAULT_* bits at the end
  std::uint64_t braked_cycles{0};    // cycles of the move with the brakes on
  std::uint64_t unsolved_plans{0};   // InProcessResult::unsolved_plans (the learning move's included)
  std::string error;                 // what a run threw (its figures are then NaN)
};

struct MoveComparison {
  ManeuverConfig maneuver;
  plant::PlantMismatch mismatch;     // the plant's, against the controllers' model
  double bound{0.0};                 // [s] T* (the nominal model's when calibrated)
  bool calibrated{false};            // the controllers' config was calibrated on this plant (compare_move's caller)
  bool learnt{false};                // made after a first move (compare_move's first_move)
  double bound_solve_seconds{0.0};   // [s] IPOPT's wall time (0 when the bound was given)
  double swing_period{0.0};          // [s] at the target cable length
  std::vector<ControllerOutcome> outcomes;  // one per controller, in their order
};

/// The bound of `maneuver` on the controllers' model (follower_problem) with `intervals`
/// collocation intervals. std::runtime_error when IPOPT does not solve it.
[[nodiscard]] optimal_control::MinimumTimeResult comparison_bound(const StackConfig& config,
                                                                  const ManeuverConfig& maneuver, int intervals = 200);

/// Runs each of `controllers` on `maneuver` against a plant with `mismatch`, the ratio taken to
/// `bound` (comparison_bound of the same maneuver and intervals); the follower with `follower`'s
/// weights (FollowerRun::follower). A run that throws is kept with its error and NaN figures.
/// `reference_bound` [s] > 0: the ratio (and MoveComparison::bound) taken to this T* instead, the
/// nominal model's, for a config calibrated on the plant (swing_calibration_run.hpp) whose own
/// bound `bound` is on the calibrated model. `first_move`: each run makes it first on the same
/// plant, unmeasured (FollowerRun::first_move and learning_move: the follower's, minimum-time, and
/// its maneuver planned in the stack from what the state estimator learnt; the other laws' with
/// the trapezoid profile, InProcessRun::first_move).
[[nodiscard]] MoveComparison compare_move(const StackConfig& config, const ManeuverConfig& maneuver,
                                          const optimal_control::MinimumTimeResult& bound,
                                          const std::vector<ComparedController>& controllers,
                                          const plant::PlantMismatch& mismatch = {}, int intervals = 200,
                                          const optimal_control::FollowerParams& follower = {},
                                          double reference_bound = 0.0,
                                          const std::optional<ManeuverConfig>& first_move = std::nullopt);

/// A comparison none of whose runs could be made (`error`: why, e.g. its bound not solved): each of
/// `controllers` with that error and NaN figures, the ratio to `bound` [s].
[[nodiscard]] MoveComparison failed_comparison(const ManeuverConfig& maneuver, const plant::PlantMismatch& mismatch,
                                               const std::vector<ComparedController>& controllers, double bound,
                                               const std::string& error);

/// The eight corners of cable length and load mass x0.8/x1.2 and friction x0.7/x1.3 (issue 32).
[[nodiscard]] std::vector<plant::PlantMismatch> mismatch_corners();

/// A mismatch's label, "nominal" or "L0.8_m1.2_f0.7".
[[nodiscard]] std::string mismatch_label(const plant::PlantMismatch& mismatch);

/// One controller's figures over many compared moves.
struct ControllerSummary {
  std::string controller;
  int runs{0};
  int settled{0};                 // runs that settled within the record
  int faulted{0};                 // runs with a latched supervisor fault or brakes on
  int failed{0};                  // runs that threw
  double median_ratio{0.0};       // over every run; a run that never settled counts as +inf
  double worst_ratio{0.0};
  double median_residual_swing{0.0};  // [rad]
  double worst_position_error{0.0};   // [m] trolley (and bridge) at the last cycle
  double worst_slew_error{0.0};       // [rad]
  double peak_voltage{0.0};           // [V]
};

/// The summaries of `moves`' outcomes per controller, in the controllers' order of the first move.
[[nodiscard]] std::vector<ControllerSummary> summarize(const std::vector<MoveComparison>& moves);

}  // namespace crane::stack
