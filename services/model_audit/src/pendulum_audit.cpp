#include "pendulum_audit.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <string_view>

namespace crane::model_audit::detail {

const std::vector<PendulumCause>& pendulum_catalog() {
  static const std::vector<PendulumCause> catalog{
      {.name = "pendulum_viscous_damping",
       .parameters = [](const SwingScales&) -> std::vector<ParameterSpec> {
         return {{"extra_viscous_damping", "1/s", 0.1, -1.0, 20.0, linspace(0.0, 0.6, 61)}};
       },
       .apply = [](const double* p, PendulumModel& m) { m.extra_viscous = std::max(p[0], -m.damping); },
       .apply_swing = [](const double* p, SwingEffects& e) { e.extra_viscous = p[0]; },
       .calibration_note = "absorbed by the calibrated nominal parameters"},
      {.name = "pendulum_coulomb_damping",
       .parameters = [](const SwingScales& scales) -> std::vector<ParameterSpec> {
         const double omega2 = scales.omega_squared;
         return {{"coulomb_damping", "rad/s^2", 0.005 * omega2, 0.0, 2.0 * omega2,
                 linspace(0.0002 * omega2, 0.012 * omega2, 60)}};
       },
       .apply = [](const double* p, PendulumModel& m) { m.coulomb = std::max(p[0], 0.0); },
       .apply_swing = [](const double* p, SwingEffects& e) { e.coulomb = std::max(p[0], 0.0); }},
      {.name = "pendulum_quadratic_damping",
       .parameters = [](const SwingScales&) -> std::vector<ParameterSpec> {
         return {{"quadratic_damping", "1/rad", 0.1, 0.0, 50.0, linspace(0.0, 1.0, 51)}};
       },
       .apply = [](const double* p, PendulumModel& m) { m.quadratic = std::max(p[0], 0.0); },
       .apply_swing = [](const double* p, SwingEffects& e) { e.quadratic = std::max(p[0], 0.0); }},
      {.name = "cable_length_error",
       .parameters = [](const SwingScales&) -> std::vector<ParameterSpec> {
         return {{"length_error", "-", 0.05, -0.8, 2.0, linspace(-0.25, 0.25, 51)}};
       },
       .apply = [](const double* p, PendulumModel& m) { m.length_error = std::max(p[0], -0.9); },
       .apply_swing = [](const double* p, SwingEffects& e) { e.length_error = std::max(p[0], -0.9); },
       .calibration_note = "absorbed by the calibrated nominal parameters"},
      {.name = "encoder_offset",
       .parameters = [](const SwingScales&) -> std::vector<ParameterSpec> {
         return {{"encoder_offset", "rad", 0.02, -0.5, 0.5, linspace(-0.1, 0.1, 41)}};
       },
       .apply = [](const double* p, PendulumModel& m) { m.encoder_offset = p[0]; },
       .apply_swing = [](const double* p, SwingEffects& e) { e.encoder_offset = p[0]; },
       .needs_known_zero = true},
      // Crane only (the plant's tower-crane options plant.wind and plant.hook). A steady wind
      // force F (inertial x, y) on the load: the swing's equilibrium moves to about F / (m g) in the
      // jib frame, so it turns with the slew angle, and both swing planes feel it (an offset of the
      // in-plane encoder does neither). Grid: up to 6 % of the load's weight per component.
      {.name = "wind_force",
       .parameters = [](const SwingScales& scales) -> std::vector<ParameterSpec> {
         const double w = std::max(scales.load_weight, 1e-6);
         return {{"wind_force_x", "N", 0.01 * w, -0.5 * w, 0.5 * w, linspace(-0.06 * w, 0.06 * w, 7)},
                 {"wind_force_y", "N", 0.01 * w, -0.5 * w, 0.5 * w, linspace(-0.06 * w, 0.06 * w, 7)}};
       },
       .apply = nullptr,
       .apply_swing =
           [](const double* p, SwingEffects& e) {
             e.wind_force_x = p[0];
             e.wind_force_y = p[1];
           },
       .crane_only = true},
      // The hook as a double pendulum: rigging of length l below the hook, the hook's share s of the
      // configured suspended mass (crane_swing.hpp). The encoders measure the cable (trolley to
      // hook); the rigging's initial state is four more nuisance values per window.
      {.name = "hook_double_pendulum",
       .parameters = [](const SwingScales&) -> std::vector<ParameterSpec> {
         return {{"rigging_length", "m", 0.1, kMinRiggingLength, kMaxRiggingLength, linspace(0.1, 0.6, 6)},
                 {"hook_mass_share", "-", 0.1, kMinHookMassShare, kMaxHookMassShare, {0.1, 0.2, 0.35, 0.5}}};
       },
       .apply = nullptr,
       .apply_swing =
           [](const double* p, SwingEffects& e) {
             e.rigging_length = std::max(p[0], kMinRiggingLength);
             e.hook_mass_share = p[1];
           },
       .crane_only = true,
       .extra_nuisance = 4},
      // The rope as a spring (the plant's plant.rope): the static stretch ratio e_r = M g / EA. Its
      // constant part is a cable length error; what only the rope does is a stretch that follows
      // the tension (crane_swing.hpp). The stretch starts each window at rest: no nuisance values.
      {.name = "elastic_rope",
       .parameters = [](const SwingScales&) -> std::vector<ParameterSpec> {
         return {{"rope_stretch_ratio", "-", 0.005, kMinRopeStretchRatio, kMaxRopeStretchRatio,
                  {0.002, 0.005, 0.01, 0.02, 0.04, 0.08}}};
       },
       .apply = nullptr,
       .apply_swing =
           [](const double* p, SwingEffects& e) {
             e.rope_stretch_ratio = std::clamp(p[0], kMinRopeStretchRatio, kMaxRopeStretchRatio);
           },
       .crane_only = true},
  };
  return catalog;
}

bool extends_swing_state(const PendulumCause& cause) {
  return std::string_view(cause.name) == "hook_double_pendulum" || std::string_view(cause.name) == "elastic_rope";
}

struct PendulumSeries {
  std::vector<double> theta;
  std::vector<double> trolley_acceleration;
  double sample_time{0.0};
  double gravity{9.80665};
  int substeps{4};
  const PendulumCause* cause{nullptr};  // nullptr: the nominal model
  const PendulumCause* first{nullptr};  // second step: the first cause (its parameter after the base)
  std::size_t first_count{0};
};

struct SwingSeries {
  std::shared_ptr<const plant::TowerCraneModel> model;
  std::vector<DriveMotion> motion;
  std::vector<double> measured;  // interleaved phi, theta [rad] (2 per sample)
  double sample_time{0.0};
  int substeps{1};
  const PendulumCause* cause{nullptr};  // nullptr: the nominal model
  const PendulumCause* first{nullptr};  // second step: the first cause (its parameters first)
  std::size_t first_count{0};
};

namespace {

constexpr std::size_t kPendulumBase = 3;  // L, damping, theta_zero

std::vector<Candidate> candidates_of(const SwingScales& scales, bool crane) {
  std::vector<Candidate> list;
  const auto& catalog = pendulum_catalog();
  for (std::size_t i = 0; i < catalog.size(); ++i) {
    if (catalog[i].crane_only && !crane) continue;
    list.push_back({catalog[i].name, catalog[i].parameters(scales), i, catalog[i].calibration_note, "", "", 0, -1e300});
  }
  return list;
}



PendulumModel pendulum_model(const PendulumSeries& s, const std::vector<double>& full) {
  PendulumModel m;
  m.length = std::max(full[0], 1e-6);
  m.damping = std::max(full[1], 0.0);
  m.theta_zero = full[2];
  m.gravity = s.gravity;
  if (s.first != nullptr) s.first->apply(full.data() + kPendulumBase, m);
  if (s.cause != nullptr) s.cause->apply(full.data() + kPendulumBase + s.first_count, m);
  return m;
}

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
    const PendulumModel model = pendulum_model(*s, full);
    PendulumState initial{nuisance[0], nuisance[1]};
    std::span<double> prediction(out, count);
    replay_pendulum(model, s->trolley_acceleration, s->sample_time, w.first, initial, s->substeps, prediction);
    for (std::size_t i = 0; i < count; ++i) out[i] = s->theta[w.first + i] - out[i];
  };
  return problem;
}




// The swing channel has no base parameters of its own: the candidate's parameters come first, after
// the first cause's in a second step.
SwingEffects swing_effects(const SwingSeries& s, const std::vector<double>& full) {
  SwingEffects e;
  if (s.first != nullptr && full.size() >= s.first_count) s.first->apply_swing(full.data(), e);
  if (s.cause != nullptr && full.size() > s.first_count) s.cause->apply_swing(full.data() + s.first_count, e);
  return e;
}

// Windows of window_duration [s] (in the interleaved index space: 2 residuals per sample, phi then
// theta); the windows in the last holdout_fraction are held out; nuisance: the initial swing state.
Problem crane_swing_problem(const std::shared_ptr<SwingSeries>& s, double window_duration,
                            double holdout_fraction) {
  Problem problem;
  const std::size_t n = s->motion.size();
  const auto length = std::max<std::size_t>(static_cast<std::size_t>(std::llround(window_duration / s->sample_time)), 10);
  const auto holdout_start = static_cast<std::size_t>(std::floor((1.0 - holdout_fraction) * static_cast<double>(n)));
  for (std::size_t first = 0; first + 10 <= n; first += length) {
    const std::size_t count = std::min(length, n - first);
    problem.windows.push_back({2 * first, 2 * count, first >= holdout_start ? 0 : 2 * count});
  }
  const std::size_t extra = (s->cause != nullptr ? s->cause->extra_nuisance : 0) +
                            (s->first != nullptr ? s->first->extra_nuisance : 0);  // (one hook at most)
  problem.nuisance_size = 4 + extra;
  problem.initial_nuisance = [s, extra](const Window& w, double* out) {
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
    if (extra == 4) {  // the hook's rigging starts in line with the cable
      out[4] = phi0;
      out[5] = phi_rate;
      out[6] = theta0;
      out[7] = theta_rate;
    }
  };
  problem.residual = [s, extra](const std::vector<double>& full, const double* nuisance, const Window& w,
                                std::size_t count, double* out) {
    const SwingEffects effects = swing_effects(*s, full);
    SwingState initial{nuisance[0] - effects.encoder_offset, nuisance[1], nuisance[2], nuisance[3]};
    if (extra == 4) {
      initial.rigging_in_plane = nuisance[4];
      initial.rigging_in_plane_rate = nuisance[5];
      initial.rigging_out_of_plane = nuisance[6];
      initial.rigging_out_of_plane_rate = nuisance[7];
    }
    replay_crane_swing(*s->model, effects, s->motion, s->sample_time, w.first / 2, count / 2, initial, s->substeps,
                       std::span<double>(out, count));
    for (std::size_t i = 0; i < count; ++i) out[i] = s->measured[w.first + i] - out[i];
  };
  return problem;
}


}  // namespace

PendulumAudit::PendulumAudit(const AuditData& data, const PendulumAuditParameters& nominal, const AuditOptions& options)
    : data_(data),
      sample_time_(checked_sample_time(data)),
      holdout_fraction_(options.holdout_fraction),
      theta_zero_known_(nominal.theta_zero.has_value()),
      gravity_(nominal.gravity) {
  const std::size_t n = data.time.size();
  if (data.output.size() != n) throw DataError(data.source + ": columns of different lengths");
  const double length = nominal.length;
  const double damping = nominal.damping;
  double zero = nominal.theta_zero.value_or(0.0);
  if (!theta_zero_known_) {  // estimate: the median of the measured angle
    std::vector<double> sorted = data.output;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<std::ptrdiff_t>(n / 2), sorted.end());
    zero = sorted[n / 2];
  }
  base_ = {length, damping, zero};
  base_specs_ = {{"L", "m", length, 1e-3 * length, 100 * length, {}},
                 {"damping", "1/s", std::max(damping, 0.05), 0.0, 100.0, {}},
                 {"theta_zero", "rad", 0.02, zero - 1.0, zero + 1.0, {}}};
  auto s = std::make_shared<PendulumSeries>();
  s->theta = data.output;
  s->sample_time = sample_time_;
  s->gravity = gravity_;
  s->substeps = options.substeps;
  if (!data.trolley_position.empty()) {
    auto& acc = s->trolley_acceleration;
    acc.assign(n, 0.0);
    for (std::size_t k = 1; k + 1 < n; ++k) {
      acc[k] = (data.trolley_position[k + 1] - 2.0 * data.trolley_position[k] + data.trolley_position[k - 1]) /
               (sample_time_ * sample_time_);
    }
  }
  series_ = std::move(s);
}

PendulumAudit::~PendulumAudit() = default;

std::vector<std::size_t> PendulumAudit::nominal_free(bool calibrate) const {
  std::vector<std::size_t> free;
  if (calibrate) free = {0, 1};
  if (!theta_zero_known_) free.push_back(2);
  for (std::size_t i = first_base_; i < base_.size() && first_base_ > 0; ++i) free.push_back(i);
  return free;
}

std::vector<Candidate> PendulumAudit::candidates() const {
  auto list = candidates_of({.omega_squared = gravity_ / base_[0], .load_weight = 0.0, .cable_length = base_[0]}, false);
  std::erase_if(list, [&](const Candidate& c) { return c.entry == first_entry_; });
  return list;
}

std::unique_ptr<ChannelAudit> PendulumAudit::with_first_cause(const Candidate& first, const std::vector<double>& full) const {
  if (series_->first != nullptr) return nullptr;  // two causes at most
  auto next = std::make_unique<PendulumAudit>(*this);
  next->first_entry_ = first.entry;
  next->first_base_ = base_.size();
  next->base_.assign(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(base_.size() + first.parameters.size()));
  for (const auto& spec : first.parameters) next->base_specs_.push_back(spec);
  auto s = std::make_shared<PendulumSeries>(*series_);
  s->first = &pendulum_catalog()[first.entry];
  s->first_count = first.parameters.size();
  next->series_ = std::move(s);
  return next;
}

std::string PendulumAudit::unavailable(const Candidate& candidate) const {
  if (!theta_zero_known_ && pendulum_catalog()[candidate.entry].needs_known_zero) {
    return "theta_zero is estimated (give --param theta_zero=VALUE to test an offset)";
  }
  return {};
}

Problem PendulumAudit::problem(const Candidate* candidate) const {
  auto s = std::make_shared<PendulumSeries>(*series_);
  s->cause = candidate != nullptr ? &pendulum_catalog()[candidate->entry] : nullptr;
  return pendulum_problem(s, data_.segment, holdout_fraction_, base_);
}

SwingAudit::SwingAudit(const AuditData& data, std::shared_ptr<const plant::TowerCraneModel> model,
                       std::vector<DriveMotion> motion, std::vector<double> measured, double mean_cable_length,
                       double gravity, const AuditOptions& options)
    : data_(data),
      sample_time_(checked_sample_time(data)),
      holdout_fraction_(options.holdout_fraction),
      window_duration_(options.window_duration),
      scales_{.omega_squared = gravity / mean_cable_length,
              .load_weight = model->parameters().load_mass * gravity,
              .cable_length = mean_cable_length} {
  auto s = std::make_shared<SwingSeries>();
  s->model = std::move(model);
  s->motion = std::move(motion);
  s->measured = std::move(measured);
  s->sample_time = sample_time_;
  s->substeps = 1;
  series_ = std::move(s);
}

SwingAudit::~SwingAudit() = default;

std::vector<std::size_t> SwingAudit::nominal_free(bool) const {
  std::vector<std::size_t> free(base_.size());
  for (std::size_t i = 0; i < free.size(); ++i) free[i] = i;
  return free;
}

std::vector<Candidate> SwingAudit::candidates() const {
  auto list = candidates_of(scales_, true);
  if (series_->first != nullptr) {
    std::erase_if(list, [&](const Candidate& c) {
      const auto& entry = pendulum_catalog()[c.entry];
      return &entry == series_->first || (extends_swing_state(entry) && extends_swing_state(*series_->first));
    });
  }
  return list;
}

std::unique_ptr<ChannelAudit> SwingAudit::with_first_cause(const Candidate& first, const std::vector<double>& full) const {
  if (series_->first != nullptr) return nullptr;  // two causes at most
  auto next = std::make_unique<SwingAudit>(*this);
  next->base_.assign(full.begin(), full.begin() + static_cast<std::ptrdiff_t>(first.parameters.size()));
  next->base_specs_ = first.parameters;
  auto s = std::make_shared<SwingSeries>(*series_);
  s->first = &pendulum_catalog()[first.entry];
  s->first_count = first.parameters.size();
  next->series_ = std::move(s);
  return next;
}

Problem SwingAudit::problem(const Candidate* candidate) const {
  auto s = std::make_shared<SwingSeries>(*series_);
  s->cause = candidate != nullptr ? &pendulum_catalog()[candidate->entry] : nullptr;
  return crane_swing_problem(s, window_duration_, holdout_fraction_);
}

double SwingAudit::quantum() const { return resolution_quantum(series_->measured, 2); }

bool SwingAudit::pairs_without_single() const { return series_->first == nullptr; }

double SwingAudit::second_step_gain_fraction() const {
  return series_->first != nullptr ? kSwingSecondStepGainFraction : 0.0;
}

double SwingAudit::measured(std::size_t k) const { return series_->measured[2 * k]; }

}  // namespace crane::model_audit::detail
