#pragma once
// The site around a tower crane: the jib's height and the no-go zones the load must never enter
// (buildings, a neighbour's site, areas where people work), after the "blocked regions" of the
// industrial anti-sway products. Read once from the `site:` block (config::ConfigDocument, a
// shared fact), used by the planner (goals refused inside a zone, paths planned around zones,
// operator speeds stopped short of them) and by the supervisor (enforced on its own, from the
// measured state).
//
// Geometry: the crane's frame has its origin on the slew axis at the ground, x along the jib at
// slew angle 0, z up. A zone is a simple polygon in the horizontal plane (x, y) [m], extruded
// from `bottom` to `top` [m] above the ground. A point intrudes on a zone when its height is within
// [bottom - clearance, top + clearance] and its horizontal distance to the polygon's inside is
// below `clearance`.
//
// The load's position from the crane's coordinates is the tower crane convention of (2.11) with
// ERRATA.md: r = x e_x + L (-cos(theta) sin(phi), sin(theta), -cos(theta) cos(phi)) in the jib
// frame, rotated by the slew angle gamma about z (the formula of plant::TowerCraneModel::
// load_position; tests/services/test_speed_reference.cpp checks analytic cases of this one, not the
// two against each other: the common layer cannot see the plant).

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace crane::common {

using Point2 = std::array<double, 2>;  // [m] x, y in the horizontal plane

struct Zone {
  std::string name;               // shown in messages ("site.zones[1] (school yard)")
  std::vector<Point2> polygon;    // [m] vertices in order (either orientation), >= 3, not self-intersecting
  double bottom{0.0};             // [m] above the ground
  double top{1.0e3};              // [m] above the ground, > bottom
  bool enabled{true};             // enforced from the start (switched at run time by the supervisor)
  bool fixed{false};              // always enforced (buildings, a neighbour's site): switching it off is
                                  // refused; needs enabled
};

struct Site {
  double jib_height{2.0};         // [m] height of the trolley's cable sheave above the ground
  double zone_clearance{0.1};     // [m] distance kept from every zone, horizontally and vertically
  std::vector<Zone> zones;        // at most kMaxZones (SupervisorStatus.zones_enabled is a 32-bit mask)

  static constexpr std::size_t kMaxZones = 32;
  /// Bit i set: zones[i].enabled.
  [[nodiscard]] std::uint32_t enabled_at_start() const noexcept;
};

/// Throws ConfigError naming the zone ("site.zones[1] (school yard): ...") when a zone has fewer
/// than 3 vertices, a non-finite vertex, zero area, two edges that cross (self-intersecting, with
/// the edges named), bottom >= top, fixed but not enabled; when there are more than kMaxZones zones; when jib_height or
/// zone_clearance is not finite or negative.
void validate(const Site& site, const std::string& prefix = "site");

/// Horizontal signed distance [m] from `p` to the polygon's boundary: negative inside.
[[nodiscard]] double signed_distance(const Zone& zone, const Point2& p) noexcept;

/// True when the point (p, height [m]) is within `clearance` [m] of the zone (see the header).
[[nodiscard]] bool intrudes(const Zone& zone, const Point2& p, double height, double clearance) noexcept;

/// Index of the first zone enabled in `enabled_mask` the point intrudes on, or -1.
[[nodiscard]] int intruded_zone(const Site& site, std::uint32_t enabled_mask, const Point2& p, double height,
                                double clearance) noexcept;

/// The load's position [m] (x, y, height above the ground) for trolley position x [m], slew angle
/// gamma [rad], in-plane swing phi [rad], out-of-plane swing theta [rad] and cable length L [m].
[[nodiscard]] std::array<double, 3> load_position(const Site& site, double trolley, double slew, double swing_in_plane,
                                                  double swing_out_of_plane, double cable_length) noexcept;

}  // namespace crane::common
