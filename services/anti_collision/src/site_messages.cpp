#include "crane/anti_collision/site_messages.hpp"

#include <algorithm>
#include <cstddef>

namespace crane::anti_collision {
namespace {

using protocol::SiteInstruction;
using protocol::SiteReport;
using protocol::SiteStatus;

template <class Array>
std::vector<Pose> read_poses(std::size_t count, const Array& slew, const Array& trolley, const Array& cable) {
  std::vector<Pose> poses(count);
  for (std::size_t k = 0; k < count; ++k) poses[k] = {slew[k], trolley[k], cable[k]};
  return poses;
}

template <class Array>
std::uint8_t write_poses(const std::vector<Pose>& poses, Array& slew, Array& trolley, Array& cable) noexcept {
  const std::size_t count = std::min(poses.size(), slew.size());
  for (std::size_t k = 0; k < count; ++k) {
    slew[k] = poses[k].slew;
    trolley[k] = poses[k].trolley;
    cable[k] = poses[k].cable_length;
  }
  return static_cast<std::uint8_t>(count);
}

}  // namespace

std::string from_message(const SiteReport& m, CraneReport& r) {
  if (m.state != SiteReport::STATE_AT_REST && m.state != SiteReport::STATE_MOVING) {
    return "SiteReport_.state = " + std::to_string(m.state) + " is not a STATE_* code";
  }
  if (m.waypoint_count > SiteReport::MAX_WAYPOINTS) {
    return "SiteReport_.waypoint_count = " + std::to_string(m.waypoint_count) + " is beyond MAX_WAYPOINTS (" +
           std::to_string(SiteReport::MAX_WAYPOINTS) + ")";
  }
  if (m.request_id != 0 && m.request_count > SiteReport::MAX_WAYPOINTS) {
    return "SiteReport_.request_count = " + std::to_string(m.request_count) + " is beyond MAX_WAYPOINTS (" +
           std::to_string(SiteReport::MAX_WAYPOINTS) + ")";
  }
  r.crane = m.crane;
  r.moving = m.state == SiteReport::STATE_MOVING;
  r.motion = motion_of(m);
  r.waypoints = read_poses(m.waypoint_count, m.waypoint_slew, m.waypoint_trolley, m.waypoint_cable_length);
  r.instruction_epoch = m.instruction_epoch;
  r.instruction_seq = m.instruction_seq;
  r.request_id = m.request_id;
  r.request = m.request_id != 0 ? read_poses(m.request_count, m.request_slew, m.request_trolley, m.request_cable_length)
                                : std::vector<Pose>{};
  r.work_left = m.work_left;
  return "";
}

void set_motion(const CraneMotion& c, SiteReport& m) noexcept {
  m.slew = c.slew;
  m.trolley = c.trolley;
  m.cable_length = c.cable_length;
  m.slew_rate = c.slew_rate;
  m.trolley_velocity = c.trolley_velocity;
  m.cable_rate = c.cable_rate;
  m.swing_in_plane = c.swing_in_plane;
  m.swing_out_of_plane = c.swing_out_of_plane;
  m.swing_in_plane_rate = c.swing_in_plane_rate;
  m.swing_out_of_plane_rate = c.swing_out_of_plane_rate;
}

CraneMotion motion_of(const SiteReport& m) noexcept {
  CraneMotion c;
  c.slew = m.slew;
  c.trolley = m.trolley;
  c.cable_length = m.cable_length;
  c.slew_rate = m.slew_rate;
  c.trolley_velocity = m.trolley_velocity;
  c.cable_rate = m.cable_rate;
  c.swing_in_plane = m.swing_in_plane;
  c.swing_out_of_plane = m.swing_out_of_plane;
  c.swing_in_plane_rate = m.swing_in_plane_rate;
  c.swing_out_of_plane_rate = m.swing_out_of_plane_rate;
  return c;
}

void to_message(const CraneReport& r, SiteReport& m) noexcept {
  m.crane = static_cast<std::uint8_t>(r.crane);
  m.state = r.moving ? SiteReport::STATE_MOVING : SiteReport::STATE_AT_REST;
  m.waypoint_count = write_poses(r.waypoints, m.waypoint_slew, m.waypoint_trolley, m.waypoint_cable_length);
  m.instruction_epoch = r.instruction_epoch;
  m.instruction_seq = r.instruction_seq;
  m.request_id = r.request_id;
  m.request_count = r.request_id != 0 ? write_poses(r.request, m.request_slew, m.request_trolley, m.request_cable_length)
                                      : std::uint8_t{0};
  set_motion(r.motion, m);
  m.work_left = r.work_left;
}

void to_message(const SiteOrder& o, std::uint32_t epoch, SiteInstruction& m) noexcept {
  m.header.seq = o.seq;
  m.epoch = epoch;
  m.crane = static_cast<std::uint8_t>(o.crane);
  m.kind = o.kind == Instruction::Kind::go ? SiteInstruction::KIND_GO : SiteInstruction::KIND_YIELD;
  m.request_id = o.request_id;
  m.waypoint_count = write_poses(o.waypoints, m.waypoint_slew, m.waypoint_trolley, m.waypoint_cable_length);
}

std::string from_message(const SiteInstruction& m, SiteOrder& o) {
  if (m.kind != SiteInstruction::KIND_GO && m.kind != SiteInstruction::KIND_YIELD) {
    return "SiteInstruction_.kind = " + std::to_string(m.kind) + " is not a KIND_* code";
  }
  if (m.waypoint_count < 2 || m.waypoint_count > m.waypoint_slew.size()) {
    return "SiteInstruction_.waypoint_count = " + std::to_string(m.waypoint_count) + " is out of range: must be in [2, " +
           std::to_string(m.waypoint_slew.size()) + "]";
  }
  o.crane = m.crane;
  o.kind = m.kind == SiteInstruction::KIND_GO ? Instruction::Kind::go : Instruction::Kind::yield;
  o.request_id = m.request_id;
  o.seq = m.header.seq;
  o.waypoints = read_poses(m.waypoint_count, m.waypoint_slew, m.waypoint_trolley, m.waypoint_cable_length);
  return "";
}

std::uint8_t holding_code(Holding holding) noexcept {
  switch (holding) {
    case Holding::rest: return SiteStatus::HOLDING_REST;
    case Holding::path: return SiteStatus::HOLDING_PATH;
    case Holding::yield: return SiteStatus::HOLDING_YIELD;
    case Holding::whole_reach: return SiteStatus::HOLDING_WHOLE_REACH;
    case Holding::out_of_service: return SiteStatus::HOLDING_OUT_OF_SERVICE;
  }
  return SiteStatus::HOLDING_WHOLE_REACH;
}

std::uint8_t wait_code(WaitReason reason) noexcept {
  switch (reason) {
    case WaitReason::none: return SiteStatus::WAIT_NONE;
    case WaitReason::held: return SiteStatus::WAIT_HELD;
    case WaitReason::starving: return SiteStatus::WAIT_STARVING;
    case WaitReason::higher_cable: return SiteStatus::WAIT_HIGHER_CABLE;
    case WaitReason::most_work_left: return SiteStatus::WAIT_MOST_WORK_LEFT;
  }
  return SiteStatus::WAIT_NONE;
}

std::vector<std::string> waits_for_names(const SiteLayout& layout, const SiteStatus& status, std::size_t crane) {
  std::vector<std::string> names;
  if (crane >= status.crane_count || crane >= status.waits_for.size()) return names;
  for (std::size_t j = 0; j < layout.cranes.size() && j < 32; ++j) {
    if ((status.waits_for[crane] & (std::uint32_t{1} << j)) != 0) names.push_back(layout.cranes[j].name);
  }
  return names;
}

void to_message(const SiteService& service, double time, SiteStatus& m) noexcept {
  static_assert(SiteLayout::kMaxCranes == SiteStatus::MAX_CRANES, "the IDL's MAX_CRANES is the site's kMaxCranes");
  static_assert(Airspace::kMaxBoxes + 1 == SiteReport::MAX_WAYPOINTS, "the IDL's MAX_WAYPOINTS is kMaxBoxes + 1");
  const SiteArbiter& a = service.arbiter();
  m.epoch = service.epoch();
  m.crane_count = static_cast<std::uint8_t>(a.size());
  m.holding.fill(SiteStatus::HOLDING_WHOLE_REACH);
  m.pending.fill(false);
  m.waits_for.fill(0);
  m.wait_reason.fill(SiteStatus::WAIT_NONE);
  m.waited.fill(0.0);
  for (std::size_t i = 0; i < a.size() && i < m.holding.size(); ++i) {
    m.holding[i] = holding_code(a.holding(i));
    m.pending[i] = a.pending(i);
    for (const std::size_t j : a.waits_for(i)) m.waits_for[i] |= std::uint32_t{1} << j;
    m.wait_reason[i] = wait_code(a.wait_reason(i));
    if (const auto since = a.requested_at(i)) m.waited[i] = std::max(0.0, time - *since);
  }
  m.yields = a.yields();
  m.unresolved = a.unresolved();
  m.reports_rejected = service.reports_rejected();
}

}  // namespace crane::anti_collision
