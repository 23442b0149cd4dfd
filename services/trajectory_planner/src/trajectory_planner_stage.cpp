#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "crane/common/protocol_signals.hpp"
#include "crane/common/validation.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::trajectory_planner {

using Request = protocol::MoveRequest;

TrajectoryPlannerParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  constexpr double kPi = std::numbers::pi;
  TrajectoryPlannerParams p;
  p.trolley_min_position = s.number("trolley_min_position", -100.0, 100.0);
  p.trolley_max_position = s.number("trolley_max_position", p.trolley_min_position, 100.0);
  p.slew_min_angle = s.number("slew_min_angle", -20.0 * kPi, 20.0 * kPi);
  p.slew_max_angle = s.number("slew_max_angle", p.slew_min_angle, 20.0 * kPi);
  s.finish();
  p.cable_min_length = facts.crane.min_cable_length;
  p.cable_max_length = facts.crane.max_cable_length;
  p.gravity = facts.crane.gravity;
  TrajectoryPlanner{p};
  return p;
}

const char* goal_status_name(GoalStatus s) noexcept {
  switch (s) {
    case GoalStatus::accepted: return "accepted";
    case GoalStatus::rejected_nonfinite: return "rejected: non-finite field";
    case GoalStatus::rejected_trolley_out_of_range: return "rejected: trolley target outside the travel limits";
    case GoalStatus::rejected_slew_out_of_range: return "rejected: slew target outside the slew range";
    case GoalStatus::rejected_cable_out_of_range: return "rejected: cable length target outside its range";
    case GoalStatus::rejected_invalid_limits: return "rejected: velocity or acceleration limit <= 0, or no profile";
    case GoalStatus::rejected_unknown_profile: return "rejected: unknown profile code";
    case GoalStatus::rejected_waypoint:
      return "rejected: more than 8 waypoints, or a waypoint non-finite or out of range";
  }
  return "unknown";
}

MoveGoal to_goal(const Request& r, const common::CraneStateEstimate& current) noexcept {
  MoveGoal g;
  g.request_id = r.request_id;
  switch (r.profile) {
    case Request::PROFILE_STEP: g.profile = ProfileKind::step; break;
    case Request::PROFILE_TRAPEZOID: g.profile = ProfileKind::trapezoid; break;
    case Request::PROFILE_ZV: g.profile = ProfileKind::zv; break;
    case Request::PROFILE_ZVD: g.profile = ProfileKind::zvd; break;
    case Request::PROFILE_EI: g.profile = ProfileKind::ei; break;
    case Request::PROFILE_TIME_OPTIMAL: g.profile = ProfileKind::time_optimal; break;
    default:
      // Not a ProfileKind: start_move() answers rejected_unknown_profile and keeps the running move.
      g.profile = static_cast<ProfileKind>(-1);
      break;
  }
  const bool trolley = (r.axes & Request::AXIS_TROLLEY) != 0;
  const bool slew = (r.axes & Request::AXIS_SLEW) != 0;
  const bool hoist = (r.axes & Request::AXIS_HOIST) != 0;
  // An axis not named in `axes` keeps its current position.
  g.trolley_target = trolley ? r.trolley_target : current.trolley_position;
  g.slew_target = slew ? r.slew_target : current.slew_angle;
  g.cable_target = hoist ? r.cable_length_target : current.cable_length;
  if (r.trolley_max_velocity > 0.0) g.trolley_limits.max_velocity = r.trolley_max_velocity;
  if (r.trolley_max_acceleration > 0.0) g.trolley_limits.max_acceleration = r.trolley_max_acceleration;
  if (r.slew_max_velocity > 0.0) g.slew_limits.max_velocity = r.slew_max_velocity;
  if (r.slew_max_acceleration > 0.0) g.slew_limits.max_acceleration = r.slew_max_acceleration;
  // Waypoints: an axis not named in `axes` stays where it is at every waypoint. More than
  // kMaxWaypoints is passed on as such, and start_move() rejects it.
  g.waypoint_count = r.waypoint_count;
  for (std::size_t i = 0; i < std::min<std::size_t>(g.waypoint_count, kMaxWaypoints); ++i) {
    g.waypoints[i].trolley = trolley ? r.waypoint_trolley[i] : current.trolley_position;
    g.waypoints[i].slew = slew ? r.waypoint_slew[i] : current.slew_angle;
    g.waypoints[i].cable = hoist ? r.waypoint_cable_length[i] : current.cable_length;
  }
  return g;
}

void describe_rejection(GoalStatus status, const MoveGoal& goal, const TrajectoryPlannerParams& params,
                        protocol::MoveStatus& f) noexcept {
  using S = protocol::MoveStatus;
  f.result = S::RESULT_REJECTED;
  f.value = 0.0;
  f.bound_min = 0.0;
  f.bound_max = 0.0;
  switch (status) {
    case GoalStatus::accepted: f.result = S::RESULT_MOVING; f.reason = S::REASON_NONE; return;
    case GoalStatus::rejected_nonfinite: f.reason = S::REASON_NON_FINITE; return;
    case GoalStatus::rejected_trolley_out_of_range:
      f.reason = S::REASON_TROLLEY_RANGE;
      f.value = goal.trolley_target;
      f.bound_min = params.trolley_min_position;
      f.bound_max = params.trolley_max_position;
      return;
    case GoalStatus::rejected_slew_out_of_range:
      f.reason = S::REASON_SLEW_RANGE;
      f.value = goal.slew_target;
      f.bound_min = params.slew_min_angle;
      f.bound_max = params.slew_max_angle;
      return;
    case GoalStatus::rejected_cable_out_of_range:
      f.reason = S::REASON_CABLE_RANGE;
      f.value = goal.cable_target;
      f.bound_min = params.cable_min_length;
      f.bound_max = params.cable_max_length;
      return;
    case GoalStatus::rejected_invalid_limits: f.reason = S::REASON_LIMITS; return;
    case GoalStatus::rejected_unknown_profile: f.reason = S::REASON_PROFILE; return;
    case GoalStatus::rejected_waypoint: f.reason = S::REASON_WAYPOINT; return;
  }
}

TrajectoryPlannerStage::TrajectoryPlannerStage(const TrajectoryPlannerParams& params, double sample_period)
    : planner_(params), sample_period_(sample_period) {
  common::require_greater("stack.sample_period", sample_period, 0.0);
}

void TrajectoryPlannerStage::record(const GoalOutcome& outcome) noexcept {
  if (outcome_count_ < outcomes_.size()) outcomes_[outcome_count_++] = outcome;
}

void TrajectoryPlannerStage::report(std::uint32_t request_id, std::uint8_t result, std::uint8_t reason) noexcept {
  if (status_count_ >= statuses_.size()) return;
  protocol::MoveStatus& s = statuses_[status_count_++];
  s = protocol::MoveStatus{};
  if (cycle_estimate_ != nullptr) common::same_cycle(cycle_estimate_->header, s.header);
  s.request_id = request_id;
  s.result = result;
  s.reason = reason;
  s.trolley_to_go = active_goal_.trolley_target - output_.reference.trolley.position;
  s.slew_to_go = active_goal_.slew_target - output_.reference.slew.position;
  s.cable_to_go = active_goal_.cable_target - output_.reference.cable_length.position;
  s.time_in_move = output_.time_in_move;
  s.move_duration = output_.move_duration;
}

common::StepStatus TrajectoryPlannerStage::step(const protocol::CraneState& estimate,
                                                std::span<const Request> goals,
                                                protocol::Reference& reference) noexcept {
  outcome_count_ = 0;
  status_count_ = 0;
  if (!protocol::all_finite(estimate)) return common::StepStatus::rejected_nonfinite;
  cycle_estimate_ = &estimate;
  const std::uint64_t seq = estimate.header.seq;
  const auto current = common::to_estimate(estimate);
  if (!holding_) {
    holding_ = planner_.hold(current) == GoalStatus::accepted;
    if (!holding_) return common::StepStatus::not_ready;
  }
  using Feedback = protocol::MoveStatus;
  // Starts `r` now: the planner takes it or refuses it (the running move then continues).
  const auto start = [&](const Request& r) {
    const MoveGoal goal = to_goal(r, current);
    const GoalStatus status = planner_.start_move(goal, current);
    if (status == GoalStatus::accepted) {
      if (active_ && active_goal_.request_id != goal.request_id) {
        report(static_cast<std::uint32_t>(active_goal_.request_id), Feedback::RESULT_ABORTED, Feedback::REASON_REPLACED);
      }
      active_goal_ = goal;
      active_ = true;
      cycles_since_progress_ = kProgressCycles;  // report at this cycle's end
    } else if (status_count_ < statuses_.size()) {
      report(r.request_id, Feedback::RESULT_REJECTED);
      describe_rejection(status, goal, planner_.params(), statuses_[status_count_ - 1]);
    }
    return status;
  };
  const auto outcome = [&](const Request& r, GoalOutcome::When when, GoalStatus status) {
    GoalOutcome o;
    o.request_id = r.request_id;
    o.cycle = seq;
    o.asked_cycle = r.header.seq;
    o.when = when;
    o.status = status;
    o.trolley_target = r.trolley_target;
    o.slew_target = r.slew_target;
    record(o);
  };
  for (const auto& request : goals) {
    if (!protocol::all_finite(request)) {
      ++nonfinite_goals_;
      outcome(request, GoalOutcome::When::now, GoalStatus::rejected_nonfinite);
      report(request.request_id, Feedback::RESULT_REJECTED, Feedback::REASON_NON_FINITE);
      continue;
    }
    if (request.request_id <= last_request_) {
      outcome(request, GoalOutcome::When::ignored, GoalStatus::accepted);
      continue;
    }
    last_request_ = request.request_id;
    if (request.header.seq > seq) {
      pending_ = request;
      outcome(request, GoalOutcome::When::waiting, GoalStatus::accepted);
      report(request.request_id, Feedback::RESULT_WAITING);
      continue;
    }
    pending_.reset();
    const auto when = request.header.seq != 0 && request.header.seq < seq ? GoalOutcome::When::late : GoalOutcome::When::now;
    outcome(request, when, start(request));
  }
  if (pending_.has_value() && pending_->header.seq <= seq) {
    outcome(*pending_, GoalOutcome::When::as_asked, start(*pending_));
    pending_.reset();
  }
  const auto status = planner_.step(sample_period_, output_);
  if (status != common::StepStatus::ok) return status;
  if (active_) {
    const auto id = static_cast<std::uint32_t>(active_goal_.request_id);
    if (output_.phase == MovePhase::arrived && output_.request_id == active_goal_.request_id) {
      report(id, Feedback::RESULT_ARRIVED);
      active_ = false;
    } else if (++cycles_since_progress_ >= kProgressCycles) {
      report(id, Feedback::RESULT_MOVING);
      cycles_since_progress_ = 0;
    }
  }
  common::from_reference(output_.reference, reference);
  reference.request_id = static_cast<std::uint32_t>(output_.request_id);
  reference.phase = static_cast<std::uint8_t>(output_.phase);
  reference.time_in_move = output_.time_in_move;
  reference.move_duration = output_.move_duration;
  common::same_cycle(estimate.header, reference.header);
  return status;
}

}  // namespace crane::trajectory_planner
