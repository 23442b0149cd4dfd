#include "crane/common/site.hpp"

#include <algorithm>
#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::common {
namespace {

double cross(const Point2& o, const Point2& a, const Point2& b) {
  return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
}

// Proper or touching intersection of the closed segments ab and cd.
bool segments_meet(const Point2& a, const Point2& b, const Point2& c, const Point2& d) {
  const double d1 = cross(c, d, a), d2 = cross(c, d, b), d3 = cross(a, b, c), d4 = cross(a, b, d);
  if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
  const auto on = [](const Point2& p, const Point2& q, const Point2& r, double side) {
    return side == 0.0 && std::min(p[0], q[0]) <= r[0] && r[0] <= std::max(p[0], q[0]) && std::min(p[1], q[1]) <= r[1] &&
           r[1] <= std::max(p[1], q[1]);
  };
  return on(c, d, a, d1) || on(c, d, b, d2) || on(a, b, c, d3) || on(a, b, d, d4);
}

double segment_distance(const Point2& p, const Point2& a, const Point2& b) {
  const double ux = b[0] - a[0], uy = b[1] - a[1];
  const double length2 = ux * ux + uy * uy;
  double t = length2 > 0.0 ? ((p[0] - a[0]) * ux + (p[1] - a[1]) * uy) / length2 : 0.0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(p[0] - (a[0] + t * ux), p[1] - (a[1] + t * uy));
}

}  // namespace

std::uint32_t Site::enabled_at_start() const noexcept {
  std::uint32_t mask = 0;
  for (std::size_t i = 0; i < zones.size() && i < kMaxZones; ++i) {
    if (zones[i].enabled) mask |= 1U << i;
  }
  return mask;
}

void validate(const Site& site, const std::string& prefix) {
  require_at_least(prefix + ".jib_height", site.jib_height, 0.0);
  require_at_least(prefix + ".zone_clearance", site.zone_clearance, 0.0);
  if (site.zones.size() > Site::kMaxZones) {
    throw ConfigError(prefix + ".zones has " + std::to_string(site.zones.size()) + " zones: at most " +
                      std::to_string(Site::kMaxZones));
  }
  for (std::size_t z = 0; z < site.zones.size(); ++z) {
    const Zone& zone = site.zones[z];
    const std::string name = prefix + ".zones[" + std::to_string(z) + "] (" + zone.name + ")";
    const auto& v = zone.polygon;
    if (v.size() < 3) {
      throw ConfigError(name + ": polygon has " + std::to_string(v.size()) + " vertices: at least 3");
    }
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!std::isfinite(v[i][0]) || !std::isfinite(v[i][1])) {
        throw ConfigError(name + ": vertex " + std::to_string(i) + " is not finite");
      }
    }
    const std::size_t n = v.size();
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        if (j == i + 1 || (i == 0 && j == n - 1)) continue;  // adjacent edges share a vertex
        if (segments_meet(v[i], v[(i + 1) % n], v[j], v[(j + 1) % n])) {
          throw ConfigError(name + ": polygon is self-intersecting: edges " + std::to_string(i) + " and " +
                            std::to_string(j) + " cross");
        }
      }
    }
    double area2 = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i) area2 += cross({0.0, 0.0}, v[i], v[(i + 1) % v.size()]);
    if (std::abs(area2) < 1e-12) throw ConfigError(name + ": polygon has zero area");
    require_finite(name + ".bottom", zone.bottom);
    require_greater(name + ".top", zone.top, zone.bottom);
    if (zone.fixed && !zone.enabled) {
      throw ConfigError(name + ": fixed but not enabled: a fixed zone is always enforced (enabled: true)");
    }
  }
}

double signed_distance(const Zone& zone, const Point2& p) noexcept {
  const auto& v = zone.polygon;
  double distance = 1e300;
  bool inside = false;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) {
    distance = std::min(distance, segment_distance(p, v[j], v[i]));
    if ((v[i][1] > p[1]) != (v[j][1] > p[1]) &&
        p[0] < (v[j][0] - v[i][0]) * (p[1] - v[i][1]) / (v[j][1] - v[i][1]) + v[i][0]) {
      inside = !inside;
    }
  }
  return inside ? -distance : distance;
}

bool intrudes(const Zone& zone, const Point2& p, double height, double clearance) noexcept {
  if (height < zone.bottom - clearance || height > zone.top + clearance) return false;
  return signed_distance(zone, p) < clearance;
}

int intruded_zone(const Site& site, std::uint32_t enabled_mask, const Point2& p, double height,
                  double clearance) noexcept {
  for (std::size_t i = 0; i < site.zones.size() && i < Site::kMaxZones; ++i) {
    if ((enabled_mask & (1U << i)) != 0 && intrudes(site.zones[i], p, height, clearance)) return static_cast<int>(i);
  }
  return -1;
}

std::array<double, 3> load_position(const Site& site, double trolley, double slew, double swing_in_plane,
                                    double swing_out_of_plane, double cable_length) noexcept {
  const double rx = trolley - cable_length * std::cos(swing_out_of_plane) * std::sin(swing_in_plane);
  const double ry = cable_length * std::sin(swing_out_of_plane);
  const double rz = -cable_length * std::cos(swing_out_of_plane) * std::cos(swing_in_plane);
  const double c = std::cos(slew), s = std::sin(slew);
  return {c * rx - s * ry, s * rx + c * ry, site.jib_height + rz};
}

}  // namespace crane::common
