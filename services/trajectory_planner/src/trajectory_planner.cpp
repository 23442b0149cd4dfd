#include "crane/trajectory_planner/trajectory_planner.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "crane/common/validation.hpp"
#include "crane/trajectory_planner/zone_guard.hpp"

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
    case ProfileKind::planned: break;  // start_planned() only
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
  validate(params.manual);
  common::require_in_range("trajectory_planner.robust_length_range", params.robust_length_range, 0.0, 0.5);
  common::require_in_range("trajectory_planner.robust_margin", params.robust_margin, 0.0, 0.5);
  common::require_in_range("trajectory_planner.robust_within_radius", params.robust_within_radius, 0.0, 1000.0);
  // The calibrated equivalent pendulum must be one over the whole cable range (a > 0: its shortest
  // is at the shortest cable), or the minimum-time plans have no pendulum to swing.
  if (!swings_down_to(params.manual.pendulum(), params.cable_min_length)) {
    const double shortest = equivalent_swing_length(params.manual, params.cable_min_length);
    throw common::ConfigError("trajectory_planner.manual.swing_length_offset = " +
                              std::to_string(params.manual.swing_length_offset) +
                              " leaves no pendulum at the shortest cable: swing_length_scale x cable_min_length + "
                              "swing_length_offset = " + std::to_string(shortest) + " m, must be > 0");
  }
  common::validate(params.site, "site");
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
    case ProfileKind::planned: break;  // start_planned() only
  }
  if (planned) axis.kind = kind;
  return planned;
}

GoalStatus TrajectoryPlanner::hold(const common::CraneStateEstimate& current) noexcept {
  if (!std::isfinite(current.trolley_position) || !std::isfinite(current.slew_angle) ||
      !std::isfinite(current.cable_length)) {
    return GoalStatus::rejected_nonfinite;
  }
  Segment& s = segments_[0];
  s.trolley.step.plan(current.trolley_position);
  s.slew.step.plan(current.slew_angle);
  s.cable.step.plan(current.cable_length);
  s.trolley.kind = ProfileKind::step;
  s.slew.kind = ProfileKind::step;
  s.cable.kind = ProfileKind::step;
  s.start_time = 0.0;
  s.duration = 0.0;
  segment_count_ = 1;
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
  if (goal.waypoint_count > kMaxWaypoints) return GoalStatus::rejected_waypoint;
  for (std::size_t i = 0; i < goal.waypoint_count; ++i) {
    const Waypoint& w = goal.waypoints[i];
    if (!std::isfinite(w.trolley) || !std::isfinite(w.slew) || !std::isfinite(w.cable) ||
        w.trolley < params_.trolley_min_position || w.trolley > params_.trolley_max_position ||
        w.slew < params_.slew_min_angle || w.slew > params_.slew_max_angle || w.cable < params_.cable_min_length ||
        w.cable > params_.cable_max_length) {
      return GoalStatus::rejected_waypoint;
    }
  }
  const ProfileKind cable_kind =
      goal.profile == ProfileKind::step ? ProfileKind::step : ProfileKind::trapezoid;
  // Plan every segment into a temporary (held by value, no allocation) and commit only if all
  // succeed. Each segment starts at rest where the previous one ends.
  Segments planned = segments_;
  Waypoint from{current.trolley_position, current.slew_angle, current.cable_length};
  double start_time = 0.0;
  const std::size_t count = goal.waypoint_count + 1;
  for (std::size_t k = 0; k < count; ++k) {
    const Waypoint to = k < goal.waypoint_count ? goal.waypoints[k]
                                                : Waypoint{goal.trolley_target, goal.slew_target, goal.cable_target};
    // Load swing w = sqrt(g/L) at the segment's start for the trolley (in-plane) and the slew
    // (out-of-plane, same w). A non-positive length gives w = 0, which the swing-aware profiles reject.
    const double swing_frequency = from.cable > 0.0 ? std::sqrt(params_.gravity / from.cable) : 0.0;
    Segment& s = planned[k];
    if (!plan_axis(s.trolley, goal.profile, from.trolley, to.trolley, goal.trolley_limits, swing_frequency) ||
        !plan_axis(s.slew, goal.profile, from.slew, to.slew, goal.slew_limits, swing_frequency) ||
        !plan_axis(s.cable, cable_kind, from.cable, to.cable, goal.cable_limits, swing_frequency)) {
      return GoalStatus::rejected_invalid_limits;
    }
    if (s.cable.kind == ProfileKind::trapezoid && to.cable != from.cable) {
      // Hoisting during the segment: shaped profiles follow the swing period of L(t).
      for (Axis* axis : {&s.trolley, &s.slew}) {
        if (axis->kind == ProfileKind::zv || axis->kind == ProfileKind::zvd || axis->kind == ProfileKind::ei) {
          if (axis->shaped.reschedule_for_hoisting(s.cable.trapezoid, params_.gravity) != ProfileStatus::ok) {
            return GoalStatus::rejected_invalid_limits;
          }
        }
      }
    }
    s.start_time = start_time;
    s.duration = std::max({s.trolley.active().duration(), s.slew.active().duration(), s.cable.active().duration()});
    start_time += s.duration;
    from = to;
  }
  // Positive but tiny limits (1e-311 m/s) plan a move of Inf or absurd duration: refused.
  if (!(start_time <= kMaxMoveDuration)) return GoalStatus::rejected_invalid_limits;
  segments_ = planned;
  segment_count_ = count;
  move_duration_ = start_time;
  time_in_move_ = 0.0;
  request_id_ = goal.request_id;
  phase_ = MovePhase::moving;
  ready_ = true;
  return GoalStatus::accepted;
}

GoalStatus TrajectoryPlanner::start_planned(std::uint64_t request_id, const std::shared_ptr<const PlannedPath>& path,
                                            bool bridge_axis) noexcept {
  if (!path || !path->valid() || (bridge_axis && path->bridge.empty())) return GoalStatus::rejected_nonfinite;
  if (!(path->duration() <= kMaxMoveDuration)) return GoalStatus::rejected_invalid_limits;
  Segment& s = segments_[0];
  s.trolley.planned = PlannedProfile(path, bridge_axis ? &PlannedPath::bridge : &PlannedPath::trolley);
  s.slew.planned = PlannedProfile(path, &PlannedPath::slew);
  s.cable.planned = PlannedProfile(path, &PlannedPath::cable);
  s.trolley.kind = s.slew.kind = s.cable.kind = ProfileKind::planned;
  s.start_time = 0.0;
  s.duration = path->duration();
  segment_count_ = 1;
  move_duration_ = s.duration;
  time_in_move_ = 0.0;
  request_id_ = request_id;
  phase_ = MovePhase::moving;
  ready_ = true;
  return GoalStatus::accepted;
}

const TrajectoryPlanner::Segment& TrajectoryPlanner::segment_at(double time_in_move) const noexcept {
  for (std::size_t k = 0; k + 1 < segment_count_; ++k) {
    if (time_in_move < segments_[k].start_time + segments_[k].duration) return segments_[k];
  }
  return segments_[segment_count_ - 1];
}

std::size_t TrajectoryPlanner::segment_index() const noexcept {
  return phase_ == MovePhase::holding ? 0 : static_cast<std::size_t>(&segment_at(time_in_move_) - segments_.data());
}

bool TrajectoryPlanner::last_segment_axes_independent() const noexcept {
  if (!ready_ || phase_ != MovePhase::moving || segment_index() + 1 != segment_count_) return false;
  const Segment& s = segments_[segment_count_ - 1];
  return s.trolley.kind != ProfileKind::planned && s.slew.kind != ProfileKind::planned &&
         s.cable.kind != ProfileKind::planned;
}

common::MotionReference TrajectoryPlanner::sample_end() const noexcept {
  const Segment& s = segments_[segment_count_ - 1];
  return {s.trolley.active().sample(s.trolley.active().duration()), s.slew.active().sample(s.slew.active().duration()),
          s.cable.active().sample(s.cable.active().duration())};
}

common::MotionReference TrajectoryPlanner::sample_now() const noexcept {
  const Segment& s = segment_at(time_in_move_);
  const double t = time_in_move_ - s.start_time;
  return {s.trolley.active().sample(t), s.slew.active().sample(t), s.cable.active().sample(t)};
}

int TrajectoryPlanner::intruded_zone(std::uint32_t zones_enabled, double spacing) const noexcept {
  if (!ready_ || zones_enabled == 0 || params_.site.zones.empty() || !(spacing > 0.0)) return -1;
  // At most about 120 samples (a long move is checked at a coarser interval); each sample keeps an
  // extra half of the distance its point travels to the next one, so nothing between two samples
  // comes closer than the margin.
  spacing = std::max(spacing, (move_duration_ - time_in_move_) / 120.0);
  const auto sample = [&](double t) {
    const double at = std::min(t, move_duration_);
    const Segment& s = segment_at(at);
    const double local = at - s.start_time;
    return common::MotionReference{s.trolley.active().sample(local), s.slew.active().sample(local),
                                   s.cable.active().sample(local)};
  };
  // The swing an acceleration excites lasts about a swing period (an input-shaped or time-optimal
  // profile cancels it within one): each sample keeps the margin of the largest horizontal
  // acceleration of the last period (zone_guard.hpp). The crane rests before the move.
  std::array<double, 512> recent{};  // accelerations of the last samples (a ring), at `spacing`
  std::size_t count = 0;
  // Where the move starts, the load rests: a zone already within its margin there may be left.
  const ZoneDistances start = zone_distances(params_.site, sample(time_in_move_));
  for (double t = time_in_move_;; t += spacing) {
    const common::MotionReference r = sample(t);
    recent[count % recent.size()] = horizontal_acceleration(r);
    ++count;
    const double cable = std::max(r.cable_length.position, 1e-3);
    const double period = 2.0 * std::numbers::pi * std::sqrt(cable / params_.gravity);
    const auto window = std::min<std::size_t>({count, recent.size(),
                                               static_cast<std::size_t>(std::ceil(period / spacing)) + 1});
    double peak = 0.0;
    for (std::size_t i = 0; i < window; ++i) peak = std::max(peak, recent[(count - 1 - i) % recent.size()]);
    const double travel = std::hypot(r.trolley.velocity, r.trolley.position * r.slew.velocity) * spacing;
    const int zone = trajectory_planner::intruded_zone(params_.site, zones_enabled, r, params_.gravity, peak, &start,
                                                       0.5 * travel + 0.5 * std::abs(r.cable_length.velocity) * spacing);
    if (zone >= 0) return zone;
    if (t >= move_duration_) return -1;
  }
}

common::StepStatus TrajectoryPlanner::step(double dt, PlannerOutput& output) noexcept {
  if (!std::isfinite(dt) || dt < 0.0) return common::StepStatus::rejected_nonfinite;
  if (!ready_) return common::StepStatus::not_ready;
  if (phase_ == MovePhase::moving) {
    time_in_move_ += dt;
    if (time_in_move_ >= move_duration_) phase_ = MovePhase::arrived;
  }
  const Segment& s = segment_at(time_in_move_);
  const double t = time_in_move_ - s.start_time;
  output.reference.trolley = s.trolley.active().sample(t);
  output.reference.slew = s.slew.active().sample(t);
  output.reference.cable_length = s.cable.active().sample(t);
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
