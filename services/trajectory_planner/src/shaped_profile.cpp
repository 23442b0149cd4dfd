#include "crane/trajectory_planner/shaped_profile.hpp"

#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::trajectory_planner {

ShapedProfile::ShapedProfile(double start, double target, const AxisLimits& limits,
                             const ShaperParams& shaper) {
  common::require_finite("shaped_profile.start", start);
  common::require_finite("shaped_profile.target", target);
  common::require_greater("shaped_profile.max_velocity", limits.max_velocity, 0.0);
  common::require_greater("shaped_profile.max_acceleration", limits.max_acceleration, 0.0);
  shaper_ = InputShaper(shaper);  // throws on an invalid shaper
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
  base_.plan(start, target, limits);
  return ProfileStatus::ok;
}

double ShapedProfile::duration() const noexcept { return base_.duration() + shaper_.length(); }

common::AxisReference ShapedProfile::sample(double time) const noexcept {
  common::AxisReference reference;
  if (time >= duration()) {
    // Exactly the target at rest (the sum of A_i * target may differ from target by rounding).
    reference.position = base_.sample(base_.duration()).position;
    return reference;
  }
  for (std::size_t i = 0; i < shaper_.impulse_count(); ++i) {
    const common::AxisReference delayed = base_.sample(time - shaper_.time(i));
    const double a = shaper_.amplitude(i);
    reference.position += a * delayed.position;
    reference.velocity += a * delayed.velocity;
    reference.acceleration += a * delayed.acceleration;
  }
  return reference;
}

}  // namespace crane::trajectory_planner
