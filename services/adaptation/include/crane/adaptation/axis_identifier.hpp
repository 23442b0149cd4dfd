#pragma once
// Recursive identification of one drive axis of the crane: its load term and its sliding friction,
// the dissertation's future work (section 5.1 of H. M. Omar, "Control of Gantry and Tower Cranes",
// Virginia Tech 2003: friction estimated on-line, the load mass included in the estimation).
//
// Linear regression in volt-equivalents, one row per accepted sample k:
//   y(k) = phi(k)^T theta + e(k),   theta = (load, b+, b-, c+, c-)
// where `load` is the load ratio of the axis (m_t = m/M [-] for the trolley, (3.31); m_r = m/J_o
// [1/m^2] for the slew, (3.32)) and (b+, b-, c+, c-) the sliding friction of (3.13)-(3.14) divided
// by the drive gain ([V s/m] or [V s/rad], [V]). OnlineAdaptation builds the rows from filtered
// signals (online_adaptation.hpp); this class only does the statistics.
//
// Exponentially weighted least squares (RLS with forgetting factor lambda, Ljung & Soederstroem
// 1983, ch. 2) kept in information form, so the excitation check reads the information matrix
// directly:
//   R(k) = lambda R(k-1) + phi phi^T,   r(k) = lambda r(k-1) + phi y,        (only accepted rows)
// i.e. R^-1 is RLS's covariance P up to the noise variance. A sample that is not accepted changes
// nothing (no forgetting either), so a crane at rest keeps its estimate and P cannot wind up.
//
// Excitation check: the parameters are grouped as {load}, {b+, c+} (moving +), {b-, c-} (moving
// -). A friction group is "excited" when the 2x2 block of the scaled information D R D (D =
// diag(scale), the parameters' typical sizes) has a smallest eigenvalue >= min_information and a
// condition number <= max_condition; the load group when its scaled information alone passes
// min_information. The estimate is then solved on the excited groups jointly,
//   theta_a = R_aa^-1 (r_a - R_ai theta_i)
// with every unexcited parameter i held at its current value, provided the scaled R_aa (all
// excited groups together) passes both bounds too (so the load is not confused with friction).
// Otherwise the estimate is left unchanged.
//
// Confidence: the residual variance s^2 is the forgetting-weighted mean of the a-posteriori
// residuals, times `noise_correlation` (the rows are low-pass filtered, so neighbouring residuals
// are correlated: OnlineAdaptation passes the filter's equivalent number of correlated samples,
// (sum h)^2 / sum h^2); the covariance of the excited parameters is s^2 R_aa^-1.
//
// Real-time: update() is noexcept and allocates nothing (fixed-size Eigen matrices).

#include <array>
#include <cstdint>

#include <Eigen/Core>

namespace crane::adaptation {

/// The sufficient statistics of exponentially weighted least squares in information form (the
/// header's R, r, and the sums the residual needs), shared by AxisIdentifier and
/// SwingLengthEstimator. Only rows that are taken forget: add() is the one update.
template <int N>
struct WeightedLeastSquares {
  Eigen::Matrix<double, N, N> information{Eigen::Matrix<double, N, N>::Zero()};  // R
  Eigen::Matrix<double, N, 1> weighted_output{Eigen::Matrix<double, N, 1>::Zero()};  // r
  double output_energy{0.0};  // sum lambda^j y^2
  double weight_sum{0.0};     // sum lambda^j
  /// Takes row (y, phi) with forgetting factor `lambda`. noexcept, no allocation.
  void add(double lambda, double y, const Eigen::Matrix<double, N, 1>& phi) noexcept {
    information = lambda * information + phi * phi.transpose();
    weighted_output = lambda * weighted_output + phi * y;
    output_energy = lambda * output_energy + y * y;
    weight_sum = lambda * weight_sum + 1.0;
  }
  /// The weighted residual sum of squares of `theta`: E - 2 theta^T r + theta^T R theta, >= 0.
  [[nodiscard]] double residual_sum_of_squares(const Eigen::Matrix<double, N, 1>& theta) const noexcept {
    const double rss = output_energy - 2.0 * theta.dot(weighted_output) + theta.dot(information * theta);
    return rss > 0.0 ? rss : 0.0;
  }
};

inline constexpr int kParameterCount = 5;   // load, b+, b-, c+, c-
inline constexpr int kLoadIndex = 0;

using ParameterVector = Eigen::Matrix<double, kParameterCount, 1>;
using InformationMatrix = Eigen::Matrix<double, kParameterCount, kParameterCount>;

struct AxisIdentifierParams {
  double forgetting_factor{0.998};  // [-] lambda in [0.9, 1]: memory 1/(1 - lambda) accepted samples
  ParameterVector initial{ParameterVector::Zero()};  // theta at start (the configured load ratio and friction), finite
  ParameterVector scale{ParameterVector::Ones()};  // [parameter units] typical size of each parameter, > 0 (normalizes
                                    // the information matrix for the excitation check)
  double min_information{1.0};      // [V^2] smallest eigenvalue of the scaled information of an
                                    // excited group, > 0
  double max_condition{1e4};        // [-] largest condition number of it, >= 1
  double noise_correlation{1.0};    // [samples] equivalent number of correlated residuals, >= 1
};

/// Throws common::ConfigError naming the field (prefixed by `prefix`), the value and the bound.
void validate(const AxisIdentifierParams& params, const char* prefix);

/// What one axis knows.
struct AxisIdentification {
  ParameterVector estimate{ParameterVector::Zero()};  // theta (held where not excited)
  ParameterVector standard_deviation{ParameterVector::Zero()};  // [parameter units] from s^2 R_aa^-1; 0 where not excited
  bool load_excited{false};                 // the load ratio was solved from data at the last solve
  bool positive_excited{false};             // b+, c+ likewise
  bool negative_excited{false};             // b-, c- likewise
  std::uint64_t accepted_samples{0};        // rows taken since start
  std::uint64_t solves{0};                  // updates of the estimate since start
  double residual_rms{0.0};                 // [V] forgetting-weighted, a posteriori
};

class AxisIdentifier {
 public:
  /// Throws common::ConfigError (validate) for invalid params.
  AxisIdentifier(const AxisIdentifierParams& params, const char* prefix);

  /// Takes one row (y [V], phi in the units that make phi^T theta volts). Rows with a non-finite
  /// value are ignored (returns false). Returns true when the row was taken. noexcept, no allocation.
  bool update(double y, const ParameterVector& phi) noexcept;

  /// Re-solves the estimate from the information gathered (the excitation check decides which
  /// parameters move). Returns true when the estimate changed. noexcept.
  bool solve() noexcept;

  /// Back to `initial` and no information.
  void reset() noexcept;

  [[nodiscard]] const AxisIdentification& identification() const noexcept { return state_; }
  /// The information matrix R (unscaled) of the excitation check.
  [[nodiscard]] const InformationMatrix& information() const noexcept { return statistics_.information; }
  [[nodiscard]] const AxisIdentifierParams& params() const noexcept { return params_; }

 private:
  AxisIdentifierParams params_;
  WeightedLeastSquares<kParameterCount> statistics_{};
  AxisIdentification state_{};
};

/// Smallest eigenvalue and condition number of the symmetric positive semidefinite `matrix`
/// (a block of a scaled information matrix); condition = +inf when the smallest is <= 0. noexcept.
struct Conditioning {
  double min_eigenvalue{0.0};
  double condition{0.0};
};
template <int N>
[[nodiscard]] Conditioning conditioning(const Eigen::Matrix<double, N, N>& matrix) noexcept;

}  // namespace crane::adaptation
