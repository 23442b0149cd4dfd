#include "crane/trajectory_planner/trapezoid_profile.hpp"

#include <cassert>
#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::trajectory_planner {

TrapezoidProfile::TrapezoidProfile(double start, double target, const AxisLimits& limits) {
  common::require_finite("trapezoid_profile.start", start);
  common::require_finite("trapezoid_profile.target", target);
  common::require_greater("trapezoid_profile.max_velocity", limits.max_velocity, 0.0);
  common::require_greater("trapezoid_profile.max_acceleration", limits.max_acceleration, 0.0);
  plan(start, target, limits);
}

void TrapezoidProfile::plan(double start, double target, const AxisLimits& limits) noexcept {
  assert(std::isfinite(start) && std::isfinite(target));
  assert(std::isfinite(limits.max_velocity) && limits.max_velocity > 0.0);
  assert(std::isfinite(limits.max_acceleration) && limits.max_acceleration > 0.0);
  start_ = start;
  target_ = target;
  const double distance = std::abs(target - start);  // Z
  direction_ = target >= start ? 1.0 : -1.0;
  const double v_max = limits.max_velocity;
  const double a_max = limits.max_acceleration;
  acceleration_ = a_max;
  if (distance >= v_max * v_max / a_max) {
    // (3.43): t_f = t_w + Delta t = Z/v_max + v_max/a_max
    peak_velocity_ = v_max;
    acceleration_time_ = v_max / a_max;
    duration_ = distance / v_max + acceleration_time_;
  } else {
    // Triangular: Z = a Delta t^2, peak a Delta t.
    acceleration_time_ = std::sqrt(distance / a_max);
    peak_velocity_ = a_max * acceleration_time_;
    duration_ = 2.0 * acceleration_time_;
  }
}

common::AxisReference TrapezoidProfile::sample(double time) const noexcept {
  common::AxisReference reference;
  if (!(time > 0.0)) {
    reference.position = start_;
    return reference;
  }
  if (time >= duration_) {
    reference.position = target_;
    return reference;
  }
  const double a = acceleration_;
  const double dt_acc = acceleration_time_;
  double s = 0.0, v = 0.0, acc = 0.0;  // along the direction of motion
  if (time < dt_acc) {
    acc = a;
    v = a * time;
    s = 0.5 * a * time * time;
  } else if (time <= duration_ - dt_acc) {
    v = peak_velocity_;
    s = 0.5 * a * dt_acc * dt_acc + peak_velocity_ * (time - dt_acc);
  } else {
    const double remaining = duration_ - time;
    acc = -a;
    v = a * remaining;
    s = std::abs(target_ - start_) - 0.5 * a * remaining * remaining;
  }
  reference.position = start_ + direction_ * s;
  reference.velocity = direction_ * v;
  reference.acceleration = direction_ * acc;
  return reference;
}

AxisLimits TrapezoidProfile::limits_for_duration(double distance, double duration,
                                                 double acceleration_time) {
  common::require_greater("trapezoid_profile.distance", distance, 0.0);
  common::require_greater("trapezoid_profile.duration", duration, 0.0);
  common::require_in_range("trapezoid_profile.acceleration_time", acceleration_time,
                           0.0, 0.5 * duration);
  common::require_greater("trapezoid_profile.acceleration_time", acceleration_time, 0.0);
  AxisLimits limits;
  limits.max_velocity = distance / (duration - acceleration_time);
  limits.max_acceleration = limits.max_velocity / acceleration_time;
  return limits;
}

}  // namespace crane::trajectory_planner
