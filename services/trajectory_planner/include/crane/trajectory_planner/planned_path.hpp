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
};

}  // namespace crane::trajectory_planner
