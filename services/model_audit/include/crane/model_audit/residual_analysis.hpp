#pragma once
// Residual diagnostics of the model audit (Ljung & Box 1978, "On a measure of lack of fit in time
// series models", Biometrika 65(2)):
//   autocorrelation r_k = sum_t e_t e_{t+k} / sum_t e_t^2 (mean removed), k = 1..max_lag
//   Ljung-Box Q = n (n + 2) sum_{k=1}^{h} r_k^2 / (n - k), compared with chi^2(h):
//   p = P(chi^2_h > Q) (regularized upper incomplete gamma Q(h/2, Q/2)); p < 0.05 = not white.
//   Pearson correlation of two equal-length series (0 when either is constant).
// All functions are pure, allocate only their result, and never throw for finite input; empty or
// too short input gives zeros (p = 1).

#include <cstddef>
#include <span>
#include <vector>

namespace crane::model_audit {

struct WhitenessTest {
  std::vector<double> autocorrelation;  // r_1 .. r_h [-]
  double ljung_box_statistic{0.0};      // Q [-]
  double p_value{1.0};                  // [-] P(chi^2_h > Q)
  std::size_t lags{0};                  // h
};

/// Autocorrelation and the Ljung-Box test of `residual` (any unit) with h = min(max_lag, n / 4) lags.
[[nodiscard]] WhitenessTest ljung_box(std::span<const double> residual, std::size_t max_lag);

/// Pearson correlation coefficient [-] of a and b over min(a.size(), b.size()) samples.
[[nodiscard]] double correlation(std::span<const double> a, std::span<const double> b);

/// Largest |correlation| [-] of residual(t) with input(t - lag) over lag = 0..max_lag [samples].
[[nodiscard]] double max_lagged_correlation(std::span<const double> residual, std::span<const double> input,
                                            std::size_t max_lag);

/// P(chi^2_dof > statistic), dof > 0.
[[nodiscard]] double chi_square_survival(double statistic, double dof);

/// Root mean square [unit of the input]; 0 for an empty span.
[[nodiscard]] double root_mean_square(std::span<const double> values);

}  // namespace crane::model_audit
