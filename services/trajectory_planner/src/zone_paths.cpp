#include "crane/trajectory_planner/zone_paths.hpp"

#include <algorithm>
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
    case ZoneRoute::hoist_over: return "hoist over";
  }
  return "unknown";
}

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
  const ZoneRoute routes[] = {ZoneRoute::direct,  ZoneRoute::radius_first, ZoneRoute::slew_first,
                              ZoneRoute::retract, ZoneRoute::sidestep,     ZoneRoute::hoist_over};
  // Slower moves swing less (the margin grows with the acceleration): each route is tried at the
  // goal's accelerations, then at 1/2, 1/4, 1/10 and 1/25 of them (velocities by the square root).
  for (const double scale : {1.0, 0.5, 0.25, 0.1, 0.04}) {
    for (const bool reverse : {false, true}) {
      if (reverse && !may_go_other_way) break;
      const double slew = reverse ? other_way : goal.slew_target;
      for (const ZoneRoute route : routes) {
        if (route != ZoneRoute::direct && goal.waypoint_count > 0) continue;
        // The retract route goes in to a tenth or a quarter of the trolley's travel;
        // the hoist-over route lifts the load just over one zone's top (for each low zone).
        // The sidestep route slews 15 or 30 degrees either way first, then retracts like the retract
        // route (in to the minimum): out of a corner next to a zone.
        const int variants = route == ZoneRoute::retract      ? 2
                             : route == ZoneRoute::hoist_over ? static_cast<int>(site.zones.size())
                             : route == ZoneRoute::sidestep   ? 8
                                                              : 1;
        for (int variant = 0; variant < variants; ++variant) {
          MoveGoal candidate = goal;
          candidate.slew_target = slew;
          // Accelerations scaled, and velocities by sqrt(scale) (the centripetal acceleration too).
          const double slower = std::sqrt(scale);
          candidate.trolley_limits.max_acceleration *= scale;
          candidate.slew_limits.max_acceleration *= scale;
          candidate.cable_limits.max_acceleration *= scale;
          candidate.trolley_limits.max_velocity *= slower;
          candidate.slew_limits.max_velocity *= slower;
          candidate.cable_limits.max_velocity *= slower;
          const double x0 = current.trolley_position, g0 = current.slew_angle, l0 = current.cable_length;
          const double x1 = goal.trolley_target;
          // Not right to the trolley's minimum: the anti-swing law overshoots a stop by several cm.
          const double span = p.trolley_max_position - p.trolley_min_position;
          const double inner = p.trolley_min_position + (0.1 + 0.15 * (variant % 2)) * span;
          std::size_t n = 0;
          const auto add = [&](double x, double g, double l) { candidate.waypoints[n++] = Waypoint{x, g, l}; };
          switch (route) {
            case ZoneRoute::direct: n = goal.waypoint_count; break;
            case ZoneRoute::radius_first: add(x1, g0, l0); break;
            case ZoneRoute::slew_first: add(x0, slew, l0); break;
            case ZoneRoute::retract:
              add(inner, g0, l0);
              add(inner, slew, l0);
              break;
            case ZoneRoute::sidestep: {
              constexpr double kSteps[] = {0.2618, -0.2618, 0.5236, -0.5236};
              const double aside = g0 + kSteps[variant % 4];
              if (aside < p.slew_min_angle || aside > p.slew_max_angle) continue;
              add(x0, aside, l0);
              add(inner, aside, l0);
              add(inner, slew, l0);
              break;
            }
            case ZoneRoute::hoist_over: {
              // Clears zone `variant` by twice the clearance (or stays at the start's or the target's
              // height if that is higher); skipped when the zone is too high to pass over.
              const double over = std::min({site.jib_height - (site.zones[variant].top + 2.0 * site.zone_clearance),
                                            l0, goal.cable_target});
              if ((enabled & (1U << variant)) == 0 || over < p.cable_min_length) continue;
              add(x0, g0, over);
              add(x1, slew, over);
              break;
            }
          }
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
            plan.other_way_round = reverse;
            plan.acceleration_scale = scale;
            plan.goal = candidate;
          }
        }
      }
    }
    if (plan.found) break;  // the fastest at the highest acceleration that has a clear route
  }
  return plan;
}

}  // namespace crane::trajectory_planner
