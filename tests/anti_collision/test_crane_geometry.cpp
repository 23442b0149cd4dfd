// The anti-collision geometry (anti_collision/crane_geometry.hpp) against hand-computed geometry:
// segments in analytic positions, jibs of two cranes at different heights, a cable against a
// lower crane's jib, two loads, a swinging load over a lower jib and risen toward a jib above, the
// stopping travel of a shaped and of an emergency stop; against an independent computation: the
// segment distance and the upright cylinders' minimised by brute force on seeded random shapes,
// and the stopping envelope against the crane's parts at densely sampled intermediate poses of the
// same stop, the load on its pendulum's sphere; and the margins' actions at their boundaries.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "crane/anti_collision/crane_geometry.hpp"

namespace {

using namespace crane::anti_collision;

constexpr double kPi = std::numbers::pi;

// A full-size tower crane (jib 50 m at 40 m), numbers easy to compute by hand.
SiteCrane tower(double x, double y, double jib_height, double heading = 0.0) {
  SiteCrane c;
  c.name = "tc";
  c.base = {x, y};
  c.slew_zero_heading = heading;
  c.jib_height = jib_height;
  c.jib_length = 50.0;
  c.counter_jib_length = 15.0;
  c.jib_width = 1.2;
  c.jib_depth = 1.6;  // cross-section diagonal 2.0 m: jib radius 1.0 m
  c.mast_width = 2.0;
  c.trolley_min = 3.0;
  c.trolley_max = 48.0;
  c.hook_height_min = 0.0;
  c.hook_height_max = jib_height - 2.0;
  c.load_radius = 1.0;
  c.stopping = {0.1, 0.5, 0.05, 0.5, 3.0, true};
  return c;
}

TEST(SegmentDistance, AnalyticCases) {
  const Vector3 o = Vector3::Zero();
  // Skew segments crossing in plan view, 3 m apart in height.
  EXPECT_NEAR(segment_distance({-1, 0, 0}, {1, 0, 0}, {0, -1, 3}, {0, 1, 3}), 3.0, 1e-12);
  // Parallel, overlapping in extent, 2 m apart.
  EXPECT_NEAR(segment_distance({0, 0, 0}, {4, 0, 0}, {1, 2, 0}, {6, 2, 0}), 2.0, 1e-12);
  // Collinear with a gap of 1.5 m between the ends.
  EXPECT_NEAR(segment_distance({0, 0, 0}, {1, 0, 0}, {2.5, 0, 0}, {4, 0, 0}), 1.5, 1e-12);
  // End to interior: (3, 4, 0) above the x axis segment's interior.
  EXPECT_NEAR(segment_distance({0, 0, 0}, {10, 0, 0}, {3, 4, 0}, {3, 9, 0}), 4.0, 1e-12);
  // End to end beyond both: (0,0,0)-(1,0,0) and (2,1,0)-(2,5,0): from (1,0,0) to (2,1,0).
  EXPECT_NEAR(segment_distance({0, 0, 0}, {1, 0, 0}, {2, 1, 0}, {2, 5, 0}), std::sqrt(2.0), 1e-12);
  // Points.
  EXPECT_NEAR(segment_distance(o, o, {3, 4, 0}, {3, 4, 0}), 5.0, 1e-12);
  EXPECT_NEAR(segment_distance(o, o, {-1, 1, 0}, {1, 1, 0}), 1.0, 1e-12);
  // Intersecting.
  EXPECT_NEAR(segment_distance({-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}), 0.0, 1e-12);
}

// The exact distance against a minimisation that shares nothing with it: for each of 401 points
// along the first segment, the closest point of the second by projection, then the minimum.
TEST(SegmentDistance, SeededRandomSegmentsAgreeWithBruteForce) {
  std::mt19937 rng(34);
  std::uniform_real_distribution<double> coordinate(-5.0, 5.0);
  const auto random_point = [&] { return Vector3(coordinate(rng), coordinate(rng), coordinate(rng)); };
  for (int trial = 0; trial < 2000; ++trial) {
    Vector3 p0 = random_point(), p1 = random_point(), q0 = random_point(), q1 = random_point();
    if (trial % 10 == 0) q1 = q0 + 0.3 * (p1 - p0);  // parallel
    if (trial % 17 == 0) p1 = p0;                      // a point
    const double exact = segment_distance(p0, p1, q0, q1);
    double brute = std::numeric_limits<double>::infinity();
    constexpr int kPoints = 401;
    for (int i = 0; i < kPoints; ++i) {
      const Vector3 p = p0 + (p1 - p0) * (static_cast<double>(i) / (kPoints - 1));
      const Vector3 d = q1 - q0;
      const double t = d.squaredNorm() > 0.0 ? std::clamp((p - q0).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
      brute = std::min(brute, (p - (q0 + t * d)).norm());
    }
    // The sampled minimum is never below the exact one and above it by at most half a sample step.
    const double step = (p1 - p0).norm() / (kPoints - 1);
    ASSERT_GE(brute, exact - 1e-9) << "trial " << trial;
    ASSERT_LE(brute, exact + step / 2.0 + 1e-9) << "trial " << trial;
  }
}

// The upright cylinder (flat ends) against a minimisation that shares nothing with the code's:
// for each of 401 points along a capsule's segment, the closest point of the solid cylinder by
// projection (the plan offset clamped to the radius, the height to the cylinder's), then the
// minimum; for two cylinders, 401 points up the first's axis, each widened by its radius toward
// the second's axis. Segments of every kind: slanted, horizontal, vertical, points.
TEST(SegmentDistance, UprightCylindersAgreeWithBruteForce) {
  std::mt19937 rng(35);
  std::uniform_real_distribution<double> coordinate(-5.0, 5.0);
  std::uniform_real_distribution<double> size(0.0, 2.0);
  const auto random_point = [&] { return Vector3(coordinate(rng), coordinate(rng), coordinate(rng)); };
  const auto closest_in = [](const Vector3& p, const Capsule& u) {
    const Vector3 axis(u.a.x(), u.a.y(), 0.0);
    Vector3 plan(p.x() - axis.x(), p.y() - axis.y(), 0.0);
    if (plan.norm() > u.radius) plan *= u.radius / plan.norm();
    return Vector3(axis.x() + plan.x(), axis.y() + plan.y(),
                   std::clamp(p.z(), std::min(u.a.z(), u.b.z()), std::max(u.a.z(), u.b.z())));
  };
  constexpr int kPoints = 401;
  int overlapping = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const Vector3 c = random_point();
    const Capsule u{c, Vector3(c.x(), c.y(), c.z() + 3.0 * size(rng)), size(rng), true};
    Vector3 p0 = random_point(), p1 = random_point();
    if (trial % 5 == 1) p1.z() = p0.z();                   // horizontal, as a jib
    if (trial % 5 == 2) p1 = Vector3(p0.x(), p0.y(), p1.z());  // vertical, as a mast
    if (trial % 5 == 3) p1 = p0;                           // a point
    const Capsule k{p0, p1, size(rng)};
    const double exact = capsule_distance(k, u);
    ASSERT_DOUBLE_EQ(exact, capsule_distance(u, k)) << "trial " << trial;
    double brute = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kPoints; ++i) {
      const Vector3 p = p0 + (p1 - p0) * (static_cast<double>(i) / (kPoints - 1));
      brute = std::min(brute, (p - closest_in(p, u)).norm());
    }
    const double step = (p1 - p0).norm() / (kPoints - 1);
    if (brute < 1e-12) {  // the segment enters the cylinder: an overlap, negative
      ++overlapping;
      ASSERT_LT(exact, 0.0) << "trial " << trial;
      continue;
    }
    ASSERT_GE(brute - k.radius, exact - 1e-9) << "trial " << trial;
    ASSERT_LE(brute - k.radius, exact + step / 2.0 + 1e-9) << "trial " << trial;
  }
  EXPECT_GT(overlapping, 0);
  for (int trial = 0; trial < 2000; ++trial) {
    const Vector3 c = random_point(), d = random_point();
    const Capsule u{c, Vector3(c.x(), c.y(), c.z() + 3.0 * size(rng)), size(rng), true};
    const Capsule v{d, Vector3(d.x(), d.y(), d.z() + 3.0 * size(rng)), size(rng), true};
    const double exact = capsule_distance(u, v);
    double brute = std::numeric_limits<double>::infinity();
    for (int i = 0; i < kPoints; ++i) {
      Vector3 p = u.a + (u.b - u.a) * (static_cast<double>(i) / (kPoints - 1));
      Vector3 toward(v.a.x() - p.x(), v.a.y() - p.y(), 0.0);
      if (toward.norm() > 0.0) p += toward * (std::min(u.radius, toward.norm()) / toward.norm());
      brute = std::min(brute, (p - closest_in(p, v)).norm());
    }
    if (brute < 1e-12) {
      ASSERT_LE(exact, 1e-9) << "trial " << trial;
      continue;
    }
    const double step = (u.b - u.a).norm() / (kPoints - 1);
    ASSERT_GE(brute, exact - 1e-9) << "trial " << trial;
    ASSERT_LE(brute, exact + step / 2.0 + 1e-9) << "trial " << trial;
  }
}

// Two cranes 60 m apart, jibs crossing at right angles in plan view, jibs at 40 m and 48 m: the
// jib capsules' axes are 8 m apart vertically (both chords + depth/2), less both radii (1 m each).
TEST(CraneGeometry, JibsAtDifferentHeights) {
  const SiteCrane low = tower(0.0, 0.0, 40.0);
  const SiteCrane high = tower(30.0, -30.0, 48.0, kPi / 2.0);
  CraneMotion a;  // jib along +x: from (0,0) to (50,0)
  a.trolley = 10.0;
  a.cable_length = 5.0;
  CraneMotion b;  // jib along +y from (30,-30) to (30,20): crosses the low jib at (30, 0)
  b.trolley = 45.0;
  b.cable_length = 1.0;
  const auto d = distance(envelope(low, a, StopKind::none), envelope(high, b, StopKind::none));
  EXPECT_NEAR(d.distance, 8.0 - 2.0, 1e-9);
  EXPECT_EQ(d.first, Part::jib);
  EXPECT_EQ(d.second, Part::jib);
  EXPECT_NEAR(jib_bottom(low), 40.0 + 0.8 - 1.0, 1e-12);
  EXPECT_NEAR(top_of_structure(low), 40.0 + 0.8 + 1.0, 1e-12);
}

// The high crane's cable hangs 5 m beside the low crane's jib axis (horizontally), its load well
// below the jib: the cable's capsule (radius = swing envelope) against the jib's (radius 1 m).
TEST(CraneGeometry, CableAgainstALowerJib) {
  const SiteCrane low = tower(0.0, 0.0, 40.0);
  const SiteCrane high = tower(20.0, 30.0, 48.0, -kPi / 2.0);  // jib along -y from (20, 30)
  CraneMotion a;
  a.trolley = 10.0;
  a.cable_length = 5.0;
  CraneMotion b;
  b.trolley = 25.0;  // sheave at (20, 5, 48)
  b.cable_length = 30.0;  // load at 18 m, the cable passes the low jib's height (40.8 m)
  b.swing_in_plane = 0.1;  // at rest in a swing of 0.1 rad: envelope 30 sin(0.1)
  const double swing = 30.0 * std::sin(0.1);
  const auto d = distance(envelope(low, a, StopKind::none), envelope(high, b, StopKind::none));
  EXPECT_NEAR(d.distance, 5.0 - 1.0 - swing, 1e-9);
  EXPECT_EQ(d.first, Part::jib);
  EXPECT_EQ(d.second, Part::cable);
}

// Two loads hanging 14 m apart at the same height: 14 m less both spheres (load radius 1 m plus
// the swing envelope of each).
TEST(CraneGeometry, LoadAgainstLoad) {
  const SiteCrane left = tower(0.0, 0.0, 40.0);
  const SiteCrane right = tower(110.0, 0.0, 60.0, kPi);  // jib toward -x
  CraneMotion a;
  a.trolley = 48.0;  // load at (48, 0, 40 - 35)
  a.cable_length = 35.0;
  a.swing_out_of_plane_rate = 0.05;  // amplitude 0.05 / omega
  CraneMotion b;
  b.trolley = 48.0;  // load at (62, 0, 60 - 55)
  b.cable_length = 55.0;
  const double swing_a = 35.0 * std::sin(0.05 / std::sqrt(kStandardGravity / 35.0));
  const auto d = distance(envelope(left, a, StopKind::none), envelope(right, b, StopKind::none));
  EXPECT_NEAR(d.distance, 14.0 - (1.0 + swing_a) - 1.0, 1e-9);
  EXPECT_EQ(d.first, Part::load);
  EXPECT_EQ(d.second, Part::load);
}

// A higher crane's load swinging over a lower crane's jib: the pendulum's load never comes lower
// than the cable's length, so its envelope widens it sideways only. The high crane's sheave at
// (30, 0, 48) over the low jib's axis, a cable of 4 m swinging 0.3 rad (an envelope of
// 4 sin(0.3) = 1.18 m): the load's lowest point 48 - 4 - 1 = 43 m, the low jib's capsule's top
// 40.8 + 1 = 41.8 m: 1.2 m, what the load hanging still would keep. (The capsule of sessions
// before 35, its sphere-swept end reaching the envelope below the load too, said 0.018 m.)
TEST(CraneGeometry, ALoadSwingingOverALowerJibKeepsItsHeight) {
  const SiteCrane low = tower(0.0, 0.0, 40.0);
  const SiteCrane high = tower(30.0, -30.0, 48.0, kPi / 2.0);  // jib along +y: x = 30
  CraneMotion a;
  a.trolley = 10.0;
  a.cable_length = 5.0;
  CraneMotion b;
  b.trolley = 30.0;  // sheave at (30, 0, 48)
  b.cable_length = 4.0;
  b.swing_out_of_plane = 0.3;
  const auto d = distance(envelope(low, a, StopKind::none), envelope(high, b, StopKind::none));
  EXPECT_NEAR(d.distance, 43.0 - 41.8, 1e-9);
  EXPECT_EQ(d.first, Part::jib);
  EXPECT_EQ(d.second, Part::load);
  // The envelope widens it sideways: the load's part is 1 + 4 sin(0.3) m wide about the sheave.
  const Capsule load = envelope(high, b, StopKind::none).samples[0][static_cast<std::size_t>(Part::load)];
  EXPECT_TRUE(load.upright);
  EXPECT_NEAR(load.radius, 1.0 + 4.0 * std::sin(0.3), 1e-12);
  EXPECT_NEAR(std::min(load.a.z(), load.b.z()), 43.0, 1e-12);
}

// A load swung sideways rises: on a cable of 9 m under a jib at 44 m, swinging asin(0.6) (an
// envelope of 5.4 m), its centre can come up to sqrt(81 - 29.16) = 7.2 m below the sheave, its
// top to 44 - 7.2 + 1 = 37.8 m. A lower crane's jib (rails at 38 m: its capsule's axis at 38.8 m,
// radius 1 m) passes 7.2 m from the sheave's vertical in plan, 0.8 m outside the load's envelope
// (6.4 m): hypot(0.8, 38.8 - 37.8) - 1 = 0.281 m. The cable (5.4 m wide, from 35 m up to the
// sheave) is 7.2 - 5.4 - 1 = 0.8 m away in plan; a load whose top did not rise (36 m) would be
// hypot(0.8, 2.8) - 1 = 1.91 m away.
TEST(CraneGeometry, ALoadSwungSidewaysRisesTowardAJibAbove) {
  const SiteCrane swinging = tower(0.0, 0.0, 44.0);
  const SiteCrane lower = tower(27.2, -30.0, 38.0, kPi / 2.0);  // jib along +y: x = 27.2
  CraneMotion a;
  a.trolley = 20.0;  // sheave at (20, 0, 44)
  a.cable_length = 9.0;
  a.swing_in_plane = std::asin(0.6);
  CraneMotion b;
  b.trolley = 45.0;  // its own sheave at (27.2, 15): far from the other
  b.cable_length = 1.0;
  const auto d = distance(envelope(swinging, a, StopKind::none), envelope(lower, b, StopKind::none));
  EXPECT_NEAR(d.distance, std::hypot(0.8, 1.0) - 1.0, 1e-9);
  EXPECT_EQ(d.first, Part::load);
  EXPECT_EQ(d.second, Part::jib);
  const auto parts = envelope(swinging, a, StopKind::none).samples[0];
  const Capsule jib = envelope(lower, b, StopKind::none).samples[0][static_cast<std::size_t>(Part::jib)];
  EXPECT_NEAR(capsule_distance(parts[static_cast<std::size_t>(Part::cable)], jib), 0.8, 1e-9);
}

// The stopping travel by hand: trolley at 0.5 m/s, 0.5 m/s^2, reaction 0.1 s, ZV shaped (mean
// delay T/4) on a cable of g/1 m (omega = 1 rad/s, T = 2 pi s): 0.05 + 0.25 + 0.5 pi/2; ZVD (T/2):
// 0.05 + 0.25 + 0.5 pi; the emergency stop at three times the deceleration, no shaping:
// 0.05 + 0.25/3, and the load's swing v/omega.
TEST(CraneGeometry, StoppingTravelOfShapedAndEmergencyStops) {
  SiteCrane c = tower(0.0, 0.0, 40.0);
  c.stopping.soft_stop_delay_periods = 0.25;  // ZV
  CraneMotion m;
  m.trolley = 20.0;
  m.trolley_velocity = -0.5;
  m.cable_length = kStandardGravity;
  const auto soft = stopping_travel(c, m, StopKind::soft);
  EXPECT_NEAR(soft.trolley, -(0.05 + 0.25 + 0.5 * 2.0 * kPi / 4.0), 1e-12);
  EXPECT_EQ(soft.slew, 0.0);
  EXPECT_NEAR(soft.swing_radius, kStandardGravity * 0.5 / kStandardGravity, 1e-12);  // L a / g, shaped
  const auto hard = stopping_travel(c, m, StopKind::emergency);
  EXPECT_NEAR(hard.trolley, -(0.05 + 0.25 / 3.0), 1e-12);
  EXPECT_NEAR(hard.swing_radius, 0.5 / 1.0, 1e-12);  // v / omega
  SiteCrane unshaped = c;
  unshaped.stopping.soft_stop_delay_periods = 0.0;
  const auto plain = stopping_travel(unshaped, m, StopKind::soft);
  EXPECT_NEAR(plain.trolley, -(0.05 + 0.25), 1e-12);
  EXPECT_NEAR(plain.swing_radius, 2.0 * 0.5, 1e-12);  // 2 L a / g
  SiteCrane zvd = c;
  zvd.stopping.soft_stop_delay_periods = 0.5;
  const auto longer = stopping_travel(zvd, m, StopKind::soft);
  EXPECT_NEAR(longer.trolley, -(0.05 + 0.25 + 0.5 * 2.0 * kPi / 2.0), 1e-12);
  EXPECT_NEAR(longer.swing_radius, 0.5, 1e-12);  // L a / g, shaped
}

// The envelope contains the stop: the crane's parts at 200 poses along the same stop (slew and
// trolley decelerating together, the load at its envelope's edge) are never closer to a probe
// crane than the envelope says, and the envelope is not looser than its padding.
TEST(CraneGeometry, StoppingEnvelopeContainsSeededRandomStops) {
  std::mt19937 rng(3402);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int trial = 0; trial < 200; ++trial) {
    const SiteCrane moving = tower(0.0, 0.0, 40.0);
    const double bearing = 2.0 * kPi * uniform(rng);
    const double apart = 40.0 + 60.0 * uniform(rng);
    const SiteCrane probe = tower(apart * std::cos(bearing), apart * std::sin(bearing), 30.0 + 20.0 * uniform(rng),
                                  2.0 * kPi * uniform(rng));
    CraneMotion m;
    m.slew = 2.0 * kPi * uniform(rng) - kPi;
    m.slew_rate = 0.8 * (uniform(rng) - 0.5);
    m.trolley = 5.0 + 40.0 * uniform(rng);
    m.trolley_velocity = 2.0 * (uniform(rng) - 0.5);
    m.cable_length = 5.0 + 30.0 * uniform(rng);
    CraneMotion p;
    p.slew = 2.0 * kPi * uniform(rng);
    p.trolley = 5.0 + 40.0 * uniform(rng);
    p.cable_length = 5.0 + 30.0 * uniform(rng);
    const auto env = envelope(moving, m, StopKind::soft);
    const auto probe_env = envelope(probe, p, StopKind::none);
    const double claimed = distance(env, probe_env).distance;

    const auto travel = stopping_travel(moving, m, StopKind::soft);
    double actual = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 200; ++i) {
      CraneMotion pose = m;
      pose.slew = m.slew + travel.slew * i / 200.0;
      pose.trolley = m.trolley + travel.trolley * i / 200.0;
      pose.slew_rate = pose.trolley_velocity = 0.0;
      auto parts = envelope(moving, pose, StopKind::none);
      for (auto& capsule : parts.samples[0]) capsule.radius = 0.0;
      // The structure at its true size; the cable and the load as they hang (the sheave the top of
      // the cable's cylinder), then swung anywhere in the envelope, sampled on two rings, the load
      // on the pendulum's sphere about the sheave.
      parts.samples[0][static_cast<std::size_t>(Part::jib)].radius = jib_radius(moving);
      parts.samples[0][static_cast<std::size_t>(Part::counter_jib)].radius = jib_radius(moving);
      parts.samples[0][static_cast<std::size_t>(Part::mast)].radius = mast_radius(moving);
      const Capsule column = parts.samples[0][static_cast<std::size_t>(Part::cable)];
      const Vector3 sheave = column.a.z() > column.b.z() ? column.a : column.b;
      const auto hang = [&](const Vector3& offset) {
        auto hung = parts;
        const double depth = std::sqrt(m.cable_length * m.cable_length - offset.squaredNorm());
        const Vector3 centre = sheave + offset - Vector3(0.0, 0.0, depth);
        hung.samples[0][static_cast<std::size_t>(Part::cable)] = {sheave, centre, 0.0};
        hung.samples[0][static_cast<std::size_t>(Part::load)] = {centre, centre, moving.load_radius};
        return hung;
      };
      actual = std::min(actual, distance(hang(Vector3::Zero()), probe_env).distance);
      const double swing = std::min(travel.swing_radius, m.cable_length);
      for (const double ring : {swing / 2.0, swing}) {
        for (int k = 0; k < 8; ++k) {
          const double a = 2.0 * kPi * k / 8.0;
          actual = std::min(actual, distance(hang(Vector3(ring * std::cos(a), ring * std::sin(a), 0.0)), probe_env).distance);
        }
      }
    }
    ASSERT_LE(claimed, actual + 1e-9) << "trial " << trial;
  }
}

// Between two samples of the slew the jib passes closer to a point than at either sample (a point
// just beyond the jib tip's arc): the samples' padding must cover it. Probe points near the tip's
// arc and the jib's chord, the jib at 4000 poses along the same stop as the truth; the envelope is
// also no looser than twice its padding.
TEST(CraneGeometry, SweptJibIsCoveredBetweenSamples) {
  std::mt19937 rng(3403);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const SiteCrane c = tower(0.0, 0.0, 40.0);
  const double chord = c.jib_height + c.jib_depth / 2.0;
  double worst_gap = 0.0;
  for (int trial = 0; trial < 300; ++trial) {
    CraneMotion m;
    m.slew = 2.0 * kPi * uniform(rng) - kPi;
    m.slew_rate = (uniform(rng) < 0.5 ? -1.0 : 1.0) * (0.1 + 0.5 * uniform(rng));
    m.trolley = 20.0;
    m.cable_length = 5.0;
    const auto env = envelope(c, m, StopKind::soft);
    const auto travel = stopping_travel(c, m, StopKind::soft);
    ASSERT_GT(env.count, 2u);
    const double heading = m.slew + travel.slew * uniform(rng);
    const double radius = c.jib_length + jib_radius(c) + 0.2 * uniform(rng);
    const Capsule probe{Vector3(radius * std::cos(heading), radius * std::sin(heading), chord),
                        Vector3(radius * std::cos(heading), radius * std::sin(heading), chord), 0.0};
    double claimed = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < env.count; ++i) {
      claimed = std::min(claimed, capsule_distance(env.samples[i][static_cast<std::size_t>(Part::jib)], probe));
    }
    double actual = std::numeric_limits<double>::infinity();
    for (int i = 0; i <= 4000; ++i) {
      const double h = m.slew + travel.slew * i / 4000.0;
      const Capsule jib{Vector3(0.0, 0.0, chord), Vector3(c.jib_length * std::cos(h), c.jib_length * std::sin(h), chord),
                        jib_radius(c)};
      actual = std::min(actual, capsule_distance(jib, probe));
    }
    const double pad = env.samples[0][static_cast<std::size_t>(Part::jib)].radius - jib_radius(c);
    ASSERT_LE(claimed, actual + 1e-9) << "trial " << trial;
    ASSERT_GE(claimed, actual - 2.0 * pad - 1e-9) << "trial " << trial;
    worst_gap = std::max(worst_gap, claimed - (actual - pad));
  }
  EXPECT_GT(worst_gap, 0.0);  // some probe lies between two samples' reach
}

TEST(CraneGeometry, ActionsAtTheMarginsBoundaries) {
  const Margins m{3.0, 2.0, 1.0};
  EXPECT_EQ(classify(5.0, 5.0, m), Action::clear);
  EXPECT_EQ(classify(3.0, 5.0, m), Action::clear);
  EXPECT_EQ(classify(2.999, 5.0, m), Action::warning);
  EXPECT_EQ(classify(1.999, 5.0, m), Action::slow_down);
  EXPECT_EQ(classify(0.999, 5.0, m), Action::stop);
  EXPECT_EQ(classify(5.0, 0.999, m), Action::emergency_stop);
  EXPECT_EQ(classify(std::nan(""), 5.0, m), Action::emergency_stop);
  EXPECT_EQ(classify(5.0, std::nan(""), m), Action::emergency_stop);
}

}  // namespace
