#pragma once
// Anti-swing controller, section 3.3.2 of H. M. Omar, "Control of Gantry and Tower Cranes",
// Virginia Tech 2003. Produces the normalized anti-swing action V_xs (dimensionless, in units of
// x_bar'' = d^2(x/L)/d tau^2 with tau = t/T, T = 2 pi sqrt(L/g)) that the tracking controller adds
// to its own action: V_bar_x = V_xp + V_xs (3.37)-(3.40). The same law acts on the out-of-plane
// swing theta for the slew axis in the variable y = -(x/L) gamma (3.34)-(3.36).
//
// SIGN CONVENTION (derived, see anti_swing.cpp and tests/services/test_anti_swing.cpp): in this
// project the load sits at x - L cos(theta) sin(phi), so the normalized swing equation is
// phi'' + a phi = +x_bar'' (a = 4 pi^2). With the PD tracking loop x_bar'' = -K_px x_bar
// - K_dx x_bar' + V_xs the characteristic equation is
//   (s^2 + a)(s^2 + K_dx s + K_px) - s^2 G_s(s) = 0,
// i.e. (3.39)/(3.48) with the sign of the G_s term flipped. The dissertation's design point
// |K_del| = 90, tau_del = 0.1 damps the swing with K_del = -90 in this convention (dominant
// pair damping ratio 0.40 with a Pade l = 20 delay); K_del = +90 is unstable. Likewise the PD
// design point is K_ps = -30, K_ds = +8.
//
// Real-time: step() is noexcept, allocates nothing (the delay line is sized at construction from
// max_cable_length), takes no locks.

#include <vector>

#include "crane/common/crane_signals.hpp"

namespace crane::anti_swing {

/// Which law computes the action. Seams for later: delayed_feedback_trajectory (3.50), fuzzy
/// (tables 3.7-3.8): add an enumerator, a params block and a case in step().
enum class AntiSwingKind {
  none,              // action 0
  pd,                // (3.45) V_xs = K_ps phi + K_ds T phi_dot
  delayed_feedback,  // (3.47) V_xs = K_del phi(tau - tau_del)
};

/// The delayed-feedback gain at short cables (beyond the dissertation, which tuned K_del at L = 1 m).
/// The law is normalized by the swing period, but the chain's fixed lags are not (the drives, the
/// estimator's filter, a cycle of latency): they are a larger part of a short pendulum's period.
/// With K_del = -90 the lab crane's slew and its load limit-cycle at L <= 0.25 m (about 2 deg for
/// 20 s and more after a slew; tests/closed_loop/test_operate.cpp, ShortCable). With -75 on the slew
/// alone a slew with the trolley coming in still took 3 s to settle at 0.2 m; with -75 on both axes
/// every such move to 0.6 m settles in under 2.3 s, and from 0.3 m up both gains settle. Near the
/// mast ((3.38) divides the slew's action by the radius) -75 still limit-cycled at 0.2 m (a slew
/// ending at 0.25-0.36 m, session 43); -65 settles every move of the test, 0.25-0.9 m, in under
/// 2.7 s (-45 lets the swing grow past the supervisor's limit). When enabled, K_del is `gain` at and below `short_length` [m],
/// delay_gain at and above `full_gain_length` [m], linear in L between, on both axes.
struct ShortCableGain {
  bool enabled{false};
  double short_length{0.25};     // [m] > 0
  double full_gain_length{0.4};  // [m] > short_length
  double gain{-65.0};            // [-] K_del at short cables, finite
};

struct AntiSwingParams {
  AntiSwingKind kind{AntiSwingKind::delayed_feedback};
  double pd_proportional_gain{-30.0};  // [-] K_ps (3.45), sign for our convention (header)
  double pd_derivative_gain{8.0};      // [-] K_ds (3.45), multiplies phi' = T phi_dot
  double delay_gain{-90.0};            // [-] K_del (3.47), sign for our convention (header)
  double normalized_delay{0.1};        // [-] tau_del in swing periods T (3.47), > 0
  double sample_period{0.01};          // [s] time between step() calls, > 0
  double gravity{9.8};                 // [m/s^2] g in T = 2 pi sqrt(L/g)
  double min_cable_length{0.1};        // [m] measured L is clamped to [min, max] for T
  double max_cable_length{5.0};        // [m] sizes the delay line
  bool slew_enabled{true};             // apply the same law on theta for the slew axis
  ShortCableGain short_cable{};  // delayed_feedback: K_del at short cables
};

struct AntiSwingOutput {
  double trolley_action{0.0};  // [-] V_xs, normalized (add to V_xp before (3.37))
  double slew_action{0.0};     // [-] V_ys, normalized (add to V_yp before (3.38))
  double swing_period{0.0};    // [s] T from the (clamped) measured cable length
  int delay_samples{0};        // [samples] round(tau_del T / sample_period), delayed_feedback only
};

class AntiSwing {
 public:
  /// Throws common::ConfigError naming the field, value and bound for: unknown kind, non-finite
  /// gains, normalized_delay <= 0, sample_period <= 0, gravity <= 0, min_cable_length <= 0, an enabled
  /// short_cable with short_length <= 0, full_gain_length <= short_length or a non-finite gain,
  /// max_cable_length <= min_cable_length, or a delay line longer than kMaxDelaySamples.
  explicit AntiSwing(const AntiSwingParams& params);

  /// Uses swing_in_plane [rad], swing_out_of_plane [rad], their rates [rad/s] (pd only) and
  /// cable_length [m] from `estimate`.
  /// - rejected_nonfinite: a used input is NaN/Inf; output set to zero actions, history unchanged.
  /// - not_ready: delayed_feedback with fewer than delay_samples+1 samples of history; zero actions.
  /// - ok otherwise.
  [[nodiscard]] common::StepStatus step(const common::CraneStateEstimate& estimate,
                                        AntiSwingOutput& output) noexcept;

  /// Empties the delay line.
  void reset() noexcept;

  [[nodiscard]] const AntiSwingParams& params() const noexcept { return params_; }
  /// Capacity of the delay line [samples].
  [[nodiscard]] int delay_line_capacity() const noexcept { return static_cast<int>(in_plane_history_.size()); }

  static constexpr int kMaxDelaySamples = 1'000'000;

 private:
  [[nodiscard]] double delayed(const std::vector<double>& history, int delay) const noexcept;

  AntiSwingParams params_;
  std::vector<double> in_plane_history_;      // ring buffers, newest at head_
  std::vector<double> out_of_plane_history_;
  int head_{0};
  int count_{0};
};

}  // namespace crane::anti_swing
