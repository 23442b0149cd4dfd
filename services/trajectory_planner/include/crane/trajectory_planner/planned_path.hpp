#pragma once
// A path planned outside the planner's cycle and run by it (issue 32; docs/optimal_control.md):
// the minimum-time bound's trajectory with its follower's feedback law of every cycle
// (optimal_control::plan_minimum_time_move). The planner stage asks for one with a PlanRequest
// when a goal with the minimum-time profile arrives, and starts it (TrajectoryPlanner::start_planned)
// when the caller hands it over; its reference then carries the law of each cycle.
//
// Shapes: every vector has one sample per cycle, sample k at t = k sample_period from the move's
// start; the last is the rest at the target, and its law the hold there. All the same length >= 2.

#include <cstdint>
#include <memory>
#include <vector>

#include "crane/common/crane_signals.hpp"
#include "crane/trajectory_planner/axis_profile.hpp"
#include "crane/trajectory_planner/trapezoid_profile.hpp"

namespace crane::trajectory_planner {

/// The pendulum the load swings as: length a L + c at cable length L [m]. The planner's configured
/// one is trajectory_planner.manual's swing_length_scale a and swing_length_offset c (a calibration,
/// `deploy/crane calibrate swing`); the state estimator learns one online (CraneState_'s
/// swing_length_*, adaptation/swing_length_estimator.hpp). 1 L + 0 is the single pendulum.
struct EquivalentPendulum {
  double scale{1.0};   // a [-], in [kMinSwingLengthScale, kMaxSwingLengthScale]
  double offset{0.0};  // c [m], in [kMinSwingLengthOffset, kMaxSwingLengthOffset]
};
inline constexpr double kMinSwingLengthScale = 0.1, kMaxSwingLengthScale = 10.0;    // [-]
inline constexpr double kMinSwingLengthOffset = -1.0, kMaxSwingLengthOffset = 10.0;  // [m]

/// [m] a L + c at `cable_length` L [m] (1 L + 0 = L exactly). Not checked > 0.
[[nodiscard]] inline double equivalent_swing_length(const EquivalentPendulum& pendulum, double cable_length) noexcept {
  return pendulum.scale * cable_length + pendulum.offset;
}

/// Whether `pendulum` is one the planner may plan down to the cable length `shortest_cable` [m]: a
/// and c finite and in their ranges above, and a pendulum there (a L + c > 0 at it; a > 0, so at
/// every longer cable too). A configured pendulum must be one over the whole hoist range
/// (shortest_cable = trajectory_planner.cable_min_length); a learnt one over the move's own cable
/// span (what the crane swung at says nothing of much shorter cables; planned_move.hpp). noexcept.
[[nodiscard]] bool swings_down_to(const EquivalentPendulum& pendulum, double shortest_cable) noexcept;

struct PlannedPath {
  double sample_period{0.01};                   // [s] T_s, > 0
  std::vector<common::AxisReference> trolley;   // [m, m/s, m/s^2]
  std::vector<common::AxisReference> slew;      // [rad, rad/s, rad/s^2] (0 without a slew)
  std::vector<common::AxisReference> cable;     // [m, m/s, m/s^2]
  std::vector<common::AxisReference> bridge;    // [m, m/s, m/s^2] an overhead crane's; empty elsewhere
  std::vector<common::TrajectoryFeedback> laws;  // the feedback law of each sample
  double minimum_time{0.0};                     // [s] T* of the bound, <= duration() (the reference's
                                                // move_duration while the path runs)
  /// [s] (samples - 1) T_s.
  [[nodiscard]] double duration() const noexcept {
    return trolley.empty() ? 0.0 : static_cast<double>(trolley.size() - 1) * sample_period;
  }
  /// The sample of time `time` [s] since the start: the nearest, clamped to [0, last].
  [[nodiscard]] std::size_t index(double time) const noexcept;
  /// True when the shapes above hold and every number is finite.
  [[nodiscard]] bool valid() const noexcept;
};

/// One axis of a PlannedPath as a rest-to-rest profile (the sample nearest to t; the last one
/// after the end, with its velocity and acceleration 0). Holds the path by shared pointer, so
/// copies allocate nothing.
class PlannedProfile final : public AxisProfile {
 public:
  PlannedProfile() = default;
  PlannedProfile(std::shared_ptr<const PlannedPath> path, const std::vector<common::AxisReference> PlannedPath::*axis)
      : path_(std::move(path)), axis_(axis) {}
  [[nodiscard]] double duration() const noexcept override { return path_ ? path_->duration() : 0.0; }
  [[nodiscard]] common::AxisReference sample(double time) const noexcept override;

 private:
  std::shared_ptr<const PlannedPath> path_;
  const std::vector<common::AxisReference> PlannedPath::*axis_{nullptr};
};

/// What the planner stage asks to be planned: a goal with the minimum-time profile, from rest.
struct PlanRequest {
  std::uint64_t sequence{0};    // increases with every request the stage makes (a goal asked again, e.g.
                                // after a mode change, gets a new one): provide_plan answers one
  std::uint32_t request_id{0};  // the move request's
  double trolley_from{0.0}, slew_from{0.0}, cable_from{1.0};  // [m, rad, m] the rest it starts from
  double trolley_target{0.0}, slew_target{0.0}, cable_target{1.0};  // [m, rad, m]
  AxisLimits trolley_limits{}, slew_limits{}, cable_limits{};  // rated speed and acceleration (the goal's)
  bool bridge{false};                                           // an overhead crane: the bridge moves too
  double bridge_from{0.0}, bridge_target{0.0};                  // [m]
  AxisLimits bridge_limits{};
  double max_swing{0.0};  // [rad] the supervisor's sway limit (SupervisorStatus.max_swing)
  EquivalentPendulum swing{};  // the pendulum to plan: the estimate's when the state estimator has
                               // learnt one that swings over the move's cable span, else the
                               // configured (manual's)
  double robust_length_range{0.0};  // [-] in [0, 0.5]: TrajectoryPlannerParams::robust_length_range where
                                    // `swing` is the configured pendulum, else 0 (not robust)
  double robust_margin{0.0};        // [-] in [0, 0.5]: TrajectoryPlannerParams::robust_margin, with it
};

}  // namespace crane::trajectory_planner
