#include "crane/anti_collision/site_layout.hpp"

#include <cmath>
#include <numbers>
#include <set>
#include <utility>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/common/validation.hpp"
#include "site_ranges.hpp"

namespace crane::anti_collision {
namespace {

using common::ConfigError;
using common::format_value;
using common::require_in_range;
using namespace detail;

std::string crane_prefix(const std::string& prefix, std::size_t i, const SiteCrane& c) {
  return prefix + ".cranes[" + std::to_string(i) + "] (" + c.name + ")";
}

// Throws unless `value` is below `bound` (value_is_lower) or above it, naming both fields.
void require_below(const std::string& field, double value, const std::string& other, double bound, bool value_is_lower) {
  if (value_is_lower ? value < bound : value > bound) return;
  throw ConfigError(field + " = " + format_value(value) + " is out of range: must be " + (value_is_lower ? "< " : "> ") +
                    other + " = " + format_value(bound));
}

}  // namespace

int find_crane(const SiteLayout& layout, const std::string& name) noexcept {
  for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
    if (layout.cranes[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

void validate(const SiteLayout& layout, const std::string& prefix) {
  if (layout.cranes.empty() || layout.cranes.size() > SiteLayout::kMaxCranes) {
    throw ConfigError(prefix + ".cranes has " + std::to_string(layout.cranes.size()) +
                      " cranes: must be 1 to " + std::to_string(SiteLayout::kMaxCranes));
  }
  const Margins& m = layout.margins;
  require_in_range(prefix + ".margins.stop", m.stop, kMargin.lower, kMargin.upper);
  require_in_range(prefix + ".margins.slow_down", m.slow_down, kMargin.lower, kMargin.upper);
  require_in_range(prefix + ".margins.warning", m.warning, kMargin.lower, kMargin.upper);
  require_below(prefix + ".margins.slow_down", m.slow_down, "margins.stop", m.stop, false);
  require_below(prefix + ".margins.warning", m.warning, "margins.slow_down", m.slow_down, false);
  require_in_range(prefix + ".link_deadline", layout.link_deadline, kDeadline.lower, kDeadline.upper);
  require_in_range(prefix + ".max_wait", layout.max_wait, kMaxWait.lower, kMaxWait.upper);
  require_in_range(prefix + ".travel_step", layout.travel_step, kTravelStep.lower, kTravelStep.upper);
  require_in_range(prefix + ".paths.trolley_overshoot", layout.paths.trolley_overshoot, kOvershoot.lower, kOvershoot.upper);
  require_in_range(prefix + ".paths.slew_overshoot", layout.paths.slew_overshoot, kOvershoot.lower, kOvershoot.upper);
  require_in_range(prefix + ".paths.travel_swing", layout.paths.travel_swing, kSwingAllowance.lower, kSwingAllowance.upper);
  require_in_range(prefix + ".paths.hoist_swing_radius", layout.paths.hoist_swing_radius, kOvershoot.lower, kOvershoot.upper);
  require_in_range(prefix + ".paths.trolley_tracking", layout.paths.trolley_tracking, kOvershoot.lower, kOvershoot.upper);
  require_in_range(prefix + ".paths.slew_tracking", layout.paths.slew_tracking, kOvershoot.lower, kOvershoot.upper);
  require_in_range(prefix + ".paths.trolley_hold", layout.paths.trolley_hold, kOvershoot.lower, kOvershoot.upper);
  require_in_range(prefix + ".paths.slew_hold", layout.paths.slew_hold, kOvershoot.lower, kOvershoot.upper);

  std::set<std::string> names;
  if (layout.domain_id < 0 || layout.domain_id > kMaxDomain) {
    throw ConfigError(prefix + ".domain_id = " + std::to_string(layout.domain_id) + " is out of range: must be in [0, " +
                      std::to_string(kMaxDomain) + "]");
  }
  std::set<int> domains{layout.domain_id};
  for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
    const SiteCrane& c = layout.cranes[i];
    if (c.name.empty()) throw ConfigError(prefix + ".cranes[" + std::to_string(i) + "].name is empty");
    const std::string p = crane_prefix(prefix, i, c);
    if (!names.insert(c.name).second) throw ConfigError(p + ".name is used by an earlier crane");
    if (c.kind != common::CraneKind::tower) {
      throw ConfigError(p + ".kind = " + common::to_string(c.kind) + ": only tower cranes are implemented on a site");
    }
    require_in_range(p + ".base.x", c.base[0], kCoordinate.lower, kCoordinate.upper);
    require_in_range(p + ".base.y", c.base[1], kCoordinate.lower, kCoordinate.upper);
    require_in_range(p + ".slew_zero_heading", c.slew_zero_heading, kHeading.lower, kHeading.upper);
    require_in_range(p + ".jib_height", c.jib_height, kHeight.lower, kHeight.upper);
    require_in_range(p + ".jib_length", c.jib_length, kLength.lower, kLength.upper);
    require_in_range(p + ".counter_jib_length", c.counter_jib_length, kCounterJib.lower, kCounterJib.upper);
    require_in_range(p + ".jib_width", c.jib_width, kSection.lower, kSection.upper);
    require_in_range(p + ".jib_depth", c.jib_depth, kSection.lower, kSection.upper);
    require_in_range(p + ".mast_width", c.mast_width, kSection.lower, kSection.upper);
    require_in_range(p + ".trolley_min", c.trolley_min, kTrolley.lower, kTrolley.upper);
    require_in_range(p + ".trolley_max", c.trolley_max, kTrolley.lower, c.jib_length);
    require_below(p + ".trolley_min", c.trolley_min, "trolley_max", c.trolley_max, true);
    require_in_range(p + ".slew_min", c.slew_min, kSlewTravel.lower, kSlewTravel.upper);
    require_in_range(p + ".slew_max", c.slew_max, kSlewTravel.lower, kSlewTravel.upper);
    require_below(p + ".slew_min", c.slew_min, "slew_max", c.slew_max, true);
    require_in_range(p + ".hook_height_min", c.hook_height_min, kHook.lower, kHook.upper);
    require_in_range(p + ".hook_height_max", c.hook_height_max, c.hook_height_min, c.jib_height - c.load_radius);
    require_in_range(p + ".load_radius", c.load_radius, kLoadRadius.lower, kLoadRadius.upper);
    const StoppingData& d = c.stopping;
    require_in_range(p + ".stopping.reaction_time", d.reaction_time, kReaction.lower, kReaction.upper);
    require_in_range(p + ".stopping.trolley_deceleration", d.trolley_deceleration, kDeceleration.lower,
                     kDeceleration.upper);
    require_in_range(p + ".stopping.slew_deceleration", d.slew_deceleration, kDeceleration.lower,
                     kDeceleration.upper);
    require_in_range(p + ".stopping.hoist_deceleration", d.hoist_deceleration, kDeceleration.lower,
                     kDeceleration.upper);
    require_in_range(p + ".stopping.brake_deceleration_factor", d.brake_deceleration_factor, kBrakeFactor.lower,
                     kBrakeFactor.upper);
    require_in_range(p + ".stopping.soft_stop_delay_periods", d.soft_stop_delay_periods, kDelayPeriods.lower,
                     kDelayPeriods.upper);
    if (c.domain_id < 0 || c.domain_id > kMaxDomain) {
      throw ConfigError(p + ".domain_id = " + std::to_string(c.domain_id) + " is out of range: must be in [0, " +
                        std::to_string(kMaxDomain) + "]");
    }
    if (!domains.insert(c.domain_id).second) {
      throw ConfigError(p + ".domain_id is used by the site (" + prefix + ".domain_id) or an earlier crane");
    }
    if (c.priority < 0 || c.priority > kMaxPriority) {
      throw ConfigError(p + ".priority = " + std::to_string(c.priority) + " is out of range: must be in [0, " +
                        std::to_string(kMaxPriority) + "]");
    }
  }

  // The fixed zones: the single crane's zone rules (common::validate), in the site frame.
  common::Site zones;
  zones.jib_height = 0.0;
  zones.zone_clearance = m.stop;
  zones.zones = layout.zones;
  common::validate(zones, prefix);

  // Pairs: masts apart; a jib that reaches another crane's mast passes above all of that crane.
  for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
    for (std::size_t j = 0; j < layout.cranes.size(); ++j) {
      if (i == j) continue;
      const SiteCrane& a = layout.cranes[i];
      const SiteCrane& b = layout.cranes[j];
      const double apart = std::hypot(a.base[0] - b.base[0], a.base[1] - b.base[1]);
      const double masts = mast_radius(a) + mast_radius(b) + m.stop;
      if (i < j && apart < masts) {
        throw ConfigError(crane_prefix(prefix, j, b) + ".base is " + format_value(apart) + " m from " + a.name +
                          "'s: must be >= " + format_value(masts) + " (both masts' radii and margins.stop)");
      }
      const double reach = std::max(a.jib_length, a.counter_jib_length) + jib_radius(a) + mast_radius(b) + m.stop;
      if (apart < reach) {
        const double clear_above = top_of_structure(b) + m.stop;
        if (jib_bottom(a) < clear_above) {
          throw ConfigError(crane_prefix(prefix, i, a) + ".jib_height = " + format_value(a.jib_height) +
                            ": its jib reaches " + b.name + "'s mast (" + format_value(apart) + " m away, reach " +
                            format_value(reach) + " m) and must pass above " + b.name +
                            " by margins.stop: its jib's lowest point " + format_value(jib_bottom(a)) +
                            " m must be >= " + format_value(clear_above) + " m");
        }
      }
    }
  }
}

}  // namespace crane::anti_collision
