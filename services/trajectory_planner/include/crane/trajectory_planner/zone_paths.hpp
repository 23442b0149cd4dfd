#pragma once
// Goals around the site's no-go zones: a goal whose target is in a zone (with the clearance) is
// refused, naming the zone; otherwise the planner tries routes made of rest-to-rest segments (the
// goal's profile on each, so every segment is swing-free) and takes the fastest one whose whole
// reference keeps the zone margin (zone_guard.hpp):
//   direct; the slew the other way round (target -+ 2 pi, inside the slew range); radius first
//   (trolley, then slew); slew first; retract (trolley in, slew, then out); sidestep
//   (slew 15 or 30 degrees either way, then retract: out of a corner beside a zone); side approach
//   (slew 15 or 30 degrees past the target, trolley out or in there, slew back: to a target beside
//   a zone, along its edge); each of these
//   with the slew the other way round, and each also lifted: the load hoisted first (to the higher
//   of the start's and the target's heights, or to twice the clearance over a low zone's top, so
//   it passes over it), travelling at that height and lowered at the target; the retract and
//   sidestep routes in to a tenth and to a quarter of the trolley's travel. When none is clear at the goal's accelerations, the same
//   routes at 1/2, 1/4, 1/10 and 1/25 of them, velocities scaled by the square root (a slower move
//   swings less, so its margin is smaller). Last, when none of these is clear: a shortest path
//   (Dijkstra on the segments' durations) over a grid of rest points (5 radii x every 15 degrees
//   of the slew range, at each travel height), each edge a rest-to-rest segment checked like a
//   route, shortened where a segment can skip a point, at 1/2 and then 1/25 of the accelerations,
//   if it needs at most the 8 waypoints of a request. Planning a goal among zones takes up to tens
//   of milliseconds in the worst case (no route at all): one late planner cycle.
// Zones the crane already intrudes on at the start are not held against a route (it may leave).
// A goal with its own waypoints is checked as given (direct only).

#include <cstdint>

#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::trajectory_planner {

enum class ZoneRoute : std::uint8_t { direct, radius_first, slew_first, retract, sidestep, side_approach, grid };
[[nodiscard]] const char* zone_route_name(ZoneRoute route) noexcept;

struct ZonePlan {
  bool found{false};          // a clear route: `goal` (with its waypoints) is it
  int zone{-1};               // not found: the zone the target is in, or the one the direct route enters
  bool target_in_zone{false}; // not found because the target itself is in `zone`
  ZoneRoute route{ZoneRoute::direct};
  bool lifted{false};         // the load lifted first (over a low zone, or to the higher end) and lowered last
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
