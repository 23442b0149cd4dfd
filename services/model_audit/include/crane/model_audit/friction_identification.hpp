#pragma once
// Offline least-squares identification of direction-dependent viscous and Coulomb friction of one
// drive axis, section 3.1 of H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003.
//
// Axis model outside the zero-velocity band, (3.6) with (3.13)'s direction split:
//   x'' = K_m u - b_s x' - c_s s,   s = sign(x'),  (b_s, c_s) = (b+, c+) for s > 0, (b-, c-) for s < 0
// with b, c >= 0 (Coulomb opposes the motion, ERRATA). x is the trolley position [m] or the slew
// angle gamma [rad], u the drive command [V], K_m the motor constant [m/s^2/V] ([rad/s^2/V]).
//
// Discrete regression (3.10)-(3.14) from samples x(k), u(k) at period T_s, where u(k) is the command
// held over [t_k, t_k+1) (zero-order hold, as (3.8) assumes and a digital loop logs it):
//   acc(k) = [x(k) - 2 x(k-1) + x(k-2)] / T_s^2                                          (3.11)
//   DifferenceScheme::centered (default):
//     vel(k) = [x(k) - x(k-2)] / (2 T_s),   in(k) = [u(k-1) + u(k-2)] / 2
//   DifferenceScheme::dissertation (as printed, with the sign of (3.11)'s velocity corrected):
//     vel(k) = [x(k-1) - x(k-2)] / T_s,     in(k) = u(k-2)        (a_1 = 0, a_2 = K_m T_s^2, ERRATA)
//   acc(k) = K_m in(k) - b+ vel eta - b- vel xi - c+ eta + c- xi                           (3.13)
// Why "centered": the second difference is the triangle-weighted mean of x'' over [t_k-2, t_k], so
// with a held input it sees exactly the mean of u(k-1) and u(k-2) (the exact ZOH terms a_1, a_2 of
// (3.9) are both about K_m T_s^2 / 2), and the central difference is the velocity at that same
// instant t_k-1. Both approximations are O(T_s^2). The printed scheme pairs the acceleration at
// t_k-1 with a velocity and an input both centred half a sample earlier (an O(T_s) misalignment, but
// a consistent one): on the section-3.1 experiment it stays within 0.35 % (tracking gains) and
// 0.5 % (gain-scheduling gains), against 0.005 % for "centered"; mixing the two (central velocity
// with u(k-2)) is off by more than 2 %.
//
// Zero-velocity band (3.3): sample k is used only when both backward differences in its stencil,
// [x(k-1) - x(k-2)]/T_s and [x(k) - x(k-1)]/T_s, exceed `dead_band` with the same sign; then
// eta = 1 (positive) or xi = 1 (negative). So the friction regime is the same over the whole
// window, and stuck or reversing samples (where friction is static or undetermined) are excluded.
//
// Least squares: Theta = (Phi^T Phi)^-1 Phi^T Y (ERRATA for (3.15)), computed by a column-pivoted
// Householder QR of Phi (never the normal equations). Standard errors: the square roots of the
// diagonal of sigma^2 (Phi^T Phi)^-1, sigma^2 = RSS / (n - p). With K_m known the regression is
// (3.14): y = acc/K_m - in, phi = [-vel eta, -vel xi, -eta, xi], Theta = [b+, b-, c+, c-]/K_m.
// With K_m unknown: y = acc, phi = [in, -vel eta, -vel xi, -eta, xi], Theta = [K_m, b+, b-, c+, c-];
// the ratios are Theta_i / K_m and their standard errors follow by the delta method from the full
// covariance.
//
// Offline: allocates; not for a cyclic path.

#include <cstddef>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>

namespace crane::model_audit {

/// Thrown when the data cannot identify the model: mismatched lengths, fewer than 3 samples,
/// non-finite values, non-uniform sampling, too few moving samples in a direction, or a
/// rank-deficient regressor matrix. The message says which and gives the numbers.
class IdentificationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Which finite differences form the regressors (see the header comment).
enum class DifferenceScheme {
  centered,      // O(T_s^2): central velocity, mean of u(k-1), u(k-2)
  dissertation,  // (3.10)-(3.11) as printed: backward velocity, u(k-2)
};

struct FrictionIdentificationOptions {
  double dead_band{0.05};         // d_s [m/s] or [rad/s], >= 0, the zero-velocity band (3.3)
  double cutoff_frequency{0.0};   // [Hz] zero-phase Butterworth prefilter of x; 0 = none, else
                                  // 0 < cutoff < sample rate / 2 (the dissertation: about 0.1 f_s)
  bool filter_input{false};       // also prefilter u with the same filter (keeps the linear part
                                  // of the model consistent when the cutoff is low)
  std::optional<double> motor_constant;  // K_m [m/s^2/V] > 0 if known: regression (3.14);
                                         // empty: K_m is identified as well
  DifferenceScheme scheme{DifferenceScheme::centered};
  std::size_t minimum_samples_per_direction{20};  // [samples] >= 1
  double sample_time_tolerance{0.01};  // [-] max |t_k+1 - t_k - T_s| / T_s, in (0, 0.5)
};

/// Throws common::ConfigError naming the field (e.g. "dead_band = -1 is out of range: must be >= 0").
void validate(const FrictionIdentificationOptions& options);

/// Parameters in volt-equivalents (Tables 3.1-3.5), i.e. divided by K_m.
struct FrictionRatios {
  double viscous_positive{0.0};  // b+/K_m [V s/m] ([V s/rad] for the slew)
  double viscous_negative{0.0};  // b-/K_m [V s/m]
  double coulomb_positive{0.0};  // c+/K_m [V]
  double coulomb_negative{0.0};  // c-/K_m [V]
};

struct FrictionIdentificationResult {
  FrictionRatios estimate;
  FrictionRatios standard_error;                   // same units as `estimate`
  std::optional<double> motor_constant;            // identified K_m [m/s^2/V] (empty when given)
  std::optional<double> motor_constant_standard_error;  // [m/s^2/V]
  std::size_t samples_positive{0};  // regression rows with eta = 1
  std::size_t samples_negative{0};  // regression rows with xi = 1
  std::size_t samples_excluded{0};  // rows dropped by the zero-velocity band
  double sample_time{0.0};          // T_s [s], (t_last - t_first) / (n - 1)
  double residual_rms{0.0};         // sqrt(RSS / n_rows) in the units of y: [m/s^2] with K_m
                                    // identified, [V] with K_m given
};

/// Identifies (3.13) from `time` [s] (strictly increasing, uniform within the tolerance), `input`
/// u [V] and `position` x [m] or gamma [rad], all of the same length n >= 3.
/// Throws common::ConfigError for invalid options (also a cutoff >= half the sample rate) and
/// IdentificationError for data that cannot identify the model (see that class).
[[nodiscard]] FrictionIdentificationResult identify_friction(std::span<const double> time,
                                                             std::span<const double> input,
                                                             std::span<const double> position,
                                                             const FrictionIdentificationOptions& options);

}  // namespace crane::model_audit
