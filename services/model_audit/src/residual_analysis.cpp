#include "crane/model_audit/residual_analysis.hpp"

#include <algorithm>
#include <cmath>

namespace crane::model_audit {

namespace {

// Regularized upper incomplete gamma Q(a, x) (series for x < a + 1, Lentz continued fraction
// otherwise; Numerical Recipes 3rd ed., section 6.2).
double upper_incomplete_gamma(double a, double x) {
  if (x <= 0.0) return 1.0;
  const double log_prefix = a * std::log(x) - x - std::lgamma(a);
  if (x < a + 1.0) {
    double term = 1.0 / a;
    double sum = term;
    for (int n = 1; n < 1000; ++n) {
      term *= x / (a + n);
      sum += term;
      if (std::abs(term) < std::abs(sum) * 1e-15) break;
    }
    return std::clamp(1.0 - sum * std::exp(log_prefix), 0.0, 1.0);
  }
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a;
  double c = 1.0 / kTiny;
  double d = 1.0 / b;
  double h = d;
  for (int i = 1; i < 1000; ++i) {
    const double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    const double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-15) break;
  }
  return std::clamp(std::exp(log_prefix) * h, 0.0, 1.0);
}

}  // namespace

double chi_square_survival(double statistic, double dof) { return upper_incomplete_gamma(0.5 * dof, 0.5 * statistic); }

double root_mean_square(std::span<const double> values) {
  if (values.empty()) return 0.0;
  double sum = 0.0;
  for (const double v : values) sum += v * v;
  return std::sqrt(sum / static_cast<double>(values.size()));
}

WhitenessTest ljung_box(std::span<const double> residual, std::size_t max_lag) {
  WhitenessTest test;
  const std::size_t n = residual.size();
  const std::size_t h = std::min(max_lag, n / 4);
  if (h == 0) return test;
  double mean = 0.0;
  for (const double e : residual) mean += e;
  mean /= static_cast<double>(n);
  double denominator = 0.0;
  for (const double e : residual) denominator += (e - mean) * (e - mean);
  if (denominator <= 0.0) return test;
  test.lags = h;
  const double nd = static_cast<double>(n);
  for (std::size_t k = 1; k <= h; ++k) {
    double sum = 0.0;
    for (std::size_t t = 0; t + k < n; ++t) sum += (residual[t] - mean) * (residual[t + k] - mean);
    const double r = sum / denominator;
    test.autocorrelation.push_back(r);
    test.ljung_box_statistic += r * r / (nd - static_cast<double>(k));
  }
  test.ljung_box_statistic *= nd * (nd + 2.0);
  test.p_value = chi_square_survival(test.ljung_box_statistic, static_cast<double>(h));
  return test;
}

double correlation(std::span<const double> a, std::span<const double> b) {
  const std::size_t n = std::min(a.size(), b.size());
  if (n < 2) return 0.0;
  double mean_a = 0.0;
  double mean_b = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= static_cast<double>(n);
  mean_b /= static_cast<double>(n);
  double sab = 0.0;
  double saa = 0.0;
  double sbb = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    sab += (a[i] - mean_a) * (b[i] - mean_b);
    saa += (a[i] - mean_a) * (a[i] - mean_a);
    sbb += (b[i] - mean_b) * (b[i] - mean_b);
  }
  if (saa <= 0.0 || sbb <= 0.0) return 0.0;
  return sab / std::sqrt(saa * sbb);
}

double max_lagged_correlation(std::span<const double> residual, std::span<const double> input, std::size_t max_lag) {
  double best = 0.0;
  const std::size_t n = std::min(residual.size(), input.size());
  for (std::size_t lag = 0; lag <= max_lag && lag + 2 < n; ++lag) {
    const double r = correlation(residual.subspan(lag, n - lag), input.subspan(0, n - lag));
    best = std::max(best, std::abs(r));
  }
  return best;
}

}  // namespace crane::model_audit
