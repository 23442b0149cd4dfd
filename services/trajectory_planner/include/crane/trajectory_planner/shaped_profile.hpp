#pragma once
// Input-shaped rest-to-rest profile: a TrapezoidProfile (3.43) convolved with an InputShaper
// (ZV, ZVD or EI) tuned to the load swing w = sqrt(g/L).
//   x_shaped(t) = sum_i A_i x_base(t - t_i),
// and likewise for velocity and acceleration. The amplitudes are >= 0 and sum to 1, so the shaped
// velocity and acceleration stay within the base limits: the base trapezoid uses v_max and a_max
// as given, and the shaped result respects them too. Duration = base duration + shaper length.
//
// Hoisting during the move: reschedule_for_hoisting() makes the impulse times follow the swing
// period of the reference cable length L(t) instead of the length the shaper was designed for,
//   t_i(t) = t_i T(L(t)) / T_design,  T(L) = 2 pi sqrt(L / g),
//   x_shaped(t) = sum_i A_i x_base(t - t_i(t)),
// with the velocity and acceleration differentiated through t_i(t) (chain rule). This is the usual
// gain-scheduled ("adaptive") shaper for slowly varying L, not an exact zero-vibration condition
// for a pendulum of varying length: tests/trajectory_profiles measures what it leaves.
//
// Held by value, no allocation; plan() is noexcept for run-time use.

#include "crane/trajectory_planner/axis_profile.hpp"
#include "crane/trajectory_planner/input_shaper.hpp"
#include "crane/trajectory_planner/trapezoid_profile.hpp"

namespace crane::trajectory_planner {

class ShapedProfile final : public AxisProfile {
 public:
  /// A zero-length profile at 0.
  ShapedProfile() = default;
  /// Throws common::ConfigError naming the field, value and bound unless start/target [m or rad]
  /// are finite, limits are finite and > 0, and `shaper` is valid (see InputShaper).
  ShapedProfile(double start, double target, const AxisLimits& limits, const ShaperParams& shaper);

  /// As the constructor without exceptions; invalid_parameters leaves *this unchanged.
  ProfileStatus plan(double start, double target, const AxisLimits& limits,
                     const ShaperParams& shaper) noexcept;

  /// Follow the reference cable length `cable_length` [m] over the move (see the file comment).
  /// invalid_parameters (nothing changed) unless gravity [m/s^2] > 0 and the cable profile stays
  /// > 0. Call after plan(); a later plan() drops the rescheduling.
  ProfileStatus reschedule_for_hoisting(const TrapezoidProfile& cable_length, double gravity) noexcept;
  [[nodiscard]] bool hoisting() const noexcept { return hoisting_; }

  [[nodiscard]] double duration() const noexcept override;
  [[nodiscard]] common::AxisReference sample(double time) const noexcept override;

  [[nodiscard]] const TrapezoidProfile& base() const noexcept { return base_; }
  [[nodiscard]] const InputShaper& shaper() const noexcept { return shaper_; }

 private:
  TrapezoidProfile base_;
  InputShaper shaper_;
  double design_period_{0.0};   // [s] 2 pi / natural_frequency of the shaper as designed
  bool hoisting_{false};
  TrapezoidProfile cable_;      // [m] reference cable length while hoisting_
  double gravity_{9.8};         // [m/s^2]
  double longest_period_{0.0};  // [s] T at the longest cable length of the move
};

}  // namespace crane::trajectory_planner
