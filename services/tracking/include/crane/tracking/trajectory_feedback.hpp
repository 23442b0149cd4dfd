#pragma once
// The tracking law of a trajectory that carries its own feedback law (common::TrajectoryFeedback):
// the minimum-time follower's feedforward plus time-varying LQR (optimal_control/
// trajectory_follower.hpp, docs/optimal_control.md), computed by the planner and applied here each
// cycle:
//   u_r = feedforward_r - sum_j (K_r,j (q_j - q_ref,j) + K_r,4+j (q'_j - q'_ref,j)),  |u_r| <= voltage_limit
// over the model's slots j = 0..3 (trolley, in-plane swing, second axis, out-of-plane swing).
//
// Errors: none thrown; a non-finite input gives a non-finite voltage, which the caller refuses.

#include <array>

#include "crane/common/crane_signals.hpp"

namespace crane::tracking {

/// The drive voltages [V] (trolley, second axis) of `law` at the measured `position` [m, rad, rad
/// or m, rad] and `velocity` (the same slots, per second), each clamped to +-voltage_limit [V].
[[nodiscard]] std::array<double, 2> trajectory_feedback_voltages(const common::TrajectoryFeedback& law,
                                                                 const std::array<double, 4>& position,
                                                                 const std::array<double, 4>& velocity,
                                                                 double voltage_limit) noexcept;

}  // namespace crane::tracking
