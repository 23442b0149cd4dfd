#include "crane/friction_compensation/friction_compensation.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::friction_compensation {
namespace {

void validate_axis(const AxisCompensationParams& axis, const std::string& prefix) {
  common::validate(axis.friction, (prefix + ".friction").c_str());
  common::require_at_least(prefix + ".zero_velocity_band", axis.zero_velocity_band, 0.0);
  common::require_greater(prefix + ".stiction_slope", axis.stiction_slope, 0.0);
  if (axis.velocity_source != VelocitySource::raw && axis.velocity_source != VelocitySource::filtered) {
    throw common::ConfigError(prefix + ".velocity_source = " +
                              std::to_string(static_cast<int>(axis.velocity_source)) +
                              " is not a VelocitySource");
  }
}

constexpr double kMaxFrictionFactor = 100.0;  // a larger factor is refused (the safe output)

FrictionCompensationParams validated(const FrictionCompensationParams& params) {
  validate_axis(params.trolley, "friction_compensation.trolley");
  validate_axis(params.slew, "friction_compensation.slew");
  common::require_greater("friction_compensation.voltage_limit", params.voltage_limit, 0.0);
  return params;
}

double clamp_voltage(double value, double limit, bool& saturated) {
  saturated = std::abs(value) > limit;
  return std::clamp(value, -limit, limit);
}

}  // namespace

int friction_direction(double velocity, double zero_velocity_band) noexcept {
  if (velocity > zero_velocity_band) return 1;
  if (velocity < -zero_velocity_band) return -1;
  return 0;
}

std::array<double, 4> friction_regressor(double velocity, int direction) noexcept {
  const double eta = direction > 0 ? 1.0 : 0.0;
  const double xi = direction < 0 ? 1.0 : 0.0;
  return {velocity * eta, velocity * xi, eta, -xi};
}

std::array<double, 4> sliding_coefficients(const common::AxisFriction& f) noexcept {
  return {f.viscous_positive, f.viscous_negative, f.coulomb_positive, f.coulomb_negative};
}

double sliding_friction_voltage(const common::AxisFriction& friction, double velocity, int direction) noexcept {
  const auto r = friction_regressor(velocity, direction);
  const auto c = sliding_coefficients(friction);
  return c[0] * r[0] + c[1] * r[1] + c[2] * r[2] + c[3] * r[3];
}

double kept_sliding_share(double sliding_friction_reduction, double friction_factor) noexcept {
  return std::min(1.0, (1.0 - sliding_friction_reduction) * friction_factor);
}

double friction_voltage(const AxisCompensationParams& axis, double velocity,
                        double commanded_voltage) noexcept {
  const auto& f = axis.friction;
  const int direction = friction_direction(velocity, axis.zero_velocity_band);
  if (direction != 0) {  // eta = 1: c+ + b+ v with the motion; xi = 1: -(c- + b- |v|)   (3.1), (3.3)
    return sliding_friction_voltage(f, velocity, direction);
  }
  // Stiction (3.2): F_fs = f_sh + f_s tanh(A V), -> +fs+ (V >> 0), -> -fs- (V << 0).
  const double f_s = 0.5 * (f.static_positive + f.static_negative);
  const double f_sh = 0.5 * (f.static_positive - f.static_negative);
  return f_sh + f_s * std::tanh(axis.stiction_slope * commanded_voltage);
}

FrictionCompensation::FrictionCompensation(const FrictionCompensationParams& params)
    : params_(validated(params)) {}

common::StepStatus FrictionCompensation::step(const FrictionCompensationInput& input,
                                              FrictionCompensationOutput& output) const noexcept {
  const auto& est = input.estimate;
  const double trolley_velocity = params_.trolley.velocity_source == VelocitySource::raw
                                      ? est.trolley_velocity_raw
                                      : est.trolley_velocity;
  const double slew_velocity =
      params_.slew.velocity_source == VelocitySource::raw ? est.slew_rate_raw : est.slew_rate;
  if (!std::isfinite(trolley_velocity) || !std::isfinite(slew_velocity) ||
      !std::isfinite(input.command.trolley_voltage) || !std::isfinite(input.command.slew_voltage) ||
      !std::isfinite(input.command.hoist_speed) ||
      !(input.sliding_friction_reduction >= 0.0 && input.sliding_friction_reduction <= 1.0) ||
      !(input.friction_factor >= 0.0 && input.friction_factor <= kMaxFrictionFactor)) {
    output = FrictionCompensationOutput{};
    return common::StepStatus::rejected_nonfinite;
  }
  output = FrictionCompensationOutput{};
  if (params_.enabled) {
    // The friction in use: the online estimate when given and sane, the configured otherwise.
    const auto in_use = [](const AxisCompensationParams& configured, const std::optional<common::AxisFriction>& estimate) {
      if (!estimate) return configured;
      const auto& f = *estimate;
      for (const double c : {f.viscous_positive, f.viscous_negative, f.coulomb_positive, f.coulomb_negative,
                             f.static_positive, f.static_negative}) {
        if (!std::isfinite(c) || c < 0.0) return configured;
      }
      AxisCompensationParams axis = configured;
      axis.friction = f;
      return axis;
    };
    output.trolley_friction =
        friction_voltage(in_use(params_.trolley, input.trolley_friction), trolley_velocity, input.command.trolley_voltage);
    output.slew_friction =
        friction_voltage(in_use(params_.slew, input.slew_friction), slew_velocity, input.command.slew_voltage);
    const double factor = input.friction_factor > 0.0 ? input.friction_factor : 1.0;
    if (input.sliding_friction_reduction != 0.0 || factor != 1.0) {
      const double kept = kept_sliding_share(input.sliding_friction_reduction, factor);
      output.trolley_friction *=
          friction_direction(trolley_velocity, params_.trolley.zero_velocity_band) != 0 ? kept : factor;
      output.slew_friction *= friction_direction(slew_velocity, params_.slew.zero_velocity_band) != 0 ? kept : factor;
    }
    // Finite inputs can still overflow (a coefficient of 1e284 times a rate of 1e202): the clamp
    // below would pass Inf as the limit and NaN as is, so such a step gives the safe output.
    if (!std::isfinite(output.trolley_friction) || !std::isfinite(output.slew_friction)) {
      output = FrictionCompensationOutput{};
      return common::StepStatus::rejected_nonfinite;
    }
  }
  // (3.5): u = V + F_f/K_m
  output.command.trolley_voltage = clamp_voltage(input.command.trolley_voltage + output.trolley_friction,
                                                 params_.voltage_limit, output.trolley_saturated);
  output.command.slew_voltage = clamp_voltage(input.command.slew_voltage + output.slew_friction,
                                              params_.voltage_limit, output.slew_saturated);
  output.command.hoist_speed = input.command.hoist_speed;
  return common::StepStatus::ok;
}

}  // namespace crane::friction_compensation
