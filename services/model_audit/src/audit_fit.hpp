#pragma once
// Fitting core of the model audit (private to crane_model_audit): a residual problem over replay
// windows with nuisance initial states, its nonlinear least-squares fit (Ceres, Levenberg-Marquardt,
// central numeric derivatives, bounds) with standard errors sqrt(diag(s^2 (J^T J)^-1)),
// s^2 = RSS / (n - parameters), and the selection statistics (BIC, Schwarz 1978:
// BIC = n ln(RSS / n) + k ln(n)). Offline: allocates.

#include <cstddef>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit::detail {

inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// One parameter of a catalog entry or of the nominal model.
struct ParameterSpec {
  std::string name;  // as reported
  std::string unit;
  double scale{1.0};  // typical size: the optimizer works on value / scale
  double lower{-1e9};
  double upper{1e9};
  std::vector<double> grid;  // initial values tried (physical units)
};

/// A catalog entry at the scales of one record: `entry` indexes the model's catalog.
struct Candidate {
  std::string name;
  std::vector<ParameterSpec> parameters;
  std::size_t entry{0};
  std::string calibration_note;  // non-empty: skipped with --calibrate (the nominal fit absorbs it)
  std::string note;              // non-empty: skipped, with the reason
  // A shared signature at a bound: when the fitted parameter `limit_parameter` ends at its lower
  // bound (or at or below limit_value) the candidate is the limit case of the catalog entry `limit_of` (a Stribeck curve whose
  // v_s falls to its bound is a breakaway excess: stiction), and the data cannot separate the two:
  // the audit reports "ambiguous" naming both (run_channel_audit). Empty: none.
  std::string limit_of;
  std::size_t limit_parameter{0};
  double limit_value{-1e300};  // at or below max(this, 1.05 x the lower bound): at the limit
};

/// n values evenly spaced over [a, b].
[[nodiscard]] std::vector<double> linspace(double a, double b, int n);

struct Window {
  std::size_t first{0};
  std::size_t count{0};
  std::size_t train_count{0};  // residuals [first, first + train_count) fit; the rest is held out
};

/// Windows, nuisance initial states and a residual function of the full parameter vector (the
/// model's base parameters, then the candidate's).
struct Problem {
  std::vector<Window> windows;
  std::size_t nuisance_size{0};
  std::function<void(const Window&, double*)> initial_nuisance;
  // Residuals (measured - model) of samples first .. first + count - 1 of the window; NaN = unused.
  std::function<void(const std::vector<double>& full, const double* nuisance, const Window&, std::size_t count,
                     double* out)>
      residual;
};

struct Fit {
  std::vector<double> full;
  std::vector<std::vector<double>> nuisance;  // per window (train values; held-out windows refitted)
  double train_rss{0.0};
  std::size_t train_n{0};
  double holdout_rss{0.0};
  std::size_t holdout_n{0};
  std::vector<double> standard_errors;      // per free index
  std::vector<double> residual_per_sample;  // whole record, NaN where unused
  std::vector<double> holdout_flag;
};

/// Indices of `full` that a fit moves, with their scales and bounds.
struct FreeSet {
  std::vector<std::size_t> index;
  std::vector<double> scale;
  std::vector<double> lower;
  std::vector<double> upper;
  void add(std::size_t i, const ParameterSpec& spec);
};

/// Fits the free parameters and every training window's nuisance, then refits the held-out windows'
/// nuisance with the model fixed; `samples` sizes the per-sample residual.
[[nodiscard]] Fit fit_problem(const Problem& problem, std::vector<double> full, const FreeSet& free,
                              std::vector<std::vector<double>> nuisance, std::size_t samples, int iterations = 30);

/// Training RSS with every nuisance held.
[[nodiscard]] double train_rss_fixed(const Problem& problem, const std::vector<double>& full,
                                     const std::vector<std::vector<double>>& nuisance);

/// Each window's initial nuisance (Problem::initial_nuisance).
[[nodiscard]] std::vector<std::vector<double>> initial_nuisance(const Problem& problem);

/// Value and slope at sample `first` of the local quadratic fit over samples first .. first + 10
/// (clipped to `last`), time step `sample_time` [s].
[[nodiscard]] std::pair<double, double> local_state(const std::vector<double>& x, std::size_t first, std::size_t last,
                                                    double sample_time);

/// Grid product of the candidate's parameter grids.
[[nodiscard]] std::vector<std::vector<double>> grid_points(const Candidate& candidate);

[[nodiscard]] double bic(double rss, std::size_t n, std::size_t k);

/// RMS, Ljung-Box test and input correlation (empty `input`: none) of the fit's training residual.
[[nodiscard]] ResidualSummary summarize(const Fit& fit, const std::vector<double>& input, std::size_t max_lag);

/// Held-out windows among the moving ones: a window moves when the range of `measured` over it
/// exceeds kMovingRangeFraction of the largest window range; the windows that start in the last
/// `fraction` of the record up to the end of its last moving window are held out (train_count = 0);
/// the windows at rest after it are trained on. A record that moves until its end is split as
/// before (the last `fraction` of the record); one that ends at rest (a whole demo run) is validated
/// where the model is exercised, not on the standstill where every model predicts the same.
inline constexpr double kMovingRangeFraction = 0.02;
void hold_out_moving_windows(const std::vector<double>& measured, double fraction, std::vector<Window>& windows);

/// Resolution of a measured channel [its unit]: the larger of its quantum (resolution_quantum) and
/// its noise, estimated robustly from the fourth difference (1.4826 MAD / sqrt(70), Gaussian noise;
/// the motion's own fourth difference is negligible at the sample rates audited). Samples `stride`
/// apart. The practical-significance floor of a cause's held-out gain (AuditOptions) is in it.
[[nodiscard]] double measurement_resolution(const std::vector<double>& measured, std::size_t stride);

/// The smallest nonzero step between samples `stride` apart (0 when there is none).
[[nodiscard]] double resolution_quantum(const std::vector<double>& measured, std::size_t stride);

[[nodiscard]] std::string join(const std::vector<std::string>& names);

}  // namespace crane::model_audit::detail
