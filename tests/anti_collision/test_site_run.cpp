// The simulated site (stack::run_site): the three-tower site of deploy/config with the lab crane's
// stack per crane, seeded random job sets run coordinated, serialized and solo. Every job done, no
// supervisor fault, the true distance between any two cranes' parts never below the stop margin,
// and the coordinated site faster than the serializing baseline over the sets; a site of one crane
// runs as that crane alone.
#include <gtest/gtest.h>

#include <string>

#include "crane/anti_collision/site_file.hpp"
#include "crane/stack/site_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace {

using namespace crane::stack;

const std::string kSource = CRANE_SOURCE_DIR;

TEST(SiteRun, SeededJobSetsKeepTheStopMarginAndBeatTheSerializedBaseline) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_stack_config(kSource + "/deploy/config/lab_tower_crane.yaml");
  double coordinated_total = 0.0;
  double serialized_total = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const auto jobs = random_site_jobs(site, config, 2, seed);
    const SiteOutcome coordinated = run_site(site, config, jobs, {SiteMode::coordinated});
    const SiteOutcome serialized = run_site(site, config, jobs, {SiteMode::serialized});
    for (const SiteOutcome* o : {&coordinated, &serialized}) {
      EXPECT_TRUE(o->completed) << "seed " << seed;
      EXPECT_EQ(o->unresolved, 0u) << "seed " << seed;
      EXPECT_GE(o->min_distance, site.margins.stop) << "seed " << seed << ": " << o->closest;
      for (const CraneOutcome& c : o->cranes) {
        EXPECT_EQ(c.jobs_done, 2) << c.name << ", seed " << seed;
        EXPECT_EQ(c.latched_faults, 0u) << c.name << ", seed " << seed;
      }
    }
    coordinated_total += coordinated.total_time;
    serialized_total += serialized.total_time;
  }
  EXPECT_LT(coordinated_total, serialized_total);
}

TEST(SiteRun, ASiteOfOneCraneRunsAsThatCraneAlone) {
  auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  site.cranes.resize(1);
  const StackConfig config = load_stack_config(kSource + "/deploy/config/lab_tower_crane.yaml");
  const auto jobs = random_site_jobs(site, config, 2, 7);
  const SiteOutcome on_site = run_site(site, config, jobs, {SiteMode::coordinated});
  const SiteOutcome alone = run_site(site, config, jobs, {SiteMode::solo});
  ASSERT_EQ(on_site.cranes.size(), 1u);
  EXPECT_EQ(on_site.cranes[0].jobs_done, 2);
  EXPECT_EQ(on_site.cranes[0].waiting_time, 0.0);
  EXPECT_EQ(on_site.cranes[0].yields, 0);
  EXPECT_EQ(on_site.total_time, alone.total_time);
}

TEST(SiteRun, JobListsMustMatchTheCranes) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_stack_config(kSource + "/deploy/config/lab_tower_crane.yaml");
  EXPECT_THROW((void)run_site(site, config, {{}}, {}), std::invalid_argument);
}

}  // namespace
