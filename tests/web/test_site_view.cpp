// The operator page's geometry (/site.json, deploy/web/site_view.hpp): the crane's kind, travel and
// no-go zones as the configuration file says, read by the stack's own readers.
#include <gtest/gtest.h>

#include <string>

#include "crane/common/validation.hpp"
#include "crane/web/site_view.hpp"

namespace {

using namespace crane;

TEST(SiteView, TheLabTowerCraneAsItsConfigurationSays) {
  const auto site = web::site_json_of_config(std::string(CRANE_CONFIG_DIR) + "/lab_tower_crane.yaml");
  EXPECT_EQ(site["source"], "lab_tower_crane.yaml");
  EXPECT_EQ(site["kind"], "tower");
  // The numbers of deploy/config/lab_tower_crane.yaml.
  EXPECT_DOUBLE_EQ(site["jib_height"].get<double>(), 2.5);
  EXPECT_DOUBLE_EQ(site["zone_clearance"].get<double>(), 0.05);
  EXPECT_DOUBLE_EQ(site["cable_length"]["min"].get<double>(), 0.2);
  EXPECT_DOUBLE_EQ(site["cable_length"]["max"].get<double>(), 2.0);
  EXPECT_DOUBLE_EQ(site["trolley"]["min"].get<double>(), 0.05);
  EXPECT_DOUBLE_EQ(site["trolley"]["max"].get<double>(), 1.30);
  EXPECT_DOUBLE_EQ(site["slew"]["min"].get<double>(), -3.3);
  EXPECT_DOUBLE_EQ(site["slew"]["max"].get<double>(), 3.3);
  EXPECT_FALSE(site.contains("bridge"));
  ASSERT_EQ(site["zones"].size(), 1U);
  const auto& desk = site["zones"][0];
  EXPECT_EQ(desk["index"], 0);
  EXPECT_EQ(desk["name"], "control desk");
  EXPECT_EQ(desk["polygon"].dump(), "[[0.45,0.45],[0.85,0.45],[0.85,0.75],[0.45,0.75]]");
  EXPECT_DOUBLE_EQ(desk["bottom"].get<double>(), 0.0);
  EXPECT_DOUBLE_EQ(desk["top"].get<double>(), 1.2);
  EXPECT_EQ(desk["enabled_at_start"], false);
}

TEST(SiteView, AnOverheadCraneHasItsBridgeAndNoSlew) {
  const auto site = web::site_json_of_config(std::string(CRANE_CONFIG_DIR) + "/overhead_crane.yaml");
  EXPECT_EQ(site["kind"], "overhead");
  EXPECT_DOUBLE_EQ(site["trolley"]["min"].get<double>(), 0.5);
  EXPECT_DOUBLE_EQ(site["trolley"]["max"].get<double>(), 19.5);
  EXPECT_DOUBLE_EQ(site["bridge"]["min"].get<double>(), 1.0);
  EXPECT_DOUBLE_EQ(site["bridge"]["max"].get<double>(), 59.0);
  EXPECT_FALSE(site.contains("slew"));
  EXPECT_TRUE(site["zones"].empty());
}

TEST(SiteView, EveryZoneWithItsIndexInTheSupervisorsMask) {
  common::StackFacts facts;
  common::Zone school{"school yard", {{2.0, -1.0}, {4.0, -1.0}, {3.0, 1.5}}, 0.0, 30.0, true};
  common::Zone road{"road", {{-5.0, 3.0}, {5.0, 3.0}, {5.0, 4.0}, {-5.0, 4.0}}, 0.0, 4.5, false};
  facts.site.zones = {school, road};
  supervisor::SupervisorParams limits;
  const auto site = web::site_json(facts, limits, "site.yaml");
  ASSERT_EQ(site["zones"].size(), 2U);
  EXPECT_EQ(site["zones"][1]["index"], 1);
  EXPECT_EQ(site["zones"][1]["name"], "road");
  EXPECT_EQ(site["zones"][1]["enabled_at_start"], false);
  EXPECT_EQ(site["zones"][0]["polygon"].dump(), "[[2.0,-1.0],[4.0,-1.0],[3.0,1.5]]");
  EXPECT_DOUBLE_EQ(site["zones"][0]["top"].get<double>(), 30.0);
  EXPECT_EQ(site["zones"][0]["enabled_at_start"], true);
}

TEST(SiteView, ABadConfigurationIsRefusedNamingTheFileAndTheField) {
  try {
    (void)web::site_json_of_config(std::string(CRANE_CONFIG_DIR) + "/no_such.yaml");
    FAIL() << "no error";
  } catch (const common::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("no_such.yaml: cannot be read"), std::string::npos) << error.what();
  }
}

}  // namespace
