#pragma once
// The plant's sliding friction as a multiple of the model's, estimated along a followed trajectory
// from the follower's own feedback (docs/optimal_control.md, "The friction the hold compensates").
//
// Along a minimum-time trajectory the follower's feedforward carries the model's drive voltage, part
// of the model's friction at the reference speed, and the friction compensation adds the rest on the
// measured speed; a plant whose friction is f times the model's needs (f - 1) F(v) more, and the
// time-varying LQR supplies it as feedback. The tracking stage hands the running estimate to the
// compensation along the move as well, which then adds s F(v) of it itself, s = kept_sliding_share
// (reduction, f_applied) - kept_sliding_share(reduction, 1) (friction_compensation.hpp), so the
// feedback no longer has to; each row adds s F back so the estimate does not chase its own
// correction. Per cycle and drive axis j that slides on the reference (|v_ref,j| >=
// min_reference_speed), one row of the linear regression
//   u_fb,j + s F_j(v_ref,j) = theta_0 F_j(v_ref,j) + theta_(1+j) a_ref,j + e,     f = 1 + theta_0
// where u_fb = u - feedforward [V] is the LQR's part of the drive voltage, F_j the model's sliding
// friction (3.1) in volt-equivalents (Coulomb and viscous, direction dependent; the compensation's
// own regressor, friction_compensation::friction_regressor . sliding_coefficients) and a_ref the
// reference acceleration, whose coefficient takes the inertia the model gets wrong (the load mass,
// the axis's own). Least squares over every row of the move, solved when asked:
//   (Phi^T Phi + ridge I) theta = Phi^T u_fb,
// the ridge (1e-9 of the information's trace) only so an axis with no rows (a gantry's second axis)
// leaves its coefficient at 0. factor() is f clamped to [min_factor, max_factor] (and rounded to
// resolution), and the prior while
// fewer than min_rows rows were taken (or, with max_standard_error, while f is not known to within
// it): 1 (the model's friction) at first, and what the last move found when reset() is handed it (a
// move with no travel, the hoist's alone, learns nothing and keeps it).
//
// The PD law (tracking_stage.hpp) feeds it other rows through add_row(): the blocks of the balance
// of the crane's momentum (friction_momentum_balance.hpp), whose momenta carry the model's inertia,
// so their second column is 0.
//
// Real-time: add(), add_row() and factor() are noexcept and allocate nothing. reset() starts a new move.
// Errors: the constructor throws common::ConfigError naming the field, the value and the bound.

#include "crane/common/crane_parameters.hpp"

namespace crane::tracking {

struct FrictionFactorParams {
  double min_reference_speed{0.05};  // [m/s or rad/s] > 0: rows only where the reference slides
  int min_rows{20};                  // [-] >= 3: fewer rows give factor() = the prior
  double min_factor{0.5};            // [-] > 0
  double max_factor{2.0};            // [-] >= min_factor
  // [-] >= 0; > 0: factor() is the prior while the standard error of f (from the rows' residuals) is
  // above it: a move too short or too disturbed to say (the PD law's rows carry its anti-swing
  // action, and a short slew alone gives few); 0: no such check (the follower's).
  double max_standard_error{0.0};
  // [-] in [0, 0.1]; > 0: factor() is f rounded to a multiple of it, the estimate's resolution (the
  // PD law's, 0.01: on the nominal crane it hands exactly 1, the configured friction, and the digits
  // below it, which differ with the plant integrator's tolerance, do not move the compensation and
  // with it the hold's stick-slip; docs/optimal_control.md, "The friction factor under delay1");
  // 0: none (the follower's).
  double resolution{0.0};
};

class FrictionFactorEstimate {
 public:
  /// `friction[j]`: the model's friction of drive axis j (0: trolley, 1: the slew or the bridge).
  FrictionFactorEstimate(const common::AxisFriction& trolley, const common::AxisFriction& second,
                         const FrictionFactorParams& params = {});

  /// Forgets every row (a new move); `prior` [-] is factor() until the new move has min_rows rows,
  /// clamped to [min_factor, max_factor] (not finite: 1).
  void reset(double prior = 1.0) noexcept;

  /// One cycle of axis `axis` (0 or 1): the LQR's part of the voltage [V], the reference speed [m/s
  /// or rad/s] and acceleration, and s [-], the share of the model's sliding friction the
  /// compensation added beyond its unscaled part because of the factor it applied (see the header;
  /// 0 with factor 1). Ignored where the reference does not slide or an input is not finite.
  void add(int axis, double feedback_voltage, double reference_speed, double reference_acceleration,
           double compensated_share = 0.0) noexcept;

  /// One row of the regression as it stands, y = theta_0 `friction` + theta_(1+axis) `inertia` + e (the
  /// unit of y, e.g. [V s] for the PD law's momentum balance, friction_momentum_balance.hpp; `inertia`
  /// 0 there: the momenta carry the model's inertia). add() builds its rows with it. Ignored if `axis`
  /// is not 0 or 1 or an input is not finite. The standard error counts the columns that have rows.
  void add_row(int axis, double y, double friction, double inertia) noexcept;

  /// f, the plant's sliding friction over the model's (see the header); the prior without enough rows.
  [[nodiscard]] double factor() const noexcept;
  [[nodiscard]] int rows() const noexcept { return rows_; }

 private:
  common::AxisFriction friction_[2];
  FrictionFactorParams params_;
  double information_[3][3]{};  // Phi^T Phi
  double moment_[3]{};          // Phi^T u_fb
  int rows_{0};
  double prior_{1.0};
  double squares_{0.0};  // sum of the rows' u_fb^2 (the residual's)
};

}  // namespace crane::tracking
