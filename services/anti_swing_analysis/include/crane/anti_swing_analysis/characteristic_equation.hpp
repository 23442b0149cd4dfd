#pragma once
// Characteristic equations of the normalized anti-swing tracking loop, section 3.3.2 of
// H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003, and their roots.
//
// Normalized loop (3.27)-(3.28), tau = t/T, T = 2 pi sqrt(L/g), x_bar = x/L, a = 4 pi^2:
//   x_bar'' = K_px (x_ref - x_bar) + K_dx (x_ref' - x_bar') + V_xs      (tracking PD (3.40))
//   phi'' + a phi = +x_bar''                                           (our tower convention)
// SIGN CONVENTION: in this project the load sits at x - L cos(theta) sin(phi), so the swing is
// driven by +x_bar''; the dissertation's printed (3.39)/(3.48) correspond to -x_bar''. All
// equations below are in OUR convention:
//   pd            (3.45)/(3.46): V_xs = K_ps phi + K_ds phi'
//       (s^2 + a)(s^2 + K_dx s + K_px) - s^2 (K_ps + K_ds s) = 0
//   delayed_feedback (3.47)/(3.48): V_xs = K_del phi(tau - tau_del)
//       (s^2 + a)(s^2 + K_dx s + K_px) - K_del s^2 e^{-tau_del s} = 0
//   delayed_trajectory_correction (3.50), Masoud's configuration (figure 3.18): the anti-swing
//   output corrects the reference, x_ref -> x_ref + K_del phi(tau - tau_del), so the tracking PD
//   sees it through (K_dx s + K_px): X (s^2 + K_dx s + K_px) = (K_dx s + K_px) K_del e^{-tau_del s}
//   Phi and (s^2 + a) Phi = s^2 X give
//       (s^2 + a)(s^2 + K_dx s + K_px) - K_del s^2 (K_dx s + K_px) e^{-tau_del s} = 0.
//   This is (3.50) exactly as printed. (In the dissertation's phi convention the same derivation
//   gives "+K_del"; the printed "-" with K_del = +0.33 is therefore the dissertation's own
//   flipped-sign/garbled variant; see the map maxima below for which sign damps here.)
//
// Roots: Pade form (3.49) of order l, e^{-tau s} ~ ((1 - c s)/(1 + c s))^l with c = tau/(2l),
// multiplied through by (1 + c s)^l and solved in w = c s (well-scaled coefficients) as the
// eigenvalues of the companion matrix (Eigen::EigenSolver); or, "direct", Newton's method in the
// complex plane on the exact transcendental equation, seeded from the Pade roots.
//
// All functions here allocate (vectors, Eigen matrices): analysis/offline use only.

#include <complex>
#include <string_view>
#include <vector>

namespace crane::anti_swing_analysis {

/// Anti-swing law whose closed-loop characteristic equation is analysed.
enum class AntiSwingLaw {
  pd,                             // parameters (K_ps, K_ds)        (3.45)
  delayed_feedback,               // parameters (K_del, tau_del)    (3.47), "delay1"
  delayed_trajectory_correction,  // parameters (K_del, tau_del)    (3.50), "delay2"
};

/// Short name used on the command line and in files: "pd", "delay1", "delay2".
[[nodiscard]] std::string_view law_name(AntiSwingLaw law) noexcept;
/// Paper symbols of the two parameters: ("K_ps", "K_ds") or ("K_del", "tau_del").
[[nodiscard]] std::string_view first_parameter_name(AntiSwingLaw law) noexcept;
[[nodiscard]] std::string_view second_parameter_name(AntiSwingLaw law) noexcept;

/// The tracking loop around the anti-swing law (normalized, dimensionless).
struct TrackingLoop {
  double proportional_gain{100.0};  // [-] K_px (3.40)-(3.42)
  double derivative_gain{20.0};     // [-] K_dx = 2 sqrt(K_px) (3.42)
  double swing_stiffness{39.47841760435743};  // [-] a = 4 pi^2 (3.33)
  /// [-] w_c = 2 pi f_c T, the cut-off of the state estimator's second-order Butterworth low-pass
  /// (section 4.3) in radians per swing period; 0: no filter. The law then sees the filtered swing
  /// F(s) phi (and its derivative), F(s) = w_c^2 / (s^2 + sqrt(2) w_c s + w_c^2), the continuous
  /// prototype of the estimator's bilinear design (its pre-warping makes them agree at f_c): every
  /// function below multiplies the characteristic equation through by s^2/w_c^2 + sqrt(2) s/w_c + 1,
  ///   (s^2 + a)(s^2 + K_dx s + K_px)(s^2/w_c^2 + sqrt(2) s/w_c + 1) - s^2 N(s) e^{-tau_del s} = 0,
  /// section 5.1's question (the effect of the filter delay on the delayed-feedback controller).
  /// Must be >= 0 (functions below throw std::invalid_argument otherwise).
  double swing_filter_cutoff{0.0};
};

/// One point of a law's parameter plane. For pd: first = K_ps [-], second = K_ds [-] (multiplies
/// phi' = d phi/d tau). For the delay laws: first = K_del [-], second = tau_del [swing periods],
/// tau_del >= 0 (tau_del = 0 is the undelayed equation).
struct LawPoint {
  AntiSwingLaw law{AntiSwingLaw::delayed_feedback};
  double first{0.0};
  double second{0.0};
};

/// Closed-loop roots (normalized s, i.e. per swing period) of the Pade form of the
/// characteristic equation. pd and tau_del = 0 have no delay: the plain quartic. Degree 4 + l for
/// the delay laws. Computed as the eigenvalues (Eigen::EigenSolver) of a state-space realization
/// (loop states plus a cascade of l first-order all-pass sections) whose characteristic polynomial
/// is exactly the Pade polynomial: the companion matrix of the expanded polynomial (below) spans
/// coefficients from 1 to c^(l+4), c = tau/(2l), and loses the swing roots for tau_del < ~0.05.
/// Throws std::invalid_argument if pade_order < 1 or tau_del < 0.
[[nodiscard]] std::vector<std::complex<double>> pade_roots(const LawPoint& point, const TrackingLoop& loop,
                                                           int pade_order = 20);

/// Same roots from the companion matrix of the expanded Pade polynomial, solved in w = c s
/// (accurate for tau_del >~ 0.05; kept as a cross-check).
[[nodiscard]] std::vector<std::complex<double>> pade_roots_companion(const LawPoint& point,
                                                                     const TrackingLoop& loop,
                                                                     int pade_order = 20);

/// Value f(s) of the exact characteristic function (left-hand side above) and f'(s).
struct CharacteristicValue {
  std::complex<double> value;
  std::complex<double> derivative;
};
[[nodiscard]] CharacteristicValue characteristic_function(const LawPoint& point, const TrackingLoop& loop,
                                                          std::complex<double> s) noexcept;

/// Newton's method on the exact equation from `seed`. Returns the root, or NaN+NaN j if it did not
/// converge (|f| relative residual 1e-12) within 60 iterations.
[[nodiscard]] std::complex<double> newton_root(const LawPoint& point, const TrackingLoop& loop,
                                               std::complex<double> seed) noexcept;

/// Dominant pole pair: the complex-conjugate pair with the largest real part (the slowest
/// decaying oscillation). damping = -Re(s)/|s| (negative when that pair is unstable).
/// stable is false if ANY root has Re(s) > 1e-9. found is false (damping NaN) if no complex pair
/// exists. A root counts as complex if |Im s| > 1e-6 max(1, |s|).
struct DominantPair {
  std::complex<double> pole{0.0, 0.0};  // upper-half-plane member of the pair
  double damping{0.0};
  bool stable{false};
  bool found{false};
};
[[nodiscard]] DominantPair dominant_pair(const std::vector<std::complex<double>>& roots) noexcept;

/// Damping at one point by both methods.
struct DampingEvaluation {
  DominantPair pade;    // from pade_roots() (l = pade_order)
  // Newton on the exact equation from the Pade dominant pole itself: the same pair, exact
  // (damping NaN if Newton fails). This is the root-by-root accuracy check of (3.49).
  DominantPair direct;
  // Dominant pair chosen independently among the 8 rightmost Pade roots refined by Newton. Where
  // two pairs have (nearly) equal real parts, which is where the damping maps peak, the choice
  // can flip between them, so this damping may jump where `direct` does not.
  DominantPair direct_independent;
};
[[nodiscard]] DampingEvaluation evaluate_damping(const LawPoint& point, const TrackingLoop& loop,
                                                 int pade_order = 20);

}  // namespace crane::anti_swing_analysis
