#include "crane/adaptation/online_adaptation.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"
#include "crane/state_estimator/filter_design.hpp"

namespace crane::adaptation {

namespace {

constexpr const char* kPrefix = "state_estimator.adaptation";
constexpr double kViscousScaleFloor = 0.5;  // [V s/m] or [V s/rad]: typical-size floor of a viscous coefficient
constexpr double kCoulombScaleFloor = 0.1;  // [V] of a Coulomb coefficient
constexpr double kLoadMassFloor = 0.1;      // [kg] typical-size floor of the load (a configured empty hook)

const OnlineAdaptationParams& validated(const OnlineAdaptationParams& p) {
  validate(p);
  return p;
}

// Typical sizes of (load ratio, b+, b-, c+, c-) for the excitation check and the release bounds.
ParameterVector scales(double load_ratio_scale, const common::AxisFriction& f) {
  ParameterVector s;
  s << load_ratio_scale, std::max(f.viscous_positive, kViscousScaleFloor), std::max(f.viscous_negative, kViscousScaleFloor),
      std::max(f.coulomb_positive, kCoulombScaleFloor), std::max(f.coulomb_negative, kCoulombScaleFloor);
  return s;
}

ParameterVector initial(double load_ratio, const common::AxisFriction& f) {
  const auto c = friction_compensation::sliding_coefficients(f);
  ParameterVector v;
  v << load_ratio, c[0], c[1], c[2], c[3];
  return v;
}

AxisIdentifierParams identifier_params(const OnlineAdaptationParams& p, double load_ratio, double load_ratio_scale,
                                       const common::AxisFriction& friction, double noise_correlation) {
  AxisIdentifierParams a;
  a.forgetting_factor = p.forgetting_factor;
  a.initial = initial(load_ratio, friction);
  a.scale = scales(load_ratio_scale, friction);
  a.min_information = p.min_information;
  a.max_condition = p.max_condition;
  a.noise_correlation = noise_correlation;
  return a;
}

// (3.3) over the stencil [k-2, k]: both backward differences beyond d_s with the same sign.
int sliding_direction(const double (&q)[3], double sample_period, double band) {
  const int newer = friction_compensation::friction_direction((q[0] - q[1]) / sample_period, band);
  const int older = friction_compensation::friction_direction((q[1] - q[2]) / sample_period, band);
  return newer == older ? newer : 0;
}

}  // namespace

ImpulseFigures impulse_figures(const state_estimator::DiscreteTransferFunction& tf) {
  // A stable filter's response decays geometrically: it is followed until it has stayed below
  // 1e-17 of its peak for kQuietSamples samples (about 250 samples for the 4 Hz Butterworth at
  // 100 Hz; the sums then hold to the last bit), at most kMaxLength samples.
  constexpr int kMaxLength = 100000;
  constexpr int kQuietSamples = 1000;
  state_estimator::DiscreteFilter filter(tf);
  filter.initialize(0.0, 0.0);
  std::vector<double> h;
  h.reserve(2 * kQuietSamples);
  double peak = 0.0;
  int quiet = 0;
  for (int k = 0; k < kMaxLength && quiet < kQuietSamples; ++k) {
    const double v = filter.update(k == 0 ? 1.0 : 0.0);
    h.push_back(v);
    peak = std::max(peak, std::abs(v));
    quiet = std::abs(v) < 1e-17 * peak ? quiet + 1 : 0;
  }
  ImpulseFigures f;
  double sum = 0.0;
  double sum_squares = 0.0;
  for (std::size_t k = 0; k < h.size(); ++k) {
    const double v = h[k];
    if (std::abs(v) >= 0.01 * peak) f.memory = static_cast<int>(k) + 1;
    sum += v;
    sum_squares += v * v;
  }
  f.correlation = std::max(1.0, sum * sum / sum_squares);
  return f;
}

void validate(const OnlineAdaptationParams& p) {
  const std::string f = kPrefix;
  common::validate(p.crane, "crane");
  common::require_in_range(f + ".sample_period", p.sample_period, 1e-6, 1.0);
  common::require_greater(f + ".filter_cutoff", p.filter_cutoff, 0.0);
  common::require_in_range(f + ".filter_cutoff", p.filter_cutoff, 0.0, 0.45 / p.sample_period);
  common::require_in_range(f + ".trolley_zero_velocity_band", p.trolley_zero_velocity_band, 0.0, 10.0);
  common::require_in_range(f + ".slew_zero_velocity_band", p.slew_zero_velocity_band, 0.0, 10.0);
  common::require_in_range(f + ".forgetting_factor", p.forgetting_factor, 0.9, 1.0);
  common::require_greater(f + ".min_information", p.min_information, 0.0);
  common::require_finite(f + ".min_information", p.min_information);
  common::require_in_range(f + ".max_condition", p.max_condition, 1.0, 1e12);
  common::require_in_range(f + ".solve_period", p.solve_period, p.sample_period, 60.0);
  common::require_greater(f + ".mass_relative_bound", p.mass_relative_bound, 0.0);
  common::require_in_range(f + ".mass_relative_bound", p.mass_relative_bound, 0.0, 1.0);
  common::require_in_range(f + ".min_mass", p.min_mass, 0.0, 1e6);
  common::require_greater(f + ".max_mass", p.max_mass, p.min_mass);
  common::require_finite(f + ".max_mass", p.max_mass);
  // The configured load must be a payload the estimate may report: [min_mass, max_mass] brackets it.
  if (p.crane.load_mass < p.min_mass || p.crane.load_mass > p.max_mass) {
    throw common::ConfigError(f + ".min_mass, max_mass = [" + common::format_value(p.min_mass) + ", " +
                              common::format_value(p.max_mass) + "] kg is out of range: must contain crane.load_mass = " +
                              common::format_value(p.crane.load_mass) + " kg");
  }
  common::require_greater(f + ".friction_relative_bound", p.friction_relative_bound, 0.0);
  common::require_in_range(f + ".friction_relative_bound", p.friction_relative_bound, 0.0, 10.0);
  common::require_greater(f + ".min_friction_factor", p.min_friction_factor, 0.0);
  common::require_in_range(f + ".min_friction_factor", p.min_friction_factor, 0.0, 1.0);
  common::require_in_range(f + ".max_friction_factor", p.max_friction_factor, 1.0, 100.0);
  common::require_greater(f + ".max_friction_rate", p.max_friction_rate, 0.0);
  common::require_finite(f + ".max_friction_rate", p.max_friction_rate);
  validate(p.limit_cycle, (f + ".limit_cycle").c_str());
}

OnlineAdaptation::OnlineAdaptation(const OnlineAdaptationParams& params)
    : params_(validated(params)),
      trolley_(identifier_params(params_, params_.crane.mass_ratio(),
                                 std::max(params_.crane.load_mass, kLoadMassFloor) / params_.crane.trolley_drive_mass,
                                 params_.crane.trolley_friction,
                                 impulse_figures(state_estimator::butterworth_low_pass(
                                                     params_.filter_cutoff, 1.0 / params_.sample_period))
                                     .correlation),
               (std::string(kPrefix) + ".trolley").c_str()),
      slew_(identifier_params(params_, params_.crane.load_inertia_ratio(),
                              std::max(params_.crane.load_mass, kLoadMassFloor) / params_.crane.jib_inertia,
                              params_.crane.slew_friction, trolley_.params().noise_correlation),
            (std::string(kPrefix) + ".slew").c_str()),
      trolley_cycles_(params_.limit_cycle, params_.sample_period, params_.trolley_zero_velocity_band,
                      (std::string(kPrefix) + ".limit_cycle").c_str()),
      slew_cycles_(params_.limit_cycle, params_.sample_period, params_.slew_zero_velocity_band,
                   (std::string(kPrefix) + ".limit_cycle").c_str()),
      low_pass_(state_estimator::butterworth_low_pass(params_.filter_cutoff, 1.0 / params_.sample_period)),
      trolley_in_use_(params_.crane.trolley_friction),
      slew_in_use_(params_.crane.slew_friction) {
  const ImpulseFigures figures = impulse_figures(low_pass_);
  settle_samples_ = figures.memory + 2;  // + the difference stencil
  noise_correlation_ = figures.correlation;
  for (auto& f : filters_) f = state_estimator::DiscreteFilter(low_pass_);
  solve_interval_ = std::max(1, static_cast<int>(std::lround(params_.solve_period / params_.sample_period)));
  solve_countdown_ = solve_interval_;
}

void OnlineAdaptation::filter_row(int axis, const std::array<double, kFiltersPerAxis>& raw,
                                  std::array<double, kFiltersPerAxis>& filtered) noexcept {
  for (int i = 0; i < kFiltersPerAxis; ++i) {
    auto& filter = filters_[static_cast<std::size_t>(axis * kFiltersPerAxis + i)];
    const double value = raw[static_cast<std::size_t>(i)];
    if (!filters_initialized_) filter.initialize(value, value * low_pass_.dc_gain());
    filtered[static_cast<std::size_t>(i)] = filter.update(value);
  }
}

void OnlineAdaptation::step(const AdaptationInput& in, AdaptationEstimate& out) noexcept {
  const auto& crane = params_.crane;
  if (!params_.enabled) {
    out = AdaptationEstimate{};
    out.payload_mass = crane.load_mass;
    out.trolley_friction = crane.trolley_friction;
    out.slew_friction = crane.slew_friction;
    return;
  }
  if (!std::isfinite(in.trolley_position) || !std::isfinite(in.slew_angle) || !std::isfinite(in.swing_in_plane) ||
      !std::isfinite(in.swing_out_of_plane) || !std::isfinite(in.applied_trolley_voltage) ||
      !std::isfinite(in.applied_slew_voltage)) {
    release(out);
    return;
  }
  History& h = history_;
  const auto shift = [](auto& a, double v) {
    for (std::size_t i = std::size(a) - 1; i > 0; --i) a[i] = a[i - 1];
    a[0] = v;
  };
  shift(h.x, in.trolley_position);
  shift(h.gamma, in.slew_angle);
  shift(h.phi, in.swing_in_plane);
  shift(h.theta, in.swing_out_of_plane);
  shift(h.u_x, in.applied_trolley_voltage);
  shift(h.u_gamma, in.applied_slew_voltage);
  if (h.count < 3) ++h.count;
  trolley_cycles_.step(in.trolley_position, in.applied_trolley_voltage);
  slew_cycles_.step(in.slew_angle, in.applied_slew_voltage);
  if (h.count < 3) {
    release(out);
    return;
  }

  const double t = params_.sample_period;
  const double g = crane.gravity;
  const double k_x = crane.trolley_drive_gain;
  const double k_g = crane.slew_drive_gain;
  const double m_r_trolley = crane.trolley_inertia_ratio();  // M_r = M_t/J_o [1/m^2]

  // Rows centred at k-1 (header): the trolley's, then the slew's, raw.
  const double x_velocity = (h.x[0] - h.x[2]) / (2.0 * t);
  const double slew_rate = (h.gamma[0] - h.gamma[2]) / (2.0 * t);
  const int x_direction = sliding_direction(h.x, t, params_.trolley_zero_velocity_band);
  const int g_direction = sliding_direction(h.gamma, t, params_.slew_zero_velocity_band);
  const auto x_friction = friction_compensation::friction_regressor(x_velocity, x_direction);
  const auto g_friction = friction_compensation::friction_regressor(slew_rate, g_direction);

  std::array<double, kFiltersPerAxis> raw{};
  std::array<double, kFiltersPerAxis> trolley_row{};
  std::array<double, kFiltersPerAxis> slew_row{};
  raw[0] = (h.x[0] - 2.0 * h.x[1] + h.x[2]) / (t * t);                                       // x''
  raw[1] = 0.5 * (h.u_x[0] + h.u_x[1]);                                                     // u_x
  raw[2] = crane.trolley_mass / crane.trolley_drive_mass * h.x[1] * slew_rate * slew_rate;  // (M_t/M) x gamma'^2
  raw[3] = g * h.phi[1];                                                                    // g phi
  for (int i = 0; i < 4; ++i) raw[static_cast<std::size_t>(4 + i)] = x_friction[static_cast<std::size_t>(i)];
  filter_row(0, raw, trolley_row);

  const double x_newer = 0.5 * (h.x[0] + h.x[1]);
  const double x_older = 0.5 * (h.x[1] + h.x[2]);
  const double momentum_newer = (1.0 + m_r_trolley * x_newer * x_newer) * (h.gamma[0] - h.gamma[1]) / t;
  const double momentum_older = (1.0 + m_r_trolley * x_older * x_older) * (h.gamma[1] - h.gamma[2]) / t;
  raw[0] = (momentum_newer - momentum_older) / t;  // [(1 + M_r x^2) gamma']'
  raw[1] = 0.5 * (h.u_gamma[0] + h.u_gamma[1]);    // u_gamma
  raw[2] = 0.0;
  raw[3] = g * h.x[1] * h.theta[1];                // g x theta
  for (int i = 0; i < 4; ++i) raw[static_cast<std::size_t>(4 + i)] = g_friction[static_cast<std::size_t>(i)];
  filter_row(1, raw, slew_row);
  filters_initialized_ = true;

  // Sliding in one direction for longer than H's memory (header).
  const auto count_sliding = [&](int direction, int& previous, int& sliding) {
    sliding = (direction != 0 && direction == previous && !in.brakes_engaged) ? sliding + 1 : (direction != 0 ? 1 : 0);
    if (in.brakes_engaged) sliding = 0;
    previous = direction;
  };
  count_sliding(x_direction, trolley_direction_, trolley_sliding_);
  count_sliding(g_direction, slew_direction_, slew_sliding_);

  if (trolley_sliding_ >= settle_samples_ && !trolley_cycles_.fired()) {
    ParameterVector phi;
    phi << -trolley_row[3] / k_x, -trolley_row[4], -trolley_row[5], -trolley_row[6], -trolley_row[7];
    (void)trolley_.update(trolley_row[0] / k_x - trolley_row[1] - trolley_row[2] / k_x, phi);
  }
  if (slew_sliding_ >= settle_samples_ && !slew_cycles_.fired()) {
    ParameterVector phi;
    phi << slew_row[3] / k_g, -slew_row[4], -slew_row[5], -slew_row[6], -slew_row[7];
    (void)slew_.update(slew_row[0] / k_g - slew_row[1], phi);
  }
  if (--solve_countdown_ <= 0) {
    solve_countdown_ = solve_interval_;
    (void)trolley_.solve();
    (void)slew_.solve();
  }
  release(out);
}

void OnlineAdaptation::release_axis(const AxisIdentifier& id, const common::AxisFriction& configured,
                                    bool limit_cycle, common::AxisFriction& in_use) noexcept {
  if (limit_cycle || !params_.adapt_friction) {
    in_use = configured;  // the fallback (header), or the payload mass only
    return;
  }
  const AxisIdentification& s = id.identification();
  const ParameterVector& scale = id.params().scale;
  const ParameterVector& nominal = id.params().initial;
  double* coefficient[kParameterCount] = {nullptr, &in_use.viscous_positive, &in_use.viscous_negative,
                                          &in_use.coulomb_positive, &in_use.coulomb_negative};
  const double step_limit = params_.max_friction_rate * params_.sample_period;
  const auto target_ok = [&](int i) {
    const double size = std::max(std::abs(nominal(i)), scale(i));
    const double low = std::max(0.0, nominal(i) - (1.0 - params_.min_friction_factor) * size);
    const double high = nominal(i) + (params_.max_friction_factor - 1.0) * size;
    const double value = s.estimate(i);
    return value >= low && value <= high && s.standard_deviation(i) > 0.0 &&
           2.0 * s.standard_deviation(i) <= params_.friction_relative_bound * std::max(std::abs(value), scale(i));
  };
  const std::array<std::array<int, 2>, 2> groups{{{1, 3}, {2, 4}}};
  const std::array<bool, 2> excited{s.positive_excited, s.negative_excited};
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (!excited[g]) continue;  // keep what is in use
    for (int i : groups[g]) {
      if (!target_ok(i)) continue;
      const double size = std::max(std::abs(nominal(i)), scale(i));
      double& value = *coefficient[i];
      value += std::clamp(s.estimate(i) - value, -step_limit * size, step_limit * size);
    }
  }
  // Breakaway scaled with the Coulomb coefficient of its direction (header).
  const auto scaled_static = [](double configured_static, double configured_coulomb, double coulomb) {
    return configured_coulomb > 0.0 ? configured_static * coulomb / configured_coulomb : configured_static;
  };
  in_use.static_positive = scaled_static(configured.static_positive, configured.coulomb_positive, in_use.coulomb_positive);
  in_use.static_negative = scaled_static(configured.static_negative, configured.coulomb_negative, in_use.coulomb_negative);
}

void OnlineAdaptation::release(AdaptationEstimate& out) noexcept {
  const auto& crane = params_.crane;
  release_axis(trolley_, crane.trolley_friction, trolley_cycles_.fired(), trolley_in_use_);
  release_axis(slew_, crane.slew_friction, slew_cycles_.fired(), slew_in_use_);
  out = AdaptationEstimate{};
  out.trolley_friction = trolley_in_use_;
  out.slew_friction = slew_in_use_;
  const auto differs = [](const common::AxisFriction& a, const common::AxisFriction& b) {
    return a.viscous_positive != b.viscous_positive || a.viscous_negative != b.viscous_negative ||
           a.coulomb_positive != b.coulomb_positive || a.coulomb_negative != b.coulomb_negative ||
           a.static_positive != b.static_positive || a.static_negative != b.static_negative;
  };
  out.trolley_friction_adapted = differs(trolley_in_use_, crane.trolley_friction);
  out.slew_friction_adapted = differs(slew_in_use_, crane.slew_friction);
  out.trolley_limit_cycle = trolley_cycles_.fired();
  out.slew_limit_cycle = slew_cycles_.fired();
  out.trolley_voltage_sign_changes = trolley_cycles_.sign_changes_at_rest();
  out.slew_voltage_sign_changes = slew_cycles_.sign_changes_at_rest();

  // Payload mass: m_t M and m_r J_o, inverse-variance weighted over the axes that identified it.
  double weight_sum = 0.0;
  double weighted = 0.0;
  bool exact = false;
  double exact_mass = 0.0;
  const auto add = [&](const AxisIdentifier& id, double to_mass) {
    const AxisIdentification& s = id.identification();
    if (!s.load_excited || s.solves == 0) return;
    const double mass = s.estimate(kLoadIndex) * to_mass;
    const double sd = s.standard_deviation(kLoadIndex) * to_mass;
    if (sd <= 0.0) {
      exact = true;
      exact_mass = mass;
      return;
    }
    weight_sum += 1.0 / (sd * sd);
    weighted += mass / (sd * sd);
  };
  add(trolley_, crane.trolley_drive_mass);
  add(slew_, crane.jib_inertia);
  double mass = crane.load_mass;
  double bound = 0.0;
  bool identified = false;
  if (exact) {
    mass = exact_mass;
    identified = true;
  } else if (weight_sum > 0.0) {
    mass = weighted / weight_sum;
    bound = 2.0 / std::sqrt(weight_sum);
    identified = true;
  }
  const bool confident_now = identified && std::isfinite(mass) && mass >= params_.min_mass &&
                             mass <= params_.max_mass && bound <= params_.mass_relative_bound * mass;
  if (confident_now) {
    ever_confident_ = true;
    confident_mass_ = mass;
    confident_bound_ = bound;
  }
  // Once confident, the last confident estimate stays in use until a better one replaces it.
  out.payload_confident = ever_confident_;
  out.payload_mass = ever_confident_ ? confident_mass_ : mass;
  out.payload_mass_bound = ever_confident_ ? confident_bound_ : bound;
}

}  // namespace crane::adaptation
