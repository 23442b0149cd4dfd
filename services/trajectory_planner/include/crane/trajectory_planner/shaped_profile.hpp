#pragma once
// Input-shaped rest-to-rest profile: a TrapezoidProfile (3.43) convolved with an InputShaper
// (ZV, ZVD or EI) tuned to the load swing w = sqrt(g/L).
//   x_shaped(t) = sum_i A_i x_base(t - t_i),
// and likewise for velocity and acceleration. The amplitudes are >= 0 and sum to 1, so the shaped
// velocity and acceleration stay within the base limits: the base trapezoid uses v_max and a_max
// as given, and the shaped result respects them too. Duration = base duration + shaper length.
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

  [[nodiscard]] double duration() const noexcept override;
  [[nodiscard]] common::AxisReference sample(double time) const noexcept override;

  [[nodiscard]] const TrapezoidProfile& base() const noexcept { return base_; }
  [[nodiscard]] const InputShaper& shaper() const noexcept { return shaper_; }

 private:
  TrapezoidProfile base_;
  InputShaper shaper_;
};

}  // namespace crane::trajectory_planner
