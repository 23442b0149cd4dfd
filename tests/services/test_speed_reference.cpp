// Operator speed control and the soft stop (speed_reference.hpp), the no-go zone geometry
// (common/site.hpp) and the planner's zone guard and routes (zone_guard.hpp, zone_paths.hpp):
// analytic cases and cross-checks, no plant.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "crane/common/site.hpp"
#include "crane/common/validation.hpp"
#include "crane/trajectory_planner/speed_reference.hpp"
#include "crane/trajectory_planner/zone_guard.hpp"
#include "crane/trajectory_planner/zone_paths.hpp"

namespace {
using namespace crane;
using namespace crane::trajectory_planner;
constexpr double kDt = 0.01;
constexpr double kG = 9.8;

// The linearized swing of the load under the trolley's acceleration, L phi'' + g phi = -x''
// (semi-implicit Euler at a fine step): the residual amplitude after the reference comes to rest.
struct Pendulum {
  double L{1.0};
  double phi{0.0}, rate{0.0};
  void step(double trolley_acceleration, double dt) {
    constexpr int kSub = 20;
    for (int i = 0; i < kSub; ++i) {
      rate += (-kG * phi - trolley_acceleration) / L * (dt / kSub);
      phi += rate * (dt / kSub);
    }
  }
  [[nodiscard]] double amplitude() const { return std::hypot(phi, rate / std::sqrt(kG / L)); }
};

SpeedBounds wide_bounds() { return {{-100.0, -100.0, 0.2}, {100.0, 100.0, 5.0}, kG}; }

// With the hoist moving, the shaper retunes to the cable length every cycle while the prediction
// uses the current length: the predicted stopping distance is then close, not exact (the issue's
// bound: 5 % of the stopping distance); the exact case is the next test.
TEST(SpeedReference, RestPredictionWhileHoistingIsWithinFivePercentOfTheStoppingDistance) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> stick(-1.0, 1.0);
  std::uniform_int_distribution<int> cycles(1, 300);
  const ManualParams params;
  double worst = 0.0;
  for (const SpeedShaping shaping : {SpeedShaping::none, SpeedShaping::zv, SpeedShaping::zvd}) {
    for (int trial = 0; trial < 50; ++trial) {
      SpeedReference ref;
      common::MotionReference start;
      start.trolley.position = 0.5;
      start.cable_length.position = 1.0 + trial * 0.02;
      ref.start(start);
      const std::array<double, 3> target{stick(rng) * params.trolley.rated_speed, stick(rng) * params.slew.rated_speed,
                                         stick(rng) * params.hoist.rated_speed};
      const int n = cycles(rng);
      for (int k = 0; k < n; ++k) (void)ref.step(target, kDt, params, shaping, wide_bounds(), {}, 0);
      const auto predicted = ref.rest(kDt, params, shaping, wide_bounds());
      const auto from = ref.reference();
      int guard = 0;
      while (!ref.at_rest() && ++guard < 5000) (void)ref.step({0, 0, 0}, kDt, params, shaping, wide_bounds(), {}, 0);
      ASSERT_TRUE(ref.at_rest());
      const auto r = ref.reference();
      EXPECT_NEAR(predicted[2], r.cable_length.position, 1e-12);  // the hoist is not shaped: exact
      const double distances[] = {r.trolley.position - from.trolley.position, r.slew.position - from.slew.position};
      const double errors[] = {predicted[0] - r.trolley.position, predicted[1] - r.slew.position};
      for (int i = 0; i < 2; ++i) {
        if (std::abs(distances[i]) < 1e-3) continue;
        const double relative = std::abs(errors[i]) / std::abs(distances[i]);
        worst = std::max(worst, relative);
        EXPECT_LT(relative, 0.05) << "shaping " << static_cast<int>(shaping) << " trial " << trial << " axis " << i;
      }
    }
  }
  std::printf("rest prediction while hoisting, 150 random cases: worst error %.2f %% of the stopping distance\n",
              100.0 * worst);
}

TEST(SpeedReference, RestPredictionIsExactAtConstantCableLength) {
  const ManualParams params;
  for (const SpeedShaping shaping : {SpeedShaping::none, SpeedShaping::zv, SpeedShaping::zvd}) {
    for (const int cycles : {5, 30, 150, 400}) {
      SpeedReference ref;
      common::MotionReference start;
      start.cable_length.position = 1.3;
      ref.start(start);
      for (int k = 0; k < cycles; ++k) (void)ref.step({0.4, 0.8, 0.0}, kDt, params, shaping, wide_bounds(), {}, 0);
      const auto predicted = ref.rest(kDt, params, shaping, wide_bounds());
      while (!ref.at_rest()) (void)ref.step({0, 0, 0}, kDt, params, shaping, wide_bounds(), {}, 0);
      EXPECT_NEAR(predicted[0], ref.reference().trolley.position, 1e-12) << static_cast<int>(shaping) << " " << cycles;
      EXPECT_NEAR(predicted[1], ref.reference().slew.position, 1e-12) << static_cast<int>(shaping) << " " << cycles;
    }
  }
}

// A full stick for 3 s, then released: the ZV-shaped reference leaves the linear pendulum at rest;
// the ramp alone leaves it swinging (the figure the industrial products remove).
TEST(SpeedReference, ZvShapedStickLeavesNoResidualSwingTheRampAlone) {
  const ManualParams params;
  double residual[2] = {0, 0};
  for (const SpeedShaping shaping : {SpeedShaping::none, SpeedShaping::zv}) {
    SpeedReference ref;
    common::MotionReference start;
    start.cable_length.position = 1.0;
    ref.start(start);
    Pendulum p;
    for (int k = 0; k < 300; ++k) {
      (void)ref.step({params.trolley.rated_speed, 0, 0}, kDt, params, shaping, wide_bounds(), {}, 0);
      p.step(ref.reference().trolley.acceleration, kDt);
    }
    for (int k = 0; k < 300; ++k) {
      (void)ref.step({0, 0, 0}, kDt, params, shaping, wide_bounds(), {}, 0);
      p.step(ref.reference().trolley.acceleration, kDt);
    }
    EXPECT_TRUE(ref.at_rest());
    residual[shaping == SpeedShaping::zv ? 1 : 0] = p.amplitude();
  }
  std::printf("linear pendulum, L = 1 m, full trolley stick 3 s then released: residual swing %.3f deg with the ramp "
              "alone, %.4f deg ZV-shaped\n",
              residual[0] * 180 / std::numbers::pi, residual[1] * 180 / std::numbers::pi);
  EXPECT_LT(residual[1], 0.02 * residual[0]);
  EXPECT_GT(residual[0] * 180 / std::numbers::pi, 1.0);
}

TEST(SpeedReference, NonFiniteTargetsAreReleasedAxes) {
  const ManualParams params;
  SpeedReference ref;
  ref.start({});
  for (int k = 0; k < 100; ++k) {
    (void)ref.step({std::nan(""), INFINITY, 0.0}, kDt, params, SpeedShaping::zv, wide_bounds(), {}, 0);
  }
  EXPECT_TRUE(ref.at_rest());
  EXPECT_EQ(ref.reference().trolley.position, 0.0);
}

TEST(SpeedReference, TravelLimitStopsTheAxisShortOfIt) {
  const ManualParams params;
  SpeedBounds bounds = wide_bounds();
  bounds.max[0] = 1.0;
  SpeedReference ref;
  common::MotionReference start;
  start.trolley.position = 0.2;
  start.cable_length.position = 1.0;
  ref.start(start);
  double furthest = 0.0;
  std::uint8_t held = 0;
  for (int k = 0; k < 1000; ++k) {
    held |= ref.step({params.trolley.rated_speed, 0, 0}, kDt, params, SpeedShaping::zv, bounds, {}, 0);
    furthest = std::max(furthest, ref.reference().trolley.position);
  }
  EXPECT_LE(furthest, 1.0);
  EXPECT_GT(furthest, 0.95);  // it does get there (not stopped early)
  EXPECT_EQ(held, 1);
}

common::Zone square(double x0, double y0, double size, double bottom = 0.0, double top = 100.0) {
  return {"square", {{x0, y0}, {x0 + size, y0}, {x0 + size, y0 + size}, {x0, y0 + size}}, bottom, top, true};
}

TEST(Site, SignedDistanceOfASquare) {
  const auto z = square(0, 0, 1);
  EXPECT_NEAR(common::signed_distance(z, {0.5, 0.5}), -0.5, 1e-15);
  EXPECT_NEAR(common::signed_distance(z, {2.0, 0.5}), 1.0, 1e-15);
  EXPECT_NEAR(common::signed_distance(z, {2.0, 2.0}), std::sqrt(2.0), 1e-15);
  EXPECT_TRUE(common::intrudes(z, {1.05, 0.5}, 50.0, 0.1));
  EXPECT_FALSE(common::intrudes(z, {1.15, 0.5}, 50.0, 0.1));
  EXPECT_FALSE(common::intrudes(z, {0.5, 0.5}, 100.2, 0.1));  // above it
}

TEST(Site, BadZonesAreRefusedNamingTheZone) {
  const auto refused = [](common::Zone zone, const std::string& expected) {
    common::Site site;
    site.zones = {square(5, 5, 1), std::move(zone)};
    try {
      common::validate(site);
      ADD_FAILURE() << "accepted: " << expected;
    } catch (const common::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused({"empty", {}, 0, 1, true}, "site.zones[1] (empty): polygon has 0 vertices: at least 3");
  refused({"bow tie", {{0, 0}, {1, 1}, {1, 0}, {0, 1}}, 0, 1, true},
          "site.zones[1] (bow tie): polygon is self-intersecting: edges 0 and 2 cross");
  refused({"flat", {{0, 0}, {1, 0}, {2, 0}}, 0, 1, true}, "site.zones[1] (flat): polygon has zero area");
  refused({"nan", {{0, 0}, {1, NAN}, {1, 1}}, 0, 1, true}, "site.zones[1] (nan): vertex 1 is not finite");
  auto upside_down = square(0, 0, 1, 2.0, 1.0);
  upside_down.name = "upside down";
  refused(upside_down, "site.zones[1] (upside down).top = 1 is out of range");
}

// The load's position of the site, analytic cases of the tower convention (2.11) with ERRATA.
TEST(Site, LoadPositionFollowsTheTowerConvention) {
  common::Site site;
  site.jib_height = 3.0;
  const auto p = common::load_position(site, 1.0, std::numbers::pi / 2, 0.0, 0.0, 1.0);
  EXPECT_NEAR(p[0], 0.0, 1e-15);
  EXPECT_NEAR(p[1], 1.0, 1e-15);
  EXPECT_NEAR(p[2], 2.0, 1e-15);
  // In-plane swing phi > 0 moves the load inward along the jib (x - L cos(theta) sin(phi)).
  const auto q = common::load_position(site, 1.0, 0.0, 0.1, 0.0, 1.0);
  EXPECT_NEAR(q[0], 1.0 - std::sin(0.1), 1e-15);
}

TrajectoryPlannerParams params_with_zone(const common::Zone& zone) {
  TrajectoryPlannerParams p;
  p.trolley_min_position = 0.1;
  p.trolley_max_position = 1.2;
  p.slew_min_angle = -3.0;
  p.slew_max_angle = 3.0;
  p.cable_min_length = 0.2;
  p.cable_max_length = 2.0;
  p.site.jib_height = 2.5;
  p.site.zone_clearance = 0.05;
  p.site.zones = {zone};
  return p;
}

// A tall zone across the straight path from slew 0 to slew pi/2 at 1 m: the direct move enters it,
// the chosen route does not (every reference sample checked with the margin), and a target in the
// zone is refused naming it.
TEST(ZonePaths, AZoneOnTheWayIsGoneAroundAndATargetInsideIsRefused) {
  const auto zone = square(0.55, 0.35, 0.3);  // across the arc at 0.8-1.0 m radius near 30-40 deg
  TrajectoryPlanner scratch(params_with_zone(zone));
  common::CraneStateEstimate current;
  current.trolley_position = 0.9;
  current.slew_angle = 0.0;
  current.cable_length = 1.0;
  MoveGoal goal;
  goal.profile = ProfileKind::time_optimal;
  goal.trolley_target = 0.9;
  goal.slew_target = std::numbers::pi / 2;
  goal.cable_target = 1.0;
  scratch.reset();
  ASSERT_EQ(scratch.start_move(goal, current), GoalStatus::accepted);
  EXPECT_EQ(scratch.intruded_zone(1, 0.02), 0) << "the test's zone must block the direct route";
  const ZonePlan plan = plan_around_zones(scratch, goal, current, 1);
  ASSERT_TRUE(plan.found);
  EXPECT_NE(plan.route, ZoneRoute::direct);
  scratch.reset();
  ASSERT_EQ(scratch.start_move(plan.goal, current), GoalStatus::accepted);
  EXPECT_EQ(scratch.intruded_zone(1, 0.005), -1);
  std::printf("route around the zone: %s%s, %.2f s\n", zone_route_name(plan.route),
              plan.other_way_round ? " (the other way round)" : "", scratch.move_duration());

  MoveGoal inside = goal;
  inside.trolley_target = 0.85;
  inside.slew_target = std::atan2(0.5, 0.7);
  const ZonePlan refused = plan_around_zones(scratch, inside, current, 1);
  EXPECT_FALSE(refused.found);
  EXPECT_TRUE(refused.target_in_zone);
  EXPECT_EQ(refused.zone, 0);
  // Switched off (bit clear): no zone, the direct route.
  const ZonePlan off = plan_around_zones(scratch, goal, current, 0);
  EXPECT_TRUE(off.found);
  EXPECT_EQ(off.route, ZoneRoute::direct);
}

// A low zone (top 1.0 m) under a crane with a 2.5 m jib: the load can be hoisted over it when the
// other routes are blocked.
TEST(ZonePaths, ALowZoneIsHoistedOver) {
  // A ring-shaped sector blocking every horizontal route from slew 0 to pi at the same radius:
  // a wide low wall across the jib's sweep on both sides.
  common::Zone wall{"wall", {{-0.05, 0.05}, {1.3, 0.05}, {1.3, 0.15}, {-0.05, 0.15}}, 0.0, 1.0, true};
  common::Zone wall2{"wall2", {{-0.05, -0.15}, {1.3, -0.15}, {1.3, -0.05}, {-0.05, -0.05}}, 0.0, 1.0, true};
  auto p = params_with_zone(wall);
  p.site.zones.push_back(wall2);
  TrajectoryPlanner scratch(p);
  common::CraneStateEstimate current;
  current.trolley_position = 0.8;
  current.slew_angle = 0.6;
  current.cable_length = 1.8;  // load at 0.7 m: inside the walls' height
  MoveGoal goal;
  goal.profile = ProfileKind::zv;
  goal.trolley_target = 0.8;
  goal.slew_target = -0.6;
  goal.cable_target = 1.8;
  const ZonePlan plan = plan_around_zones(scratch, goal, current, 3);
  ASSERT_TRUE(plan.found);
  EXPECT_TRUE(plan.lifted) << zone_route_name(plan.route);
  scratch.reset();
  ASSERT_EQ(scratch.start_move(plan.goal, current), GoalStatus::accepted);
  EXPECT_EQ(scratch.intruded_zone(3, 0.005), -1);
}

}  // namespace

// Found by the topic-gates fuzzer (tests/fuzz): a speed reference started at an absurd cable length
// (3e180 m, from a corrupted estimate) designed a ZVD shaper 3.5e90 s long; rest() then looped over
// 3.5e92 cycles (the planner's 100 Hz step never returned). A shaper longer than the history
// (kHistory cycles: 10.24 s at 100 Hz, a ZV half period T_d/2 = pi sqrt(L/g) > 10.23 s for L > 104 m,
// a ZVD period 2 pi sqrt(L/g) for L > 26 m) is the identity, as documented: the reference is then
// exactly the unshaped one.
TEST(SpeedReference, AShaperLongerThanTheHistoryIsTheIdentity) {
  const ManualParams params;
  const SpeedBounds bounds{{-100.0, -100.0, 0.2}, {100.0, 100.0, 1e300}, kG};
  for (const double cable : {30.0, 3.0404018637411493e+180}) {
    for (const SpeedShaping shaping : {SpeedShaping::zv, SpeedShaping::zvd}) {
      if (shaping == SpeedShaping::zv && cable == 30.0) continue;  // ZV at 30 m: 5.5 s, within the history
      SpeedReference shaped, unshaped;
      common::MotionReference start;
      start.trolley.position = 0.5;
      start.cable_length.position = cable;
      shaped.start(start);
      unshaped.start(start);
      const std::array<double, 3> target{0.3, 0.0, 0.0};
      for (int k = 0; k < 50; ++k) {
        (void)shaped.step(target, kDt, params, shaping, bounds, {}, 0);
        (void)unshaped.step(target, kDt, params, SpeedShaping::none, bounds, {}, 0);
      }
      EXPECT_EQ(shaped.reference().trolley.velocity, unshaped.reference().trolley.velocity) << cable;
      EXPECT_EQ(shaped.reference().trolley.position, unshaped.reference().trolley.position) << cable;
      const auto rest = shaped.rest(kDt, params, shaping, bounds);
      EXPECT_EQ(rest[0], unshaped.rest(kDt, params, SpeedShaping::none, bounds)[0]) << cable;
    }
  }
  // Within the history the shaper acts: at 1 m, 0.5 s in, the ZV reference (half the command now,
  // half the command T_d/2 = 1.0 s ago, which was 0) is half the unshaped one.
  SpeedReference shaped, unshaped;
  common::MotionReference start;
  start.trolley.position = 0.5;
  start.cable_length.position = 1.0;
  shaped.start(start);
  unshaped.start(start);
  for (int k = 0; k < 50; ++k) {
    (void)shaped.step({0.3, 0.0, 0.0}, kDt, params, SpeedShaping::zv, bounds, {}, 0);
    (void)unshaped.step({0.3, 0.0, 0.0}, kDt, params, SpeedShaping::none, bounds, {}, 0);
  }
  EXPECT_NEAR(shaped.reference().trolley.velocity, 0.5 * unshaped.reference().trolley.velocity, 1e-12);
}

TEST(SpeedReference, AnAbsurdHandedOverSpeedIsReportedAsNeverComingToRestAtOnce) {
  // Found by the topic-gates fuzzer (tests/fuzz, regression-speed-rest-of-an-absurd-speed): a goal
  // with limits of 2e37 m/s and 8e34 m/s^2 was planned, a stop handed its 8e32 m/s over to the
  // speed reference, and rest() ran its ramp to zero forward, about 1e33 cycles: the planner's step
  // never returned (a libFuzzer timeout in keeps_bounds).
  const ManualParams params;
  SpeedReference reference;
  common::MotionReference start;
  start.trolley.position = 4e30;
  start.trolley.velocity = 8e32;
  start.slew.velocity = -3e20;
  start.cable_length.position = 1.0;
  reference.start(start);
  const auto rest = reference.rest(kDt, params, SpeedShaping::zv, wide_bounds());
  EXPECT_EQ(rest[0], std::numeric_limits<double>::max());
  EXPECT_EQ(rest[1], -std::numeric_limits<double>::max());
  EXPECT_EQ(rest[2], 1.0);  // the hoist at rest stays where it is
  // Every candidate's rest is outside the travel bounds, so the one with all axes released is
  // taken: the two asked-for axes are reported held, and the reference stays finite.
  EXPECT_EQ(reference.step({0.5, 0.5, 0.0}, kDt, params, SpeedShaping::zv, wide_bounds(), {}, 0), 3);
  EXPECT_TRUE(std::isfinite(reference.reference().trolley.position));
  // A real stop (1 m/s at the default 1 m/s^2: 100 cycles of ramp) is still run forward exactly.
  SpeedReference real;
  start = {};
  start.trolley.velocity = 1.0;
  start.cable_length.position = 1.0;
  real.start(start);
  const double predicted = real.rest(kDt, params, SpeedShaping::zv, wide_bounds())[0];
  EXPECT_LT(predicted, 10.0);
  for (int k = 0; k < 2000; ++k) (void)real.step({0.0, 0.0, 0.0}, kDt, params, SpeedShaping::zv, wide_bounds(), {}, 0);
  EXPECT_NEAR(real.reference().trolley.position, predicted, 1e-9);
}
