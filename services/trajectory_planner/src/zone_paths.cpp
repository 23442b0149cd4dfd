#include "crane/trajectory_planner/zone_paths.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "crane/trajectory_planner/zone_guard.hpp"

namespace crane::trajectory_planner {

const char* zone_route_name(ZoneRoute route) noexcept {
  switch (route) {
    case ZoneRoute::direct: return "direct";
    case ZoneRoute::radius_first: return "radius first";
    case ZoneRoute::slew_first: return "slew first";
    case ZoneRoute::retract: return "retract";
    case ZoneRoute::sidestep: return "sidestep";
    case ZoneRoute::side_approach: return "side approach";
    case ZoneRoute::grid: return "grid path";
  }
  return "unknown";
}

namespace {

// `goal` with its accelerations scaled by `scale` and its velocities by sqrt(scale) (so the
// centripetal acceleration scales too).
MoveGoal slowed(const MoveGoal& goal, double scale) noexcept {
  MoveGoal g = goal;
  const double slower = std::sqrt(scale);
  for (AxisLimits* limits : {&g.trolley_limits, &g.slew_limits, &g.cable_limits}) {
    limits->max_acceleration *= scale;
    limits->max_velocity *= slower;
  }
  return g;
}

// The last resort: a shortest path over a grid of rest points in (trolley, slew) at one cable
// length (5 radii x every 15 degrees of the slew range), each edge a rest-to-rest segment of the
// goal's profile checked against the zones like a whole route; Dijkstra on the segments' durations,
// then the path shortened (a node skipped when the segment over it is clear too): its waypoints
// (not found: no path, or one needing more than `room`).
struct GridPath {
  bool found{false};
  std::size_t count{0};
  std::array<Waypoint, kMaxWaypoints> points{};
};

GridPath grid_path(TrajectoryPlanner& scratch, const MoveGoal& limits, const Waypoint& from, const Waypoint& to,
                   std::uint32_t enabled, double spacing, std::size_t room) noexcept {
  const TrajectoryPlannerParams& p = scratch.params();
  constexpr std::size_t kRadii = 5;
  constexpr double kStep = 0.2617993877991494;  // 15 degrees
  const auto angles = static_cast<std::size_t>(std::floor((p.slew_max_angle - p.slew_min_angle) / kStep)) + 1;
  constexpr std::size_t kMaxAngles = 64;
  constexpr std::size_t kMaxNodes = kRadii * kMaxAngles + 2;
  GridPath none;
  if (angles > kMaxAngles) return none;
  const std::size_t grid = kRadii * angles;
  const std::size_t start = grid, target = grid + 1, nodes = grid + 2;
  const double span = p.trolley_max_position - p.trolley_min_position;
  const auto node = [&](std::size_t i) -> Waypoint {
    if (i == start) return from;
    if (i == target) return to;
    return {p.trolley_min_position + span * (0.1 + 0.2 * static_cast<double>(i % kRadii)),
            p.slew_min_angle + kStep * static_cast<double>(i / kRadii), from.cable};
  };
  // A clear rest-to-rest segment a -> b: its duration, or a negative value.
  const auto segment = [&](std::size_t a, std::size_t b) {
    MoveGoal g = limits;
    const Waypoint wb = node(b);
    g.trolley_target = wb.trolley;
    g.slew_target = wb.slew;
    g.cable_target = wb.cable;
    g.waypoint_count = 0;
    const Waypoint wa = node(a);
    common::CraneStateEstimate at;
    at.trolley_position = wa.trolley;
    at.slew_angle = wa.slew;
    at.cable_length = wa.cable;
    scratch.reset();
    if (scratch.start_move(g, at) != GoalStatus::accepted) return -1.0;
    if (scratch.intruded_zone(enabled, spacing) >= 0) return -1.0;
    return scratch.move_duration();
  };
  // Neighbours: the grid's four, and the start and target to the grid points of their cell.
  const auto near = [&](const Waypoint& w, std::size_t i) {
    const Waypoint g = node(i);
    return std::abs(g.trolley - w.trolley) <= 0.2 * span + 1e-9 && std::abs(g.slew - w.slew) <= kStep + 1e-9;
  };
  std::array<double, kMaxNodes> cost{};
  std::array<std::size_t, kMaxNodes> previous{};
  std::array<bool, kMaxNodes> done{};
  cost.fill(1e300);
  cost[start] = 0.0;
  for (std::size_t round = 0; round < nodes; ++round) {
    std::size_t u = nodes;
    for (std::size_t i = 0; i < nodes; ++i) {
      if (!done[i] && cost[i] < 1e300 && (u == nodes || cost[i] < cost[u])) u = i;
    }
    if (u == nodes || u == target) break;
    done[u] = true;
    for (std::size_t v = 0; v < nodes; ++v) {
      if (done[v] || v == start) continue;
      bool adjacent = false;
      if (u < grid && v < grid) {
        const std::size_t ru = u % kRadii, au = u / kRadii, rv = v % kRadii, av = v / kRadii;
        adjacent = (au == av && (ru + 1 == rv || rv + 1 == ru)) || (ru == rv && (au + 1 == av || av + 1 == au));
      } else if (u == start && v < grid) {
        adjacent = near(from, v);
      } else if (v == target && u < grid) {
        adjacent = near(to, u);
      } else if (u == start && v == target) {
        adjacent = true;
      }
      if (!adjacent) continue;
      const double d = segment(u, v);
      if (d < 0.0) continue;
      if (cost[u] + d < cost[v]) {
        cost[v] = cost[u] + d;
        previous[v] = u;
      }
    }
  }
  if (!(cost[target] < 1e300)) return none;
  std::array<std::size_t, kMaxNodes> path{};
  std::size_t length = 0;
  for (std::size_t i = target; i != start; i = previous[i]) path[length++] = i;
  path[length++] = start;
  std::reverse(path.begin(), path.begin() + static_cast<std::ptrdiff_t>(length));
  // Shorten: from each kept node, the farthest node along the path with a clear segment to it.
  GridPath out;
  std::size_t at = 0;
  while (at + 1 < length) {
    std::size_t next = at + 1;
    for (std::size_t j = length - 1; j > at + 1; --j) {
      if (segment(path[at], path[j]) >= 0.0) {
        next = j;
        break;
      }
    }
    if (path[next] != target) {
      if (out.count >= room) return none;
      out.points[out.count++] = node(path[next]);
    }
    at = next;
  }
  out.found = true;
  return out;
}

}  // namespace

ZonePlan plan_around_zones(TrajectoryPlanner& scratch, const MoveGoal& goal, const common::CraneStateEstimate& current,
                           std::uint32_t zones_enabled, double spacing) noexcept {
  const TrajectoryPlannerParams& p = scratch.params();
  ZonePlan plan;
  plan.goal = goal;
  const common::Site& site = p.site;
  const auto at_rest = [](double x, double g, double l) {
    common::MotionReference r;
    r.trolley.position = x;
    r.slew.position = g;
    r.cable_length.position = l;
    return r;
  };
  // Zones the crane is in at the start are not held against a route.
  std::uint32_t enabled = zones_enabled;
  for (int zone = intruded_zone(site, enabled, at_rest(current.trolley_position, current.slew_angle, current.cable_length),
                                p.gravity);
       zone >= 0;
       zone = intruded_zone(site, enabled, at_rest(current.trolley_position, current.slew_angle, current.cable_length),
                            p.gravity)) {
    enabled &= ~(1U << zone);
  }
  if (enabled == 0 || site.zones.empty()) {
    plan.found = true;
    return plan;
  }
  const int target_zone = intruded_zone(site, enabled, at_rest(goal.trolley_target, goal.slew_target, goal.cable_target),
                                        p.gravity);
  if (target_zone >= 0) {
    plan.zone = target_zone;
    plan.target_in_zone = true;
    return plan;
  }
  double best = 0.0;
  const double two_pi = 2.0 * std::numbers::pi;
  const double other_way = goal.slew_target > current.slew_angle ? goal.slew_target - two_pi : goal.slew_target + two_pi;
  const bool may_go_other_way = other_way >= p.slew_min_angle && other_way <= p.slew_max_angle;
  const ZoneRoute routes[] = {ZoneRoute::direct,   ZoneRoute::radius_first, ZoneRoute::slew_first,
                              ZoneRoute::retract,  ZoneRoute::sidestep,     ZoneRoute::side_approach};
  const double x0 = current.trolley_position, g0 = current.slew_angle, l0 = current.cable_length;
  const double x1 = goal.trolley_target, l1 = goal.cable_target;
  // Heights to travel at: as the move goes (0: no lift), or lifted first to the higher of the two
  // ends, or to twice the clearance over a low zone (and at least that high), lowered at the end.
  std::array<double, common::Site::kMaxZones + 2> lifts{};
  std::size_t lift_count = 0;
  lifts[lift_count++] = 0.0;
  const double higher_end = std::min(l0, l1);
  if (higher_end < l0 || higher_end < l1) lifts[lift_count++] = higher_end;
  for (std::size_t z = 0; z < site.zones.size() && z < common::Site::kMaxZones; ++z) {
    if ((enabled & (1U << z)) == 0) continue;
    const double over = std::min(site.jib_height - (site.zones[z].top + 2.0 * site.zone_clearance), higher_end);
    if (over >= p.cable_min_length && over < higher_end) lifts[lift_count++] = over;
  }
  // Slower moves swing less (the margin grows with the acceleration): each route is tried at the
  // goal's accelerations, then at 1/2, 1/4, 1/10 and 1/25 of them (velocities by the square root).
  for (const double scale : {1.0, 0.5, 0.25, 0.1, 0.04}) {
    for (const bool reverse : {false, true}) {
      if (reverse && !may_go_other_way) break;
      const double slew = reverse ? other_way : goal.slew_target;
      for (std::size_t lift = 0; lift < lift_count; ++lift) {
        if (lift > 0 && goal.waypoint_count > 0) break;
        for (const ZoneRoute route : routes) {
          if (route != ZoneRoute::direct && goal.waypoint_count > 0) continue;
          // The retract route goes in to a tenth or a quarter of the trolley's travel; the sidestep
          // route slews 15 or 30 degrees either way first, then retracts: out of a corner beside a zone.
          // The side approach slews 15 or 30 degrees past the target (either side), moves the trolley
          // out or in there, and slews back: to a target beside a zone, along the zone's edge.
          const int variants = route == ZoneRoute::retract         ? 2
                               : route == ZoneRoute::sidestep      ? 8
                               : route == ZoneRoute::side_approach ? 4
                                                                   : 1;
          for (int variant = 0; variant < variants; ++variant) {
            MoveGoal candidate = slowed(goal, scale);
            candidate.slew_target = slew;
            // Not right to the trolley's minimum: the anti-swing law overshoots a stop by several cm.
            const double span = p.trolley_max_position - p.trolley_min_position;
            const double inner = p.trolley_min_position + (0.1 + 0.15 * (variant % 2)) * span;
            const double l = lift > 0 ? lifts[lift] : l0;  // the cable while travelling
            std::size_t n = 0;
            const auto add = [&](double x, double g, double length) {
              candidate.waypoints[n++] = Waypoint{x, g, length};
            };
            if (lift > 0) add(x0, g0, l);
            switch (route) {
              case ZoneRoute::direct:
                if (lift == 0) n = goal.waypoint_count;
                break;
              case ZoneRoute::radius_first: add(x1, g0, l); break;
              case ZoneRoute::slew_first: add(x0, slew, l); break;
              case ZoneRoute::retract:
                add(inner, g0, l);
                add(inner, slew, l);
                break;
              case ZoneRoute::sidestep: {
                constexpr double kSteps[] = {0.2618, -0.2618, 0.5236, -0.5236};
                const double aside = g0 + kSteps[variant % 4];
                if (aside < p.slew_min_angle || aside > p.slew_max_angle) continue;
                add(x0, aside, l);
                add(inner, aside, l);
                add(inner, slew, l);
                break;
              }
              case ZoneRoute::grid: continue;  // the last resort, below
              case ZoneRoute::side_approach: {
                constexpr double kSteps[] = {0.2618, -0.2618, 0.5236, -0.5236};
                const double beside = slew + kSteps[variant];
                if (beside < p.slew_min_angle || beside > p.slew_max_angle) continue;
                add(x0, beside, l);
                add(x1, beside, l);
                break;
              }
            }
            if (lift > 0) add(x1, slew, l);
            candidate.waypoint_count = n;
            scratch.reset();
            if (scratch.start_move(candidate, current) != GoalStatus::accepted) continue;
            const int zone = scratch.intruded_zone(enabled, spacing);
            if (zone >= 0) {
              if (plan.zone < 0) plan.zone = zone;
              continue;
            }
            if (!plan.found || scratch.move_duration() < best) {
              best = scratch.move_duration();
              plan.found = true;
              plan.route = route;
              plan.lifted = lift > 0;
              plan.other_way_round = reverse;
              plan.acceleration_scale = scale;
              plan.goal = candidate;
            }
          }
        }
      }
    }
    if (plan.found) break;  // the fastest at the highest acceleration that has a clear route
  }
  // The last resort: a path over a grid of rest points, at the start's height and at the highest
  // travel height, at half and at 1/25 of the goal's accelerations.
  if (!plan.found && goal.waypoint_count == 0) {
    for (const double scale : {0.5, 0.04}) {
      // At the start's height, and at the highest travel height of the routes above.
      for (std::size_t which = 0; which < std::min<std::size_t>(2, lift_count) && !plan.found; ++which) {
        const std::size_t lift = which == 0 ? 0 : lift_count - 1;
        MoveGoal candidate = slowed(goal, scale);
        const double l = lift > 0 ? lifts[lift] : l0;
        const std::size_t room = kMaxWaypoints - (lift > 0 ? 2 : 0);
        const GridPath path = grid_path(scratch, candidate, Waypoint{x0, g0, l}, Waypoint{x1, goal.slew_target, l},
                                        enabled, spacing, room);
        if (!path.found) continue;
        std::size_t n = 0;
        if (lift > 0) candidate.waypoints[n++] = Waypoint{x0, g0, l};
        for (std::size_t i = 0; i < path.count; ++i) candidate.waypoints[n++] = path.points[i];
        if (lift > 0) candidate.waypoints[n++] = Waypoint{x1, goal.slew_target, l};
        candidate.waypoint_count = n;
        scratch.reset();
        if (scratch.start_move(candidate, current) != GoalStatus::accepted) continue;
        if (scratch.intruded_zone(enabled, spacing) >= 0) continue;
        plan.found = true;
        plan.route = ZoneRoute::grid;
        plan.lifted = lift > 0;
        plan.acceleration_scale = scale;
        plan.goal = candidate;
      }
      if (plan.found) break;
    }
  }
  return plan;
}

}  // namespace crane::trajectory_planner
