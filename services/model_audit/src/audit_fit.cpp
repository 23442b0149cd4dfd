#include "audit_fit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

namespace crane::model_audit::detail {

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(a + (b - a) * i / std::max(n - 1, 1));
  return v;
}

void FreeSet::add(std::size_t i, const ParameterSpec& spec) {
  index.push_back(i);
  scale.push_back(spec.scale);
  lower.push_back(spec.lower);
  upper.push_back(spec.upper);
}

namespace {

class WindowCost {
 public:
  WindowCost(const Problem& problem, const Window& window, const std::vector<double>& full, const FreeSet& free,
             bool has_free, std::vector<double> fixed_nuisance)
      : problem_(problem), window_(window), full_(full), free_(free), has_free_(has_free),
        fixed_nuisance_(std::move(fixed_nuisance)), buffer_(window.count) {}

  bool operator()(double const* const* parameters, double* residuals) const {
    std::vector<double> full = full_;
    int block = 0;
    if (has_free_) {
      for (std::size_t i = 0; i < free_.index.size(); ++i) full[free_.index[i]] = parameters[0][i] * free_.scale[i];
      ++block;
    }
    const double* nuisance = fixed_nuisance_.empty() ? parameters[block] : fixed_nuisance_.data();
    const std::size_t n = window_.train_count == 0 ? window_.count : window_.train_count;
    problem_.residual(full, nuisance, window_, n, buffer_.data());
    for (std::size_t i = 0; i < n; ++i) residuals[i] = std::isfinite(buffer_[i]) ? buffer_[i] : 0.0;
    return true;
  }

 private:
  const Problem& problem_;
  const Window& window_;
  const std::vector<double>& full_;
  const FreeSet& free_;
  bool has_free_;
  std::vector<double> fixed_nuisance_;
  mutable std::vector<double> buffer_;
};

void solve(ceres::Problem& problem, int iterations) {
  ceres::Solver::Options options;
  options.linear_solver_type = ceres::DENSE_QR;
  options.max_num_iterations = iterations;
  options.logging_type = ceres::SILENT;
  options.minimizer_progress_to_stdout = false;
  options.function_tolerance = 1e-8;
  options.parameter_tolerance = 1e-8;
  ceres::Solver::Summary summary;
  ceres::Solve(options, &problem, &summary);
}

using CostFunction = ceres::DynamicNumericDiffCostFunction<WindowCost, ceres::CENTRAL>;

// Sum of squares and count of finite residuals of one window, samples [begin, end).
std::pair<double, std::size_t> window_rss(const Problem& problem, const std::vector<double>& full,
                                          const double* nuisance, const Window& window, std::size_t begin,
                                          std::size_t end, std::vector<double>* per_sample) {
  std::vector<double> r(window.count);
  problem.residual(full, nuisance, window, end, r.data());
  double rss = 0.0;
  std::size_t n = 0;
  for (std::size_t i = begin; i < end; ++i) {
    if (per_sample != nullptr) (*per_sample)[window.first + i] = r[i];
    if (!std::isfinite(r[i])) continue;
    rss += r[i] * r[i];
    ++n;
  }
  return {rss, n};
}

// Fits the free parameters and every training window's nuisance, then the held-out part.

}  // namespace

Fit fit_problem(const Problem& problem, std::vector<double> full, const FreeSet& free,
                std::vector<std::vector<double>> nuisance, std::size_t samples, int iterations) {
  const bool has_free = !free.index.empty();
  std::vector<double> x(free.index.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = full[free.index[i]] / free.scale[i];
  {
    ceres::Problem ceres_problem;
    bool any = false;
    for (std::size_t w = 0; w < problem.windows.size(); ++w) {
      const Window& window = problem.windows[w];
      if (window.train_count < 3) continue;
      auto* cost = new CostFunction(new WindowCost(problem, window, full, free, has_free, {}));
      std::vector<double*> blocks;
      if (has_free) {
        cost->AddParameterBlock(static_cast<int>(x.size()));
        blocks.push_back(x.data());
      }
      if (problem.nuisance_size > 0) {
        cost->AddParameterBlock(static_cast<int>(problem.nuisance_size));
        blocks.push_back(nuisance[w].data());
      }
      if (blocks.empty()) {
        delete cost;
        continue;
      }
      cost->SetNumResiduals(static_cast<int>(window.train_count));
      ceres_problem.AddResidualBlock(cost, nullptr, blocks);
      any = true;
    }
    if (any) {
      if (has_free) {
        for (std::size_t i = 0; i < x.size(); ++i) {
          ceres_problem.SetParameterLowerBound(x.data(), static_cast<int>(i), free.lower[i] / free.scale[i]);
          ceres_problem.SetParameterUpperBound(x.data(), static_cast<int>(i), free.upper[i] / free.scale[i]);
        }
      }
      solve(ceres_problem, iterations);
    }
  }
  for (std::size_t i = 0; i < x.size(); ++i) full[free.index[i]] = x[i] * free.scale[i];

  // Held-out windows: refit their initial state with the model fixed.
  for (std::size_t w = 0; w < problem.windows.size(); ++w) {
    const Window& window = problem.windows[w];
    if (window.train_count != 0 || problem.nuisance_size == 0 || window.count < 3) continue;
    ceres::Problem ceres_problem;
    FreeSet none;
    auto* cost = new CostFunction(new WindowCost(problem, window, full, none, false, {}));
    cost->AddParameterBlock(static_cast<int>(problem.nuisance_size));
    cost->SetNumResiduals(static_cast<int>(window.count));
    ceres_problem.AddResidualBlock(cost, nullptr, nuisance[w].data());
    solve(ceres_problem, 30);
  }

  Fit fit;
  fit.full = full;
  fit.residual_per_sample.assign(samples, kNaN);
  fit.holdout_flag.assign(samples, 0.0);
  for (std::size_t w = 0; w < problem.windows.size(); ++w) {
    const Window& window = problem.windows[w];
    const double* nz = problem.nuisance_size > 0 ? nuisance[w].data() : nullptr;
    if (window.train_count > 0) {
      const auto [rss, n] = window_rss(problem, full, nz, window, 0, window.train_count, &fit.residual_per_sample);
      fit.train_rss += rss;
      fit.train_n += n;
    }
    if (window.train_count < window.count) {
      const auto [rss, n] = window_rss(problem, full, nz, window, window.train_count, window.count,
                                       &fit.residual_per_sample);
      fit.holdout_rss += rss;
      fit.holdout_n += n;
      for (std::size_t i = window.train_count; i < window.count; ++i) fit.holdout_flag[window.first + i] = 1.0;
    }
  }
  fit.nuisance = std::move(nuisance);

  // Standard errors from the numeric Jacobian of the training residuals (nuisance held).
  fit.standard_errors.assign(free.index.size(), kNaN);
  if (has_free && fit.train_n > free.index.size()) {
    const auto stacked = [&](const std::vector<double>& f) {
      std::vector<double> all;
      for (std::size_t w = 0; w < problem.windows.size(); ++w) {
        const Window& window = problem.windows[w];
        if (window.train_count == 0) continue;
        std::vector<double> r(window.count);
        problem.residual(f, problem.nuisance_size > 0 ? fit.nuisance[w].data() : nullptr, window,
                         window.train_count, r.data());
        for (std::size_t i = 0; i < window.train_count; ++i) all.push_back(std::isfinite(r[i]) ? r[i] : 0.0);
      }
      return all;
    };
    const std::size_t p = free.index.size();
    std::vector<double> base = stacked(full);
    Eigen::MatrixXd jacobian(static_cast<Eigen::Index>(base.size()), static_cast<Eigen::Index>(p));
    for (std::size_t j = 0; j < p; ++j) {
      const double h = 1e-3 * free.scale[j];
      std::vector<double> plus = full;
      std::vector<double> minus = full;
      plus[free.index[j]] += h;
      minus[free.index[j]] -= h;
      const auto rp = stacked(plus);
      const auto rm = stacked(minus);
      for (std::size_t i = 0; i < base.size(); ++i) {
        jacobian(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = (rp[i] - rm[i]) / (2.0 * h);
      }
    }
    const std::size_t nuisance_total = problem.nuisance_size * problem.windows.size();
    const double dof = static_cast<double>(fit.train_n) - static_cast<double>(p + nuisance_total);
    const double s2 = fit.train_rss / std::max(dof, 1.0);
    const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
    Eigen::FullPivLU<Eigen::MatrixXd> lu(normal);
    if (lu.isInvertible()) {
      const Eigen::MatrixXd covariance = s2 * lu.inverse();
      for (std::size_t j = 0; j < p; ++j) {
        fit.standard_errors[j] = std::sqrt(std::max(0.0, covariance(static_cast<Eigen::Index>(j),
                                                                    static_cast<Eigen::Index>(j))));
      }
    }
  }
  return fit;
}

double train_rss_fixed(const Problem& problem, const std::vector<double>& full,
                       const std::vector<std::vector<double>>& nuisance) {
  double rss = 0.0;
  for (std::size_t w = 0; w < problem.windows.size(); ++w) {
    const Window& window = problem.windows[w];
    if (window.train_count == 0) continue;
    rss += window_rss(problem, full, problem.nuisance_size > 0 ? nuisance[w].data() : nullptr, window, 0,
                      window.train_count, nullptr)
               .first;
  }
  return rss;
}

// Local quadratic fit x(t) = p0 + p1 t + p2 t^2 over samples first .. first + 10 (clipped).
std::pair<double, double> local_state(const std::vector<double>& x, std::size_t first, std::size_t last,
                                      double sample_time) {
  const std::size_t end = std::min(last, first + 11);
  const std::size_t m = end - first;
  if (m < 3) return {x[first], 0.0};
  Eigen::MatrixXd a(static_cast<Eigen::Index>(m), 3);
  Eigen::VectorXd y(static_cast<Eigen::Index>(m));
  for (std::size_t i = 0; i < m; ++i) {
    const double t = static_cast<double>(i) * sample_time;
    const auto row = static_cast<Eigen::Index>(i);
    a(row, 0) = 1.0;
    a(row, 1) = t;
    a(row, 2) = t * t;
    y(row) = x[first + i];
  }
  const Eigen::Vector3d p = a.colPivHouseholderQr().solve(y);
  return {p(0), p(1)};
}

std::vector<std::vector<double>> grid_points(const Candidate& candidate) {
  std::vector<std::vector<double>> points{{}};
  for (const auto& spec : candidate.parameters) {
    std::vector<std::vector<double>> next;
    for (const auto& p : points) {
      for (const double g : spec.grid) {
        auto q = p;
        q.push_back(g);
        next.push_back(q);
      }
    }
    points = next;
  }
  return points;
}

double bic(double rss, std::size_t n, std::size_t k) {
  const double nd = static_cast<double>(std::max<std::size_t>(n, 1));
  return nd * std::log(std::max(rss, 1e-300) / nd) + static_cast<double>(k) * std::log(nd);
}

ResidualSummary summarize(const Fit& fit, const std::vector<double>& input, std::size_t max_lag) {
  ResidualSummary summary;
  std::vector<double> train;
  std::vector<double> train_input;
  for (std::size_t i = 0; i < fit.residual_per_sample.size(); ++i) {
    if (fit.holdout_flag[i] != 0.0 || !std::isfinite(fit.residual_per_sample[i])) continue;
    train.push_back(fit.residual_per_sample[i]);
    if (!input.empty()) train_input.push_back(input[i]);
  }
  summary.train_rms = fit.train_n ? std::sqrt(fit.train_rss / static_cast<double>(fit.train_n)) : 0.0;
  summary.holdout_rms = fit.holdout_n ? std::sqrt(fit.holdout_rss / static_cast<double>(fit.holdout_n)) : 0.0;
  summary.whiteness = ljung_box(train, max_lag);
  summary.input_correlation = train_input.empty() ? 0.0 : max_lagged_correlation(train, train_input, max_lag);
  return summary;
}

std::vector<std::vector<double>> initial_nuisance(const Problem& problem) {
  std::vector<std::vector<double>> nuisance(problem.windows.size(), std::vector<double>(problem.nuisance_size));
  if (problem.nuisance_size > 0) {
    for (std::size_t w = 0; w < problem.windows.size(); ++w) problem.initial_nuisance(problem.windows[w], nuisance[w].data());
  }
  return nuisance;
}

void hold_out_moving_windows(const std::vector<double>& measured, double fraction, std::vector<Window>& windows) {
  std::vector<double> range(windows.size(), 0.0);
  double largest = 0.0;
  for (std::size_t i = 0; i < windows.size(); ++i) {
    const auto begin = measured.begin() + static_cast<std::ptrdiff_t>(windows[i].first);
    const auto [lo, hi] = std::minmax_element(begin, begin + static_cast<std::ptrdiff_t>(windows[i].count));
    range[i] = *hi - *lo;
    largest = std::max(largest, range[i]);
  }
  std::size_t end = 0;  // one past the last sample of the last moving window
  for (std::size_t i = 0; i < windows.size(); ++i) {
    if (range[i] > kMovingRangeFraction * largest) end = windows[i].first + windows[i].count;
  }
  if (end == 0) end = measured.size();
  const auto start = static_cast<std::size_t>(std::floor((1.0 - fraction) * static_cast<double>(end)));
  for (auto& w : windows) w.train_count = w.first >= start && w.first < end ? 0 : w.count;
}

double measurement_resolution(const std::vector<double>& measured, std::size_t stride) {
  std::vector<double> fourth;
  for (std::size_t k = 4 * stride; k < measured.size(); ++k) {
    const double d = measured[k] - 4.0 * measured[k - stride] + 6.0 * measured[k - 2 * stride] -
                     4.0 * measured[k - 3 * stride] + measured[k - 4 * stride];
    if (std::isfinite(d)) fourth.push_back(std::abs(d));
  }
  double noise = 0.0;
  if (!fourth.empty()) {
    auto middle = fourth.begin() + static_cast<std::ptrdiff_t>(fourth.size() / 2);
    std::nth_element(fourth.begin(), middle, fourth.end());
    noise = 1.4826 * *middle / std::sqrt(70.0);
  }
  return std::max(resolution_quantum(measured, stride), noise);
}

double resolution_quantum(const std::vector<double>& measured, std::size_t stride) {
  double quantum = std::numeric_limits<double>::infinity();
  for (std::size_t k = stride; k < measured.size(); ++k) {
    const double step = std::abs(measured[k] - measured[k - stride]);
    if (step > 1e-15) quantum = std::min(quantum, step);
  }
  return std::isfinite(quantum) ? quantum : 0.0;
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

}  // namespace crane::model_audit::detail
