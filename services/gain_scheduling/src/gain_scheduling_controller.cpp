#include "crane/gain_scheduling/gain_scheduling_controller.hpp"

#include <algorithm>
#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::gain_scheduling {
namespace {

GainSchedulingParams validated(const GainSchedulingParams& p) {
  common::require_greater("gain_scheduling.trolley_forward_gain", p.trolley_forward_gain, 0.0);
  common::require_greater("gain_scheduling.slew_forward_gain", p.slew_forward_gain, 0.0);
  common::require_greater("gain_scheduling.trolley_drive_gain", p.trolley_drive_gain, 0.0);
  common::require_greater("gain_scheduling.slew_drive_gain", p.slew_drive_gain, 0.0);
  common::require_at_least("gain_scheduling.mass_ratio", p.mass_ratio, 0.0);
  common::require_at_least("gain_scheduling.load_inertia_ratio", p.load_inertia_ratio, 0.0);
  common::require_at_least("gain_scheduling.trolley_inertia_ratio", p.trolley_inertia_ratio, 0.0);
  common::require_greater("gain_scheduling.gravity", p.gravity, 0.0);
  common::require_in_range("gain_scheduling.damping_ratio", p.damping_ratio, 1e-6, 1.0 - 1e-6);
  common::require_greater("gain_scheduling.min_cable_length", p.min_cable_length, 0.0);
  common::require_greater("gain_scheduling.min_radius", p.min_radius, 0.0);
  common::require_greater("gain_scheduling.voltage_limit", p.voltage_limit, 0.0);
  return p;
}

double feedback(const GainSchedulingGains& k, double reference, double position, double velocity,
                double swing, double swing_rate) noexcept {
  return k.forward_gain * (reference - k.position_gain * position - k.velocity_gain * velocity +
                           k.swing_gain * swing + k.swing_rate_gain * swing_rate);
}

}  // namespace

GainSchedulingParams gain_scheduling_params_from(const common::CraneParameters& crane) {
  GainSchedulingParams params;
  params.trolley_drive_gain = crane.trolley_drive_gain;
  params.slew_drive_gain = crane.slew_drive_gain;
  params.mass_ratio = crane.mass_ratio();
  params.load_inertia_ratio = crane.load_inertia_ratio();
  params.trolley_inertia_ratio = crane.trolley_inertia_ratio();
  params.gravity = crane.gravity;
  params.voltage_limit = crane.dac_range;
  return params;
}

GainSchedulingController::GainSchedulingController(const GainSchedulingParams& params)
    : params_(validated(params)) {}

common::StepStatus GainSchedulingController::step(const common::CraneStateEstimate& estimate,
                                                  const common::MotionReference& reference,
                                                  common::DriveCommand& command,
                                                  const common::LoadRatios* load) noexcept {
  const auto& est = estimate;
  const double used[] = {est.trolley_position, est.trolley_velocity, est.slew_angle, est.slew_rate,
                         est.swing_in_plane, est.swing_in_plane_rate, est.swing_out_of_plane,
                         est.swing_out_of_plane_rate, est.cable_length, reference.trolley.position,
                         reference.slew.position, reference.cable_length.velocity};
  for (const double value : used) {
    if (!std::isfinite(value)) {
      command = common::DriveCommand{};
      return common::StepStatus::rejected_nonfinite;
    }
  }
  const auto& p = params_;
  const bool estimated = load != nullptr && std::isfinite(load->mass_ratio) && load->mass_ratio >= 0.0 &&
                         std::isfinite(load->load_inertia_ratio) && load->load_inertia_ratio >= 0.0;
  const double mass_ratio = estimated ? load->mass_ratio : p.mass_ratio;                    // m_t
  const double load_inertia_ratio = estimated ? load->load_inertia_ratio : p.load_inertia_ratio;  // m_r
  const bool full = p.kind == FeedbackKind::full;
  const double L = std::max(est.cable_length, p.min_cable_length);
  const double limit = p.voltage_limit;

  // Trolley: b = K_mx, f = -m_t g, rho = +1 (2.28)-(2.29).
  trolley_gains_ = detail::place_poles(L, p.gravity, p.damping_ratio, p.trolley_drive_gain,
                                       -mass_ratio * p.gravity, 1.0, full,
                                       full ? p.trolley_forward_gain : 0.0);
  command.trolley_voltage =
      std::clamp(feedback(trolley_gains_, reference.trolley.position, est.trolley_position,
                          est.trolley_velocity, est.swing_in_plane, est.swing_in_plane_rate),
                 -limit, limit);

  // Slew at the frozen trolley position (section 3.2.1): J = 1 + M_r x^2, b = K_mg/J,
  // f = m_r g x/J, rho = -x (2.30)-(2.31).
  if (p.slew_enabled) {
    const double x = est.trolley_position;
    const double x_safe = x < 0.0 ? std::min(x, -p.min_radius) : std::max(x, p.min_radius);
    const double inertia = 1.0 + p.trolley_inertia_ratio * x_safe * x_safe;
    slew_gains_ = detail::place_poles(L, p.gravity, p.damping_ratio, p.slew_drive_gain / inertia,
                                      load_inertia_ratio * p.gravity * x_safe / inertia, -x_safe, full,
                                      full ? p.slew_forward_gain : 0.0);
    command.slew_voltage =
        std::clamp(feedback(slew_gains_, reference.slew.position, est.slew_angle, est.slew_rate,
                            est.swing_out_of_plane, est.swing_out_of_plane_rate),
                   -limit, limit);
  } else {
    command.slew_voltage = 0.0;
  }
  command.hoist_speed = reference.cable_length.velocity;
  return common::StepStatus::ok;
}

}  // namespace crane::gain_scheduling
