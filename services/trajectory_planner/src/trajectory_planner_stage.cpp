#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "crane/common/protocol_signals.hpp"
#include "crane/common/validation.hpp"
#include "crane/config/yaml_section.hpp"
#include "crane/trajectory_planner/zone_paths.hpp"

namespace crane::trajectory_planner {

using Request = protocol::MoveRequest;

TrajectoryPlannerParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  constexpr double kPi = std::numbers::pi;
  TrajectoryPlannerParams p;
  p.trolley_min_position = s.number("trolley_min_position", -100.0, 100.0);
  p.trolley_max_position = s.number("trolley_max_position", p.trolley_min_position, 100.0);
  p.slew_min_angle = s.number("slew_min_angle", -20.0 * kPi, 20.0 * kPi);
  p.slew_max_angle = s.number("slew_max_angle", p.slew_min_angle, 20.0 * kPi);
  if (facts.crane_kind == common::CraneKind::overhead) {
    p.bridge_min_position = s.number("bridge_min_position", -1000.0, 1000.0);
    p.bridge_max_position = s.number("bridge_max_position", p.bridge_min_position, 1000.0);
  }
  auto m = s.child("manual");
  const auto axis = [&](const char* name, bool swings) {
    return SpeedAxisParams{m.number(std::string(name) + "_speed", 0.0, 100.0),
                           m.number(std::string(name) + "_acceleration", 0.0, 100.0), swings};
  };
  p.manual.trolley = axis("trolley", true);
  p.manual.slew = axis("slew", true);
  p.manual.hoist = axis("hoist", false);
  p.bridge_enabled = facts.crane_kind == common::CraneKind::overhead;
  if (p.bridge_enabled) {  // elsewhere these are unknown fields
    p.manual.bridge = axis("bridge", true);
  }
  p.manual.micro_speed_fraction = m.number("micro_speed_fraction", 0.0, 1.0);
  p.manual.maintenance_speed_fraction = m.number("maintenance_speed_fraction", 0.0, 1.0);
  p.manual.dead_man_timeout = m.number("dead_man_timeout", 0.02, 5.0);
  p.manual.shaping = speed_shaping_from_string(m.text("shaping"), m.field("shaping"));
  p.manual.swing_length_scale = m.number("swing_length_scale", kMinSwingLengthScale, kMaxSwingLengthScale);
  p.manual.swing_length_offset = m.number("swing_length_offset", kMinSwingLengthOffset, kMaxSwingLengthOffset);
  p.manual.swing_damping_ratio = m.number("swing_damping_ratio", 0.0, 0.3);
  m.finish();
  p.robust_length_range = s.number("robust_length_range", 0.0, 0.5);
  p.robust_margin = s.number("robust_margin", 0.0, 0.5);
  p.robust_within_radius = s.number("robust_within_radius", 0.0, 1000.0);
  s.finish();
  p.site = facts.site;
  if (p.robust_within_radius > 0.0 && facts.crane_kind != common::CraneKind::tower) {
    throw common::ConfigError("trajectory_planner.robust_within_radius = " + common::format_value(p.robust_within_radius) +
                              ": a radius about the slew axis, for a tower crane only (crane.kind = " +
                              common::to_string(facts.crane_kind) + "); 0 here");
  }
  if (p.bridge_enabled && !p.site.zones.empty()) {
    throw common::ConfigError("site.zones: no-go zones are planned around for a slewing crane only (crane.kind = "
                              "overhead has " + std::to_string(p.site.zones.size()) + " zones)");
  }
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
    case GoalStatus::rejected_zone: return "rejected: the target is in a no-go zone, or no route around the zones";
    case GoalStatus::rejected_operating_mode: return "rejected: goals are not taken in this operating mode";
    case GoalStatus::rejected_supervisor_stop: return "rejected: the supervisor has stopped the crane (fault or emergency stop)";
    case GoalStatus::rejected_manual_motion: return "rejected: operator speed control is moving the crane";
    case GoalStatus::rejected_bridge_out_of_range: return "rejected: bridge target outside its travel (or no bridge)";
  }
  return "unknown";
}

namespace {
// [rad] the larger swing amplitude of the two planes, sqrt(angle^2 + (rate / w)^2), w = sqrt(g / L).
double swing_amplitude(const common::CraneStateEstimate& s, double gravity) noexcept {
  const double w = std::sqrt(gravity / std::max(s.cable_length, 1e-3));
  return std::max(std::hypot(s.swing_in_plane, s.swing_in_plane_rate / w),
                  std::hypot(s.swing_out_of_plane, s.swing_out_of_plane_rate / w));
}
}  // namespace

MoveGoal to_goal(const Request& r, const common::CraneStateEstimate& current, const ManualParams& rated) noexcept {
  MoveGoal g;
  g.trolley_limits = {rated.trolley.rated_speed, rated.trolley.acceleration};
  g.slew_limits = {rated.slew.rated_speed, rated.slew.acceleration};
  g.cable_limits = {rated.hoist.rated_speed, rated.hoist.acceleration};
  g.request_id = r.request_id;
  switch (r.profile) {
    case Request::PROFILE_STEP: g.profile = ProfileKind::step; break;
    case Request::PROFILE_TRAPEZOID: g.profile = ProfileKind::trapezoid; break;
    case Request::PROFILE_ZV: g.profile = ProfileKind::zv; break;
    case Request::PROFILE_ZVD: g.profile = ProfileKind::zvd; break;
    case Request::PROFILE_EI: g.profile = ProfileKind::ei; break;
    case Request::PROFILE_TIME_OPTIMAL:
    case Request::PROFILE_MINIMUM_TIME:  // checked and, until its plan arrives or if none does, run as time-optimal
      g.profile = ProfileKind::time_optimal;
      break;
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
    case GoalStatus::rejected_zone: f.reason = S::REASON_ZONE; return;
    case GoalStatus::rejected_operating_mode: f.reason = S::REASON_MODE; return;
    case GoalStatus::rejected_supervisor_stop: f.reason = S::REASON_FAULT; return;
    case GoalStatus::rejected_manual_motion: f.reason = S::REASON_MANUAL_MOTION; return;
    case GoalStatus::rejected_bridge_out_of_range:  // value: the caller's (the bridge target)
      f.reason = S::REASON_BRIDGE_RANGE;
      f.bound_min = params.bridge_min_position;
      f.bound_max = params.bridge_max_position;
      return;
  }
}

TrajectoryPlannerStage::TrajectoryPlannerStage(const TrajectoryPlannerParams& params, double sample_period)
    : planner_(params), scratch_(params), sample_period_(sample_period) {
  common::require_greater("stack.sample_period", sample_period, 0.0);
  zones_enabled_ = params.site.enabled_at_start();
  if (params.bridge_enabled) bridge_.emplace(params.bridge_view());
}

void TrajectoryPlannerStage::record(const GoalOutcome& outcome) noexcept {
  if (outcome_count_ < outcomes_.size()) outcomes_[outcome_count_++] = outcome;
}

protocol::MoveStatus* TrajectoryPlannerStage::report(std::uint32_t request_id, std::uint8_t result,
                                                     std::uint8_t reason) noexcept {
  if (status_count_ >= statuses_.size()) return nullptr;
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
  s.rest_trolley_position = active_goal_.trolley_target;
  s.rest_slew_angle = active_goal_.slew_target;
  s.rest_cable_length = active_goal_.cable_target;
  if (bridge_) {
    s.bridge_to_go = bridge_->target - bridge_->reference(source_ == Source::speed).position;
    s.rest_bridge_position = bridge_->target;
  }
  return &s;
}

void TrajectoryPlannerStage::report_rest(protocol::MoveStatus& s) const noexcept {
  const auto& p = planner_.params();
  auto rest = speed_.rest(sample_period_, p.manual, p.manual.shaping, p.speed_bounds());
  const auto now = speed_.reference();
  if (finishing_axes_ != 0) {
    // The axes that run on rest at their targets.
    const auto end = planner_.sample_end();
    const double ends[3] = {end.trolley.position, end.slew.position, end.cable_length.position};
    for (std::size_t i = 0; i < 3; ++i) {
      if ((finishing_axes_ & (1U << i)) != 0) rest[i] = ends[i];
    }
  }
  s.rest_trolley_position = rest[0];
  s.rest_slew_angle = rest[1];
  s.rest_cable_length = rest[2];
  s.trolley_to_go = rest[0] - now.trolley.position;
  s.slew_to_go = rest[1] - now.slew.position;
  s.cable_to_go = rest[2] - now.cable_length.position;
  if (bridge_) {
    const auto& b = bridge_->params;
    s.rest_bridge_position = bridge_->speed.rest(sample_period_, b.manual, b.manual.shaping, b.speed_bounds())[0];
    s.bridge_to_go = s.rest_bridge_position - bridge_->speed.reference().trolley.position;
  }
}

void TrajectoryPlannerStage::abort_active(std::uint8_t reason) noexcept {
  if (active_) report(static_cast<std::uint32_t>(active_goal_.request_id), protocol::MoveStatus::RESULT_ABORTED, reason);
  active_ = false;
  paused_.reset();
}

void TrajectoryPlannerStage::cancel_plan(std::uint8_t reason) noexcept {
  if (!plan_request_) return;
  report(plan_request_->request_id, protocol::MoveStatus::RESULT_ABORTED, reason);
  plan_request_.reset();
  plan_answer_.reset();
  plan_answered_ = false;
}

PlanRequest TrajectoryPlannerStage::plan_of(const protocol::MoveRequest& r, const common::CraneStateEstimate& current,
                                            const common::MotionReference& rest, double bridge_rest) const noexcept {
  // From where the reference rests (not the estimate: its last digits vary while the crane rests, and
  // the plan would vary with the cycle the goal arrived at); an axis the goal does not name stays there.
  const auto& params = planner_.params();
  common::CraneStateEstimate at_rest = current;
  at_rest.trolley_position = rest.trolley.position;
  at_rest.slew_angle = rest.slew.position;
  at_rest.cable_length = rest.cable_length.position;
  const MoveGoal goal = to_goal(r, at_rest, params.manual);
  PlanRequest plan;
  plan.request_id = r.request_id;
  plan.trolley_from = rest.trolley.position;
  plan.slew_from = rest.slew.position;
  plan.cable_from = rest.cable_length.position;
  plan.trolley_target = goal.trolley_target;
  plan.slew_target = goal.slew_target;
  plan.cable_target = goal.cable_target;
  plan.trolley_limits = goal.trolley_limits;
  plan.slew_limits = goal.slew_limits;
  plan.cable_limits = goal.cable_limits;
  if (bridge_) {
    plan.bridge = true;
    plan.bridge_from = bridge_rest;
    plan.bridge_target = (r.axes & protocol::MoveRequest::AXIS_BRIDGE) != 0 ? r.bridge_target : bridge_rest;
    plan.bridge_limits = {r.bridge_max_velocity > 0.0 ? r.bridge_max_velocity : params.manual.bridge.rated_speed,
                          r.bridge_max_acceleration > 0.0 ? r.bridge_max_acceleration : params.manual.bridge.acceleration};
  }
  plan.max_swing = max_swing_;
  plan_on_pendulum(plan, params.manual.pendulum(), false, params);
  if (cycle_estimate_ != nullptr && cycle_estimate_->swing_length_confident) {
    const EquivalentPendulum learnt{cycle_estimate_->swing_length_scale, cycle_estimate_->swing_length_offset};
    if (swings_down_to(learnt, std::min(plan.cable_from, plan.cable_target))) {
      plan_on_pendulum(plan, learnt, true, params);
    }
  }
  return plan;
}

void TrajectoryPlannerStage::plan_ahead(const protocol::MoveRequest& r, const common::CraneStateEstimate& current) noexcept {
  // From rest only, with no waypoint and no zone to plan around, the sway limit heard: as start()
  // would plan it, from where the crane rests now (it holds until the start cycle).
  const auto& params = planner_.params();
  if (moving() || source_ != Source::profile || r.waypoint_count != 0 || max_swing_ <= 0.0 ||
      (zones_enabled_ != 0 && !params.site.zones.empty())) {
    return;
  }
  plan_request_ = plan_of(r, current, planner_.sample_now(),
                         bridge_ ? bridge_->planner.sample_now().trolley.position : 0.0);
  plan_request_->sequence = ++plan_sequence_;
  plan_answer_.reset();
  plan_answered_ = false;
}

void TrajectoryPlannerStage::provide_plan(std::uint64_t sequence, std::shared_ptr<const PlannedPath> path) noexcept {
  if (!plan_request_ || plan_request_->sequence != sequence) return;
  plan_answer_ = std::move(path);
  plan_answered_ = true;
}

bool TrajectoryPlannerStage::moving() const noexcept {
  return source_ == Source::speed ? !speed_.at_rest() || (bridge_ && !bridge_->speed.at_rest())
                                  : output_.phase == MovePhase::moving;
}

void TrajectoryPlannerStage::soft_stop(std::uint32_t stop_id, std::uint8_t stopped_axes) noexcept {
  paused_.reset();
  finishing_axes_ = 0;
  if (source_ == Source::profile) {
    if (!bridge_ && planner_.last_segment_axes_independent()) {
      finishing_axes_ = static_cast<std::uint8_t>(kEveryAxis & ~stopped_axes);
    }
    speed_.start(planner_.sample_now());
    if (bridge_) bridge_->speed.start(bridge_->planner.sample_now());
    source_ = Source::speed;
  }
  stop_id_ = stop_id;
  require_neutral_ = true;
  if (stop_id != 0) {
    if (auto* s = report(stop_id, protocol::MoveStatus::RESULT_STOPPING)) report_rest(*s);
  }
}

void TrajectoryPlannerStage::take_speeds(std::span<const protocol::OperatorSpeed> speeds, std::uint64_t seq) noexcept {
  using Speed = protocol::OperatorSpeed;
  for (const auto& sample : speeds) {
    const double values[] = {sample.trolley, sample.slew, sample.hoist, sample.bridge};
    bool valid = sample.range == Speed::RANGE_NORMAL || sample.range == Speed::RANGE_MICRO;
    for (const double v : values) valid = valid && std::isfinite(v) && std::abs(v) <= 1.0;
    valid = valid && (bridge_ || sample.bridge == 0.0);  // a bridge speed for a crane without a bridge
    if (!valid) {
      ++rejected_speeds_;
      continue;
    }
    if (operating_mode_ == protocol::SupervisorStatus::OPERATION_FULLAUTOMATIC) {
      ++speeds_outside_manual_;
      continue;
    }
    operator_speed_ = {sample.trolley, sample.slew, sample.hoist};
    if (bridge_) bridge_->operator_speed = sample.bridge;
    operator_micro_ = sample.range == Speed::RANGE_MICRO;
    operator_seq_ = seq;
    have_operator_input_ = true;
  }
}

std::array<double, 4> TrajectoryPlannerStage::targets_of(std::uint64_t seq) const noexcept {
  const auto& m = planner_.params().manual;
  const bool silent = !have_operator_input_ ||
                      static_cast<double>(seq - operator_seq_) * sample_period_ > m.dead_man_timeout + 1e-9;
  if (silent || require_neutral_ || stop_id_ != 0 || supervisor_stopped_ ||
      operating_mode_ == protocol::SupervisorStatus::OPERATION_FULLAUTOMATIC) {
    return {0.0, 0.0, 0.0, 0.0};
  }
  double fraction = operator_micro_ ? m.micro_speed_fraction : 1.0;
  if (operating_mode_ == protocol::SupervisorStatus::OPERATION_MAINTENANCE) fraction *= m.maintenance_speed_fraction;
  return {operator_speed_[0] * fraction * m.trolley.rated_speed, operator_speed_[1] * fraction * m.slew.rated_speed,
          operator_speed_[2] * fraction * m.hoist.rated_speed,
          bridge_ ? bridge_->operator_speed * fraction * m.bridge.rated_speed : 0.0};
}

common::StepStatus TrajectoryPlannerStage::step(const PlannerCycle& cycle, protocol::Reference& reference) noexcept {
  using Feedback = protocol::MoveStatus;
  using Status = protocol::SupervisorStatus;
  outcome_count_ = 0;
  status_count_ = 0;
  held_axes_ = 0;
  if (cycle.estimate == nullptr) return common::StepStatus::not_ready;
  const protocol::CraneState& estimate = *cycle.estimate;
  if (!protocol::all_finite(estimate)) return common::StepStatus::rejected_nonfinite;
  cycle_estimate_ = &estimate;
  const std::uint64_t seq = estimate.header.seq;
  const auto current = common::to_estimate(estimate);
  // The bridge's planner holds and moves the bridge as its trolley, at the crane's slew 0 and cable.
  const auto bridge_state = [&](double position) {
    common::CraneStateEstimate b = current;
    b.trolley_position = position;
    b.slew_angle = 0.0;
    return b;
  };
  const auto hold_bridge = [&](double position) {
    if (bridge_) (void)bridge_->planner.hold(bridge_state(position));
  };
  if (!holding_) {
    holding_ = planner_.hold(current) == GoalStatus::accepted;
    if (!holding_) return common::StepStatus::not_ready;
    hold_bridge(estimate.bridge_position);
  }
  const auto& params = planner_.params();

  // The supervisor's view: operating mode, zones, faults, zone approach.
  bool zone_warning = false, limit_warning = false, site_warning = false, braked = false;
  if (cycle.status != nullptr) {
    const auto& st = *cycle.status;
    const std::uint8_t mode = st.operating_mode;
    if (mode >= Status::OPERATION_MANUAL && mode <= Status::OPERATION_MAINTENANCE && mode != operating_mode_) {
      cancel_plan(Feedback::REASON_MODE);
      if (moving()) {
        abort_active(Feedback::REASON_MODE);
        soft_stop(0);
      } else if (paused_) {
        abort_active(Feedback::REASON_MODE);  // braked under way, at rest: it ends there
      }
      operating_mode_ = mode;
    }
    zones_enabled_ = st.zones_enabled;
    supervisor_mode_ = st.mode;
    supervisor_stopped_ = st.mode == Status::MODE_FAULT || st.mode == Status::MODE_EMERGENCY_STOP;
    if (std::isfinite(st.max_swing) && st.max_swing > 0.0) max_swing_ = st.max_swing;
    zone_warning = (st.warnings & Status::WARNING_ZONE_APPROACH) != 0;
    limit_warning = (st.warnings & Status::WARNING_SPEED_LIMITED) != 0;
    site_warning = (st.warnings & Status::WARNING_SITE) != 0;
    braked = (st.warnings & Status::WARNING_DRIVES_BRAKED) != 0;
  }
  if (braked && !supervisor_stopped_ && moving()) {
    // The drives were braked under way (the actuation gate's watchdog after a stalled chain, or a
    // late stage): the brakes stopped the crane where it is. The goal pauses: the reference holds
    // the measured position while they stay on, so that when they open the tracking law does not
    // chase a reference that ran on (at full voltage: twice the planned speed); the rest of the
    // goal starts again from there (below). A reference at rest (arrived, holding) is left as it
    // is: nothing runs on, and a client waits for its arrival.
    if (source_ == Source::speed) {
      // Operator speeds (or a soft stop): the speed reference starts again from rest where the
      // crane is; the stick still held drives it on from there, shaped (a soft stop is at rest).
      common::MotionReference here;
      here.trolley.position = current.trolley_position;
      here.slew.position = current.slew_angle;
      here.cable_length.position = current.cable_length;
      speed_.start(here);
      finishing_axes_ = 0;
      if (bridge_) {
        common::MotionReference bridge_here;
        bridge_here.trolley.position = estimate.bridge_position;
        bridge_here.cable_length.position = current.cable_length;
        bridge_->speed.start(bridge_here);
      }
    } else {
      if (active_ && !bridge_) {
        MoveGoal rest = active_goal_;
        const std::size_t passed = std::min(planner_.segment_index(), rest.waypoint_count);
        for (std::size_t i = passed; i < rest.waypoint_count; ++i) rest.waypoints[i - passed] = rest.waypoints[i];
        rest.waypoint_count -= passed;
        paused_ = rest;
        paused_seq_ = seq;
      } else {
        abort_active(Feedback::REASON_BRAKED);  // an overhead crane's goal (its bridge) ends here
      }
      cancel_plan(Feedback::REASON_BRAKED);
      (void)planner_.hold(current);
      hold_bridge(estimate.bridge_position);
    }
  } else if (paused_ && (supervisor_stopped_ || zone_warning || limit_warning || site_warning)) {
    // Paused at rest, and now a reason to stop: the goal ends here, with that reason.
    abort_active(supervisor_stopped_ ? Feedback::REASON_FAULT
                 : zone_warning      ? Feedback::REASON_ZONE
                 : site_warning      ? Feedback::REASON_SITE
                                     : Feedback::REASON_LIMIT_APPROACH);
  } else if (paused_ && braked) {
    paused_seq_ = seq;  // still held by the brakes (at rest: moving() is false)
  } else if (paused_ && seq > paused_seq_ + kResumeTimeoutCycles) {
    abort_active(Feedback::REASON_BRAKED);  // the swing did not settle: a client sends the goal again
  } else if (paused_ && swing_amplitude(current, params.gravity) < kResumeSwing &&
             std::abs(current.trolley_velocity) < kResumeSpeed && std::abs(current.slew_rate) < kResumeSpeed &&
             std::abs(current.cable_length_rate) < kResumeSpeed) {
    // The brakes are open again, the swing they caused has settled (the reference holds meanwhile,
    // the anti-swing law damps it) and the crane is at rest (the hoist, which the brakes do not
    // hold, ramps down on its own): the rest of the goal, planned from rest where the crane stopped.
    const MoveGoal rest = *paused_;
    paused_.reset();
    if (planner_.start_move(rest, current) != GoalStatus::accepted) {
      abort_active(Feedback::REASON_BRAKED);
      (void)planner_.hold(current);
    } else {
      cycles_since_progress_ = kProgressCycles;  // a progress report at this cycle's end
    }
  }
  if (supervisor_stopped_) {
    // The brakes hold the crane where it is and the drives are off: the running goal is over. The
    // reference is left as it runs (a lockstep run gives the same record whatever cycle the status
    // arrives at); when the supervisor lets the crane move again, it holds the measured position,
    // so a reset resumes nothing.
    abort_active(Feedback::REASON_FAULT);
    cancel_plan(Feedback::REASON_FAULT);
    if (stop_id_ != 0) report(stop_id_, Feedback::RESULT_ARRIVED);
    stop_id_ = 0;
    hold_on_release_ = true;
    require_neutral_ = true;
  } else if (hold_on_release_) {
    hold_on_release_ = false;
    source_ = Source::profile;
    (void)planner_.hold(current);
    hold_bridge(estimate.bridge_position);
  } else if ((zone_warning || limit_warning || site_warning) && moving() && stop_id_ == 0) {
    // The supervisor's first reaction where a hard stop is not yet required: this soft stop.
    abort_active(zone_warning   ? Feedback::REASON_ZONE
                 : site_warning ? Feedback::REASON_SITE
                                : Feedback::REASON_LIMIT_APPROACH);
    soft_stop(0);
  }

  // Start `r` now: the planner takes it or refuses it (the running move then continues).
  // The crane holds where a plan starts until the plan is handed over.
  const auto hold_for_plan = [&](const PlanRequest& plan) {
    common::CraneStateEstimate at_rest = current;
    at_rest.trolley_position = plan.trolley_from;
    at_rest.slew_angle = plan.slew_from;
    at_rest.cable_length = plan.cable_from;
    (void)planner_.hold(at_rest);
    if (bridge_) hold_bridge(plan.bridge_from);
  };
  const auto start = [&](const Request& r) {
    const bool was_moving = moving();
    // Where the reference rests before this goal (a minimum-time plan starts there: see plan_ahead).
    const common::MotionReference rest = source_ == Source::speed ? speed_.reference() : planner_.sample_now();
    const double bridge_rest = bridge_ ? bridge_->reference(source_ == Source::speed).position : 0.0;
    MoveGoal goal = to_goal(r, current, params.manual);
    // Refuses with the reason; `value` the mode or zone it names.
    const auto reject = [&](GoalStatus status, double value) {
      if (auto* f = report(r.request_id, Feedback::RESULT_REJECTED)) {
        describe_rejection(status, goal, params, *f);
        if (status >= GoalStatus::rejected_zone) f->value = value;
        f->rest_trolley_position = f->rest_slew_angle = f->rest_cable_length = 0.0;
      }
      return status;
    };
    if (supervisor_stopped_) return reject(GoalStatus::rejected_supervisor_stop, supervisor_mode_);
    if (operating_mode_ == Status::OPERATION_MANUAL || operating_mode_ == Status::OPERATION_MAINTENANCE) {
      return reject(GoalStatus::rejected_operating_mode, operating_mode_);
    }
    if (source_ == Source::speed && (!speed_.at_rest() || (bridge_ && !bridge_->speed.at_rest()))) {
      return reject(GoalStatus::rejected_manual_motion, 0.0);
    }
    // The move starts from where the reference rests (the speed reference, or the estimate).
    common::CraneStateEstimate from = current;
    if (source_ == Source::speed) {
      const auto r0 = speed_.reference();
      from.trolley_position = r0.trolley.position;
      from.slew_angle = r0.slew.position;
      from.cable_length = r0.cable_length.position;
    }
    if (zones_enabled_ != 0 && !params.site.zones.empty()) {
      // The goal's own bounds first (travel, limits: their own reason and bound), then the zones.
      scratch_.reset();
      const GoalStatus own = scratch_.start_move(goal, from);
      if (own != GoalStatus::accepted) return reject(own, 0.0);
      const ZonePlan plan = plan_around_zones(scratch_, goal, from, zones_enabled_);
      if (!plan.found) return reject(GoalStatus::rejected_zone, plan.zone);
      goal = plan.goal;
    }
    // The bridge first, on its own planner's copy: both axes start the goal, or neither.
    MoveGoal bridge_goal;
    if (bridge_) {
      bridge_goal = goal;  // profile, cable target and limits, waypoints' cable lengths
      const bool named = (r.axes & Request::AXIS_BRIDGE) != 0;
      const double bridge_from = source_ == Source::speed ? bridge_->speed.reference().trolley.position
                                                          : estimate.bridge_position;
      bridge_goal.trolley_target = named ? r.bridge_target : bridge_from;
      bridge_goal.trolley_limits = {r.bridge_max_velocity > 0.0 ? r.bridge_max_velocity : params.manual.bridge.rated_speed,
                                    r.bridge_max_acceleration > 0.0 ? r.bridge_max_acceleration
                                                                    : params.manual.bridge.acceleration};
      bridge_goal.slew_target = 0.0;
      for (std::size_t i = 0; i < std::min<std::size_t>(goal.waypoint_count, kMaxWaypoints); ++i) {
        bridge_goal.waypoints[i].trolley = named ? r.waypoint_bridge[i] : bridge_from;
        bridge_goal.waypoints[i].slew = 0.0;
      }
      common::CraneStateEstimate bridge_start = from;
      bridge_start.trolley_position = bridge_from;
      bridge_start.slew_angle = 0.0;
      bridge_->trial = bridge_->planner;
      GoalStatus b = bridge_->trial.start_move(bridge_goal, bridge_start);
      if (b == GoalStatus::rejected_trolley_out_of_range || b == GoalStatus::rejected_waypoint) {
        b = GoalStatus::rejected_bridge_out_of_range;
      }
      if (b != GoalStatus::accepted) return reject(b, bridge_goal.trolley_target);  // value: bridge_out_of_range's
    } else if ((r.axes & Request::AXIS_BRIDGE) != 0) {
      return reject(GoalStatus::rejected_bridge_out_of_range, r.bridge_target);
    }
    const GoalStatus status = planner_.start_move(goal, from);
    if (status != GoalStatus::accepted) return reject(status, 0.0);
    if (bridge_) {
      bridge_->planner = bridge_->trial;
      bridge_->target = bridge_goal.trolley_target;
    }
    if (active_ && active_goal_.request_id != goal.request_id) abort_active(Feedback::REASON_REPLACED);
    paused_.reset();
    source_ = Source::profile;
    stop_id_ = 0;
    active_goal_ = goal;
    active_ = true;
    cycles_since_progress_ = kProgressCycles;  // report at this cycle's end
    // The minimum-time profile: from rest, with no waypoint and no zone to plan around, and with the
    // supervisor's sway limit heard, the crane holds where it is until the plan is handed over
    // (provide_plan); otherwise the time-optimal profile just started runs.
    const bool planned_ahead = plan_request_ && plan_request_->request_id == r.request_id;
    if (planned_ahead && (was_moving || goal.waypoint_count != 0)) {
      // The crane moved meanwhile: that plan starts from the wrong place; the time-optimal profile runs.
      plan_request_.reset();
      plan_answer_.reset();
      plan_answered_ = false;
    }
    if (r.profile == Request::PROFILE_MINIMUM_TIME && plan_request_ && plan_request_->request_id == r.request_id) {
      // Planned while the goal waited for its start cycle: the move starts with that plan (now if it
      // was handed over already, else when it is).
      hold_for_plan(*plan_request_);
      active_ = false;
      plan_fallback_ = r;
      plan_fallback_.profile = Request::PROFILE_TIME_OPTIMAL;
      if (!plan_answered_) report(r.request_id, Feedback::RESULT_WAITING);
    } else if (r.profile == Request::PROFILE_MINIMUM_TIME && !was_moving && goal.waypoint_count == 0 &&
        (zones_enabled_ == 0 || params.site.zones.empty()) && max_swing_ > 0.0) {
      const PlanRequest plan = plan_of(r, current, rest, bridge_rest);
      hold_for_plan(plan);
      active_ = false;
      plan_request_ = plan;
      plan_request_->sequence = ++plan_sequence_;
      plan_fallback_ = r;
      plan_fallback_.profile = Request::PROFILE_TIME_OPTIMAL;
      plan_answered_ = false;
      plan_answer_.reset();
      report(r.request_id, Feedback::RESULT_WAITING);
    } else if (r.profile == Request::PROFILE_MINIMUM_TIME && !was_moving && goal.waypoint_count == 0 &&
               (zones_enabled_ == 0 || params.site.zones.empty())) {
      ++unsolved_plans_;  // the supervisor's sway limit not heard: the time-optimal profile runs
    }
    return status;
  };
  // A plan handed over: its move starts now (or, unsolved, the time-optimal profile's), unless its
  // goal still waits for its start cycle.
  const auto hand_over = [&] {
    if (!plan_request_ || !plan_answered_ || (pending_ && pending_->request_id == plan_request_->request_id)) return;
    const std::uint32_t id = plan_request_->request_id;
    const bool bridge_ok =
        !bridge_ || (plan_answer_ && bridge_->planner.start_planned(id, plan_answer_, true) == GoalStatus::accepted);
    if (plan_answer_ && bridge_ok && planner_.start_planned(id, plan_answer_) == GoalStatus::accepted) {
      planned_ = plan_answer_;
      planned_id_ = id;
      active_goal_ = to_goal(plan_fallback_, current, params.manual);
      if (bridge_) bridge_->target = plan_request_->bridge_target;
      active_ = true;
      source_ = Source::profile;
      cycles_since_progress_ = kProgressCycles;
      plan_request_.reset();
    } else {
      if (bridge_) hold_bridge(plan_request_->bridge_from);
      plan_request_.reset();
      ++unsolved_plans_;
      GoalOutcome o;
      o.request_id = id;
      o.cycle = seq;
      o.asked_cycle = plan_fallback_.header.seq;
      o.status = start(plan_fallback_);
      o.trolley_target = plan_fallback_.trolley_target;
      o.slew_target = plan_fallback_.slew_target;
      record(o);
    }
    plan_answer_.reset();
    plan_answered_ = false;
  };
  hand_over();
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
  for (const auto& request : cycle.goals) {
    if (!protocol::all_finite(request)) {
      ++nonfinite_goals_;
      outcome(request, GoalOutcome::When::now, GoalStatus::rejected_nonfinite);
      report(request.request_id, Feedback::RESULT_REJECTED, Feedback::REASON_NON_FINITE);
      continue;
    }
    if (request.request_id <= last_request_) {
      outcome(request, GoalOutcome::When::ignored, GoalStatus::accepted);
      // A resend of the request that waits for its start cycle is answered again: the client may
      // not have heard the first answer (its status reader can match after our reader matched its
      // writer; MoveStatus keeps no history for late joiners).
      if (pending_.has_value() && pending_->request_id == request.request_id) {
        report(request.request_id, Feedback::RESULT_WAITING);
      }
      continue;
    }
    last_request_ = request.request_id;
    cancel_plan(request.command == Request::COMMAND_STOP ? Feedback::REASON_STOPPED : Feedback::REASON_REPLACED);
    if (request.command == Request::COMMAND_STOP) {
      pending_.reset();
      outcome(request, GoalOutcome::When::now, GoalStatus::accepted);
      if (supervisor_stopped_ || !moving()) {
        // Nothing moves (or the brakes hold it): at rest where it is.
        abort_active(Feedback::REASON_STOPPED);
        require_neutral_ = true;
        if (auto* f = report(request.request_id, Feedback::RESULT_ARRIVED)) {
          // At rest where the reference holds now (the last cycle's).
          f->rest_trolley_position = output_.reference.trolley.position;
          f->rest_slew_angle = output_.reference.slew.position;
          f->rest_cable_length = output_.reference.cable_length.position;
          f->trolley_to_go = f->slew_to_go = f->cable_to_go = f->bridge_to_go = 0.0;
          if (bridge_) f->rest_bridge_position = bridge_->reference(source_ == Source::speed).position;
        }
        continue;
      }
      abort_active(Feedback::REASON_STOPPED);
      const std::uint8_t named = request.axes & kEveryAxis;
      soft_stop(request.request_id, named == 0 ? kEveryAxis : named);
      continue;
    }
    if (request.header.seq > seq) {
      pending_ = request;
      outcome(request, GoalOutcome::When::waiting, GoalStatus::accepted);
      report(request.request_id, Feedback::RESULT_WAITING);
      if (request.profile == Request::PROFILE_MINIMUM_TIME) plan_ahead(request, current);
      continue;
    }
    pending_.reset();
    const auto when = request.header.seq != 0 && request.header.seq < seq ? GoalOutcome::When::late : GoalOutcome::When::now;
    outcome(request, when, start(request));
  }
  // A minimum-time goal that waits and could not be planned when it arrived (the supervisor's sway
  // limit not heard yet, the crane still moving): planned as soon as it can be.
  if (pending_.has_value() && pending_->profile == Request::PROFILE_MINIMUM_TIME && !plan_request_ &&
      pending_->header.seq > seq) {
    plan_ahead(*pending_, current);
  }
  if (pending_.has_value() && pending_->header.seq <= seq) {
    const Request due = *pending_;
    pending_.reset();
    outcome(due, GoalOutcome::When::as_asked, start(due));
    hand_over();  // a plan made while it waited starts with it
  }

  // Operator speeds: taken in the manual modes; in SEMIAUTOMATIC they take over from a goal.
  take_speeds(cycle.speeds, seq);
  const auto all_targets = targets_of(seq);
  const std::array<double, 3> targets{all_targets[0], all_targets[1], all_targets[2]};
  targets_ = targets;
  if (bridge_) bridge_->speed_target = all_targets[3];
  const bool commanding = targets[0] != 0.0 || targets[1] != 0.0 || targets[2] != 0.0 || all_targets[3] != 0.0;
  if (require_neutral_ && have_operator_input_ && operator_speed_ == std::array<double, 3>{} &&
      (source_ == Source::profile || speed_.at_rest())) {
    require_neutral_ = false;
  }
  if (commanding && source_ == Source::profile) {
    if (active_ && (output_.phase == MovePhase::moving || paused_)) abort_active(Feedback::REASON_MANUAL_MOTION);
    active_ = false;
    paused_.reset();
    finishing_axes_ = 0;
    speed_.start(planner_.sample_now());
    if (bridge_) bridge_->speed.start(bridge_->planner.sample_now());
    source_ = Source::speed;
  }

  if (source_ == Source::profile) {
    const auto status = planner_.step(sample_period_, output_);
    if (status != common::StepStatus::ok) return status;
    if (bridge_) {
      // One move: moving while either axis moves, its duration the longer one's.
      (void)bridge_->planner.step(sample_period_, bridge_->output);
      if (bridge_->output.phase == MovePhase::moving && output_.phase == MovePhase::arrived) {
        output_.phase = MovePhase::moving;
      }
      output_.move_duration = std::max(output_.move_duration, bridge_->output.move_duration);
      output_.time_in_move = std::max(output_.time_in_move, bridge_->output.time_in_move);
    }
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
  } else {
    const SpeedShaping shaping = operating_mode_ == Status::OPERATION_MAINTENANCE ? SpeedShaping::none
                                                                                        : params.manual.shaping;
    held_axes_ = speed_.step(targets, sample_period_, params.manual, shaping, params.speed_bounds(), params.site,
                             zones_enabled_);
    // A stop naming axes: the others run on along planner_'s profile to their targets.
    const std::uint8_t ran_on = finishing_axes_;
    PlannerOutput run_on;
    if (ran_on != 0) {
      (void)planner_.step(sample_period_, run_on);
      const common::AxisReference* axes[3] = {&run_on.reference.trolley, &run_on.reference.slew,
                                              &run_on.reference.cable_length};
      for (std::size_t i = 0; i < 3; ++i) {
        const auto bit = static_cast<std::uint8_t>(1U << i);
        if ((ran_on & bit) == 0) continue;
        speed_.start_axis(i, *axes[i]);
        // A profile is at rest only at its ends: this axis has arrived.
        if (axes[i]->velocity == 0.0 && axes[i]->acceleration == 0.0) finishing_axes_ &= static_cast<std::uint8_t>(~bit);
      }
    }
    bool at_rest = speed_.at_rest();
    if (bridge_) {
      const auto& b = bridge_->params;
      const std::uint8_t held = bridge_->speed.step({bridge_->speed_target, 0.0, 0.0}, sample_period_, b.manual, shaping,
                                                    b.speed_bounds(), b.site, 0);
      if ((held & protocol::MoveRequest::AXIS_TROLLEY) != 0) held_axes_ |= protocol::MoveRequest::AXIS_BRIDGE;
      at_rest = at_rest && bridge_->speed.at_rest();
    }
    output_.reference = speed_.reference();
    if ((ran_on & protocol::MoveRequest::AXIS_TROLLEY) != 0) output_.reference.trolley = run_on.reference.trolley;
    if ((ran_on & protocol::MoveRequest::AXIS_SLEW) != 0) output_.reference.slew = run_on.reference.slew;
    if ((ran_on & protocol::MoveRequest::AXIS_HOIST) != 0) output_.reference.cable_length = run_on.reference.cable_length;
    output_.request_id = stop_id_;
    output_.phase = at_rest ? MovePhase::arrived : MovePhase::moving;
    const bool released = was_commanding_ && !commanding;
    if (stop_id_ == 0 && (released || (!speed_.at_rest() && ++cycles_since_manual_report_ >= kProgressCycles))) {
      if (auto* s = report(0, Feedback::RESULT_MANUAL)) report_rest(*s);
      cycles_since_manual_report_ = 0;
    }
    if (at_rest) {
      // At rest: back to holding the rest position (goals start from it).
      if (stop_id_ != 0) {
        if (auto* s = report(stop_id_, Feedback::RESULT_ARRIVED)) report_rest(*s);
      }
      stop_id_ = 0;
      const auto r = speed_.reference();
      common::CraneStateEstimate rest = current;
      rest.trolley_position = r.trolley.position;
      rest.slew_angle = r.slew.position;
      rest.cable_length = r.cable_length.position;
      (void)planner_.hold(rest);
      if (bridge_) hold_bridge(bridge_->speed.reference().trolley.position);
      source_ = Source::profile;
    }
  }
  was_commanding_ = commanding;
  common::from_reference(output_.reference, reference);
  if (bridge_) {
    const common::AxisReference b = bridge_->reference(source_ == Source::speed);
    reference.bridge_position = b.position;
    reference.bridge_velocity = b.velocity;
    reference.bridge_acceleration = b.acceleration;
  }
  if (planned_ && source_ == Source::profile && output_.request_id == planned_id_ && output_.phase != MovePhase::holding) {
    // A planned move, under way or arrived: the reference carries its law (the hold after the end).
    common::set_trajectory_feedback(planned_->laws[planned_->index(output_.time_in_move)], bridge_.has_value(), reference);
    output_.move_duration = planned_->minimum_time;  // T*: the path's samples end on the cycle after it
  } else {
    planned_.reset();
    reference.feedback_law = false;
    reference.swing_in_plane = reference.swing_in_plane_rate = 0.0;
    reference.swing_out_of_plane = reference.swing_out_of_plane_rate = 0.0;
    reference.trolley_feedforward_voltage = reference.second_feedforward_voltage = 0.0;
    reference.feedback_gain = {};
    reference.sliding_friction_reduction = 0.0;
  }
  reference.request_id = static_cast<std::uint32_t>(output_.request_id);
  reference.phase = static_cast<std::uint8_t>(output_.phase);
  reference.time_in_move = output_.time_in_move;
  reference.move_duration = output_.move_duration;
  common::same_cycle(estimate.header, reference.header);
  return common::StepStatus::ok;
}

}  // namespace crane::trajectory_planner
