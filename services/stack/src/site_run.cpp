#include "crane/stack/site_run.hpp"

#include <algorithm>
#include <cstdio>
#include <deque>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>
#include <optional>
#include <random>
#include <stdexcept>
#include <string>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/crane_site_link.hpp"
#include "crane/anti_collision/site_service.hpp"
#include "crane/common/validation.hpp"
#include "crane/anti_collision/grant_guard.hpp"
#include "crane/common/site.hpp"
#include "crane/stack/in_process_stack.hpp"

namespace crane::stack {
namespace {

namespace ac = anti_collision;
using Request = protocol::MoveRequest;

// Each crane: its stack and its side of the site protocol (crane_site_link.hpp).
struct Crane {
  std::unique_ptr<InProcessStack> stack;
  std::unique_ptr<ac::CraneSiteLink> link;
  bool braked{false};  // its guard braked it (it left its grant): it stays braked
  std::uint64_t stop_cycle{std::numeric_limits<std::uint64_t>::max()};  // its host gone from this cycle on
  double out_of_service_after{std::numeric_limits<double>::infinity()};  // [s] the operator's word, after the stop
  double stuck_since{std::numeric_limits<double>::quiet_NaN()};  // [s] waiting for a stopped crane since
  CraneOutcome outcome;
  [[nodiscard]] bool host_stopped(std::uint64_t k) const noexcept { return k >= stop_cycle; }
};

std::uint32_t draw_epoch(std::uint32_t restarts) { return 7001u + 7919u * restarts; }

// CraneOutcome::timeline, after the crane's step of cycle k: a new interval whenever what its
// report holds changes, none once its jobs are done.
void record_timeline(Crane& c, std::uint64_t k, const ac::PathAllowance& paths) {
  if (c.link->phase() == ac::CraneSiteLink::Phase::done || c.link->phase() == ac::CraneSiteLink::Phase::braked) return;
  const std::optional<ac::CraneReport> report = c.link->report();
  if (!report || report->waypoints.empty()) return;
  const std::vector<ac::Pose>& w = report->waypoints;
  const ac::Airspace uses = report->moving && w.size() >= 2 ? ac::path_airspace(std::span(w.data(), 2), paths)
                                                             : ac::rest_airspace(w.front(), paths);
  std::vector<ac::TimelineStep>& steps = c.outcome.timeline.steps;
  const auto end = static_cast<std::int64_t>(k) + 1;  // it holds `uses` over cycle k (the first from 0)
  const bool rest = !report->moving;
  if (!steps.empty() && steps.back().rest == rest && ac::same_airspace(steps.back().uses, uses)) {
    steps.back().end_cycle = end;
  } else {
    steps.push_back({end, uses, rest});
  }
}

// A message on its way between a crane and the site service: a report (up), an instruction or a
// heartbeat (down), due at `at` [s].
struct InFlight {
  double at{0.0};
  std::optional<ac::CraneReport> report;
  std::optional<ac::SiteOrder> order;  // down: an instruction of epoch `epoch`; none: a heartbeat
  std::uint32_t epoch{0};
};

// One crane's link: what is on its way each way, in the order sent.
struct Wire {
  std::deque<InFlight> up, down;
};

ac::Pose measured_pose(const InProcessStack& stack) {
  const auto& e = stack.estimate();
  return {e.slew_angle, e.trolley_position, e.cable_length};
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
  std::uint32_t restarts = 0;
  auto service = std::make_unique<ac::SiteService>(site, arbiter_mode, draw_epoch(restarts));
  const double dt = config.facts.sample_period;
  ac::CraneLinkParams params;
  params.travel_cable_length = config.trajectory_planner.cable_min_length;
  params.rated = config.trajectory_planner.manual;
  params.dwell = options.dwell;
  params.settle_timeout = options.settle_timeout;
  params.slew_acceleration = options.slew_acceleration;
  params.gravity = config.facts.crane.gravity;
  const auto limit = static_cast<std::uint64_t>(std::llround(options.time_limit / dt));
  std::vector<Crane> cranes(n);
  for (const HostStop& h : options.host_stops) {
    const auto cycle = static_cast<std::uint64_t>(std::llround(h.time / dt));
    if (cycle < cranes[h.crane].stop_cycle) {
      cranes[h.crane].stop_cycle = cycle;
      cranes[h.crane].out_of_service_after = h.out_of_service_after;
    }
  }
  double faults_end = 0.0;  // [s] the last link fault over
  for (const LinkFault& f : options.faults) faults_end = std::max(faults_end, f.start + f.duration);
  for (std::size_t i = 0; i < n; ++i) {
    const ac::Pose start = ac::site_start_pose(site, i, config.trajectory_planner.slew_min_angle,
                                               config.trajectory_planner.slew_max_angle,
                                               config.trajectory_planner.trolley_min_position + 0.1);
    InProcessOptions o;
    o.initial_slew_angle = start.slew;
    o.initial_trolley_position = start.trolley;
    o.mismatch = options.plant_mismatch;
    if (cranes[i].stop_cycle < limit) {  // from its host's stop on, nothing reaches its drives
      o.lost_commands_from = cranes[i].stop_cycle;
      o.lost_commands = limit + 1 - cranes[i].stop_cycle;
    }
    cranes[i].stack = std::make_unique<InProcessStack>(config, o);
    cranes[i].link = std::make_unique<ac::CraneSiteLink>(site, i, params, jobs[i], 1);
    cranes[i].outcome.name = site.cranes[i].name;
  }

  SiteOutcome out;
  out.min_distance = std::numeric_limits<double>::infinity();
  std::vector<ac::Action> watched(n * n, ac::Action::clear);
  std::vector<Wire> wires(n);
  std::mt19937_64 loss_rng(options.loss_seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  bool service_was_down = false;
  std::uint64_t k = 0;
  for (; k < limit; ++k) {
    const double t = static_cast<double>(k) * dt;
    // The links: a crane whose link is down neither reports nor hears; a killed service hears and
    // sends nothing, and restarts (another epoch) with its memory file only (site_service
    // --memory): where each crane stood, used by nothing but the operator's word.
    const auto active = [&](const LinkFault& f) { return t >= f.start && t < f.start + f.duration; };
    const bool service_down = std::any_of(options.faults.begin(), options.faults.end(), [&](const LinkFault& f) {
      return f.crane == kSiteService && !f.degraded() && active(f);
    });
    if (service_was_down && !service_down) {
      const ac::SiteMemory memory = service->memory();  // as written before the kill (write-ahead)
      service = std::make_unique<ac::SiteService>(site, arbiter_mode, draw_epoch(++restarts));
      const std::string why = service->recall(memory);
      if (!why.empty()) throw std::logic_error("site run: " + why);
    }
    service_was_down = service_down;
    std::vector<bool> up(n);
    std::vector<const LinkFault*> degraded(n, nullptr);  // the first active degradation of each link
    for (std::size_t i = 0; i < n; ++i) {
      up[i] = !service_down && !cranes[i].host_stopped(k) && std::none_of(options.faults.begin(), options.faults.end(), [&](const LinkFault& f) {
        return f.crane == i && !f.degraded() && active(f);
      });
      // What was on its way over a link now down is lost (and to or from a killed service).
      if (!up[i]) wires[i] = Wire{};
      for (const LinkFault& f : options.faults) {
        if (degraded[i] == nullptr && f.degraded() && (f.crane == i || f.crane == kSiteService) && active(f)) {
          degraded[i] = &f;
        }
      }
    }
    // Sends `m` on crane i's link: due now, or later on a degraded link, never before what was
    // sent earlier the same way.
    const auto send = [&](std::size_t i, std::deque<InFlight>& way, InFlight m) {
      const LinkFault* f = degraded[i];
      const bool lost = f != nullptr && f->loss > 0.0 && unit(loss_rng) < f->loss;
      out.delayed_messages += f != nullptr ? 1 : 0;
      out.resent_messages += lost ? 1 : 0;
      m.at = arrival_time(t, f, lost, way.empty() ? -std::numeric_limits<double>::infinity() : way.back().at);
      way.push_back(std::move(m));
    };
    const auto due = [&](std::deque<InFlight>& way) { return !way.empty() && way.front().at <= t + 1e-9; };
    // Where the waits go: each crane that asked over the cycle now ending, by what the cranes the
    // service's last decision had it wait for were doing.
    for (std::size_t i = 0; k > 0 && i < n; ++i) {
      if (cranes[i].host_stopped(k) || cranes[i].link->phase() != ac::CraneSiteLink::Phase::asking) continue;
      const std::vector<std::size_t>& blockers = service->arbiter().waits_for(i);
      const ac::WaitReason why = service_down ? ac::WaitReason::none : service->arbiter().wait_reason(i);
      out.waited_why[static_cast<std::size_t>(why)] += dt;
      if (service_down || blockers.empty()) {
        out.waited_for_none += dt;
        continue;
      }
      for (const std::size_t j : blockers) {
        const double share = dt / static_cast<double>(blockers.size());
        if (cranes[j].host_stopped(k)) {
          out.waited_for_stopped_host += share;
        } else {
          out.waited_for[static_cast<std::size_t>(cranes[j].link->activity())] += share;
        }
      }
    }
    // The site operator's word: a stopped crane out of service, given each cycle of kWordWindow
    // until the service takes it.
    bool word_to_come = false;  // a word not yet given, or being given
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      const double from = static_cast<double>(c.stop_cycle) * dt + c.out_of_service_after;
      if (!c.host_stopped(k) || !std::isnan(c.outcome.out_of_service_at) || !std::isfinite(from) ||
          t >= from + kWordWindow) {
        continue;
      }
      word_to_come = true;
      if (service_down || t < from - 1e-9) continue;
      c.outcome.out_of_service_refused = service->out_of_service(i, t);
      if (c.outcome.out_of_service_refused.empty()) c.outcome.out_of_service_at = t;
    }
    // The reports of the last cycle's state, then the service's rules and its instructions.
    if (!service_down) {
      for (std::size_t i = 0; i < n; ++i) {
        if (!up[i]) continue;
        if (auto report = cranes[i].link->report()) send(i, wires[i].up, InFlight{0.0, std::move(report), {}, 0});
        for (; due(wires[i].up); wires[i].up.pop_front()) {
          const std::string why = service->report(*wires[i].up.front().report, t);
          if (!why.empty()) throw std::logic_error("site run: " + why);
        }
      }
      for (const ac::SiteOrder& order : service->step(t)) {
        if (up[order.crane]) send(order.crane, wires[order.crane].down, InFlight{0.0, {}, order, service->epoch()});
      }
      for (std::size_t i = 0; i < n; ++i) {
        if (!up[i]) continue;
        send(i, wires[i].down, InFlight{});  // its heartbeat
        for (; due(wires[i].down); wires[i].down.pop_front()) {
          const InFlight& m = wires[i].down.front();
          if (m.order) {
            (void)cranes[i].link->instruction(*m.order, m.epoch, t);
          } else {
            cranes[i].link->heard(t);
          }
        }
      }
    }
    // A crane that disobeys (SiteRunOptions::rogue): told to move off its grant, without asking.
    std::vector<std::optional<Request>> goal(n);
    if (options.rogue && k == static_cast<std::uint64_t>(std::llround(options.rogue->time / dt))) {
      Crane& c = cranes.at(options.rogue->crane);
      goal[options.rogue->crane] = c.link->disobey(options.rogue->to, measured_pose(*c.stack));
    }
    // Each crane's guard on its grant (grant_guard.hpp), every cycle: rules 1-3 brake the crane;
    // rule 4 (a lost link) is the link's to apply; rule 5 (the swing) is counted, not applied.
    std::vector<bool> estop(n, false);
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      const auto phase = c.link->phase();
      if (k == 0 || c.braked || c.host_stopped(k) || phase == ac::CraneSiteLink::Phase::done) continue;  // no estimate at 0
      const ac::GrantCheck verdict = c.link->guard().check(ac::motion_of(c.stack->estimate()), t);
      if (verdict.action == ac::GrantAction::proceed || c.link->guard().must_leave_shared_airspace(t)) continue;
      if (out.guard_first.empty()) {
        out.guard_first = site.cranes[i].name + " at " + std::to_string(t) + " s: " + verdict.reason;
      }
      if (verdict.action == ac::GrantAction::soft_stop) {
        ++out.guard_soft_stops;
        continue;
      }
      ++out.guard_emergency_stops;
      estop[i] = true;
      c.braked = true;  // its link then stops reporting: the service holds its whole reach
      c.outcome.braked_at = t;
    }
    for (std::size_t i = 0; i < n; ++i) {
      Crane& c = cranes[i];
      if (k > 0 && !c.host_stopped(k)) {
        // Braked: by its guard, or by its supervisor for a fault of its own (the sway limiter, ...).
        const bool braked = c.braked || c.stack->status().latched_faults != 0;
        if (auto g = c.link->step(t, c.stack->estimate(), c.stack->reference(), braked)) {
          if (!goal[i]) goal[i] = g;
        }
      }
      record_timeline(c, k, site.paths);
      protocol::SupervisorCommand brake{};
      brake.request_id = 1;
      brake.command = protocol::SupervisorCommand::COMMAND_EMERGENCY_STOP;
      c.stack->step(goal[i] && !estop[i] ? std::span(&*goal[i], 1) : std::span<const Request>(), {},
                    estop[i] ? &brake : nullptr);
      if (k == c.stop_cycle) {  // its supervisor's last word: what it latches later, on a dead host, is not heard
        c.outcome.host_stopped_at = t;
        c.outcome.latched_faults = c.stack->status().latched_faults;
        ++out.stopped_hosts;
      }
      if (c.host_stopped(k)) {  // its plant runs on, braked: when it comes to rest
        const plant::PlantState& s = c.stack->plant().simulator().state();
        if (std::isnan(c.outcome.rest_after_host_stop) && std::abs(s.trolley_velocity) < 0.01 &&
            std::abs(s.slew_rate) < 0.01 && std::abs(s.cable_length_rate) < 0.01) {
          c.outcome.rest_after_host_stop = t + dt - c.outcome.host_stopped_at;
        }
        continue;
      }
      for (const auto& status : c.stack->planner().move_statuses()) c.link->move_status(status, t);
      for (const auto& outcome : c.stack->planner().goal_outcomes()) {
        if (outcome.status != trajectory_planner::GoalStatus::accepted) {
          throw std::runtime_error("site run: " + site.cranes[i].name + "'s planner refused a move at " + std::to_string(t) +
                                   " s: " + trajectory_planner::goal_status_name(outcome.status) + " (targets: slew " +
                                   std::to_string(goal[i]->slew_target) + " rad, trolley " + std::to_string(goal[i]->trolley_target) +
                                   " m, cable " + std::to_string(goal[i]->cable_length_target) + " m; to waypoint " +
                                   std::to_string(c.link->waypoint()) + " of " + std::to_string(c.link->path().size()) +
                                   (c.link->yielding() ? " (yield)" : "") + "; supervisor faults " +
                                   std::to_string(c.stack->status().latched_faults) + ")");
        }
      }
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
        const ac::CraneMotion m = ac::motion_of(cranes[i].stack->estimate());
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
    // With a host stopped: the cranes that wait for it, each asking with every crane it waits for
    // stopped, done (it would have yielded if it could: a yield through the stopped crane's reach
    // cannot be granted) or blocked so in turn (the service holds the stopped crane's whole reach
    // for good).
    if (out.stopped_hosts > 0) {
      std::vector<bool> blocked(n);
      for (std::size_t i = 0; i < n; ++i) {
        blocked[i] = cranes[i].host_stopped(k) || cranes[i].link->phase() == ac::CraneSiteLink::Phase::done;
      }
      for (bool grew = true; grew;) {
        grew = false;
        for (std::size_t i = 0; i < n; ++i) {
          const std::vector<std::size_t>& blockers = service->arbiter().waits_for(i);
          if (blocked[i] || cranes[i].link->phase() != ac::CraneSiteLink::Phase::asking || blockers.empty() ||
              !std::all_of(blockers.begin(), blockers.end(), [&](std::size_t j) { return blocked[j]; })) {
            continue;
          }
          blocked[i] = grew = true;
        }
      }
      for (std::size_t i = 0; i < n; ++i) {
        Crane& c = cranes[i];
        if (!blocked[i] || c.host_stopped(k) || c.link->phase() == ac::CraneSiteLink::Phase::done) {
          c.stuck_since = std::numeric_limits<double>::quiet_NaN();
        } else if (std::isnan(c.stuck_since)) {
          c.stuck_since = t;
        }
      }
    }
    if (std::all_of(cranes.begin(), cranes.end(), [&](const Crane& c) {
          const bool stuck = c.stuck_since <= t - kStuckWait && t >= faults_end && !word_to_come;
          const bool stopped_at_rest = c.host_stopped(k) && !std::isnan(c.outcome.rest_after_host_stop);
          return c.link->phase() == ac::CraneSiteLink::Phase::done || c.braked || stopped_at_rest || stuck;
        })) {
      for (Crane& c : cranes) c.outcome.stuck = !std::isnan(c.stuck_since);
      break;
    }
  }
  out.completed = k < limit && std::none_of(cranes.begin(), cranes.end(), [](const Crane& c) { return c.braked; });
  out.unresolved = service->arbiter().unresolved();
  for (Crane& c : cranes) {
    const ac::CraneSiteLink& link = *c.link;
    c.outcome.jobs_done = link.jobs_done();
    c.outcome.finish_time = link.finish_time() + dt;
    if (link.jobs_done() == 0) c.outcome.finish_time = 0.0;
    c.outcome.waiting_time = link.waiting_time();
    c.outcome.yields = link.yields();
    c.outcome.unsettled_moves = link.unsettled_moves();
    if (std::isnan(c.outcome.host_stopped_at)) c.outcome.latched_faults = c.stack->status().latched_faults;
    out.total_time = std::max(out.total_time, c.outcome.finish_time);
    out.reactions.insert(out.reactions.end(), link.reactions().begin(), link.reactions().end());
    if (const auto& longest = link.longest_reaction(); longest && longest->seconds > out.longest_reaction_seconds) {
      out.longest_reaction_seconds = longest->seconds;
      char text[96];
      std::snprintf(text, sizeof text, ": link lost at %.2f s, safe %.2f s later, ", longest->lost_at, longest->seconds);
      out.longest_reaction = c.outcome.name + text + ac::to_string(longest->end);
    }
    out.halts += link.halts();
    out.halts_at_waypoint += link.halts_at_waypoint();
    out.halts_per_axis += link.halts_per_axis();
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
  for (const LinkFault& f : options.faults) {
    if (!(f.delay >= 0.0 && f.delay <= 60.0) || !(f.loss >= 0.0 && f.loss <= 1.0)) {
      throw std::invalid_argument("site run: a link fault's delay " + std::to_string(f.delay) + " s (in [0, 60]) or loss " +
                                  std::to_string(f.loss) + " (in [0, 1]) is out of range");
    }
  }
  for (const HostStop& h : options.host_stops) {
    if (h.crane >= site.cranes.size() || !(h.time >= 0.0 && h.time <= options.time_limit) ||
        !(h.out_of_service_after > 0.0)) {
      throw std::invalid_argument("site run: a host stop of crane " + std::to_string(h.crane) + " (in [0, " +
                                  std::to_string(site.cranes.size()) + ")) at " + std::to_string(h.time) +
                                  " s (in [0, time_limit " + std::to_string(options.time_limit) +
                                  "]), out of service after " + std::to_string(h.out_of_service_after) +
                                  " s (> 0), is out of range");
    }
  }
  if (options.mode != SiteMode::solo) return run_together(site, config, jobs, options);
  SiteOutcome out;
  out.min_distance = std::numeric_limits<double>::infinity();
  out.completed = true;
  for (std::size_t i = 0; i < site.cranes.size(); ++i) {
    ac::SiteLayout alone = site;
    alone.cranes = {site.cranes[i]};
    // Its own faults and host stops, and the site service's, as crane 0 of a site of one.
    SiteRunOptions own = options;
    own.faults.clear();
    own.host_stops.clear();
    for (LinkFault f : options.faults) {
      if (f.crane != i && f.crane != kSiteService) continue;
      if (f.crane == i) f.crane = 0;
      own.faults.push_back(f);
    }
    for (HostStop h : options.host_stops) {
      if (h.crane == i) own.host_stops.push_back({0, h.time, h.out_of_service_after});
    }
    const SiteOutcome one = run_together(alone, config, {jobs[i]}, own);
    out.cranes.push_back(one.cranes[0]);
    out.stopped_hosts += one.stopped_hosts;
    out.completed = out.completed && one.completed;
    out.total_time = std::max(out.total_time, one.total_time);
    out.simulated_seconds += one.simulated_seconds;
  }
  return out;
}

// One of the site's cranes, drawn uniformly from `u` in [0, 1).
std::size_t crane_drawn(const ac::SiteLayout& site, double u) {
  return std::min(site.cranes.size() - 1, static_cast<std::size_t>(u * static_cast<double>(site.cranes.size())));
}

std::vector<LinkFault> random_link_faults(const ac::SiteLayout& site, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<LinkFault> faults;
  for (int f = 0; f < count; ++f) {
    LinkFault fault;
    fault.start = 80.0 * unit(rng);
    if (unit(rng) < 0.6) {
      fault.crane = crane_drawn(site, unit(rng));
      fault.duration = 0.5 + 29.5 * unit(rng);
    } else {
      fault.crane = kSiteService;
      fault.duration = 0.5 + 9.5 * unit(rng);
    }
    faults.push_back(fault);
  }
  return faults;
}

std::vector<HostStop> random_host_stops(const ac::SiteLayout& site, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x57099edc0ULL);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<HostStop> stops;
  for (int f = 0; f < count; ++f) {
    HostStop stop;
    stop.crane = crane_drawn(site, unit(rng));
    stop.time = 80.0 * unit(rng);
    stops.push_back(stop);
  }
  return stops;
}

double arrival_time(double time, const LinkFault* fault, bool lost, double previous) noexcept {
  double at = time;
  if (fault != nullptr && fault->degraded()) at += fault->delay + (lost ? kResendDelay : 0.0);
  return std::max(at, previous);
}

std::vector<LinkFault> random_degraded_links(const ac::SiteLayout& site, int count, std::uint64_t seed) {
  std::mt19937_64 rng(seed ^ 0x5eedde1a7ULL);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::vector<LinkFault> faults;
  for (int f = 0; f < count; ++f) {
    LinkFault fault;
    fault.start = 80.0 * unit(rng);
    fault.duration = 5.0 + 25.0 * unit(rng);
    fault.crane = unit(rng) < 0.75 ? crane_drawn(site, unit(rng)) : kSiteService;
    fault.delay = 0.2 * unit(rng);
    fault.loss = 0.3 * unit(rng);
    if (!fault.degraded()) fault.delay = 0.001;  // 0 and 0 would be a lost link
    faults.push_back(fault);
  }
  return faults;
}

std::vector<std::vector<SiteJob>> random_site_jobs(const ac::SiteLayout& site, const StackConfig& config, int per_crane,
                                                   std::uint64_t seed, const SiteJobDraw& draw) {
  if (!(draw.shared_probability >= 0.0 && draw.shared_probability <= 1.0)) {
    throw std::invalid_argument("random_site_jobs: shared_probability " + std::to_string(draw.shared_probability) +
                                " outside [0, 1]");
  }
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
      const bool shared = site.cranes.size() > 1 && unit(rng) < draw.shared_probability;
      const bool clear_point = site.cranes.size() > 1 && !shared && draw.others_clear;
      WorkPoint w;
      for (int attempt = 0; attempt < 1000; ++attempt) {
        w.slew = s_low + (s_high - s_low) * unit(rng);
        w.trolley = r_low + (r_high - r_low) * unit(rng);
        const double heading = c.slew_zero_heading + w.slew;
        const double x = c.base[0] + w.trolley * std::cos(heading);
        const double y = c.base[1] + w.trolley * std::sin(heading);
        bool in_other = false;
        bool under_other_jib = false;
        for (std::size_t j = 0; j < site.cranes.size(); ++j) {
          if (j == i) continue;
          const double d = std::hypot(x - site.cranes[j].base[0], y - site.cranes[j].base[1]);
          in_other = in_other || (d > r_low && d < r_high);
          const auto& o = site.cranes[j];
          under_other_jib = under_other_jib || d <= std::max(o.jib_length, o.counter_jib_length) + site.margins.slow_down;
        }
        if (shared ? in_other : (!clear_point || !under_other_jib)) break;
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
