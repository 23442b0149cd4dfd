#pragma once
// The airspace a crane may use: what the site service grants (site_arbiter.hpp) and what two
// cranes must keep apart (issue 34; docs/site.md, "Grants"). Pure functions, noexcept.
//
// A crane's airspace is a union of boxes of its joint space: a slew interval [rad], a trolley
// interval [m] and a cable-length interval [m], with the load's swing (a horizontal radius [m]
// about the sheave's vertical). A path through waypoints is one box per segment, widened by the
// tracking controller's overshoot past each goal and by the tracking allowance on either side of
// its slew and trolley intervals (PathAllowance's *_tracking while the trolley or the slew
// travels in the segment, *_hold while neither does); the swing is the site's travel allowance
// (the crane's supervisor brakes beyond it) while the trolley or the slew moves, and its hoist
// allowance while only the hoist does. At rest a crane holds the box of its pose (with the hold
// allowance).
//
// Geometry: each part of a crane at one slew angle is a slab, a segment in plan view swept by a
// disc, times a height interval (every part of a tower crane is one: the jib and counter-jib
// (plan segment, its half width, the chord's height), the mast (a point, its half diagonal, from
// the ground to the jib), and what hangs from the trolley (the trolley's interval in plan, the
// swing plus the load's radius, from the lowest load to the jib)). The distance between two
// slabs is exact: sqrt(d_plan^2 + d_height^2), d_plan the plan segments' distance less both
// radii, d_height the gap between the height intervals (each clamped at 0). A box's slew interval
// is sampled every CraneEnvelope::kMaxSlewStep at most and each sample padded by 2 R sin(delta/4)
// (R the crane's largest radius, delta the step: the chord's sagitta bound of crane_geometry.hpp),
// so the samples' union contains the swept parts. Distances are >= 0 (0: touching or overlapping).

#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

/// A crane's pose in its own coordinates.
struct Pose {
  double slew{0.0};          // [rad] slew angle
  double trolley{0.5};       // [m] from the slew axis
  double cable_length{1.0};  // [m] sheave to the load's centre, > 0
};

/// One box of joint space (see the header).
struct JointBox {
  double slew_low{0.0}, slew_high{0.0};        // [rad] slew_low <= slew_high
  double trolley_low{0.0}, trolley_high{0.0};  // [m]
  double cable_low{0.0}, cable_high{0.0};      // [m]
  double swing_radius{0.0};                    // [m] horizontal, about the sheave's vertical
  bool operator==(const JointBox&) const = default;
};

struct Airspace {
  static constexpr std::size_t kMaxBoxes = 8;
  std::array<JointBox, kMaxBoxes> boxes{};
  std::size_t count{0};  // boxes used; 0: no airspace
};

/// True when `a` and `b` have the same boxes in use (count and every field, exactly).
[[nodiscard]] bool same_airspace(const Airspace& a, const Airspace& b) noexcept;

/// At rest at `pose`: one box, the pose itself, with the hoist swing allowance.
[[nodiscard]] Airspace rest_airspace(const Pose& pose, const PathAllowance& allowance) noexcept;

/// The path through `waypoints` (the first is where the crane is; 1 to Airspace::kMaxBoxes + 1 of
/// them; extra waypoints are ignored): one box per segment (see the header). A single waypoint is
/// rest_airspace.
[[nodiscard]] Airspace path_airspace(std::span<const Pose> waypoints, const PathAllowance& allowance) noexcept;

/// [m] two cable lengths this close are one: a crane at rest within it of the travel's cable length
/// travels without hoisting first (CraneSiteLink), and a run of travels (stops_of) may differ by it.
inline constexpr double kSameCable = 1e-3;

/// The waypoints a crane stops at on the path through `waypoints`: a run of consecutive segments
/// that each travel (slew or trolley) at one cable length, the same for the whole run, is one
/// move, from the run's first waypoint straight to its last; the waypoints inside the run are
/// dropped. A request may list such waypoints inside its travel so that the site service can grant
/// a part of the leg that ends there (docs/site.md, "A wait inside the travel"); the service grants,
/// holds and sends the stops of the part it grants. Cable lengths compare within kSameCable. Paths
/// with no such run come back unchanged.
[[nodiscard]] std::vector<Pose> stops_of(std::span<const Pose> waypoints);

/// Everything the crane can reach: any slew, its whole trolley and hook range, the travel swing.
/// What a crane that stops reporting holds (issue 34, item 4).
[[nodiscard]] Airspace whole_reach(const SiteCrane& crane, const PathAllowance& allowance) noexcept;

/// What a crane out of service holds (SiteArbiter::out_of_service): `held`, the airspace it held
/// when it went silent (it stands braked in it), each box's swing radius [m] that of an emergency
/// stop (crane_geometry.hpp's stopping_travel, StopKind::emergency: the measured swing's amplitude
/// plus the sheave's speed over the pendulum's frequency) from `last`, its last reported motion,
/// taken at the box's longest cable (the widest), with its trolley and slew speeds first raised
/// by `report_age` [s] of its soft stop's deceleration (it may have sped up since that report).
/// Non-finite `last` gives non-finite radii: callers check it first (is_finite).
[[nodiscard]] Airspace out_of_service_airspace(const SiteCrane& crane, const Airspace& held, const CraneMotion& last,
                                               double report_age) noexcept;

/// Closest distance [m] between two cranes' airspaces (>= 0; +infinity when either is empty), and
/// the parts it is between (Part::cable stands for what hangs from the trolley, the load included).
[[nodiscard]] PairDistance airspace_distance(const SiteCrane& first, const Airspace& a, const SiteCrane& second,
                                             const Airspace& b) noexcept;

namespace internal {
/// airspace_distance without its pruning: every pair of slabs evaluated. The reference its tests
/// check the pruning against (the same distance and parts, to the bit). A site run takes about 3.8
/// times as long on it (docs/site.md).
[[nodiscard]] PairDistance airspace_distance_every_pair(const SiteCrane& first, const Airspace& a,
                                                        const SiteCrane& second, const Airspace& b) noexcept;
}  // namespace internal

}  // namespace crane::anti_collision
