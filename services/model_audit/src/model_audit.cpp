#include "crane/model_audit/model_audit.hpp"

#include <ceres/ceres.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <numeric>
#include <optional>
#include <sstream>

#include "crane/common/validation.hpp"
#include "crane/model_audit/audit_models.hpp"

namespace crane::model_audit {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ---------------------------------------------------------------------------------------------
// Catalog definitions.

struct ParameterSpec {
  std::string name;
  std::string unit;
  double scale{1.0};  // typical size: the optimizer works on value / scale
  double lower{-1e9};
  double upper{1e9};
  std::vector<double> grid;  // initial values tried (physical units)
};

struct Candidate {
  std::string name;
  std::vector<ParameterSpec> parameters;
  std::string note;  // non-empty: skipped, with the reason
};

std::vector<double> linspace(double a, double b, int n) {
  std::vector<double> v;
  for (int i = 0; i < n; ++i) v.push_back(a + (b - a) * i / std::max(n - 1, 1));
  return v;
}

// ---------------------------------------------------------------------------------------------
// Problem: windows, nuisance initial states and a residual function of the full parameter vector.

struct Window {
  std::size_t first{0};
  std::size_t count{0};
  std::size_t train_count{0};  // residuals [first, first + train_count) fit; the rest is held out
};

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
  std::vector<double> standard_errors;  // per free index
  std::vector<double> residual_per_sample;  // whole record, NaN where unused
  std::vector<double> holdout_flag;
};

struct FreeSet {
  std::vector<std::size_t> index;
  std::vector<double> scale;
  std::vector<double> lower;
  std::vector<double> upper;
};

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
Fit fit_problem(const Problem& problem, std::vector<double> full, const FreeSet& free,
                std::vector<std::vector<double>> nuisance, std::size_t samples, int iterations = 30) {
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

double parameter(const std::map<std::string, double>& parameters, const std::string& name, double fallback) {
  const auto it = parameters.find(name);
  return it == parameters.end() ? fallback : it->second;
}

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

// ---------------------------------------------------------------------------------------------
// Axis.

constexpr std::size_t kAxisBase = 3;  // K_m, b, c

AxisModel axis_model(const std::vector<double>& full, const std::string& cause) {
  AxisModel m;
  m.motor_constant = std::max(full[0], 1e-9);
  m.viscous = std::max(full[1], 0.0);
  m.coulomb = std::max(full[2], 0.0);
  const double* p = full.data() + kAxisBase;
  if (cause == "coulomb_friction_asymmetry") m.coulomb_asymmetry = p[0];
  if (cause == "viscous_friction_asymmetry") m.viscous_asymmetry = p[0];
  if (cause == "stiction") m.stiction = std::max(p[0], 0.0);
  if (cause == "stribeck") {
    m.stribeck_level = std::max(p[0], 0.0);
    m.stribeck_velocity = std::max(p[1], 1e-6);
  }
  if (cause == "deadzone") m.deadzone = std::max(p[0], 0.0);
  if (cause == "saturation") m.saturation = std::max(p[0], 1e-9);
  if (cause == "backlash") m.backlash = std::max(p[0], 0.0);
  if (cause == "input_delay") m.input_delay = std::max(p[0], 0.0);
  if (cause == "gain_error") m.gain_error = std::max(p[0], -0.99);
  if (cause == "position_dependent_friction") m.position_friction = p[0];
  return m;
}

bool axis_needs_substeps(const std::string& cause) {
  return cause == "stribeck" || cause == "position_dependent_friction";
}

std::vector<Candidate> axis_candidates(const AuditData& data, double k_m, double b, double c, double sample_time) {
  double max_input = 0.0;
  for (const double u : data.input) max_input = std::max(max_input, std::abs(u));
  const auto [min_x, max_x] = std::minmax_element(data.output.begin(), data.output.end());
  const double range = std::max(*max_x - *min_x, 1e-6);
  const double half_range = 0.5 * range;
  const double c_scale = std::max(c, 0.05 * k_m);
  const double b_scale = std::max(b, 0.1);
  const double volt = c_scale / k_m;
  std::vector<Candidate> list;
  list.push_back({"coulomb_friction_asymmetry",
                  {{"coulomb_asymmetry", "m/s^2", c_scale, -10 * c_scale, 10 * c_scale, linspace(-c_scale, c_scale, 41)}},
                  ""});
  list.push_back({"viscous_friction_asymmetry",
                  {{"viscous_asymmetry", "1/s", b_scale, -b_scale, b_scale, linspace(-0.6 * b_scale, 0.6 * b_scale, 41)}},
                  ""});
  list.push_back({"stiction", {{"stiction", "m/s^2", c_scale, 0.0, 20 * c_scale, linspace(0.05 * c_scale, 2.5 * c_scale, 120)}}, ""});
  std::vector<double> stribeck_grid;
  list.push_back({"stribeck",
                  {{"stribeck_level", "m/s^2", c_scale, 0.0, 20 * c_scale, linspace(0.1 * c_scale, 2.0 * c_scale, 20)},
                   {"stribeck_velocity", "m/s", 0.05, 0.002, 0.5, {0.005, 0.01, 0.015, 0.02, 0.03, 0.045, 0.07, 0.1, 0.15}}},
                  ""});
  list.push_back({"deadzone", {{"deadzone", "V", volt, 0.0, max_input, linspace(0.05 * volt, 2.0 * volt, 80)}}, ""});
  list.push_back({"saturation",
                  {{"saturation", "V", max_input, 0.02 * max_input, max_input, linspace(0.2 * max_input, 0.99 * max_input, 80)}},
                  ""});
  list.push_back({"backlash",
                  {{"backlash", "m", 0.005 * range, 0.0, 0.2 * range, linspace(0.0005 * range, 0.02 * range, 80)}}, ""});
  list.push_back({"input_delay",
                  {{"input_delay", "s", sample_time, 0.0, 30 * sample_time, linspace(0.1 * sample_time, 5 * sample_time, 80)}},
                  ""});
  list.push_back({"gain_error", {{"gain_error", "-", 0.1, -0.9, 3.0, linspace(-0.5, 0.5, 41)}}, ""});
  list.push_back({"position_dependent_friction",
                  {{"position_friction_slope", "m/s^2/m", c_scale / half_range, -10 * c_scale / half_range,
                    10 * c_scale / half_range, linspace(-c_scale / half_range, c_scale / half_range, 41)}},
                  ""});
  return list;
}

struct AxisSeries {
  std::vector<double> x;
  std::vector<double> u;
  double sample_time{0.0};
  int substeps{1};
  std::string cause;
  double dead_band{0.0};
};

Problem axis_position_problem(const std::shared_ptr<AxisSeries>& s, double window_duration, double holdout_fraction) {
  Problem problem;
  const std::size_t n = s->x.size();
  const auto length = std::max<std::size_t>(static_cast<std::size_t>(std::llround(window_duration / s->sample_time)), 10);
  const auto holdout_start = static_cast<std::size_t>(std::floor((1.0 - holdout_fraction) * static_cast<double>(n)));
  for (std::size_t first = 0; first + 10 <= n; first += length) {
    Window w;
    w.first = first;
    w.count = std::min(length, n - first);
    w.train_count = first >= holdout_start ? 0 : w.count;
    problem.windows.push_back(w);
  }
  // Nuisance: initial measured position, velocity and (backlash only) where the axis sits in the
  // gap, as a fraction in [-1, 1] of the half gap.
  const bool gap = s->cause == "backlash";
  problem.nuisance_size = gap ? 3 : 2;
  problem.initial_nuisance = [s, gap](const Window& w, double* out) {
    const auto [x0, v0] = local_state(s->x, w.first, w.first + w.count, s->sample_time);
    out[0] = x0;
    out[1] = v0;
    if (gap) out[2] = v0 > 0.0 ? 0.9 : -0.9;
  };
  problem.residual = [s](const std::vector<double>& full, const double* nuisance, const Window& w, std::size_t count,
                         double* out) {
    const AxisModel model = axis_model(full, s->cause);
    AxisState initial;
    initial.load_position = nuisance[0];
    initial.velocity = nuisance[1];
    const double sign = s->cause == "backlash" ? std::clamp(nuisance[2], -1.0, 1.0) : 0.0;
    initial.position = nuisance[0] + 0.5 * model.backlash * sign;
    std::span<double> prediction(out, count);
    replay_axis(model, s->u, s->sample_time, w.first, initial, s->substeps, prediction);
    for (std::size_t i = 0; i < count; ++i) out[i] = s->x[w.first + i] - out[i];
  };
  return problem;
}

// Effort residual [V] of sample k (1 <= k <= n - 2), NaN when the stencil mixes regimes.
double axis_effort_residual(const AxisSeries& s, const AxisModel& m, std::size_t k) {
  const double t = s.sample_time;
  const double vm = (s.x[k] - s.x[k - 1]) / t;
  const double vp = (s.x[k + 1] - s.x[k]) / t;
  const double v = 0.5 * (vm + vp);
  const double a = (vp - vm) / t;
  const double delay = m.input_delay / t;
  const auto whole = static_cast<std::ptrdiff_t>(std::floor(delay));
  const double fraction = delay - static_cast<double>(whole);
  const auto last = static_cast<std::ptrdiff_t>(s.u.size()) - 1;
  const auto drive_over = [&](std::ptrdiff_t j) {  // mean drive over [t_j, t_j+1)
    const auto at = [&](std::ptrdiff_t i) {
      return axis_drive_acceleration(m, s.u[static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(i, 0, last))]);
    };
    return (1.0 - fraction) * at(j - whole) + fraction * at(j - whole - 1);
  };
  const auto kk = static_cast<std::ptrdiff_t>(k);
  const double drive = 0.5 * (drive_over(kk - 1) + drive_over(kk));
  const double position_term = m.position_friction * s.x[k];
  const double c_plus = std::max(0.0, m.coulomb + m.coulomb_asymmetry + position_term);
  const double c_minus = std::max(0.0, m.coulomb - m.coulomb_asymmetry + position_term);
  const double k_eff = m.motor_constant;
  if (vm > s.dead_band && vp > s.dead_band) {
    const double friction = std::max(0.0, m.viscous + m.viscous_asymmetry) * v + c_plus +
                            m.stribeck_level * std::exp(-std::pow(v / m.stribeck_velocity, 2));
    return (drive - a - friction) / k_eff;
  }
  if (vm < -s.dead_band && vp < -s.dead_band) {
    const double friction = std::max(0.0, m.viscous - m.viscous_asymmetry) * v - c_minus -
                            m.stribeck_level * std::exp(-std::pow(v / m.stribeck_velocity, 2));
    return (drive - a - friction) / k_eff;
  }
  if (std::abs(vm) <= s.dead_band && std::abs(vp) <= s.dead_band) {
    const double net = drive - a - m.viscous * v;
    const double extra = m.stribeck_level + m.stiction;
    return (net - std::clamp(net, -(c_minus + extra), c_plus + extra)) / k_eff;
  }
  return kNaN;
}

Problem axis_effort_problem(const std::shared_ptr<AxisSeries>& s, double holdout_fraction) {
  Problem problem;
  const std::size_t n = s->x.size();
  const auto split = static_cast<std::size_t>(std::floor((1.0 - holdout_fraction) * static_cast<double>(n)));
  problem.windows.push_back({0, split, split});
  problem.windows.push_back({split, n - split, 0});
  problem.residual = [s](const std::vector<double>& full, const double*, const Window& w, std::size_t count,
                         double* out) {
    const AxisModel model = axis_model(full, s->cause);
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t k = w.first + i;
      out[i] = (k >= 1 && k + 2 <= s->x.size()) ? axis_effort_residual(*s, model, k) : kNaN;
    }
  };
  return problem;
}

// Linear least squares in the effort domain for the candidates linear in their parameter:
// K_m u - a - b v - c s = phi * theta on moving samples (Eigen column-pivoted QR).
std::optional<double> axis_linear_estimate(const AxisSeries& s, const std::vector<double>& base, const std::string& cause) {
  std::vector<double> y;
  std::vector<double> phi;
  const double t = s.sample_time;
  for (std::size_t k = 1; k + 1 < s.x.size(); ++k) {
    const double vm = (s.x[k] - s.x[k - 1]) / t;
    const double vp = (s.x[k + 1] - s.x[k]) / t;
    if (!((vm > s.dead_band && vp > s.dead_band) || (vm < -s.dead_band && vp < -s.dead_band))) continue;
    const double v = 0.5 * (vm + vp);
    const double a = (vp - vm) / t;
    const double sign = v > 0.0 ? 1.0 : -1.0;
    const double u = 0.5 * (s.u[k - 1] + s.u[k]);
    y.push_back(base[0] * u - a - base[1] * v - base[2] * sign);
    if (cause == "coulomb_friction_asymmetry") phi.push_back(1.0);
    else if (cause == "viscous_friction_asymmetry") phi.push_back(std::abs(v));
    else if (cause == "gain_error") phi.push_back(-base[0] * u);
    else if (cause == "position_dependent_friction") phi.push_back(sign * s.x[k]);
    else return std::nullopt;
  }
  if (y.size() < 10) return std::nullopt;
  const Eigen::Map<const Eigen::VectorXd> yv(y.data(), static_cast<Eigen::Index>(y.size()));
  const Eigen::Map<const Eigen::VectorXd> pv(phi.data(), static_cast<Eigen::Index>(phi.size()));
  const Eigen::VectorXd theta = Eigen::MatrixXd(pv).colPivHouseholderQr().solve(yv);
  // gain_error regressor is -K_m u against K_m(1+g)u - ...: residual(g) = y + g K_m u => theta = -g.
  return cause == "gain_error" ? -theta(0) : theta(0);
}

// Stick threshold from the breakaways (stiction only). A position fit of Delta_s is piecewise flat:
// with the command held over each sample, a breakaway can only start at a sample instant, so the
// data only say that the threshold c + Delta_s lies between the drive K_m u of the last held
// sample and that of the breakaway sample. This estimator reads those brackets off the record:
// a rest episode is a run of >= 5 samples within kRestQuanta position quanta (the smallest
// nonzero step of the record) of its first sample, followed by motion; the breakaway instant is
// the one (of the last four of the episode) whose nominal-model motion from rest (kinetic friction
// only, which does not depend on Delta_s) best matches the next kMotionSamples samples. The
// estimate is the middle of the stretch covered by the most brackets; nullopt below two brackets.
// Returns the threshold bracket [lower, upper] of c + Delta_s [m/s^2].
constexpr double kRestQuanta = 2.5;
constexpr std::size_t kMotionSamples = 5;

std::optional<std::pair<double, double>> axis_breakaway_bracket(const AxisSeries& s, const std::vector<double>& full) {
  const std::size_t n = s.x.size();
  double quantum = std::numeric_limits<double>::infinity();
  for (std::size_t k = 1; k < n; ++k) {
    const double step = std::abs(s.x[k] - s.x[k - 1]);
    if (step > 1e-12) quantum = std::min(quantum, step);
  }
  if (!std::isfinite(quantum)) return std::nullopt;
  const double tolerance = kRestQuanta * quantum;
  AxisModel nominal;
  nominal.motor_constant = std::max(full[0], 1e-9);
  nominal.viscous = std::max(full[1], 0.0);
  nominal.coulomb = std::max(full[2], 0.0);
  std::vector<std::pair<double, double>> brackets;
  std::size_t first = 0;
  while (first + 5 + kMotionSamples + 4 < n) {
    std::size_t last = first;
    while (last + 1 < n && std::abs(s.x[last + 1] - s.x[first]) <= tolerance) ++last;
    if (last - first < 4 || last + kMotionSamples + 1 >= n) {
      first = last + 1;
      continue;
    }
    double rest = 0.0;
    for (std::size_t k = first; k <= last; ++k) rest += s.x[k];
    rest /= static_cast<double>(last - first + 1);
    const double direction = s.x[last + kMotionSamples] > rest ? 1.0 : -1.0;
    if (std::abs(s.x[last + kMotionSamples] - rest) < 4.0 * tolerance) {  // no clear breakaway
      first = last + 1;
      continue;
    }
    // Breakaway instant b in [last - 3, last]: the axis rests at t_b and moves from there on.
    double best_error = std::numeric_limits<double>::infinity();
    std::size_t breakaway = last;
    for (std::size_t b = std::max(first + 1, last - 3); b <= last; ++b) {
      AxisState state;
      state.position = rest;
      state.load_position = rest;
      double error = 0.0;
      for (std::size_t k = b; k < last + kMotionSamples; ++k) {
        advance_axis(nominal, s.u[k], s.sample_time, 1, state);
        const double e = s.x[k + 1] - state.position;
        error += e * e;
      }
      for (std::size_t k = first; k <= b; ++k) error += (s.x[k] - rest) * (s.x[k] - rest);
      if (error < best_error) {
        best_error = error;
        breakaway = b;
      }
    }
    double lower = 0.0;  // the samples held at rest: direction * drive <= threshold
    for (std::size_t k = first + 1; k < breakaway; ++k) {
      lower = std::max(lower, direction * axis_drive_acceleration(nominal, s.u[k]));
    }
    const double upper = direction * axis_drive_acceleration(nominal, s.u[breakaway]);
    if (upper > lower) brackets.emplace_back(lower, upper);
    first = last + 1;
  }
  if (brackets.size() < 2) return std::nullopt;
  // The stretch covered by the most brackets (ends of the brackets are the candidates).
  std::vector<double> ends;
  for (const auto& [lo, hi] : brackets) {
    ends.push_back(lo);
    ends.push_back(hi);
  }
  std::sort(ends.begin(), ends.end());
  std::size_t best_count = 0;
  std::pair<double, double> best{0.0, 0.0};
  for (std::size_t i = 0; i + 1 < ends.size(); ++i) {
    const double middle = 0.5 * (ends[i] + ends[i + 1]);
    std::size_t count = 0;
    for (const auto& [lo, hi] : brackets) count += (lo < middle && middle <= hi) ? 1 : 0;
    if (count > best_count) {
      best_count = count;
      best = {ends[i], ends[i + 1]};
    } else if (count == best_count && count > 0 && ends[i] <= best.second) {
      best.second = ends[i + 1];  // contiguous stretch of the same cover
    }
  }
  if (best_count < 2) return std::nullopt;
  return best;
}

// ---------------------------------------------------------------------------------------------
// Pendulum.

constexpr std::size_t kPendulumBase = 3;  // L, damping, theta_zero

PendulumModel pendulum_model(const std::vector<double>& full, const std::string& cause, double gravity) {
  PendulumModel m;
  m.length = std::max(full[0], 1e-6);
  m.damping = std::max(full[1], 0.0);
  m.theta_zero = full[2];
  m.gravity = gravity;
  const double* p = full.data() + kPendulumBase;
  if (cause == "pendulum_viscous_damping") m.extra_viscous = std::max(p[0], -m.damping);
  if (cause == "pendulum_coulomb_damping") m.coulomb = std::max(p[0], 0.0);
  if (cause == "pendulum_quadratic_damping") m.quadratic = std::max(p[0], 0.0);
  if (cause == "cable_length_error") m.length_error = std::max(p[0], -0.9);
  if (cause == "encoder_offset") m.encoder_offset = p[0];
  return m;
}

struct PendulumSeries {
  std::vector<double> theta;
  std::vector<double> trolley_acceleration;
  double sample_time{0.0};
  double gravity{9.80665};
  int substeps{4};
  std::string cause;
};

Problem pendulum_problem(const std::shared_ptr<PendulumSeries>& s, const std::vector<double>& segment,
                         double holdout_fraction, const std::vector<double>& base) {
  Problem problem;
  const std::size_t n = s->theta.size();
  std::size_t first = 0;
  for (std::size_t k = 1; k <= n; ++k) {
    if (k == n || (!segment.empty() && segment[k] != segment[k - 1])) {
      Window w;
      w.first = first;
      w.count = k - first;
      w.train_count = static_cast<std::size_t>(std::floor((1.0 - holdout_fraction) * static_cast<double>(w.count)));
      if (w.count >= 10) problem.windows.push_back(w);
      first = k;
    }
  }
  problem.nuisance_size = 2;
  const double zero = base[2];
  problem.initial_nuisance = [s, zero](const Window& w, double* out) {
    const auto [a0, r0] = local_state(s->theta, w.first, w.first + w.count, s->sample_time);
    out[0] = a0 - zero;
    out[1] = r0;
  };
  problem.residual = [s](const std::vector<double>& full, const double* nuisance, const Window& w, std::size_t count,
                         double* out) {
    const PendulumModel model = pendulum_model(full, s->cause, s->gravity);
    PendulumState initial{nuisance[0], nuisance[1]};
    std::span<double> prediction(out, count);
    replay_pendulum(model, s->trolley_acceleration, s->sample_time, w.first, initial, s->substeps, prediction);
    for (std::size_t i = 0; i < count; ++i) out[i] = s->theta[w.first + i] - out[i];
  };
  return problem;
}

std::vector<Candidate> pendulum_candidates(double length, double gravity) {
  const double omega2 = gravity / length;
  std::vector<Candidate> list;
  list.push_back({"pendulum_viscous_damping",
                  {{"extra_viscous_damping", "1/s", 0.1, -1.0, 20.0, linspace(0.0, 0.6, 61)}}, ""});
  list.push_back({"pendulum_coulomb_damping",
                  {{"coulomb_damping", "rad/s^2", 0.005 * omega2, 0.0, 2.0 * omega2,
                    linspace(0.0002 * omega2, 0.012 * omega2, 60)}},
                  ""});
  list.push_back({"pendulum_quadratic_damping",
                  {{"quadratic_damping", "1/rad", 0.1, 0.0, 50.0, linspace(0.0, 1.0, 51)}}, ""});
  list.push_back({"cable_length_error", {{"length_error", "-", 0.05, -0.8, 2.0, linspace(-0.25, 0.25, 51)}}, ""});
  list.push_back({"encoder_offset", {{"encoder_offset", "rad", 0.02, -0.5, 0.5, linspace(-0.1, 0.1, 41)}}, ""});
  return list;
}

// Grid product of the candidate's grids.
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

}  // namespace

// ---------------------------------------------------------------------------------------------

const std::vector<std::string>& audit_catalog(AuditPlant plant) {
  static const std::vector<std::string> axis{"coulomb_friction_asymmetry", "viscous_friction_asymmetry", "stiction",
                                             "stribeck", "deadzone", "saturation", "backlash", "input_delay",
                                             "gain_error", "position_dependent_friction"};
  static const std::vector<std::string> pendulum{"pendulum_viscous_damping", "pendulum_coulomb_damping",
                                                 "pendulum_quadratic_damping", "cable_length_error", "encoder_offset"};
  return plant == AuditPlant::axis ? axis : pendulum;
}

const std::vector<std::string>& audit_parameter_names(AuditPlant plant) {
  static const std::vector<std::string> axis{"K_m", "b", "c"};
  static const std::vector<std::string> pendulum{"L", "damping", "theta_zero", "gravity"};
  return plant == AuditPlant::axis ? axis : pendulum;
}

void validate(const AuditOptions& options) {
  const auto& names = audit_parameter_names(options.plant);
  const std::string plant = options.plant == AuditPlant::axis ? "axis" : "pendulum";
  for (const auto& [name, value] : options.parameters) {
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      throw common::ConfigError("param: unknown parameter '" + name + "' for model " + plant + " (valid: " +
                                join(names) + ")");
    }
    common::require_finite("param " + name, value);
  }
  const std::vector<std::string> required =
      options.plant == AuditPlant::axis ? std::vector<std::string>{"K_m", "b", "c"} : std::vector<std::string>{"L"};
  for (const auto& name : required) {
    if (!options.parameters.contains(name)) {
      throw common::ConfigError("param: nominal parameter '" + name + "' of model " + plant +
                                " is missing (give --param " + name + "=VALUE)");
    }
  }
  if (options.plant == AuditPlant::axis) {
    common::require_greater("param K_m", options.parameters.at("K_m"), 0.0);
    common::require_at_least("param b", options.parameters.at("b"), 0.0);
    common::require_at_least("param c", options.parameters.at("c"), 0.0);
  } else {
    common::require_greater("param L", options.parameters.at("L"), 0.0);
    common::require_at_least("param damping", parameter(options.parameters, "damping", 0.0), 0.0);
    common::require_greater("param gravity", parameter(options.parameters, "gravity", 9.80665), 0.0);
  }
  const auto& catalog = audit_catalog(options.plant);
  for (const auto& cause : options.causes) {
    if (std::find(catalog.begin(), catalog.end(), cause) == catalog.end()) {
      throw common::ConfigError("cause: '" + cause + "' is not in the " + plant + " catalog (valid: " +
                                join(catalog) + ")");
    }
  }
  if (options.plant == AuditPlant::pendulum && options.channel == AuditChannel::effort) {
    throw common::ConfigError("channel: effort is defined for the axis model only");
  }
  common::require_in_range("holdout_fraction", options.holdout_fraction, 0.1, 0.6);
  common::require_greater("window_duration", options.window_duration, 0.0);
  common::require_at_least("dead_band", options.dead_band, 0.0);
  common::require_at_least("bic_threshold", options.bic_threshold, 0.0);
  common::require_at_least("min_holdout_gain_percent", options.min_holdout_gain_percent, 0.0);
  if (options.substeps < 1) throw common::ConfigError("substeps = " + std::to_string(options.substeps) + " must be >= 1");
}

AuditData read_audit_data(const std::filesystem::path& file, AuditPlant plant, const std::string& columns,
                          double max_rate, std::size_t minimum_samples) {
  CsvReadOptions read;
  read.mapping = parse_column_mapping(columns);
  const std::vector<std::string> allowed = plant == AuditPlant::axis
                                               ? std::vector<std::string>{"t", "u", "x"}
                                               : std::vector<std::string>{"t", "theta", "x", "segment"};
  for (const auto& [canonical, file_column] : read.mapping.entries) {
    if (std::find(allowed.begin(), allowed.end(), canonical) == allowed.end()) {
      throw common::ConfigError("columns: unknown canonical name '" + canonical + "' (expected " + join(allowed) + ")");
    }
  }
  read.required_columns = plant == AuditPlant::axis ? std::vector<std::string>{"t", "u", "x"}
                                                    : std::vector<std::string>{"t", "theta"};
  read.time_column = "t";
  read.minimum_samples = minimum_samples;
  const TimeSeries series = read_time_series_csv(file, read);
  const auto& t = series.column("t");
  const std::size_t n = t.size();
  const double dt = (t.back() - t.front()) / static_cast<double>(n - 1);
  for (std::size_t k = 1; k < n; ++k) {
    const double step = t[k] - t[k - 1];
    if (std::abs(step - dt) > 0.01 * dt) {
      // Data rows start after the comment lines and the header; the reader's rows are 1-based file
      // lines, which we do not have here, so name the sample and the time.
      throw DataError(file.string() + ": column '" + read.mapping.file_column("t") + "': sampling not uniform at data row " +
                      std::to_string(k + 1) + " (t = " + common::format_value(t[k]) + " s, step " +
                      common::format_value(step) + " s, mean step " + common::format_value(dt) + " s, tolerance 1 %)");
    }
  }
  std::size_t factor = 1;
  if (max_rate > 0.0 && 1.0 / dt > max_rate) factor = static_cast<std::size_t>(std::ceil((1.0 / dt) / max_rate));
  AuditData data;
  data.source = file.string();
  const auto take = [&](const std::vector<double>& column) {
    std::vector<double> out;
    for (std::size_t k = 0; k < n; k += factor) out.push_back(column[k]);
    return out;
  };
  data.time = take(t);
  if (plant == AuditPlant::axis) {
    data.input = take(series.column("u"));
    data.output = take(series.column("x"));
  } else {
    data.output = take(series.column("theta"));
    if (series.has_column("x") && (read.mapping.file_column("x") != "x" || series.has_column("x"))) {
      bool mapped = false;
      for (const auto& e : read.mapping.entries) mapped |= e.first == "x";
      if (mapped || series.has_column("x")) data.trolley_position = take(series.column("x"));
    }
    if (series.has_column("segment")) data.segment = take(series.column("segment"));
  }
  if (data.time.size() < minimum_samples) {
    throw DataError(file.string() + ": only " + std::to_string(data.time.size()) + " samples after decimation by " +
                    std::to_string(factor) + " (minimum " + std::to_string(minimum_samples) + ")");
  }
  return data;
}

AuditReport run_audit(const AuditData& data, const AuditOptions& options) {
  validate(options);
  const std::size_t n = data.time.size();
  if (n < 50) throw DataError(data.source + ": too few samples: " + std::to_string(n) + " (minimum 50)");
  if (data.output.size() != n || (options.plant == AuditPlant::axis && data.input.size() != n)) {
    throw DataError(data.source + ": columns of different lengths");
  }
  const double sample_time = (data.time.back() - data.time.front()) / static_cast<double>(n - 1);
  const bool axis = options.plant == AuditPlant::axis;
  const bool effort = axis && options.channel == AuditChannel::effort;

  AuditReport report;
  report.plant = axis ? "axis" : "pendulum";
  report.channel = axis ? (effort ? "effort" : "position") : "angle";
  report.unit = axis ? (effort ? "V" : "m") : "rad";
  report.sample_time = sample_time;
  report.samples = n;

  // Base parameters and what is free in the nominal fit.
  std::vector<double> base;
  std::vector<ParameterSpec> base_specs;
  bool theta_zero_known = true;
  double gravity = 9.80665;
  std::vector<Candidate> candidates;
  std::shared_ptr<AxisSeries> axis_series;
  std::shared_ptr<PendulumSeries> pendulum_series;
  if (axis) {
    const double k_m = options.parameters.at("K_m");
    const double b = options.parameters.at("b");
    const double c = options.parameters.at("c");
    base = {k_m, b, c};
    base_specs = {{"K_m", "m/s^2/V", k_m, 1e-3 * k_m, 100 * k_m, {}},
                  {"b", "1/s", std::max(b, 0.1), 0.0, 100 * std::max(b, 0.1), {}},
                  {"c", "m/s^2", std::max(c, 0.05 * k_m), 0.0, 100 * std::max(c, 0.05 * k_m), {}}};
    candidates = axis_candidates(data, k_m, b, c, sample_time);
    axis_series = std::make_shared<AxisSeries>();
    axis_series->x = data.output;
    axis_series->u = data.input;
    axis_series->sample_time = sample_time;
    axis_series->dead_band = options.dead_band;
  } else {
    gravity = parameter(options.parameters, "gravity", 9.80665);
    const double length = options.parameters.at("L");
    const double damping = parameter(options.parameters, "damping", 0.0);
    theta_zero_known = options.parameters.contains("theta_zero");
    double zero = parameter(options.parameters, "theta_zero", 0.0);
    if (!theta_zero_known) {  // estimate: the median of the measured angle
      std::vector<double> sorted = data.output;
      std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
      zero = sorted[n / 2];
    }
    base = {length, damping, zero};
    base_specs = {{"L", "m", length, 1e-3 * length, 100 * length, {}},
                  {"damping", "1/s", std::max(damping, 0.05), 0.0, 100.0, {}},
                  {"theta_zero", "rad", 0.02, zero - 1.0, zero + 1.0, {}}};
    candidates = pendulum_candidates(length, gravity);
    pendulum_series = std::make_shared<PendulumSeries>();
    pendulum_series->theta = data.output;
    pendulum_series->sample_time = sample_time;
    pendulum_series->gravity = gravity;
    pendulum_series->substeps = options.substeps;
    if (!data.trolley_position.empty()) {
      auto& acc = pendulum_series->trolley_acceleration;
      acc.assign(n, 0.0);
      for (std::size_t k = 1; k + 1 < n; ++k) {
        acc[k] = (data.trolley_position[k + 1] - 2.0 * data.trolley_position[k] + data.trolley_position[k - 1]) /
                 (sample_time * sample_time);
      }
    }
  }
  const std::size_t base_count = base.size();
  FreeSet nominal_free;
  const auto add_free = [&](FreeSet& set, std::size_t index, const ParameterSpec& spec) {
    set.index.push_back(index);
    set.scale.push_back(spec.scale);
    set.lower.push_back(spec.lower);
    set.upper.push_back(spec.upper);
  };
  if (options.calibrate) {
    const std::size_t calibrated = axis ? 3 : 2;
    for (std::size_t i = 0; i < calibrated; ++i) add_free(nominal_free, i, base_specs[i]);
  }
  if (!axis && !theta_zero_known) add_free(nominal_free, 2, base_specs[2]);

  // Exclusions.
  for (auto& candidate : candidates) {
    const auto& allowed = options.causes;
    if (!allowed.empty() && std::find(allowed.begin(), allowed.end(), candidate.name) == allowed.end()) {
      candidate.note = "not requested (--cause)";
    } else if (options.calibrate && candidate.name == "gain_error") {
      candidate.note = "absorbed by the calibrated K_m";
    } else if (options.calibrate &&
               (candidate.name == "cable_length_error" || candidate.name == "pendulum_viscous_damping")) {
      candidate.note = "absorbed by the calibrated nominal parameters";
    } else if (!axis && !theta_zero_known && candidate.name == "encoder_offset") {
      candidate.note = "theta_zero is estimated (give --param theta_zero=VALUE to test an offset)";
    } else if (effort && candidate.name == "backlash") {
      candidate.note = "backlash is not defined in the effort channel";
    }
  }

  // Problem factory for a cause ("" = nominal).
  const auto make_problem = [&](const std::string& cause) {
    if (axis) {
      auto s = std::make_shared<AxisSeries>(*axis_series);
      s->cause = cause;
      s->substeps = axis_needs_substeps(cause) ? options.substeps : 1;
      return effort ? axis_effort_problem(s, options.holdout_fraction)
                    : axis_position_problem(s, options.window_duration, options.holdout_fraction);
    }
    auto s = std::make_shared<PendulumSeries>(*pendulum_series);
    s->cause = cause;
    return pendulum_problem(s, data.segment, options.holdout_fraction, base);
  };
  const auto initial_nuisance = [](const Problem& problem) {
    std::vector<std::vector<double>> nuisance(problem.windows.size(), std::vector<double>(problem.nuisance_size));
    if (problem.nuisance_size > 0) {
      for (std::size_t w = 0; w < problem.windows.size(); ++w) problem.initial_nuisance(problem.windows[w], nuisance[w].data());
    }
    return nuisance;
  };

  // Nominal.
  const Problem nominal_problem = make_problem("");
  std::size_t train_windows = 0;
  for (const auto& w : nominal_problem.windows) train_windows += w.train_count >= 3 ? 1 : 0;
  if (train_windows == 0) throw DataError(data.source + ": too few samples for a training window");
  const Fit nominal = fit_problem(nominal_problem, base, nominal_free, initial_nuisance(nominal_problem), n);
  for (std::size_t i = 0; i < base_count; ++i) {
    report.nominal.push_back({base_specs[i].name, base_specs[i].unit, nominal.full[i], 0.0});
  }
  for (std::size_t j = 0; j < nominal_free.index.size(); ++j) {
    report.nominal[nominal_free.index[j]].standard_error = nominal.standard_errors[j];
  }
  const std::vector<double>& summary_input = axis ? data.input : std::vector<double>{};
  report.before = summarize(nominal, summary_input, options.max_lag);
  const double bic_nominal = bic(nominal.train_rss, nominal.train_n, 0);
  const double holdout_nominal = report.before.holdout_rms;

  // Candidates.
  std::vector<Fit> fits(candidates.size());
  std::vector<char> fitted(candidates.size(), 0);
  for (std::size_t c = 0; c < candidates.size(); ++c) {
    const Candidate& candidate = candidates[c];
    CandidateReport entry;
    entry.name = candidate.name;
    entry.note = candidate.note;
    if (!candidate.note.empty()) {
      report.candidates.push_back(entry);
      continue;
    }
    const Problem problem = make_problem(candidate.name);
    std::vector<double> full = nominal.full;
    full.resize(base_count + candidate.parameters.size(), 0.0);
    // Coarse grid (nuisance and base from the nominal fit), plus the linear estimate.
    auto points = grid_points(candidate);
    if (axis) {
      if (const auto linear = axis_linear_estimate(*axis_series, nominal.full, candidate.name)) {
        points.push_back({std::clamp(*linear, candidate.parameters[0].lower, candidate.parameters[0].upper)});
      }
    }
    double best_rss = std::numeric_limits<double>::infinity();
    std::vector<double> best_point;
    const auto data_nuisance = initial_nuisance(problem);
    std::vector<std::pair<double, std::vector<double>>> scored;  // (rss, point), for extra starts
    for (const auto& point : points) {
      std::vector<double> trial = full;
      std::copy(point.begin(), point.end(), trial.begin() + static_cast<std::ptrdiff_t>(base_count));
      const double rss = train_rss_fixed(problem, trial, data_nuisance);
      scored.emplace_back(rss, point);
      if (rss < best_rss) {
        best_rss = rss;
        best_point = point;
      }
    }
    if (candidate.parameters.size() == 1 && points.size() > 2) {
      // Piecewise-constant costs (stick thresholds, dead zones): take the middle of the flat
      // stretch of the grid around the optimum, where numeric derivatives are zero.
      const auto& grid = candidate.parameters[0].grid;
      const auto at = std::find(grid.begin(), grid.end(), best_point[0]);
      if (at != grid.end()) {
        auto lo = at;
        auto hi = at;
        const auto same = [&](double value) {
          std::vector<double> trial = full;
          trial[base_count] = value;
          return train_rss_fixed(problem, trial, data_nuisance) <= best_rss * (1.0 + 1e-9);
        };
        while (lo != grid.begin() && same(*(lo - 1))) --lo;
        while (hi + 1 != grid.end() && same(*(hi + 1))) ++hi;
        best_point[0] = 0.5 * (*lo + *hi);
      }
    }
    std::copy(best_point.begin(), best_point.end(), full.begin() + static_cast<std::ptrdiff_t>(base_count));
    // Signature: what the candidate changes (at its grid optimum) against the nominal residual.
    {
      std::vector<double> signature;
      std::vector<double> residual;
      for (std::size_t w = 0; w < problem.windows.size(); ++w) {
        const Window& window = problem.windows[w];
        if (window.train_count == 0) continue;
        std::vector<double> with(window.count);
        std::vector<double> without(window.count);
        const double* nz = problem.nuisance_size ? data_nuisance[w].data() : nullptr;
        problem.residual(full, nz, window, window.train_count, with.data());
        problem.residual(nominal.full.size() == full.size() ? nominal.full : [&] {
          auto f = full;
          for (std::size_t i = base_count; i < f.size(); ++i) f[i] = 0.0;
          return f;
        }(), nz, window, window.train_count, without.data());
        for (std::size_t i = 0; i < window.train_count; ++i) {
          if (!std::isfinite(with[i]) || !std::isfinite(without[i])) continue;
          signature.push_back(without[i] - with[i]);
          residual.push_back(without[i]);
        }
      }
      entry.signature_correlation = correlation(residual, signature);
    }
    FreeSet free = nominal_free;
    for (std::size_t i = 0; i < candidate.parameters.size(); ++i) add_free(free, base_count + i, candidate.parameters[i]);
    auto start_nuisance = nominal.nuisance;
    if (problem.nuisance_size != nominal_problem.nuisance_size) {
      for (std::size_t w = 0; w < start_nuisance.size(); ++w) {
        start_nuisance[w].resize(problem.nuisance_size);
        for (std::size_t i = nominal_problem.nuisance_size; i < problem.nuisance_size; ++i) {
          start_nuisance[w][i] = data_nuisance[w][i];
        }
      }
    }
    fits[c] = fit_problem(problem, full, free, start_nuisance, n);
    if (candidate.parameters.size() > 1) {
      // Several parameters (stribeck: level and v_s trade off along a valley): the grid scores use
      // unfitted initial states, so also fit from other starts and keep the lowest training RSS.
      // Extra starts: the best grid points at the second parameter's grid neighbours (below and
      // above) of the grid optimum.
      std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      const auto& second = candidate.parameters[1].grid;
      const auto at = std::find(second.begin(), second.end(), best_point[1]);
      std::vector<double> neighbours;
      if (at != second.end() && at != second.begin()) neighbours.push_back(*(at - 1));
      if (at != second.end() && at + 1 != second.end()) neighbours.push_back(*(at + 1));
      for (const auto& [rss, point] : scored) {
        const auto it = std::find(neighbours.begin(), neighbours.end(), point[1]);
        if (it == neighbours.end()) continue;
        neighbours.erase(it);
        std::vector<double> start = full;
        std::copy(point.begin(), point.end(), start.begin() + static_cast<std::ptrdiff_t>(base_count));
        Fit other = fit_problem(problem, start, free, start_nuisance, n);
        if (other.train_rss < fits[c].train_rss) fits[c] = std::move(other);
      }
    }
    if (axis && candidate.name == "stiction") {
      // The stick threshold from the breakaway brackets (axis_breakaway_bracket), the rest of the
      // model and the initial states refitted with it held.
      if (const auto bracket = axis_breakaway_bracket(*axis_series, fits[c].full)) {
        std::vector<double> held = fits[c].full;
        held[base_count] = std::max(0.5 * (bracket->first + bracket->second) - held[2], 0.0);
        const double half_width = 0.5 * (bracket->second - bracket->first);
        Fit refit = fit_problem(problem, held, nominal_free, fits[c].nuisance, n);
        refit.standard_errors.push_back(half_width / std::sqrt(3.0));  // uniform within the bracket
        fits[c] = std::move(refit);
      }
    }
    fitted[c] = 1;
    const Fit& fit = fits[c];
    for (std::size_t i = 0; i < candidate.parameters.size(); ++i) {
      entry.parameters.push_back({candidate.parameters[i].name, candidate.parameters[i].unit,
                                  fit.full[base_count + i], fit.standard_errors[nominal_free.index.size() + i]});
    }
    entry.fitted = true;
    entry.delta_bic = bic(fit.train_rss, fit.train_n, candidate.parameters.size()) - bic_nominal;
    entry.train_rms = fit.train_n ? std::sqrt(fit.train_rss / static_cast<double>(fit.train_n)) : 0.0;
    entry.holdout_rms = fit.holdout_n ? std::sqrt(fit.holdout_rss / static_cast<double>(fit.holdout_n)) : 0.0;
    entry.holdout_gain_percent = holdout_nominal > 0.0 ? 100.0 * (holdout_nominal - entry.holdout_rms) / holdout_nominal : 0.0;
    entry.qualifies = entry.delta_bic < -options.bic_threshold &&
                      entry.holdout_gain_percent >= options.min_holdout_gain_percent;
    report.candidates.push_back(entry);
  }

  // Selection.
  std::ptrdiff_t chosen = -1;
  const bool white = report.before.whiteness.lags > 0 && report.before.whiteness.p_value >= 0.05;
  for (std::size_t c = 0; c < report.candidates.size(); ++c) {
    const auto& entry = report.candidates[c];
    if (!entry.qualifies) continue;
    if (chosen < 0 || entry.delta_bic < report.candidates[static_cast<std::size_t>(chosen)].delta_bic) {
      chosen = static_cast<std::ptrdiff_t>(c);
    }
  }
  if (white) {
    report.stop_reason = "the nominal residual is white (Ljung-Box p = " +
                         common::format_value(report.before.whiteness.p_value) + " >= 0.05)";
    chosen = -1;
  } else if (chosen < 0) {
    report.stop_reason = "no candidate earns its parameters (delta-BIC < -" + common::format_value(options.bic_threshold) +
                         " and held-out gain >= " + common::format_value(options.min_holdout_gain_percent) + " %)";
  }
  const Fit* selected = &nominal;
  if (chosen >= 0) {
    const auto& entry = report.candidates[static_cast<std::size_t>(chosen)];
    // candidates and report.candidates are in the same order here (ranking comes later).
    selected = &fits[static_cast<std::size_t>(chosen)];
    report.cause = entry.name;
    report.parameters = entry.parameters;
    for (std::size_t i = 0; i < base_count; ++i) {
      report.extended_nominal.push_back({base_specs[i].name, base_specs[i].unit, selected->full[i], 0.0});
    }
    for (std::size_t j = 0; j < nominal_free.index.size(); ++j) {
      report.extended_nominal[nominal_free.index[j]].standard_error = selected->standard_errors[j];
    }
    report.stop_reason = "selected " + entry.name + " (lowest delta-BIC among qualifying candidates)";
    report.after = summarize(*selected, summary_input, options.max_lag);
    if (report.after.whiteness.p_value >= 0.05) report.stop_reason += "; the residual is now white";
    else report.stop_reason += "; the residual is still not white (single-cause report)";
  } else {
    report.after = report.before;
  }
  report.holdout_before = holdout_nominal;
  report.holdout_after = report.after.holdout_rms;
  report.holdout_percent = holdout_nominal > 0.0 ? 100.0 * (holdout_nominal - report.holdout_after) / holdout_nominal : 0.0;

  // Effort channel as a second opinion for the axis position audit.
  report.effort_holdout_before = kNaN;
  report.effort_holdout_after = kNaN;
  if (axis) {
    const auto effort_rms = [&](const std::vector<double>& full, const std::string& cause) {
      auto s = std::make_shared<AxisSeries>(*axis_series);
      s->cause = cause;
      const Problem p = axis_effort_problem(s, options.holdout_fraction);
      const Window& w = p.windows[1];
      std::vector<double> r(w.count);
      p.residual(full, nullptr, w, w.count, r.data());
      double sum = 0.0;
      std::size_t count = 0;
      for (const double v : r) {
        if (!std::isfinite(v)) continue;
        sum += v * v;
        ++count;
      }
      return count ? std::sqrt(sum / static_cast<double>(count)) : kNaN;
    };
    report.effort_holdout_before = effort_rms(nominal.full, "");
    report.effort_holdout_after = report.cause == "none" ? report.effort_holdout_before
                                  : report.cause == "backlash" ? kNaN
                                                              : effort_rms(selected->full, report.cause);
  }

  // Series.
  report.time = data.time;
  report.measured = effort ? std::vector<double>(n, kNaN) : data.output;
  report.nominal_prediction.assign(n, kNaN);
  report.extended_prediction.assign(n, kNaN);
  report.holdout = nominal.holdout_flag;
  for (std::size_t k = 0; k < n; ++k) {
    const double measured = effort ? (k >= 1 ? 0.5 * (data.input[k - 1] + data.input[k]) : data.input[0]) : data.output[k];
    report.measured[k] = measured;
    if (std::isfinite(nominal.residual_per_sample[k])) report.nominal_prediction[k] = measured - nominal.residual_per_sample[k];
    if (std::isfinite(selected->residual_per_sample[k])) report.extended_prediction[k] = measured - selected->residual_per_sample[k];
  }

  // Rank: fitted candidates by delta-BIC, then the skipped ones.
  std::stable_sort(report.candidates.begin(), report.candidates.end(), [](const auto& a, const auto& b) {
    if (a.fitted != b.fitted) return a.fitted;
    return a.fitted && a.delta_bic < b.delta_bic;
  });
  return report;
}

void write_audit_report(const AuditReport& report, const std::filesystem::path& directory,
                        const std::string& command_line) {
  std::error_code error;
  std::filesystem::create_directories(directory, error);
  if (error) throw DataError(directory.string() + ": cannot create the output directory: " + error.message());
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  const auto parameters_json = [&](const std::vector<FittedParameter>& list) {
    nlohmann::json out = nlohmann::json::object();
    for (const auto& p : list) {
      out[p.name] = {{"value", number(p.value)}, {"standard_error", number(p.standard_error)}, {"unit", p.unit}};
    }
    return out;
  };
  const auto summary_json = [&](const ResidualSummary& s) {
    nlohmann::json a = nlohmann::json::array();
    for (const double r : s.whiteness.autocorrelation) a.push_back(number(r));
    return nlohmann::json{{"train_rms", number(s.train_rms)},
                          {"holdout_rms", number(s.holdout_rms)},
                          {"ljung_box_q", number(s.whiteness.ljung_box_statistic)},
                          {"ljung_box_p", number(s.whiteness.p_value)},
                          {"lags", s.whiteness.lags},
                          {"white", s.whiteness.lags > 0 && s.whiteness.p_value >= 0.05},
                          {"autocorrelation", a},
                          {"input_correlation", number(s.input_correlation)}};
  };
  nlohmann::json json;
  json["model"] = report.plant;
  json["channel"] = report.channel;
  json["cause"] = report.cause;
  json["stop_reason"] = report.stop_reason;
  json["parameters"] = parameters_json(report.parameters);
  json["gain"] = {{"metric", "holdout_rms_" + report.channel + " [" + report.unit + "]"},
                  {"before", number(report.holdout_before)},
                  {"after", number(report.holdout_after)},
                  {"percent", number(report.holdout_percent)}};
  json["nominal"] = parameters_json(report.nominal);
  if (!report.extended_nominal.empty()) json["nominal_refitted_with_cause"] = parameters_json(report.extended_nominal);
  json["residual_before"] = summary_json(report.before);
  json["residual_after"] = summary_json(report.after);
  if (report.plant == "axis") {
    json["effort_holdout_rms_V"] = {{"before", number(report.effort_holdout_before)},
                                    {"after", number(report.effort_holdout_after)}};
  }
  nlohmann::json list = nlohmann::json::array();
  int rank = 0;
  for (const auto& c : report.candidates) {
    nlohmann::json entry{{"name", c.name}, {"fitted", c.fitted}};
    if (c.fitted) {
      entry["rank"] = ++rank;
      entry["delta_bic"] = number(c.delta_bic);
      entry["holdout_rms"] = number(c.holdout_rms);
      entry["holdout_gain_percent"] = number(c.holdout_gain_percent);
      entry["train_rms"] = number(c.train_rms);
      entry["signature_correlation"] = number(c.signature_correlation);
      entry["qualifies"] = c.qualifies;
      entry["parameters"] = parameters_json(c.parameters);
    } else {
      entry["note"] = c.note;
    }
    list.push_back(entry);
  }
  json["candidates"] = list;
  json["sample_time"] = report.sample_time;
  json["samples"] = report.samples;
  json["command"] = command_line;
  {
    std::ofstream out(directory / "report.json");
    out << json.dump(2) << '\n';
    if (!out) throw DataError((directory / "report.json").string() + ": write failed");
  }
  {
    std::ofstream md(directory / "report.md");
    md << "# Model audit: " << report.plant << "\n\n";
    md << "Command: `" << command_line << "`\n\n";
    md << "**Cause: `" << report.cause << "`** (" << report.stop_reason << ")\n\n";
    if (!report.parameters.empty()) {
      md << "| parameter | value | std. error | unit |\n|---|---|---|---|\n";
      for (const auto& p : report.parameters) {
        md << "| " << p.name << " | " << common::format_value(p.value) << " | " << common::format_value(p.standard_error)
           << " | " << p.unit << " |\n";
      }
      md << "\n";
    }
    md << "Held-out RMS (" << report.channel << ", " << report.unit << "): " << common::format_value(report.holdout_before)
       << " -> " << common::format_value(report.holdout_after) << " (" << common::format_value(report.holdout_percent)
       << " %)\n\n";
    md << "Nominal:";
    for (const auto& p : report.nominal) md << " " << p.name << " = " << common::format_value(p.value) << " " << p.unit << ";";
    md << "\n\nResidual before: Ljung-Box p = " << common::format_value(report.before.whiteness.p_value)
       << ", after: p = " << common::format_value(report.after.whiteness.p_value) << "\n\n";
    md << "| rank | candidate | delta-BIC | held-out RMS | gain % | signature corr. | parameters |\n|---|---|---|---|---|---|---|\n";
    int r = 0;
    for (const auto& c : report.candidates) {
      if (!c.fitted) {
        md << "| - | " << c.name << " | skipped: " << c.note << " | | | | |\n";
        continue;
      }
      md << "| " << ++r << " | " << c.name << " | " << common::format_value(std::round(c.delta_bic * 10) / 10) << " | "
         << common::format_value(c.holdout_rms) << " | " << common::format_value(std::round(c.holdout_gain_percent * 10) / 10)
         << " | " << common::format_value(std::round(c.signature_correlation * 100) / 100) << " |";
      for (const auto& p : c.parameters) md << " " << p.name << " = " << common::format_value(p.value);
      md << " |\n";
    }
  }
  {
    std::ofstream csv(directory / "series.csv");
    write_time_series_csv(csv, {"model audit series: " + report.plant + ", channel " + report.channel + " [" + report.unit + "]"},
                          {"t", "measured", "nominal", "extended", "holdout"},
                          {report.time, report.measured, report.nominal_prediction, report.extended_prediction, report.holdout});
  }
}

}  // namespace crane::model_audit
