#include "crane/gain_scheduling/gain_schedule.hpp"

#include <cmath>
#include <numbers>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::gain_scheduling {
namespace detail {

// Derivation (notation of gain_schedule.hpp). Closed loop, Laplace, q_r = 0:
//   (s^2 + k K_d s + k K_x)(L s^2 + g) - rho s^2 (k K_psi + f) - rho k K_psid s^3 = 0.
// Desired (3.20) with w0^2 = g/L, a = 4/T = 2 w0/pi (3.21):
//   c3 = 2a + 2 zeta w,  c2 = a^2 + 4 a zeta w + w^2,  c1 = 2 a w^2 + 2 zeta w a^2,  c0 = a^2 w^2.
// Matching (coefficients divided by L):
//   s^3: k K_d - rho k K_psid / L = c3      s^1: w0^2 k K_d = c1
//   s^2: k K_x + (g - rho (k K_psi + f))/L = c2      s^0: w0^2 k K_x = c0
// Partial (K_psid = 0): s^3 and s^1 give w0^2 c3 = c1, i.e.
//   a w^2 + zeta (a^2 - w0^2) w - w0^2 a = 0   (one positive root: the product of roots is < 0);
//   then k K_x = c0/w0^2, K_d = c3/k, and s^2 gives K_psi.
// Full (k = b K given, K_x = 1): s^0 gives w = w0 sqrt(k)/a, s^1 gives K_d = c1/(w0^2 k),
//   s^3 gives K_psid = L (k K_d - c3)/(rho k), and s^2 gives K_psi.
// The printed (3.22)-(3.25) differ from this by factors of 2 in places; this matching reproduces
// (4.18) and (4.21) (see ERRATA.md), so it is taken as the intended one.
GainSchedulingGains place_poles(double cable_length, double gravity, double damping_ratio,
                                double drive_gain, double swing_force, double coupling, bool full,
                                double forward_gain) noexcept {
  const double L = cable_length;
  const double g = gravity;
  const double zeta = damping_ratio;
  const double b = drive_gain;
  const double f = swing_force;
  const double rho = coupling;
  const double w0_sq = g / L;
  const double w0 = std::sqrt(w0_sq);
  const double a = 2.0 * w0 / std::numbers::pi;  // (3.21): 4/a = 2 pi / w0

  GainSchedulingGains gains;
  gains.trolley_pole = a;
  gains.damping_ratio = zeta;
  double w = 0.0;
  double k = 0.0;
  if (full) {
    k = b * forward_gain;
    w = w0 * std::sqrt(k) / a;
  } else {
    const double linear = zeta * (a * a - w0_sq);
    w = (-linear + std::sqrt(linear * linear + 4.0 * a * a * w0_sq)) / (2.0 * a);
  }
  const double c3 = 2.0 * a + 2.0 * zeta * w;
  const double c2 = a * a + 4.0 * a * zeta * w + w * w;
  const double c1 = 2.0 * a * w * w + 2.0 * zeta * w * a * a;
  const double c0 = a * a * w * w;
  double position_gain = 1.0;
  if (!full) {
    const double k_auto = c0 / w0_sq;  // k K_x
    if (forward_gain > 0.0) {
      k = b * forward_gain;
      position_gain = k_auto / k;
    } else {
      k = k_auto;
    }
  }
  gains.forward_gain = k / b;
  gains.position_gain = position_gain;
  gains.natural_frequency = w;
  gains.velocity_gain = full ? c1 / (w0_sq * k) : c3 / k;
  gains.swing_rate_gain = full ? L * (k * gains.velocity_gain - c3) / (rho * k) : 0.0;
  gains.swing_gain = ((g + L * (k * position_gain - c2)) / rho - f) / k;
  return gains;
}

}  // namespace detail

namespace {

void validate_common(double cable_length, double gravity, double damping_ratio) {
  common::require_greater("cable_length", cable_length, 0.0);
  common::require_greater("gravity", gravity, 0.0);
  common::require_in_range("damping_ratio", damping_ratio, 1e-6, 1.0 - 1e-6);
}

void require_nonzero(const char* field, double value) {
  common::require_finite(field, value);
  if (value == 0.0) {
    throw common::ConfigError(std::string(field) + " = " + common::format_value(value) +
                              " is out of range: must be != 0");
  }
}

void validate_trolley(double cable_length, double mass_ratio, double trolley_drive_gain,
                      double gravity, double damping_ratio) {
  validate_common(cable_length, gravity, damping_ratio);
  common::require_at_least("mass_ratio", mass_ratio, 0.0);
  common::require_greater("trolley_drive_gain", trolley_drive_gain, 0.0);
}

void validate_slew(double cable_length, double trolley_position, const SlewModel& model,
                   double gravity, double damping_ratio) {
  validate_common(cable_length, gravity, damping_ratio);
  require_nonzero("trolley_position", trolley_position);
  common::require_at_least("load_inertia_ratio", model.load_inertia_ratio, 0.0);
  common::require_at_least("trolley_inertia_ratio", model.trolley_inertia_ratio, 0.0);
  common::require_greater("slew_drive_gain", model.slew_drive_gain, 0.0);
}

GainSchedulingGains slew_gains(double cable_length, double x, const SlewModel& model, bool full,
                               double forward_gain, double gravity, double damping_ratio) {
  const double inertia = 1.0 + model.trolley_inertia_ratio * x * x;  // 1 + M_r x^2 (2.30)
  return detail::place_poles(cable_length, gravity, damping_ratio, model.slew_drive_gain / inertia,
                             model.load_inertia_ratio * gravity * x / inertia, -x, full,
                             forward_gain);
}

}  // namespace

GainSchedulingGains partial_state_gains(double cable_length, double mass_ratio,
                                        double trolley_drive_gain, std::optional<double> forward_gain,
                                        double gravity, double damping_ratio) {
  validate_trolley(cable_length, mass_ratio, trolley_drive_gain, gravity, damping_ratio);
  if (forward_gain) {
    common::require_greater("forward_gain", *forward_gain, 0.0);
  }
  return detail::place_poles(cable_length, gravity, damping_ratio, trolley_drive_gain,
                             -mass_ratio * gravity, 1.0, false, forward_gain.value_or(0.0));
}

GainSchedulingGains full_state_gains(double cable_length, double mass_ratio, double trolley_drive_gain,
                                     double forward_gain, double gravity, double damping_ratio) {
  validate_trolley(cable_length, mass_ratio, trolley_drive_gain, gravity, damping_ratio);
  common::require_greater("forward_gain", forward_gain, 0.0);
  return detail::place_poles(cable_length, gravity, damping_ratio, trolley_drive_gain,
                             -mass_ratio * gravity, 1.0, true, forward_gain);
}

GainSchedulingGains slew_partial_state_gains(double cable_length, double trolley_position,
                                             const SlewModel& model, std::optional<double> forward_gain,
                                             double gravity, double damping_ratio) {
  validate_slew(cable_length, trolley_position, model, gravity, damping_ratio);
  if (forward_gain) {
    common::require_greater("forward_gain", *forward_gain, 0.0);
  }
  return slew_gains(cable_length, trolley_position, model, false, forward_gain.value_or(0.0), gravity,
                    damping_ratio);
}

GainSchedulingGains slew_full_state_gains(double cable_length, double trolley_position,
                                          const SlewModel& model, double forward_gain, double gravity,
                                          double damping_ratio) {
  validate_slew(cable_length, trolley_position, model, gravity, damping_ratio);
  common::require_greater("forward_gain", forward_gain, 0.0);
  return slew_gains(cable_length, trolley_position, model, true, forward_gain, gravity, damping_ratio);
}

double max_forward_gain(double distance, double voltage_limit) {
  require_nonzero("distance", distance);
  common::require_greater("voltage_limit", voltage_limit, 0.0);
  return voltage_limit / std::abs(distance);
}

}  // namespace crane::gain_scheduling
