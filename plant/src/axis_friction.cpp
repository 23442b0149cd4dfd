#include "crane/plant/axis_friction.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::plant {

AxisFrictionModel::AxisFrictionModel(const common::AxisFriction& friction, double force_per_volt,
                                     double brake_holding_force, const char* field_prefix) {
  common::validate(friction, field_prefix);
  const std::string prefix(field_prefix);
  common::require_greater(prefix + ".force_per_volt", force_per_volt, 0.0);
  common::require_at_least(prefix + ".brake_holding_force", brake_holding_force, 0.0);
  viscous_positive_ = friction.viscous_positive * force_per_volt;
  viscous_negative_ = friction.viscous_negative * force_per_volt;
  coulomb_positive_ = friction.coulomb_positive * force_per_volt;
  coulomb_negative_ = friction.coulomb_negative * force_per_volt;
  static_positive_ = std::max(friction.static_positive, friction.coulomb_positive) * force_per_volt;
  static_negative_ = std::max(friction.static_negative, friction.coulomb_negative) * force_per_volt;
  brake_holding_force_ = brake_holding_force;
}

double AxisFrictionModel::sliding_force(double velocity, int direction, bool brake_engaged) const noexcept {
  // (3.1): F_f = (c+ - b+ v) eta + (-c- - b- v) xi written with Coulomb opposing the motion (ERRATA).
  const double brake = brake_engaged ? brake_holding_force_ : 0.0;
  const double speed = std::abs(velocity);
  if (direction >= 0) return -(coulomb_positive_ + brake + viscous_positive_ * speed);
  return coulomb_negative_ + brake + viscous_negative_ * speed;
}

double AxisFrictionModel::holding_limit_positive(bool brake_engaged) const noexcept {
  return static_positive_ + (brake_engaged ? brake_holding_force_ : 0.0);
}

double AxisFrictionModel::holding_limit_negative(bool brake_engaged) const noexcept {
  return static_negative_ + (brake_engaged ? brake_holding_force_ : 0.0);
}

double AxisFrictionModel::stick_margin(double driving_force, bool brake_engaged) const noexcept {
  return std::min(holding_limit_positive(brake_engaged) - driving_force,
                  driving_force + holding_limit_negative(brake_engaged));
}

bool AxisFrictionModel::can_stick(bool brake_engaged) const noexcept {
  return holding_limit_positive(brake_engaged) + holding_limit_negative(brake_engaged) > 0.0;
}

int AxisFrictionModel::motion_at_rest(double driving_force, bool brake_engaged) const noexcept {
  if (can_stick(brake_engaged) && stick_margin(driving_force, brake_engaged) >= 0.0) return 0;
  return driving_force >= 0.0 ? 1 : -1;
}

}  // namespace crane::plant
