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
#include "crane/model_audit/crane_swing.hpp"
#include "crane/model_audit/zero_phase_filter.hpp"

namespace crane::model_audit {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kTrolleyPrefix = "trolley_";  // crane catalog names of the trolley axis entries
constexpr const char* kSlewPrefix = "slew_";
constexpr double kRestartQuanta = 2.0;  // every_grid_start: restart above this training RMS [quanta]
constexpr double kSwingWindow = 5.0;  // [s] shortest replay window of the crane swing channel
constexpr double kSwingCutoff = 5.0;  // [Hz] low-pass of the swing angles in the drives' coupling (swing ~0.5 Hz)

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

struct AxisSeries {
  std::vector<double> x;
  std::vector<double> u;
  double sample_time{0.0};
  int substeps{1};
  std::string cause;
  double dead_band{0.0};
  AxisModel nominal;  // nominal asymmetries and stiction (catalog entries add to them)
  // Crane drive axis (empty for a lone axis): the axis row I a + C = I_drive (drive - friction) with
  // I = inertia + dm inertia_per_mass and C = force + dm force_per_mass at t_k (dm = the
  // payload_mass_error parameter [kg]); see AuditData.
  std::vector<double> inertia;
  std::vector<double> inertia_per_mass;
  std::vector<double> force;
  std::vector<double> force_per_mass;
  double drive_inertia{0.0};
};

AxisModel axis_model(const AxisSeries& s, const std::vector<double>& full) {
  const std::string& cause = s.cause;
  AxisModel m = s.nominal;
  m.motor_constant = std::max(full[0], 1e-9);
  m.viscous = std::max(full[1], 0.0);
  m.coulomb = std::max(full[2], 0.0);
  const double* p = full.data() + kAxisBase;
  if (cause == "coulomb_friction_asymmetry") m.coulomb_asymmetry += p[0];
  if (cause == "viscous_friction_asymmetry") m.viscous_asymmetry += p[0];
  if (cause == "stiction") m.stiction += std::max(p[0], 0.0);
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
  if (!data.coupling_inertia.empty()) {  // a crane drive axis
    const double m = std::max(data.load_mass, 0.1);
    list.push_back({"payload_mass_error",
                    {{"load_mass_error", "kg", 0.2 * m, -0.95 * data.load_mass, 5.0 * m, linspace(-0.6 * m, 0.6 * m, 49)}},
                    ""});
  }
  return list;
}

// Coupling of a crane drive axis for `full` (payload_mass_error shifts the load mass): the row
// inertia I and force C at t_k, and, held over [t_k, t_k+1) (means of t_k and t_k+1), the inertia
// ratio I_drive / I and the external acceleration -C / I of the replay. Empty for a lone axis.
struct AxisCoupling {
  std::vector<double> inertia;  // [kg] or [kg m^2]
  std::vector<double> force;    // [N] or [N m]
  std::vector<double> ratio;    // [-]
  std::vector<double> external; // [m/s^2] or [rad/s^2]
};

AxisCoupling axis_coupling(const AxisSeries& s, const std::vector<double>& full) {
  AxisCoupling c;
  if (s.inertia.empty()) return c;
  const double dm = s.cause == "payload_mass_error" ? full[kAxisBase] : 0.0;
  const std::size_t n = s.inertia.size();
  c.inertia.resize(n);
  c.force.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    c.inertia[k] = std::max(s.inertia[k] + dm * s.inertia_per_mass[k], 1e-9);
    c.force[k] = s.force[k] + dm * s.force_per_mass[k];
  }
  c.ratio.resize(n);
  c.external.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t next = std::min(k + 1, n - 1);
    const double inertia = 0.5 * (c.inertia[k] + c.inertia[next]);
    c.ratio[k] = s.drive_inertia / inertia;
    c.external[k] = -0.5 * (c.force[k] + c.force[next]) / inertia;
  }
  return c;
}

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
    const AxisModel model = axis_model(*s, full);
    const AxisCoupling coupling = axis_coupling(*s, full);
    AxisState initial;
    initial.load_position = nuisance[0];
    initial.velocity = nuisance[1];
    const double sign = s->cause == "backlash" ? std::clamp(nuisance[2], -1.0, 1.0) : 0.0;
    initial.position = nuisance[0] + 0.5 * model.backlash * sign;
    std::span<double> prediction(out, count);
    replay_axis(model, s->u, s->sample_time, w.first, initial, s->substeps, prediction, coupling.external,
                coupling.ratio);
    for (std::size_t i = 0; i < count; ++i) out[i] = s->x[w.first + i] - out[i];
  };
  return problem;
}

// Effort residual [V] of sample k (1 <= k <= n - 2), NaN when the stencil mixes regimes.
double axis_effort_residual(const AxisSeries& s, const AxisModel& m, const AxisCoupling& coupling, std::size_t k) {
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
  // What the motion needs from the drive besides friction: a, or (I a + C) / I_drive on a crane.
  const double needed = coupling.inertia.empty() ? a : (coupling.inertia[k] * a + coupling.force[k]) / s.drive_inertia;
  const double position_term = m.position_friction * s.x[k];
  const double c_plus = std::max(0.0, m.coulomb + m.coulomb_asymmetry + position_term);
  const double c_minus = std::max(0.0, m.coulomb - m.coulomb_asymmetry + position_term);
  const double k_eff = m.motor_constant;
  if (vm > s.dead_band && vp > s.dead_band) {
    const double friction = std::max(0.0, m.viscous + m.viscous_asymmetry) * v + c_plus +
                            m.stribeck_level * std::exp(-std::pow(v / m.stribeck_velocity, 2));
    return (drive - needed - friction) / k_eff;
  }
  if (vm < -s.dead_band && vp < -s.dead_band) {
    const double friction = std::max(0.0, m.viscous - m.viscous_asymmetry) * v - c_minus -
                            m.stribeck_level * std::exp(-std::pow(v / m.stribeck_velocity, 2));
    return (drive - needed - friction) / k_eff;
  }
  if (std::abs(vm) <= s.dead_band && std::abs(vp) <= s.dead_band) {
    const double net = drive - needed - m.viscous * v;
    const double extra = m.stribeck_level + m.stiction;
    return (net - std::clamp(net, -(c_minus + extra - m.stiction_asymmetry), c_plus + extra + m.stiction_asymmetry)) /
           k_eff;
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
    const AxisModel model = axis_model(*s, full);
    const AxisCoupling coupling = axis_coupling(*s, full);
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t k = w.first + i;
      out[i] = (k >= 1 && k + 2 <= s->x.size()) ? axis_effort_residual(*s, model, coupling, k) : kNaN;
    }
  };
  return problem;
}

// Linear least squares in the effort domain for the candidates linear in their parameter:
// K_m u - a - b v - db |v| - c s - dc = phi * theta on moving samples (db, dc nominal; on a crane
// axis (I a + C) / I_drive instead of a; Eigen column-pivoted QR).
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
    const double needed = s.inertia.empty() ? a : (s.inertia[k] * a + s.force[k]) / s.drive_inertia;
    y.push_back(base[0] * u - needed - base[1] * v - s.nominal.viscous_asymmetry * std::abs(v) - base[2] * sign -
                s.nominal.coulomb_asymmetry);
    if (cause == "coulomb_friction_asymmetry") phi.push_back(1.0);
    else if (cause == "payload_mass_error") phi.push_back((s.inertia_per_mass[k] * a + s.force_per_mass[k]) / s.drive_inertia);
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
// Each bracket is taken relative to the nominal breakaway level of its direction (c + s dc +
// Delta_s,nominal + s dDelta_s,nominal), so it brackets the added Delta_s also for an asymmetric
// nominal; on a crane axis the drive includes the coupling -C / I_drive and the motion from rest is
// simulated with the coupling of the replay.
// Returns the bracket [lower, upper] of the added Delta_s [m/s^2].
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
  AxisSeries base = s;
  base.cause.clear();
  const AxisModel nominal = axis_model(base, full);
  const AxisCoupling coupling = axis_coupling(base, full);
  const auto external = [&](std::size_t k) { return coupling.force.empty() ? 0.0 : -coupling.force[k] / s.drive_inertia; };
  const auto nominal_level = [&](double direction) {
    return std::max(0.0, nominal.coulomb + direction * nominal.coulomb_asymmetry) + nominal.stiction +
           direction * nominal.stiction_asymmetry;
  };
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
        if (coupling.ratio.empty()) {
          advance_axis(nominal, s.u[k], s.sample_time, 1, state);
        } else {
          advance_axis(scale_axis_inertia(nominal, coupling.ratio[k]), s.u[k], s.sample_time, 1, state,
                       coupling.external[k]);
        }
        const double e = s.x[k + 1] - state.position;
        error += e * e;
      }
      for (std::size_t k = first; k <= b; ++k) error += (s.x[k] - rest) * (s.x[k] - rest);
      if (error < best_error) {
        best_error = error;
        breakaway = b;
      }
    }
    const double level = nominal_level(direction);
    double lower = -level;  // the samples held at rest: direction * drive <= threshold
    for (std::size_t k = first + 1; k < breakaway; ++k) {
      lower = std::max(lower, direction * (axis_drive_acceleration(nominal, s.u[k]) + external(k)) - level);
    }
    const double upper = direction * (axis_drive_acceleration(nominal, s.u[breakaway]) + external(breakaway)) - level;
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

// ---------------------------------------------------------------------------------------------
// Crane swing channel (crane_swing.hpp): the swing replayed with the measured drive motion.

struct CraneSwingSeries {
  std::shared_ptr<const plant::TowerCraneModel> model;
  std::vector<DriveMotion> motion;
  std::vector<double> measured;  // interleaved phi, theta [rad] (2 per sample)
  double sample_time{0.0};
  int substeps{1};
  std::string cause;
};

SwingEffects swing_effects(const std::vector<double>& full, const std::string& cause) {
  SwingEffects e;
  if (full.empty()) return e;
  const double p = full[0];  // no base parameters: the candidate's parameter comes first
  if (cause == "pendulum_viscous_damping") e.extra_viscous = p;
  if (cause == "pendulum_coulomb_damping") e.coulomb = std::max(p, 0.0);
  if (cause == "pendulum_quadratic_damping") e.quadratic = std::max(p, 0.0);
  if (cause == "cable_length_error") e.length_error = std::max(p, -0.9);
  if (cause == "encoder_offset") e.encoder_offset = p;
  return e;
}

// Windows of window_duration [s] (in the interleaved index space: 2 residuals per sample, phi then
// theta); the windows in the last holdout_fraction are held out; nuisance: the initial swing state.
Problem crane_swing_problem(const std::shared_ptr<CraneSwingSeries>& s, double window_duration,
                            double holdout_fraction) {
  Problem problem;
  const std::size_t n = s->motion.size();
  const auto length = std::max<std::size_t>(static_cast<std::size_t>(std::llround(window_duration / s->sample_time)), 10);
  const auto holdout_start = static_cast<std::size_t>(std::floor((1.0 - holdout_fraction) * static_cast<double>(n)));
  for (std::size_t first = 0; first + 10 <= n; first += length) {
    const std::size_t count = std::min(length, n - first);
    problem.windows.push_back({2 * first, 2 * count, first >= holdout_start ? 0 : 2 * count});
  }
  problem.nuisance_size = 4;
  problem.initial_nuisance = [s](const Window& w, double* out) {
    std::vector<double> phi(w.count / 2);
    std::vector<double> theta(w.count / 2);
    for (std::size_t i = 0; i < phi.size(); ++i) {
      phi[i] = s->measured[w.first + 2 * i];
      theta[i] = s->measured[w.first + 2 * i + 1];
    }
    const auto [phi0, phi_rate] = local_state(phi, 0, phi.size(), s->sample_time);
    const auto [theta0, theta_rate] = local_state(theta, 0, theta.size(), s->sample_time);
    out[0] = phi0;
    out[1] = phi_rate;
    out[2] = theta0;
    out[3] = theta_rate;
  };
  problem.residual = [s](const std::vector<double>& full, const double* nuisance, const Window& w, std::size_t count,
                         double* out) {
    const SwingEffects effects = swing_effects(full, s->cause);
    const SwingState initial{nuisance[0] - effects.encoder_offset, nuisance[1], nuisance[2], nuisance[3]};
    replay_crane_swing(*s->model, effects, s->motion, s->sample_time, w.first / 2, count / 2, initial, s->substeps,
                       std::span<double>(out, count));
    for (std::size_t i = 0; i < count; ++i) out[i] = s->measured[w.first + i] - out[i];
  };
  return problem;
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
  static const std::vector<std::string> crane = [] {
    std::vector<std::string> list;
    for (const char* prefix : {kTrolleyPrefix, kSlewPrefix}) {
      for (const auto& name : axis) list.push_back(prefix + name);
    }
    list.insert(list.end(), pendulum.begin(), pendulum.end());
    list.push_back("payload_mass_error");
    return list;
  }();
  return plant == AuditPlant::axis ? axis : plant == AuditPlant::pendulum ? pendulum : crane;
}

const std::vector<std::string>& audit_parameter_names(AuditPlant plant) {
  static const std::vector<std::string> axis{"K_m", "b", "c", "coulomb_asymmetry", "viscous_asymmetry", "stiction",
                                             "stiction_asymmetry"};
  static const std::vector<std::string> pendulum{"L", "damping", "theta_zero", "gravity"};
  static const std::vector<std::string> crane = [] {
    std::vector<std::string> list;
    for (const auto& [name, value] : crane_audit_parameters(common::CraneParameters{})) list.push_back(name);
    return list;
  }();
  return plant == AuditPlant::axis ? axis : plant == AuditPlant::pendulum ? pendulum : crane;
}

namespace {

// One table for both directions of the crane parameter mapping.
struct CraneField {
  std::string name;
  double common::CraneParameters::*scalar;
  common::AxisFriction common::CraneParameters::*axis;
  double common::AxisFriction::*friction;
};

const std::vector<CraneField>& crane_fields() {
  using P = common::CraneParameters;
  using F = common::AxisFriction;
  static const std::vector<CraneField> fields = [] {
    std::vector<CraneField> list{{"gravity", &P::gravity, nullptr, nullptr},
                                 {"load_mass", &P::load_mass, nullptr, nullptr},
                                 {"trolley_drive_mass", &P::trolley_drive_mass, nullptr, nullptr},
                                 {"trolley_mass", &P::trolley_mass, nullptr, nullptr},
                                 {"jib_inertia", &P::jib_inertia, nullptr, nullptr},
                                 {"trolley_drive_gain", &P::trolley_drive_gain, nullptr, nullptr},
                                 {"slew_drive_gain", &P::slew_drive_gain, nullptr, nullptr}};
    const std::pair<const char*, double F::*> friction[] = {
        {"viscous_positive", &F::viscous_positive}, {"viscous_negative", &F::viscous_negative},
        {"coulomb_positive", &F::coulomb_positive}, {"coulomb_negative", &F::coulomb_negative},
        {"static_positive", &F::static_positive},   {"static_negative", &F::static_negative}};
    for (const auto& [axis, member] : {std::pair{"trolley_", &P::trolley_friction}, std::pair{"slew_", &P::slew_friction}}) {
      for (const auto& [name, field] : friction) {
        list.push_back({std::string(axis) + name, nullptr, member, field});
      }
    }
    return list;
  }();
  return fields;
}

}  // namespace

std::map<std::string, double> drive_axis_audit_parameters(const common::AxisFriction& f, double gain) {
  const double excess_plus = std::max(f.static_positive, f.coulomb_positive) - f.coulomb_positive;
  const double excess_minus = std::max(f.static_negative, f.coulomb_negative) - f.coulomb_negative;
  return {{"K_m", gain},
          {"b", gain * 0.5 * (f.viscous_positive + f.viscous_negative)},
          {"viscous_asymmetry", gain * 0.5 * (f.viscous_positive - f.viscous_negative)},
          {"c", gain * 0.5 * (f.coulomb_positive + f.coulomb_negative)},
          {"coulomb_asymmetry", gain * 0.5 * (f.coulomb_positive - f.coulomb_negative)},
          {"stiction", gain * 0.5 * (excess_plus + excess_minus)},
          {"stiction_asymmetry", gain * 0.5 * (excess_plus - excess_minus)}};
}

std::map<std::string, double> crane_audit_parameters(const common::CraneParameters& crane) {
  std::map<std::string, double> out;
  for (const auto& f : crane_fields()) out[f.name] = f.scalar != nullptr ? crane.*f.scalar : (crane.*f.axis).*f.friction;
  return out;
}

common::CraneParameters crane_parameters_from_audit(const std::map<std::string, double>& parameters,
                                                    const common::CraneParameters& base) {
  common::CraneParameters crane = base;
  for (const auto& [name, value] : parameters) {
    const auto& fields = crane_fields();
    const auto it = std::find_if(fields.begin(), fields.end(), [&](const CraneField& f) { return name == f.name; });
    if (it == fields.end()) throw common::ConfigError("param: unknown crane parameter '" + name + "'");
    if (it->scalar != nullptr) crane.*it->scalar = value;
    else (crane.*it->axis).*it->friction = value;
  }
  common::validate(crane, "param");
  return crane;
}

void validate(const AuditOptions& options) {
  const auto& names = audit_parameter_names(options.plant);
  const std::string plant = options.plant == AuditPlant::axis       ? "axis"
                            : options.plant == AuditPlant::pendulum ? "pendulum"
                                                                    : "crane";
  for (const auto& [name, value] : options.parameters) {
    if (std::find(names.begin(), names.end(), name) == names.end()) {
      throw common::ConfigError("param: unknown parameter '" + name + "' for model " + plant + " (valid: " +
                                join(names) + ")");
    }
    common::require_finite("param " + name, value);
  }
  const std::vector<std::string> required = options.plant == AuditPlant::axis       ? std::vector<std::string>{"K_m", "b", "c"}
                                            : options.plant == AuditPlant::pendulum ? std::vector<std::string>{"L"}
                                                                                    : names;
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
    const double stiction = parameter(options.parameters, "stiction", 0.0);
    common::require_at_least("param stiction", stiction, 0.0);
    common::require_in_range("param stiction_asymmetry", parameter(options.parameters, "stiction_asymmetry", 0.0),
                             -stiction, stiction);
  } else if (options.plant == AuditPlant::crane) {
    static_cast<void>(crane_parameters_from_audit(options.parameters));  // validates every field
  } else {
    common::require_greater("param L", options.parameters.at("L"), 0.0);
    common::require_at_least("param damping", parameter(options.parameters, "damping", 0.0), 0.0);
    common::require_greater("param gravity", parameter(options.parameters, "gravity", 9.80665), 0.0);
  }
  const auto& catalog = audit_catalog(options.plant);
  for (const auto& cause : options.causes) {
    // payload_mass_error is fitted on an axis only as a drive of the crane (coupling data given).
    if (options.plant == AuditPlant::axis && cause == "payload_mass_error") continue;
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
  common::require_at_least("min_holdout_gain_quanta", options.min_holdout_gain_quanta, 0.0);
  if (options.substeps < 1) throw common::ConfigError("substeps = " + std::to_string(options.substeps) + " must be >= 1");
}

AuditData read_audit_data(const std::filesystem::path& file, AuditPlant plant, const std::string& columns,
                          double max_rate, std::size_t minimum_samples) {
  CsvReadOptions read;
  read.mapping = parse_column_mapping(columns);
  const std::vector<std::string> crane_columns{"t", "u_x", "u_gamma", "x", "gamma", "phi", "theta", "L"};
  const std::vector<std::string> allowed = plant == AuditPlant::axis       ? std::vector<std::string>{"t", "u", "x"}
                                           : plant == AuditPlant::pendulum ? std::vector<std::string>{"t", "theta", "x", "segment"}
                                                                           : crane_columns;
  for (const auto& [canonical, file_column] : read.mapping.entries) {
    if (std::find(allowed.begin(), allowed.end(), canonical) == allowed.end()) {
      throw common::ConfigError("columns: unknown canonical name '" + canonical + "' (expected " + join(allowed) + ")");
    }
  }
  read.required_columns = plant == AuditPlant::axis       ? std::vector<std::string>{"t", "u", "x"}
                          : plant == AuditPlant::pendulum ? std::vector<std::string>{"t", "theta"}
                                                          : crane_columns;
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
  } else if (plant == AuditPlant::crane) {
    data.input = take(series.column("u_x"));
    data.output = take(series.column("x"));
    data.slew_input = take(series.column("u_gamma"));
    data.slew_angle = take(series.column("gamma"));
    data.swing_in_plane = take(series.column("phi"));
    data.swing_out_of_plane = take(series.column("theta"));
    data.cable_length = take(series.column("L"));
    for (std::size_t k = 0; k < data.cable_length.size(); ++k) {
      if (data.cable_length[k] <= 0.0) {
        throw DataError(file.string() + ": column '" + read.mapping.file_column("L") + "': cable length " +
                        common::format_value(data.cable_length[k]) + " m at data row " + std::to_string(k * factor + 1) +
                        " must be > 0");
      }
    }
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

namespace {

// The audit of one channel: axis (position or effort), pendulum, or, with `swing` given, the crane
// swing channel (then `options` is a pendulum's, with L the mean cable length).
AuditReport run_audit_channel(const AuditData& data, const AuditOptions& options,
                              const std::shared_ptr<CraneSwingSeries>& swing) {
  const std::size_t n = data.time.size();
  const std::size_t residual_count = swing ? 2 * n : n;
  if (n < 50) throw DataError(data.source + ": too few samples: " + std::to_string(n) + " (minimum 50)");
  if (data.output.size() != n || (options.plant == AuditPlant::axis && data.input.size() != n)) {
    throw DataError(data.source + ": columns of different lengths");
  }
  const double sample_time = (data.time.back() - data.time.front()) / static_cast<double>(n - 1);
  const bool axis = options.plant == AuditPlant::axis;
  const bool effort = axis && options.channel == AuditChannel::effort;

  AuditReport report;
  report.plant = axis ? "axis" : (swing ? "swing" : "pendulum");
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
    axis_series->nominal.coulomb_asymmetry = parameter(options.parameters, "coulomb_asymmetry", 0.0);
    axis_series->nominal.viscous_asymmetry = parameter(options.parameters, "viscous_asymmetry", 0.0);
    axis_series->nominal.stiction = parameter(options.parameters, "stiction", 0.0);
    axis_series->nominal.stiction_asymmetry = parameter(options.parameters, "stiction_asymmetry", 0.0);
    axis_series->inertia = data.coupling_inertia;
    axis_series->inertia_per_mass = data.coupling_inertia_per_mass;
    axis_series->force = data.coupling_force;
    axis_series->force_per_mass = data.coupling_force_per_mass;
    axis_series->drive_inertia = data.drive_inertia;
    axis_series->sample_time = sample_time;
    axis_series->dead_band = options.dead_band;
  } else if (swing) {
    candidates = pendulum_candidates(options.parameters.at("L"), parameter(options.parameters, "gravity", 9.80665));
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
    if (swing) {
      auto s = std::make_shared<CraneSwingSeries>(*swing);
      s->cause = cause;
      return crane_swing_problem(s, options.window_duration, options.holdout_fraction);
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
  const Fit nominal = fit_problem(nominal_problem, base, nominal_free, initial_nuisance(nominal_problem), residual_count);
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
  // Resolution of the channel: the smallest nonzero step of the measured signal (position/angle
  // channels; 0 for effort, which sets no resolution floor).
  double quantum = 0.0;
  if (!effort) {
    const std::vector<double>& measured = swing ? swing->measured : data.output;
    const std::size_t stride = swing ? 2 : 1;
    quantum = std::numeric_limits<double>::infinity();
    for (std::size_t k = stride; k < measured.size(); ++k) {
      const double step = std::abs(measured[k] - measured[k - stride]);
      if (step > 1e-15) quantum = std::min(quantum, step);
    }
    if (!std::isfinite(quantum)) quantum = 0.0;
  }

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
    const auto fit_from = [&](const std::vector<double>& start) {
      return fit_problem(problem, start, free, start_nuisance, residual_count);
    };
    fits[c] = fit_from(full);
    if (candidate.parameters.size() > 1) {
      // Several parameters (stribeck: level and v_s trade off along a valley): the grid scores use
      // unfitted initial states, so also fit from other starts and keep the lowest training RSS.
      // Extra starts: the best grid points at the second parameter's grid neighbours (below and
      // above) of the grid optimum; with every_grid_start, when the fit still leaves more than
      // kRestartQuanta quanta of training RMS, at each of its other grid values too.
      std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      const auto& second = candidate.parameters[1].grid;
      const auto at = std::find(second.begin(), second.end(), best_point[1]);
      std::vector<double> neighbours;
      if (at != second.end() && at != second.begin()) neighbours.push_back(*(at - 1));
      if (at != second.end() && at + 1 != second.end()) neighbours.push_back(*(at + 1));
      const auto fit_from_best_at = [&](std::vector<double> values) {
        for (const auto& [rss, point] : scored) {
          const auto it = std::find(values.begin(), values.end(), point[1]);
          if (it == values.end()) continue;
          values.erase(it);
          std::vector<double> start = full;
          std::copy(point.begin(), point.end(), start.begin() + static_cast<std::ptrdiff_t>(base_count));
          Fit other = fit_from(start);
          if (other.train_rss < fits[c].train_rss) fits[c] = std::move(other);
        }
      };
      fit_from_best_at(neighbours);
      const double train_rms = std::sqrt(fits[c].train_rss / static_cast<double>(std::max<std::size_t>(fits[c].train_n, 1)));
      if (options.every_grid_start && train_rms > kRestartQuanta * quantum) {
        std::vector<double> others;
        for (const double v : second) {
          if (v != best_point[1] && std::find(neighbours.begin(), neighbours.end(), v) == neighbours.end()) others.push_back(v);
        }
        fit_from_best_at(others);
      }
    }
    if (axis && candidate.name == "stiction") {
      // The stick threshold from the breakaway brackets (axis_breakaway_bracket), the rest of the
      // model and the initial states refitted with it held.
      if (const auto bracket = axis_breakaway_bracket(*axis_series, fits[c].full)) {
        std::vector<double> held = fits[c].full;
        held[base_count] = std::max(0.5 * (bracket->first + bracket->second), 0.0);
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
                      entry.holdout_gain_percent >= options.min_holdout_gain_percent &&
                      holdout_nominal - entry.holdout_rms >= options.min_holdout_gain_quanta * quantum;
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
                         " and held-out gain >= " + common::format_value(options.min_holdout_gain_percent) + " %" +
                         (options.min_holdout_gain_quanta > 0.0
                              ? " and >= " + common::format_value(options.min_holdout_gain_quanta) + " quanta of " +
                                    common::format_value(quantum) + " " + report.unit
                              : std::string()) +
                         ")";
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
  report.measured.assign(n, kNaN);
  report.nominal_prediction.assign(n, kNaN);
  report.extended_prediction.assign(n, kNaN);
  report.holdout.assign(n, 0.0);
  const std::size_t stride = swing ? 2 : 1;  // swing: the in-plane angle phi
  for (std::size_t k = 0; k < n; ++k) {
    const double measured = swing    ? swing->measured[stride * k]
                            : effort ? (k >= 1 ? 0.5 * (data.input[k - 1] + data.input[k]) : data.input[0])
                                     : data.output[k];
    const std::size_t i = stride * k;
    report.measured[k] = measured;
    report.holdout[k] = nominal.holdout_flag[i];
    if (std::isfinite(nominal.residual_per_sample[i])) report.nominal_prediction[k] = measured - nominal.residual_per_sample[i];
    if (std::isfinite(selected->residual_per_sample[i])) report.extended_prediction[k] = measured - selected->residual_per_sample[i];
  }

  // Rank: fitted candidates by delta-BIC, then the skipped ones.
  std::stable_sort(report.candidates.begin(), report.candidates.end(), [](const auto& a, const auto& b) {
    if (a.fitted != b.fitted) return a.fitted;
    return a.fitted && a.delta_bic < b.delta_bic;
  });
  return report;
}

// ---------------------------------------------------------------------------------------------
// Crane: three channels (trolley, slew, swing), each an audit of its own, combined.

// Causes of one channel requested by the crane options: names with `prefix` stripped, pendulum
// names, or payload_mass_error. `requested` = false when the options name causes but none here.
std::vector<std::string> channel_causes(const std::vector<std::string>& causes, const std::string& prefix,
                                        const std::vector<std::string>& catalog, bool with_payload, bool& requested) {
  requested = causes.empty();
  std::vector<std::string> out;
  for (const auto& cause : causes) {
    std::string name = cause;
    if (!prefix.empty()) {
      if (cause == "payload_mass_error" && with_payload) {
        out.push_back(cause);
        continue;
      }
      if (cause.rfind(prefix, 0) != 0) continue;
      name = cause.substr(prefix.size());
    }
    if (std::find(catalog.begin(), catalog.end(), name) != catalog.end()) out.push_back(name);
  }
  requested = requested || !out.empty();
  return out;
}

// Measured motion of the crane per sample: central differences (one-sided copies at the ends).
struct CraneMotion {
  std::vector<plant::ModelState> state;
  std::vector<plant::CoordinateVector> acceleration;
  std::vector<plant::HoistMotion> hoist;
};

CraneMotion crane_motion(const AuditData& data, double sample_time) {
  const std::size_t n = data.time.size();
  const std::vector<double>* q[plant::kNumCoordinates] = {&data.output, &data.swing_in_plane, &data.slew_angle,
                                                           &data.swing_out_of_plane};
  CraneMotion m;
  m.state.resize(n);
  m.acceleration.resize(n);
  m.hoist.resize(n);
  const double t = sample_time;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t c = std::clamp<std::size_t>(k, 1, n - 2);  // stencil centre
    for (int j = 0; j < plant::kNumCoordinates; ++j) {
      const auto& v = *q[j];
      m.state[k].position[j] = v[k];
      m.state[k].velocity[j] = (v[c + 1] - v[c - 1]) / (2.0 * t);
      m.acceleration[k][j] = (v[c + 1] - 2.0 * v[c] + v[c - 1]) / (t * t);
    }
    const auto& L = data.cable_length;
    m.hoist[k] = {L[k], (L[c + 1] - L[c - 1]) / (2.0 * t), (L[c + 1] - 2.0 * L[c] + L[c - 1]) / (t * t)};
  }
  return m;
}

// Coupling of the drive axes (inverse dynamics of the full model with the measured motion). The
// swing accelerations are not differentiated twice (the swing encoders' quanta would give several
// rad/s^2 of noise): the swing rows of TowerCraneModel give them from the drive accelerations,
// s'' = -M_ss^-1 (M_sa a'' + bias_s), so the drive rows become M_eff a'' + b_eff = (F_x, T_gamma) with
//   M_eff = M_aa - M_as M_ss^-1 M_sa,  b_eff = bias_a - M_as M_ss^-1 bias_s
// at the measured positions and (central-difference) rates. Drive i: I_i a_i + C_i with the inertia
// I_i = M_eff,ii and C_i = b_eff,i + M_eff,ij a_j (the other drive's measured acceleration). The swing
// rows do not depend on the load mass and the drive rows are affine in it, so I and C are affine in
// m: I = I(0) + m dI, C = C(0) + m dC.
struct DriveCoupling {
  std::vector<double> inertia;           // at the nominal load mass
  std::vector<double> inertia_per_mass;
  std::vector<double> force;
  std::vector<double> force_per_mass;
};

std::pair<DriveCoupling, DriveCoupling> crane_coupling(const common::CraneParameters& crane, const CraneMotion& motion) {
  common::CraneParameters massless = crane;
  massless.load_mass = 0.0;
  common::CraneParameters unit = crane;
  unit.load_mass = 1.0;
  const plant::TowerCraneModel model0(massless);
  const plant::TowerCraneModel model1(unit);
  const std::size_t n = motion.state.size();
  std::pair<DriveCoupling, DriveCoupling> out;
  for (auto* c : {&out.first, &out.second}) {
    c->inertia.resize(n);
    c->inertia_per_mass.resize(n);
    c->force.resize(n);
    c->force_per_mass.resize(n);
  }
  for (std::size_t k = 0; k < n; ++k) {
    plant::CoordinateMatrix mass0;
    plant::CoordinateMatrix mass1;
    plant::CoordinateVector bias0;
    plant::CoordinateVector bias1;
    model0.compute_dynamics(motion.state[k], motion.hoist[k], mass0, bias0);
    model1.compute_dynamics(motion.state[k], motion.hoist[k], mass1, bias1);
    const Eigen::Vector2d a(motion.acceleration[k][plant::kTrolleyIndex], motion.acceleration[k][plant::kSlewIndex]);
    const SwingElimination e0 = eliminate_swing(mass0, bias0);
    const SwingElimination e1 = eliminate_swing(mass1, bias1);
    const Eigen::Matrix2d inertia[2] = {e0.drive_inertia, e1.drive_inertia};
    const Eigen::Vector2d bias[2] = {e0.drive_bias, e1.drive_bias};
    for (int i = 0; i < 2; ++i) {
      DriveCoupling& c = i == 0 ? out.first : out.second;
      const double force0 = bias[0](i) + inertia[0](i, 1 - i) * a(1 - i);
      const double force1 = bias[1](i) + inertia[1](i, 1 - i) * a(1 - i);
      c.inertia_per_mass[k] = inertia[1](i, i) - inertia[0](i, i);
      c.force_per_mass[k] = force1 - force0;
      c.inertia[k] = inertia[0](i, i) + crane.load_mass * c.inertia_per_mass[k];
      c.force[k] = force0 + crane.load_mass * c.force_per_mass[k];
    }
  }
  return out;
}

// Drive motion held over [t_k, t_k+1) for the swing replay: position and rates at t_k, the
// acceleration of the interval (mean of the second differences at k and k+1).
std::vector<DriveMotion> swing_drive_motion(const CraneMotion& m) {
  const std::size_t n = m.state.size();
  std::vector<DriveMotion> out(n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t next = std::min(k + 1, n - 1);
    DriveMotion& d = out[k];
    d.trolley_position = m.state[k].position[plant::kTrolleyIndex];
    d.trolley_velocity = m.state[k].velocity[plant::kTrolleyIndex];
    d.trolley_acceleration = 0.5 * (m.acceleration[k][plant::kTrolleyIndex] + m.acceleration[next][plant::kTrolleyIndex]);
    d.slew_rate = m.state[k].velocity[plant::kSlewIndex];
    d.slew_acceleration = 0.5 * (m.acceleration[k][plant::kSlewIndex] + m.acceleration[next][plant::kSlewIndex]);
    d.cable_length = m.hoist[k].cable_length;
    d.cable_length_rate = m.hoist[k].cable_length_rate;
    d.cable_length_acceleration = m.hoist[k].cable_length_acceleration;
  }
  return out;
}

// The slew's units: the axis model's metres are radians there ("m/s^2/m" -> "rad/s^2/rad").
std::string slew_unit(const std::string& unit) {
  std::string out;
  std::size_t start = 0;
  while (start <= unit.size()) {
    const std::size_t end = std::min(unit.find('/', start), unit.size());
    const std::string token = unit.substr(start, end - start);
    out += (token == "m" ? "rad" : token.rfind("m^", 0) == 0 ? "rad" + token.substr(1) : token);
    if (end < unit.size()) out += '/';
    start = end + 1;
  }
  return out;
}

AuditReport run_crane_audit(const AuditData& data, const AuditOptions& options) {
  if (options.calibrate) {
    throw common::ConfigError("calibrate: not available for the crane model (give the nominal parameters with "
                              "--config and --param)");
  }
  if (options.channel == AuditChannel::effort) {
    throw common::ConfigError("channel: the crane audit fits the position and swing channels and reports the "
                              "effort channel of each drive as a second opinion; do not give --channel effort");
  }
  const std::size_t n = data.time.size();
  if (n < 50) throw DataError(data.source + ": too few samples: " + std::to_string(n) + " (minimum 50)");
  for (const auto* column : {&data.input, &data.output, &data.slew_input, &data.slew_angle, &data.swing_in_plane,
                             &data.swing_out_of_plane, &data.cable_length}) {
    if (column->size() != n) throw DataError(data.source + ": crane columns of different lengths");
  }
  const common::CraneParameters crane = crane_parameters_from_audit(options.parameters);
  const double sample_time = (data.time.back() - data.time.front()) / static_cast<double>(n - 1);
  const CraneMotion motion = crane_motion(data, sample_time);
  // The coupling uses the swing angles low-passed (zero phase, kSwingCutoff): their encoder quanta
  // would otherwise reach the drives through the rates in the centripetal and Coriolis terms.
  AuditData smoothed = data;
  if (sample_time < 0.25 / kSwingCutoff) {
    smoothed.swing_in_plane = zero_phase_low_pass(data.swing_in_plane, kSwingCutoff, 1.0 / sample_time);
    smoothed.swing_out_of_plane = zero_phase_low_pass(data.swing_out_of_plane, kSwingCutoff, 1.0 / sample_time);
  }
  const auto [trolley_coupling, slew_coupling] = crane_coupling(crane, crane_motion(smoothed, sample_time));

  AuditReport report;
  report.plant = "crane";
  report.sample_time = sample_time;
  report.samples = n;
  for (const auto& [name, value] : crane_audit_parameters(crane)) report.nominal.push_back({name, "", value, 0.0});

  // Drive axes.
  const auto& axis_catalog = audit_catalog(AuditPlant::axis);
  const auto drive_channel = [&](const std::string& prefix, const std::vector<double>& input,
                                 const std::vector<double>& position, const DriveCoupling& coupling,
                                 double drive_inertia, const common::AxisFriction& friction,
                                 double gain) -> std::optional<AuditReport> {
    bool requested = false;
    AuditOptions axis_options = options;
    axis_options.plant = AuditPlant::axis;
    axis_options.causes = channel_causes(options.causes, prefix, axis_catalog, true, requested);
    if (!requested) return std::nullopt;
    axis_options.parameters = drive_axis_audit_parameters(friction, gain);
    axis_options.min_holdout_gain_quanta = kCraneResolutionQuanta;
    axis_options.every_grid_start = true;
    AuditData axis_data;
    axis_data.source = data.source;
    axis_data.time = data.time;
    axis_data.input = input;
    axis_data.output = position;
    axis_data.coupling_inertia = coupling.inertia;
    axis_data.coupling_inertia_per_mass = coupling.inertia_per_mass;
    axis_data.coupling_force = coupling.force;
    axis_data.coupling_force_per_mass = coupling.force_per_mass;
    axis_data.drive_inertia = drive_inertia;
    axis_data.load_mass = crane.load_mass;
    validate(axis_options);
    AuditReport channel = run_audit_channel(axis_data, axis_options, nullptr);
    channel.plant = prefix.substr(0, prefix.size() - 1);
    const bool slew = prefix == kSlewPrefix;
    if (slew) channel.unit = slew_unit(channel.unit);
    for (auto& candidate : channel.candidates) {
      if (candidate.name != "payload_mass_error") candidate.name = prefix + candidate.name;
      for (auto& p : candidate.parameters) p.unit = slew ? slew_unit(p.unit) : p.unit;
    }
    for (auto& p : channel.extended_nominal) p.unit = slew ? slew_unit(p.unit) : p.unit;
    if (channel.cause != "none" && channel.cause != "payload_mass_error") channel.cause = prefix + channel.cause;
    return channel;
  };
  if (auto c = drive_channel(kTrolleyPrefix, data.input, data.output, trolley_coupling, crane.trolley_drive_mass,
                             crane.trolley_friction, crane.trolley_drive_gain)) {
    report.channels.push_back(std::move(*c));
  }
  if (auto c = drive_channel(kSlewPrefix, data.slew_input, data.slew_angle, slew_coupling, crane.jib_inertia,
                             crane.slew_friction, crane.slew_drive_gain)) {
    report.channels.push_back(std::move(*c));
  }

  // Swing.
  {
    bool requested = false;
    AuditOptions swing_options = options;
    swing_options.plant = AuditPlant::pendulum;
    swing_options.causes = channel_causes(options.causes, "", audit_catalog(AuditPlant::pendulum), false, requested);
    double mean_length = 0.0;
    for (const double L : data.cable_length) mean_length += L / static_cast<double>(n);
    swing_options.parameters = {{"L", mean_length}, {"gravity", crane.gravity}};
    swing_options.window_duration = std::max(options.window_duration, kSwingWindow);
    swing_options.min_holdout_gain_quanta = kCraneResolutionQuanta;
    if (requested) {
      auto series = std::make_shared<CraneSwingSeries>();
      series->model = std::make_shared<const plant::TowerCraneModel>(crane);
      series->motion = swing_drive_motion(motion);
      series->sample_time = sample_time;
      series->substeps = 1;
      series->measured.resize(2 * n);
      for (std::size_t k = 0; k < n; ++k) {
        series->measured[2 * k] = data.swing_in_plane[k];
        series->measured[2 * k + 1] = data.swing_out_of_plane[k];
      }
      AuditData swing_data;
      swing_data.source = data.source;
      swing_data.time = data.time;
      swing_data.output = data.swing_in_plane;
      validate(swing_options);
      report.channels.push_back(run_audit_channel(swing_data, swing_options, series));
    }
  }

  // Combine: the qualifying candidate with the lowest delta-BIC over the channels whose nominal
  // residual is not white; payload_mass_error (fitted on both drives) keeps its better fit.
  const AuditReport* chosen_channel = nullptr;
  const CandidateReport* chosen = nullptr;
  const CandidateReport* payload = nullptr;
  for (const auto& channel : report.channels) {
    const bool white = channel.before.whiteness.lags > 0 && channel.before.whiteness.p_value >= 0.05;
    for (const auto& candidate : channel.candidates) {
      if (candidate.name == "payload_mass_error" && candidate.fitted &&
          (payload == nullptr || candidate.delta_bic < payload->delta_bic)) {
        payload = &candidate;
      }
      if (white || !candidate.qualifies) continue;
      if (chosen == nullptr || candidate.delta_bic < chosen->delta_bic) {
        chosen = &candidate;
        chosen_channel = &channel;
      }
    }
  }
  for (const auto& channel : report.channels) {
    for (const auto& candidate : channel.candidates) {
      if (candidate.name == "payload_mass_error" && candidate.fitted && &candidate != payload) continue;
      report.candidates.push_back(candidate);
    }
  }
  std::stable_sort(report.candidates.begin(), report.candidates.end(), [](const auto& a, const auto& b) {
    if (a.fitted != b.fitted) return a.fitted;
    return a.fitted && a.delta_bic < b.delta_bic;
  });
  const AuditReport& shown = chosen_channel != nullptr ? *chosen_channel : report.channels.front();
  report.channel = shown.plant + " " + shown.channel;
  report.unit = shown.unit;
  report.before = shown.before;
  report.after = shown.after;
  report.holdout_before = shown.holdout_before;
  report.holdout_after = shown.holdout_after;
  report.holdout_percent = shown.holdout_percent;
  report.effort_holdout_before = shown.effort_holdout_before;
  report.effort_holdout_after = shown.effort_holdout_after;
  report.time = shown.time;
  report.measured = shown.measured;
  report.nominal_prediction = shown.nominal_prediction;
  report.extended_prediction = shown.extended_prediction;
  report.holdout = shown.holdout;
  if (chosen != nullptr) {
    report.cause = chosen->name;
    report.parameters = chosen->parameters;
    report.extended_nominal = shown.extended_nominal;
    if (chosen->name == "payload_mass_error") {
      const double dm = chosen->parameters.front().value;
      report.parameters.push_back({"load_mass", "kg", crane.load_mass + dm, chosen->parameters.front().standard_error});
    }
    report.stop_reason = "selected " + chosen->name + " on the " + report.channel +
                         " channel (lowest delta-BIC among qualifying candidates of all channels)";
  } else {
    report.stop_reason = "no channel has a candidate that earns its parameters (";
    for (const auto& channel : report.channels) {
      report.stop_reason += channel.plant + " " + channel.channel + ": " + channel.stop_reason + "; ";
    }
    report.stop_reason.resize(report.stop_reason.size() - 2);
    report.stop_reason += ")";
  }
  return report;
}

}  // namespace

AuditReport run_audit(const AuditData& data, const AuditOptions& options) {
  validate(options);
  if (options.plant == AuditPlant::crane) return run_crane_audit(data, options);
  return run_audit_channel(data, options, nullptr);
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
  const auto effort_json = [&](const AuditReport& r) {
    return nlohmann::json{{"before", number(r.effort_holdout_before)}, {"after", number(r.effort_holdout_after)}};
  };
  if (report.plant == "axis") json["effort_holdout_rms_V"] = effort_json(report);
  if (!report.channels.empty()) {
    nlohmann::json channels = nlohmann::json::array();
    for (const auto& c : report.channels) {
      nlohmann::json entry{{"name", c.plant},
                           {"channel", c.channel},
                           {"unit", c.unit},
                           {"cause", c.cause},
                           {"stop_reason", c.stop_reason},
                           {"holdout_rms", {{"before", number(c.holdout_before)}, {"after", number(c.holdout_after)}}},
                           {"residual_before", summary_json(c.before)},
                           {"residual_after", summary_json(c.after)}};
      if (c.channel == "position") entry["effort_holdout_rms_V"] = effort_json(c);
      channels.push_back(entry);
    }
    json["channels"] = channels;
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
    if (!report.channels.empty()) {
      md << "\n\n| channel | cause | held-out RMS before | after | effort RMS before [V] | after [V] | Ljung-Box p |\n"
            "|---|---|---|---|---|---|---|\n";
      for (const auto& c : report.channels) {
        md << "| " << c.plant << " " << c.channel << " [" << c.unit << "] | " << c.cause << " | "
           << common::format_value(c.holdout_before) << " | " << common::format_value(c.holdout_after) << " | "
           << common::format_value(c.effort_holdout_before) << " | " << common::format_value(c.effort_holdout_after)
           << " | " << common::format_value(c.before.whiteness.p_value) << " |\n";
      }
    }
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
