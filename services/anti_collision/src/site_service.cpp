#include "crane/anti_collision/site_service.hpp"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <utility>

namespace crane::anti_collision {
namespace {

// "" when every waypoint is finite with a positive cable length, else the first bad one named.
std::string bad_waypoint(const std::vector<Pose>& waypoints, const char* field) {
  for (std::size_t k = 0; k < waypoints.size(); ++k) {
    const Pose& p = waypoints[k];
    if (!std::isfinite(p.slew) || !std::isfinite(p.trolley) || !std::isfinite(p.cable_length) ||
        !(p.cable_length > 0.0)) {
      return std::string(field) + "[" + std::to_string(k) + "] (slew " + std::to_string(p.slew) + " rad, trolley " +
             std::to_string(p.trolley) + " m, cable " + std::to_string(p.cable_length) +
             " m) is not finite or its cable length is not > 0";
    }
  }
  return "";
}

}  // namespace

SiteService::SiteService(SiteLayout layout, ArbiterMode mode, std::uint32_t epoch)
    : arbiter_(std::move(layout), mode), epoch_(epoch) {
  if (epoch == 0) throw std::invalid_argument("site service: the epoch must not be 0");
  links_.resize(arbiter_.size());
}

bool SiteService::heard(std::size_t crane, double time) const {
  return time - links_.at(crane).last_heard <= arbiter_.layout().link_deadline;
}

std::string SiteService::report(const CraneReport& r, double time) {
  const std::size_t max_waypoints = Airspace::kMaxBoxes + 1;
  std::string why;
  if (r.crane >= links_.size()) {
    why = "crane " + std::to_string(r.crane) + " is not on the site (" + std::to_string(links_.size()) + " cranes)";
  } else if (r.waypoints.empty() || r.waypoints.size() > max_waypoints) {
    why = "waypoint_count = " + std::to_string(r.waypoints.size()) + " is out of range: must be in [1, " +
          std::to_string(max_waypoints) + "]";
  } else if (r.request_id != 0 && (r.request.size() < 2 || r.request.size() > max_waypoints)) {
    why = "request_count = " + std::to_string(r.request.size()) + " is out of range: must be in [2, " +
          std::to_string(max_waypoints) + "] with request_id " + std::to_string(r.request_id);
  } else if (!std::isfinite(time)) {
    why = "the arrival time is not finite";
  } else {
    why = bad_waypoint(r.waypoints, "waypoint");
    if (why.empty() && r.request_id != 0) why = bad_waypoint(r.request, "request");
    if (why.empty() && !is_finite(r.motion)) {
      char text[320];
      std::snprintf(text, sizeof text,
                    "the measured motion (slew %g rad, %g rad/s; trolley %g m, %g m/s; cable %g m; swing %g, %g rad) is "
                    "not finite or its cable length is not > 0",
                    r.motion.slew, r.motion.slew_rate, r.motion.trolley, r.motion.trolley_velocity, r.motion.cable_length,
                    r.motion.swing_in_plane, r.motion.swing_out_of_plane);
      why = text;
    }
    if (why.empty() && !(std::isfinite(r.work_left) && r.work_left >= 0.0)) {
      why = "work_left = " + std::to_string(r.work_left) + " s is not finite and >= 0";
    }
  }
  if (!why.empty()) {
    ++rejected_;
    return "site service: a report refused: " + why;
  }

  Link& link = links_[r.crane];
  const auto most_work_left = arbiter_.most_work_left();
  arbiter_.work_left(r.crane, r.work_left);
  link.last_heard = time;
  link.motion = r.motion;
  link.motion_trusted = true;
  if (!link.carried_out && r.instruction_epoch == epoch_ && r.instruction_seq >= link.last_order.seq) {
    link.carried_out = true;
  }
  const Pose& here = r.waypoints.front();
  const auto rest = [&] {
    arbiter_.rest(r.crane, here);
    link.rest_pose = here;
    link.progressed.clear();
    dirty_ = true;
  };
  switch (arbiter_.holding(r.crane)) {
    case Holding::whole_reach:
      if (!r.moving) {
        rest();
      } else if (const auto place = arbiter_.place(r.crane); place && !place->moving) {
        arbiter_.lost(r.crane, true);  // it moves, but stood at rest when last known: it had no grant
      }
      break;
    case Holding::out_of_service:
      if (r.moving) {
        ++moves_without_grant_;
        arbiter_.lost(r.crane, true);
      } else {
        rest();  // it is back
      }
      dirty_ = true;
      break;
    case Holding::rest:
      if (r.moving) {
        ++moves_without_grant_;
        arbiter_.lost(r.crane, true);
        dirty_ = true;
      } else if (std::abs(here.slew - link.rest_pose.slew) > kRestTolerance ||
                 std::abs(here.trolley - link.rest_pose.trolley) > kRestTolerance ||
                 std::abs(here.cable_length - link.rest_pose.cable_length) > kRestTolerance) {
        rest();  // it crept: the box follows
      }
      break;
    case Holding::path:
    case Holding::yield:
      if (!link.carried_out) break;  // it has not heard, or not started, its instruction yet
      if (!r.moving) {
        rest();
      } else if (narrows(link.last_order.waypoints, link.progressed, r.waypoints)) {
        arbiter_.progress(r.crane, r.waypoints);  // further along its path: what it left is free
        link.progressed = r.waypoints;
        dirty_ = true;
      }
      break;
  }

  if (r.request_id == 0) {
    if (link.pending_id != 0) {
      arbiter_.withdraw(r.crane);
      dirty_ = true;
    }
    link.pending_id = 0;
  } else if (r.request_id != link.pending_id && r.request_id != link.granted_id) {
    arbiter_.request(r.crane, r.request, time);
    link.pending_id = r.request_id;
    dirty_ = true;
  }
  if (arbiter_.most_work_left() != most_work_left) dirty_ = true;  // rule 0 ranks another request first
  return "";
}

std::string SiteService::out_of_service(std::size_t crane, double time) {
  if (crane >= links_.size()) {
    return "site service: crane " + std::to_string(crane) + " is not on the site (" + std::to_string(links_.size()) +
           " cranes)";
  }
  const std::string& name = arbiter_.layout().cranes[crane].name;
  if (heard(crane, time)) {
    char ago[32];
    std::snprintf(ago, sizeof ago, "%.2f", time - links_[crane].last_heard);
    return "site service: " + name + " was heard " + ago + " s ago: a crane that reports is not out of service";
  }
  if (arbiter_.holding(crane) == Holding::out_of_service) return "";
  if (arbiter_.holding(crane) != Holding::whole_reach) arbiter_.lost(crane);  // silent: as step() would
  try {
    const Link& link = links_[crane];
    arbiter_.out_of_service(crane, link.motion_trusted ? std::optional<CraneMotion>(link.motion) : std::nullopt,
                            kReportPeriod);
  } catch (const std::logic_error& error) {
    return error.what();
  }
  links_[crane].pending_id = 0;
  dirty_ = true;
  return "";
}

bool same_memory(const SiteMemory& a, const SiteMemory& b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const CraneMemory& p = a[i];
    const CraneMemory& q = b[i];
    if (p.out_of_service != q.out_of_service || !(p.motion == q.motion) || p.place.has_value() != q.place.has_value()) {
      return false;
    }
    if (p.place && (p.place->moving != q.place->moving || !same_airspace(p.place->airspace, q.place->airspace))) {
      return false;
    }
  }
  return true;
}

SiteMemory SiteService::memory() const {
  SiteMemory out(links_.size());
  for (std::size_t i = 0; i < links_.size(); ++i) {
    out[i].place = arbiter_.place(i);
    out[i].motion = links_[i].motion;
    out[i].out_of_service = arbiter_.holding(i) == Holding::out_of_service;
  }
  return out;
}

std::string SiteService::recall(const SiteMemory& memory) {
  if (memory.size() != links_.size()) {
    return "site service: the memory has " + std::to_string(memory.size()) + " cranes, the site " +
           std::to_string(links_.size());
  }
  for (std::size_t i = 0; i < links_.size(); ++i) {
    if (std::isfinite(links_[i].last_heard)) {
      return "site service: crane " + arbiter_.layout().cranes[i].name +
             " was heard already: a memory is recalled only at the start";
    }
  }
  SiteArbiter arbiter = arbiter_;  // all or nothing
  std::vector<Link> links = links_;
  try {
    for (std::size_t i = 0; i < links.size(); ++i) {
      const CraneMemory& m = memory[i];
      if (!m.place) {
        if (m.out_of_service) {
          throw std::invalid_argument("site arbiter: crane " + arbiter.layout().cranes[i].name +
                                      " is out of service in the memory but has no place");
        }
        continue;
      }
      arbiter.recall(i, *m.place);
      links[i].motion = m.motion;
      // Moving when last known: the motion of the memory may be older than the crane's stop.
      links[i].motion_trusted = !m.place->moving || m.out_of_service;
      if (m.out_of_service) arbiter.out_of_service(i, m.motion, kReportPeriod);
    }
  } catch (const std::exception& error) {
    return std::string("site service: the memory refused: ") + error.what();
  }
  arbiter_ = std::move(arbiter);
  links_ = std::move(links);
  dirty_ = true;
  return "";
}

std::vector<SiteOrder> SiteService::step(double time) {
  for (std::size_t i = 0; i < links_.size(); ++i) {
    if (heard(i, time)) continue;
    if (arbiter_.holding(i) != Holding::whole_reach && arbiter_.holding(i) != Holding::out_of_service) {
      arbiter_.lost(i);
      dirty_ = true;
    }
    if (links_[i].pending_id != 0) {
      arbiter_.withdraw(i);
      dirty_ = true;
    }
    links_[i].pending_id = 0;
  }
  std::vector<SiteOrder> out;
  // The rules decide on what the service holds and is asked: only when that changed.
  std::vector<Instruction> decided;
  if (dirty_) decided = arbiter_.decide(time);
  dirty_ = false;
  for (Instruction& instruction : decided) {
    Link& link = links_[instruction.crane];
    SiteOrder order;
    order.crane = instruction.crane;
    order.kind = instruction.kind;
    order.seq = ++seq_;
    order.waypoints = std::move(instruction.waypoints);
    if (instruction.kind == Instruction::Kind::go) {
      order.request_id = link.pending_id;
      link.granted_id = link.pending_id;
      link.pending_id = 0;
    }
    link.last_order = order;
    link.progressed.clear();
    link.carried_out = false;
    link.last_sent = time;
    out.push_back(std::move(order));
  }
  for (std::size_t i = 0; i < links_.size(); ++i) {
    Link& link = links_[i];
    const Holding h = arbiter_.holding(i);
    if (link.carried_out || link.last_order.seq == 0 || (h != Holding::path && h != Holding::yield) ||
        time - link.last_sent < kResendPeriod) {
      continue;
    }
    link.last_sent = time;
    out.push_back(link.last_order);
  }
  return out;
}

}  // namespace crane::anti_collision
