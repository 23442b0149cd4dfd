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

}  // namespace

TrajectoryPlanner::TrajectoryPlanner(const TrajectoryPlannerParams& params) : params_(params) {
  require_ordered("trajectory_planner.trolley_min_position", params.trolley_min_position,
                  "trajectory_planner.trolley_max_position", params.trolley_max_position);
  require_ordered("trajectory_planner.slew_min_angle", params.slew_min_angle,
                  "trajectory_planner.slew_max_angle", params.slew_max_angle);
  common::require_greater("trajectory_planner.cable_min_length", params.cable_min_length, 0.0);
  require_ordered("trajectory_planner.cable_min_length", params.cable_min_length,
                  "trajectory_planner.cable_max_length", params.cable_max_length);
}

void TrajectoryPlanner::plan_axis(Axis& axis, ProfileKind kind, double start, double target,
                                  const AxisLimits& limits) noexcept {
  switch (kind) {
    case ProfileKind::trapezoid:
      axis.trapezoid.plan(start, target, limits);
      axis.kind = ProfileKind::trapezoid;
      break;
    case ProfileKind::step:
      axis.step.plan(target);
      axis.kind = ProfileKind::step;
      break;
  }
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
  if (goal.profile != ProfileKind::step && goal.profile != ProfileKind::trapezoid) {
    return GoalStatus::rejected_invalid_limits;
  }
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
  if (goal.profile == ProfileKind::trapezoid &&
      (!positive_limits(goal.trolley_limits) || !positive_limits(goal.slew_limits) ||
       !positive_limits(goal.cable_limits))) {
    return GoalStatus::rejected_invalid_limits;
  }
  plan_axis(trolley_, goal.profile, current.trolley_position, goal.trolley_target, goal.trolley_limits);
  plan_axis(slew_, goal.profile, current.slew_angle, goal.slew_target, goal.slew_limits);
  plan_axis(cable_, goal.profile, current.cable_length, goal.cable_target, goal.cable_limits);
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
