#pragma once
// Seam for single-axis reference profiles. TrapezoidProfile (3.43) and StepProfile implement it;
// shaped (ZV, ZVD, EI) and time-optimal profiles are meant to be added as further implementations
// held by value inside TrajectoryPlanner (no allocation at run time).

#include "crane/common/crane_signals.hpp"

namespace crane::trajectory_planner {

/// A rest-to-rest reference for one axis, defined for every t (clamped to [0, duration]).
class AxisProfile {
 public:
  virtual ~AxisProfile() = default;
  /// Time from start to arrival [s], >= 0.
  [[nodiscard]] virtual double duration() const noexcept = 0;
  /// Position [m or rad], velocity and acceleration at time `time` [s] since the start. Before 0 the
  /// start is held, after duration() the target is held (velocity and acceleration 0).
  [[nodiscard]] virtual common::AxisReference sample(double time) const noexcept = 0;

 protected:
  AxisProfile() = default;
  AxisProfile(const AxisProfile&) = default;
  AxisProfile& operator=(const AxisProfile&) = default;
};

}  // namespace crane::trajectory_planner
