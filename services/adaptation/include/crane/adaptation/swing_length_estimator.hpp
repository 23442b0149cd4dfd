#pragma once
// Online estimation of the load's equivalent pendulum a L + c from the swing the crane measures while
// it works: the calibration of `deploy/crane calibrate swing` (swing_calibration.hpp) without a
// calibration move. A hook on rigging, a sling, a load hung below the hook: the pendulum the
// encoders see is longer than the cable the hoist reports, and the minimum-time plans, which swing
// the equivalent pendulum (optimal_control/planned_move.hpp), need its length.
//
// Model: the controllers' (the one the minimum-time plans use, plant::make_crane_dynamics of the
// crane kind, rigid: the tower's Lagrangian (2.11)-(2.16) of H. M. Omar, "Control of Gantry and Tower
// Cranes", Virginia Tech 2003, with the slew's centripetal and Coriolis terms; the gantry's
// (2.5)-(2.6); the overhead crane's), its swing rows (phi; theta but on a gantry) with the cable
// length replaced by the equivalent pendulum's L_e = a L + c (L_e' = a L'). Normalized by its own
// swing coefficient over the length, r = row L_e / M_ss(L_e), a swing row of these models is
// affine in L_e and L_e' (the tower's and the overhead crane's rows are L_e u_s . (load
// acceleration + g), M_ss = L_e^2 |u_s|^2; the gantry's (2.6) is affine itself, M_ss = L_e; the
// L_e'' term vanishes, u . u_s = 0), so
//   r = alpha + beta L_e + delta L_e' = 0   =>   a (beta L + delta L') + c beta = -alpha,
// linear in (a, c). alpha, beta, delta are read from three evaluations of the model at L_e = 1 and
// 2 m with L_e' = 0, and at L_e = 1 m with L_e' = 1 m/s. At small swing with the slew at rest these
// are the linearized rows (2.8), (2.29), (2.31) that `deploy/crane calibrate swing` fits offline
// (swing_calibration.hpp): beta = s'', delta = 2 s', alpha = g s - x'' (in plane),
// g s + x gamma'' (tower, out of plane), g s + y'' (overhead).
//
// No double differentiation of encoder noise: every signal (x, gamma or y, phi, theta, L) passes one
// second-order Butterworth (`filter_cutoff`, state_estimator::butterworth_low_pass) and the
// derivatives are the filtered values' differences centred at k-1 (as OnlineAdaptation's rows). A
// channel's row is taken while the brakes are off and that channel swings: |s| or |s''| L / g at
// least `min_swing` (at rest the rows are encoder noise, which would only erode what was learnt).
// The gantry crane's theta row is never taken (its model holds theta).
//
// Exponentially weighted least squares in information form (AxisIdentifier's statistics, 2 x 2):
//   R(k) = lambda R(k-1) + h h^T,   r(k) = lambda r(k-1) + h y   (taken rows only)
// Every `solve_period`: (a, c) jointly when the information scaled by diag(1, 1 m) has a smallest
// eigenvalue >= `min_information` and a condition number <= `max_condition` (the rows span cable
// lengths: at one length h is proportional to (L, 1) and a is not separable from c); otherwise c
// alone, a held at the value in use (1 until a joint solve), when R_cc >= `min_information`;
// otherwise nothing moves.
// Standard deviations from the forgetting-weighted a-posteriori residual variance times the filter's
// equivalent number of correlated samples, times R^-1 (as AxisIdentifier).
//
// Release: a solved estimate is *confident* while 2 sigma of the equivalent length a L + c at the
// rows' mean cable length (weighted by s''^2: R_ac / R_cc) is <= `length_bound` [m] (a and c alone
// are correlated; their sum at the lengths the rows saw is what the swing tells), and 2 sigma of a
// <= `scale_bound` when a was solved. A confident estimate replaces the one in use; the last one
// stays in use until a better one replaces it. Before the first: a = 1, c = 0, not confident (the
// planner then plans its configured trajectory_planner.manual pendulum, and plans an estimate only
// where it is a pendulum over the move's cable span: trajectory_planner::swings_down_to).
//
// Errors: the constructor validates (common::ConfigError naming "state_estimator.swing_length.<field>",
// the value and the bound); step() is noexcept, allocates nothing, and skips samples with a
// non-finite value or a cable length <= 0.

#include <array>
#include <cstdint>
#include <memory>

#include <Eigen/Core>

#include "crane/adaptation/axis_identifier.hpp"
#include "crane/common/crane_parameters.hpp"
#include "crane/plant/crane_dynamics.hpp"
#include "crane/state_estimator/discrete_filter.hpp"

namespace crane::adaptation {

struct SwingLengthParams {
  bool enabled{false};                // false: step() reports a = 1, c = 0, not confident
  double sample_period{0.01};         // [s] T, in (0, 1]
  common::CraneKind crane_kind{common::CraneKind::tower};
  common::CraneParameters crane{};    // the configured crane (its gravity; the model's parameters)
  common::BridgeParameters bridge{};  // an overhead crane's
  double filter_cutoff{2.0};          // [Hz] in (0, 0.45 / T)
  double forgetting_factor{0.999};    // [-] in [0.9, 1]
  double min_swing{0.003};            // [rad] a channel's row is taken while it swings this much, >= 0
  double min_information{1.0};        // [(m/s^2)^2] of the scaled information, > 0
  double max_condition{1e4};          // [-] >= 1
  double solve_period{0.1};           // [s] >= T
  double length_bound{0.02};          // [m] confident while 2 sigma of a L + c at the rows' mean length <= this, > 0
  double scale_bound{0.05};           // [-] and of a (when solved) <= this, > 0
};

/// Throws common::ConfigError naming "state_estimator.swing_length.<field>", the value and the bound
/// (the crane's and the bridge's through the model's constructor, "crane." and "bridge.").
void validate(const SwingLengthParams& params);

/// One sensor sample (SI).
struct SwingLengthInput {
  double trolley_position{0.0};     // [m] x
  double second_axis{0.0};          // [rad] slew angle gamma (tower) or [m] bridge position y (overhead)
  double swing_in_plane{0.0};       // [rad] phi
  double swing_out_of_plane{0.0};   // [rad] theta
  double cable_length{1.0};         // [m] L, as the hoist reports it
  bool brakes_engaged{true};
};

/// What the stage publishes (CraneState_'s swing_length_* fields).
struct SwingLengthEstimate {
  double scale{1.0};          // [-] a in use (1 until the first confident estimate)
  double offset{0.0};         // [m] c in use (0 until then)
  double length_bound{0.0};   // [m] 2 sigma of a L + c at the rows' mean length, of the a, c in use (0: none)
  double scale_bound{0.0};    // [-] 2 sigma of the a in use (0: configured or held)
  bool confident{false};      // a, c are an estimate (else the configured ones)
};

/// What the regression knows now (for tests and status): the latest solve, whether released or not.
struct SwingLengthSolution {
  double scale{1.0};
  double offset{0.0};
  double scale_deviation{0.0};   // [-] 1 sigma; 0 where not solved
  double offset_deviation{0.0};  // [m] 1 sigma; 0 where not solved
  double length_deviation{0.0};  // [m] 1 sigma of a L + c at mean_cable_length
  double mean_cable_length{0.0}; // [m] of the rows, weighted by s''^2 (R_ac / R_cc)
  bool offset_solved{false};     // at the last solve
  bool scale_solved{false};
  std::uint64_t rows{0};         // rows taken since start
  std::uint64_t solves{0};
  double residual_rms{0.0};      // [m/s^2] forgetting-weighted, a posteriori
};

class SwingLengthEstimator {
 public:
  /// Throws common::ConfigError (validate).
  explicit SwingLengthEstimator(const SwingLengthParams& params);

  /// One sample. Never throws, never allocates. Disabled: `estimate` is a = 1, c = 0, not confident.
  void step(const SwingLengthInput& input, SwingLengthEstimate& estimate) noexcept;

  [[nodiscard]] const SwingLengthSolution& solution() const noexcept { return solution_; }
  [[nodiscard]] const Eigen::Matrix2d& information() const noexcept { return statistics_.information; }
  [[nodiscard]] const SwingLengthParams& params() const noexcept { return params_; }

 private:
  static constexpr int kSignals = 5;  // x, second axis, phi, theta, L
  // The row of swing coordinate `slot` (plant::kInPlaneSwingIndex or kOutOfPlaneSwingIndex) at the
  // filtered state centred at k-1 (header).
  void take_row(int slot, const plant::ModelState& state, const plant::CoordinateVector& acceleration,
                double length, double length_rate) noexcept;
  void solve() noexcept;

  SwingLengthParams params_;
  std::unique_ptr<plant::CraneDynamics> model_;
  state_estimator::DiscreteTransferFunction low_pass_{};
  std::array<state_estimator::DiscreteFilter, kSignals> filters_{};
  std::array<std::array<double, 3>, kSignals> history_{};  // filtered, [0] newest
  int samples_{0};
  double noise_correlation_{1.0};
  int solve_interval_{1};
  int solve_countdown_{1};
  WeightedLeastSquares<2> statistics_{};
  SwingLengthSolution solution_{};
  SwingLengthEstimate in_use_{};
};

}  // namespace crane::adaptation
