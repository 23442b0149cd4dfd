#pragma once
// The planner's view of the site's no-go zones (common/site.hpp): whether a planned path of the
// reference, or the region an operator's motion can reach before it stops, keeps the load out of
// every enabled zone.
//
// The load hangs below the trolley; while the trolley accelerates horizontally by a [m/s^2] it
// swings out by about L a / g (the quasi-static deflection of the pendulum, exact for a constant
// acceleration held long enough; input-shaped commands do not overshoot it). The guard keeps
// site.zone_clearance plus kSwingAllowanceFactor times that deflection between the trolley's point
// and a zone, at the load's height jib_height - L. The supervisor checks the measured load itself
// (supervisor.hpp); this is the planner's margin so that it never has to.

#include <array>
#include <cstdint>

#include "crane/common/crane_signals.hpp"
#include "crane/common/site.hpp"

namespace crane::trajectory_planner {

inline constexpr double kSwingAllowanceFactor = 4.0;

/// Horizontal signed distance [m] of a reference sample's trolley point to each zone (index i).
using ZoneDistances = std::array<double, common::Site::kMaxZones>;

/// Horizontal margin [m] kept from zones by a load on a cable of `cable_length` [m] whose trolley
/// accelerates horizontally by `horizontal_acceleration` [m/s^2] under gravity [m/s^2].
[[nodiscard]] double zone_margin(const common::Site& site, double cable_length, double horizontal_acceleration,
                                 double gravity) noexcept;

/// Horizontal acceleration [m/s^2] of the trolley's point of a reference sample: radial
/// x'' - x gamma'^2, tangential x gamma'' + 2 x' gamma'.
[[nodiscard]] double horizontal_acceleration(const common::MotionReference& sample) noexcept;

[[nodiscard]] ZoneDistances zone_distances(const common::Site& site, const common::MotionReference& sample) noexcept;

/// The zone (index) the reference sample intrudes on with its margin, or -1: the margin of the
/// larger of the sample's horizontal acceleration and `acceleration` [m/s^2] (a recent peak: the
/// swing it excited is still there). With `caps`, zone i's margin is at most caps[i]: a move that
/// starts inside a zone's margin may leave it (no sample closer than its start), not approach it.
/// `extra` [m] is added to the margin (the half-distance to the next sample of a sampled path).
[[nodiscard]] int intruded_zone(const common::Site& site, std::uint32_t enabled, const common::MotionReference& sample,
                                double gravity, double acceleration = 0.0, const ZoneDistances* caps = nullptr,
                                double extra = 0.0) noexcept;

/// Horizontal swing allowance [m] of a load on a cable of `cable_length` [m] that changes its
/// horizontal speed by `speed_change` [m/s] at up to `horizontal_acceleration` [m/s^2]: the factor
/// times the smaller of the quasi-static deflection L a / g and the swing a velocity step excites,
/// speed_change / w with w = sqrt(g/L) (a slow move excites little swing, however hard it brakes).
[[nodiscard]] double swing_allowance(double cable_length, double horizontal_acceleration, double speed_change,
                                     double gravity) noexcept;

/// The zone (index) intruded on anywhere in the region the trolley and the cable can sweep while
/// each axis moves monotonically between its two given values (trolley [m], slew [rad], cable
/// [m]), keeping the clearance plus `allowance` [m] (swing_allowance), or -1. Checks the region's
/// boundary and diagonal at a spacing below the zone clearance. With `caps`, zone i's margin is at
/// most caps[i] (a crane already that close may move away, or along it, not closer).
[[nodiscard]] int intruded_zone(const common::Site& site, std::uint32_t enabled, double trolley_from,
                                double trolley_to, double slew_from, double slew_to, double cable_from, double cable_to,
                                double allowance, const ZoneDistances* caps = nullptr) noexcept;

}  // namespace crane::trajectory_planner
