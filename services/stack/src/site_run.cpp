#include "crane/stack/site_run.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/common/validation.hpp"
#include "crane/anti_collision/grant_guard.hpp"
#include "crane/common/site.hpp"
#include "crane/stack/in_process_stack.hpp"

namespace crane::stack {
namespace {

namespace ac = anti_collision;
using Request = protocol::MoveRequest;

constexpr double kSettledSpeed = 0.01;   // [m/s], [rad/s]
constexpr double kSettledSwing = 0.0087;  // [rad] (0.5 deg) swing amplitude

double wrap(double angle) { return std::remainder(angle, 2.0 * std::numbers::pi); }

// A leg: where to travel and the cable length to lower to there.
struct Leg {
  WorkPoint at;
  bool place{false};  // the job's second leg: the job is done when it ends
};

struct Crane {
  std::unique_ptr<InProcessStack> stack;
  std::vector<Leg> legs;  // left to do, front first
  std::size_t next_leg{0};
  // braked: its guard braked it (it left its grant); it stays braked and asks for nothing.
  enum class Phase { resting, asking, moving, dwelling, halting, halted, done, braked } phase{Phase::resting};
  std::optional<double> down_since;  // [s] its link to the site service is down since
  bool link_lost{false};             // down for link_deadline: the site service holds its whole reach
  double halt_from{0.0};             // [s] the link loss its soft stop answers
  std::vector<ac::Pose> path;    // the granted path or yield, path[0] where it started
  std::size_t waypoint{0};       // the waypoint being moved to
  bool yielding{false};
  std::uint32_t request_id{0};
  bool start_next{false};        // the move to waypoint + 1 starts at the next cycle
  std::optional<std::uint64_t> arrived_cycle;  // the reference arrived at this cycle
  std::optional<Request> stop_goal;             // a soft stop to send this cycle
  std::optional<ac::GrantGuard> guard;          // the crane's own enforcement of its grant
  std::uint64_t dwell_until{0};
  double asked_at{0.0};
  CraneOutcome outcome;
};

// The estimator's state as the site's geometry takes it.
ac::CraneMotion motion_of(const protocol::CraneState& e) {
  ac::CraneMotion m;
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

ac::Pose measured_pose(const InProcessStack& stack) {
  const auto& e = stack.estimate();
  return {e.slew_angle, e.trolley_position, e.cable_length};
}

// The drives at rest (the swing may still decay).
bool at_rest(const InProcessStack& stack) {
  const auto& e = stack.estimate();
  return std::abs(e.trolley_velocity) < kSettledSpeed && std::abs(e.slew_rate) < kSettledSpeed &&
         std::abs(e.cable_length_rate) < kSettledSpeed;
}

bool settled(const InProcessStack& stack, double gravity) {
  const auto& e = stack.estimate();
  const double omega2 = gravity / std::max(e.cable_length, 0.01);
  const double amplitude = std::sqrt(e.swing_in_plane * e.swing_in_plane + e.swing_out_of_plane * e.swing_out_of_plane +
                                     (e.swing_in_plane_rate * e.swing_in_plane_rate +
                                      e.swing_out_of_plane_rate * e.swing_out_of_plane_rate) / omega2);
  return std::abs(e.trolley_velocity) < kSettledSpeed && std::abs(e.slew_rate) < kSettledSpeed &&
         std::abs(e.cable_length_rate) < kSettledSpeed && amplitude < kSettledSwing;
}

Request move_to(const ac::Pose& to, std::uint32_t id, double slew_acceleration) {
  Request r{};
  r.request_id = id;
  r.profile = Request::PROFILE_TRAPEZOID;
  r.command = Request::COMMAND_MOVE;
  // Every axis named: an axis left out keeps its measured position as its target, which the
  // planner refuses when it reads a hair outside its range (a hoist at its top: 0.19999 m).
  r.axes = Request::AXIS_SLEW | Request::AXIS_TROLLEY | Request::AXIS_HOIST;
  r.trolley_target = to.trolley;
  r.slew_target = to.slew;
  r.cable_length_target = to.cable_length;
  r.slew_max_acceleration = slew_acceleration;
  return r;
}

// The true parts of a crane from its plant's state (crane_geometry.hpp's capsules; the cable to
// the swinging load).
std::array<ac::Capsule, ac::kPartCount> true_parts(const ac::SiteCrane& c, const plant::PlantState& s) {
  common::Site local;
  local.jib_height = c.jib_height;
  const auto load = common::load_position(local, s.trolley_position, s.slew_angle, s.swing_in_plane,
                                          s.swing_out_of_plane, s.cable_length);
  const double h = c.slew_zero_heading;
  const auto to_site = [&](double x, double y, double z) {
    return ac::Vector3(c.base[0] + std::cos(h) * x - std::sin(h) * y, c.base[1] + std::sin(h) * x + std::cos(h) * y, z);
  };
  ac::CraneMotion m;
  m.slew = s.slew_angle;
  m.trolley = s.trolley_position;
  m.cable_length = s.cable_length;
  auto parts = ac::envelope(c, m, ac::StopKind::none).samples[0];  // jib, counter-jib, mast at the pose
  const ac::Vector3 sheave = to_site(s.trolley_position * std::cos(s.slew_angle), s.trolley_position * std::sin(s.slew_angle),
                                     c.jib_height);
  const ac::Vector3 hook = to_site(load[0], load[1], load[2]);
  parts[static_cast<std::size_t>(ac::Part::cable)] = {sheave, hook, 0.0};
  parts[static_cast<std::size_t>(ac::Part::load)] = {hook, hook, c.load_radius};
  return parts;
}

SiteOutcome run_together(const ac::SiteLayout& site, const StackConfig& config,
                         const std::vector<std::vector<SiteJob>>& jobs, const SiteRunOptions& options) {
  const std::size_t n = site.cranes.size();
  const auto arbiter_mode =
      options.mode == SiteMode::serialized ? ac::ArbiterMode::serialized : ac::ArbiterMode::coordinated;
  auto arbiter_ptr = std::make_unique<ac::SiteArbiter>(site, arbiter_mode);
  const double dt = config.facts.sample_period;
  const double gravity = config.facts.crane.gravity;
  const double hook_up_cable = config.trajectory_planner.cable_min_length;
  // Where each crane starts: its jib turned away from the site's centre, trolley in.
  double cx = 0.0, cy = 0.0;
  for (const auto& c : site.cranes) cx += c.base[0] / static_cast<double>(n), cy += c.base[1] / static_cast<double>(n);
  std::vector<Crane> cranes(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& c = site.cranes[i];
    InProcessOptions o;
    const double away = n > 1 ? std::atan2(c.base[1] - cy, c.base[0] - cx) : 0.0;
    const double low = std::max(c.slew_min, config.trajectory_planner.slew_min_angle) + 0.1;
    const double high = std::min(c.slew_max, config.trajectory_planner.slew_max_angle) - 0.1;
    o.initial_slew_angle = std::clamp(wrap(away - c.slew_zero_heading), low, high);
    o.initial_trolley_position = config.trajectory_planner.trolley_min_position + 0.1;
    cranes[i].stack = std::make_unique<InProcessStack>(config, o);
    for (const SiteJob& j : jobs[i]) {
      cranes[i].legs.push_back({j.pick, false});
      cranes[i].legs.push_back({j.place, true});
    }
    cranes[i].outcome.name = c.name;
    cranes[i].guard.emplace(site, i);
  }

  SiteOutcome out;
  out.min_distance = std::numeric_limits<double>::infinity();
  const auto limit = static_cast<std::uint64_t>(std::llround(options.time_limit / dt));
  const auto dwell_cycles = static_cast<std::uint64_t>(std::llround(options.dwell / dt));
  const auto settle_cycles = static_cast<std::uint64_t>(std::llround(options.settle_timeout / dt));
  std::vector<Request> goal(n);
  std::vector<bool> has_goal(n);
  std::vector<ac::Action> watched(n * n, ac::Action::clear);
  bool changed = true;
  bool service_was_down = false;
  std::uint64_t k = 0;
  for (; k < limit; ++k) {
    const double t = static_cast<double>(k) * dt;
    // The links: which are down, which came back, which are lost.
    const auto active = [&](const LinkFault& f) { return t >= f.start && t < f.start + f.duration; };
    const bool service_down = std::any_of(options.faults.begin(), options.faults.end(),
                                          [&](const LinkFault& f) { return f.crane == kSiteService && active(f); });
    if (service_was_down && !service_down) {
      // The site service restarted with no memory: every crane holds its whole reach until it
      // reports, and a request it had asked for is asked again.
      arbiter_ptr = std::make_unique<ac::SiteArbiter>(site, arbiter_mode);
      for (Crane& c : cranes) {
        if (c.phase == Crane::Phase::asking) c.phase = Crane::Phase::resting;
      }
      changed = true;
    }
    service_was_down = service_down;
    ac::SiteArbiter& arbiter = *arbiter_ptr;
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      const bool down = service_down || std::any_of(options.faults.begin(), options.faults.end(),
                                                    [&](const LinkFault& f) { return f.crane == i && active(f); });
      if (down && !c.down_since) c.down_since = t;
      if (!down && c.down_since) {
        // Back: the crane reports where it rests and asks again (a grant sent meanwhile was lost).
        c.down_since.reset();
        if (c.phase == Crane::Phase::halted || c.phase == Crane::Phase::asking) c.phase = Crane::Phase::resting;
        if (c.phase == Crane::Phase::done) {
          arbiter.rest(i, measured_pose(*c.stack));
          c.guard->grant(ac::rest_airspace(measured_pose(*c.stack), site.paths), t);
        }
        c.link_lost = false;
        changed = true;
      }
      if (!down) c.guard->heard(t);
      if (!down || c.link_lost || t - *c.down_since < site.link_deadline - 1e-9) continue;
      c.link_lost = true;
      if (!service_down) arbiter.lost(i);
      if (c.phase == Crane::Phase::moving || c.phase == Crane::Phase::dwelling) {
        std::vector<ac::Pose> rest{measured_pose(*c.stack)};
        rest.insert(rest.end(), c.path.begin() + static_cast<std::ptrdiff_t>(std::min(c.waypoint, c.path.size() - 1)), c.path.end());
        // The crane holds only what is ahead of it; its guard's rule 4 decides. A path longer than
        // an airspace holds is not checked: the crane stops.
        c.guard->progress(ac::path_airspace(rest, site.paths));
        if (rest.size() > ac::Airspace::kMaxBoxes + 1 || c.guard->must_leave_shared_airspace(t)) {
          c.phase = Crane::Phase::halting;
          c.halt_from = *c.down_since;
          c.arrived_cycle.reset();
          ++out.halts;
          // A soft stop, unless it would run out of the grant (a fast slew near its goal: the shaped
          // stop travels v T/4 further); then the move under way ends at its waypoint, inside.
          if (c.start_next || c.guard->soft_stop_stays_in_grant(motion_of(c.stack->estimate()))) {
            Request stop{};
            stop.request_id = ++c.request_id;
            stop.command = Request::COMMAND_STOP;
            c.stop_goal = stop;
          } else {
            ++out.halts_at_waypoint;
          }
          c.start_next = false;
          continue;
        }
        out.reactions.push_back(t - *c.down_since);  // it keeps to its own airspace
      } else if (c.phase != Crane::Phase::done) {
        if (c.phase == Crane::Phase::asking || c.phase == Crane::Phase::resting) c.phase = Crane::Phase::halted;
        out.reactions.push_back(t - *c.down_since);  // at rest already
      }
    }
    // A crane that disobeys (SiteRunOptions::rogue): told to move off its grant, without asking.
    std::vector<bool> estop(n, false);
    if (options.rogue && k == static_cast<std::uint64_t>(std::llround(options.rogue->time / dt))) {
      Crane& c = cranes.at(options.rogue->crane);
      c.phase = Crane::Phase::moving;
      c.start_next = false;
      c.arrived_cycle.reset();
      c.stop_goal = move_to(options.rogue->to, ++c.request_id, options.slew_acceleration);
      c.path = {measured_pose(*c.stack), options.rogue->to};
      c.waypoint = 1;
      c.yielding = true;  // its leg is not a job's
    }
    // Each crane's guard on its grant (grant_guard.hpp), every cycle: rules 1-3 brake the crane;
    // rule 4 (a lost link) is applied above; rule 5 (the swing) is counted, not applied.
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      if (k == 0 || c.phase == Crane::Phase::done || c.phase == Crane::Phase::braked) continue;  // no estimate at 0
      const ac::GrantCheck verdict = c.guard->check(motion_of(c.stack->estimate()), t);
      if (verdict.action == ac::GrantAction::proceed || c.guard->must_leave_shared_airspace(t)) continue;
      if (out.guard_first.empty()) {
        out.guard_first = site.cranes[i].name + " at " + std::to_string(t) + " s: " + verdict.reason;
      }
      if (verdict.action == ac::GrantAction::soft_stop) {
        ++out.guard_soft_stops;
        continue;
      }
      ++out.guard_emergency_stops;
      estop[i] = true;
      // Outside its grant the crane is somewhere the service did not give it: the service holds
      // its whole reach from now on, as for a crane that stops reporting.
      if (!service_down && !c.down_since) arbiter.lost(i);  // (link down: at its deadline)
      c.phase = Crane::Phase::braked;
      c.stop_goal.reset();
      c.outcome.braked_at = t;
    }
    // Each crane at rest asks for its next leg.
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      if (c.phase != Crane::Phase::resting || k == 0 || c.down_since) continue;
      const ac::Pose here = measured_pose(*c.stack);
      arbiter.rest(i, here);
      c.guard->grant(ac::rest_airspace(here, site.paths), t);
      changed = true;
      if (c.next_leg == c.legs.size()) {
        arbiter.withdraw(i);
        c.phase = Crane::Phase::done;
        continue;
      }
      const WorkPoint& w = c.legs[c.next_leg].at;
      std::vector<ac::Pose> path{here};
      if (here.cable_length > hook_up_cable + 1e-3) path.push_back({here.slew, here.trolley, hook_up_cable});
      path.push_back({w.slew, w.trolley, hook_up_cable});
      path.push_back({w.slew, w.trolley, w.cable_length});
      path.push_back({w.slew, w.trolley, hook_up_cable});
      arbiter.request(i, std::move(path), t);
      c.phase = Crane::Phase::asking;
      c.asked_at = t;
    }
    if (changed && !service_down) {
      changed = false;
      for (ac::Instruction& instruction : arbiter.decide()) {
        Crane& c = cranes[instruction.crane];
        // A crane whose link is down does not hear it (the service holds the path for it until it
        // reports again); an idle one (done) may be told to yield.
        if (c.down_since || (c.phase != Crane::Phase::asking && c.phase != Crane::Phase::done)) continue;
        c.yielding = instruction.kind == ac::Instruction::Kind::yield;
        if (c.yielding) ++c.outcome.yields;
        c.outcome.waiting_time += t - c.asked_at;
        c.path = std::move(instruction.waypoints);
        // The site file's hook range is the planner's cable range to its rounding (3.0 - 2.8 m).
        for (ac::Pose& p : c.path) {
          if (std::abs(p.cable_length - hook_up_cable) < 1e-9) p.cable_length = hook_up_cable;
        }
        c.guard->grant(ac::path_airspace(c.path, site.paths), t);
        c.waypoint = 0;
        c.phase = Crane::Phase::moving;
        c.start_next = true;
      }
    }
    // The next move of each crane that has one: the first of a path, the one after a dwell or
    // after the last move ended.
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      has_goal[i] = false;
      if (c.phase == Crane::Phase::dwelling && k >= c.dwell_until) {
        c.phase = Crane::Phase::moving;
        c.start_next = true;
      }
      if (c.phase != Crane::Phase::moving || !c.start_next) continue;
      c.start_next = false;
      if (c.waypoint > 0 && !c.down_since &&
          (arbiter.holding(i) == ac::Holding::path || arbiter.holding(i) == ac::Holding::yield)) {
        // What the crane left behind is free for the others.
        const std::vector<ac::Pose> ahead(c.path.begin() + static_cast<std::ptrdiff_t>(c.waypoint), c.path.end());
        arbiter.progress(i, ahead);
        c.guard->progress(ac::path_airspace(ahead, site.paths));
        changed = true;
      }
      ++c.waypoint;
      goal[i] = move_to(c.path[c.waypoint], ++c.request_id, options.slew_acceleration);
      has_goal[i] = true;
      c.arrived_cycle.reset();
    }
    for (std::size_t i = 0; i < n; ++i) {
      if (cranes[i].stop_goal) {
        goal[i] = *cranes[i].stop_goal;
        cranes[i].stop_goal.reset();
        has_goal[i] = true;
      }
      protocol::SupervisorCommand brake{};
      brake.request_id = 1;
      brake.command = protocol::SupervisorCommand::COMMAND_EMERGENCY_STOP;
      cranes[i].stack->step(has_goal[i] && !estop[i] ? std::span(&goal[i], 1) : std::span<const Request>(), {},
                            estop[i] ? &brake : nullptr);
      for (const auto& outcome : cranes[i].stack->planner().goal_outcomes()) {
        if (outcome.status != trajectory_planner::GoalStatus::accepted) {
          throw std::runtime_error("site run: " + site.cranes[i].name + "'s planner refused a move at " + std::to_string(t) +
                                   " s: " + trajectory_planner::goal_status_name(outcome.status) + " (targets: slew " +
                                   std::to_string(goal[i].slew_target) + " rad, trolley " + std::to_string(goal[i].trolley_target) +
                                   " m, cable " + std::to_string(goal[i].cable_length_target) + " m; after waypoint " + std::to_string(cranes[i].waypoint - 1) + " of " + std::to_string(cranes[i].path.size()) +
                                   (cranes[i].yielding ? " (yield)" : "") + "; supervisor faults " +
                                   std::to_string(cranes[i].stack->status().latched_faults) + ")");
        }
      }
    }
    // Moves that ended.
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      if (c.phase == Crane::Phase::halting) {
        const auto& r = c.stack->reference();
        // The stop was taken at the cycle it was sent: a soft stop's reference moves until it
        // arrives; a crane that was not moving (settling at a waypoint) holds at once.
        if (r.phase != protocol::Reference::PHASE_MOVING && at_rest(*c.stack)) {
          c.yielding = false;
          out.reactions.push_back(t + dt - c.halt_from);
          // At rest; if the link came back while it stopped, it asks again at once.
          c.phase = c.down_since ? Crane::Phase::halted : Crane::Phase::resting;
        }
        continue;
      }
      if (c.phase != Crane::Phase::moving || c.start_next) continue;
      const auto& r = c.stack->reference();
      if (r.request_id != c.request_id || r.phase != protocol::Reference::PHASE_ARRIVED) continue;
      if (!c.arrived_cycle) c.arrived_cycle = k;
      const bool timed_out = k - *c.arrived_cycle >= settle_cycles;
      if (!settled(*c.stack, gravity) && !timed_out) continue;
      if (timed_out) ++c.outcome.unsettled_moves;
      if (c.waypoint + 1 < c.path.size()) {
        if (!c.yielding && c.waypoint + 2 == c.path.size()) {  // at the work height
          c.phase = Crane::Phase::dwelling;
          c.dwell_until = k + dwell_cycles;
        } else {
          c.start_next = true;
        }
        continue;
      }
      if (!c.yielding) {
        if (c.legs[c.next_leg].place) {
          ++c.outcome.jobs_done;
          c.outcome.finish_time = t + dt;
        }
        ++c.next_leg;
      }
      c.yielding = false;
      c.phase = Crane::Phase::resting;
    }
    // The true distance between every two cranes.
    std::vector<std::array<ac::Capsule, ac::kPartCount>> parts(n);
    for (std::size_t i = 0; i < n; ++i) parts[i] = true_parts(site.cranes[i], cranes[i].stack->plant().simulator().state());
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        for (std::size_t p = 0; p < ac::kPartCount; ++p) {
          for (std::size_t q = 0; q < ac::kPartCount; ++q) {
            const double d = ac::capsule_distance(parts[i][p], parts[j][q]);
            if (d < out.min_distance) {
              out.min_distance = d;
              out.closest = site.cranes[i].name + "." + ac::to_string(static_cast<ac::Part>(p)) + "-" +
                            site.cranes[j].name + "." + ac::to_string(static_cast<ac::Part>(q)) + " at " +
                            std::to_string(t) + " s";
            }
          }
        }
      }
    }
    // The distance-watching rule, counted.
    if (k % kWatchStride == 0) {
      std::vector<ac::CraneEnvelope> soft(n), emergency(n);
      for (std::size_t i = 0; i < n; ++i) {
        const ac::CraneMotion m = motion_of(cranes[i].stack->estimate());
        soft[i] = ac::envelope(site.cranes[i], m, ac::StopKind::soft);
        emergency[i] = ac::envelope(site.cranes[i], m, ac::StopKind::emergency);
      }
      for (std::size_t i = 0; i < n; ++i) {
        for (std::size_t j = i + 1; j < n; ++j) {
          const ac::Action action = ac::classify(ac::distance(soft[i], soft[j]).distance,
                                                 ac::distance(emergency[i], emergency[j]).distance, site.margins);
          ac::Action& before = watched[i * n + j];
          if (action > before) {
            if (action >= ac::Action::slow_down && before < ac::Action::slow_down) ++out.watch_slow_downs;
            if (action >= ac::Action::stop && before < ac::Action::stop) ++out.watch_stops;
            if (action == ac::Action::emergency_stop) ++out.watch_emergency_stops;
          }
          before = action;
        }
      }
    }
    if (std::all_of(cranes.begin(), cranes.end(), [](const Crane& c) {
          return c.phase == Crane::Phase::done || c.phase == Crane::Phase::braked;
        })) {
      break;
    }
  }
  out.completed = k < limit && std::none_of(cranes.begin(), cranes.end(),
                                             [](const Crane& c) { return c.phase == Crane::Phase::braked; });
  out.unresolved = arbiter_ptr->unresolved();
  for (Crane& c : cranes) {
    c.outcome.latched_faults = c.stack->status().latched_faults;
    out.total_time = std::max(out.total_time, c.outcome.finish_time);
    out.cranes.push_back(c.outcome);
  }
  out.simulated_seconds = static_cast<double>(k) * dt * static_cast<double>(n);
  return out;
}

}  // namespace

const char* to_string(SiteMode mode) noexcept {
  switch (mode) {
    case SiteMode::coordinated: return "coordinated";
    case SiteMode::serialized: return "serialized";
    case SiteMode::solo: return "solo";
  }
  return "?";
}

StackConfig load_site_crane_config(const ac::SiteLayout& site) {
  if (site.cranes.empty()) throw common::ConfigError("site.cranes: the site has no crane");
  for (std::size_t i = 1; i < site.cranes.size(); ++i) {
    if (site.cranes[i].config != site.cranes[0].config) {
      throw common::ConfigError("site.cranes[" + std::to_string(i) + "].config = " + site.cranes[i].config +
                                " differs from site.cranes[0].config = " + site.cranes[0].config +
                                ": the simulated site runs one crane config");
    }
  }
  return load_stack_config(site.cranes[0].config);
}

SiteOutcome run_site(const ac::SiteLayout& site, const StackConfig& config, const std::vector<std::vector<SiteJob>>& jobs,
                     const SiteRunOptions& options) {
  ac::validate(site);
  if (jobs.size() != site.cranes.size()) {
    throw std::invalid_argument("site run: " + std::to_string(jobs.size()) + " job lists for " +
                                std::to_string(site.cranes.size()) + " cranes");
  }
  if (options.mode != SiteMode::solo) return run_together(site, config, jobs, options);
  SiteOutcome out;
  out.min_distance = std::numeric_limits<double>::infinity();
  out.completed = true;
  for (std::size_t i = 0; i < site.cranes.size(); ++i) {
    ac::SiteLayout alone = site;
    alone.cranes = {site.cranes[i]};
    const SiteOutcome one = run_together(alone, config, {jobs[i]}, options);
    out.cranes.push_back(one.cranes[0]);
    out.completed = out.completed && one.completed;
    out.total_time = std::max(out.total_time, one.total_time);
    out.simulated_seconds += one.simulated_seconds;
  }
  return out;
}

std::vector<LinkFault> random_link_faults(const ac::SiteLayout& site, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<LinkFault> faults;
  for (int f = 0; f < count; ++f) {
    LinkFault fault;
    fault.start = 80.0 * unit(rng);
    if (unit(rng) < 0.6) {
      fault.crane = std::min(site.cranes.size() - 1, static_cast<std::size_t>(unit(rng) * static_cast<double>(site.cranes.size())));
      fault.duration = 0.5 + 29.5 * unit(rng);
    } else {
      fault.crane = kSiteService;
      fault.duration = 0.5 + 9.5 * unit(rng);
    }
    faults.push_back(fault);
  }
  return faults;
}

std::vector<std::vector<SiteJob>> random_site_jobs(const ac::SiteLayout& site, const StackConfig& config, int per_crane,
                                                   std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto& planner = config.trajectory_planner;
  const double r_low = planner.trolley_min_position + 0.1;
  const double r_high = planner.trolley_max_position - 0.05;
  std::vector<std::vector<SiteJob>> jobs(site.cranes.size());
  for (std::size_t i = 0; i < site.cranes.size(); ++i) {
    const auto& c = site.cranes[i];
    const double s_low = std::max(c.slew_min, planner.slew_min_angle) + 0.2;
    const double s_high = std::min(c.slew_max, planner.slew_max_angle) - 0.2;
    const auto point = [&]() {
      const bool shared = site.cranes.size() > 1 && unit(rng) < 0.7;
      WorkPoint w;
      for (int attempt = 0; attempt < 1000; ++attempt) {
        w.slew = s_low + (s_high - s_low) * unit(rng);
        w.trolley = r_low + (r_high - r_low) * unit(rng);
        const double heading = c.slew_zero_heading + w.slew;
        const double x = c.base[0] + w.trolley * std::cos(heading);
        const double y = c.base[1] + w.trolley * std::sin(heading);
        bool in_other = false;
        for (std::size_t j = 0; j < site.cranes.size(); ++j) {
          if (j == i) continue;
          const double d = std::hypot(x - site.cranes[j].base[0], y - site.cranes[j].base[1]);
          in_other = in_other || (d > r_low && d < r_high);
        }
        if (!shared || in_other) break;
      }
      const double height = c.hook_height_min + 0.8 * unit(rng);
      w.cable_length = std::clamp(c.jib_height - height, planner.cable_min_length, planner.cable_max_length);
      return w;
    };
    for (int j = 0; j < per_crane; ++j) {
      SiteJob job;
      job.pick = point();
      job.place = point();
      jobs[i].push_back(job);
    }
  }
  return jobs;
}

}  // namespace crane::stack
