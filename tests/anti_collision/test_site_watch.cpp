// What an observer of the site's domain knows (site_watch.hpp): the distance between two cranes at
// their reports against a hand computation, the smallest over the watch, the airspace the service
// holds for a crane as its status and the crane's report say, what it asks for, bad messages
// ignored, and the plan outline of a box by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "crane/anti_collision/site_file.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/anti_collision/site_watch.hpp"

namespace {

using namespace crane::anti_collision;
using crane::protocol::SiteInstruction;
using crane::protocol::SiteReport;
using crane::protocol::SiteStatus;

const std::string kSite = std::string(CRANE_SOURCE_DIR) + "/deploy/config/site_three_towers.yaml";
constexpr double kPi = std::numbers::pi;

// Crane `crane` at rest at `pose` (or moving along `path`), still load.
SiteReport report_of(std::size_t crane, const Pose& pose, std::vector<Pose> path = {}) {
  CraneReport r;
  r.crane = crane;
  r.moving = !path.empty();
  r.waypoints = path.empty() ? std::vector<Pose>{pose} : path;
  SiteReport m{};
  to_message(r, m);
  CraneMotion motion;
  motion.slew = pose.slew;
  motion.trolley = pose.trolley;
  motion.cable_length = pose.cable_length;
  set_motion(motion, m);
  return m;
}

// tc1 (base (0, 0), jib along +x at slew 0, rails at 2.5 m) and tc2 (base (2, 0), jib along -x at
// slew 0, rails at 3.0 m), both trolleys at 0.9 m, cables 0.2 m, loads still. The jibs' capsules:
// axes at the chord's centre (2.54 m, 3.04 m), radius half the 0.06 x 0.08 m section's diagonal,
// 0.05 m. tc2's load hangs at (1.1, 0, 2.8), radius 0.05 m, over tc1's jib (x in [0, 1.4]): 0.26 m
// between the axes, less both radii: 0.16 m, the closest two parts (tc2's cable, radius 0 with no
// swing, from 3.0 to 2.8 m: 0.26 - 0.05 = 0.21 m; tc1's sheave at (0.9, 0, 2.5) under tc2's jib
// (x in [0.6, 2]): 0.54 - 0.05 = 0.49 m).
TEST(SiteWatch, TheDistanceBetweenTwoReportedCranesByHand) {
  SiteWatch watch(load_site_layout(kSite));
  EXPECT_TRUE(watch.distances().empty());
  EXPECT_FALSE(std::isfinite(watch.closest()));
  ASSERT_TRUE(watch.report(report_of(0, {0.0, 0.9, 0.2}), 1.0));
  EXPECT_TRUE(watch.distances().empty()) << "one crane reported";
  ASSERT_TRUE(watch.report(report_of(1, {0.0, 0.9, 0.2}), 2.0));
  const auto pairs = watch.distances();
  ASSERT_EQ(pairs.size(), 1u) << "tc3 has not reported";
  EXPECT_EQ(pairs[0].first, 0u);
  EXPECT_EQ(pairs[0].second, 1u);
  EXPECT_NEAR(pairs[0].distance.distance, 0.16, 1e-4);
  EXPECT_EQ(pairs[0].distance.first, Part::jib);
  EXPECT_EQ(pairs[0].distance.second, Part::load);
  // tc2 slews its jib away (90 deg): farther now; the closest stays the one seen at 2 s.
  ASSERT_TRUE(watch.report(report_of(1, {kPi / 2.0, 0.9, 0.2}), 3.0));
  EXPECT_GT(watch.distances()[0].distance.distance, 0.3);
  EXPECT_NEAR(watch.closest(), 0.16, 1e-4);
  EXPECT_EQ(watch.closest_parts(), "tc1.jib-tc2.load");
  EXPECT_DOUBLE_EQ(watch.closest_time(), 2.0);
  // The reports it paired: tc1's of 1 s, tc2's of 2 s, one second apart.
  ASSERT_EQ(watch.closest_reports().size(), 2u);
  EXPECT_EQ(watch.closest_reports()[0].crane, 0u);
  EXPECT_EQ(watch.closest_reports()[1].crane, 1u);
  EXPECT_DOUBLE_EQ(watch.closest_reports()[1].slew, 0.0);
  EXPECT_DOUBLE_EQ(watch.closest_apart(), 1.0);
  EXPECT_EQ(watch.cranes()[1].reports, 2u);
  EXPECT_DOUBLE_EQ(watch.cranes()[1].first_heard, 2.0);
  EXPECT_DOUBLE_EQ(watch.cranes()[1].heard, 3.0);
}

TEST(SiteWatch, WhatTheServiceHoldsAndWhatACraneAsksFor) {
  const SiteLayout layout = load_site_layout(kSite);
  SiteWatch watch(layout);
  const Pose here{0.0, 0.5, 0.2};
  SiteReport r = report_of(0, here);
  const std::vector<Pose> leg{here, {0.5, 0.5, 0.2}, {0.5, 0.8, 0.2}, {0.5, 0.8, 1.0}};
  r.request_id = 7;
  r.request_count = static_cast<std::uint8_t>(leg.size());
  for (std::size_t k = 0; k < leg.size(); ++k) {
    r.request_slew[k] = leg[k].slew;
    r.request_trolley[k] = leg[k].trolley;
    r.request_cable_length[k] = leg[k].cable_length;
  }
  ASSERT_TRUE(watch.report(r, 1.0));
  EXPECT_EQ(watch.held(0).count, 0u) << "no status yet: nothing known to be held";
  // One box a move: the slew and the trolley travel at one cable length, one move (stops_of).
  ASSERT_EQ(watch.requested(0).count, 2u);
  EXPECT_DOUBLE_EQ(watch.requested(0).boxes[0].trolley_high, 0.8 + layout.paths.trolley_overshoot + layout.paths.trolley_tracking);

  SiteStatus s{};
  s.epoch = 9;
  s.crane_count = 3;
  s.holding[0] = SiteStatus::HOLDING_REST;
  s.holding[1] = SiteStatus::HOLDING_WHOLE_REACH;
  watch.status(s, 1.1);
  const Airspace rest = watch.held(0);
  const Airspace expected = rest_airspace(here, layout.paths);
  ASSERT_EQ(rest.count, 1u);
  EXPECT_DOUBLE_EQ(rest.boxes[0].trolley_low, expected.boxes[0].trolley_low);
  EXPECT_DOUBLE_EQ(rest.boxes[0].slew_high, expected.boxes[0].slew_high);
  EXPECT_EQ(watch.held(1).count, 0u) << "tc2 has not reported";
  ASSERT_TRUE(watch.report(report_of(1, {0.0, 0.5, 0.2}), 1.2));
  EXPECT_EQ(watch.held(1).count, whole_reach(layout.cranes[1], layout.paths).count);

  // Granted: the instruction's path until the crane's report says it carried it out, then the
  // rest of its reported path.
  SiteOrder go;
  go.crane = 0;
  go.kind = Instruction::Kind::go;
  go.request_id = 7;
  go.seq = 4;
  go.waypoints = leg;
  SiteInstruction m{};
  to_message(go, 9, m);
  ASSERT_TRUE(watch.instruction(m));
  s.holding[0] = SiteStatus::HOLDING_PATH;
  watch.status(s, 1.3);
  EXPECT_EQ(watch.held(0).count, 3u);
  SiteReport moving = report_of(0, {0.5, 0.6, 0.2}, {leg[1], leg[2], leg[3]});
  moving.instruction_epoch = 9;
  moving.instruction_seq = 4;
  ASSERT_TRUE(watch.report(moving, 1.4));
  EXPECT_EQ(watch.held(0).count, 2u);
  EXPECT_EQ(watch.requested(0).count, 0u);
}

TEST(SiteWatch, MessagesItCannotPlaceAreIgnored) {
  SiteWatch watch(load_site_layout(kSite));
  EXPECT_FALSE(watch.report(report_of(5, {0.0, 0.5, 0.2}), 1.0)) << "no crane 5 on a site of 3";
  SiteReport bad = report_of(0, {0.0, 0.5, 0.2});
  bad.slew = std::nan("");
  EXPECT_FALSE(watch.report(bad, 1.0));
  bad = report_of(0, {0.0, 0.5, 0.2});
  bad.waypoint_count = 40;
  EXPECT_FALSE(watch.report(bad, 1.0));
  EXPECT_FALSE(watch.cranes()[0].report.has_value());
  SiteInstruction i{};
  i.crane = 9;
  i.waypoint_count = 2;
  EXPECT_FALSE(watch.instruction(i));
}

// tc1 (base (0, 0), heading 0), slew [0, 90 deg], trolley [0.5, 0.7] m, swing 0.1 m: what hangs
// reaches 0.1 + 0.05 (load radius) past the trolley's ends: radii 0.35 and 0.85 m; the arcs in
// 2 deg steps: 46 points each.
TEST(SiteWatch, ThePlanOutlineOfABoxByHand) {
  const SiteLayout layout = load_site_layout(kSite);
  JointBox box;
  box.slew_low = 0.0;
  box.slew_high = kPi / 2.0;
  box.trolley_low = 0.5;
  box.trolley_high = 0.7;
  box.swing_radius = 0.1;
  const auto outline = plan_outline(layout.cranes[0], box);
  ASSERT_EQ(outline.size(), 92u);
  EXPECT_NEAR(outline[0][0], 0.85, 1e-12);
  EXPECT_NEAR(outline[0][1], 0.0, 1e-12);
  EXPECT_NEAR(outline[45][0], 0.0, 1e-12);
  EXPECT_NEAR(outline[45][1], 0.85, 1e-12);
  EXPECT_NEAR(outline[46][1], 0.35, 1e-12);
  EXPECT_NEAR(outline[91][0], 0.35, 1e-12);
  // tc2 (base (2, 0), heading pi) at one slew: a segment along -x.
  box.slew_high = 0.0;
  const auto line = plan_outline(layout.cranes[1], box);
  ASSERT_EQ(line.size(), 2u);
  EXPECT_NEAR(line[0][0], 2.0 - 0.85, 1e-5);
  EXPECT_NEAR(line[1][0], 2.0 - 0.35, 1e-5);
}

}  // namespace
