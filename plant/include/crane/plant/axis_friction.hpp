#pragma once
// Plant-truth friction of one drive axis (trolley or slew): the model of Omar 2003, (3.1)-(3.3),
// taken as an exact hybrid law instead of the smoothed, dead-banded form used for compensation:
//
//   sliding (v != 0):  F_f = -(c_s + b_s |v|) * s,   s = sign(v), c_s, b_s direction dependent
//                      (Coulomb opposes the motion, ERRATA);
//   at rest (v = 0):   the axis sticks while the driving force D that friction must hold
//                      (all other generalized forces on the axis, minus inertial coupling) stays
//                      within  -F_static_negative <= D <= F_static_positive, else it breaks away
//                      toward sign(D).
//
// Coefficients come in common::AxisFriction volt-equivalents; a coefficient k [V] (or [V s/m])
// becomes the force k * force_per_volt [N] (or [N s/m]), force_per_volt = mass * K_m, i.e.
// M_drive*K_mx [N/V] for the trolley and J_o*K_mgamma [N m/V] for the slew. Units below say [N];
// read [N m] and [rad/s] for the slew.
//
// Brake: an engaged brake adds `brake_holding_force` to both the static thresholds and the Coulomb
// level, so a moving axis decelerates hard and then locks.
//
// A static threshold smaller than the Coulomb level would make "break away" inconsistent (the axis
// would break away and decelerate at once); the effective threshold is max(static, Coulomb).
//
// Errors: the constructor throws common::ConfigError for invalid coefficients; the rest is noexcept.

#include "crane/common/crane_parameters.hpp"

namespace crane::plant {

class AxisFrictionModel {
 public:
  /// `friction` in volt-equivalents (validated with `field_prefix`), `force_per_volt` [N/V] > 0,
  /// `brake_holding_force` [N] >= 0. Throws common::ConfigError naming the field.
  AxisFrictionModel(const common::AxisFriction& friction, double force_per_volt, double brake_holding_force,
                    const char* field_prefix = "friction");
  AxisFrictionModel() = default;  // frictionless, no brake

  /// Sliding friction force [N] for motion in `direction` (+1 or -1) at velocity `velocity` [m/s]
  /// (only |velocity| is used): -(c + b |v|) * direction, (3.1) with eta/xi selected by direction.
  [[nodiscard]] double sliding_force(double velocity, int direction, bool brake_engaged) const noexcept;

  /// Largest driving force toward + [N] the axis holds at rest (>= 0).
  [[nodiscard]] double holding_limit_positive(bool brake_engaged) const noexcept;
  /// Largest driving force toward - [N] (magnitude, >= 0) the axis holds at rest.
  [[nodiscard]] double holding_limit_negative(bool brake_engaged) const noexcept;

  /// Stick margin [N] for driving force `driving_force` [N]: min(limit+ - D, D + limit-).
  /// >= 0 while the axis stays stuck; the integrator uses it as a root function.
  [[nodiscard]] double stick_margin(double driving_force, bool brake_engaged) const noexcept;

  /// True when an axis at rest can stick at all (a nonzero holding range).
  [[nodiscard]] bool can_stick(bool brake_engaged) const noexcept;

  /// Decision at zero velocity: 0 = stays stuck, +1/-1 = breaks away in that direction.
  [[nodiscard]] int motion_at_rest(double driving_force, bool brake_engaged) const noexcept;

 private:
  double viscous_positive_{0.0};   // [N s/m]
  double viscous_negative_{0.0};   // [N s/m]
  double coulomb_positive_{0.0};   // [N]
  double coulomb_negative_{0.0};   // [N]
  double static_positive_{0.0};    // [N] effective: max(static, Coulomb)
  double static_negative_{0.0};    // [N]
  double brake_holding_force_{0.0};  // [N]
};

}  // namespace crane::plant
