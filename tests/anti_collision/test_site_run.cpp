// The simulated site (stack::run_site): the three-tower site of deploy/config with the lab crane's
// stack per crane, seeded random job sets run coordinated, serialized and solo. Every job done, no
// supervisor fault, the true distance between any two cranes' parts never below the stop margin,
// and the coordinated site faster than the serializing baseline over the sets; lost links and a
// restarted site service; a crane that leaves its grant braked by its own guard; a site of one
// crane runs as that crane alone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <string>
#include <vector>

#include "crane/anti_collision/site_file.hpp"
#include "crane/stack/site_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace {

using namespace crane::stack;

SiteRunOptions in_mode(SiteMode mode) {
  SiteRunOptions options;
  options.mode = mode;
  return options;
}

const std::string kSource = CRANE_SOURCE_DIR;

// Coordinated, with seed's 2 lost links and 3 degraded links (as `crane_site demo --faults 2
// --degraded 3`).
SiteRunOptions with_network_faults(const crane::anti_collision::SiteLayout& site, std::uint64_t seed) {
  SiteRunOptions options = in_mode(SiteMode::coordinated);
  options.faults = random_link_faults(site, 2, seed);
  const auto slow = random_degraded_links(site, 3, seed);
  options.faults.insert(options.faults.end(), slow.begin(), slow.end());
  options.loss_seed = seed;
  return options;
}

TEST(SiteRun, SeededJobSetsKeepTheStopMarginAndBeatTheSerializedBaseline) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  double coordinated_total = 0.0;
  double serialized_total = 0.0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const auto jobs = random_site_jobs(site, config, 2, seed);
    const SiteOutcome coordinated = run_site(site, config, jobs, in_mode(SiteMode::coordinated));
    const SiteOutcome serialized = run_site(site, config, jobs, in_mode(SiteMode::serialized));
    for (const SiteOutcome* o : {&coordinated, &serialized}) {
      EXPECT_TRUE(o->completed) << "seed " << seed;
      EXPECT_EQ(o->unresolved, 0u) << "seed " << seed;
      EXPECT_GE(o->min_distance, site.margins.stop) << "seed " << seed << ": " << o->closest;
      // Healthy cranes keep to their grants, swing included: no guard braked one (rules 1-3), and
      // none saw its load swing wider than the box allows (rule 5: the travel's swing, and the
      // hoist's swing radius where only the hoist moves; docs/site.md, "The swing while hoisting").
      EXPECT_EQ(o->guard_emergency_stops, 0) << "seed " << seed << ": " << o->guard_first;
      EXPECT_EQ(o->guard_soft_stops, 0) << "seed " << seed << ": " << o->guard_first;
      double waiting = 0.0;
      for (const CraneOutcome& c : o->cranes) {
        EXPECT_EQ(c.jobs_done, 2) << c.name << ", seed " << seed;
        EXPECT_EQ(c.latched_faults, 0u) << c.name << ", seed " << seed;
        waiting += c.waiting_time;
      }
      // Where the waits go, counted cycle by cycle from what the service had each crane wait
      // for, adds up to the waiting each crane's link timed from its ask to its go.
      double counted = o->waited_for_none;
      for (const double w : o->waited_for) {
        EXPECT_GE(w, 0.0);
        counted += w;
      }
      EXPECT_NEAR(counted, waiting, 1e-9 * waiting + 1e-9) << "seed " << seed;
      // And by why the service had them wait (SiteArbiter::wait_reason): the same sum, part of it
      // for what other cranes hold.
      const double why = std::accumulate(o->waited_why.begin(), o->waited_why.end(), 0.0);
      EXPECT_NEAR(why, waiting, 1e-9 * waiting + 1e-9) << "seed " << seed;
      EXPECT_GT(o->waited_why[static_cast<std::size_t>(crane::anti_collision::WaitReason::held)], 0.0) << "seed " << seed;
      EXPECT_GT(waiting, 0.0) << "seed " << seed << ": the jobs force conflicts";
    }
    coordinated_total += coordinated.total_time;
    serialized_total += serialized.total_time;
  }
  EXPECT_LT(coordinated_total, serialized_total);
}

// The bound of any order of grants (schedule_bound.hpp) from the solo runs' timelines: each
// crane's timeline ends where its last job was done (to a cycle), every pair's bound lies between
// the longer of the two alone and both one after the other, waiting only at rest never beats
// waiting anywhere, and the site's order (the coordinated run) is no faster than either. Seeds
// 1-2: the conflicts the jobs force cost time even in the best order.
TEST(SiteRun, TheBoundOfAnyOrderOfGrantsLiesBetweenTheCranesAloneAndTheSite) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  const double dt = config.facts.sample_period;
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    const auto jobs = random_site_jobs(site, config, 2, seed);
    const SiteOutcome solo = run_site(site, config, jobs, in_mode(SiteMode::solo));
    const SiteOutcome coordinated = run_site(site, config, jobs, in_mode(SiteMode::coordinated));
    ASSERT_TRUE(solo.completed && coordinated.completed);
    std::int64_t longest = 0;
    for (const CraneOutcome& c : solo.cranes) {
      ASSERT_FALSE(c.timeline.steps.empty()) << c.name;
      EXPECT_NEAR(static_cast<double>(c.timeline.cycles()) * dt, c.finish_time, 2.0 * dt) << c.name;
      for (const auto& step : c.timeline.steps) EXPECT_GE(step.uses.count, 1u);
      longest = std::max(longest, c.timeline.cycles());
    }
    std::int64_t site_bound = 0;
    for (std::size_t i = 0; i < site.cranes.size(); ++i) {
      for (std::size_t j = i + 1; j < site.cranes.size(); ++j) {
        const auto& a = solo.cranes[i].timeline;
        const auto& b = solo.cranes[j].timeline;
        const std::int64_t pair = crane::anti_collision::two_crane_bound(site, i, a, j, b);
        EXPECT_GE(pair, std::max(a.cycles(), b.cycles()));
        EXPECT_LE(pair, a.cycles() + b.cycles());
        EXPECT_EQ(crane::anti_collision::two_crane_bound(site, j, b, i, a), pair) << "the same plane, turned";
        // Waiting only at rest between legs (the site's whole legs): never shorter.
        const std::int64_t at_rest =
            crane::anti_collision::two_crane_bound(site, i, a, j, b, crane::anti_collision::WaitRule::at_rest);
        ASSERT_GE(at_rest, pair) << "seed " << seed;
        EXPECT_GE(coordinated.total_time, static_cast<double>(at_rest) * dt) << "seed " << seed;
        site_bound = std::max(site_bound, pair);
      }
    }
    EXPECT_GT(site_bound, longest) << "seed " << seed << ": the jobs' conflicts cost time in any order";
    EXPECT_GE(coordinated.total_time, static_cast<double>(site_bound) * dt) << "seed " << seed;
    std::printf("seed %llu: alone %.2f s, the bound of any order %.2f s, the site %.2f s\n",
                static_cast<unsigned long long>(seed), static_cast<double>(longest) * dt,
                static_cast<double>(site_bound) * dt, coordinated.total_time);
  }
}

// The job draw: with SiteJobDraw{1, true} every point lies within another crane's reach, with
// {0, true} every point is clear of the other cranes' jibs, each checked here from the site file's
// bases, jibs and margins and the planner's travel (as site_run.hpp defines them); the default draw
// is unchanged by the option (the same points as {0.7, false}) and puts about 0.7 of the points in
// another's reach.
TEST(SiteRun, TheJobDrawPlacesPointsWithinOrOutsideTheOtherCranesReachAsAsked) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  const double r_low = config.trajectory_planner.trolley_min_position + 0.1;
  const double r_high = config.trajectory_planner.trolley_max_position - 0.05;
  const auto share_in_other = [&](const std::vector<std::vector<SiteJob>>& jobs, bool under_jib = false) {
    int in_other = 0, points = 0;
    for (std::size_t i = 0; i < jobs.size(); ++i) {
      const auto& c = site.cranes[i];
      for (const SiteJob& job : jobs[i]) {
        for (const WorkPoint& w : {job.pick, job.place}) {
          const double heading = c.slew_zero_heading + w.slew;
          const double x = c.base[0] + w.trolley * std::cos(heading);
          const double y = c.base[1] + w.trolley * std::sin(heading);
          bool inside = false;
          for (std::size_t j = 0; j < site.cranes.size(); ++j) {
            const double d = std::hypot(x - site.cranes[j].base[0], y - site.cranes[j].base[1]);
            const auto& o = site.cranes[j];
            const double jib_circle = std::max(o.jib_length, o.counter_jib_length) + site.margins.slow_down;
            inside = inside || (j != i && (under_jib ? d <= jib_circle : d > r_low && d < r_high));
          }
          in_other += inside ? 1 : 0;
          ++points;
        }
      }
    }
    return static_cast<double>(in_other) / points;
  };
  for (std::uint64_t seed = 1; seed <= 20; ++seed) {
    EXPECT_EQ(share_in_other(random_site_jobs(site, config, 5, seed, SiteJobDraw{1.0, true})), 1.0) << seed;
    EXPECT_EQ(share_in_other(random_site_jobs(site, config, 5, seed, SiteJobDraw{0.0, true}), true), 0.0) << seed;
    const auto by_default = random_site_jobs(site, config, 5, seed);
    const auto explicit_default = random_site_jobs(site, config, 5, seed, SiteJobDraw{0.7, false});
    for (std::size_t i = 0; i < by_default.size(); ++i) {
      for (std::size_t j = 0; j < by_default[i].size(); ++j) {
        EXPECT_EQ(by_default[i][j].pick.slew, explicit_default[i][j].pick.slew);
        EXPECT_EQ(by_default[i][j].place.trolley, explicit_default[i][j].place.trolley);
      }
    }
  }
  // By default 0.7 of the points are drawn within another's reach, and a few of the others fall
  // there by chance: over 3000 points the share lies within a few standard deviations (0.008) of that.
  double share = 0.0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) share += share_in_other(random_site_jobs(site, config, 5, seed)) / 100;
  std::printf("default draw: %.3f of the points within another crane's reach\n", share);
  EXPECT_GT(share, 0.67);
  EXPECT_LT(share, 0.85);
  EXPECT_THROW((void)random_site_jobs(site, config, 1, 1, SiteJobDraw{1.5, true}), std::invalid_argument);
  EXPECT_THROW((void)random_site_jobs(site, config, 1, 1, SiteJobDraw{std::nan(""), false}), std::invalid_argument);
}

// Link faults: each crane's link lost in turn for 5 s while the site works, then the site service
// killed and restarted after 3 s (every link down, its memory lost). Every job is still done, the
// stop margin kept, and each crane whose link was lost past the deadline is safe within the
// deadline plus its soft stop: at most a stop from the rated slew rate at the planned
// deceleration (1.04 rad/s at 1.0 rad/s^2: 1.04 s), the ZV shaper's half period at the longest
// cable (2 m: 1.42 s) and one swing period of the drives' settling (2.84 s), 5.6 s in all.
TEST(SiteRun, LostLinksAndARestartedSiteServiceKeepTheMarginAndStopInBoundedTime) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  const auto jobs = random_site_jobs(site, config, 2, 11);
  SiteRunOptions options;
  options.faults = {{0, 10.0, 5.0}, {1, 25.0, 5.0}, {2, 40.0, 5.0}, {kSiteService, 60.0, 3.0}};
  const SiteOutcome o = run_site(site, config, jobs, options);
  EXPECT_TRUE(o.completed);
  EXPECT_GE(o.min_distance, site.margins.stop) << o.closest;
  EXPECT_EQ(o.unresolved, 0u);
  for (const CraneOutcome& c : o.cranes) {
    EXPECT_EQ(c.jobs_done, 2) << c.name;
    EXPECT_EQ(c.latched_faults, 0u) << c.name;
  }
  // Three crane links and the service's three: six losses past the deadline.
  ASSERT_EQ(o.reactions.size(), 6u);
  for (const double r : o.reactions) {
    EXPECT_GE(r, site.link_deadline - 1e-9);
    EXPECT_LE(r, site.link_deadline + 5.6);
  }
}

// A crane that disobeys: 40 s into the run, while it waits at rest for its next leg (it asks from
// 32.6 s to 100 s in this set), tc1 is told to slew to 2.0 rad without asking. Its own
// guard brakes it once its emergency stop would end outside its grant, well before it reaches
// another crane: the true distance keeps the stop margin. The same jobs with no rogue brake no
// crane (the guard's containment does not stop healthy cranes).
TEST(SiteRun, ACraneThatLeavesItsGrantIsBrakedByItsOwnGuard) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  const auto jobs = random_site_jobs(site, config, 2, 11);
  SiteRunOptions options;
  options.time_limit = 120.0;
  const SiteOutcome healthy = run_site(site, config, jobs, options);
  EXPECT_EQ(healthy.guard_emergency_stops, 0) << healthy.guard_first;
  options.rogue = SiteRunOptions::Rogue{0, 40.0, {2.0, 1.0, 0.2}};
  const SiteOutcome o = run_site(site, config, jobs, options);
  EXPECT_EQ(o.guard_emergency_stops, 1) << o.guard_first;
  ASSERT_TRUE(std::isfinite(o.cranes[0].braked_at)) << o.guard_first;
  EXPECT_GE(o.cranes[0].braked_at, 40.0);
  EXPECT_LT(o.cranes[0].braked_at, 42.0);
  EXPECT_NE(o.cranes[0].latched_faults & crane::protocol::SupervisorStatus::FAULT_EMERGENCY_STOP, 0u);
  EXPECT_FALSE(o.completed);
  EXPECT_GE(o.min_distance, site.margins.stop) << o.closest;
  std::printf("rogue tc1 braked by its guard at %.2f s (%s); min distance %.3f m (%s)\n", o.cranes[0].braked_at,
              o.guard_first.c_str(), o.min_distance, o.closest.c_str());
}

// Every crane's plant 10 % less friction than its stack assumes (SiteRunOptions::plant_mismatch,
// `crane_site demo --plant-mismatch 1 1 0.9`): with the configured friction (3.5) the compensation
// overcompensates and the default controller's hold (delay1) limit-cycles with the load swinging,
// every run stopped (docs/site.md, "Plants off their configuration"). Whatever the control does,
// the site keeps its stop margin: the guards brake a crane whose swing leaves its grant, and its
// supervisor latches what it sees. The mismatch reaches the plants: the same jobs end otherwise than
// on the nominal plants. With the friction factor the PD law estimates along each move (on in the
// shipped configuration, tracking.estimate_friction_factor) the jobs are done, no crane faulted.
TEST(SiteRun, PlantsOffTheirConfigurationStillKeepTheStopMargin) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  const auto jobs = random_site_jobs(site, config, 2, 1);
  SiteRunOptions options;
  options.time_limit = 300.0;
  const SiteOutcome nominal = run_site(site, config, jobs, options);
  options.plant_mismatch.friction_factor = 0.9;
  const SiteOutcome off = run_site(site, config, jobs, options);
  EXPECT_TRUE(nominal.completed);
  EXPECT_GE(nominal.min_distance, site.margins.stop) << nominal.closest;
  EXPECT_GE(off.min_distance, site.margins.stop) << off.closest;
  int nominal_unsettled = 0, off_unsettled = 0, faulted = 0, braked = 0;
  for (const auto& c : nominal.cranes) nominal_unsettled += c.unsettled_moves;
  for (const auto& c : off.cranes) {
    off_unsettled += c.unsettled_moves;
    faulted += c.latched_faults != 0 ? 1 : 0;
    braked += std::isfinite(c.braked_at) ? 1 : 0;
  }
  EXPECT_TRUE(off.completed != nominal.completed || off.total_time != nominal.total_time ||
              off_unsettled != nominal_unsettled)
      << "the plants' friction changed nothing: the mismatch did not reach them";
  ASSERT_TRUE(config.tracking.estimate_friction_factor) << "on in the shipped configuration";
  EXPECT_TRUE(off.completed) << off.guard_first;
  EXPECT_EQ(faulted, 0) << off.guard_first;
  EXPECT_EQ(braked, 0) << off.guard_first;
  std::printf("nominal plants: completed %d, %.1f s, %d moves unsettled, min distance %.3f m; friction x0.9: completed "
              "%d, %.1f s, %d moves unsettled, %d cranes faulted, %d braked by their guard (%s), min distance %.3f m "
              "(%s)\n",
              nominal.completed ? 1 : 0, nominal.total_time, nominal_unsettled, nominal.min_distance, off.completed ? 1 : 0,
              off.total_time, off_unsettled, faulted, braked, off.guard_first.c_str(), off.min_distance, off.closest.c_str());
}

TEST(SiteRun, ASiteOfOneCraneRunsAsThatCraneAlone) {
  auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  site.cranes.resize(1);
  const StackConfig config = load_site_crane_config(site);
  const auto jobs = random_site_jobs(site, config, 2, 7);
  const SiteOutcome on_site = run_site(site, config, jobs, in_mode(SiteMode::coordinated));
  const SiteOutcome alone = run_site(site, config, jobs, in_mode(SiteMode::solo));
  ASSERT_EQ(on_site.cranes.size(), 1u);
  EXPECT_EQ(on_site.cranes[0].jobs_done, 2);
  // Alone, each leg waits one cycle for its grant: the crane asks at cycle k, its report reaches
  // the service and the go comes back at k + 1 (the messages pass once a cycle, as over DDS).
  EXPECT_NEAR(on_site.cranes[0].waiting_time, 4 * config.facts.sample_period, 1e-9);
  EXPECT_EQ(on_site.cranes[0].yields, 0);
  EXPECT_EQ(on_site.total_time, alone.total_time);
}

// A degraded link (LinkFault::delay, loss): alone on the site, each leg's report reaches the
// service one delay late and the go comes back one delay later, so each of the 4 legs waits one
// cycle plus two delays (by hand: 0.01 + 2 x 0.2 s); with every message lost once, each way costs
// one kResendDelay more. Nothing else changes: the same jobs done, and the messages counted.
TEST(SiteRun, ADegradedLinkDelaysEachGrantByTheDelayBothWays) {
  auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  site.cranes.resize(1);
  const StackConfig config = load_site_crane_config(site);
  const double dt = config.facts.sample_period;
  const auto jobs = random_site_jobs(site, config, 2, 7);
  SiteRunOptions delayed = in_mode(SiteMode::coordinated);
  delayed.faults = {LinkFault{0, 0.0, 1e4, 0.2, 0.0}};
  const SiteOutcome late = run_site(site, config, jobs, delayed);
  ASSERT_TRUE(late.completed);
  EXPECT_EQ(late.cranes[0].jobs_done, 2);
  EXPECT_NEAR(late.cranes[0].waiting_time, 4 * (dt + 2 * 0.2), 1e-6);
  EXPECT_GT(late.delayed_messages, 0u);
  EXPECT_EQ(late.resent_messages, 0u);

  SiteRunOptions lossy = delayed;
  lossy.faults[0].loss = 1.0;
  const SiteOutcome resent = run_site(site, config, jobs, lossy);
  ASSERT_TRUE(resent.completed);
  EXPECT_NEAR(resent.cranes[0].waiting_time, 4 * (dt + 2 * (0.2 + kResendDelay)), 1e-6);
  EXPECT_EQ(resent.resent_messages, resent.delayed_messages);

  // The service's host degraded delays the one crane's link the same way.
  SiteRunOptions service_host = delayed;
  service_host.faults[0].crane = kSiteService;
  EXPECT_NEAR(run_site(site, config, jobs, service_host).cranes[0].waiting_time, 4 * (dt + 2 * 0.2), 1e-6);

  SiteRunOptions bad = delayed;
  bad.faults[0].loss = 1.5;
  EXPECT_THROW((void)run_site(site, config, jobs, bad), std::invalid_argument);
  bad.faults[0] = LinkFault{0, 0.0, 1.0, std::nan(""), 0.0};
  EXPECT_THROW((void)run_site(site, config, jobs, bad), std::invalid_argument);
}

// The degraded link's rule by hand, the order kept: a message sent as a degradation ends, or as
// its delay shrinks, does not overtake one sent before it.
TEST(SiteRun, ADegradedLinkDeliversInTheOrderSent) {
  const LinkFault slow{0, 0.0, 10.0, 0.2, 0.3};
  const double none = -std::numeric_limits<double>::infinity();
  EXPECT_DOUBLE_EQ(arrival_time(1.0, nullptr, false, none), 1.0);
  EXPECT_DOUBLE_EQ(arrival_time(1.0, &slow, false, none), 1.2);
  EXPECT_DOUBLE_EQ(arrival_time(1.0, &slow, true, none), 1.2 + kResendDelay);
  // Sent at 1.01 s after a message lost at 1.0 s (due 1.3 s): it waits behind it.
  EXPECT_DOUBLE_EQ(arrival_time(1.01, &slow, false, 1.3), 1.3);
  // The degradation over at 1.02 s: still behind the messages on their way.
  EXPECT_DOUBLE_EQ(arrival_time(1.02, nullptr, false, 1.3), 1.3);
  EXPECT_DOUBLE_EQ(arrival_time(1.5, nullptr, false, 1.3), 1.5);
  const LinkFault lost_link{0, 0.0, 10.0, 0.0, 0.0};  // not degraded: a lost link, handled apart
  EXPECT_DOUBLE_EQ(arrival_time(1.0, &lost_link, true, none), 1.0);
}

// The three-tower site with degraded links and lost links together (seeded, as `crane_site demo
// --faults 2 --degraded 3`): every job done, the stop margin kept, no crane braked by its guard.
TEST(SiteRun, DegradedAndLostLinksTogetherKeepTheStopMargin) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SiteRunOptions options = with_network_faults(site, seed);
    const auto slow = random_degraded_links(site, 3, seed);
    for (const LinkFault& f : slow) {
      EXPECT_TRUE(f.degraded());
      EXPECT_LE(f.delay, 0.2);
      EXPECT_LE(f.loss, 0.3);
      EXPECT_GE(f.duration, 5.0);
      EXPECT_LE(f.duration, 30.0);
    }
    const SiteOutcome o = run_site(site, config, random_site_jobs(site, config, 2, seed), options);
    EXPECT_TRUE(o.completed) << "seed " << seed << ": " << o.guard_first;
    EXPECT_GE(o.min_distance, site.margins.stop) << "seed " << seed << ": " << o.closest;
    EXPECT_EQ(o.guard_emergency_stops, 0) << "seed " << seed << ": " << o.guard_first;
    EXPECT_GT(o.delayed_messages, 0u) << "seed " << seed;
    EXPECT_GT(o.resent_messages, 0u) << "seed " << seed;
    for (const CraneOutcome& c : o.cranes) EXPECT_EQ(c.jobs_done, 2) << c.name << ", seed " << seed;
  }
}

// A crane's host stopped for good (HostStop): tc1's host stops before it has reported, so the site
// service never hears from it and holds its whole reach for good. tc2, whose points all lie within
// tc1's reach, asks for its first leg and waits: it is stuck once it has waited kStuckWait for the
// stopped crane, and the run ends there, every second of the wait counted against the stopped host.
// (Points clear of tc1's jib do not help here: the whole reach holds the swing of tc1's longest
// cable, which covers most of tc2's.) tc1's plant, braked by its actuation gate, is at rest.
TEST(SiteRun, AStoppedHostsCraneHoldsItsWholeReachForGood) {
  auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  site.cranes.resize(2);
  const StackConfig config = load_site_crane_config(site);
  const double dt = config.facts.sample_period;
  SiteRunOptions options = in_mode(SiteMode::coordinated);
  options.host_stops = {HostStop{0, 0.0}};

  const auto shared = random_site_jobs(site, config, 2, 5, SiteJobDraw{1.0, true});
  const SiteOutcome o = run_site(site, config, shared, options);
  EXPECT_TRUE(o.completed);
  EXPECT_EQ(o.stopped_hosts, 1);
  EXPECT_DOUBLE_EQ(o.cranes[0].host_stopped_at, 0.0);
  EXPECT_NEAR(o.cranes[0].rest_after_host_stop, dt, 1e-9);  // it was at rest
  EXPECT_EQ(o.cranes[0].jobs_done, 0);
  EXPECT_FALSE(o.cranes[0].stuck);
  EXPECT_TRUE(o.cranes[1].stuck);
  EXPECT_EQ(o.cranes[1].jobs_done, 0);
  EXPECT_TRUE(std::isnan(o.cranes[1].host_stopped_at));
  // It asks from cycle 1 on; blocked by the stopped crane from the service's first decision.
  EXPECT_NEAR(o.waited_for_stopped_host, kStuckWait, 3 * dt);
  EXPECT_NEAR(o.simulated_seconds, 2 * (kStuckWait + 2 * dt), 3 * dt);
  EXPECT_GE(o.min_distance, site.margins.stop) << o.closest;

  // The same jobs with tc2 standing apart, out of tc1's reach: all done, no wait for tc1.
  auto apart = site;
  apart.cranes[1].base = {10.0, 0.0};
  const SiteOutcome free = run_site(apart, config, shared, options);
  EXPECT_TRUE(free.completed);
  EXPECT_EQ(free.cranes[1].jobs_done, 2);
  EXPECT_FALSE(free.cranes[1].stuck);
  EXPECT_EQ(free.waited_for_stopped_host, 0.0);

  // A stop after every job is done does not happen; solo, each crane keeps its own host stop.
  SiteRunOptions late = in_mode(SiteMode::coordinated);
  late.host_stops = {HostStop{1, 1000.0}};
  const SiteOutcome done = run_site(site, config, shared, late);
  EXPECT_EQ(done.stopped_hosts, 0);
  EXPECT_TRUE(std::isnan(done.cranes[1].host_stopped_at));
  EXPECT_EQ(done.cranes[1].jobs_done, 2);
  SiteRunOptions solo = options;
  solo.mode = SiteMode::solo;
  const SiteOutcome alone = run_site(site, config, shared, solo);
  EXPECT_DOUBLE_EQ(alone.cranes[0].host_stopped_at, 0.0);
  EXPECT_TRUE(std::isnan(alone.cranes[1].host_stopped_at));
  EXPECT_EQ(alone.cranes[1].jobs_done, 2);

  SiteRunOptions bad = options;
  bad.host_stops = {HostStop{2, 1.0}};
  EXPECT_THROW((void)run_site(site, config, shared, bad), std::invalid_argument);
  bad.host_stops = {HostStop{0, std::nan("")}};
  EXPECT_THROW((void)run_site(site, config, shared, bad), std::invalid_argument);
}

// The site operator's word (HostStop::out_of_service_after, as `crane_site_status --out-of-service`):
// tc1's host stops 0.5 s in, while tc1 waits at rest for tc2, and the operator puts it out of
// service 5 s later; the service then holds where tc1 stood instead of its whole reach, and tc2
// works on. (At 0.79 s tc1 is granted a part of its leg, to a waypoint on its travel's way: its
// host stopped after that, the service, not knowing where on that path tc1 stopped, holds the
// path, which every leg of tc2 meets.) A crane whose host stopped before
// the service ever heard it cannot be put out of service: its whole reach stays held; one whose
// host stopped while the service was down can, from the restarted service's memory.
TEST(SiteRun, AnOperatorPutsAStoppedCraneOutOfServiceAndTheOthersWorkOn) {
  auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  site.cranes.resize(2);
  // First come, so that tc1 waits at rest: with the most work left first (tc1's the most), tc2 did
  // no job in either run (seen in session 42), tc1 ranking first and holding a grant when its host
  // stopped; not this case.
  site.most_work_left_first = false;
  const StackConfig config = load_site_crane_config(site);
  const auto shared = random_site_jobs(site, config, 2, 5, SiteJobDraw{1.0, true});
  SiteRunOptions options = in_mode(SiteMode::coordinated);
  options.host_stops = {HostStop{0, 0.5}};
  const SiteOutcome held = run_site(site, config, shared, options);
  options.host_stops[0].out_of_service_after = 5.0;
  const SiteOutcome o = run_site(site, config, shared, options);
  EXPECT_TRUE(o.completed);
  EXPECT_TRUE(std::isnan(held.cranes[0].out_of_service_at));
  EXPECT_NEAR(o.cranes[0].out_of_service_at, 5.5, 1e-6);
  EXPECT_GT(o.cranes[1].jobs_done, held.cranes[1].jobs_done);
  EXPECT_GE(o.min_distance, site.margins.stop) << o.closest;
  EXPECT_GE(held.min_distance, site.margins.stop) << held.closest;
  std::printf("tc1's host stopped at 0.5 s: tc2 did %d jobs of 2 with its whole reach held, %d with tc1 out of service "
              "at %.2f s (stuck: %d); min distance %.3f m (%s)\n", held.cranes[1].jobs_done, o.cranes[1].jobs_done,
              o.cranes[0].out_of_service_at, o.cranes[1].stuck ? 1 : 0, o.min_distance, o.closest.c_str());

  options.host_stops = {HostStop{0, 0.0, 5.0}};
  const SiteOutcome never_heard = run_site(site, config, shared, options);
  EXPECT_TRUE(std::isnan(never_heard.cranes[0].out_of_service_at));
  EXPECT_TRUE(never_heard.cranes[1].stuck);
  EXPECT_EQ(never_heard.cranes[1].jobs_done, 0);

  // The service killed at 0.5 s and restarted at 2.5 s; tc1's host stops at 1 s, while it is down,
  // so the service after never hears tc1. Its memory (site_service --memory) knows where tc1 stood
  // when the service before last heard it, and the word is taken.
  options.host_stops = {HostStop{0, 1.0, 5.0}};
  options.faults = {LinkFault{kSiteService, 0.5, 2.0}};
  const SiteOutcome restarted = run_site(site, config, shared, options);
  EXPECT_TRUE(restarted.completed);
  EXPECT_NEAR(restarted.cranes[0].out_of_service_at, 6.0, 1e-6);
  EXPECT_GT(restarted.cranes[1].jobs_done, held.cranes[1].jobs_done);
  EXPECT_GE(restarted.min_distance, site.margins.stop) << restarted.closest;
  std::printf("with the service down 0.5-2.5 s: tc1 out of service at %.2f s, tc2 did %d jobs; min distance %.3f m\n",
              restarted.cranes[0].out_of_service_at, restarted.cranes[1].jobs_done, restarted.min_distance);
  options.faults.clear();

  options.host_stops = {HostStop{0, 1.0, 0.0}};
  EXPECT_THROW((void)run_site(site, config, shared, options), std::invalid_argument);
}

// A host stopped among the network faults (seeded, as `crane_site demo --faults 2 --degraded 3
// --stopped-hosts 1`): the stop margin kept, no crane braked by its guard, the stopped crane at
// rest within its brakes' time, and every other crane done or stuck waiting for its reach.
TEST(SiteRun, AStoppedHostAmongTheNetworkFaultsKeepsTheStopMargin) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    SiteRunOptions options = with_network_faults(site, seed);
    options.host_stops = random_host_stops(site, 1, seed);
    ASSERT_EQ(options.host_stops.size(), 1u);
    EXPECT_LT(options.host_stops[0].crane, site.cranes.size());
    EXPECT_GE(options.host_stops[0].time, 0.0);
    EXPECT_LE(options.host_stops[0].time, 80.0);
    const SiteOutcome o = run_site(site, config, random_site_jobs(site, config, 2, seed), options);
    EXPECT_TRUE(o.completed) << "seed " << seed << ": " << o.guard_first;
    EXPECT_GE(o.min_distance, site.margins.stop) << "seed " << seed << ": " << o.closest;
    EXPECT_EQ(o.guard_emergency_stops, 0) << "seed " << seed << ": " << o.guard_first;
    for (const CraneOutcome& c : o.cranes) {
      EXPECT_EQ(c.latched_faults, 0u) << c.name << ", seed " << seed;
      if (!std::isnan(c.host_stopped_at)) {
        EXPECT_NEAR(c.host_stopped_at, options.host_stops[0].time, 0.006) << c.name << ", seed " << seed;
        EXPECT_LE(c.rest_after_host_stop, 1.0) << c.name << ", seed " << seed;
      } else {
        EXPECT_TRUE(c.jobs_done == 2 || c.stuck) << c.name << ", seed " << seed;
      }
      std::printf("seed %llu %s: %d jobs, host stopped at %.2f s, at rest %.2f s later%s\n",
                  static_cast<unsigned long long>(seed), c.name.c_str(), c.jobs_done, c.host_stopped_at,
                  c.rest_after_host_stop, c.stuck ? ", stuck" : "");
    }
  }
}

TEST(SiteRun, JobListsMustMatchTheCranes) {
  const auto site = crane::anti_collision::load_site_layout(kSource + "/deploy/config/site_three_towers.yaml");
  const StackConfig config = load_site_crane_config(site);
  EXPECT_THROW((void)run_site(site, config, {{}}, {}), std::invalid_argument);
}

}  // namespace
