#include "crane/trajectory_planner/zone_guard.hpp"

#include <algorithm>
#include <cmath>

namespace crane::trajectory_planner {
namespace {

// The load at the trolley's point (trolley [m], slew [rad]), anywhere between the heights of the
// cable lengths l0 and l1 [m], within `margin` [m] horizontally and the clearance vertically.
int point_zone(const common::Site& site, std::uint32_t enabled, double trolley, double slew, double l0, double l1,
               double margin, const ZoneDistances* caps = nullptr) noexcept {
  const common::Point2 p{trolley * std::cos(slew), trolley * std::sin(slew)};
  const double low = site.jib_height - std::max(l0, l1), high = site.jib_height - std::min(l0, l1);
  for (std::size_t i = 0; i < site.zones.size() && i < common::Site::kMaxZones; ++i) {
    const common::Zone& zone = site.zones[i];
    if ((enabled & (1U << i)) == 0) continue;
    if (high < zone.bottom - site.zone_clearance || low > zone.top + site.zone_clearance) continue;
    const double limit = caps != nullptr ? std::min(margin, (*caps)[i]) : margin;
    if (common::signed_distance(zone, p) < limit) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace

double zone_margin(const common::Site& site, double cable_length, double horizontal_acceleration,
                   double gravity) noexcept {
  return site.zone_clearance + kSwingAllowanceFactor * std::abs(cable_length * horizontal_acceleration) / gravity;
}

double horizontal_acceleration(const common::MotionReference& r) noexcept {
  const double x = r.trolley.position, xd = r.trolley.velocity, xdd = r.trolley.acceleration;
  const double gd = r.slew.velocity, gdd = r.slew.acceleration;
  return std::hypot(xdd - x * gd * gd, x * gdd + 2.0 * xd * gd);
}

ZoneDistances zone_distances(const common::Site& site, const common::MotionReference& r) noexcept {
  ZoneDistances d;
  d.fill(1e300);
  const common::Point2 p{r.trolley.position * std::cos(r.slew.position), r.trolley.position * std::sin(r.slew.position)};
  for (std::size_t i = 0; i < site.zones.size() && i < d.size(); ++i) d[i] = common::signed_distance(site.zones[i], p);
  return d;
}

int intruded_zone(const common::Site& site, std::uint32_t enabled, const common::MotionReference& r, double gravity,
                  double acceleration, const ZoneDistances* caps, double extra) noexcept {
  if (enabled == 0 || site.zones.empty()) return -1;
  const double x = r.trolley.position;
  const double a = std::max(horizontal_acceleration(r), acceleration);
  return point_zone(site, enabled, x, r.slew.position, r.cable_length.position, r.cable_length.position,
                    zone_margin(site, r.cable_length.position, a, gravity) + extra, caps);
}

double swing_allowance(double cable_length, double horizontal_acceleration, double speed_change,
                       double gravity) noexcept {
  const double w = std::sqrt(gravity / std::max(cable_length, 1e-3));
  return kSwingAllowanceFactor * std::min(std::abs(cable_length * horizontal_acceleration) / gravity,
                                          std::abs(speed_change) / w);
}

int intruded_zone(const common::Site& site, std::uint32_t enabled, double x0, double x1, double g0, double g1,
                  double l0, double l1, double allowance, const ZoneDistances* caps) noexcept {
  if (enabled == 0 || site.zones.empty()) return -1;
  const double margin = site.zone_clearance + allowance;
  // Sample spacing along the trolley's arcs and radii: at most half the clearance (and 64 points).
  const double reach = std::max({std::abs(x0), std::abs(x1), 1e-3});
  const double length = std::max(std::abs(x1 - x0), reach * std::abs(g1 - g0));
  const double spacing = std::max(0.5 * std::max(site.zone_clearance, 1e-3), length / 64.0);
  const int n = std::max(2, static_cast<int>(std::ceil(length / spacing)));
  for (int i = 0; i <= n; ++i) {
    const double s = static_cast<double>(i) / n;
    const double x = x0 + s * (x1 - x0), g = g0 + s * (g1 - g0);
    for (const auto& [px, pg] : {std::pair{x, g0}, std::pair{x, g1}, std::pair{x0, g}, std::pair{x1, g}, std::pair{x, g}}) {
      const int zone = point_zone(site, enabled, px, pg, l0, l1, margin, caps);
      if (zone >= 0) return zone;
    }
  }
  return -1;
}

}  // namespace crane::trajectory_planner
