#include "crane/anti_collision/airspace.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace crane::anti_collision {
namespace {

// A segment in plan view swept by a disc of `radius`, times the heights [z_low, z_high] (see the
// header).
struct Slab {
  Slab() = default;
  Slab(const Vector3& from, const Vector3& to, double disc, double low, double high) noexcept
      : a(from), b(to), radius(disc), z_low(low), z_high(high), middle((from + to) / 2.0),
        half_length((to - from).norm() / 2.0) {}
  Vector3 a{Vector3::Zero()};  // plan points (z = 0)
  Vector3 b{Vector3::Zero()};
  double radius{0.0};
  double z_low{0.0};
  double z_high{0.0};
  Vector3 middle{Vector3::Zero()};  // of [a, b], and half its length: may_be_closer()'s bound
  double half_length{0.0};
};

double height_apart(const Slab& p, const Slab& q) noexcept {
  return std::max({0.0, q.z_low - p.z_high, p.z_low - q.z_high});
}

double slab_distance(const Slab& p, const Slab& q) noexcept {
  const double plan = std::max(0.0, segment_distance(p.a, p.b, q.a, q.b) - p.radius - q.radius);
  const double height = height_apart(p, q);
  // hypot(x, 0) is |x| exactly: the common cases skip glibc's careful hypot (most of a site run).
  if (height == 0.0) return plan;
  if (plan == 0.0) return height;
  return std::hypot(plan, height);
}

// Whether slab_distance(p, q) can be below `best`, from a lower bound of it: the plan distance of
// two segments is at least their middles' distance less both half lengths (triangle inequality),
// and slab_distance at least its plan and its height parts. 1 nm of slack covers the bound's
// rounding, so a pair it skips could not have been kept (keep() takes only a smaller distance):
// airspace_distance gives the same answer with or without it, only sooner.
bool may_be_closer(const Slab& p, const Slab& q, double best) noexcept {
  if (height_apart(p, q) >= best) return false;
  const double reach = best + p.half_length + q.half_length + p.radius + q.radius + 1e-9;
  return (p.middle - q.middle).squaredNorm() < reach * reach;
}

// The parts of one sample that turn with the slew.
enum Moving : std::size_t { kJib, kCounterJib, kHanging, kMovingParts };
constexpr Part kPartOf[kMovingParts] = {Part::jib, Part::counter_jib, Part::cable};

constexpr std::size_t kMaxSamples = 192;  // a full turn at kMaxSlewStep: 2 pi / 0.035 + 1 = 181

struct BoxSamples {
  std::array<std::array<Slab, kMovingParts>, kMaxSamples> parts;
  std::size_t count{0};
};

void sample(const SiteCrane& c, const JointBox& box, BoxSamples& out) noexcept {
  const double span = box.slew_high - box.slew_low;
  std::size_t n = 1;
  if (span > 0.0) {
    n = std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(span / CraneEnvelope::kMaxSlewStep)) + 1, 2, kMaxSamples);
  }
  const double step = n > 1 ? span / static_cast<double>(n - 1) : 0.0;
  const double half_width = c.jib_width / 2.0;
  const double hanging = box.swing_radius + c.load_radius;
  const double reach = std::max({c.jib_length + half_width, c.counter_jib_length + half_width, box.trolley_high + hanging});
  const double pad = n > 1 ? 2.0 * reach * std::sin(step / 4.0) : 0.0;
  const Vector3 base(c.base[0], c.base[1], 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double heading = c.slew_zero_heading + box.slew_low + static_cast<double>(i) * step;
    const Vector3 u(std::cos(heading), std::sin(heading), 0.0);
    auto& p = out.parts[i];
    p[kJib] = {base, base + c.jib_length * u, half_width + pad, c.jib_height, c.jib_height + c.jib_depth};
    p[kCounterJib] = {base, base - c.counter_jib_length * u, half_width + pad, c.jib_height, c.jib_height + c.jib_depth};
    p[kHanging] = {base + box.trolley_low * u, base + box.trolley_high * u, hanging + pad,
                   c.jib_height - box.cable_high - c.load_radius, c.jib_height};
  }
  out.count = n;
}

Slab mast(const SiteCrane& c) noexcept {
  const Vector3 base(c.base[0], c.base[1], 0.0);
  return {base, base, mast_radius(c), 0.0, c.jib_height};
}

void keep(PairDistance& best, double d, Part first, Part second) noexcept {
  if (d < best.distance) best = {d, first, second};
}

JointBox box_of(const Pose& from, const Pose& to, const PathAllowance& allowance) noexcept {
  JointBox box;
  const bool travels = from.slew != to.slew || from.trolley != to.trolley;
  box.slew_low = std::min(from.slew, to.slew);
  box.slew_high = std::max(from.slew, to.slew);
  box.trolley_low = std::min(from.trolley, to.trolley);
  box.trolley_high = std::max(from.trolley, to.trolley);
  // The overshoot past the goal, in the direction of the motion.
  if (to.slew > from.slew) box.slew_high += allowance.slew_overshoot;
  if (to.slew < from.slew) box.slew_low -= allowance.slew_overshoot;
  if (to.trolley > from.trolley) box.trolley_high += allowance.trolley_overshoot;
  if (to.trolley < from.trolley) box.trolley_low = std::max(0.0, box.trolley_low - allowance.trolley_overshoot);
  // The tracking allowance on either side: the travel's, or where the trolley and the slew hold.
  const double slew_tracking = travels ? allowance.slew_tracking : allowance.slew_hold;
  const double trolley_tracking = travels ? allowance.trolley_tracking : allowance.trolley_hold;
  box.slew_low -= slew_tracking;
  box.slew_high += slew_tracking;
  box.trolley_low = std::max(0.0, box.trolley_low - trolley_tracking);
  box.trolley_high += trolley_tracking;
  box.cable_low = std::min(from.cable_length, to.cable_length);
  box.cable_high = std::max(from.cable_length, to.cable_length);
  box.swing_radius = travels ? box.cable_high * std::sin(allowance.travel_swing) : allowance.hoist_swing_radius;
  return box;
}

}  // namespace

Airspace rest_airspace(const Pose& pose, const PathAllowance& allowance) noexcept {
  Airspace out;
  out.boxes[0] = box_of(pose, pose, allowance);
  out.count = 1;
  return out;
}

Airspace path_airspace(std::span<const Pose> waypoints, const PathAllowance& allowance) noexcept {
  if (waypoints.size() <= 1) return waypoints.empty() ? Airspace{} : rest_airspace(waypoints[0], allowance);
  Airspace out;
  for (std::size_t i = 1; i < waypoints.size() && out.count < Airspace::kMaxBoxes; ++i) {
    out.boxes[out.count++] = box_of(waypoints[i - 1], waypoints[i], allowance);
  }
  return out;
}

std::vector<Pose> stops_of(std::span<const Pose> waypoints) {
  const auto travels_at = [](const Pose& a, const Pose& b, double cable) {
    return (a.slew != b.slew || a.trolley != b.trolley) && std::abs(a.cable_length - cable) <= kSameCable &&
           std::abs(b.cable_length - cable) <= kSameCable;
  };
  std::vector<Pose> out;
  for (std::size_t k = 0; k < waypoints.size(); ++k) {
    // Waypoint k lies inside a run when the segments on both sides of it travel at its cable.
    const bool inside = k > 0 && k + 1 < waypoints.size() &&
                        travels_at(waypoints[k - 1], waypoints[k], waypoints[k].cable_length) &&
                        travels_at(waypoints[k], waypoints[k + 1], waypoints[k].cable_length);
    if (!inside) out.push_back(waypoints[k]);
  }
  return out;
}

Airspace out_of_service_airspace(const SiteCrane& crane, const Airspace& held, const CraneMotion& last,
                                 double report_age) noexcept {
  const auto faster = [&](double speed, double deceleration) {
    return speed + (speed < 0.0 ? -1.0 : 1.0) * deceleration * report_age;
  };
  CraneMotion braked = last;
  braked.trolley_velocity = faster(last.trolley_velocity, crane.stopping.trolley_deceleration);
  braked.slew_rate = faster(last.slew_rate, crane.stopping.slew_deceleration);
  braked.cable_rate = 0.0;  // the box's longest cable is taken below
  Airspace out = held;
  for (std::size_t i = 0; i < out.count; ++i) {
    JointBox& box = out.boxes[i];
    braked.cable_length = box.cable_high;
    braked.trolley = box.trolley_high;  // the largest radius: the sheave's fastest
    box.swing_radius = stopping_travel(crane, braked, StopKind::emergency).swing_radius;
  }
  return out;
}

bool same_airspace(const Airspace& a, const Airspace& b) noexcept {
  return a.count == b.count && a.count <= Airspace::kMaxBoxes &&
         std::equal(a.boxes.begin(), a.boxes.begin() + static_cast<std::ptrdiff_t>(a.count), b.boxes.begin());
}

Airspace whole_reach(const SiteCrane& c, const PathAllowance& allowance) noexcept {
  Airspace out;
  JointBox& box = out.boxes[0];
  box.slew_low = -std::numbers::pi;
  box.slew_high = std::numbers::pi;
  box.trolley_low = c.trolley_min;
  box.trolley_high = c.trolley_max;
  box.cable_low = c.jib_height - c.hook_height_max;
  box.cable_high = c.jib_height - c.hook_height_min;
  box.swing_radius = box.cable_high * std::sin(allowance.travel_swing);
  out.count = 1;
  return out;
}

namespace {

// The one loop: with kPrune, a pair may_be_closer() rules out is skipped (the same answer, sooner).
template <bool kPrune>
PairDistance closest(const SiteCrane& first, const Airspace& a, const SiteCrane& second, const Airspace& b) noexcept {
  PairDistance best{std::numeric_limits<double>::infinity(), Part::jib, Part::jib};
  if (a.count == 0 || b.count == 0) return best;
  const Slab mast_a = mast(first);
  const Slab mast_b = mast(second);
  keep(best, slab_distance(mast_a, mast_b), Part::mast, Part::mast);
  // thread_local: two samplings of up to a full turn each (about 80 kB) stay off the stack.
  thread_local BoxSamples sa;
  thread_local BoxSamples sb;
  for (std::size_t i = 0; i < b.count; ++i) {
    sample(second, b.boxes[i], sb);
    for (std::size_t s = 0; s < sb.count; ++s) {
      for (std::size_t q = 0; q < kMovingParts; ++q) {
        if (!kPrune || may_be_closer(mast_a, sb.parts[s][q], best.distance)) {
          keep(best, slab_distance(mast_a, sb.parts[s][q]), Part::mast, kPartOf[q]);
        }
      }
    }
  }
  for (std::size_t i = 0; i < a.count; ++i) {
    sample(first, a.boxes[i], sa);
    for (std::size_t s = 0; s < sa.count; ++s) {
      for (std::size_t p = 0; p < kMovingParts; ++p) {
        if (!kPrune || may_be_closer(sa.parts[s][p], mast_b, best.distance)) {
          keep(best, slab_distance(sa.parts[s][p], mast_b), kPartOf[p], Part::mast);
        }
      }
    }
    for (std::size_t j = 0; j < b.count; ++j) {
      sample(second, b.boxes[j], sb);
      for (std::size_t s = 0; s < sa.count; ++s) {
        for (std::size_t t = 0; t < sb.count; ++t) {
          for (std::size_t p = 0; p < kMovingParts; ++p) {
            for (std::size_t q = 0; q < kMovingParts; ++q) {
              if (!kPrune || may_be_closer(sa.parts[s][p], sb.parts[t][q], best.distance)) {
                keep(best, slab_distance(sa.parts[s][p], sb.parts[t][q]), kPartOf[p], kPartOf[q]);
              }
            }
          }
        }
      }
    }
  }
  return best;
}

}  // namespace

PairDistance airspace_distance(const SiteCrane& first, const Airspace& a, const SiteCrane& second,
                               const Airspace& b) noexcept {
  return closest<true>(first, a, second, b);
}

namespace internal {
PairDistance airspace_distance_every_pair(const SiteCrane& first, const Airspace& a, const SiteCrane& second,
                                          const Airspace& b) noexcept {
  return closest<false>(first, a, second, b);
}
}  // namespace internal

}  // namespace crane::anti_collision
