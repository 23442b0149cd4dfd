#include "crane/tracking/tracking_controller.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "crane/common/validation.hpp"

namespace crane::tracking {
namespace {

TrackingParams validated(const TrackingParams& p) {
  common::require_at_least("tracking.proportional_gain", p.proportional_gain, 0.0);
  common::require_at_least("tracking.derivative_gain", p.derivative_gain, 0.0);
  common::require_greater("tracking.trolley_drive_gain", p.trolley_drive_gain, 0.0);
  common::require_greater("tracking.slew_drive_gain", p.slew_drive_gain, 0.0);
  common::require_at_least("tracking.mass_ratio", p.mass_ratio, 0.0);
  common::require_at_least("tracking.load_inertia_ratio", p.load_inertia_ratio, 0.0);
  common::require_at_least("tracking.trolley_inertia_ratio", p.trolley_inertia_ratio, 0.0);
  common::require_at_least("tracking.trolley_mass_ratio", p.trolley_mass_ratio, 0.0);
  common::require_greater("tracking.gravity", p.gravity, 0.0);
  common::require_greater("tracking.min_radius", p.min_radius, 0.0);
  common::require_greater("tracking.min_cable_length", p.min_cable_length, 0.0);
  common::require_greater("tracking.voltage_limit", p.voltage_limit, 0.0);
  return p;
}

double clamp_voltage(double value, double limit, bool& saturated) {
  saturated = std::abs(value) > limit;
  return std::clamp(value, -limit, limit);
}

}  // namespace

TrackingParams tracking_params_from(const common::CraneParameters& crane) {
  TrackingParams params;
  params.trolley_drive_gain = crane.trolley_drive_gain;
  params.slew_drive_gain = crane.slew_drive_gain;
  params.mass_ratio = crane.mass_ratio();
  params.load_inertia_ratio = crane.load_inertia_ratio();
  params.trolley_inertia_ratio = crane.trolley_inertia_ratio();
  params.trolley_mass_ratio = crane.trolley_mass / crane.trolley_drive_mass;
  params.gravity = crane.gravity;
  params.voltage_limit = crane.dac_range;
  return params;
}

TrackingController::TrackingController(const TrackingParams& params) : params_(validated(params)) {}

common::StepStatus TrackingController::step(const TrackingInput& input,
                                            TrackingOutput& output) const noexcept {
  const auto& est = input.estimate;
  const auto& ref = input.reference;
  const double used[] = {est.trolley_position, est.trolley_velocity, est.slew_angle, est.slew_rate,
                         est.swing_in_plane, est.swing_out_of_plane, est.cable_length,
                         ref.trolley.position, ref.trolley.velocity, ref.trolley.acceleration,
                         ref.slew.position, ref.slew.velocity, ref.slew.acceleration, ref.cable_length.velocity,
                         input.trolley_anti_swing_action, input.slew_anti_swing_action};
  for (const double value : used) {
    if (!std::isfinite(value)) {
      output = TrackingOutput{};
      return common::StepStatus::rejected_nonfinite;
    }
  }
  const auto& p = params_;
  const double g = p.gravity;
  const double L = std::max(est.cable_length, p.min_cable_length);
  const double T = 2.0 * std::numbers::pi * std::sqrt(L / g);
  const double T2 = T * T;
  const double K_px = p.proportional_gain;
  const double K_dx = p.derivative_gain;

  // Trolley, (3.40) and (3.37).
  const double e = ref.trolley.position - est.trolley_position;
  const double e_dot = ref.trolley.velocity - est.trolley_velocity;
  const double V_xp = (K_px * e + T * K_dx * e_dot) / L;
  const double V_bar_x = V_xp + input.trolley_anti_swing_action;
  // With feedforward the reference acceleration enters where the normalized action does (L/T^2 V_bar
  // is an acceleration): the drive then follows the planned profile and the PD corrects what remains.
  const double a_ff = p.acceleration_feedforward ? ref.trolley.acceleration : 0.0;
  const bool estimated = input.load && std::isfinite(input.load->mass_ratio) && input.load->mass_ratio >= 0.0 &&
                         std::isfinite(input.load->load_inertia_ratio) && input.load->load_inertia_ratio >= 0.0;
  const double m_t = estimated ? input.load->mass_ratio : p.mass_ratio;
  const double V_x = (L / T2 * V_bar_x + a_ff + m_t * g * est.swing_in_plane) / p.trolley_drive_gain;

  // Slew in y = -(x/L) gamma (3.34), x frozen over the cycle; (3.38) with m_r g x theta.
  const double x = est.trolley_position;
  const double x_safe = x < 0.0 ? std::min(x, -p.min_radius) : std::max(x, p.min_radius);
  const double x_bar = x_safe / L;
  const double e_y = -x_bar * (ref.slew.position - est.slew_angle);
  const double e_y_prime = -x_bar * T * (ref.slew.velocity - est.slew_rate);
  const double V_yp = K_px * e_y + K_dx * e_y_prime;
  const double V_bar_y = V_yp + input.slew_anti_swing_action;
  const double M_r = p.trolley_inertia_ratio;
  const double m_r = estimated ? input.load->load_inertia_ratio : p.load_inertia_ratio;
  const double gamma_ff = p.acceleration_feedforward ? ref.slew.acceleration : 0.0;
  const double V_gamma =
      (-L * (1.0 + M_r * x_safe * x_safe) / (x_safe * T2) * V_bar_y + (1.0 + M_r * x_safe * x_safe) * gamma_ff -
       m_r * g * x_safe * est.swing_out_of_plane) / p.slew_drive_gain;

  output = TrackingOutput{};
  output.trolley_tracking_action = V_xp;
  output.trolley_normalized_action = V_bar_x;
  output.swing_period = T;
  output.command.trolley_voltage = clamp_voltage(V_x, p.voltage_limit, output.trolley_saturated);
  if (p.slew_enabled) {
    output.slew_tracking_action = V_yp;
    output.slew_normalized_action = V_bar_y;
    output.command.slew_voltage = clamp_voltage(V_gamma, p.voltage_limit, output.slew_saturated);
  }
  output.command.hoist_speed = ref.cable_length.velocity;
  // Finite but absurd inputs (a corrupted estimate: 1e200 m) can overflow the law to Inf - Inf = NaN,
  // which the voltage clamp passes through: the safe output instead (found by tests/fuzz/topic_gates).
  const double outputs[] = {output.command.trolley_voltage, output.command.slew_voltage, output.trolley_tracking_action,
                            output.slew_tracking_action, output.trolley_normalized_action,
                            output.slew_normalized_action, output.swing_period};
  for (const double value : outputs) {
    if (!std::isfinite(value)) {
      output = TrackingOutput{};
      return common::StepStatus::rejected_nonfinite;
    }
  }
  // The momenta (see the header), with the load's kinematics of tower_crane_model.cpp.
  const double gamma_dot = p.slew_enabled ? est.slew_rate : 0.0;
  const double phi = est.swing_in_plane;
  const double theta = est.swing_out_of_plane;
  const double phi_dot = est.swing_in_plane_rate;
  const double theta_dot = est.swing_out_of_plane_rate;
  const double L_m = est.cable_length;
  const double L_dot = est.cable_length_rate;
  const double c_theta = std::cos(theta), s_theta = std::sin(theta), c_phi = std::cos(phi), s_phi = std::sin(phi);
  const double u[3] = {-c_theta * s_phi, s_theta, -c_theta * c_phi};
  const double u_phi[3] = {-c_theta * c_phi, 0.0, c_theta * s_phi};
  const double u_theta[3] = {s_theta * s_phi, c_theta, s_theta * c_phi};
  const double r_x = x + L_m * u[0];
  const double r_y = L_m * u[1];
  const double r_dot_x = est.trolley_velocity + L_dot * u[0] + L_m * (u_phi[0] * phi_dot + u_theta[0] * theta_dot);
  const double r_dot_y = L_dot * u[1] + L_m * (u_phi[1] * phi_dot + u_theta[1] * theta_dot);
  const double v_x = r_dot_x - gamma_dot * r_y;
  const double v_y = r_dot_y + gamma_dot * r_x;
  output.trolley_momentum = (est.trolley_velocity + m_t * v_x) / p.trolley_drive_gain;
  output.trolley_centripetal_voltage =
      (p.trolley_mass_ratio * x * gamma_dot * gamma_dot + m_t * gamma_dot * v_y) / p.trolley_drive_gain;
  output.slew_momentum =
      p.slew_enabled ? ((1.0 + M_r * x * x) * gamma_dot + m_r * (r_x * v_y - r_y * v_x)) / p.slew_drive_gain : 0.0;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!std::isfinite(output.trolley_momentum) || !std::isfinite(output.trolley_centripetal_voltage) ||
      !std::isfinite(output.slew_momentum)) {
    output.trolley_momentum = output.slew_momentum = output.trolley_centripetal_voltage = nan;
  }
  return common::StepStatus::ok;
}

}  // namespace crane::tracking
