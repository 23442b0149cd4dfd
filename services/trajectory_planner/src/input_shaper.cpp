#include "crane/trajectory_planner/input_shaper.hpp"

#include <cassert>
#include <cmath>
#include <numbers>

#include "crane/common/validation.hpp"

namespace crane::trajectory_planner {
namespace {

constexpr double kMaxEiDamping = 0.3;
constexpr double kMaxEiTolerance = 0.2;

bool is_ei(ShaperKind kind) { return kind == ShaperKind::ei || kind == ShaperKind::two_hump_ei; }

bool valid(const ShaperParams& p) noexcept {
  if (!std::isfinite(p.natural_frequency) || !(p.natural_frequency > 0.0)) return false;
  if (!std::isfinite(p.damping_ratio) || p.damping_ratio < 0.0 || !(p.damping_ratio < 1.0)) return false;
  if (is_ei(p.kind)) {
    if (p.damping_ratio > kMaxEiDamping) return false;
    if (!std::isfinite(p.vibration_tolerance) || !(p.vibration_tolerance > 0.0) ||
        p.vibration_tolerance > kMaxEiTolerance) {
      return false;
    }
  }
  return true;
}

}  // namespace

const char* to_string(ShaperKind kind) noexcept {
  switch (kind) {
    case ShaperKind::zv: return "zv";
    case ShaperKind::zvd: return "zvd";
    case ShaperKind::ei: return "ei";
    case ShaperKind::mzv: return "mzv";
    case ShaperKind::two_hump_ei: return "two_hump_ei";
  }
  return "zv";
}

double pendulum_natural_frequency(double cable_length, double gravity) {
  common::require_greater("swing_model.cable_length", cable_length, 0.0);
  common::require_greater("swing_model.gravity", gravity, 0.0);
  return std::sqrt(gravity / cable_length);
}

InputShaper::InputShaper(const ShaperParams& params) {
  common::require_greater("input_shaper.natural_frequency", params.natural_frequency, 0.0);
  common::require_at_least("input_shaper.damping_ratio", params.damping_ratio, 0.0);
  if (is_ei(params.kind)) {
    common::require_in_range("input_shaper.damping_ratio", params.damping_ratio, 0.0, kMaxEiDamping);
    common::require_greater("input_shaper.vibration_tolerance", params.vibration_tolerance, 0.0);
    common::require_in_range("input_shaper.vibration_tolerance", params.vibration_tolerance, 0.0,
                             kMaxEiTolerance);
  } else if (!(params.damping_ratio < 1.0)) {
    throw common::ConfigError("input_shaper.damping_ratio = " +
                              common::format_value(params.damping_ratio) +
                              " is out of range: must be < 1");
  }
  const ProfileStatus status = design(params);
  assert(status == ProfileStatus::ok);
  (void)status;
}

ProfileStatus InputShaper::design(const ShaperParams& params) noexcept {
  if (!valid(params)) return ProfileStatus::invalid_parameters;
  const double zeta = params.damping_ratio;
  const double root = std::sqrt(1.0 - zeta * zeta);
  // Damped period T_d = 2 pi / (w sqrt(1 - zeta^2)); K = exp(-zeta pi / sqrt(1 - zeta^2)).
  const double damped_period = 2.0 * std::numbers::pi / (params.natural_frequency * root);
  const double k = std::exp(-zeta * std::numbers::pi / root);
  switch (params.kind) {
    case ShaperKind::zv: {
      // ZV: A = [1, K]/(1 + K) at t = [0, T_d/2].
      count_ = 2;
      amplitudes_ = {1.0 / (1.0 + k), k / (1.0 + k), 0.0};
      times_ = {0.0, 0.5 * damped_period, 0.0};
      break;
    }
    case ShaperKind::zvd: {
      // ZVD: A = [1, 2K, K^2]/(1 + K)^2 at t = [0, T_d/2, T_d].
      const double d = (1.0 + k) * (1.0 + k);
      count_ = 3;
      amplitudes_ = {1.0 / d, 2.0 * k / d, k * k / d};
      times_ = {0.0, 0.5 * damped_period, damped_period};
      break;
    }
    case ShaperKind::ei: {
      const double v = params.vibration_tolerance;
      count_ = 3;
      if (zeta == 0.0) {
        // Undamped EI: A = [(1+V)/4, (1-V)/2, (1+V)/4] at [0, T/2, T]; residual V at w, zero at
        // the two frequencies where cos(pi w'/w) = -(1-V)/(1+V).
        amplitudes_ = {0.25 * (1.0 + v), 0.5 * (1.0 - v), 0.25 * (1.0 + v)};
        times_ = {0.0, 0.5 * damped_period, damped_period};
      } else {
        // Singhose, Seering & Singer 1994, curve fit for 0 <= zeta <= 0.3, 0 <= V <= 0.15.
        const double z2 = zeta * zeta;
        const double a1 = 0.24968 + 0.24961 * v + 0.80008 * zeta + 1.23328 * v * zeta +
                          0.49599 * z2 + 3.17316 * v * z2;
        const double a3 = 0.25149 + 0.21474 * v - 0.83249 * zeta + 1.41498 * v * zeta +
                          0.85181 * z2 - 4.90094 * v * z2;
        const double t2 = 0.49990 + 0.46159 * v * zeta + 4.26169 * v * z2 +
                          1.75601 * v * v * zeta + 8.57843 * v * v * z2;
        amplitudes_ = {a1, 1.0 - a1 - a3, a3};
        times_ = {0.0, t2 * damped_period, damped_period};
      }
      break;
    }
    case ShaperKind::mzv: {
      // Undamped: unit vectors at 0, 135 and 270 deg (t = 0, 3/8 T, 3/4 T) cancel with weights
      // [1 - 1/sqrt(2), sqrt(2) - 1, 1 - 1/sqrt(2)] (x: a1 - a2/sqrt(2) = 0, y: a2/sqrt(2) - a3 = 0,
      // sum 1). Damped: each weight times exp(-zeta w t_i) (so the decayed vectors cancel), then
      // normalized: K^(3/4) and K^(3/2) with K as above.
      const double a = 1.0 - 1.0 / std::sqrt(2.0);
      const double b = (std::sqrt(2.0) - 1.0) * std::pow(k, 0.75);
      const double c = a * std::pow(k, 1.5);
      const double sum = a + b + c;
      count_ = 3;
      amplitudes_ = {a / sum, b / sum, c / sum, 0.0};
      times_ = {0.0, 0.375 * damped_period, 0.75 * damped_period, 0.0};
      break;
    }
    case ShaperKind::two_hump_ei: {
      // Singhose, Porter, Tuttle, Singer 1997, undamped two-hump EI: with
      // X = (V^2 (sqrt(1 - V^2) + 1))^(1/3), A_1 = A_4 = (3 X^2 + 2 X + 3 V^2) / (16 X),
      // A_2 = A_3 = 1/2 - A_1 at t = 0, T/2, T, 3T/2. Damped: the weights times exp(-zeta w t_i),
      // normalized (exact at zeta = 0; an approximation of the damped design above it).
      const double v = params.vibration_tolerance;
      const double x = std::cbrt(v * v * (std::sqrt(1.0 - v * v) + 1.0));
      const double a1 = (3.0 * x * x + 2.0 * x + 3.0 * v * v) / (16.0 * x);
      const double a2 = 0.5 - a1;
      const std::array<double, 4> base{a1, a2, a2, a1};
      double sum = 0.0;
      count_ = 4;
      for (std::size_t i = 0; i < 4; ++i) {
        times_[i] = 0.5 * damped_period * static_cast<double>(i);
        amplitudes_[i] = base[i] * std::pow(k, static_cast<double>(i));
        sum += amplitudes_[i];
      }
      for (double& a : amplitudes_) a /= sum;
      break;
    }
  }
  return ProfileStatus::ok;
}

double InputShaper::amplitude(std::size_t i) const noexcept {
  assert(i < count_);
  return amplitudes_[i];
}

double InputShaper::time(std::size_t i) const noexcept {
  assert(i < count_);
  return times_[i];
}

double InputShaper::mean_delay() const noexcept {
  double sum = 0.0;
  for (std::size_t i = 0; i < count_; ++i) sum += amplitudes_[i] * times_[i];
  return sum;
}

double InputShaper::residual_vibration(double frequency, double damping_ratio) const noexcept {
  // V = exp(-zeta w t_N) sqrt(C^2 + S^2), C = sum A_i exp(zeta w t_i) cos(w_d t_i), S likewise.
  const double damped = frequency * std::sqrt(1.0 - damping_ratio * damping_ratio);
  const double t_last = length();
  double c = 0.0;
  double s = 0.0;
  for (std::size_t i = 0; i < count_; ++i) {
    const double decay = std::exp(-damping_ratio * frequency * (t_last - times_[i]));
    c += amplitudes_[i] * decay * std::cos(damped * times_[i]);
    s += amplitudes_[i] * decay * std::sin(damped * times_[i]);
  }
  return std::hypot(c, s);
}

}  // namespace crane::trajectory_planner
