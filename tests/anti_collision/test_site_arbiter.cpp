// The site service's rules (site_arbiter.hpp) and the airspace they grant (airspace.hpp): distances
// computed by hand, the priority rules, a deadlock of two cranes that wait for each other, a lost
// crane holding its whole reach, bad requests.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>
#include <random>
#include <stdexcept>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/crane_site_link.hpp"
#include "crane/anti_collision/grant_guard.hpp"
#include "crane/anti_collision/site_arbiter.hpp"
#include "crane/anti_collision/site_memory.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/anti_collision/site_service.hpp"
#include "crane/common/validation.hpp"
#include "two_towers.hpp"

namespace {

using namespace crane::anti_collision;
using crane::anti_collision::test_sites::two_towers;

constexpr double kPi = 3.14159265358979323846;
constexpr double kNow = 5.0;  // [s] the time of a decision, after every request of these tests

// A's jib along +x (its chord 2.5..2.58 m, half width 0.03) under B's load hanging at x = 1.0
// (B's slew pi, trolley 1.0), at cable 2.0 (load centre 1.0 m, bottom 0.95): in plan the load's
// disc (0.05) sits on A's jib line: plan distance 0; heights overlap: distance 0. With B's cable
// 0.2 (load 2.8 m, bottom 2.75 m) the gap is 2.75 - 2.58 = 0.17 m, straight up.
TEST(Airspace, RestPosesByHand) {
  const SiteLayout s = two_towers();
  const Airspace a = rest_airspace({0.0, 0.5, 0.2}, s.paths);
  EXPECT_NEAR(airspace_distance(s.cranes[0], a, s.cranes[1], rest_airspace({kPi, 1.0, 2.0}, s.paths)).distance, 0.0, 1e-12);
  const PairDistance up = airspace_distance(s.cranes[0], a, s.cranes[1], rest_airspace({kPi, 1.0, 0.2}, s.paths));
  EXPECT_NEAR(up.distance, 0.17, 1e-9);
  EXPECT_EQ(up.first, Part::jib);
  EXPECT_EQ(up.second, Part::cable);
  // B's load beside A's jib in plan: B's slew pi + 0.3 puts its sheave (trolley 1.0) at
  // (2 - cos 0.3, -sin 0.3) = (1.04466, -0.29552); A's jib line is y = 0 (x in [0, 1.4]): plan gap
  // 0.29552 - 0.03 - 0.05 = 0.21552, heights overlapping.
  const double d = airspace_distance(s.cranes[0], a, s.cranes[1], rest_airspace({kPi + 0.3, 1.0, 2.0}, s.paths)).distance;
  EXPECT_NEAR(d, std::sin(0.3) - 0.03 - 0.05, 1e-9);
  // Its swing allowance widens the load by its radius, 0.1 m, whatever the cable.
  SiteLayout swinging = two_towers();
  swinging.paths.hoist_swing_radius = 0.1;
  const double dswing = airspace_distance(swinging.cranes[0], rest_airspace({0.0, 0.5, 0.2}, swinging.paths),
                                          swinging.cranes[1], rest_airspace({kPi + 0.3, 1.0, 2.0}, swinging.paths))
                            .distance;
  EXPECT_NEAR(dswing, std::sin(0.3) - 0.03 - 0.05 - 0.1, 1e-9);
}

// The allowances of a box by hand: a segment in which the slew or the trolley travels gets the
// tracking allowance on either side of both intervals (and the overshoot past its goals); one in
// which neither travels (only the hoist moves) and a rest box get the hold allowance.
TEST(Airspace, TheTrackingAllowanceWhereAnAxisTravelsTheHoldAllowanceWhereNone) {
  SiteLayout s = two_towers();
  s.paths = {.trolley_overshoot = 0.07, .slew_overshoot = 0.05, .travel_swing = 0.6, .hoist_swing_radius = 0.03,
             .trolley_tracking = 0.04, .slew_tracking = 0.07, .trolley_hold = 0.01, .slew_hold = 0.02};
  // Hook up at (0.3 rad, 0.8 m), travel to (0.9 rad, 0.6 m), lower to 1.5 m of cable.
  const std::vector<Pose> path{{0.3, 0.8, 0.2}, {0.9, 0.6, 0.2}, {0.9, 0.6, 1.5}};
  const Airspace a = path_airspace(path, s.paths);
  ASSERT_EQ(a.count, 2u);
  const JointBox& travel = a.boxes[0];
  EXPECT_NEAR(travel.slew_low, 0.3 - 0.07, 1e-15);
  EXPECT_NEAR(travel.slew_high, 0.9 + 0.05 + 0.07, 1e-15);
  EXPECT_NEAR(travel.trolley_low, 0.6 - 0.07 - 0.04, 1e-15);
  EXPECT_NEAR(travel.trolley_high, 0.8 + 0.04, 1e-15);
  EXPECT_NEAR(travel.swing_radius, 0.2 * std::sin(0.6), 1e-15);
  const JointBox& lower = a.boxes[1];
  EXPECT_NEAR(lower.slew_low, 0.9 - 0.02, 1e-15);
  EXPECT_NEAR(lower.slew_high, 0.9 + 0.02, 1e-15);
  EXPECT_NEAR(lower.trolley_low, 0.6 - 0.01, 1e-15);
  EXPECT_NEAR(lower.trolley_high, 0.6 + 0.01, 1e-15);
  EXPECT_NEAR(lower.cable_high, 1.5, 1e-15);
  EXPECT_NEAR(lower.swing_radius, 0.03, 1e-15);  // a radius: the same at 1.5 m of cable as at rest hook up
  const Airspace at_rest = rest_airspace({0.9, 0.6, 1.5}, s.paths);
  const JointBox& rest = at_rest.boxes[0];
  EXPECT_NEAR(rest.slew_high - rest.slew_low, 2 * 0.02, 1e-15);
  EXPECT_NEAR(rest.trolley_high - rest.trolley_low, 2 * 0.01, 1e-15);
  EXPECT_NEAR(rest.swing_radius, 0.03, 1e-15);
  // A slew alone travels: the trolley still gets the tracking allowance (pulled outward).
  const Airspace slewing = path_airspace(std::vector<Pose>{{0.3, 0.8, 0.2}, {0.9, 0.8, 0.2}}, s.paths);
  const JointBox& slew_only = slewing.boxes[0];
  EXPECT_NEAR(slew_only.trolley_low, 0.8 - 0.04, 1e-15);
  EXPECT_NEAR(slew_only.trolley_high, 0.8 + 0.04, 1e-15);
}

// A slewing path sweeps every heading between its ends: A turning from -1 to +1 rad passes under
// B's lowered load at heading 0; the samples' padding keeps the swept jib inside the airspace at
// every heading, checked against 2000 seeded random headings of the path.
TEST(Airspace, ASlewingPathContainsEveryHeadingBetween) {
  const SiteLayout s = two_towers();
  const Pose from{-1.0, 0.5, 0.2};
  const Pose to{1.0, 0.5, 0.2};
  const Pose path[] = {from, to};
  const Airspace swept = path_airspace(path, s.paths);
  ASSERT_EQ(swept.count, 1u);
  std::mt19937_64 rng(34);
  std::uniform_real_distribution<double> heading(-1.0, 1.0);
  std::uniform_real_distribution<double> b_slew(kPi - 0.6, kPi + 0.6);
  for (int i = 0; i < 2000; ++i) {
    const Airspace at = rest_airspace({heading(rng), 0.5, 0.2}, s.paths);
    const Airspace other = rest_airspace({b_slew(rng), 1.0, 2.0}, s.paths);
    const double whole = airspace_distance(s.cranes[0], swept, s.cranes[1], other).distance;
    const double one = airspace_distance(s.cranes[0], at, s.cranes[1], other).distance;
    ASSERT_LE(whole, one + 1e-12) << "sample " << i;
  }
  EXPECT_NEAR(airspace_distance(s.cranes[0], swept, s.cranes[1], rest_airspace({kPi, 1.0, 2.0}, s.paths)).distance, 0.0,
              1e-12);
}

// A leg's stops (stops_of), by hand: the waypoints on its travel's way go, the hoists' stay; a
// travel that changes the cable, or runs at another cable length, is a run of its own.
TEST(Airspace, TheWaypointsOnATravelsWayAreNotStops) {
  const auto slews = [](const std::vector<Pose>& w) {
    std::vector<double> out;
    for (const Pose& p : stops_of(w)) out.push_back(p.slew);
    return out;
  };
  // Hook down, up, three waypoints on the travel's way, its end, lowering, up again.
  const std::vector<Pose> leg{{-1.5, 0.5, 1.0}, {-1.5, 0.5, 0.2}, {-1.0, 0.6, 0.2}, {-0.5, 0.7, 0.2},
                              {0.0, 0.8, 0.2},  {0.5, 0.9, 0.2},  {0.5, 0.9, 1.2},  {0.5, 0.9, 0.2}};
  EXPECT_EQ(slews(leg), (std::vector<double>{-1.5, -1.5, 0.5, 0.5, 0.5}));
  EXPECT_EQ(stops_of(leg)[2].trolley, 0.9);
  // A part of it up to a waypoint on the way: one move there.
  EXPECT_EQ(slews({leg.begin(), leg.begin() + 4}), (std::vector<double>{-1.5, -1.5, -0.5}));
  // A cable a hair off the travel's (within kSameCable) still travels with it; one further off does not.
  std::vector<Pose> hair = leg;
  hair[3].cable_length += 0.5 * kSameCable;
  EXPECT_EQ(stops_of(hair).size(), 5u);
  std::vector<Pose> off = leg;
  off[3].cable_length += 2.0 * kSameCable;
  EXPECT_EQ(slews(off), (std::vector<double>{-1.5, -1.5, -1.0, -0.5, 0.0, 0.5, 0.5, 0.5}));
  // Paths with no such run come back as they were: a single segment, a yield's hoist then travel.
  const std::vector<Pose> yield{{0.0, 0.5, 1.0}, {0.0, 0.5, 0.2}, {0.5236, 0.5, 0.2}};
  EXPECT_EQ(slews(yield), (std::vector<double>{0.0, 0.0, 0.5236}));
  EXPECT_TRUE(stops_of(std::vector<Pose>{}).empty());
  EXPECT_EQ(stops_of(std::vector<Pose>{leg[0]}).size(), 1u);
}

// The pruning of airspace_distance (a pair whose lower bound is not below the closest so far is
// skipped) changes nothing: over seeded random pairs of cranes (bases, heights, jibs, widths) and
// airspaces (paths of 1-5 waypoints over up to a full turn, the whole reach, allowances), the same
// distance to the bit and the same parts as every pair evaluated.
TEST(Airspace, ThePruningGivesTheSameAnswerAsEveryPair) {
  std::mt19937_64 rng(3434);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const auto in = [&](double lo, double hi) { return lo + (hi - lo) * u(rng); };
  int touching = 0;
  int apart = 0;
  for (int i = 0; i < 400; ++i) {
    SiteLayout s = two_towers(in(2.0, 4.0));
    s.paths = {.trolley_overshoot = in(0.0, 0.1), .slew_overshoot = in(0.0, 0.1), .travel_swing = in(0.0, 0.6),
               .hoist_swing_radius = in(0.0, 0.05), .trolley_tracking = in(0.0, 0.05), .slew_tracking = in(0.0, 0.05),
               .trolley_hold = in(0.0, 0.05), .slew_hold = in(0.0, 0.05)};
    for (auto& c : s.cranes) {
      c.base = {in(-2.0, 2.0), in(-2.0, 2.0)};
      c.jib_length = in(0.8, 2.0);
      c.counter_jib_length = in(0.2, 0.6);
      c.jib_width = in(0.02, 0.2);
      c.jib_depth = in(0.02, 0.2);
      c.trolley_max = c.jib_length - 0.05;
    }
    const auto airspace = [&](const SiteCrane& c) {
      if (u(rng) < 0.1) return whole_reach(c, s.paths);
      std::vector<Pose> path(1 + static_cast<std::size_t>(u(rng) * 5.0));
      for (auto& p : path) p = {in(-kPi, kPi), in(c.trolley_min, c.trolley_max), in(0.2, 2.0)};
      return path_airspace(path, s.paths);
    };
    const Airspace a = airspace(s.cranes[0]);
    const Airspace b = airspace(s.cranes[1]);
    const PairDistance pruned = airspace_distance(s.cranes[0], a, s.cranes[1], b);
    const PairDistance every = internal::airspace_distance_every_pair(s.cranes[0], a, s.cranes[1], b);
    ASSERT_EQ(pruned.distance, every.distance) << "case " << i;
    ASSERT_EQ(pruned.first, every.first) << "case " << i;
    ASSERT_EQ(pruned.second, every.second) << "case " << i;
    (every.distance == 0.0 ? touching : apart) += 1;
  }
  // Both kinds of case occur.
  EXPECT_GT(touching, 20);
  EXPECT_GT(apart, 100);
}

TEST(SiteArbiter, AClearRequestIsGrantedAndAConflictingOneWaits) {
  SiteArbiter arbiter(two_towers(), ArbiterMode::coordinated);
  arbiter.rest(0, {-1.5, 0.5, 0.2});  // A's jib away from B
  arbiter.rest(1, {kPi - 1.5, 0.5, 0.2});
  // B lowers its load at x = 1.0 on A's jib line: A's jib is turned away, so B goes.
  arbiter.request(1, {{kPi - 1.5, 0.5, 0.2}, {kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}}, 1.0);
  auto decided = arbiter.decide(kNow);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 1u);
  EXPECT_EQ(decided[0].kind, Instruction::Kind::go);
  EXPECT_EQ(arbiter.holding(1), Holding::path);
  // A now asks to turn its jib to heading 0, under B's load: it waits for B.
  arbiter.request(0, {{-1.5, 0.5, 0.2}, {0.0, 0.5, 0.2}}, 2.0);
  EXPECT_TRUE(arbiter.decide(kNow).empty());
  ASSERT_EQ(arbiter.waits_for(0).size(), 1u);
  EXPECT_EQ(arbiter.waits_for(0)[0], 1u);
  EXPECT_EQ(arbiter.wait_reason(0), WaitReason::held);
  EXPECT_EQ(arbiter.wait_reason(1), WaitReason::none);
  EXPECT_EQ(arbiter.requested_at(0), 2.0);
  EXPECT_EQ(arbiter.requested_at(1), std::nullopt);  // granted: none pending
  // B hoists up and rests there: its load 0.17 m above A's jib, beyond slow_down (0.15): A goes.
  arbiter.rest(1, {kPi, 1.0, 0.2});
  decided = arbiter.decide(kNow);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 0u);
}

// Rules 1 and 3: two cranes with their jibs at the same height (2 m apart, 1.4 m jibs: they meet
// between the masts) both turn toward each other; the priority crane goes first, and without
// priorities the earlier request.
TEST(SiteArbiter, PriorityThenFirstCome) {
  for (const bool b_priority : {false, true}) {
    SiteLayout s = two_towers(2.5);
    s.cranes[1].priority = b_priority ? 1 : 0;
    SiteArbiter arbiter(s, ArbiterMode::coordinated);
    arbiter.rest(0, {-1.5, 0.5, 0.2});
    arbiter.rest(1, {kPi + 1.5, 0.5, 0.2});
    arbiter.request(0, {{-1.5, 0.5, 0.2}, {0.0, 0.5, 0.2}}, 1.0);  // first
    arbiter.request(1, {{kPi + 1.5, 0.5, 0.2}, {kPi, 0.5, 0.2}}, 2.0);
    const auto decided = arbiter.decide(kNow);
    ASSERT_EQ(decided.size(), 1u);
    EXPECT_EQ(decided[0].crane, b_priority ? 1u : 0u);
    EXPECT_EQ(decided[0].kind, Instruction::Kind::go);
  }
}

// Rule 2: A's jib (the lower crane) and B's cable want the same place; B asked later and has no
// priority, yet goes first.
TEST(SiteArbiter, TheLowerCraneYieldsItsJibToTheHigherCranesCable) {
  SiteArbiter arbiter(two_towers(), ArbiterMode::coordinated);
  arbiter.rest(0, {-1.5, 0.5, 0.2});
  arbiter.rest(1, {kPi + 1.5, 0.5, 0.2});
  arbiter.request(0, {{-1.5, 0.5, 0.2}, {0.0, 0.5, 0.2}}, 1.0);  // A's jib to heading 0
  arbiter.request(1, {{kPi + 1.5, 0.5, 0.2}, {kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}}, 2.0);  // B's load down on it
  const auto decided = arbiter.decide(kNow);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 1u);
  EXPECT_EQ(arbiter.waits_for(0), std::vector<std::size_t>{1u});
  EXPECT_EQ(arbiter.wait_reason(0), WaitReason::higher_cable);
}

// The deadlock: A rests with its jib under the place where B must lower, B rests with its load
// lowered where A's jib must pass. Each waits for the other's held airspace; A ranks last (the
// later request), so A is told to yield: hook up where it is does not free B (A's jib stays), so
// A turns its jib away; B then goes, and A after B rests hook up.
TEST(SiteArbiter, TwoCranesThatWaitForEachOtherAreResolvedByAYield) {
  SiteArbiter arbiter(two_towers(), ArbiterMode::coordinated);
  arbiter.rest(0, {0.0, 0.5, 0.2});         // A's jib along +x: under (1, 0)
  arbiter.rest(1, {kPi + 0.5, 1.0, 2.0});   // B's load lowered at heading pi + 0.5, beside A's jib
  // B wants to lower at (1, 0), over A's jib; A wants to slew to -0.6, through B's load (at
  // (2 - cos 0.5, -sin 0.5) = (1.12, -0.48) in plan; A's trolley 0.5 does not reach it, its jib does).
  arbiter.request(1, {{kPi + 0.5, 1.0, 2.0}, {kPi, 1.0, 2.0}}, 1.0);
  arbiter.request(0, {{0.0, 0.5, 0.2}, {-0.6, 0.5, 0.2}}, 2.0);
  const auto decided = arbiter.decide(kNow);
  EXPECT_EQ(arbiter.waits_for(0), std::vector<std::size_t>{1u});
  EXPECT_EQ(arbiter.waits_for(1), std::vector<std::size_t>{0u});
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 0u);
  EXPECT_EQ(decided[0].kind, Instruction::Kind::yield);
  ASSERT_GE(decided[0].waypoints.size(), 2u);
  const Pose yielded = decided[0].waypoints.back();
  EXPECT_NEAR(std::abs(yielded.slew), SiteArbiter::kYieldSlewStep * std::round(std::abs(yielded.slew) / SiteArbiter::kYieldSlewStep), 1e-12);
  EXPECT_EQ(arbiter.yields(), 1u);
  EXPECT_EQ(arbiter.holding(0), Holding::yield);
  EXPECT_TRUE(arbiter.pending(0));
  // A rests at its yield pose: B goes; A asks again from there and waits for B.
  arbiter.rest(0, yielded);
  arbiter.request(0, {yielded, {-0.6, 0.5, 0.2}}, 3.0);
  auto next = arbiter.decide(kNow);
  ASSERT_EQ(next.size(), 1u);
  EXPECT_EQ(next[0].crane, 1u);
  EXPECT_EQ(next[0].kind, Instruction::Kind::go);
  EXPECT_EQ(arbiter.unresolved(), 0u);
}

// The site of rule 0's tests: A and B of two_towers; a third crane C (jib 3.5 m) at (1, -2), its jib
// at heading +y at slew 0; a fourth crane E at (4.2, 0).
SiteLayout four_cranes() {
  SiteLayout site = two_towers();
  SiteCrane c = site.cranes[1];
  c.name = "c";
  c.base = {1.0, -2.0};
  c.slew_zero_heading = kPi / 2.0;
  c.jib_height = 3.5;
  c.hook_height_min = 1.5;
  c.hook_height_max = 3.3;
  c.domain_id = 13;
  site.cranes.push_back(c);
  // A fourth crane E at (4.2, 0), jib 3.5 m: its whole reach (x >= 2.75) meets B's jib turned to
  // +x (it reaches 3.4 at 3.0-3.08 m, under E's loads) and nothing of A's or C's.
  SiteCrane e = c;
  e.name = "e";
  e.base = {4.2, 0.0};
  e.slew_zero_heading = 0.0;
  e.domain_id = 14;
  site.cranes.push_back(e);
  return site;
}

const double kCSlew = std::atan2(1.1, -0.5) - kPi / 2.0;  // from C's base (1, -2) to P: (-0.5, 1.1)
const double kCTrolley = std::hypot(0.5, 1.1);

// B lowering and raising at (1, 0) since 0.5 s, A waiting for it since 1 s, C asking since 2 s.
SiteArbiter waiting_site(const SiteLayout& layout) {
  SiteArbiter arbiter(layout, ArbiterMode::coordinated);
  arbiter.rest(0, {-kPi / 2.0, 0.5, 0.2});
  arbiter.rest(1, {kPi, 1.0, 0.2});
  arbiter.rest(2, {kCSlew, kCTrolley, 0.2});
  arbiter.rest(3, {0.0, 0.5, 0.2});
  arbiter.request(1, {{kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}, {kPi, 1.0, 0.2}}, 0.0);
  EXPECT_EQ(arbiter.decide(0.5).size(), 1u);  // B goes
  arbiter.request(0, {{-kPi / 2.0, 0.5, 0.2}, {0.0, 0.5, 0.2}}, 1.0);
  arbiter.request(2, {{kCSlew, kCTrolley, 0.2}, {kCSlew, kCTrolley, 2.0}}, 2.0);
  return arbiter;
}

// Rule 0, no starving. A third crane C (jib 3.5 m) at (1, -2), its jib at heading +y at slew 0.
// B lowers its load at (1, 0) and hoists it again: A's request, to slew its jib from -y to +x
// over (1, 0), waits for B. C asks later to lower its load at P = (0.5, -0.9), which A's jib
// sweeps over (|P| = 1.03 < 1.4) but which meets nothing held: 0.42 m in plan from A's jib at
// -y, 1.03 from B's cable, 1.75 - 1.35 - 0.05 = 0.35 from B's whole reach. Once A has waited
// max_wait (40 s), C's later request waits for A's instead of taking the place A must pass; and
// A, starving, no longer gives its jib way to C's cable (rule 2), which would make it yield.
TEST(SiteArbiter, ARequestThatWaitedMaxWaitGoesBeforeLaterOnesThatMeetIt) {
  SiteLayout site = four_cranes();
  site.max_wait = 40.0;
  SiteArbiter arbiter = waiting_site(site);

  // Before A has waited 40 s, C goes: first come among the requests that can go.
  SiteArbiter before = arbiter;
  auto decided = before.decide(40.9);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 2u);
  EXPECT_EQ(before.waits_for(0), std::vector<std::size_t>{1u});
  EXPECT_EQ(before.wait_reason(0), WaitReason::held);

  // From then on C waits for A, which waits for B; B rests hook up, A goes, C waits for A's path.
  SiteArbiter after = arbiter;
  EXPECT_TRUE(after.decide(41.0).empty());
  EXPECT_EQ(after.waits_for(0), std::vector<std::size_t>{1u});
  EXPECT_EQ(after.waits_for(2), std::vector<std::size_t>{0u});
  EXPECT_EQ(after.wait_reason(0), WaitReason::held);
  EXPECT_EQ(after.wait_reason(2), WaitReason::starving);  // A's path, reserved, and not C's rule 2
  after.rest(1, {kPi, 1.0, 0.2});
  decided = after.decide(42.5);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 0u);
  EXPECT_EQ(after.waits_for(2), std::vector<std::size_t>{0u});
  EXPECT_EQ(after.wait_reason(2), WaitReason::held);  // now what A holds
  EXPECT_EQ(after.holding(0), Holding::path);
  EXPECT_EQ(after.yields() + after.unresolved(), 0u);

  // With no limit (max_wait 0), C goes at 41 s as before.
  SiteLayout no_limit = site;
  no_limit.max_wait = 0.0;
  SiteArbiter unlimited = waiting_site(no_limit);
  decided = unlimited.decide(41.0);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 2u);

  // A starving request reserves its path only while it waits for cranes that will move. Kept
  // waiting by a silent crane (its whole reach), it reserves nothing: B may never come back, and
  // C's leg meets nothing B can hold.
  SiteArbiter silent = arbiter;
  silent.lost(1);
  decided = silent.decide(41.0);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 2u);
  EXPECT_EQ(silent.waits_for(0), std::vector<std::size_t>{1u});
  // B resting idle with its load lowered in A's way will move: it is told to yield, and C still
  // waits for A.
  SiteArbiter resting = arbiter;
  resting.rest(1, {kPi, 1.0, 2.0});
  decided = resting.decide(41.0);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 1u);
  EXPECT_EQ(decided[0].kind, Instruction::Kind::yield);
  EXPECT_EQ(resting.waits_for(2), std::vector<std::size_t>{0u});
  // But when B, resting there, asks to turn its jib to +x and waits for E, silent, B may never
  // move either (in turn): C goes.
  SiteArbiter chain = arbiter;
  chain.rest(1, {kPi, 1.0, 2.0});
  chain.request(1, {{kPi, 1.0, 2.0}, {kPi, 1.0, 0.2}, {0.0, 1.0, 0.2}}, 3.0);
  chain.lost(3);
  decided = chain.decide(41.0);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 2u);
  EXPECT_EQ(decided[0].kind, Instruction::Kind::go);
  EXPECT_EQ(chain.waits_for(1), std::vector<std::size_t>{3u});
  EXPECT_EQ(chain.waits_for(0), std::vector<std::size_t>{1u});

  EXPECT_THROW((void)arbiter.decide(std::nan("")), std::invalid_argument);
}

// Rule 0, the most work left first (the site file's most_work_left_first). The site of the test
// above with no max_wait: A waits for B, and C's later request, which could go, meets A's path.
// With A's work left more than every other crane's, C waits for A (most_work_left), as for a
// starving A; with C's the most, or a tie, or the rule off, C goes, first come. Only cranes that
// report count (E, silent, with more, does not), and only a crane at rest that asks is ranked (B
// on its path with the most: none is).
TEST(SiteArbiter, TheRequestOfTheCraneWithTheMostWorkLeftGoesFirst) {
  SiteLayout site = four_cranes();
  site.most_work_left_first = true;
  const auto with_work = [&](const SiteLayout& layout, std::vector<double> work) {
    SiteArbiter arbiter = waiting_site(layout);
    for (std::size_t i = 0; i < work.size(); ++i) arbiter.work_left(i, work[i]);
    return arbiter;
  };
  SiteArbiter a_most = with_work(site, {300.0, 100.0, 200.0, 50.0});
  EXPECT_EQ(a_most.most_work_left(), std::optional<std::size_t>(0u));
  EXPECT_TRUE(a_most.decide(3.0).empty());
  EXPECT_EQ(a_most.waits_for(0), std::vector<std::size_t>{1u});
  EXPECT_EQ(a_most.wait_reason(0), WaitReason::held);
  EXPECT_EQ(a_most.waits_for(2), std::vector<std::size_t>{0u});
  EXPECT_EQ(a_most.wait_reason(2), WaitReason::most_work_left);
  EXPECT_EQ(a_most.yields() + a_most.unresolved(), 0u);  // nor does A give its jib way to C's cable (rule 2)
  // B rests: A goes, and C waits for what A holds.
  a_most.rest(1, {kPi, 1.0, 0.2});
  auto decided = a_most.decide(4.0);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 0u);
  EXPECT_EQ(a_most.wait_reason(2), WaitReason::held);

  const auto c_goes = [&](SiteArbiter arbiter, const char* why) {
    SCOPED_TRACE(why);
    const auto d = arbiter.decide(3.0);
    ASSERT_EQ(d.size(), 1u);
    EXPECT_EQ(d[0].crane, 2u);
    EXPECT_EQ(d[0].kind, Instruction::Kind::go);
  };
  SiteArbiter c_most = with_work(site, {200.0, 100.0, 300.0, 50.0});
  EXPECT_EQ(c_most.most_work_left(), std::optional<std::size_t>(2u));
  c_goes(c_most, "C has the most work left");
  SiteArbiter tie = with_work(site, {300.0, 100.0, 300.0, 50.0});
  EXPECT_EQ(tie.most_work_left(), std::nullopt);
  c_goes(tie, "A and C tie");
  SiteLayout off = site;
  off.most_work_left_first = false;
  SiteArbiter rule_off = with_work(off, {300.0, 100.0, 200.0, 50.0});
  EXPECT_EQ(rule_off.most_work_left(), std::nullopt);
  c_goes(rule_off, "the rule off");
  SiteArbiter b_most = with_work(site, {300.0, 400.0, 200.0, 50.0});
  EXPECT_EQ(b_most.most_work_left(), std::nullopt);  // B, on its path, is the critical crane: no request to rank
  c_goes(b_most, "B, moving, has the most");
  SiteArbiter e_silent = with_work(site, {300.0, 100.0, 200.0, 900.0});
  EXPECT_EQ(e_silent.most_work_left(), std::nullopt);  // E reports the most
  e_silent.lost(3);
  EXPECT_EQ(e_silent.most_work_left(), std::optional<std::size_t>(0u));  // silent, it is not counted
  EXPECT_TRUE(e_silent.decide(3.0).empty());
  EXPECT_EQ(e_silent.wait_reason(2), WaitReason::most_work_left);

  SiteArbiter bad = waiting_site(site);
  EXPECT_THROW(bad.work_left(0, -1.0), std::invalid_argument);
  EXPECT_THROW(bad.work_left(0, std::nan("")), std::invalid_argument);
  EXPECT_THROW(bad.work_left(7, 1.0), std::out_of_range);
}

// An idle crane in the way (no request of its own) is told to yield as well.
TEST(SiteArbiter, AnIdleCraneInTheWayYields) {
  SiteArbiter arbiter(two_towers(), ArbiterMode::coordinated);
  arbiter.rest(0, {0.0, 0.5, 0.2});
  arbiter.rest(1, {kPi + 1.5, 0.5, 0.2});
  arbiter.request(1, {{kPi + 1.5, 0.5, 0.2}, {kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}}, 1.0);
  const auto decided = arbiter.decide(kNow);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 0u);
  EXPECT_EQ(decided[0].kind, Instruction::Kind::yield);
}

// A crane that stops reporting holds its whole reach: nothing of the other crane that meets it is
// granted until it rests again; nothing is allowed by default (every crane starts so). B's travel
// with its hook up passes above all of A (its load's bottom 2.75 m, A's jib top 2.58 m) and is
// granted even so; lowering is not.
TEST(SiteArbiter, ALostCraneHoldsItsWholeReach) {
  SiteArbiter arbiter(two_towers(), ArbiterMode::coordinated);
  EXPECT_EQ(arbiter.holding(0), Holding::whole_reach);
  arbiter.rest(1, {kPi + 1.5, 0.5, 0.2});
  arbiter.request(1, {{kPi + 1.5, 0.5, 0.2}, {kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}}, 1.0);
  EXPECT_TRUE(arbiter.decide(kNow).empty());  // A never reported
  EXPECT_EQ(arbiter.waits_for(1), std::vector<std::size_t>{0u});
  arbiter.request(1, {{kPi + 1.5, 0.5, 0.2}, {kPi, 1.0, 0.2}}, 1.5);  // hook up only
  ASSERT_EQ(arbiter.decide(kNow).size(), 1u);
  arbiter.rest(1, {kPi, 1.0, 0.2});
  arbiter.rest(0, {-1.5, 0.5, 0.2});
  arbiter.lost(0);
  arbiter.request(1, {{kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}}, 2.0);
  EXPECT_TRUE(arbiter.decide(kNow).empty());
  EXPECT_EQ(arbiter.waits_for(1), std::vector<std::size_t>{0u});
  arbiter.rest(0, {-1.5, 0.5, 0.2});  // A reports again, its jib away
  ASSERT_EQ(arbiter.decide(kNow).size(), 1u);
}

// An operator's word that a silent crane stands braked where it went silent (out_of_service): A,
// lost from its rest pose with its jib away (heading -1.5 rad), no longer holds its whole reach but
// its rest box, with the swing of its load braked from its last reported motion (at rest, but it
// may have sped up for report_age 0.1 s at the soft decelerations of 0.5 m/s^2 and rad/s^2: 0.05
// m/s and rad/s; the brakes, 3 times as hard, then stop it 0.1 s later: by hand, the sheave at
// radius 0.5 + 0.05 x 0.1 + 0.05^2 / 3 moves at hypot(0.05, r x 0.05), and the load keeps that
// speed over the pendulum's frequency sqrt(g / 0.2)). So B may lower its load at (1, 0). A crane
// lost on its path holds the rest of that path, the braked swing at each box's longest cable.
// Refused: a crane that is not silent, one never known (a restarted arbiter), one out of service
// that moved (it forgets where it stood), and a non-finite motion.
TEST(SiteArbiter, AnOperatorPutsASilentCraneOutOfServiceWhereItStood) {
  const SiteLayout layout = two_towers();
  SiteArbiter arbiter(layout, ArbiterMode::coordinated);
  CraneMotion still;
  still.slew = -1.5;
  still.trolley = 0.5;
  still.cable_length = 0.2;
  EXPECT_THROW(arbiter.out_of_service(0, still, 0.1), std::logic_error);  // never known: its whole reach stays
  arbiter.rest(0, {-1.5, 0.5, 0.2});
  EXPECT_THROW(arbiter.out_of_service(0, still, 0.1), std::logic_error);  // it reports
  arbiter.rest(1, {kPi, 1.0, 0.2});
  arbiter.lost(0);
  arbiter.request(1, {{kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}}, 1.0);
  EXPECT_TRUE(arbiter.decide(kNow).empty());
  EXPECT_EQ(arbiter.waits_for(1), std::vector<std::size_t>{0u});
  CraneMotion nan = still;
  nan.swing_in_plane = std::nan("");
  EXPECT_THROW(arbiter.out_of_service(0, nan, 0.1), std::invalid_argument);
  EXPECT_THROW(arbiter.out_of_service(0, still, -0.1), std::invalid_argument);
  EXPECT_EQ(arbiter.holding(0), Holding::whole_reach);
  arbiter.out_of_service(0, still, 0.1);
  EXPECT_EQ(arbiter.holding(0), Holding::out_of_service);
  EXPECT_STREQ(to_string(Holding::out_of_service), "out_of_service");
  ASSERT_EQ(arbiter.held(0).count, 1u);
  EXPECT_DOUBLE_EQ(arbiter.held(0).boxes[0].slew_low, -1.5);
  const double radius = 0.5 + 0.05 * 0.1 + 0.05 * 0.05 / (2.0 * 1.5);
  const double by_hand = std::hypot(0.05, radius * 0.05) * std::sqrt(0.2 / 9.80665);
  EXPECT_NEAR(arbiter.held(0).boxes[0].swing_radius, by_hand, 1e-12);
  const auto orders = arbiter.decide(kNow);
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].crane, 1u);
  // It comes back at rest.
  arbiter.rest(0, {-1.5, 0.5, 0.2});
  EXPECT_EQ(arbiter.holding(0), Holding::rest);

  // Lost on its path, slewing at 0.3 rad/s: the rest of the path; the swing wider on the box
  // whose cable reaches 1.0 m than on the one at 0.2 m, and wider than from rest.
  SiteArbiter moving(layout, ArbiterMode::coordinated);
  moving.rest(0, {-1.5, 0.5, 0.2});
  moving.rest(1, {kPi - 1.5, 0.5, 0.2});
  const std::vector<Pose> path{{-1.5, 0.5, 0.2}, {-1.0, 0.5, 0.2}, {-1.0, 0.5, 1.0}};
  moving.request(0, path, 0.0);
  ASSERT_EQ(moving.decide(kNow).size(), 1u);
  moving.lost(0);
  CraneMotion slewing = still;
  slewing.slew_rate = 0.3;
  moving.out_of_service(0, slewing, 0.1);
  ASSERT_EQ(moving.held(0).count, 2u);
  EXPECT_GT(moving.held(0).boxes[0].swing_radius, by_hand);
  EXPECT_GT(moving.held(0).boxes[1].swing_radius, moving.held(0).boxes[0].swing_radius);
  // Moving without a grant while out of service: its whole reach, and it cannot be put out of
  // service again before it rests.
  moving.lost(0);
  EXPECT_EQ(moving.holding(0), Holding::whole_reach);
  EXPECT_THROW(moving.out_of_service(0, slewing, 0.1), std::logic_error);
  EXPECT_THROW(moving.out_of_service(5, slewing, 0.1), std::out_of_range);
}

// A crane that reports reaching a waypoint holds only the rest of its path: B's load hangs low at
// (1, 0), on the line A's jib wants to turn to; B hoists up, travels to (1.93, 1.0) and lowers
// there, beyond A's reach. Once B reports it has hoisted up and travelled, A's jib may turn.
TEST(SiteArbiter, ProgressFreesThePathBehind) {
  SiteArbiter arbiter(two_towers(), ArbiterMode::coordinated);
  arbiter.rest(0, {-1.5, 0.5, 0.2});
  arbiter.rest(1, {kPi, 1.0, 1.5});
  const std::vector<Pose> path{{kPi, 1.0, 1.5}, {kPi, 1.0, 0.2}, {kPi - 1.5, 1.0, 0.2}, {kPi - 1.5, 1.0, 1.5}};
  arbiter.request(1, path, 1.0);
  ASSERT_EQ(arbiter.decide(kNow).size(), 1u);
  // A's jib to heading 0 meets B's load where B's path starts.
  arbiter.request(0, {{-1.5, 0.5, 0.2}, {0.0, 0.5, 0.2}}, 2.0);
  EXPECT_TRUE(arbiter.decide(kNow).empty());
  EXPECT_EQ(arbiter.waits_for(0), std::vector<std::size_t>{1u});
  arbiter.progress(1, {path.begin() + 2, path.end()});  // B hoisted up and travelled
  ASSERT_EQ(arbiter.decide(kNow).size(), 1u);
  EXPECT_THROW(arbiter.progress(0, {}), std::invalid_argument);
  SiteArbiter idle(two_towers(), ArbiterMode::coordinated);
  idle.rest(0, {0.0, 0.5, 0.2});
  EXPECT_THROW(idle.progress(0, {{0.0, 0.5, 0.2}}), std::logic_error);
}

// A part of a leg (the site file's part_of_leg). B, its load low over A's jib line at x = 1.0
// (heading 0 of A), hoists up and slews away, hook up: its cable meets A's jib at heading 0 only
// while it hoists there; its load at 0.2 m of cable passes 0.17 m above A's jib. A turns its jib
// from heading -1.5 through 0 to 0.5: its first segment (to -0.5) and its rest at -0.5 keep clear
// of B, its second segment meets B's hoist. A goes to -0.5, holding that part only; at rest there
// it asks for the rest, a new request, which waits for B; once B has hoisted, it goes. Without
// part_of_leg, A waits at -1.5. The same when B will rest in A's way (B's leg reversed: at rest
// there with nothing to do, B then yields), and when B stands there at rest; A waits whole when its
// first segment meets B, or when B is silent. And it waits at an earlier waypoint when the rest box
// at the last one before B meets B (a hold allowance wider than the travel's).
TEST(SiteArbiter, APartOfALegGoesUpToAWaypointWhereItWaitsForTheCranesInItsWay) {
  const std::vector<Pose> b_path{{kPi, 1.0, 1.5}, {kPi, 1.0, 0.2}, {kPi - 1.5, 1.0, 0.2}};
  const std::vector<Pose> b_back(b_path.rbegin(), b_path.rend());
  const std::vector<Pose> a_path{{-1.5, 0.5, 0.2}, {-0.5, 0.5, 0.2}, {0.5, 0.5, 0.2}};
  SiteLayout site = two_towers();
  // B granted `b` first, then A asks for `a`.
  const auto started_on = [&](const SiteLayout& on, const std::vector<Pose>& b, const std::vector<Pose>& a) {
    SiteArbiter arbiter(on, ArbiterMode::coordinated);
    arbiter.rest(0, a.front());
    arbiter.rest(1, b.front());
    arbiter.request(1, b, 1.0);
    EXPECT_EQ(arbiter.decide(kNow).size(), 1u);
    arbiter.request(0, a, 2.0);
    return arbiter;
  };
  const auto started = [&](bool part_of_leg, const std::vector<Pose>& b) {
    site.part_of_leg = part_of_leg;
    return started_on(site, b, a_path);
  };
  {
    SiteArbiter arbiter = started(false, b_path);
    EXPECT_TRUE(arbiter.decide(kNow).empty());
    EXPECT_EQ(arbiter.waits_for(0), std::vector<std::size_t>{1u});
  }
  // The geometry as the test's comment says.
  const auto distance = [&](const Airspace& a, const Airspace& b) {
    return airspace_distance(site.cranes[0], a, site.cranes[1], b).distance;
  };
  const auto path = [&](const std::vector<Pose>& p) { return path_airspace(p, site.paths); };
  const Airspace a_wait = rest_airspace(a_path[1], site.paths);
  ASSERT_GE(distance(path({a_path[0], a_path[1]}), path(b_path)), site.margins.slow_down);
  ASSERT_GE(distance(a_wait, path(b_path)), site.margins.slow_down);
  ASSERT_LT(distance(path({a_path[1], a_path[2]}), path({b_path[0], b_path[1]})), site.margins.slow_down);
  const Airspace b_low = rest_airspace(b_path[0], site.paths);
  ASSERT_GE(distance(path({a_path[0], a_path[1]}), b_low), site.margins.slow_down);
  ASSERT_GE(distance(a_wait, b_low), site.margins.slow_down);
  ASSERT_LT(distance(path(a_path), b_low), site.margins.slow_down);

  SiteArbiter arbiter = started(true, b_path);
  auto decided = arbiter.decide(kNow);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 0u);
  EXPECT_EQ(decided[0].kind, Instruction::Kind::go);
  ASSERT_EQ(decided[0].waypoints.size(), 2u) << "up to the waypoint before the segment that meets B";
  EXPECT_DOUBLE_EQ(decided[0].waypoints[1].slew, -0.5);
  EXPECT_TRUE(same_airspace(arbiter.held(0), path({a_path[0], a_path[1]}))) << "that part only";
  // At rest there (a hair off), it asks for the rest: a new request, which waits for B.
  arbiter.rest(0, {-0.501, 0.5, 0.2});
  EXPECT_TRUE(same_airspace(arbiter.held(0), rest_airspace({-0.501, 0.5, 0.2}, site.paths)));
  arbiter.request(0, {a_path[1], a_path[2]}, 9.0);
  EXPECT_EQ(arbiter.requested_at(0), 9.0);
  EXPECT_TRUE(arbiter.decide(10.0).empty()) << "its first segment meets B's hoist: it waits whole";
  EXPECT_EQ(arbiter.waits_for(0), std::vector<std::size_t>{1u});
  arbiter.progress(1, {b_path[1], b_path[2]});  // B hoisted up
  decided = arbiter.decide(10.0);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].crane, 0u);
  EXPECT_EQ(decided[0].waypoints.size(), 2u) << "the rest, whole";

  // B will rest in A's way: A still goes to -0.5, and waits there until B leaves.
  SiteArbiter in_the_way = started(true, b_back);
  decided = in_the_way.decide(kNow);
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].waypoints.size(), 2u);
  in_the_way.rest(0, a_path[1]);
  in_the_way.rest(1, b_back.back());
  in_the_way.request(0, {a_path[1], a_path[2]}, 12.0);
  decided = in_the_way.decide(12.0);
  EXPECT_EQ(in_the_way.waits_for(0), std::vector<std::size_t>{1u});
  ASSERT_EQ(decided.size(), 1u) << "B, with nothing to do, yields";
  EXPECT_EQ(decided[0].crane, 1u);
  EXPECT_EQ(decided[0].kind, Instruction::Kind::yield);
  // B at rest there from the start: the same.
  site.part_of_leg = true;
  // What A, asking for `a`, is granted with B at rest at `b` (and what A holds then).
  const auto granted_with_b_at = [&](const Pose& b, const std::vector<Pose>& a) {
    SiteArbiter arbiter_b_rests(site, ArbiterMode::coordinated);
    arbiter_b_rests.rest(0, a.front());
    arbiter_b_rests.rest(1, b);
    arbiter_b_rests.request(0, a, 2.0);
    auto d = arbiter_b_rests.decide(kNow);
    return std::make_pair(d, arbiter_b_rests.held(0));
  };
  decided = granted_with_b_at(b_path.front(), a_path).first;
  ASSERT_EQ(decided.size(), 1u);
  EXPECT_EQ(decided[0].waypoints.size(), 2u);
  // B silent (its whole reach held): A waits whole.
  SiteArbiter silent(site, ArbiterMode::coordinated);
  silent.rest(0, a_path.front());
  silent.request(0, a_path, 2.0);
  EXPECT_TRUE(silent.decide(kNow).empty());

  // A waypoint whose rest box meets B is not where A waits: with a hold allowance wider than the
  // travel's (0.2 rad of slew either side, against 0.07), A's rest box at -0.5 meets B's hoist,
  // though the travel there does not; A, through -1.0, goes to -1.0 only (to -0.5 with the
  // shipped 0.02). Each is one move: the waypoints on a travel's way are not stops (stops_of).
  const std::vector<Pose> a_long{{-1.5, 0.5, 0.2}, {-1.0, 0.5, 0.2}, {-0.5, 0.5, 0.2}, {0.5, 0.5, 0.2}};
  for (const double slew_hold : {site.paths.slew_hold, 0.2}) {
    SiteLayout wide = two_towers();
    wide.part_of_leg = true;
    wide.paths.slew_hold = slew_hold;
    const auto meets_b = [&](const Airspace& a) {
      return airspace_distance(wide.cranes[0], a, wide.cranes[1], path_airspace(b_path, wide.paths)).distance <
             wide.margins.slow_down;
    };
    ASSERT_FALSE(meets_b(path_airspace(std::vector<Pose>{a_long[0], a_long[1], a_long[2]}, wide.paths))) << slew_hold;
    ASSERT_FALSE(meets_b(rest_airspace(a_long[1], wide.paths)));
    ASSERT_EQ(meets_b(rest_airspace(a_long[2], wide.paths)), slew_hold == 0.2);
    SiteArbiter narrow = started_on(wide, b_path, a_long);
    decided = narrow.decide(kNow);
    ASSERT_EQ(decided.size(), 1u);
    ASSERT_EQ(decided[0].waypoints.size(), 2u) << "slew_hold " << slew_hold;
    EXPECT_EQ(decided[0].waypoints[1].slew, slew_hold == 0.2 ? -1.0 : -0.5) << "slew_hold " << slew_hold;
    EXPECT_TRUE(same_airspace(narrow.held(0), path_airspace(decided[0].waypoints, wide.paths)));
  }
  // Granted whole, the travel is one move too: from -1.5 straight to 0.5.
  ASSERT_GE(distance(path(a_long), rest_airspace(b_path.back(), site.paths)), site.margins.slow_down);
  const auto [whole, held] = granted_with_b_at(b_path.back(), a_long);
  ASSERT_EQ(whole.size(), 1u);
  ASSERT_EQ(whole[0].waypoints.size(), 2u);
  EXPECT_EQ(whole[0].waypoints[1].slew, 0.5);
  EXPECT_TRUE(same_airspace(held, path_airspace(whole[0].waypoints, site.paths)));
}

// The serialized baseline: two requests in shared airspace that keep apart geometrically still go
// one at a time.
TEST(SiteArbiter, SerializedModeLetsOneCraneAtATimeIntoSharedAirspace) {
  for (const auto mode : {ArbiterMode::coordinated, ArbiterMode::serialized}) {
    SiteArbiter arbiter(two_towers(), mode);
    arbiter.rest(0, {-1.5, 0.5, 0.2});
    arbiter.rest(1, {kPi - 1.5, 0.5, 0.2});
    // A's load down in the overlap, south (0.99, -0.68); B's, north (1.01, 0.68): 1.36 m apart,
    // and neither jib turns over the other's load.
    arbiter.request(0, {{-1.5, 0.5, 0.2}, {-0.6, 1.2, 0.2}, {-0.6, 1.2, 1.5}}, 1.0);
    arbiter.request(1, {{kPi - 1.5, 0.5, 0.2}, {kPi - 0.6, 1.2, 0.2}, {kPi - 0.6, 1.2, 1.5}}, 2.0);
    EXPECT_EQ(arbiter.decide(kNow).size(), mode == ArbiterMode::coordinated ? 2u : 1u);
  }
}

TEST(SiteArbiter, BadRequestsAreRefused) {
  SiteArbiter arbiter(two_towers(), ArbiterMode::coordinated);
  EXPECT_THROW(arbiter.request(0, {}, 0.0), std::invalid_argument);
  EXPECT_THROW(arbiter.request(0, {{std::nan(""), 0.5, 0.2}}, 0.0), std::invalid_argument);
  EXPECT_THROW(arbiter.request(0, {{0.0, 0.5, 0.0}}, 0.0), std::invalid_argument);
  EXPECT_THROW(arbiter.request(5, {{0.0, 0.5, 0.2}}, 0.0), std::out_of_range);
  SiteLayout bad = two_towers();
  bad.margins.stop = 0.2;
  EXPECT_THROW(SiteArbiter(bad, ArbiterMode::coordinated), crane::common::ConfigError);
}

// Containment in joint space, by hand: one box, each axis at its edge, within and beyond the
// tolerance.
TEST(GrantGuard, ContainmentByHand) {
  Airspace a;
  a.boxes[0] = {0.0, 1.0, 0.5, 1.0, 0.2, 1.0, 0.1};
  a.count = 1;
  EXPECT_TRUE(contains(a, {0.5, 0.7, 0.5}));
  EXPECT_TRUE(contains(a, {0.5, 1.0 + 0.9 * kContainmentTolerance, 0.5}));
  EXPECT_FALSE(contains(a, {0.5, 1.0 + 1.1 * kContainmentTolerance, 0.5}));
  EXPECT_FALSE(contains(a, {-1.1 * kContainmentTolerance, 0.7, 0.5}));
  EXPECT_FALSE(contains(a, {0.5, 0.7, 0.2 - 1.1 * kContainmentTolerance}));
  EXPECT_FALSE(contains(Airspace{}, {0.5, 0.7, 0.5}));
  // A second box of a path: the union.
  a.boxes[1] = {1.0, 1.0, 1.0, 1.2, 0.2, 0.2, 0.1};
  a.count = 2;
  EXPECT_TRUE(contains(a, {1.0, 1.15, 0.2}));
  EXPECT_FALSE(contains(a, {0.5, 1.15, 0.2}));
}

// Crane A's guard on the two-tower site (default stopping data: reaction 0.1 s, trolley 0.5 m/s^2,
// brakes 3 times that). Its grant: the trolley from 0.3 to 1.0 m at slew 0 (towards B), hook up.
TEST(GrantGuard, EachRuleByHand) {
  const SiteLayout site = two_towers();
  GrantGuard guard(site, 0);
  CraneMotion m;
  m.slew = 0.0;
  m.trolley = 0.6;
  m.cable_length = 0.2;
  // Nothing is allowed by default: at rest it may stay, moving it is stopped.
  EXPECT_EQ(guard.check(m, 0.0).action, GrantAction::proceed);
  m.trolley_velocity = 0.5;
  EXPECT_EQ(guard.check(m, 0.0).action, GrantAction::emergency_stop);
  EXPECT_STREQ(guard.check(m, 0.0).reason, "moving with no grant");

  const std::vector<Pose> path{{0.0, 0.3, 0.2}, {0.0, 1.0, 0.2}};
  guard.grant(path_airspace(path, site.paths), 10.0);
  EXPECT_EQ(guard.check(m, 10.0).action, GrantAction::proceed);
  // The brakes from 0.5 m/s: 0.5 x 0.1 + 0.5^2 / (2 x 1.5) = 0.1333 m. From 0.85 m they end at
  // 0.983 m, inside; from 0.90 m at 1.033 m, beyond the box (1.0 m) and its tolerance.
  m.trolley = 0.85;
  EXPECT_EQ(guard.check(m, 10.0).action, GrantAction::proceed);
  m.trolley = 0.90;
  EXPECT_EQ(guard.check(m, 10.0).action, GrantAction::emergency_stop);
  EXPECT_STREQ(guard.check(m, 10.0).reason, "leaving its grant");
  // Off the path sideways (the jib turned 0.05 rad from the slew-0 path): outside.
  m.trolley = 0.6;
  m.slew = 0.05;
  EXPECT_EQ(guard.check(m, 10.0).action, GrantAction::emergency_stop);
  m.slew = 0.0;
  // The link: the path reaches B's airspace (A's jib towards B), so once nothing was heard for
  // link_deadline the crane soft-stops; a message from the service in time keeps it going.
  // The soft stop from 0.5 m/s, ZVD shaped on 0.2 m of cable (T = 2 pi sqrt(0.2 / 9.80665) =
  // 0.8973 s): 0.5 x 0.1 + 0.5^2 / (2 x 0.5) + 0.5 x 0.8973 / 2 = 0.5243 m. From 0.4 m it ends at
  // 0.924 m, inside the grant: the soft stop. From 0.6 m at 1.124 m, beyond it: the move goes on to
  // its waypoint (1.0 m), the sooner rest inside the grant.
  ASSERT_TRUE(in_shared_airspace(site, 0, guard.granted()));
  m.trolley = 0.4;
  EXPECT_EQ(guard.check(m, 10.0 + 0.9 * site.link_deadline).action, GrantAction::proceed);
  EXPECT_EQ(guard.check(m, 10.0 + 1.1 * site.link_deadline).action, GrantAction::soft_stop);
  m.trolley = 0.6;
  EXPECT_EQ(guard.check(m, 10.0 + 1.1 * site.link_deadline).action, GrantAction::finish_path);
  EXPECT_NEAR(stopping_travel(site.cranes[0], m, StopKind::soft).trolley,
              0.05 + 0.25 + 0.5 * 2.0 * kPi * std::sqrt(0.2 / kStandardGravity) / 2.0, 1e-9);
  // The predicted stop must end the containment tolerance (0.02 m) inside the box: ending at 0.99 m
  // (from 0.4657 m), 0.01 m inside the box's end (1.0 m), is too close for a model that takes the
  // speed as constant; ending at 0.97 m (from 0.4457 m), 0.03 m inside, is not. A slew and a hoist
  // at rest (their speeds' noise) do not count: the cable's interval has no width.
  m.slew_rate = 1e-4;
  m.cable_rate = -1e-4;
  m.trolley = 0.99 - 0.5243;
  EXPECT_EQ(guard.check(m, 10.0 + 1.1 * site.link_deadline).action, GrantAction::finish_path);
  m.trolley = 0.97 - 0.5243;
  EXPECT_EQ(guard.check(m, 10.0 + 1.1 * site.link_deadline).action, GrantAction::soft_stop);
  m.slew_rate = 0.0;
  m.cable_rate = 0.0;
  m.trolley = 0.6;
  guard.heard(10.0 + site.link_deadline);
  EXPECT_EQ(guard.check(m, 10.0 + 1.1 * site.link_deadline).action, GrantAction::proceed);
  // The same path turned away from B (slew pi: the load 0.3-1.0 m on the far side) is A's own
  // airspace: with the link lost it goes on.
  guard.grant(path_airspace(std::vector<Pose>{{kPi, 0.3, 0.2}, {kPi, 1.0, 0.2}}, site.paths), 20.0);
  ASSERT_FALSE(in_shared_airspace(site, 0, guard.granted()));
  m.slew = kPi;
  EXPECT_EQ(guard.check(m, 30.0).action, GrantAction::proceed);
  // Progress: what the crane left behind is no longer its own.
  guard.progress(path_airspace(std::vector<Pose>{{kPi, 0.8, 0.2}, {kPi, 1.0, 0.2}}, site.paths));
  EXPECT_EQ(guard.check(m, 30.0).action, GrantAction::emergency_stop);
  m.trolley = 0.8;
  EXPECT_EQ(guard.check(m, 30.0).action, GrantAction::proceed);
  // The swing: the path's allowance here is 0 (two_towers), the load swinging 0.1 rad at 0.2 m of
  // cable spreads 0.02 m: wider than allowed plus the tolerance? 0.2 sin 0.1 = 0.01997 < 0.02: no.
  // At 0.15 rad it is 0.0299 m: yes.
  m.trolley_velocity = 0.0;
  m.swing_in_plane = 0.1;
  EXPECT_EQ(guard.check(m, 30.0).action, GrantAction::proceed);
  m.swing_in_plane = 0.15;
  EXPECT_EQ(guard.check(m, 30.0).action, GrantAction::soft_stop);
  EXPECT_STREQ(guard.check(m, 30.0).reason, "the load swings wider than its grant allows");
  // Non-finite motion: the brakes.
  m.swing_in_plane = std::nan("");
  EXPECT_EQ(guard.check(m, 30.0).action, GrantAction::emergency_stop);
  EXPECT_THROW(GrantGuard(site, 2), std::out_of_range);
}


// A lost link in the middle of a move of both axes (slew 0 -> 0.8 rad, trolley 0.3 -> 0.9 m, on
// 0.2 m of cable; the path's box is slew [0, 0.8], trolley [0.3, 0.9]): the trolley 2 cm short of
// its goal at 0.5 m/s, the slew at 0.3 rad turning at 0.3 rad/s. ZVD on 0.2 m of cable: T = 2 pi
// sqrt(0.2 / 9.80665) = 0.89729 s. The trolley's soft stop runs 0.5 x 0.1 + 0.5^2 / (2 x 0.5) +
// 0.5 x 0.89729 / 2 = 0.52432 m, to 1.44 m with the margin: far past 0.9 m. The slew's runs 0.3 x
// 0.1 + 0.3^2 / (2 x 0.5) + 0.3 x 0.89729 / 2 = 0.25459 rad, to 0.5946 rad with the margin: inside
// 0.8. So the slew stops (and the hoist, at rest, is named too) while the trolley runs on to 0.9 m.
TEST(GrantGuard, ASoftStopOfTheAxesThatStayInsideLetsTheOthersRunOnToTheirTarget) {
  const SiteLayout site = two_towers();
  GrantGuard guard(site, 0);
  const Pose target{0.8, 0.9, 0.2};
  EXPECT_FALSE(guard.soft_stop_axes(CraneMotion{}, {}, target).has_value()) << "no grant";
  guard.grant(path_airspace(std::vector<Pose>{{0.0, 0.3, 0.2}, target}, site.paths), 10.0);
  CraneMotion m;
  m.slew = 0.3;
  m.slew_rate = 0.3;
  m.trolley = 0.88;
  m.trolley_velocity = 0.5;
  m.cable_length = 0.2;
  const double period = 2.0 * kPi * std::sqrt(0.2 / kStandardGravity);
  const StoppingTravel stop = stopping_travel(site.cranes[0], m, StopKind::soft);
  EXPECT_NEAR(stop.trolley, 0.05 + 0.25 + 0.5 * period / 2.0, 1e-12);
  EXPECT_NEAR(stop.slew, 0.03 + 0.09 + 0.3 * period / 2.0, 1e-12);
  EXPECT_FALSE(guard.soft_stop_stays_in_grant(m));
  const auto axes = guard.soft_stop_axes(m, {}, target);
  ASSERT_TRUE(axes.has_value());
  EXPECT_EQ(*axes, kStopSlew | kStopHoist);
  // The other way round: the slew 0.05 rad short of its goal, the trolley slow and far from its
  // own (0.1 m/s at 0.5 m: 0.01 + 0.01 + 0.04486 = 0.06486 m, to 0.605 m).
  m.slew = 0.75;
  m.trolley = 0.5;
  m.trolley_velocity = 0.1;
  EXPECT_EQ(guard.soft_stop_axes(m, {}, target), std::optional<std::uint8_t>(kStopTrolley | kStopHoist));
  // Both near their goals: no choice but the move's own end stays inside.
  m.trolley = 0.88;
  m.trolley_velocity = 0.5;
  EXPECT_FALSE(guard.soft_stop_axes(m, {}, target).has_value());
  // Both slow: every axis stops, as soft_stop_stays_in_grant says.
  m.slew = 0.3;
  m.trolley = 0.5;
  m.trolley_velocity = 0.1;
  ASSERT_TRUE(guard.soft_stop_stays_in_grant(m));
  EXPECT_EQ(guard.soft_stop_axes(m, {}, target), std::optional<std::uint8_t>(kStopTrolley | kStopSlew | kStopHoist));
  // A trolley whose reference rests at its goal ends there (reference_rest_of): every axis stops.
  m.trolley = 0.88;
  m.trolley_velocity = 0.5;
  ReferenceRest rest;
  rest.trolley = 0.9;
  EXPECT_EQ(guard.soft_stop_axes(m, rest, target), std::optional<std::uint8_t>(kStopTrolley | kStopSlew | kStopHoist));
  // A target outside the grant is no place to run on to; a non-finite one is refused.
  EXPECT_FALSE(guard.soft_stop_axes(m, {}, {0.8, 1.2, 0.2}).has_value());
  EXPECT_FALSE(guard.soft_stop_axes(m, {}, {0.8, std::nan(""), 0.2}).has_value());
}

// The site service's protocol (site_service.hpp) over the same two towers: reports that carry
// each crane's whole state, instructions numbered and sent again until carried out.
CraneReport at_rest(std::size_t crane, Pose pose, std::uint32_t request_id = 0, std::vector<Pose> request = {}) {
  CraneReport r;
  r.crane = crane;
  r.waypoints = {pose};
  r.request_id = request_id;
  r.request = std::move(request);
  return r;
}

// The traced case of the simulated site (docs/site.md, seed 88): crane A lowers its hook at a work
// point towards B (slew 0, trolley 0.6 m, cable 0.2 -> 1.0 m) while its load settles, the measured
// slew 0.007 rad past its goal and still turning at 0.09 rad/s; the link is lost. From the measured
// speed, a ZVD-shaped soft stop on 0.5 m of cable (T = 2 pi sqrt(0.5 / 9.80665) = 1.41878 s) runs
// the slew 0.09 x 0.1 + 0.09^2 / (2 x 0.5) + 0.09 x 1.41878 / 2 = 0.08095 rad, to 0.128 rad with
// the tolerance's margin: far outside the path's zero-width slew interval (0 +- 0.02), so the
// move would go on to its waypoint (the rest of the descent). But the slew's reference rests at 0:
// the planner's stop keeps it there and the tracking brings the slew back, so the soft stop ends
// at 0 on the slew; the hoist, whose reference moves, stops from its speed: 0.2 x 0.1 + 0.2^2 /
// (2 x 0.5) = 0.06 m, to 0.6 m with the margin, inside 0.2-1.0 m.
TEST(GrantGuard, AnAxisWhoseReferenceRestsEndsItsSoftStopThere) {
  const SiteLayout site = two_towers();
  GrantGuard guard(site, 0);
  guard.grant(path_airspace(std::vector<Pose>{{0.0, 0.6, 0.2}, {0.0, 0.6, 1.0}}, site.paths), 10.0);
  ASSERT_TRUE(in_shared_airspace(site, 0, guard.granted()));
  CraneMotion m;
  m.slew = 0.007;
  m.slew_rate = 0.09;
  m.trolley = 0.6;
  m.cable_length = 0.5;
  m.cable_rate = 0.2;
  const double lost = 10.0 + 1.1 * site.link_deadline;
  EXPECT_NEAR(stopping_travel(site.cranes[0], m, StopKind::soft).slew,
              0.009 + 0.0081 + 0.09 * 2.0 * kPi * std::sqrt(0.5 / kStandardGravity) / 2.0, 1e-12);
  EXPECT_NEAR(stopping_travel(site.cranes[0], m, StopKind::soft).cable, 0.06, 1e-12);
  // The guard alone (the supervisor's, which does not read the reference): the move goes on.
  EXPECT_FALSE(guard.soft_stop_stays_in_grant(m));
  EXPECT_EQ(guard.check(m, lost).action, GrantAction::finish_path);

  crane::protocol::Reference r{};
  r.slew_angle = 0.0;
  r.trolley_position = 0.6;
  r.cable_length = 0.5;
  r.cable_length_rate = 0.2;
  const ReferenceRest rest = reference_rest_of(r);
  ASSERT_TRUE(rest.slew.has_value() && rest.trolley.has_value());
  EXPECT_EQ(*rest.slew, 0.0);
  EXPECT_FALSE(rest.cable_length.has_value());
  EXPECT_TRUE(guard.soft_stop_stays_in_grant(m, rest));
  // A reference that rests outside the slew interval by more than the tolerance does not count as
  // inside; one still turning, or still accelerating from rest, stops from the measured speed.
  r.slew_angle = 0.03;
  EXPECT_FALSE(guard.soft_stop_stays_in_grant(m, reference_rest_of(r)));
  r.slew_angle = 0.0;
  r.slew_rate = 1e-3;
  EXPECT_FALSE(guard.soft_stop_stays_in_grant(m, reference_rest_of(r)));
  r.slew_rate = 0.0;
  r.slew_acceleration = 0.1;
  EXPECT_FALSE(guard.soft_stop_stays_in_grant(m, reference_rest_of(r)));
  r.slew_acceleration = 0.0;
  // The hoist's own stop must still end inside: lowering at 0.2 m/s from 0.95 m ends at 1.05 m with
  // the margin, past 1.0 m and the tolerance.
  m.cable_length = 0.95;
  EXPECT_FALSE(guard.soft_stop_stays_in_grant(m, reference_rest_of(r)));
  // Non-finite references are not at rest; a non-finite resting position is not inside.
  m.cable_length = 0.5;
  r.slew_rate = std::nan("");
  EXPECT_FALSE(reference_rest_of(r).slew.has_value());
  EXPECT_FALSE(guard.soft_stop_stays_in_grant(m, ReferenceRest{std::nan(""), 0.6, std::nullopt}));
}

// Progress within a segment (grant_guard.hpp), by hand: the point a crane has passed on each axis,
// in whole steps, and which reports narrow what a crane holds of its grant.
TEST(GrantGuard, ProgressWithinASegmentByHand) {
  ASSERT_DOUBLE_EQ(kProgressStep, 0.1);
  const Pose from{0.0, 0.5, 0.2};
  const Pose to{1.0, 0.9, 0.2};
  // The slew 0.57 rad on: 5 steps; the trolley 0.27 m on: 2 steps; the hoist does not move here.
  Pose p = passed_point(from, to, {0.57, 0.77, 0.2}, from);
  EXPECT_NEAR(p.slew, 0.5, 1e-12);
  EXPECT_NEAR(p.trolley, 0.7, 1e-12);
  EXPECT_DOUBLE_EQ(p.cable_length, 0.2);
  // Pulled back: nothing passed is given back.
  p = passed_point(from, to, {0.45, 0.62, 0.2}, p);
  EXPECT_NEAR(p.slew, 0.5, 1e-12);
  EXPECT_NEAR(p.trolley, 0.7, 1e-12);
  // Within each axis's last step: a step short of `to` (the slew 0.9, the trolley 0.8).
  p = passed_point(from, to, {0.99, 0.9, 0.2}, p);
  EXPECT_NEAR(p.slew, 0.9, 1e-12);
  EXPECT_NEAR(p.trolley, 0.8, 1e-12);
  // 0.6 m of trolley is six steps in doubles too (0.6 / 0.1 = 5.999999999999999): 0.8 at most.
  EXPECT_NEAR(passed_point({0.0, 0.3, 0.2}, {0.0, 0.9, 0.2}, {0.0, 0.9, 0.2}, {0.0, 0.3, 0.2}).trolley, 0.8, 1e-12);
  // Backwards along an axis (the slew from 1.0 to 0.0), an axis shorter than two steps, NaN.
  EXPECT_NEAR(passed_point(to, from, {0.62, 0.9, 0.2}, to).slew, 0.7, 1e-12);
  EXPECT_DOUBLE_EQ(passed_point(from, {0.15, 0.5, 0.2}, {0.15, 0.5, 0.2}, from).slew, 0.0);
  EXPECT_DOUBLE_EQ(passed_point(from, to, {std::nan(""), 0.5, 0.2}, from).slew, 0.0);

  const std::vector<Pose> granted{{0.0, 0.5, 1.5}, {0.0, 0.5, 0.2}, {1.0, 1.0, 0.2}, {1.0, 1.0, 1.5}};
  const auto on_travel = [&](double slew, double trolley) {
    return std::vector<Pose>{{slew, trolley, 0.2}, granted[2], granted[3]};
  };
  const std::vector<Pose> none;
  EXPECT_FALSE(narrows(granted, none, granted)) << "the whole grant is not progress";
  EXPECT_TRUE(narrows(granted, none, std::vector<Pose>(granted.begin() + 1, granted.end()))) << "a waypoint reached";
  EXPECT_TRUE(narrows(granted, none, on_travel(0.4, 0.5)));
  EXPECT_TRUE(narrows(granted, on_travel(0.4, 0.5), on_travel(0.4, 0.6))) << "one axis further, none back";
  EXPECT_FALSE(narrows(granted, on_travel(0.4, 0.6), on_travel(0.5, 0.5))) << "the trolley back: it would widen";
  EXPECT_FALSE(narrows(granted, on_travel(0.4, 0.6), on_travel(0.4, 0.6)));
  EXPECT_TRUE(narrows(granted, on_travel(0.9, 0.9), std::vector<Pose>(granted.begin() + 2, granted.end())));
  EXPECT_TRUE(narrows(granted, on_travel(0.9, 0.9), std::vector<Pose>{granted[3]}));
  EXPECT_FALSE(narrows(granted, std::vector<Pose>(granted.begin() + 2, granted.end()), on_travel(0.9, 0.9)))
      << "an earlier segment";
  // Off the segment: the trolley beyond its end, the hoist on a travel segment, the segment's end
  // itself with the waypoints of the segment before.
  EXPECT_FALSE(narrows(granted, none, on_travel(0.5, 1.1)));
  std::vector<Pose> hook_down = on_travel(0.5, 0.7);
  hook_down[0].cable_length = 0.3;
  EXPECT_FALSE(narrows(granted, none, hook_down));
  EXPECT_FALSE(narrows(granted, none, on_travel(1.0, 1.0)));
  // Another tail, a longer path than the grant, nothing, or a waypoint within kPathTolerance (the
  // site link's rounding of a cable length).
  std::vector<Pose> other_tail = on_travel(0.5, 0.7);
  other_tail[2].cable_length = 1.4;
  EXPECT_FALSE(narrows(granted, none, other_tail));
  std::vector<Pose> longer = granted;
  longer.push_back({1.0, 1.0, 0.2});
  EXPECT_FALSE(narrows(granted, none, longer));
  EXPECT_FALSE(narrows(granted, none, none));
  EXPECT_FALSE(narrows(none, none, granted));
  std::vector<Pose> rounded = on_travel(0.5, 0.7);
  rounded[1].cable_length += 1e-9;
  EXPECT_TRUE(narrows(granted, none, rounded));
  // A point of a hoist-only segment (the cable 0.85 m, half way up).
  EXPECT_TRUE(narrows(granted, none, std::vector<Pose>{{0.0, 0.5, 0.85}, granted[1], granted[2], granted[3]}));
}

// The site service takes a crane's progress within a segment: what the crane has passed is free
// for the others before it reaches its next waypoint; a report that would widen what it holds, or
// one off its path, changes nothing.
TEST(SiteService, ACraneFreesTheSegmentItHasPassed) {
  SiteService service(two_towers(), ArbiterMode::coordinated, 77);
  const Pose a_rest{-1.5, 0.5, 0.2};
  // B slews its load, hook down at 1.5 m (from 3.0 m to 1.5 m high), away from over A's jib line.
  const std::vector<Pose> b_path{{kPi, 1.0, 1.5}, {kPi - 1.5, 1.0, 1.5}};
  ASSERT_EQ(service.report(at_rest(0, a_rest), 0.0), "");
  ASSERT_EQ(service.report(at_rest(1, b_path[0], 5, b_path), 0.0), "");
  auto orders = service.step(0.01);
  ASSERT_EQ(orders.size(), 1u);
  ASSERT_EQ(orders[0].crane, 1u);
  CraneReport moving;
  moving.crane = 1;
  moving.moving = true;
  moving.instruction_epoch = 77;
  moving.instruction_seq = orders[0].seq;
  moving.waypoints = b_path;
  ASSERT_EQ(service.report(moving, 0.1), "");
  // A asks to turn its jib to heading 0, under where B's load starts: it waits for B.
  ASSERT_EQ(service.report(at_rest(0, a_rest, 9, {a_rest, {0.0, 0.5, 0.2}}), 0.2), "");
  EXPECT_TRUE(service.step(0.2).empty());
  ASSERT_EQ(service.arbiter().waits_for(0), std::vector<std::size_t>{1u});
  // B has passed 0.1 rad of its slew: its load still over A's jib line. A waits.
  moving.waypoints = {{kPi - 0.1, 1.0, 1.5}, b_path[1]};
  ASSERT_EQ(service.report(moving, 0.3), "");
  EXPECT_NEAR(service.arbiter().held(1).boxes[0].slew_high, kPi - 0.1, 1e-12);
  EXPECT_TRUE(service.step(0.3).empty());
  // A report off B's path, and one behind what it holds, change nothing.
  CraneReport off = moving;
  off.waypoints[0].trolley = 0.8;
  ASSERT_EQ(service.report(off, 0.35), "");
  CraneReport behind = moving;
  behind.waypoints[0] = {kPi - 0.05, 1.0, 1.5};
  ASSERT_EQ(service.report(behind, 0.35), "");
  EXPECT_NEAR(service.arbiter().held(1).boxes[0].slew_high, kPi - 0.1, 1e-12);
  // 0.7 rad on, B's load 0.64 m off A's jib line (1.0 sin 0.7): A goes, B still on its way.
  moving.waypoints = {{kPi - 0.7, 1.0, 1.5}, b_path[1]};
  ASSERT_EQ(service.report(moving, 0.4), "");
  orders = service.step(0.4);
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].crane, 0u);
  EXPECT_EQ(orders[0].request_id, 9u);
  EXPECT_EQ(service.arbiter().holding(1), Holding::path);
}

TEST(SiteService, AGrantIsHeldUntilCarriedOutThenFollowsTheCranesProgress) {
  SiteService service(two_towers(), ArbiterMode::coordinated, 77);
  EXPECT_EQ(service.arbiter().holding(0), Holding::whole_reach);  // nothing allowed by default
  const Pose a_rest{-1.5, 0.5, 0.2};
  const Pose b_rest{kPi - 1.5, 0.5, 0.2};
  const std::vector<Pose> b_leg{b_rest, {kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}};
  ASSERT_EQ(service.report(at_rest(0, a_rest), 0.0), "");
  ASSERT_EQ(service.report(at_rest(1, b_rest, 5, b_leg), 0.0), "");
  EXPECT_EQ(service.arbiter().holding(0), Holding::rest);
  auto orders = service.step(0.01);
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].crane, 1u);
  EXPECT_EQ(orders[0].kind, Instruction::Kind::go);
  EXPECT_EQ(orders[0].request_id, 5u);
  EXPECT_EQ(orders[0].seq, 1u);
  EXPECT_EQ(orders[0].waypoints.size(), 3u);
  // B's next report was sent before it heard the grant: at rest, still asking for 5. The service
  // keeps the path and does not take the request again.
  ASSERT_EQ(service.report(at_rest(1, b_rest, 5, b_leg), 0.05), "");
  EXPECT_EQ(service.arbiter().holding(1), Holding::path);
  EXPECT_FALSE(service.arbiter().pending(1));
  // Not carried out after kResendPeriod: sent again, the same seq.
  EXPECT_TRUE(service.step(0.2).empty());
  ASSERT_EQ(service.report(at_rest(1, b_rest, 5, b_leg), 0.45), "");  // still not heard
  ASSERT_EQ(service.report(at_rest(0, a_rest), 0.45), "");
  orders = service.step(0.01 + SiteService::kResendPeriod);
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].seq, 1u);
  // B carries it out: moving, past its first waypoint.
  CraneReport moving;
  moving.crane = 1;
  moving.moving = true;
  moving.waypoints = {b_leg[1], b_leg[2]};
  moving.instruction_epoch = 77;
  moving.instruction_seq = 1;
  ASSERT_EQ(service.report(moving, 0.6), "");
  EXPECT_EQ(service.arbiter().holding(1), Holding::path);
  EXPECT_EQ(service.arbiter().held(1).count, 1u);  // the rest of the path: one box
  EXPECT_TRUE(service.step(1.2).empty());           // carried out: not sent again
  // A asks to turn under B's lowering load: it waits; B hoists up and rests, and A goes.
  ASSERT_EQ(service.report(at_rest(0, a_rest, 9, {a_rest, {0.0, 0.5, 0.2}}), 1.3), "");
  ASSERT_EQ(service.report(moving, 1.3), "");
  EXPECT_TRUE(service.step(1.3).empty());
  ASSERT_EQ(service.arbiter().waits_for(0).size(), 1u);
  CraneReport done = at_rest(1, {kPi, 1.0, 0.2});
  done.instruction_epoch = 77;
  done.instruction_seq = 1;
  ASSERT_EQ(service.report(done, 1.4), "");
  EXPECT_EQ(service.arbiter().holding(1), Holding::rest);
  orders = service.step(1.4);
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].crane, 0u);
  EXPECT_EQ(orders[0].request_id, 9u);
  EXPECT_EQ(orders[0].seq, 2u);
}

// A crane heard from for no longer than link_deadline is lost: the service holds its whole reach
// and drops its request; it holds the pose's box again once the crane reports at rest. A report
// from the crane moving, then, does not give it back its path.
TEST(SiteService, ASilentCraneIsLostAndComesBackAtRest) {
  SiteLayout s = two_towers();
  s.link_deadline = 0.3;
  SiteService service(s, ArbiterMode::coordinated, 3);
  const Pose a_rest{-1.5, 0.5, 0.2};
  ASSERT_EQ(service.report(at_rest(0, a_rest, 4, {a_rest, {-1.0, 0.5, 0.2}}), 0.0), "");
  ASSERT_EQ(service.report(at_rest(1, {kPi - 1.5, 0.5, 0.2}), 0.0), "");
  ASSERT_EQ(service.step(0.0).size(), 1u);  // A's leg granted
  EXPECT_TRUE(service.heard(0, 0.3));
  EXPECT_FALSE(service.heard(0, 0.31));
  ASSERT_EQ(service.report(at_rest(1, {kPi - 1.5, 0.5, 0.2}), 0.25), "");
  (void)service.step(0.31);
  EXPECT_EQ(service.arbiter().holding(0), Holding::whole_reach);
  EXPECT_EQ(service.arbiter().holding(1), Holding::rest);  // heard at 0.25
  CraneReport moving;
  moving.crane = 0;
  moving.moving = true;
  moving.waypoints = {a_rest, {-1.0, 0.5, 0.2}};
  moving.instruction_epoch = 3;
  moving.instruction_seq = 1;
  ASSERT_EQ(service.report(moving, 0.4), "");
  EXPECT_EQ(service.arbiter().holding(0), Holding::whole_reach);
  ASSERT_EQ(service.report(at_rest(0, {-1.2, 0.5, 0.2}), 0.5), "");
  EXPECT_EQ(service.arbiter().holding(0), Holding::rest);
  EXPECT_DOUBLE_EQ(service.arbiter().held(0).boxes[0].slew_low, -1.2);
}

// The operator's word through the service (rt/site/command): refused while the crane reports, for
// an unknown crane and by a restarted service that never knew the crane; taken once the crane is
// silent past link_deadline, shown in the status (HOLDING_OUT_OF_SERVICE), idempotent; the crane's
// report at rest brings it back, one moving takes its whole reach.
TEST(SiteService, AnOperatorPutsASilentCraneOutOfService) {
  SiteLayout s = two_towers();
  s.link_deadline = 0.3;
  SiteService service(s, ArbiterMode::coordinated, 3);
  const Pose a_rest{-1.5, 0.5, 0.2};
  ASSERT_EQ(service.report(at_rest(0, a_rest), 0.0), "");
  ASSERT_EQ(service.report(at_rest(1, {kPi, 1.0, 0.2}, 6, {{kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}}), 0.0), "");
  ASSERT_EQ(service.step(0.0).size(), 1u);  // B lowers
  EXPECT_EQ(service.out_of_service(0, 0.1), "site service: a was heard 0.10 s ago: a crane that reports is not out of service");
  EXPECT_EQ(service.out_of_service(2, 0.1), "site service: crane 2 is not on the site (2 cranes)");
  EXPECT_EQ(service.out_of_service(0, 0.31), "");  // silent: lost, then out of service
  EXPECT_EQ(service.arbiter().holding(0), Holding::out_of_service);
  EXPECT_EQ(service.out_of_service(0, 0.4), "");
  (void)service.step(0.4);
  EXPECT_EQ(service.arbiter().holding(0), Holding::out_of_service);  // step does not take it back
  crane::protocol::SiteStatus status;
  to_message(service, 0.4, status);
  EXPECT_EQ(status.holding[0], crane::protocol::SiteStatus::HOLDING_OUT_OF_SERVICE);
  ASSERT_EQ(service.report(at_rest(0, a_rest), 0.5), "");
  EXPECT_EQ(service.arbiter().holding(0), Holding::rest);
  (void)service.step(0.9);
  ASSERT_EQ(service.out_of_service(0, 0.9), "");
  CraneReport moving;
  moving.crane = 0;
  moving.moving = true;
  moving.waypoints = {a_rest, {-1.0, 0.5, 0.2}};
  ASSERT_EQ(service.report(moving, 1.0), "");
  EXPECT_EQ(service.arbiter().holding(0), Holding::whole_reach);
  EXPECT_EQ(service.moves_without_grant(), 1u);

  SiteService restarted(s, ArbiterMode::coordinated, 4);
  (void)restarted.step(1.0);
  EXPECT_EQ(restarted.out_of_service(0, 1.0),
            "site arbiter: crane a went silent where this service did not know it stood (never heard at rest or on a grant, with no "
            "memory of it, or it moved without a grant): its whole reach stays held");
  EXPECT_EQ(restarted.arbiter().holding(0), Holding::whole_reach);
}

// The status (rt/site/status) says who waits for whom, why and since when: B lowers on its grant,
// A's later request to turn its jib under B's load waits for what B holds, asked at 0.5 s and
// reported again since (the same request: its time stays). The IDL's WAIT_* names are the
// arbiter's.
TEST(SiteService, TheStatusSaysWhoWaitsForWhomWhyAndForHowLong) {
  SiteService service(two_towers(), ArbiterMode::coordinated, 3);
  const Pose a_rest{-1.5, 0.5, 0.2};
  const Pose b_rest{kPi - 1.5, 0.5, 0.2};
  const CraneReport b = at_rest(1, b_rest, 1, {b_rest, {kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}});
  ASSERT_EQ(service.report(at_rest(0, a_rest), 0.0), "");
  ASSERT_EQ(service.report(b, 0.0), "");
  ASSERT_EQ(service.step(0.0).size(), 1u);  // B goes
  const CraneReport a = at_rest(0, a_rest, 7, {a_rest, {0.0, 0.5, 0.2}});
  ASSERT_EQ(service.report(a, 0.5), "");
  EXPECT_TRUE(service.step(0.5).empty());
  ASSERT_EQ(service.report(a, 2.0), "");
  (void)service.step(2.0);
  crane::protocol::SiteStatus status;
  to_message(service, 2.5, status);
  using crane::protocol::SiteStatus;
  EXPECT_TRUE(status.pending[0]);
  EXPECT_EQ(status.waits_for[0], 1u << 1);
  EXPECT_EQ(waits_for_names(service.arbiter().layout(), status, 0), std::vector<std::string>{"b"});
  EXPECT_TRUE(waits_for_names(service.arbiter().layout(), status, 1).empty());
  EXPECT_TRUE(waits_for_names(service.arbiter().layout(), status, 5).empty());  // beyond crane_count
  EXPECT_EQ(status.wait_reason[0], SiteStatus::WAIT_HELD);
  EXPECT_DOUBLE_EQ(status.waited[0], 2.0);
  EXPECT_FALSE(status.pending[1]);
  EXPECT_EQ(status.wait_reason[1], SiteStatus::WAIT_NONE);
  EXPECT_EQ(status.waited[1], 0.0);
  for (const WaitReason reason : {WaitReason::none, WaitReason::held, WaitReason::starving, WaitReason::higher_cable,
                                  WaitReason::most_work_left}) {
    EXPECT_EQ(crane::protocol::code_name(SiteStatus::kCodes, "WAIT", wait_code(reason)), to_string(reason));
  }
}

void expect_same_airspace(const Airspace& a, const Airspace& b) {
  ASSERT_EQ(a.count, b.count);
  for (std::size_t k = 0; k < a.count; ++k) {
    const JointBox& x = a.boxes[k];
    const JointBox& y = b.boxes[k];
    EXPECT_EQ(x.slew_low, y.slew_low) << k;
    EXPECT_EQ(x.slew_high, y.slew_high) << k;
    EXPECT_EQ(x.trolley_low, y.trolley_low) << k;
    EXPECT_EQ(x.trolley_high, y.trolley_high) << k;
    EXPECT_EQ(x.cable_low, y.cable_low) << k;
    EXPECT_EQ(x.cable_high, y.cable_high) << k;
    EXPECT_EQ(x.swing_radius, y.swing_radius) << k;
  }
}

// The service's memory across its own restart (SiteService::memory and recall; site_service
// --memory, site_memory.hpp): A rests (its load swinging 0.03 rad), B lowers on its grant; both go
// silent and the service restarts. Without the memory the operator's word is refused for both; with
// it, A is held in its rest box braked from its remembered motion, exactly as the service before
// would have held it, and B on its path as it was held (travel and hoist allowances): the memory's
// motion may be older than B's stop. Nothing is granted on a memory; the memory reads back from its
// file to the bit; a crane out of service stays so; a crane heard moving from a remembered rest
// forgets it; bad memories are refused whole, the crane and the box named.
TEST(SiteService, ARestartedServiceRecallsWhereASilentCraneStood) {
  SiteLayout s = two_towers();
  s.link_deadline = 0.3;
  SiteService before(s, ArbiterMode::coordinated, 3);
  const Pose a_rest{-1.5, 0.5, 0.2};
  CraneReport a = at_rest(0, a_rest);
  a.motion = {-1.5, 0.0, 0.5, 0.0, 0.2, 0.0, 0.03, 0.0, 0.0, 0.0};
  ASSERT_EQ(before.report(a, 0.0), "");
  const std::vector<Pose> b_path{{kPi, 1.0, 0.2}, {kPi, 1.0, 2.0}};
  ASSERT_EQ(before.report(at_rest(1, b_path[0], 6, b_path), 0.0), "");
  const std::vector<SiteOrder> go = before.step(0.0);
  ASSERT_EQ(go.size(), 1u);  // B lowers
  CraneReport b;
  b.crane = 1;
  b.moving = true;
  b.waypoints = b_path;
  b.instruction_epoch = 3;
  b.instruction_seq = go[0].seq;
  b.motion = {kPi, 0.0, 1.0, 0.0, 0.4, 0.2, 0.0, 0.0, 0.0, 0.0};
  ASSERT_EQ(before.report(b, 0.05), "");
  ASSERT_EQ(before.arbiter().holding(1), Holding::path);
  const Airspace b_held = before.arbiter().held(1);
  SiteService reference = before;  // the word, given to the service before its restart
  ASSERT_EQ(reference.out_of_service(0, 0.4), "");

  const SiteMemory memory = before.memory();
  const std::string text = memory_to_json(memory, s);
  const SiteMemory read = memory_from_json(text, s, "memory.json");
  EXPECT_EQ(memory_to_json(read, s), text);
  EXPECT_TRUE(same_memory(read, memory));
  EXPECT_FALSE(same_memory(read, reference.memory()));  // a out of service there
  SiteMemory moved_a = read;
  moved_a[0].motion.swing_in_plane = 0.031;
  EXPECT_FALSE(same_memory(read, moved_a));
  EXPECT_FALSE(same_memory(read, SiteMemory(2)));
  ASSERT_TRUE(read[0].place && read[1].place);
  EXPECT_FALSE(read[0].place->moving);
  EXPECT_TRUE(read[1].place->moving);
  expect_same_airspace(read[1].place->airspace, b_held);
  EXPECT_EQ(read[0].motion.swing_in_plane, 0.03);

  SiteService without(s, ArbiterMode::coordinated, 4);
  EXPECT_EQ(without.out_of_service(0, 1.0),
            "site arbiter: crane a went silent where this service did not know it stood (never heard at rest or on a grant, with no "
            "memory of it, or it moved without a grant): its whole reach stays held");
  EXPECT_EQ(without.out_of_service(1, 1.0),
            "site arbiter: crane b went silent where this service did not know it stood (never heard at rest or on a grant, with no "
            "memory of it, or it moved without a grant): its whole reach stays held");

  SiteService after(s, ArbiterMode::coordinated, 4);
  ASSERT_EQ(after.recall(read), "");
  EXPECT_TRUE(after.step(1.0).empty());
  EXPECT_EQ(after.arbiter().holding(0), Holding::whole_reach);  // nothing granted on a memory
  EXPECT_EQ(after.arbiter().holding(1), Holding::whole_reach);
  ASSERT_EQ(after.out_of_service(0, 1.0), "");
  expect_same_airspace(after.arbiter().held(0), reference.arbiter().held(0));
  EXPECT_GT(after.arbiter().held(0).boxes[0].swing_radius, 0.2 * std::sin(0.03));  // braked from its swing
  ASSERT_EQ(after.out_of_service(1, 1.0), "");
  expect_same_airspace(after.arbiter().held(1), b_held);

  // Out of service before the restart: so again at once after it.
  SiteService again(s, ArbiterMode::coordinated, 5);
  ASSERT_EQ(again.recall(reference.memory()), "");
  EXPECT_EQ(again.arbiter().holding(0), Holding::out_of_service);
  expect_same_airspace(again.arbiter().held(0), reference.arbiter().held(0));

  // Heard moving from a remembered rest: a move without a grant, the place forgotten. From a
  // remembered path: it may be finishing it, the place kept.
  SiteService moved(s, ArbiterMode::coordinated, 6);
  ASSERT_EQ(moved.recall(read), "");
  CraneReport a_moving = a;
  a_moving.moving = true;
  a_moving.waypoints = {a_rest, {-1.0, 0.5, 0.2}};
  ASSERT_EQ(moved.report(a_moving, 1.0), "");
  b.instruction_seq = 0;  // an instruction of the service before: not this one's
  ASSERT_EQ(moved.report(b, 1.0), "");
  (void)moved.step(1.5);
  EXPECT_EQ(moved.out_of_service(0, 1.5),
            "site arbiter: crane a went silent where this service did not know it stood (never heard at rest or on a grant, with no "
            "memory of it, or it moved without a grant): its whole reach stays held");
  EXPECT_EQ(moved.out_of_service(1, 1.5), "");

  // At rest, then moving without a grant, then silent: where it stood says nothing any more.
  SiteService rogue(s, ArbiterMode::coordinated, 9);
  ASSERT_EQ(rogue.report(a, 0.0), "");
  ASSERT_EQ(rogue.report(a_moving, 0.1), "");
  EXPECT_EQ(rogue.moves_without_grant(), 1u);
  (void)rogue.step(0.5);
  EXPECT_NE(rogue.out_of_service(0, 0.5).find("its whole reach stays held"), std::string::npos);
  EXPECT_EQ(rogue.arbiter().holding(0), Holding::whole_reach);

  // Refused whole: heard already, another site's size, a bad box (crane a's place not recalled).
  SiteService heard(s, ArbiterMode::coordinated, 7);
  ASSERT_EQ(heard.report(a, 1.0), "");
  EXPECT_EQ(heard.recall(read), "site service: crane a was heard already: a memory is recalled only at the start");
  SiteService bad(s, ArbiterMode::coordinated, 8);
  EXPECT_EQ(bad.recall(SiteMemory(3)), "site service: the memory has 3 cranes, the site 2");
  SiteMemory broken = read;
  broken[1].place->airspace.boxes[0].cable_low = std::nan("");
  EXPECT_EQ(bad.recall(broken).rfind("site service: the memory refused: site arbiter: crane b's recalled box 0 (slew", 0),
            0u)
      << bad.recall(broken);
  broken[1].place->airspace.boxes[0].cable_low = 3.0;  // above its high end
  EXPECT_NE(bad.recall(broken).find("crane b's recalled box 0"), std::string::npos);
  broken[1].place->airspace.count = 0;
  EXPECT_EQ(bad.recall(broken),
            "site service: the memory refused: site arbiter: crane b's recalled place has 0 boxes: must be in [1, 8]");
  broken = read;
  broken[0].place.reset();
  broken[0].out_of_service = true;
  EXPECT_EQ(bad.recall(broken),
            "site service: the memory refused: site arbiter: crane a is out of service in the memory but has no place");
  (void)bad.step(2.0);
  EXPECT_NE(bad.out_of_service(0, 2.0), "");  // nothing recalled
  EXPECT_NE(bad.out_of_service(1, 2.0), "");
}

// The memory's file (site_memory.hpp): written whole and read back; a missing file is no memory;
// a bad one is refused with the field and the value named.
TEST(SiteMemory, TheFileIsReadBackOrRefusedWithTheFieldNamed) {
  const SiteLayout s = two_towers();
  SiteMemory memory(2);
  memory[0].place = SiteArbiter::Place{rest_airspace({0.1, 0.7, 0.3}, s.paths), false};
  memory[0].motion.slew_rate = 1.0 / 3.0;
  const std::string text = memory_to_json(memory, s);
  const std::string path = ::testing::TempDir() + "site_memory_test.json";
  std::remove(path.c_str());
  EXPECT_FALSE(read_memory_file(path, s).has_value());
  write_memory_file(path, text);
  const auto back = read_memory_file(path, s);
  ASSERT_TRUE(back.has_value());
  EXPECT_EQ(memory_to_json(*back, s), text);
  EXPECT_EQ((*back)[0].motion.slew_rate, 1.0 / 3.0);
  EXPECT_FALSE((*back)[1].place.has_value());
  EXPECT_THROW(write_memory_file("/nonexistent-dir/memory.json", text), std::runtime_error);
  EXPECT_THROW((void)memory_to_json(SiteMemory(1), s), std::invalid_argument);

  const auto refused = [&](std::string changed, const std::string& from, const std::string& to) {
    const auto at = changed.find(from);
    if (at == std::string::npos) return "'" + from + "' not in the file";
    changed.replace(at, from.size(), to);
    try {
      (void)memory_from_json(changed, s, "m.json");
    } catch (const crane::common::ConfigError& error) {
      return std::string(error.what());
    }
    return std::string("not refused");
  };
  EXPECT_EQ(refused("[]", "[]", "[1]"), "m.json: the file is not an object");
  EXPECT_EQ(refused(text, "\"cranes\"", "x").substr(0, 30), "m.json: the file is not JSON: ");
  // A number beyond a double is nlohmann's out_of_range, not its parse_error (found by fuzz.site_memory).
  EXPECT_EQ(refused(text, "\"trolley\": 0.5", "\"trolley\": 1e99999").substr(0, 30), "m.json: the file is not JSON: ");
  EXPECT_EQ(refused(text, "memory 1", "memory 2"),
            "m.json: format = \"crane site service memory 2\": must be \"crane site service memory 1\"");
  EXPECT_EQ(refused(text, "\"site\": \"" + s.name + "\"", "\"site\": \"other\""),
            "m.json: site = \"other\": the site file is '" + s.name + "'");
  EXPECT_EQ(refused(text, "\"name\": \"b\"", "\"name\": \"c\""),
            "m.json: cranes[1].name = \"c\": the site file's crane 1 is 'b'");
  EXPECT_EQ(refused(text, "\"moving\": false", "\"moving\": 0"), "m.json: cranes[0].place.moving = 0 is not true or false");
  EXPECT_EQ(refused(text, "\"slew_rate\"", "\"slew_speed\""), "m.json: cranes[0].motion.slew_rate is missing");
  EXPECT_EQ(refused(text, "\"trolley\": 0.5", "\"trolley\": \"x\""),
            "m.json: cranes[0].motion.trolley = \"x\" is not a number");
  // A box of 6 numbers: its first number and the comma after it taken out.
  const std::size_t open = text.find('[', text.find('[', text.find("\"boxes\"")) + 1);
  const std::size_t comma = text.find(',', open);
  EXPECT_EQ(refused(text, text.substr(open, comma + 1 - open), "["), "m.json: cranes[0].place.boxes[0] has 6 numbers: must be 7");
  EXPECT_EQ(refused(text, "\"place\": null", "\"place\": {\"moving\": true, \"boxes\": []}"),
            "m.json: cranes[1].place.boxes has 0 boxes: must be 1 to 8");
}

// A crane that moves while the service holds only its rest box has no grant: its whole reach is
// held; a restarted service (another epoch) does not take a crane's echo of the old service's
// instruction numbers for its own.
TEST(SiteService, MovingWithoutAGrantAndARestartedService) {
  SiteService service(two_towers(), ArbiterMode::coordinated, 1);
  const Pose a_rest{-1.5, 0.5, 0.2};
  ASSERT_EQ(service.report(at_rest(0, a_rest), 0.0), "");
  CraneReport rogue;
  rogue.crane = 0;
  rogue.moving = true;
  rogue.waypoints = {a_rest, {0.0, 0.5, 0.2}};
  ASSERT_EQ(service.report(rogue, 0.1), "");
  EXPECT_EQ(service.arbiter().holding(0), Holding::whole_reach);
  EXPECT_EQ(service.moves_without_grant(), 1u);

  SiteService restarted(two_towers(), ArbiterMode::coordinated, 2);
  CraneReport old_echo = at_rest(0, a_rest, 12, {a_rest, {-1.0, 0.5, 0.2}});
  old_echo.instruction_epoch = 1;
  old_echo.instruction_seq = 40;
  ASSERT_EQ(restarted.report(old_echo, 0.0), "");
  ASSERT_EQ(restarted.report(at_rest(1, {kPi - 1.5, 0.5, 0.2}), 0.0), "");
  const auto orders = restarted.step(0.0);
  ASSERT_EQ(orders.size(), 1u);
  EXPECT_EQ(orders[0].seq, 1u);
  // The same echo (epoch 1, seq 40) again: not this service's instruction 1, so the grant is kept.
  ASSERT_EQ(restarted.report(old_echo, 0.1), "");
  EXPECT_EQ(restarted.arbiter().holding(0), Holding::path);
}

// Each crane's work left, on its report (through the IDL message and back), reaches the rules:
// A asks with 50 s left, B rests with 20 s: A's request is rule 0's; B's 80 s: B is the crane with
// the most, and it asks for nothing, so none is.
TEST(SiteService, EachCranesWorkLeftReachesTheRules) {
  SiteLayout site = two_towers();
  site.most_work_left_first = true;
  SiteService service(site, ArbiterMode::coordinated, 5);
  const auto sent = [](CraneReport r, double work_left) {
    r.work_left = work_left;
    crane::protocol::SiteReport m{};
    to_message(r, m);
    CraneReport back;
    EXPECT_EQ(from_message(m, back), "");
    EXPECT_EQ(back.work_left, work_left);
    return back;
  };
  const Pose a_rest{-1.5, 0.5, 0.2};
  ASSERT_EQ(service.report(sent(at_rest(0, a_rest, 3, {a_rest, {-1.0, 0.5, 0.2}}), 50.0), 0.0), "");
  ASSERT_EQ(service.report(sent(at_rest(1, {kPi - 1.5, 0.5, 0.2}), 20.0), 0.0), "");
  EXPECT_EQ(service.arbiter().most_work_left(), std::optional<std::size_t>(0u));
  ASSERT_EQ(service.report(sent(at_rest(1, {kPi - 1.5, 0.5, 0.2}), 80.0), 0.05), "");
  EXPECT_EQ(service.arbiter().most_work_left(), std::nullopt);
}

// Malformed reports are refused with the field named, counted, and change nothing.
TEST(SiteService, MalformedReportsAreRefused) {
  SiteService service(two_towers(), ArbiterMode::coordinated, 5);
  const Pose a_rest{-1.5, 0.5, 0.2};
  EXPECT_EQ(service.report(at_rest(7, a_rest), 0.0), "site service: a report refused: crane 7 is not on the site (2 cranes)");
  CraneReport empty = at_rest(0, a_rest);
  empty.waypoints.clear();
  EXPECT_EQ(service.report(empty, 0.0),
            "site service: a report refused: waypoint_count = 0 is out of range: must be in [1, 9]");
  EXPECT_NE(service.report(at_rest(0, {std::nan(""), 0.5, 0.2}), 0.0).find("waypoint[0] (slew nan rad"),
            std::string::npos);
  EXPECT_NE(service.report(at_rest(0, {0.0, 0.5, 0.0}), 0.0).find("cable length is not > 0"), std::string::npos);
  EXPECT_EQ(service.report(at_rest(0, a_rest, 3, {a_rest}), 0.0),
            "site service: a report refused: request_count = 1 is out of range: must be in [2, 9] with request_id 3");
  EXPECT_NE(service.report(at_rest(0, a_rest, 3, {a_rest, {0.0, INFINITY, 0.2}}), 0.0).find("request[1]"),
            std::string::npos);
  CraneReport nan_motion = at_rest(0, a_rest);
  nan_motion.motion.swing_out_of_plane_rate = std::nan("");
  EXPECT_NE(service.report(nan_motion, 0.0).find("the measured motion (slew 0 rad"), std::string::npos);
  CraneReport negative_work = at_rest(0, a_rest);
  negative_work.work_left = -2.5;
  EXPECT_EQ(service.report(negative_work, 0.0),
            "site service: a report refused: work_left = -2.500000 s is not finite and >= 0");
  negative_work.work_left = INFINITY;
  EXPECT_NE(service.report(negative_work, 0.0).find("work_left = inf s"), std::string::npos);
  EXPECT_EQ(service.reports_rejected(), 9u);
  EXPECT_EQ(service.arbiter().holding(0), Holding::whole_reach);
  EXPECT_FALSE(service.heard(0, 0.0));
  EXPECT_THROW(SiteService(two_towers(), ArbiterMode::coordinated, 0), std::invalid_argument);
}

}  // namespace
