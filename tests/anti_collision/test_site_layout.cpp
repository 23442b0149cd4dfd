// The site file (anti_collision/site_layout.hpp): the shipped three-crane site loads with its
// values; bad files are refused naming the field, the value and the bound (each rule of
// validate(), hand-computed where it is geometry: the lower jib that reaches a higher crane's mast).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/site_file.hpp"
#include "crane/common/validation.hpp"

namespace {

using namespace crane::anti_collision;
using crane::common::ConfigError;
namespace fs = std::filesystem;

const std::string kSitePath = std::string(CRANE_SOURCE_DIR) + "/deploy/config/site_three_towers.yaml";

std::string shipped_text() {
  std::ifstream file(kSitePath);
  std::stringstream text;
  text << file.rdbuf();
  return text.str();
}

// The shipped text with the first match of `pattern` replaced.
std::string edited(const std::string& pattern, const std::string& replacement) {
  const std::string text = shipped_text();
  const std::regex re(pattern);
  if (!std::regex_search(text, re)) throw std::runtime_error("the site file has no '" + pattern + "'");
  return std::regex_replace(text, re, replacement, std::regex_constants::format_first_only);
}

// The message of the ConfigError parsing `text` throws ("" when none).
std::string refusal(const std::string& text) {
  try {
    (void)parse_site_layout(text, "site.yaml", std::filesystem::path(kSitePath).parent_path());
  } catch (const ConfigError& error) {
    return error.what();
  }
  return "";
}

TEST(SiteLayout, ShippedSiteLoads) {
  const SiteLayout site = load_site_layout(kSitePath);
  ASSERT_EQ(site.cranes.size(), 3u);
  EXPECT_EQ(site.cranes[0].name, "tc1");
  EXPECT_DOUBLE_EQ(site.cranes[1].base[0], 2.0);
  EXPECT_DOUBLE_EQ(site.cranes[2].jib_height, 3.5);
  EXPECT_EQ(site.cranes[2].priority, 1);
  EXPECT_EQ(site.cranes[1].domain_id, 12);
  EXPECT_DOUBLE_EQ(site.margins.stop, 0.05);
  // From lab_tower_crane.yaml's manual.shaping: zvd, impulses 1/4, 1/2, 1/4 at 0, T/2, T.
  EXPECT_NEAR(site.cranes[0].stopping.soft_stop_delay_periods, 0.5, 1e-12);
  EXPECT_EQ(std::filesystem::path(site.cranes[0].config),
            (std::filesystem::path(kSitePath).parent_path() / "lab_tower_crane.yaml").lexically_normal());
  ASSERT_EQ(site.zones.size(), 1u);
  EXPECT_TRUE(site.zones[0].fixed);
  EXPECT_DOUBLE_EQ(site.max_wait, 20.0);
  EXPECT_TRUE(site.part_of_leg);
  EXPECT_TRUE(site.most_work_left_first);
  EXPECT_DOUBLE_EQ(site.travel_step, 0.5);
  EXPECT_DOUBLE_EQ(site.paths.trolley_hold, 0.01);
  EXPECT_DOUBLE_EQ(site.paths.slew_hold, 0.02);
  EXPECT_DOUBLE_EQ(site.paths.hoist_swing_radius, 0.025);
  EXPECT_EQ(find_crane(site, "tc3"), 2);
  EXPECT_EQ(find_crane(site, "tc9"), -1);
  // The jibs overlap in plan view (bases 2 m apart, each reaching 1.4 m + its radius).
  EXPECT_LT(std::hypot(site.cranes[0].base[0] - site.cranes[1].base[0], site.cranes[0].base[1] - site.cranes[1].base[1]),
            site.cranes[0].jib_length + site.cranes[1].jib_length);
}

TEST(SiteLayout, BadFilesAreRefusedNamingFieldValueAndBound) {
  EXPECT_EQ(refusal(shipped_text()), "");
  EXPECT_EQ(refusal(edited("jib_length: 1.4", "jib_length: 0")),
            "site.yaml: site.cranes[0].jib_length = 0 is out of range: must be in [0.1, 200]");
  EXPECT_EQ(refusal(edited("stop: 0.05", "stop: 0.2")),
            "site.yaml: site.margins.slow_down = 0.15 is out of range: must be > margins.stop = 0.2");
  EXPECT_EQ(refusal(edited("name: tc2", "name: tc1")), "site.yaml: site.cranes[1] (tc1).name is used by an earlier crane");
  EXPECT_EQ(refusal(edited("domain_id: 12", "domain_id: 11")),
            "site.yaml: site.cranes[1] (tc2).domain_id is used by the site (site.domain_id) or an earlier crane");
  EXPECT_EQ(refusal(edited("domain_id: 10 ", "domain_id: 13 ")),
            "site.yaml: site.cranes[2] (tc3).domain_id is used by the site (site.domain_id) or an earlier crane");
  EXPECT_EQ(refusal(edited("trolley_max: 1.30", "trolley_max: 1.50")),
            "site.yaml: site.cranes[0] (tc1).trolley_max = 1.5 is out of range: must be in [0, 1.4]");
  EXPECT_EQ(refusal(edited("hook_height_max: 2.3", "hook_height_max: 2.48")),
            "site.yaml: site.cranes[0] (tc1).hook_height_max = 2.48 is out of range: must be in [0.5, 2.45]");
  EXPECT_EQ(refusal(edited("travel_swing: 0.6", "travel_swing: 2")),
            "site.yaml: site.paths.travel_swing = 2 is out of range: must be in [0, 1.5]");
  EXPECT_EQ(refusal(edited("slew_hold: 0.02", "slew_hold: -0.02")),
            "site.yaml: site.paths.slew_hold = -0.02 is out of range: must be in [0, 10]");
  EXPECT_EQ(refusal(edited("hoist_swing_radius: 0.025", "hoist_swing_radius: -1")),
            "site.yaml: site.paths.hoist_swing_radius = -1 is out of range: must be in [0, 10]");
  // A site file of before session 34 gave the hoist's swing as an angle: refused, not misread as metres.
  EXPECT_EQ(refusal(edited("hoist_swing_radius: 0.025", "hoist_swing: 0.05")),
            "site.yaml: missing field site.paths.hoist_swing_radius");
  EXPECT_EQ(refusal(edited("max_wait: 20", "max_wait: -1")),
            "site.yaml: site.max_wait = -1 is out of range: must be in [0, 3600]");
  EXPECT_EQ(refusal(edited("part_of_leg: true", "part_of_leg: often")),
            "site.yaml: site.part_of_leg = 'often' is not a boolean (true or false)");
  EXPECT_EQ(refusal(edited("part_of_leg: true", "part_of_leg_: true")), "site.yaml: missing field site.part_of_leg");
  EXPECT_EQ(refusal(edited("most_work_left_first: true", "most_work_left_first: 1.5")),
            "site.yaml: site.most_work_left_first = '1.5' is not a boolean (true or false)");
  EXPECT_EQ(refusal(edited("most_work_left_first: true", "most_work_left_first_: true")),
            "site.yaml: missing field site.most_work_left_first");
  EXPECT_EQ(refusal(edited("travel_step: 0.5", "travel_step: -0.1")),
            "site.yaml: site.travel_step = -0.1 is out of range: must be in [0, 10]");
  EXPECT_EQ(refusal(edited("travel_step: 0.5", "travel_step_: 0.5")), "site.yaml: missing field site.travel_step");
  EXPECT_EQ(refusal(edited("slew_max: 3.0", "slew_max: -3.5")),
            "site.yaml: site.cranes[0] (tc1).slew_min = -3 is out of range: must be < slew_max = -3.5");
  EXPECT_EQ(refusal(edited("kind: tower", "kind: gantry")),
            "site.yaml: site.cranes[0].kind = 'gantry' is not one of: tower");
  EXPECT_EQ(refusal(edited("priority: 0", "priority: 0\n      colour: red")),
            "site.yaml: unknown field site.cranes[0].colour");
  EXPECT_EQ(refusal(edited("link_deadline: 0.3", "link_deadline: [0.3")).rfind("site.yaml: YAML syntax error at line", 0),
            0u);
  EXPECT_EQ(refusal(edited("bottom: 0.0", "bottom: 2.0")).rfind("site.yaml: site.zones[0] (site office)", 0), 0u)
      << refusal(edited("bottom: 0.0", "bottom: 2.0"));
  // What the site says of a crane against its own config (lab_tower_crane.yaml: the planner's trolley
  // 0.2-1.1 m, slew +-3.0 rad, cable 0.2-2.0 m under tc1's jib at 2.5 m: hooks 0.5-2.3 m; its soft
  // stops at 0.9929 m/s^2, 2.0796 rad/s^2 and 0.5 m/s^2): a site that holds less than the crane's
  // reach, or models its stop quicker than the planner makes it, is refused.
  const std::string reach = " (lab_tower_crane.yaml): the site would not hold all of the crane's reach";
  const std::string stop =
      " (lab_tower_crane.yaml): the site would predict the crane's soft stop shorter than the planner makes it";
  const struct {
    const char *pattern, *replacement;
    std::string message;  // after "site.yaml: site.cranes[0] (tc1)."
  } short_of_the_config[] = {
      {"trolley_max: 1.30", "trolley_max: 1.05",
       "trolley_max = 1.05 is below the crane's config trajectory_planner.trolley_max_position = 1.1" + reach},
      {"trolley_min: 0.05", "trolley_min: 0.25",
       "trolley_min = 0.25 is above the crane's config trajectory_planner.trolley_min_position = 0.2" + reach},
      {"slew_min: -3.0", "slew_min: -2.9",
       "slew_min = -2.9 is above the crane's config trajectory_planner.slew_min_angle = -3" + reach},
      {"slew_max: 3.0", "slew_max: 2.9", "slew_max = 2.9 is below the crane's config trajectory_planner.slew_max_angle = 3" + reach},
      {"hook_height_min: 0.5 ", "hook_height_min: 0.6 ",
       "hook_height_min = 0.6 is above jib_height less the crane's config crane.max_cable_length = 2" + reach},
      {"hook_height_max: 2.3", "hook_height_max: 2.2",
       "hook_height_max = 2.2 is below jib_height less the crane's config crane.min_cable_length = 0.2" + reach},
      // A raised jib raises the hook's whole range: its highest is then 2.4 m, above the site's 2.3 m.
      {"jib_height: 2.5", "jib_height: 2.6",
       "hook_height_max = 2.3 is below jib_height less the crane's config crane.min_cable_length = 0.2" + reach},
      {"trolley_deceleration: 0.99", "trolley_deceleration: 1.2",
       "stopping.trolley_deceleration = 1.2 is above the crane's config trajectory_planner.manual.trolley_acceleration "
       "= 0.9929" + stop},
      {"slew_deceleration: 2.0", "slew_deceleration: 2.5",
       "stopping.slew_deceleration = 2.5 is above the crane's config trajectory_planner.manual.slew_acceleration = "
       "2.0796" + stop},
      {"hoist_deceleration: 0.5", "hoist_deceleration: 0.6",
       "stopping.hoist_deceleration = 0.6 is above the crane's config trajectory_planner.manual.hoist_acceleration = "
       "0.5" + stop},
  };
  for (const auto& c : short_of_the_config) {
    EXPECT_EQ(refusal(edited(c.pattern, c.replacement)), "site.yaml: site.cranes[0] (tc1)." + c.message);
  }
  // The crane's own config: missing, not a stack config, or a stack config whose planner block the
  // planner's own reader refuses (its message passed on).
  const std::string missing = refusal(edited("config: lab_tower_crane.yaml", "config: no_such_crane.yaml"));
  EXPECT_EQ(missing.rfind("site.yaml: site.cranes[0].config = \"no_such_crane.yaml\": the crane's config: ", 0), 0u)
      << missing;
  EXPECT_NE(missing.find("no_such_crane.yaml: cannot be read"), std::string::npos) << missing;
  EXPECT_EQ(refusal(edited("config: lab_tower_crane.yaml", "config: site_three_towers.yaml")),
            "site.yaml: site.cranes[0].config = \"site_three_towers.yaml\": the crane's config: "
            "site_three_towers.yaml: missing field crane");
  const fs::path dir = fs::temp_directory_path() / ("crane_site_layout_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  {
    std::ifstream in(fs::path(kSitePath).parent_path() / "lab_tower_crane.yaml");
    std::stringstream text;
    text << in.rdbuf();
    const std::string damped = std::regex_replace(text.str(), std::regex("swing_damping_ratio: 0.0"),
                                                  "swing_damping_ratio: 0.5", std::regex_constants::format_first_only);
    std::ofstream(dir / "lab_tower_crane.yaml") << damped;
  }
  std::string damped_refusal;
  try {
    (void)parse_site_layout(shipped_text(), "site.yaml", dir);
  } catch (const ConfigError& error) {
    damped_refusal = error.what();
  }
  fs::remove_all(dir);
  EXPECT_EQ(damped_refusal, "site.yaml: site.cranes[0].config = \"lab_tower_crane.yaml\": the crane's config: "
                            "lab_tower_crane.yaml: trajectory_planner.manual.swing_damping_ratio = 0.5 is out of range: "
                            "must be in [0, 0.3]");
}

// tc2 moved to 1.5 m from tc1: its jib (1.4 m, radius 0.05) reaches tc1's mast (radius 0.0566) with
// the stop margin 0.05 (reach 1.5566 m > 1.5 m), and it is higher, so it must pass above tc1's
// highest part: 2.5 + 0.04 + 0.05 = 2.59 m plus the margin, 2.64 m, against its own jib's lowest
// point 3.0 + 0.04 - 0.05 = 2.99 m: accepted. Lowered to 2.6 m (lowest point 2.59 m) it is refused.
// And tc1's jib reaches tc2's mast too and is the lower: refused whatever tc2's height.
TEST(SiteLayout, AJibThatReachesAnotherMastMustPassAboveThatCrane) {
  SiteLayout site = load_site_layout(kSitePath);
  site.cranes[1].base = {1.5, 0.0};
  site.cranes[0].jib_length = 1.35;  // tc1's own jib: 1.35 + 0.05 + 0.0566 + 0.05 = 1.5066 > 1.5 still reaches
  site.cranes[0].trolley_max = 1.3;
  try {
    validate(site);
    FAIL() << "tc1's jib reaches tc2's mast from below";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()).rfind("site.cranes[0] (tc1).jib_height = 2.5: its jib reaches tc2's mast", 0), 0u)
        << error.what();
  }
  site.cranes[0].jib_length = 1.32;  // 1.32 + 0.05 + 0.0566 + 0.05 = 1.4766 < 1.5: tc1 no longer reaches
  site.cranes[0].trolley_max = 1.3;
  EXPECT_NO_THROW(validate(site));
  EXPECT_NEAR(jib_bottom(site.cranes[1]), 2.99, 1e-12);
  EXPECT_NEAR(top_of_structure(site.cranes[0]) + site.margins.stop, 2.64, 1e-12);
  site.cranes[1].jib_height = 2.6;
  site.cranes[1].hook_height_max = 2.4;
  try {
    validate(site);
    FAIL() << "tc2's jib passes 0.05 m above tc1's top";
  } catch (const ConfigError& error) {
    EXPECT_EQ(std::string(error.what()),
              "site.cranes[1] (tc2).jib_height = 2.6: its jib reaches tc1's mast (1.5 m away, reach 1.556568542 "
              "m) and must pass above tc1 by margins.stop: its jib's lowest point 2.59 m must be >= 2.64 m");
  }
}

TEST(SiteLayout, MastsTooCloseAreRefused) {
  SiteLayout site = load_site_layout(kSitePath);
  site.cranes[1].base = {0.1, 0.0};
  site.cranes[1].jib_height = 3.6;
  EXPECT_THROW(validate(site), ConfigError);
}

}  // namespace
