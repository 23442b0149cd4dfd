#include "crane/trajectory_planner/shaped_profile.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "crane/common/validation.hpp"

namespace crane::trajectory_planner {

ShapedProfile::ShapedProfile(double start, double target, const AxisLimits& limits,
                             const ShaperParams& shaper) {
  common::require_finite("shaped_profile.start", start);
  common::require_finite("shaped_profile.target", target);
  common::require_greater("shaped_profile.max_velocity", limits.max_velocity, 0.0);
  common::require_greater("shaped_profile.max_acceleration", limits.max_acceleration, 0.0);
  shaper_ = InputShaper(shaper);  // throws on an invalid shaper
  design_period_ = 2.0 * std::numbers::pi / shaper.natural_frequency;
  base_.plan(start, target, limits);
}

ProfileStatus ShapedProfile::plan(double start, double target, const AxisLimits& limits,
                                  const ShaperParams& shaper) noexcept {
  if (!std::isfinite(start) || !std::isfinite(target) || !std::isfinite(limits.max_velocity) ||
      !std::isfinite(limits.max_acceleration) || !(limits.max_velocity > 0.0) ||
      !(limits.max_acceleration > 0.0)) {
    return ProfileStatus::invalid_parameters;
  }
  InputShaper designed;
  if (designed.design(shaper) != ProfileStatus::ok) return ProfileStatus::invalid_parameters;
  shaper_ = designed;
  design_period_ = 2.0 * std::numbers::pi / shaper.natural_frequency;
  hoisting_ = false;
  base_.plan(start, target, limits);
  return ProfileStatus::ok;
}

ProfileStatus ShapedProfile::reschedule_for_hoisting(const TrapezoidProfile& cable_length, double gravity) noexcept {
  const double first = cable_length.sample(0.0).position;
  const double last = cable_length.sample(cable_length.duration()).position;
  // A trapezoid is monotonic: its extremes are its ends.
  if (!(gravity > 0.0) || !std::isfinite(gravity) || !(std::min(first, last) > 0.0) || !(design_period_ > 0.0)) {
    return ProfileStatus::invalid_parameters;
  }
  cable_ = cable_length;
  gravity_ = gravity;
  longest_period_ = 2.0 * std::numbers::pi * std::sqrt(std::max(first, last) / gravity);
  hoisting_ = true;
  return ProfileStatus::ok;
}

double ShapedProfile::duration() const noexcept {
  if (!hoisting_) return base_.duration() + shaper_.length();
  return std::max(base_.duration() + shaper_.length() * longest_period_ / design_period_, cable_.duration());
}

common::AxisReference ShapedProfile::sample(double time) const noexcept {
  common::AxisReference reference;
  if (time >= duration()) {
    // Exactly the target at rest (the sum of A_i * target may differ from target by rounding).
    reference.position = base_.sample(base_.duration()).position;
    return reference;
  }
  if (!hoisting_) {
    for (std::size_t i = 0; i < shaper_.impulse_count(); ++i) {
      const common::AxisReference delayed = base_.sample(time - shaper_.time(i));
      const double a = shaper_.amplitude(i);
      reference.position += a * delayed.position;
      reference.velocity += a * delayed.velocity;
      reference.acceleration += a * delayed.acceleration;
    }
    return reference;
  }
  // Period of the reference cable length and its first two time derivatives:
  // T = 2 pi sqrt(L/g), T' = pi L' / sqrt(g L), T'' = pi (L'' / sqrt(g L) - L'^2 / (2 sqrt(g) L^1.5)).
  const common::AxisReference cable = cable_.sample(time);
  const double L = cable.position;
  const double sg = std::sqrt(gravity_);
  const double period = 2.0 * std::numbers::pi * std::sqrt(L) / sg;
  const double period_rate = std::numbers::pi * cable.velocity / (sg * std::sqrt(L));
  const double period_acceleration = std::numbers::pi * (cable.acceleration / (sg * std::sqrt(L)) -
                                                         cable.velocity * cable.velocity / (2.0 * sg * L * std::sqrt(L)));
  for (std::size_t i = 0; i < shaper_.impulse_count(); ++i) {
    const double c = shaper_.time(i) / design_period_;  // impulse time in periods
    const double delay = c * period;
    const double delay_rate = c * period_rate;
    const double delay_acceleration = c * period_acceleration;
    const common::AxisReference delayed = base_.sample(time - delay);
    const double a = shaper_.amplitude(i);
    const double stretch = 1.0 - delay_rate;  // d(t - t_i(t))/dt
    reference.position += a * delayed.position;
    reference.velocity += a * delayed.velocity * stretch;
    reference.acceleration += a * (delayed.acceleration * stretch * stretch - delayed.velocity * delay_acceleration);
  }
  return reference;
}

}  // namespace crane::trajectory_planner
