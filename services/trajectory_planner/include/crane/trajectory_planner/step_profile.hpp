#pragma once
// Step reference: the target at once (as used with the gain-scheduling controller, section 3.2).

#include "crane/trajectory_planner/axis_profile.hpp"

namespace crane::trajectory_planner {

class StepProfile final : public AxisProfile {
 public:
  StepProfile() = default;
  /// Precondition: finite target (asserted).
  void plan(double target) noexcept;
  /// Always 0 [s].
  [[nodiscard]] double duration() const noexcept override { return 0.0; }
  /// Position = target for all t, velocity and acceleration 0.
  [[nodiscard]] common::AxisReference sample(double time) const noexcept override;

 private:
  double target_{0.0};
};

}  // namespace crane::trajectory_planner
