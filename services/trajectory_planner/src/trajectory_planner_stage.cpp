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

TrajectoryPlannerStage::TrajectoryPlannerStage(const TrajectoryPlannerParams& params, double sample_period)
    : planner_(params), sample_period_(sample_period) {
  common::require_greater("stack.sample_period", sample_period, 0.0);
}

void TrajectoryPlannerStage::record(const GoalOutcome& outcome) noexcept {
  if (outcome_count_ < outcomes_.size()) outcomes_[outcome_count_++] = outcome;
}

common::StepStatus TrajectoryPlannerStage::step(const protocol::CraneState& estimate,
                                                std::span<const Request> goals,
                                                protocol::Reference& reference) noexcept {
  outcome_count_ = 0;
  if (!protocol::all_finite(estimate)) return common::StepStatus::rejected_nonfinite;
  const std::uint64_t seq = estimate.header.seq;
  const auto current = common::to_estimate(estimate);
  if (!holding_) {
    holding_ = planner_.hold(current) == GoalStatus::accepted;
    if (!holding_) return common::StepStatus::not_ready;
  }
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
      continue;
    }
    pending_.reset();
    const auto when = request.header.seq != 0 && request.header.seq < seq ? GoalOutcome::When::late : GoalOutcome::When::now;
    outcome(request, when, planner_.start_move(to_goal(request, current), current));
  }
  if (pending_.has_value() && pending_->header.seq <= seq) {
    outcome(*pending_, GoalOutcome::When::as_asked, planner_.start_move(to_goal(*pending_, current), current));
    pending_.reset();
  }
  const auto status = planner_.step(sample_period_, output_);
  if (status != common::StepStatus::ok) return status;
  common::from_reference(output_.reference, reference);
  reference.request_id = static_cast<std::uint32_t>(output_.request_id);
  reference.phase = static_cast<std::uint8_t>(output_.phase);
  reference.time_in_move = output_.time_in_move;
  reference.move_duration = output_.move_duration;
  common::same_cycle(estimate.header, reference.header);
  return status;
}

}  // namespace crane::trajectory_planner
