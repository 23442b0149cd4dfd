#include "axis_audit.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>

namespace crane::model_audit::detail {

struct AxisSeries {
  std::vector<double> x;
  std::vector<double> u;
  double sample_time{0.0};
  int substeps{1};
  const AxisCause* cause{nullptr};  // nullptr: the nominal model
  // Second step of the stepwise audit: the first cause, its parameters at full[kAxisBase ..
  // kAxisBase + first_count), the candidate's after them.
  const AxisCause* first{nullptr};
  std::size_t first_count{0};
  [[nodiscard]] bool gap() const {
    return (cause != nullptr && cause->gap_state) || (first != nullptr && first->gap_state);
  }
  double dead_band{0.0};
  AxisModel nominal;  // nominal asymmetries and stiction (catalog entries add to them)
  // A crane drive's nominal asymmetries and stiction are configured in volts: with a calibrated
  // K_m they scale with K_m / nominal_gain (a lone axis keeps them in m/s^2; without calibration
  // K_m is nominal_gain and nothing changes).
  bool asymmetries_in_volts{false};
  double nominal_gain{1.0};  // [m/s^2/V] the nominal K_m
  // Crane drive axis (empty for a lone axis): the axis row I a + C = I_drive (drive - friction) with
  // I = inertia + dm inertia_per_mass and C = force + dm force_per_mass at t_k (dm = the
  // payload_mass_error parameter [kg]); see AuditData.
  std::vector<double> inertia;
  std::vector<double> inertia_per_mass;
  std::vector<double> force;
  std::vector<double> force_per_mass;
  double drive_inertia{0.0};
};

namespace {

constexpr std::size_t kAxisBase = 3;  // K_m, b, c



// The nominal model with the base parameters of `full` (K_m, b, c), and the cause's terms.
// The nominal asymmetries and stiction for base K_m `gain` (asymmetries_in_volts).
AxisModel scaled_nominal(const AxisSeries& s, double gain) {
  AxisModel m = s.nominal;
  if (s.asymmetries_in_volts) {
    const double scale = gain / s.nominal_gain;
    m.coulomb_asymmetry *= scale;
    m.viscous_asymmetry *= scale;
    m.stiction *= scale;
    m.stiction_asymmetry *= scale;
  }
  return m;
}

AxisTerms axis_terms(const AxisSeries& s, const std::vector<double>& full) {
  AxisTerms t;
  t.model = scaled_nominal(s, std::max(full[0], 1e-9));
  t.model.motor_constant = std::max(full[0], 1e-9);
  t.model.viscous = std::max(full[1], 0.0);
  t.model.coulomb = std::max(full[2], 0.0);
  if (s.first != nullptr) s.first->apply(full.data() + kAxisBase, t);
  if (s.cause != nullptr) s.cause->apply(full.data() + kAxisBase + s.first_count, t);
  return t;
}

// Coupling of a crane drive axis for the load mass error dm [kg] (payload_mass_error): the row
// inertia I and force C at t_k, and, held over [t_k, t_k+1) (means of t_k and t_k+1), the inertia
// ratio I_drive / I and the external acceleration -C / I of the replay. Empty for a lone axis.
struct AxisCoupling {
  std::vector<double> inertia;  // [kg] or [kg m^2]
  std::vector<double> force;    // [N] or [N m]
  std::vector<double> ratio;    // [-]
  std::vector<double> external; // [m/s^2] or [rad/s^2]
};

AxisCoupling axis_coupling(const AxisSeries& s, double dm) {
  AxisCoupling c;
  if (s.inertia.empty()) return c;
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
  for (std::size_t first = 0; first + 10 <= n; first += length) {
    Window w;
    w.first = first;
    w.count = std::min(length, n - first);
    w.train_count = w.count;
    problem.windows.push_back(w);
  }
  hold_out_moving_windows(s->x, holdout_fraction, problem.windows);
  // Nuisance: initial measured position, velocity and (backlash only) where the axis sits in the
  // gap, as a fraction in [-1, 1] of the half gap.
  const bool gap = s->gap();
  problem.nuisance_size = gap ? 3 : 2;
  problem.initial_nuisance = [s, gap](const Window& w, double* out) {
    const auto [x0, v0] = local_state(s->x, w.first, w.first + w.count, s->sample_time);
    out[0] = x0;
    out[1] = v0;
    if (gap) out[2] = v0 > 0.0 ? 0.9 : -0.9;
  };
  problem.residual = [s](const std::vector<double>& full, const double* nuisance, const Window& w, std::size_t count,
                         double* out) {
    const AxisTerms terms = axis_terms(*s, full);
    const AxisModel& model = terms.model;
    const AxisCoupling coupling = axis_coupling(*s, terms.load_mass_error);
    AxisState initial;
    initial.load_position = nuisance[0];
    initial.velocity = nuisance[1];
    const double sign = s->gap() ? std::clamp(nuisance[2], -1.0, 1.0) : 0.0;
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
    const AxisTerms terms = axis_terms(*s, full);
    const AxisCoupling coupling = axis_coupling(*s, terms.load_mass_error);
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t k = w.first + i;
      out[i] = (k >= 1 && k + 2 <= s->x.size()) ? axis_effort_residual(*s, terms.model, coupling, k) : kNaN;
    }
  };
  return problem;
}

// Linear least squares in the effort domain for the candidates linear in their parameter:
// K_m u - a - b v - db |v| - c s - dc = phi * theta on moving samples (db, dc nominal; on a crane
// axis (I a + C) / I_drive instead of a; Eigen column-pivoted QR).

std::optional<double> axis_linear_estimate(const AxisSeries& s, const std::vector<double>& base, const AxisCause& cause) {
  if (cause.regressor == nullptr) return std::nullopt;
  const AxisModel nominal = scaled_nominal(s, base[0]);
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
    y.push_back(base[0] * u - needed - base[1] * v - nominal.viscous_asymmetry * std::abs(v) - base[2] * sign -
                nominal.coulomb_asymmetry);
    AxisRegressorSample sample;
    sample.drive = base[0] * u;
    sample.velocity = v;
    sample.sign = sign;
    sample.position = s.x[k];
    if (!s.inertia.empty()) sample.mass_term = (s.inertia_per_mass[k] * a + s.force_per_mass[k]) / s.drive_inertia;
    phi.push_back(cause.regressor(sample));
  }
  if (y.size() < 10) return std::nullopt;
  const Eigen::Map<const Eigen::VectorXd> yv(y.data(), static_cast<Eigen::Index>(y.size()));
  const Eigen::Map<const Eigen::VectorXd> pv(phi.data(), static_cast<Eigen::Index>(phi.size()));
  const Eigen::VectorXd theta = Eigen::MatrixXd(pv).colPivHouseholderQr().solve(yv);
  return cause.regressor_factor * theta(0);
}


// Stick threshold from the breakaways (stiction only). A position fit of Delta_s is piecewise flat:
// with the command held over each sample, a breakaway can only start at a sample instant, so the
// data only say that the threshold c + Delta_s lies between the drive K_m u of the last held
// sample and that of the breakaway sample. This estimator reads those brackets off the record:
// a rest episode is a run of >= 5 samples within kRestQuanta position quanta (the record's
// resolution: the smallest nonzero step, or its noise when that is larger) of its first sample, followed by motion; the breakaway instant is
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
  const double quantum = measurement_resolution(s.x, 1);  // the quantum, or the noise when larger
  if (!(quantum > 0.0)) return std::nullopt;
  const double tolerance = kRestQuanta * quantum;
  AxisSeries base = s;
  base.cause = nullptr;
  const AxisModel nominal = axis_terms(base, full).model;
  const AxisCoupling coupling = axis_coupling(base, 0.0);
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


}  // namespace

AxisAudit::AxisAudit(const AuditData& data, const AxisAuditParameters& nominal, const AuditOptions& options)
    : data_(data),
      sample_time_(checked_sample_time(data)),
      effort_(options.channel == AuditChannel::effort),
      holdout_fraction_(options.holdout_fraction),
      window_duration_(options.window_duration),
      substeps_(options.substeps) {
  const std::size_t n = data.time.size();
  if (data.output.size() != n || data.input.size() != n) throw DataError(data.source + ": columns of different lengths");
  const double k_m = nominal.motor_constant;
  const double b = nominal.viscous;
  const double c = nominal.coulomb;
  base_ = {k_m, b, c};
  base_specs_ = {{"K_m", "m/s^2/V", k_m, 1e-3 * k_m, 100 * k_m, {}},
                 {"b", "1/s", std::max(b, 0.1), 0.0, 100 * std::max(b, 0.1), {}},
                 {"c", "m/s^2", std::max(c, 0.05 * k_m), 0.0, 100 * std::max(c, 0.05 * k_m), {}}};
  auto s = std::make_shared<AxisSeries>();
  s->x = data.output;
  s->u = data.input;
  s->nominal.coulomb_asymmetry = nominal.coulomb_asymmetry;
  s->nominal.viscous_asymmetry = nominal.viscous_asymmetry;
  s->nominal.stiction = nominal.stiction;
  s->nominal.stiction_asymmetry = nominal.stiction_asymmetry;
  s->inertia = data.coupling_inertia;
  s->inertia_per_mass = data.coupling_inertia_per_mass;
  s->force = data.coupling_force;
  s->force_per_mass = data.coupling_force_per_mass;
  s->drive_inertia = data.drive_inertia;
  s->asymmetries_in_volts = !data.coupling_inertia.empty();
  s->nominal_gain = nominal.motor_constant;
  s->sample_time = sample_time_;
  s->dead_band = options.dead_band;
  series_ = std::move(s);
}

AxisAudit::~AxisAudit() = default;

std::vector<std::size_t> AxisAudit::nominal_free(bool calibrate) const {
  std::vector<std::size_t> free = calibrate ? std::vector<std::size_t>{0, 1, 2} : std::vector<std::size_t>{};
  for (std::size_t i = first_base_; i < base_.size() && first_base_ > 0; ++i) free.push_back(i);
  return free;
}

std::unique_ptr<ChannelAudit> AxisAudit::with_first_cause(const Candidate& first, const std::vector<double>& full) const {
  if (series_->first != nullptr) return nullptr;  // two causes at most
  auto next = std::make_unique<AxisAudit>(*this);
  next->first_entry_ = first.entry;
  next->first_base_ = base_.size();
  next->base_.assign(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(base_.size() + first.parameters.size()));
  for (const auto& spec : first.parameters) next->base_specs_.push_back(spec);
  auto s = std::make_shared<AxisSeries>(*series_);
  s->first = &axis_catalog()[first.entry];
  s->first_count = first.parameters.size();
  next->series_ = std::move(s);
  return next;
}

std::vector<Candidate> AxisAudit::candidates() const {
  AxisScales scales;
  for (const double u : data_.input) scales.max_input = std::max(scales.max_input, std::abs(u));
  const auto [min_x, max_x] = std::minmax_element(data_.output.begin(), data_.output.end());
  scales.range = std::max(*max_x - *min_x, 1e-6);
  scales.half_range = 0.5 * scales.range;
  scales.motor_constant = base_[0];
  scales.c_scale = std::max(base_[2], 0.05 * base_[0]);
  scales.b_scale = std::max(base_[1], 0.1);
  scales.volt = scales.c_scale / base_[0];
  scales.sample_time = sample_time_;
  scales.load_mass = data_.load_mass;
  const bool crane_drive = !data_.coupling_inertia.empty();
  std::vector<Candidate> list;
  const auto& catalog = axis_catalog();
  for (std::size_t i = 0; i < catalog.size(); ++i) {
    if (catalog[i].crane_drive_only && !crane_drive) continue;
    if (i == first_entry_) continue;  // the first cause of a second step
    list.push_back({catalog[i].name, catalog[i].parameters(scales), i, catalog[i].calibration_note, "",
                    catalog[i].limit_of, catalog[i].limit_parameter,
                    catalog[i].limit_value != nullptr ? catalog[i].limit_value(scales) : -1e300});
  }
  return list;
}

std::string AxisAudit::unavailable(const Candidate& candidate) const {
  if (effort_ && !axis_catalog()[candidate.entry].effort_channel) {
    return candidate.name + " is not defined in the effort channel";
  }
  return {};
}

std::shared_ptr<AxisSeries> AxisAudit::series(const AxisCause* cause) const {
  auto s = std::make_shared<AxisSeries>(*series_);
  s->cause = cause;
  s->substeps = (cause != nullptr && cause->substeps) || (s->first != nullptr && s->first->substeps) ? substeps_ : 1;
  return s;
}

Problem AxisAudit::problem(const Candidate* candidate) const {
  const auto s = series(candidate != nullptr ? &axis_catalog()[candidate->entry] : nullptr);
  return effort_ ? axis_effort_problem(s, holdout_fraction_) : axis_position_problem(s, window_duration_, holdout_fraction_);
}

double AxisAudit::quantum() const { return effort_ ? 0.0 : resolution_quantum(data_.output, 1); }
double AxisAudit::resolution() const { return effort_ ? 0.0 : measurement_resolution(data_.output, 1); }

double AxisAudit::measured(std::size_t k) const {
  if (!effort_) return data_.output[k];
  return k >= 1 ? 0.5 * (data_.input[k - 1] + data_.input[k]) : data_.input[0];
}

std::optional<double> AxisAudit::linear_estimate(const Candidate& candidate, const std::vector<double>& nominal) const {
  return axis_linear_estimate(*series_, nominal, axis_catalog()[candidate.entry]);
}

// The stick threshold from the breakaway brackets (axis_breakaway_bracket), the rest of the model and
// the initial states refitted with it held.
void AxisAudit::refine(const Candidate& candidate, const Problem& problem, const FreeSet& nominal_free, Fit& fit) const {
  if (!axis_catalog()[candidate.entry].breakaway_threshold) return;
  const auto bracket = axis_breakaway_bracket(*series_, fit.full);
  if (!bracket) return;
  std::vector<double> held = fit.full;
  held[base_.size()] = std::max(0.5 * (bracket->first + bracket->second), 0.0);
  const double half_width = 0.5 * (bracket->second - bracket->first);
  Fit refit = fit_problem(problem, held, nominal_free, fit.nuisance, samples());
  refit.standard_errors.push_back(half_width / std::sqrt(3.0));  // uniform within the bracket
  fit = std::move(refit);
}

// The effort channel's held-out RMS [V] as a second opinion (NaN where the cause is not defined there).
void AxisAudit::second_opinion(const std::vector<double>& nominal, const Candidate* selected,
                               const std::vector<double>& selected_full, AuditReport& report) const {
  const auto effort_rms = [&](const std::vector<double>& full, const AxisCause* cause) {
    const Problem p = axis_effort_problem(series(cause), holdout_fraction_);
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
  report.effort_holdout_before = effort_rms(nominal, nullptr);
  if (selected == nullptr) {
    report.effort_holdout_after = report.effort_holdout_before;
    return;
  }
  const AxisCause& cause = axis_catalog()[selected->entry];
  report.effort_holdout_after = cause.effort_channel ? effort_rms(selected_full, &cause) : kNaN;
}

}  // namespace crane::model_audit::detail
