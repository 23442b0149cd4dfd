#include "crane/anti_collision/site_watch.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <utility>

#include "crane/anti_collision/site_messages.hpp"

namespace crane::anti_collision {

SiteWatch::SiteWatch(SiteLayout layout) : layout_(std::move(layout)), cranes_(layout_.cranes.size()) {}

PairDistance SiteWatch::pair_distance(std::size_t i, std::size_t j) const {
  const auto a = envelope(layout_.cranes[i], motion_of(*cranes_[i].report), StopKind::none);
  const auto b = envelope(layout_.cranes[j], motion_of(*cranes_[j].report), StopKind::none);
  return distance(a, b);
}

bool SiteWatch::report(const protocol::SiteReport& message, double time) {
  if (message.crane >= cranes_.size() || !is_finite(motion_of(message))) return false;
  CraneReport read;
  if (!from_message(message, read).empty()) return false;
  Crane& c = cranes_[message.crane];
  c.report = message;
  c.read = std::move(read);
  if (c.reports++ == 0) c.first_heard = time;
  c.heard = time;
  for (std::size_t j = 0; j < cranes_.size(); ++j) {
    if (j == message.crane || !cranes_[j].report) continue;
    const std::size_t i = std::min<std::size_t>(j, message.crane), k = std::max<std::size_t>(j, message.crane);
    const PairDistance d = pair_distance(i, k);
    if (d.distance < closest_) {
      closest_ = d.distance;
      closest_parts_ = layout_.cranes[i].name + "." + to_string(d.first) + "-" + layout_.cranes[k].name + "." +
                       to_string(d.second);
      closest_time_ = time;
      closest_reports_ = {*cranes_[i].report, *cranes_[k].report};
      closest_apart_ = time - cranes_[j].heard;
    }
  }
  return true;
}

void SiteWatch::status(const protocol::SiteStatus& message, double time) {
  status_ = message;
  status_heard_ = time;
}

bool SiteWatch::instruction(const protocol::SiteInstruction& message) {
  if (message.crane >= cranes_.size()) return false;
  SiteOrder order;
  if (!from_message(message, order).empty()) return false;
  cranes_[message.crane].order = std::move(order);
  cranes_[message.crane].order_epoch = message.epoch;
  return true;
}

std::vector<SiteWatch::Pair> SiteWatch::distances() const {
  std::vector<Pair> out;
  for (std::size_t i = 0; i < cranes_.size(); ++i) {
    for (std::size_t j = i + 1; j < cranes_.size(); ++j) {
      if (cranes_[i].report && cranes_[j].report) out.push_back({i, j, pair_distance(i, j)});
    }
  }
  return out;
}

Airspace SiteWatch::held(std::size_t i) const {
  const Crane& c = cranes_.at(i);
  if (!c.read || !status_ || i >= status_->holding.size()) return {};
  switch (status_->holding[i]) {
    case protocol::SiteStatus::HOLDING_REST: return rest_airspace(c.read->waypoints.front(), layout_.paths);
    case protocol::SiteStatus::HOLDING_PATH:
    case protocol::SiteStatus::HOLDING_YIELD: {
      const bool carried_out = !c.order || (c.read->instruction_epoch == c.order_epoch &&
                                            c.read->instruction_seq >= c.order->seq);
      if (!carried_out) return path_airspace(c.order->waypoints, layout_.paths);
      if (!c.read->moving) return rest_airspace(c.read->waypoints.front(), layout_.paths);
      return path_airspace(c.read->waypoints, layout_.paths);
    }
    case protocol::SiteStatus::HOLDING_WHOLE_REACH: return whole_reach(layout_.cranes[i], layout_.paths);
    case protocol::SiteStatus::HOLDING_OUT_OF_SERVICE:  // where its last report put it, braked
      return out_of_service_airspace(layout_.cranes[i],
                                     c.read->moving ? path_airspace(c.read->waypoints, layout_.paths)
                                                    : rest_airspace(c.read->waypoints.front(), layout_.paths),
                                     c.read->motion, kReportPeriod);
    default: return {};
  }
}

Airspace SiteWatch::requested(std::size_t i) const {
  const Crane& c = cranes_.at(i);
  if (!c.read || c.read->request_id == 0 || c.read->request.size() < 2) return {};
  return path_airspace(stops_of(c.read->request), layout_.paths);  // as the service would hold it
}

std::vector<common::Point2> plan_outline(const SiteCrane& crane, const JointBox& box) {
  const double hanging = box.swing_radius + crane.load_radius;
  const double inner = std::max(0.0, box.trolley_low - hanging);
  const double outer = box.trolley_high + hanging;
  const double span = std::max(0.0, box.slew_high - box.slew_low);
  const auto steps = static_cast<std::size_t>(std::ceil(span / (2.0 * std::numbers::pi / 180.0)));
  const auto at = [&](double slew, double radius) {
    const double heading = crane.slew_zero_heading + slew;
    return common::Point2{crane.base[0] + radius * std::cos(heading), crane.base[1] + radius * std::sin(heading)};
  };
  std::vector<common::Point2> out;
  for (std::size_t k = 0; k <= steps; ++k) {
    out.push_back(at(box.slew_low + span * (steps == 0 ? 0.0 : static_cast<double>(k) / static_cast<double>(steps)), outer));
  }
  for (std::size_t k = 0; k <= steps; ++k) {
    out.push_back(at(box.slew_high - span * (steps == 0 ? 0.0 : static_cast<double>(k) / static_cast<double>(steps)), inner));
  }
  return out;
}

}  // namespace crane::anti_collision
