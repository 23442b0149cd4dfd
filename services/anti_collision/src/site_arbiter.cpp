#include "crane/anti_collision/site_arbiter.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <utility>

namespace crane::anti_collision {

const char* to_string(Holding holding) noexcept {
  switch (holding) {
    case Holding::rest: return "rest";
    case Holding::path: return "path";
    case Holding::yield: return "yield";
    case Holding::whole_reach: return "whole_reach";
    case Holding::out_of_service: return "out_of_service";
  }
  return "?";
}

const char* to_string(WaitReason reason) noexcept {
  switch (reason) {
    case WaitReason::none: return "none";
    case WaitReason::held: return "held";
    case WaitReason::starving: return "starving";
    case WaitReason::higher_cable: return "higher_cable";
    case WaitReason::most_work_left: return "most_work_left";
  }
  return "?";
}

SiteArbiter::SiteArbiter(SiteLayout layout, ArbiterMode mode) : layout_(std::move(layout)), mode_(mode) {
  validate(layout_);
  cranes_.resize(layout_.cranes.size());
  for (std::size_t i = 0; i < cranes_.size(); ++i) cranes_[i].held = whole_reach(layout_.cranes[i], layout_.paths);
}

bool SiteArbiter::clear(std::size_t i, const Airspace& a, std::size_t j, const Airspace& b) const noexcept {
  return airspace_distance(layout_.cranes[i], a, layout_.cranes[j], b).distance >= layout_.margins.slow_down;
}

void SiteArbiter::rest(std::size_t crane, const Pose& pose) {
  CraneState& c = cranes_.at(crane);
  c.holding = Holding::rest;
  c.held_when_lost.reset();
  c.pose = pose;
  c.held = rest_airspace(pose, layout_.paths);
  c.held_shared = false;
  c.path_end.reset();
}

namespace {

void check_waypoints(const std::string& crane, const std::vector<Pose>& waypoints) {
  if (waypoints.empty() || waypoints.size() > Airspace::kMaxBoxes + 1) {
    throw std::invalid_argument("site arbiter: a path of crane " + crane + " has " + std::to_string(waypoints.size()) +
                                " waypoints: must be 1 to " + std::to_string(Airspace::kMaxBoxes + 1));
  }
  for (const Pose& p : waypoints) {
    if (!std::isfinite(p.slew) || !std::isfinite(p.trolley) || !std::isfinite(p.cable_length) || !(p.cable_length > 0.0)) {
      throw std::invalid_argument("site arbiter: a path of crane " + crane + " has a non-finite waypoint or a cable length <= 0");
    }
  }
}

}  // namespace

void SiteArbiter::progress(std::size_t crane, const std::vector<Pose>& remaining) {
  CraneState& c = cranes_.at(crane);
  if (c.holding != Holding::path && c.holding != Holding::yield) {
    throw std::logic_error("site arbiter: crane " + layout_.cranes[crane].name + " reports progress holding " +
                           to_string(c.holding));
  }
  check_waypoints(layout_.cranes[crane].name, remaining);
  c.held = path_airspace(remaining, layout_.paths);
  c.held_shared = shared(crane, c.held);
}

void SiteArbiter::request(std::size_t crane, std::vector<Pose> waypoints, double time) {
  CraneState& c = cranes_.at(crane);
  check_waypoints(layout_.cranes[crane].name, waypoints);
  if (!std::isfinite(time)) throw std::invalid_argument("site arbiter: a request time is not finite");
  Request r;
  r.airspace = path_airspace(stops_of(waypoints), layout_.paths);
  r.waypoints = std::move(waypoints);
  r.time = time;
  r.shared = shared(crane, r.airspace);
  c.request = std::move(r);
}

void SiteArbiter::withdraw(std::size_t crane) { cranes_.at(crane).request.reset(); }

void SiteArbiter::work_left(std::size_t crane, double seconds) {
  CraneState& c = cranes_.at(crane);
  if (!std::isfinite(seconds) || seconds < 0.0) {
    throw std::invalid_argument("site arbiter: crane " + layout_.cranes[crane].name + "'s work left " +
                                std::to_string(seconds) + " s is not finite and >= 0");
  }
  c.work_left = seconds;
}

std::optional<std::size_t> SiteArbiter::most_work_left() const {
  if (!layout_.most_work_left_first) return std::nullopt;
  std::optional<std::size_t> most;
  bool tie = false;
  for (std::size_t i = 0; i < cranes_.size(); ++i) {
    const CraneState& c = cranes_[i];
    if (c.holding == Holding::whole_reach || c.holding == Holding::out_of_service) continue;  // not reporting
    if (!most || c.work_left > cranes_[*most].work_left) {
      most = i;
      tie = false;
    } else if (c.work_left == cranes_[*most].work_left) {
      tie = true;
    }
  }
  if (!most || tie || !cranes_[*most].request || cranes_[*most].holding != Holding::rest) return std::nullopt;
  return most;
}

void SiteArbiter::lost(std::size_t crane, bool moved) {
  CraneState& c = cranes_.at(crane);
  if (moved || c.holding == Holding::out_of_service) {
    c.held_when_lost.reset();  // it moved: where it stood says nothing any more
  } else if (c.holding != Holding::whole_reach) {
    c.held_when_lost = c.held;
    c.lost_moving = c.holding == Holding::path || c.holding == Holding::yield;
  }
  c.holding = Holding::whole_reach;
  c.held = whole_reach(layout_.cranes[crane], layout_.paths);
  c.held_shared = true;
  c.path_end.reset();
}

void SiteArbiter::out_of_service(std::size_t crane, const std::optional<CraneMotion>& last, double report_age) {
  CraneState& c = cranes_.at(crane);
  if ((last && !is_finite(*last)) || !(report_age >= 0.0) || !std::isfinite(report_age)) {
    throw std::invalid_argument("site arbiter: crane " + layout_.cranes[crane].name +
                                "'s last motion or report age is not finite (or the age is negative)");
  }
  const std::string& name = layout_.cranes[crane].name;
  if (c.holding != Holding::whole_reach) {
    throw std::logic_error("site arbiter: crane " + name + " holds " + to_string(c.holding) +
                           ": only a silent crane (whole_reach) can be put out of service");
  }
  if (!c.held_when_lost) {
    throw std::logic_error("site arbiter: crane " + name +
                           " went silent where this service did not know it stood (never heard at rest or on a grant, "
                           "with no memory of it, or it moved without a grant): its whole reach stays held");
  }
  c.holding = Holding::out_of_service;
  c.held = last ? out_of_service_airspace(layout_.cranes[crane], *c.held_when_lost, *last, report_age) : *c.held_when_lost;
  c.held_shared = shared(crane, c.held);
  c.request.reset();
}

std::optional<SiteArbiter::Place> SiteArbiter::place(std::size_t crane) const {
  const CraneState& c = cranes_.at(crane);
  switch (c.holding) {
    case Holding::rest: return Place{c.held, false};
    case Holding::path:
    case Holding::yield: return Place{c.held, true};
    case Holding::whole_reach:
    case Holding::out_of_service: break;
  }
  if (!c.held_when_lost) return std::nullopt;
  return Place{*c.held_when_lost, c.lost_moving};
}

void SiteArbiter::recall(std::size_t crane, const Place& place) {
  CraneState& c = cranes_.at(crane);
  const std::string& name = layout_.cranes[crane].name;
  if (c.holding != Holding::whole_reach || c.held_when_lost) {
    throw std::logic_error("site arbiter: crane " + name + " holds " + to_string(c.holding) +
                           (c.held_when_lost ? " and is known where it went silent" : "") +
                           ": only a crane this service never knew the place of can be recalled");
  }
  const Airspace& a = place.airspace;
  if (a.count == 0 || a.count > Airspace::kMaxBoxes) {
    throw std::invalid_argument("site arbiter: crane " + name + "'s recalled place has " + std::to_string(a.count) +
                                " boxes: must be in [1, " + std::to_string(Airspace::kMaxBoxes) + "]");
  }
  for (std::size_t k = 0; k < a.count; ++k) {
    const JointBox& b = a.boxes[k];
    const bool finite = std::isfinite(b.slew_low) && std::isfinite(b.slew_high) && std::isfinite(b.trolley_low) &&
                        std::isfinite(b.trolley_high) && std::isfinite(b.cable_low) && std::isfinite(b.cable_high) &&
                        std::isfinite(b.swing_radius);
    if (!finite || b.slew_low > b.slew_high || b.trolley_low > b.trolley_high || b.cable_low > b.cable_high ||
        !(b.cable_low > 0.0) || b.swing_radius < 0.0) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "'s recalled box %zu (slew [%g, %g] rad, trolley [%g, %g] m, cable [%g, %g] m, swing %g m) is not "
                    "finite, has a low end above its high end, a cable length <= 0 or a negative swing",
                    k, b.slew_low, b.slew_high, b.trolley_low, b.trolley_high, b.cable_low, b.cable_high, b.swing_radius);
      throw std::invalid_argument("site arbiter: crane " + name + text);
    }
  }
  c.held_when_lost = a;
  c.lost_moving = place.moving;
}

bool SiteArbiter::starving(std::size_t i) const noexcept {
  const auto& r = cranes_[i].request;
  return r && layout_.max_wait > 0.0 && decided_at_ >= r->time + layout_.max_wait;
}

bool SiteArbiter::first(std::size_t i) const noexcept { return starving(i) || critical_ == i; }

bool SiteArbiter::ranks_before(std::size_t i, std::size_t j) const {
  const bool si = first(i);
  const bool sj = first(j);
  if (si != sj) return si;
  if (si && cranes_[i].request->time != cranes_[j].request->time) return cranes_[i].request->time < cranes_[j].request->time;
  const int pi = layout_.cranes[i].priority;
  const int pj = layout_.cranes[j].priority;
  if (pi != pj) return pi > pj;
  const auto& ri = cranes_[i].request;
  const auto& rj = cranes_[j].request;
  if (ri && rj && ri->time != rj->time) return ri->time < rj->time;
  if (ri.has_value() != rj.has_value()) return ri.has_value();
  return i < j;
}

bool SiteArbiter::yields_jib_to(std::size_t i, std::size_t j) const {
  const SiteCrane& a = layout_.cranes[i];
  const SiteCrane& b = layout_.cranes[j];
  if (!(a.jib_height < b.jib_height) || layout_.cranes[i].priority != layout_.cranes[j].priority) return false;
  const PairDistance d = airspace_distance(a, cranes_[i].request->airspace, b, cranes_[j].request->airspace);
  return d.distance < layout_.margins.slow_down && (d.first == Part::jib || d.first == Part::counter_jib) &&
         (d.second == Part::cable || d.second == Part::load);
}

bool in_shared_airspace(const SiteLayout& layout, std::size_t crane, const Airspace& airspace) {
  const SiteCrane& self = layout.cranes.at(crane);
  for (std::size_t j = 0; j < layout.cranes.size(); ++j) {
    if (j == crane) continue;
    const Airspace reach = whole_reach(layout.cranes[j], layout.paths);
    if (airspace_distance(self, airspace, layout.cranes[j], reach).distance < layout.margins.slow_down) return true;
  }
  return false;
}

bool SiteArbiter::shared(std::size_t i, const Airspace& a) const { return in_shared_airspace(layout_, i, a); }

std::optional<std::vector<Pose>> SiteArbiter::yield_path(std::size_t v, const std::vector<std::size_t>& waiting) const {
  const SiteCrane& crane = layout_.cranes[v];
  const Pose here = cranes_[v].pose;
  const double hook_up = crane.jib_height - crane.hook_height_max;
  std::vector<Pose> candidates;
  if (here.cable_length > hook_up + 1e-9) candidates.push_back({here.slew, here.trolley, hook_up});
  for (int k = 1; k * kYieldSlewStep <= 2.0 * 3.14159265358979; ++k) {
    for (const double sign : {1.0, -1.0}) {
      const double slew = here.slew + sign * k * kYieldSlewStep;
      if (slew >= crane.slew_min && slew <= crane.slew_max) candidates.push_back({slew, here.trolley, hook_up});
    }
  }
  for (const Pose& target : candidates) {
    const Airspace at = rest_airspace(target, layout_.paths);
    const bool frees = std::all_of(waiting.begin(), waiting.end(),
                                   [&](std::size_t w) { return clear(v, at, w, cranes_[w].request->airspace); });
    if (!frees) continue;
    std::vector<Pose> path{here};
    if (here.cable_length > hook_up + 1e-9) path.push_back({here.slew, here.trolley, hook_up});
    if (target.slew != here.slew) path.push_back(target);
    const Airspace way = path_airspace(path, layout_.paths);
    bool free = true;
    for (std::size_t j = 0; j < cranes_.size() && free; ++j) free = j == v || clear(v, way, j, cranes_[j].held);
    if (free) return path;
  }
  return std::nullopt;
}

std::size_t SiteArbiter::part_of_leg(std::size_t i, const std::vector<std::size_t>& waits) const {
  if (!layout_.part_of_leg || mode_ != ArbiterMode::coordinated) return 0;
  const Request& r = *cranes_[i].request;
  if (r.waypoints.size() < 3) return 0;
  // What the cranes it waits for hold, and, for one moving on a path, the rest box at its end.
  std::vector<std::pair<std::size_t, Airspace>> kept;
  for (const std::size_t j : waits) {
    const CraneState& other = cranes_[j];
    if (other.holding == Holding::path && other.path_end) {
      kept.emplace_back(j, rest_airspace(*other.path_end, layout_.paths));
    } else if (other.holding != Holding::rest) {
      return 0;  // yielding, silent or out of service: it waits whole
    }
  }
  // What every other crane holds (a part of a leg is not always inside the whole leg's airspace:
  // its waypoints are the requester's word), and the rest boxes above.
  const auto clear_of_all = [&](const Airspace& a) {
    for (std::size_t j = 0; j < cranes_.size(); ++j) {
      if (j != i && !clear(i, a, j, cranes_[j].held)) return false;
    }
    return std::all_of(kept.begin(), kept.end(), [&](const auto& k) { return clear(i, a, k.first, k.second); });
  };
  // The last waypoint, not the leg's end (the leg meets them, or it would not wait), up to which
  // the part's stops and the rest box there keep clear of them. The part grows with k (a travel's
  // waypoints lie on its way), so that is the last before the first that meets them.
  const std::span<const Pose> w(r.waypoints);
  for (std::size_t k = w.size() - 2; k >= 1; --k) {
    if (clear_of_all(path_airspace(stops_of(w.first(k + 1)), layout_.paths)) &&
        clear_of_all(rest_airspace(w[k], layout_.paths))) {
      return k + 1;
    }
  }
  return 0;
}

std::vector<Instruction> SiteArbiter::decide(double time) {
  if (!std::isfinite(time)) throw std::invalid_argument("site arbiter: a decision time is not finite");
  decided_at_ = time;
  critical_ = most_work_left();
  const std::size_t n = cranes_.size();
  std::vector<Instruction> out;
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < n; ++i) {
    cranes_[i].waits_for.clear();
    cranes_[i].wait_reason = WaitReason::none;
    if (cranes_[i].request && cranes_[i].holding == Holding::rest) order.push_back(i);
  }
  std::sort(order.begin(), order.end(), [this](std::size_t a, std::size_t b) { return ranks_before(a, b); });

  std::vector<bool> instructed(n, false);
  std::vector<std::vector<bool>> blocks(n, std::vector<bool>(n, false));  // i waits for j's held airspace
  const auto blockers = [&](std::size_t i) {
    std::vector<std::size_t> waits;
    const Request& r = *cranes_[i].request;
    for (std::size_t j = 0; j < n; ++j) {
      if (j == i) continue;
      const CraneState& c = cranes_[j];
      // Serialized: in shared airspace and not at rest (a crane out of service stands braked).
      const bool travels_shared = c.held_shared && c.holding != Holding::rest && c.holding != Holding::out_of_service;
      if (!clear(i, r.airspace, j, c.held) || (mode_ == ArbiterMode::serialized && r.shared && travels_shared)) {
        waits.push_back(j);
      }
    }
    return waits;
  };
  // Rule 0. The cranes that may never move: silent or out of service, and, in turn, those at rest
  // whose request waits for one of them.
  std::vector<bool> stalled(n, false);
  if (std::any_of(order.begin(), order.end(), [this](std::size_t i) { return first(i); })) {
    std::vector<std::vector<std::size_t>> asking(n);
    for (std::size_t i = 0; i < n; ++i) {
      stalled[i] = cranes_[i].holding == Holding::whole_reach || cranes_[i].holding == Holding::out_of_service;
    }
    for (const std::size_t i : order) asking[i] = blockers(i);
    for (bool grew = true; grew;) {
      grew = false;
      for (const std::size_t i : order) {
        if (stalled[i] || std::none_of(asking[i].begin(), asking[i].end(), [&](std::size_t j) { return stalled[j]; })) {
          continue;
        }
        stalled[i] = true;
        grew = true;
      }
    }
  }
  // The request of rule 0 (starving, or the most work left) ranked before `position` whose path
  // i's request meets and that still waits, for no crane that may never move. Every such request
  // ranks before the others, so they are decided by then.
  const auto reserved = [&](std::size_t i, std::size_t position) -> std::optional<std::size_t> {
    for (std::size_t earlier = 0; earlier < position; ++earlier) {
      const std::size_t k = order[earlier];
      if (k == i || instructed[k] || !first(k) ||
          clear(i, cranes_[i].request->airspace, k, cranes_[k].request->airspace)) {
        continue;
      }
      const auto& kept = cranes_[k].waits_for;
      if (std::none_of(kept.begin(), kept.end(), [&](std::size_t j) { return stalled[j]; })) return k;
    }
    return std::nullopt;
  };
  for (std::size_t position = 0; position < order.size(); ++position) {
    const std::size_t i = order[position];
    std::vector<std::size_t> waits = blockers(i);
    WaitReason why = WaitReason::held;
    const std::size_t part = waits.empty() ? 0 : part_of_leg(i, waits);
    if (part > 0) waits.clear();  // it goes up to waypoint part - 1, and waits there
    for (const std::size_t j : waits) blocks[i][j] = true;
    if (waits.empty()) {
      if (const auto k = reserved(i, position)) {
        waits.push_back(*k);
        blocks[i][*k] = true;
        why = starving(*k) ? WaitReason::starving : WaitReason::most_work_left;
      }
    }
    if (waits.empty() && !first(i)) {
      // Rule 2: a later request of a higher crane whose cable meets this jib, and that could go now
      // (rule 0 before it: a starving request, or the most work left's, gives way to none).
      for (std::size_t later = position + 1; later < order.size() && waits.empty(); ++later) {
        const std::size_t k = order[later];
        if (yields_jib_to(i, k) && blockers(k).empty() && !reserved(k, later)) waits.push_back(k);
      }
      why = WaitReason::higher_cable;
    }
    cranes_[i].waits_for = waits;
    if (!waits.empty()) {
      cranes_[i].wait_reason = why;
      continue;
    }
    CraneState& c = cranes_[i];
    std::vector<Pose>& waypoints = c.request->waypoints;
    c.holding = Holding::path;
    if (part > 0) {
      waypoints.resize(part);
      waypoints = stops_of(waypoints);
      c.held = path_airspace(waypoints, layout_.paths);
      c.held_shared = shared(i, c.held);
    } else {
      waypoints = stops_of(waypoints);
      c.held = c.request->airspace;
      c.held_shared = c.request->shared;
    }
    c.path_end = waypoints.back();
    out.push_back({i, Instruction::Kind::go, std::move(waypoints)});
    c.request.reset();
    instructed[i] = true;
  }

  // Who would wait forever: reach[a][b] when a waits, through cranes at rest, for b.
  std::vector<std::vector<bool>> reach(n, std::vector<bool>(n, false));
  for (std::size_t a = 0; a < n; ++a) {
    for (std::size_t b = 0; b < n; ++b) reach[a][b] = blocks[a][b] && cranes_[b].holding == Holding::rest;
  }
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t a = 0; a < n; ++a) {
      for (std::size_t b = 0; b < n; ++b) reach[a][b] = reach[a][b] || (reach[a][k] && reach[k][b]);
    }
  }
  for (const std::size_t i : order) {
    if (instructed[i]) continue;
    for (const std::size_t j : cranes_[i].waits_for) {
      if (instructed[j] || cranes_[j].holding != Holding::rest || instructed[i]) continue;
      std::size_t victim = j;
      if (cranes_[j].request) {
        if (!reach[j][i]) continue;  // j waits for something that will move
        // A cycle: the one of it that ranks last yields.
        victim = i;
        for (std::size_t k = 0; k < n; ++k) {
          if (reach[i][k] && reach[k][i] && !instructed[k] && ranks_before(victim, k)) victim = k;
        }
      }
      std::vector<std::size_t> waiting;
      for (std::size_t w = 0; w < n; ++w) {
        if (cranes_[w].request && !instructed[w] && blocks[w][victim]) waiting.push_back(w);
      }
      const auto path = yield_path(victim, waiting);
      if (!path) {
        ++unresolved_;
        continue;
      }
      CraneState& c = cranes_[victim];
      c.path_end.reset();
      c.holding = Holding::yield;
      c.held = path_airspace(*path, layout_.paths);
      c.held_shared = shared(victim, c.held);
      out.push_back({victim, Instruction::Kind::yield, *path});
      instructed[victim] = true;
      ++yields_;
    }
  }
  return out;
}

}  // namespace crane::anti_collision
