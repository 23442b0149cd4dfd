#pragma once
// Time-optimal rest-to-rest profile under velocity and acceleration limits: bang-bang
// acceleration with a coast phase, (3.43) of H. M. Omar, "Control of Gantry and Tower Cranes", 2003:
//   t_f = Z/v_max + v_max/a_max                  if the distance Z >= v_max^2/a_max,
//   t_f = 2 sqrt(Z/a_max), peak speed sqrt(Z a_max)  otherwise (triangular, v_max not reached).

#include "crane/trajectory_planner/axis_profile.hpp"

namespace crane::trajectory_planner {

/// Limits of one axis.
struct AxisLimits {
  double max_velocity{0.5};      // [m/s] or [rad/s], > 0
  double max_acceleration{1.0};  // [m/s^2] or [rad/s^2], > 0
};

class TrapezoidProfile final : public AxisProfile {
 public:
  /// A zero-length profile at 0.
  TrapezoidProfile() = default;
  /// Throws common::ConfigError naming the field if start/target are not finite or a limit is not
  /// finite and > 0.
  TrapezoidProfile(double start, double target, const AxisLimits& limits);

  /// Re-plans without allocation or exceptions. Preconditions (asserted; the planner validates
  /// first): finite start/target, finite positive limits.
  void plan(double start, double target, const AxisLimits& limits) noexcept;

  [[nodiscard]] double duration() const noexcept override { return duration_; }
  [[nodiscard]] common::AxisReference sample(double time) const noexcept override;

  /// Peak speed actually reached [unit/s] (<= max_velocity).
  [[nodiscard]] double peak_velocity() const noexcept { return peak_velocity_; }
  /// Duration of the acceleration (and of the deceleration) phase [s], Delta t in figure 3.15.
  [[nodiscard]] double acceleration_time() const noexcept { return acceleration_time_; }

  /// Inverse of (3.43): the limits that make a move of `distance` last `duration` with
  /// acceleration phases of `acceleration_time` each, as in (3.54)-(3.55):
  /// v_max = Z/(t_f - Delta t), a_max = v_max/Delta t. Throws common::ConfigError unless
  /// distance > 0 and 0 < acceleration_time <= duration/2 (all finite).
  [[nodiscard]] static AxisLimits limits_for_duration(double distance, double duration,
                                                      double acceleration_time);

 private:
  double start_{0.0};
  double target_{0.0};
  double direction_{1.0};
  double acceleration_{0.0};     // magnitude used [unit/s^2]
  double peak_velocity_{0.0};    // [unit/s]
  double acceleration_time_{0.0};
  double duration_{0.0};
};

}  // namespace crane::trajectory_planner
