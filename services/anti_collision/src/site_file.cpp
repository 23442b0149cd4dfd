#include "crane/anti_collision/site_file.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <utility>

#include "crane/common/validation.hpp"
#include "crane/config/config_document.hpp"
#include "crane/config/yaml_section.hpp"
#include "crane/trajectory_planner/speed_reference.hpp"
#include "crane/trajectory_planner/trajectory_planner_stage.hpp"
#include "site_ranges.hpp"

namespace crane::anti_collision {
namespace {

using common::ConfigError;
using namespace detail;

StoppingData read_stopping(config::YamlSection s) {
  StoppingData d;
  d.reaction_time = s.number("reaction_time", kReaction.lower, kReaction.upper);
  d.trolley_deceleration = s.number("trolley_deceleration", kDeceleration.lower, kDeceleration.upper);
  d.slew_deceleration = s.number("slew_deceleration", kDeceleration.lower, kDeceleration.upper);
  d.hoist_deceleration = s.number("hoist_deceleration", kDeceleration.lower, kDeceleration.upper);
  d.brake_deceleration_factor = s.number("brake_deceleration_factor", kBrakeFactor.lower, kBrakeFactor.upper);
  s.finish();
  return d;
}

// The planner's block of the crane whose stack config is `path`, read by the planner's own reader
// (trajectory_planner::read_params: every field and range checked there; the cable range from the
// config's crane block).
trajectory_planner::TrajectoryPlannerParams crane_planner(const std::filesystem::path& path) {
  try {
    return config::ConfigDocument::load(path.string()).read("trajectory_planner", trajectory_planner::read_params);
  } catch (const ConfigError& error) {
    throw ConfigError(std::string("the crane's config: ") + error.what());
  }
}

// What the site file says of a crane against what its own config lets it do. The site's airspace
// (its whole reach, a lost crane's) must hold every pose the crane's planner may command: the
// planner's trolley travel and slew range, and the hook heights of its cable range under the site's
// jib_height. Its soft stops must be no quicker than the planner's, which makes them (a stop
// modelled quicker than it is ends short of where the crane rests). Each pair is checked where the
// values live; throws ConfigError naming the site's field, both values and the config's field.
void require_within_site(const std::string& prefix, const SiteCrane& crane,
                         const trajectory_planner::TrajectoryPlannerParams& planner, const std::string& config_name) {
  const auto fail = [&](const char* field, double site_value, const char* relation, const std::string& config_field,
                        double config_value, const char* why) {
    throw ConfigError(prefix + "." + field + " = " + common::format_value(site_value) + " " + relation +
                      " the crane's config " + config_field + " = " + common::format_value(config_value) + " (" +
                      config_name + "): " + why);
  };
  constexpr const char* kReach = "the site would not hold all of the crane's reach";
  if (crane.trolley_min > planner.trolley_min_position) {
    fail("trolley_min", crane.trolley_min, "is above", "trajectory_planner.trolley_min_position",
         planner.trolley_min_position, kReach);
  }
  if (crane.trolley_max < planner.trolley_max_position) {
    fail("trolley_max", crane.trolley_max, "is below", "trajectory_planner.trolley_max_position",
         planner.trolley_max_position, kReach);
  }
  if (crane.slew_min > planner.slew_min_angle) {
    fail("slew_min", crane.slew_min, "is above", "trajectory_planner.slew_min_angle", planner.slew_min_angle, kReach);
  }
  if (crane.slew_max < planner.slew_max_angle) {
    fail("slew_max", crane.slew_max, "is below", "trajectory_planner.slew_max_angle", planner.slew_max_angle, kReach);
  }
  constexpr double kHeightTolerance = 1e-9;  // [m] jib_height - cable length in floating point
  const double lowest = crane.jib_height - planner.cable_max_length;
  if (crane.hook_height_min > lowest + kHeightTolerance) {
    fail("hook_height_min", crane.hook_height_min, "is above jib_height less", "crane.max_cable_length",
         planner.cable_max_length, kReach);
  }
  const double highest = crane.jib_height - planner.cable_min_length;
  if (crane.hook_height_max < highest - kHeightTolerance) {
    fail("hook_height_max", crane.hook_height_max, "is below jib_height less", "crane.min_cable_length",
         planner.cable_min_length, kReach);
  }
  constexpr const char* kStop = "the site would predict the crane's soft stop shorter than the planner makes it";
  const auto& d = crane.stopping;
  if (d.trolley_deceleration > planner.manual.trolley.acceleration) {
    fail("stopping.trolley_deceleration", d.trolley_deceleration, "is above",
         "trajectory_planner.manual.trolley_acceleration", planner.manual.trolley.acceleration, kStop);
  }
  if (d.slew_deceleration > planner.manual.slew.acceleration) {
    fail("stopping.slew_deceleration", d.slew_deceleration, "is above", "trajectory_planner.manual.slew_acceleration",
         planner.manual.slew.acceleration, kStop);
  }
  if (d.hoist_deceleration > planner.manual.hoist.acceleration) {
    fail("stopping.hoist_deceleration", d.hoist_deceleration, "is above",
         "trajectory_planner.manual.hoist_acceleration", planner.manual.hoist.acceleration, kStop);
  }
}

}  // namespace

SiteLayout parse_site_layout(const std::string& yaml_text, const std::string& source_name,
                             const std::filesystem::path& directory) {
  const YAML::Node root = config::parse_yaml_mapping(yaml_text, source_name);
  SiteLayout layout;
  try {
    config::YamlSection document(root, "");
    config::YamlSection s = document.child("site");
    layout.name = s.text("name");
    config::YamlSection margins = s.child("margins");
    layout.margins.warning = margins.number("warning", kMargin.lower, kMargin.upper);
    layout.margins.slow_down = margins.number("slow_down", kMargin.lower, kMargin.upper);
    layout.margins.stop = margins.number("stop", kMargin.lower, kMargin.upper);
    margins.finish();
    layout.domain_id = s.integer("domain_id", 0, kMaxDomain);
    layout.link_deadline = s.number("link_deadline", kDeadline.lower, kDeadline.upper);
    layout.max_wait = s.number("max_wait", kMaxWait.lower, kMaxWait.upper);
    layout.part_of_leg = s.flag("part_of_leg");
    layout.most_work_left_first = s.flag("most_work_left_first");
    layout.travel_step = s.number("travel_step", kTravelStep.lower, kTravelStep.upper);
    config::YamlSection paths = s.child("paths");
    layout.paths.trolley_overshoot = paths.number("trolley_overshoot", kOvershoot.lower, kOvershoot.upper);
    layout.paths.slew_overshoot = paths.number("slew_overshoot", kOvershoot.lower, kOvershoot.upper);
    layout.paths.travel_swing = paths.number("travel_swing", kSwingAllowance.lower, kSwingAllowance.upper);
    layout.paths.hoist_swing_radius = paths.number("hoist_swing_radius", kOvershoot.lower, kOvershoot.upper);
    layout.paths.trolley_tracking = paths.number("trolley_tracking", kOvershoot.lower, kOvershoot.upper);
    layout.paths.slew_tracking = paths.number("slew_tracking", kOvershoot.lower, kOvershoot.upper);
    layout.paths.trolley_hold = paths.number("trolley_hold", kOvershoot.lower, kOvershoot.upper);
    layout.paths.slew_hold = paths.number("slew_hold", kOvershoot.lower, kOvershoot.upper);
    paths.finish();
    for (auto& z : s.list("zones")) layout.zones.push_back(config::read_zone(z));
    // Each crane's planner block and the config's name as the site file gives it: checked against the
    // site's description once the site's own structure is (validate).
    std::vector<std::pair<trajectory_planner::TrajectoryPlannerParams, std::string>> planners;
    for (auto& c : s.list("cranes")) {
      SiteCrane crane;
      crane.name = c.text("name");
      crane.kind = common::crane_kind_from_string(c.text("kind", {"tower"}), c.field("kind"));
      config::YamlSection base = c.child("base");
      crane.base = {base.number("x", kCoordinate.lower, kCoordinate.upper),
                    base.number("y", kCoordinate.lower, kCoordinate.upper)};
      base.finish();
      crane.slew_zero_heading = c.number("slew_zero_heading", kHeading.lower, kHeading.upper);
      crane.jib_height = c.number("jib_height", kHeight.lower, kHeight.upper);
      crane.jib_length = c.number("jib_length", kLength.lower, kLength.upper);
      crane.counter_jib_length = c.number("counter_jib_length", kCounterJib.lower, kCounterJib.upper);
      crane.jib_width = c.number("jib_width", kSection.lower, kSection.upper);
      crane.jib_depth = c.number("jib_depth", kSection.lower, kSection.upper);
      crane.mast_width = c.number("mast_width", kSection.lower, kSection.upper);
      crane.trolley_min = c.number("trolley_min", kTrolley.lower, kTrolley.upper);
      crane.trolley_max = c.number("trolley_max", kTrolley.lower, kTrolley.upper);
      crane.slew_min = c.number("slew_min", kSlewTravel.lower, kSlewTravel.upper);
      crane.slew_max = c.number("slew_max", kSlewTravel.lower, kSlewTravel.upper);
      crane.hook_height_min = c.number("hook_height_min", kHook.lower, kHook.upper);
      crane.hook_height_max = c.number("hook_height_max", kHook.lower, kHook.upper);
      crane.load_radius = c.number("load_radius", kLoadRadius.lower, kLoadRadius.upper);
      crane.stopping = read_stopping(c.child("stopping"));
      const std::string named = c.text("config");
      crane.config = (directory / named).lexically_normal().string();
      trajectory_planner::TrajectoryPlannerParams planner;
      try {
        planner = crane_planner(crane.config);
      } catch (const ConfigError& error) {
        throw ConfigError(c.field("config") + " = \"" + named + "\": " + error.what());
      }
      // The soft stop's shaper: the mean delay sum A_i t_i of the planner's manual.shaping, in swing
      // periods (the site file has no field of its own for it).
      crane.stopping.soft_stop_delay_periods =
          trajectory_planner::shaper_delay_periods(planner.manual.shaping, planner.manual.swing_damping_ratio);
      planners.emplace_back(std::move(planner), named);
      crane.domain_id = c.integer("domain_id", 0, kMaxDomain);
      crane.priority = c.integer("priority", 0, kMaxPriority);
      c.finish();
      layout.cranes.push_back(std::move(crane));
    }
    s.finish();
    document.finish();
    validate(layout, "site");
    for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
      const SiteCrane& crane = layout.cranes[i];
      require_within_site("site.cranes[" + std::to_string(i) + "] (" + crane.name + ")", crane, planners[i].first,
                          planners[i].second);
    }
  } catch (const ConfigError& error) {
    throw ConfigError(source_name + ": " + error.what());
  } catch (const YAML::Exception& error) {
    throw ConfigError(source_name + ": " + error.what());
  }
  return layout;
}

SiteLayout load_site_layout(const std::string& path) {
  const std::filesystem::path file(path);
  return parse_site_layout(config::read_text_file(path), file.filename().string(), file.parent_path());
}

std::vector<SiteJob> load_site_jobs(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  std::istringstream text(config::read_text_file(path));
  std::string line;
  if (!std::getline(text, line) || line != kSiteJobsHeader) {
    throw ConfigError(name + ": line 1 must be the header " + kSiteJobsHeader);
  }
  constexpr std::array<const char*, 6> kFields{"pick_slew_rad",  "pick_trolley_m",  "pick_cable_length_m",
                                               "place_slew_rad", "place_trolley_m", "place_cable_length_m"};
  std::vector<SiteJob> jobs;
  for (int number = 2; std::getline(text, line); ++number) {
    if (line.empty()) continue;
    std::array<double, 6> v{};
    std::size_t field = 0, begin = 0;
    for (; field < v.size() && begin <= line.size(); ++field) {
      const std::size_t end = std::min(line.find(',', begin), line.size());
      const std::string cell = line.substr(begin, end - begin);
      const auto [ptr, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), v[field]);
      if (ec != std::errc() || ptr != cell.data() + cell.size() || !std::isfinite(v[field])) {
        throw ConfigError(name + ": line " + std::to_string(number) + ": " + kFields[field] + " = '" + cell +
                          "' is not a finite number");
      }
      begin = end + 1;
    }
    if (field != v.size() || begin <= line.size()) {
      throw ConfigError(name + ": line " + std::to_string(number) + ": expected 6 fields (" + kSiteJobsHeader + ")");
    }
    jobs.push_back({{v[0], v[1], v[2]}, {v[3], v[4], v[5]}});
  }
  return jobs;
}

void write_site_jobs(const std::string& path, const std::vector<SiteJob>& jobs) {
  std::ofstream out(path);
  out << kSiteJobsHeader << '\n';
  char row[256];
  for (const SiteJob& j : jobs) {
    std::snprintf(row, sizeof row, "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", j.pick.slew, j.pick.trolley,
                  j.pick.cable_length, j.place.slew, j.place.trolley, j.place.cable_length);
    out << row;
  }
  if (!out) throw std::runtime_error("cannot write the jobs file " + path);
}

}  // namespace crane::anti_collision
