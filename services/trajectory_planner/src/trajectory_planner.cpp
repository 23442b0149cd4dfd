#include "crane/trajectory_planner/trajectory_planner.hpp"

#include <algorithm>
#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::trajectory_planner {
namespace {

void require_ordered(const char* min_field, double min_value, const char* max_field, double max_value) {
  common::require_finite(min_field, min_value);
  common::require_greater(max_field, max_value, min_value);
}

bool finite_limits(const AxisLimits& limits) {
  return std::isfinite(limits.max_velocity) && std::isfinite(limits.max_acceleration);
}
bool positive_limits(const AxisLimits& limits) {
  return limits.max_velocity > 0.0 && limits.max_acceleration > 0.0;
}

bool known_profile(ProfileKind kind) {
  switch (kind) {
    case ProfileKind::step:
    case ProfileKind::trapezoid:
    case ProfileKind::zv:
    case ProfileKind::zvd:
    case ProfileKind::ei:
    case ProfileKind::time_optimal: return true;
  }
  return false;
}

ShaperKind shaper_kind(ProfileKind kind) {
  if (kind == ProfileKind::zv) return ShaperKind::zv;
  if (kind == ProfileKind::ei) return ShaperKind::ei;
  return ShaperKind::zvd;
}

}  // namespace

TrajectoryPlanner::TrajectoryPlanner(const TrajectoryPlannerParams& params) : params_(params) {
  require_ordered("trajectory_planner.trolley_min_position", params.trolley_min_position,
                  "trajectory_planner.trolley_max_position", params.trolley_max_position);
  require_ordered("trajectory_planner.slew_min_angle", params.slew_min_angle,
                  "trajectory_planner.slew_max_angle", params.slew_max_angle);
  common::require_greater("trajectory_planner.cable_min_length", params.cable_min_length, 0.0);
  require_ordered("trajectory_planner.cable_min_length", params.cable_min_length,
                  "trajectory_planner.cable_max_length", params.cable_max_length);
  common::require_greater("trajectory_planner.gravity", params.gravity, 0.0);
  common::require_in_range("trajectory_planner.swing_damping_ratio", params.swing_damping_ratio, 0.0, 0.3);
  common::require_greater("trajectory_planner.ei_vibration_tolerance", params.ei_vibration_tolerance, 0.0);
  common::require_in_range("trajectory_planner.ei_vibration_tolerance", params.ei_vibration_tolerance,
                           0.0, 0.2);
}

bool TrajectoryPlanner::plan_axis(Axis& axis, ProfileKind kind, double start, double target,
                                  const AxisLimits& limits, double swing_frequency) const noexcept {
  bool planned = false;  // stays false for a value outside the enum
  switch (kind) {
    case ProfileKind::step:
      axis.step.plan(target);
      planned = true;
      break;
    case ProfileKind::trapezoid:
      axis.trapezoid.plan(start, target, limits);
      planned = true;
      break;
    case ProfileKind::zv:
    case ProfileKind::zvd:
    case ProfileKind::ei: {
      const ShaperParams shaper{shaper_kind(kind), swing_frequency, params_.swing_damping_ratio,
                                params_.ei_vibration_tolerance};
      planned = axis.shaped.plan(start, target, limits, shaper) == ProfileStatus::ok;
      break;
    }
    case ProfileKind::time_optimal:
      planned = axis.time_optimal.plan(start, target, limits, swing_frequency) == ProfileStatus::ok;
      break;
  }
  if (planned) axis.kind = kind;
  return planned;
}

GoalStatus TrajectoryPlanner::hold(const common::CraneStateEstimate& current) noexcept {
  if (!std::isfinite(current.trolley_position) || !std::isfinite(current.slew_angle) ||
      !std::isfinite(current.cable_length)) {
    return GoalStatus::rejected_nonfinite;
  }
  trolley_.step.plan(current.trolley_position);
  slew_.step.plan(current.slew_angle);
  cable_.step.plan(current.cable_length);
  trolley_.kind = ProfileKind::step;
  slew_.kind = ProfileKind::step;
  cable_.kind = ProfileKind::step;
  phase_ = MovePhase::holding;
  time_in_move_ = 0.0;
  move_duration_ = 0.0;
  ready_ = true;
  return GoalStatus::accepted;
}

GoalStatus TrajectoryPlanner::start_move(const MoveGoal& goal,
                                         const common::CraneStateEstimate& current) noexcept {
  const double values[] = {goal.trolley_target,    goal.slew_target,        goal.cable_target,
                           current.trolley_position, current.slew_angle,  current.cable_length};
  for (const double value : values) {
    if (!std::isfinite(value)) return GoalStatus::rejected_nonfinite;
  }
  if (!finite_limits(goal.trolley_limits) || !finite_limits(goal.slew_limits) ||
      !finite_limits(goal.cable_limits)) {
    return GoalStatus::rejected_nonfinite;
  }
  if (!known_profile(goal.profile)) return GoalStatus::rejected_unknown_profile;
  if (goal.trolley_target < params_.trolley_min_position ||
      goal.trolley_target > params_.trolley_max_position) {
    return GoalStatus::rejected_trolley_out_of_range;
  }
  if (goal.slew_target < params_.slew_min_angle || goal.slew_target > params_.slew_max_angle) {
    return GoalStatus::rejected_slew_out_of_range;
  }
  if (goal.cable_target < params_.cable_min_length || goal.cable_target > params_.cable_max_length) {
    return GoalStatus::rejected_cable_out_of_range;
  }
  if (goal.profile != ProfileKind::step &&
      (!positive_limits(goal.trolley_limits) || !positive_limits(goal.slew_limits) ||
       !positive_limits(goal.cable_limits))) {
    return GoalStatus::rejected_invalid_limits;
  }
  // Load swing w = sqrt(g/L) for the trolley (in-plane) and the slew (out-of-plane, same w). A
  // non-positive measured length gives w = 0, which the swing-aware profiles reject.
  const double swing_frequency =
      current.cable_length > 0.0 ? std::sqrt(params_.gravity / current.cable_length) : 0.0;
  const ProfileKind cable_kind =
      goal.profile == ProfileKind::step ? ProfileKind::step : ProfileKind::trapezoid;
  // Plan into temporaries (held by value, no allocation) and commit only if every axis succeeds.
  Axis trolley = trolley_;
  Axis slew = slew_;
  Axis cable = cable_;
  if (!plan_axis(trolley, goal.profile, current.trolley_position, goal.trolley_target,
                 goal.trolley_limits, swing_frequency) ||
      !plan_axis(slew, goal.profile, current.slew_angle, goal.slew_target, goal.slew_limits,
                 swing_frequency) ||
      !plan_axis(cable, cable_kind, current.cable_length, goal.cable_target, goal.cable_limits,
                 swing_frequency)) {
    return GoalStatus::rejected_invalid_limits;
  }
  trolley_ = trolley;
  slew_ = slew;
  cable_ = cable;
  move_duration_ = std::max({trolley_.active().duration(), slew_.active().duration(),
                             cable_.active().duration()});
  time_in_move_ = 0.0;
  request_id_ = goal.request_id;
  phase_ = MovePhase::moving;
  ready_ = true;
  return GoalStatus::accepted;
}

common::StepStatus TrajectoryPlanner::step(double dt, PlannerOutput& output) noexcept {
  if (!std::isfinite(dt) || dt < 0.0) return common::StepStatus::rejected_nonfinite;
  if (!ready_) return common::StepStatus::not_ready;
  if (phase_ == MovePhase::moving) {
    time_in_move_ += dt;
    if (time_in_move_ >= move_duration_) phase_ = MovePhase::arrived;
  }
  output.reference.trolley = trolley_.active().sample(time_in_move_);
  output.reference.slew = slew_.active().sample(time_in_move_);
  output.reference.cable_length = cable_.active().sample(time_in_move_);
  output.phase = phase_;
  output.request_id = request_id_;
  output.time_in_move = time_in_move_;
  output.move_duration = move_duration_;
  return common::StepStatus::ok;
}

void TrajectoryPlanner::reset() noexcept {
  ready_ = false;
  phase_ = MovePhase::holding;
  request_id_ = 0;
  time_in_move_ = 0.0;
  move_duration_ = 0.0;
}

}  // namespace crane::trajectory_planner
