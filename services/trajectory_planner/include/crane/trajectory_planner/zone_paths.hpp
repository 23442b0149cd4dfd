#pragma once
// Goals around the site's no-go zones: a goal whose target is in a zone (with the clearance) is
// refused, naming the zone; otherwise the planner tries routes made of rest-to-rest segments (the
// goal's profile on each, so every segment is swing-free) and takes the fastest one whose whole
// reference keeps the zone margin (zone_guard.hpp):
//   direct; the slew the other way round (target -+ 2 pi, inside the slew range); radius first
//   (trolley, then slew); slew first; retract (trolley in, slew, then out); sidestep
//   (slew 15 or 30 degrees either way, then retract: out of a corner beside a zone); hoist
//   over (the load lifted to twice the clearance over a low zone's top, travel, then down); and
//   each of these with the slew the other way round; the retract and sidestep routes in to a tenth
//   and to a quarter of the trolley's travel. When none is clear at the goal's accelerations, the same
//   routes at 1/2, 1/4, 1/10 and 1/25 of them, velocities scaled by the square root (a slower move
//   swings less, so its margin is smaller).
// Zones the crane already intrudes on at the start are not held against a route (it may leave).
// A goal with its own waypoints is checked as given (direct only).

#include <cstdint>

#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::trajectory_planner {

enum class ZoneRoute : std::uint8_t { direct, radius_first, slew_first, retract, sidestep, hoist_over };
[[nodiscard]] const char* zone_route_name(ZoneRoute route) noexcept;

struct ZonePlan {
  bool found{false};          // a clear route: `goal` (with its waypoints) is it
  int zone{-1};               // not found: the zone the target is in, or the one the direct route enters
  bool target_in_zone{false}; // not found because the target itself is in `zone`
  ZoneRoute route{ZoneRoute::direct};
  bool other_way_round{false};
  double acceleration_scale{1.0};  // of the goal's accelerations (1, 0.5, 0.25, 0.1, 0.04)
  MoveGoal goal{};
};

/// Plans `goal` from `current` on `scratch` (a copy of the running planner: it is overwritten).
/// `zones_enabled`: bit i enforces params().site.zones[i]. `spacing` [s]: the reference is checked
/// at this interval. Never throws, never allocates.
[[nodiscard]] ZonePlan plan_around_zones(TrajectoryPlanner& scratch, const MoveGoal& goal,
                                         const common::CraneStateEstimate& current, std::uint32_t zones_enabled,
                                         double spacing = 0.02) noexcept;

}  // namespace crane::trajectory_planner
