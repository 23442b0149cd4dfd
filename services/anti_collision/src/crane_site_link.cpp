#include "crane/anti_collision/crane_site_link.hpp"

#include "crane/trajectory_planner/trapezoid_profile.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <utility>

namespace crane::anti_collision {
namespace {

using Request = protocol::MoveRequest;

constexpr double kSettledSpeed = 0.01;    // [m/s], [rad/s]
constexpr double kSettledSwing = 0.0087;  // [rad] (0.5 deg) swing amplitude

Pose pose_of(const protocol::CraneState& e) noexcept { return {e.slew_angle, e.trolley_position, e.cable_length}; }

// The drives at rest (the swing may still decay).
bool at_rest(const protocol::CraneState& e) noexcept {
  return std::abs(e.trolley_velocity) < kSettledSpeed && std::abs(e.slew_rate) < kSettledSpeed &&
         std::abs(e.cable_length_rate) < kSettledSpeed;
}

bool settled(const protocol::CraneState& e, double gravity) noexcept {
  const double omega2 = gravity / std::max(e.cable_length, 0.01);
  const double amplitude = std::sqrt(e.swing_in_plane * e.swing_in_plane + e.swing_out_of_plane * e.swing_out_of_plane +
                                     (e.swing_in_plane_rate * e.swing_in_plane_rate +
                                      e.swing_out_of_plane_rate * e.swing_out_of_plane_rate) / omega2);
  return at_rest(e) && amplitude < kSettledSwing;
}

void check_point(const SiteCrane& c, const WorkPoint& w, std::size_t job, const char* which) {
  const auto refuse = [&](const char* field, double value, double low, double high) {
    throw std::invalid_argument("crane " + c.name + " job " + std::to_string(job) + " " + which + "." + field + " = " +
                                std::to_string(value) + " is outside [" + std::to_string(low) + ", " +
                                std::to_string(high) + "]");
  };
  if (!(w.slew >= c.slew_min && w.slew <= c.slew_max)) refuse("slew", w.slew, c.slew_min, c.slew_max);
  if (!(w.trolley >= c.trolley_min && w.trolley <= c.trolley_max)) refuse("trolley", w.trolley, c.trolley_min, c.trolley_max);
  const double shortest = c.jib_height - c.hook_height_max;
  const double longest = c.jib_height - c.hook_height_min;
  if (!(w.cable_length >= shortest - 1e-9 && w.cable_length <= longest + 1e-9)) {
    refuse("cable_length", w.cable_length, shortest, longest);
  }
}

// What moves_time needs of `params`, each finite: > 0, the slew speed >= 0 (0: rated).
void check_rates(const CraneLinkParams& params, const char* who) {
  const auto positive = [who](const char* field, double value) {
    if (!(value > 0.0) || !std::isfinite(value)) {
      throw std::invalid_argument(std::string(who) + ": " + field + " = " + std::to_string(value) + " must be > 0");
    }
  };
  positive("travel_cable_length", params.travel_cable_length);
  positive("gravity", params.gravity);
  positive("slew_acceleration", params.slew_acceleration);
  positive("rated.trolley.rated_speed", params.rated.trolley.rated_speed);
  positive("rated.trolley.acceleration", params.rated.trolley.acceleration);
  positive("rated.slew.rated_speed", params.rated.slew.rated_speed);
  positive("rated.hoist.rated_speed", params.rated.hoist.rated_speed);
  positive("rated.hoist.acceleration", params.rated.hoist.acceleration);
  if (!(params.slew_speed >= 0.0) || !std::isfinite(params.slew_speed)) {
    throw std::invalid_argument(std::string(who) + ": slew_speed = " + std::to_string(params.slew_speed) +
                                " must be >= 0");
  }
}

bool finite(const Pose& p) noexcept {
  return std::isfinite(p.slew) && std::isfinite(p.trolley) && std::isfinite(p.cable_length);
}

// moves_time, its arguments checked.
double checked_moves_time(std::span<const Pose> poses, const CraneLinkParams& params) {
  using trajectory_planner::AxisLimits;
  using trajectory_planner::TrapezoidProfile;
  const AxisLimits trolley{params.rated.trolley.rated_speed, params.rated.trolley.acceleration};
  const AxisLimits slew{params.slew_speed > 0.0 ? params.slew_speed : params.rated.slew.rated_speed,
                        params.slew_acceleration};
  const AxisLimits hoist{params.rated.hoist.rated_speed, params.rated.hoist.acceleration};
  const double swing_period = 2.0 * std::numbers::pi * std::sqrt(params.travel_cable_length / params.gravity);
  const std::vector<Pose> stops = stops_of(poses);
  double total = 0.0;
  for (std::size_t k = 1; k < stops.size(); ++k) {
    const Pose& a = stops[k - 1];
    const Pose& b = stops[k];
    const double move = std::max({TrapezoidProfile(a.slew, b.slew, slew).duration(),
                                  TrapezoidProfile(a.trolley, b.trolley, trolley).duration(),
                                  TrapezoidProfile(a.cable_length, b.cable_length, hoist).duration()});
    const bool travel = a.slew != b.slew || a.trolley != b.trolley;
    total += move + (travel ? swing_period : 0.0) + kSettleAllowance;
  }
  return total;
}

}  // namespace

bool ready_for_site(const protocol::SupervisorStatus& s) noexcept {
  using Status = protocol::SupervisorStatus;
  return s.stages_alive == Status::STAGES_ALL && s.brakes_released && s.latched_faults == 0 &&
         (s.mode == Status::MODE_READY || s.mode == Status::MODE_OPERATING) &&
         (s.warnings & Status::WARNING_SITE_UNHEARD) == 0;
}

static_assert(kStopTrolley == protocol::MoveRequest::AXIS_TROLLEY && kStopSlew == protocol::MoveRequest::AXIS_SLEW &&
                  kStopHoist == protocol::MoveRequest::AXIS_HOIST,
              "a stop's axes are the MoveRequest's AXIS bits");

const char* to_string(CraneSiteLink::ReactionEnd end) noexcept {
  using E = CraneSiteLink::ReactionEnd;
  switch (end) {
    case E::outside_shared: return "still on a path outside shared airspace";
    case E::at_rest_already: return "at rest already";
    case E::soft_stop: return "at rest after its soft stop";
    case E::at_waypoint: return "at rest at its move's waypoint (a soft stop would have left the grant)";
    case E::per_axis: return "at rest after a stop of some axes, the others at their waypoint (stopping them would have left the grant)";
  }
  return "?";
}

void CraneSiteLink::record_reaction(double lost_at, double time, ReactionEnd end) {
  const double seconds = time - lost_at;
  reactions_.push_back(seconds);
  if (!longest_reaction_ || seconds > longest_reaction_->seconds) longest_reaction_ = Reaction{lost_at, seconds, end};
}

const char* to_string(CraneSiteLink::Phase phase) noexcept {
  using P = CraneSiteLink::Phase;
  switch (phase) {
    case P::resting: return "resting";
    case P::asking: return "asking";
    case P::moving: return "moving";
    case P::dwelling: return "dwelling";
    case P::halting: return "halting";
    case P::halted: return "halted";
    case P::done: return "done";
    case P::braked: return "braked";
    case P::aborted: return "aborted";
  }
  return "?";
}

CraneMotion motion_of(const protocol::CraneState& e) noexcept {
  CraneMotion m;
  m.slew = e.slew_angle;
  m.slew_rate = e.slew_rate;
  m.trolley = e.trolley_position;
  m.trolley_velocity = e.trolley_velocity;
  m.cable_length = e.cable_length;
  m.cable_rate = e.cable_length_rate;
  m.swing_in_plane = e.swing_in_plane;
  m.swing_out_of_plane = e.swing_out_of_plane;
  m.swing_in_plane_rate = e.swing_in_plane_rate;
  m.swing_out_of_plane_rate = e.swing_out_of_plane_rate;
  return m;
}

ReferenceRest reference_rest_of(const protocol::Reference& r) noexcept {
  const auto rest = [](double position, double speed, double acceleration) -> std::optional<double> {
    if (std::abs(speed) <= kReferenceAtRest && std::abs(acceleration) <= kReferenceAtRest) return position;
    return std::nullopt;  // moving, or not finite
  };
  return {rest(r.slew_angle, r.slew_rate, r.slew_acceleration),
          rest(r.trolley_position, r.trolley_velocity, r.trolley_acceleration),
          rest(r.cable_length, r.cable_length_rate, r.cable_length_acceleration)};
}

Pose site_start_pose(const SiteLayout& layout, std::size_t crane, double planner_slew_min, double planner_slew_max,
                     double trolley) {
  const SiteCrane& c = layout.cranes.at(crane);
  const std::size_t n = layout.cranes.size();
  double cx = 0.0, cy = 0.0;
  for (const auto& other : layout.cranes) {
    cx += other.base[0] / static_cast<double>(n);
    cy += other.base[1] / static_cast<double>(n);
  }
  const double away = n > 1 ? std::atan2(c.base[1] - cy, c.base[0] - cx) : 0.0;
  const double low = std::max(c.slew_min, planner_slew_min) + 0.1;
  const double high = std::min(c.slew_max, planner_slew_max) - 0.1;
  const double slew = std::clamp(std::remainder(away - c.slew_zero_heading, 2.0 * std::numbers::pi), low, high);
  return {slew, trolley, c.jib_height - c.hook_height_max};
}

CraneSiteLink::CraneSiteLink(const SiteLayout& layout, std::size_t crane, const CraneLinkParams& params,
                             std::vector<SiteJob> jobs, std::uint32_t first_goal_id)
    : layout_(layout), crane_(crane), params_(params), guard_(layout, crane), goal_id_(first_goal_id) {
  check_rates(params, "site link");
  if (!(params.dwell > 0.0) || !std::isfinite(params.dwell) || !(params.settle_timeout > 0.0) ||
      !std::isfinite(params.settle_timeout)) {
    throw std::invalid_argument("site link: dwell = " + std::to_string(params.dwell) + " s and settle_timeout = " +
                                std::to_string(params.settle_timeout) + " s must be > 0");
  }
  const SiteCrane& c = layout_.cranes.at(crane_);
  for (std::size_t j = 0; j < jobs.size(); ++j) {
    check_point(c, jobs[j].pick, j, "pick");
    check_point(c, jobs[j].place, j, "place");
    legs_.push_back({jobs[j].pick, false});
    legs_.push_back({jobs[j].place, true});
  }
  work_state_.fill(std::numeric_limits<double>::quiet_NaN());
  // Each leg after the first from the work point before it, at the travel height.
  legs_after_.assign(legs_.size(), 0.0);
  for (std::size_t k = legs_.size(); k-- > 1;) {
    const WorkPoint& before = legs_[k - 1].at;
    legs_after_[k - 1] = legs_after_[k] + params_.dwell +
                         checked_moves_time(leg_path({before.slew, before.trolley, params_.travel_cable_length}, k), params_);
  }
}

void CraneSiteLink::heard(double time) noexcept { guard_.heard(time); }

void CraneSiteLink::move_status(const protocol::MoveStatus& status, double time) noexcept {
  if (!goal_ || goal_->request_id != status.request_id) return;
  goal_taken_ = true;
  const bool ended_short =
      status.result == protocol::MoveStatus::RESULT_ABORTED || status.result == protocol::MoveStatus::RESULT_REJECTED;
  if (ended_short && goal_->command == Request::COMMAND_MOVE && phase_ == Phase::moving && !ended_short_at_) {
    ended_short_at_ = time;
    ended_braked_ = status.result == protocol::MoveStatus::RESULT_ABORTED &&
                    status.reason == protocol::MoveStatus::REASON_BRAKED;
    stopped_at_.reset();
    ++aborted_moves_;
  }
}

bool CraneSiteLink::instruction(const SiteOrder& order, std::uint32_t epoch, double time) {
  if (order.crane != crane_ || order.waypoints.size() < 2) return false;
  guard_.heard(time);
  if (epoch == carried_epoch_ && order.seq <= carried_seq_) return false;  // sent again, or older
  const bool go = order.kind == Instruction::Kind::go;
  if (go ? (phase_ != Phase::asking || order.request_id != request_id_ || order.waypoints.size() > request_.size())
         : (phase_ != Phase::asking && phase_ != Phase::done && phase_ != Phase::aborted)) {
    return false;
  }
  // A go names the stops of the part of the request granted, its waypoints 0..part_end
  // (stops_of): the rest is asked from there.
  std::size_t part_end = 0;
  if (go) {
    const auto same = [](const Pose& a, const Pose& b) {
      return a.slew == b.slew && a.trolley == b.trolley && a.cable_length == b.cable_length;
    };
    for (std::size_t j = request_.size() - 1; j >= 1 && part_end == 0; --j) {
      const std::vector<Pose> stops = stops_of(std::span(request_).first(j + 1));
      if (std::equal(stops.begin(), stops.end(), order.waypoints.begin(), order.waypoints.end(), same)) part_end = j;
    }
    if (part_end == 0) return false;  // not the stops of a part of the request
  }
  rest_of_leg_.clear();
  if (go && part_end + 1 < request_.size()) {  // a part of the leg: the rest asked at its end
    rest_of_leg_.assign(request_.begin() + static_cast<std::ptrdiff_t>(part_end), request_.end());
  }
  yielding_ = !go;
  if (yielding_) ++yields_;
  waiting_time_ += phase_ == Phase::asking ? time - asked_at_ : 0.0;
  path_ = order.waypoints;
  // The site file's hook range is the planner's cable range to its rounding (3.0 - 2.8 m).
  for (Pose& p : path_) {
    if (std::abs(p.cable_length - params_.travel_cable_length) < 1e-9) p.cable_length = params_.travel_cable_length;
  }
  guard_.grant(path_airspace(path_, layout_.paths), time);
  carried_epoch_ = epoch;
  carried_seq_ = order.seq;
  request_id_ = 0;
  request_.clear();
  waypoint_ = 0;
  attempts_ = 0;
  ended_short_at_.reset();
  phase_ = Phase::moving;
  start_next_ = true;
  changed_ = true;
  return true;
}

Request CraneSiteLink::move_to(const Pose& to) {
  Request r{};
  r.request_id = ++goal_id_;
  r.profile = Request::PROFILE_TRAPEZOID;
  r.command = Request::COMMAND_MOVE;
  // Every axis named: an axis left out keeps its measured position as its target, which the
  // planner refuses when it reads a hair outside its range (a hoist at its top: 0.19999 m).
  r.axes = Request::AXIS_SLEW | Request::AXIS_TROLLEY | Request::AXIS_HOIST;
  r.trolley_target = to.trolley;
  r.slew_target = to.slew;
  r.cable_length_target = to.cable_length;
  r.slew_max_acceleration = params_.slew_acceleration;
  r.slew_max_velocity = params_.slew_speed;
  return r;
}

std::vector<Pose> CraneSiteLink::leg_path(const Pose& here, std::size_t leg) const {
  const WorkPoint& w = legs_[leg].at;
  const double up = params_.travel_cable_length;
  std::vector<Pose> path{here};
  if (here.cable_length > up + kSameCable) path.push_back({here.slew, here.trolley, up});
  // Waypoints on the travel's way (the site file's travel_step), as many as the request has room for.
  const Pose from = path.back();
  const std::size_t room = Airspace::kMaxBoxes + 1 - path.size() - 3;
  const double travel = std::max(std::abs(w.slew - from.slew), std::abs(w.trolley - from.trolley));
  if (layout_.travel_step > 0.0 && travel > layout_.travel_step) {
    const auto pieces = std::min<std::size_t>(room + 1, static_cast<std::size_t>(std::ceil(travel / layout_.travel_step)));
    for (std::size_t k = 1; k < pieces; ++k) {
      const double f = static_cast<double>(k) / static_cast<double>(pieces);
      path.push_back({from.slew + f * (w.slew - from.slew), from.trolley + f * (w.trolley - from.trolley), up});
    }
  }
  path.push_back({w.slew, w.trolley, up});
  path.push_back({w.slew, w.trolley, w.cable_length});
  path.push_back({w.slew, w.trolley, up});
  return path;
}

void CraneSiteLink::rest_at(const Pose& here, double time) {
  guard_.grant(rest_airspace(here, layout_.paths), time);
  changed_ = true;
  if (next_leg_ == legs_.size()) {
    phase_ = Phase::done;
    return;
  }
  request_ = leg_path(here, next_leg_);
  rest_of_leg_.clear();
  request_id_ = ++requests_;  // a new id: a new request
  phase_ = Phase::asking;
  asked_at_ = time;
}

void CraneSiteLink::ask_rest_of_leg(double time) {
  guard_.grant(rest_airspace(pose_, layout_.paths), time);
  // From the waypoint it rests at, not its measured pose: a hair of slew between the two would make
  // the next segment, the hoist's, a travel's, held with the travel swing.
  request_ = rest_of_leg_;
  rest_of_leg_.clear();
  request_id_ = ++requests_;
  phase_ = Phase::asking;
  asked_at_ = time;
  changed_ = true;
}

Request CraneSiteLink::disobey(const Pose& to, const Pose& here) {
  phase_ = Phase::moving;
  start_next_ = false;
  arrived_at_.reset();
  path_ = {here, to};
  waypoint_ = 1;
  passed_ = here;
  yielding_ = true;  // its leg is not a job's
  request_id_ = 0;
  request_.clear();
  goal_ = move_to(to);
  goal_taken_ = true;
  changed_ = true;
  return *goal_;
}

std::optional<Request> CraneSiteLink::step(double time, const protocol::CraneState& estimate,
                                           const protocol::Reference& reference, bool braked) {
  auto goal = advance(time, estimate, reference, braked);
  // At rest with legs left, it asks in the same cycle: its report never shows it idle between two
  // legs (the service would take it for an idle crane in the way and tell it to yield).
  if (phase_ == Phase::resting && !link_lost_) rest_at(pose_, time);
  refresh_work_left();
  return goal;
}

std::optional<Request> CraneSiteLink::advance(double time, const protocol::CraneState& estimate,
                                              const protocol::Reference& reference, bool braked) {
  if (phase_ == Phase::braked) return std::nullopt;
  pose_ = pose_of(estimate);
  motion_ = motion_of(estimate);
  stepped_ = true;
  if (braked) {
    phase_ = Phase::braked;
    changed_ = true;
    return std::nullopt;
  }
  std::optional<Request> goal;
  const bool lost = guard_.link_lost(time);
  if (link_lost_ && !lost) {
    // Back: a crane waiting at rest reports where it rests and asks again.
    link_lost_ = false;
    if (phase_ == Phase::halted || phase_ == Phase::asking) phase_ = gave_up_ ? Phase::aborted : Phase::resting;
    if (phase_ == Phase::done) guard_.grant(rest_airspace(pose_, layout_.paths), time);
    changed_ = true;
  } else if (!link_lost_ && lost) {
    link_lost_ = true;
    lost_from_ = time - layout_.link_deadline;
    if (phase_ == Phase::moving || phase_ == Phase::dwelling) {
      std::vector<Pose> rest{pose_};
      rest.insert(rest.end(), path_.begin() + static_cast<std::ptrdiff_t>(std::min(waypoint_, path_.size() - 1)),
                  path_.end());
      // The crane holds only what is ahead of it; its guard's rule 4 decides. A path longer than
      // an airspace holds is not checked: the crane stops.
      guard_.progress(path_airspace(rest, layout_.paths));
      if (rest.size() > Airspace::kMaxBoxes + 1 || guard_.must_leave_shared_airspace(time)) {
        phase_ = Phase::halting;
        halt_from_ = lost_from_;
        arrived_at_.reset();
        ended_short_at_.reset();
        ++halts_;
        constexpr std::uint8_t kEveryAxis = kStopTrolley | kStopSlew | kStopHoist;
        // At rest at a waypoint it was about to leave: every axis. Otherwise the axes whose soft stop
        // stays inside the grant, the others on to the move's waypoint (GrantGuard::soft_stop_axes).
        const std::optional<std::uint8_t> stopped =
            start_next_ ? std::optional<std::uint8_t>(kEveryAxis)
                        : guard_.soft_stop_axes(motion_of(estimate), reference_rest_of(reference),
                                                path_[std::min(waypoint_, path_.size() - 1)]);
        halt_at_waypoint_ = !stopped.has_value();
        halt_per_axis_ = stopped.has_value() && *stopped != kEveryAxis;
        if (!halt_at_waypoint_) {
          if (halt_per_axis_) ++halts_per_axis_;
          Request stop{};
          stop.request_id = ++goal_id_;
          stop.command = Request::COMMAND_STOP;
          stop.axes = *stopped;
          goal_ = stop;
          goal_taken_ = false;
          goal_sent_ = time;
          goal = stop;
        } else {
          ++halts_at_waypoint_;  // a soft stop would run out of the grant: the move under way ends at its waypoint
        }
        start_next_ = false;
        changed_ = true;
        return goal;
      }
      record_reaction(lost_from_, time, ReactionEnd::outside_shared);  // it keeps to its own airspace
    } else if (phase_ != Phase::done && phase_ != Phase::halting && phase_ != Phase::aborted) {
      if (phase_ == Phase::asking || phase_ == Phase::resting) phase_ = Phase::halted;
      record_reaction(lost_from_, time, ReactionEnd::at_rest_already);
      changed_ = true;
    }
  }

  if (phase_ == Phase::dwelling && time >= dwell_until_ - 1e-9) {
    if (waypoint_ + 1 < path_.size()) {
      phase_ = Phase::moving;
      start_next_ = true;
    } else if (!link_lost_) {  // the end of the part of its leg it was granted
      ask_rest_of_leg(time);
    } else {
      rest_of_leg_.clear();
      phase_ = Phase::resting;
      changed_ = true;
    }
  }
  if (phase_ == Phase::moving && start_next_) {
    start_next_ = false;
    if (waypoint_ > 0) {
      // What the crane left behind is free for the others (its report says so).
      guard_.progress(path_airspace(std::vector<Pose>(path_.begin() + static_cast<std::ptrdiff_t>(waypoint_), path_.end()),
                                    layout_.paths));
      changed_ = true;
    }
    ++waypoint_;
    passed_ = path_[waypoint_ - 1];
    attempts_ = 0;
    goal_ = move_to(path_[waypoint_]);
    goal_taken_ = false;
    goal_sent_ = time;
    arrived_at_.reset();
    return goal_;
  }

  // Progress within the segment under way (grant_guard.hpp, kProgressStep): what the crane has
  // passed on each axis is free for the others. Not while the link is lost: the service holds its
  // whole reach, and the guard holds what lay ahead at the loss.
  if (phase_ == Phase::moving && !link_lost_ && waypoint_ >= 1 && waypoint_ < path_.size()) {
    const Pose passed = passed_point(path_[waypoint_ - 1], path_[waypoint_], pose_, passed_);
    if (passed.slew != passed_.slew || passed.trolley != passed_.trolley ||
        passed.cable_length != passed_.cable_length) {
      passed_ = passed;
      guard_.progress(path_airspace(rest_of_path(), layout_.paths));
      changed_ = true;
    }
  }

  // A goal the planner has not answered is sent again.
  if (goal_ && !goal_taken_ && time - goal_sent_ >= kGoalResendPeriod - 1e-9) {
    goal_sent_ = time;
    goal = goal_;
  }

  if (phase_ == Phase::halting) {
    // A soft stop's reference moves until it arrives; a crane settling at a waypoint holds at once.
    if (reference.phase != protocol::Reference::PHASE_MOVING && at_rest(estimate)) {
      yielding_ = false;
      record_reaction(halt_from_, time,
                      halt_at_waypoint_ ? ReactionEnd::at_waypoint
                      : halt_per_axis_  ? ReactionEnd::per_axis
                                        : ReactionEnd::soft_stop);
      phase_ = link_lost_ ? Phase::halted : gave_up_ ? Phase::aborted : Phase::resting;
      changed_ = true;
    }
    return goal;
  }
  if (phase_ != Phase::moving) return goal;
  if (ended_short_at_) {
    // The move ended short: once the crane rests and has settled, the move is sent again, or, the
    // last attempt spent, the crane rests where it is.
    if (reference.phase == protocol::Reference::PHASE_MOVING || !at_rest(estimate)) {
      stopped_at_.reset();
      return goal;
    }
    if (!stopped_at_) stopped_at_ = time;
    const bool calm = settled(estimate, params_.gravity) || time - *stopped_at_ >= params_.settle_timeout - 1e-9;
    if (!calm || time - *ended_short_at_ < kGoalResendPeriod - 1e-9) return goal;
    ended_short_at_.reset();
    stopped_at_.reset();
    if (!ended_braked_ && ++attempts_ >= kMoveAttempts) {
      gave_up_ = true;
      yielding_ = false;
      goal_.reset();
      phase_ = Phase::aborted;
      guard_.grant(rest_airspace(pose_, layout_.paths), time);
      changed_ = true;
      return goal;
    }
    goal_ = move_to(path_[waypoint_]);
    goal_taken_ = false;
    goal_sent_ = time;
    arrived_at_.reset();
    return goal_;
  }
  if (!goal_ || reference.request_id != goal_->request_id || reference.phase != protocol::Reference::PHASE_ARRIVED) {
    return goal;
  }
  if (!arrived_at_) arrived_at_ = time;
  const bool timed_out = time - *arrived_at_ >= params_.settle_timeout - 1e-9;
  // The work height: the leg's last waypoint but one (the leg ends lowering, then hoisting up).
  const bool work_height = !yielding_ && (rest_of_leg_.empty() ? waypoint_ + 2 == path_.size()
                                                                : rest_of_leg_.size() == 2 && waypoint_ + 1 == path_.size());
  if (!settled(estimate, params_.gravity) && !timed_out) return goal;
  if (timed_out) ++unsettled_moves_;
  if (waypoint_ + 1 < path_.size() || (work_height && !rest_of_leg_.empty())) {
    if (work_height) {
      phase_ = Phase::dwelling;
      dwell_until_ = time + params_.dwell;
    } else {
      start_next_ = true;
    }
    return goal;
  }
  if (!yielding_ && !rest_of_leg_.empty()) {  // the end of the part of its leg it was granted
    if (!link_lost_) {
      ask_rest_of_leg(time);
    } else {
      rest_of_leg_.clear();  // it asks for the whole leg when the link is back
      phase_ = Phase::resting;
      changed_ = true;
    }
    return goal;
  }
  if (!yielding_) {
    if (legs_[next_leg_].place) {
      ++jobs_done_;
      finish_time_ = time;
    }
    ++next_leg_;
  }
  yielding_ = false;
  phase_ = gave_up_ ? Phase::aborted : Phase::resting;
  if (gave_up_) guard_.grant(rest_airspace(pose_, layout_.paths), time);
  changed_ = true;
  return goal;
}

std::optional<CraneReport> CraneSiteLink::report() const {
  if (phase_ == Phase::braked || !stepped_) return std::nullopt;
  CraneReport r;
  r.crane = crane_;
  r.moving = phase_ == Phase::moving || phase_ == Phase::dwelling || phase_ == Phase::halting;
  if (r.moving) {
    r.waypoints = rest_of_path();
  } else {
    r.waypoints = {pose_};
  }
  r.motion = motion_;
  r.instruction_epoch = carried_epoch_;
  r.instruction_seq = carried_seq_;
  if (phase_ == Phase::asking) {
    r.request_id = request_id_;
    r.request = request_;
  }
  r.work_left = work_left();
  return r;
}

double moves_time(std::span<const Pose> poses, const CraneLinkParams& params) {
  check_rates(params, "moves_time");
  if (!std::all_of(poses.begin(), poses.end(), finite)) throw std::invalid_argument("moves_time: a pose is not finite");
  return checked_moves_time(poses, params);
}

void CraneSiteLink::refresh_work_left() {
  // What the estimate depends on (rest_of_path() included), compared with the last: far cheaper
  // than the estimate, and no allocation.
  const std::array<double, kWorkStateSize> state{
      static_cast<double>(phase_), static_cast<double>(next_leg_), static_cast<double>(waypoint_),
      start_next_ ? 1.0 : 0.0, static_cast<double>(request_id_), yielding_ ? 1.0 : 0.0,
      static_cast<double>(rest_of_leg_.size()), static_cast<double>(path_.size()), passed_.slew, passed_.trolley,
      passed_.cable_length};
  if (state == work_state_) return;
  work_state_ = state;
  if (next_leg_ >= legs_.size() || phase_ == Phase::done || phase_ == Phase::braked || phase_ == Phase::aborted) {
    work_left_ = 0.0;
    return;
  }
  // The rest of the leg it is on, from where it stands (or where its yield ends).
  std::vector<Pose> rest;
  if (phase_ == Phase::asking) {
    rest = request_;
  } else if ((phase_ == Phase::moving || phase_ == Phase::dwelling || phase_ == Phase::halting) && !yielding_) {
    rest = rest_of_path();
    if (!rest_of_leg_.empty()) rest.insert(rest.end(), rest_of_leg_.begin() + 1, rest_of_leg_.end());
  } else {
    Pose from = pose_;
    if (yielding_ && !path_.empty()) {
      rest = rest_of_path();
      from = path_.back();
    }
    const std::vector<Pose> leg = leg_path(from, next_leg_);
    rest.insert(rest.end(), leg.begin() + (rest.empty() ? 0 : 1), leg.end());
  }
  const WorkPoint& w = legs_[next_leg_].at;
  const auto at_work_point = [&](const Pose& p) {
    return p.slew == w.slew && p.trolley == w.trolley && std::abs(p.cable_length - w.cable_length) < kSameCable;
  };
  if (!std::all_of(rest.begin(), rest.end(), finite)) return;  // a NaN estimate: keep the last
  double total = checked_moves_time(rest, params_) + legs_after_[next_leg_];
  if (std::any_of(rest.begin() + std::min<std::ptrdiff_t>(1, std::ssize(rest)), rest.end(), at_work_point)) {
    total += params_.dwell;
  }
  work_left_ = total;
}

std::vector<Pose> CraneSiteLink::rest_of_path() const {
  const std::size_t reached =
      waypoint_ == 0 ? 0 : (start_next_ || phase_ == Phase::dwelling ? waypoint_ : waypoint_ - 1);
  std::vector<Pose> rest(path_.begin() + static_cast<std::ptrdiff_t>(std::min(reached, path_.size() - 1)),
                         path_.end());
  if (reached + 1 == waypoint_ && waypoint_ < path_.size()) rest.front() = passed_;
  return rest;
}

CraneSiteLink::Activity CraneSiteLink::activity() const noexcept {
  switch (phase_) {
    case Phase::moving: break;
    case Phase::dwelling: return Activity::dwelling;
    case Phase::halting: return Activity::stopping;
    default: return Activity::at_rest;
  }
  if (yielding_) return Activity::yielding;
  // The segment under way: the one about to start when it has reached a waypoint.
  const std::size_t to = start_next_ ? waypoint_ + 1 : waypoint_;
  if (to == 0 || to >= path_.size()) return Activity::travelling;
  const Pose& from = path_[to - 1];
  const Pose& end = path_[to];
  if (from.slew != end.slew || from.trolley != end.trolley) return Activity::travelling;
  return end.cable_length > from.cable_length ? Activity::lowering : Activity::raising;
}

const char* to_string(CraneSiteLink::Activity activity) noexcept {
  using A = CraneSiteLink::Activity;
  switch (activity) {
    case A::at_rest: return "at rest";
    case A::travelling: return "travelling";
    case A::lowering: return "lowering";
    case A::dwelling: return "dwelling";
    case A::raising: return "raising";
    case A::yielding: return "yielding";
    case A::stopping: return "stopping";
  }
  return "unknown";
}

bool CraneSiteLink::report_changed() noexcept { return std::exchange(changed_, false); }

}  // namespace crane::anti_collision
