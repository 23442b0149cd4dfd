#include "crane/anti_collision/crane_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace crane::anti_collision {
namespace {

constexpr double kMinCable = 0.01;  // [m] the swing frequency's cable length is at least this

double travel(double speed, double deceleration, double reaction_time, double shaping_delay) noexcept {
  const double v = std::abs(speed);
  return v * (reaction_time + shaping_delay) + v * v / (2.0 * deceleration);
}

double sign(double x) noexcept { return x > 0.0 ? 1.0 : x < 0.0 ? -1.0 : 0.0; }

}  // namespace

double segment_distance(const Vector3& p0, const Vector3& p1, const Vector3& q0, const Vector3& q1) noexcept {
  // Ericson (2005), 5.1.9 ClosestPtSegmentSegment: s on [p0, p1], t on [q0, q1], both clamped.
  constexpr double kEpsilon = 1e-12;
  const Vector3 d1 = p1 - p0;
  const Vector3 d2 = q1 - q0;
  const Vector3 r = p0 - q0;
  const double a = d1.squaredNorm();
  const double e = d2.squaredNorm();
  const double f = d2.dot(r);
  double s = 0.0;
  double t = 0.0;
  if (a <= kEpsilon && e <= kEpsilon) return r.norm();
  if (a <= kEpsilon) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= kEpsilon) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2);
      const double denominator = a * e - b * b;  // >= 0; 0 when parallel
      s = denominator > kEpsilon * a * e ? std::clamp((b * f - c * e) / denominator, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  return ((p0 + s * d1) - (q0 + t * d2)).norm();
}

namespace {

// The gap [m] between the height intervals [a0, a1] and [b0, b1] (either end first); 0 when they meet.
double height_gap(double a0, double a1, double b0, double b1) noexcept {
  return std::max({0.0, std::min(b0, b1) - std::max(a0, a1), std::min(a0, a1) - std::max(b0, b1)});
}

// Combines a plan distance less the radii (`plan`, negative inside) and a height gap: Pythagoras
// apart, the plan's (negative: overlapping) where the heights meet.
double combine(double plan, double gap) noexcept {
  return gap > 0.0 ? std::hypot(std::max(0.0, plan), gap) : plan;
}

// The segment [p0, p1] (its radius not counted) against the upright cylinder `u`.
double segment_upright_distance(const Vector3& p0, const Vector3& p1, const Capsule& u) noexcept {
  const double cx = u.a.x();
  const double cy = u.a.y();
  constexpr double kFlat = 1e-12;  // [m] a segment this close to horizontal or vertical is one
  if (std::abs(p1.z() - p0.z()) <= kFlat) {
    // The plan distance: segment_distance with every point at height 0, the axis a point.
    const Vector3 axis(cx, cy, 0.0);
    return combine(segment_distance(axis, axis, Vector3(p0.x(), p0.y(), 0.0), Vector3(p1.x(), p1.y(), 0.0)) - u.radius,
                   height_gap(p0.z(), p0.z(), u.a.z(), u.b.z()));
  }
  if (std::hypot(p1.x() - p0.x(), p1.y() - p0.y()) <= kFlat) {
    return combine(std::hypot(p0.x() - cx, p0.y() - cy) - u.radius, height_gap(p0.z(), p1.z(), u.a.z(), u.b.z()));
  }
  // Any other segment: the distance from a point moving along it to the solid cylinder (a convex
  // set) is convex in the point's parameter, so golden-section search finds its minimum.
  const auto at = [&](double t) {
    const Vector3 p = p0 + t * (p1 - p0);
    return combine(std::hypot(p.x() - cx, p.y() - cy) - u.radius, height_gap(p.z(), p.z(), u.a.z(), u.b.z()));
  };
  const double ratio = (std::sqrt(5.0) - 1.0) / 2.0;
  double lo = 0.0;
  double hi = 1.0;
  double x1 = hi - ratio * (hi - lo);
  double x2 = lo + ratio * (hi - lo);
  double f1 = at(x1);
  double f2 = at(x2);
  for (int k = 0; k < 80; ++k) {
    if (f1 <= f2) {
      hi = x2;
      x2 = x1;
      f2 = f1;
      x1 = hi - ratio * (hi - lo);
      f1 = at(x1);
    } else {
      lo = x1;
      x1 = x2;
      f1 = f2;
      x2 = lo + ratio * (hi - lo);
      f2 = at(x2);
    }
  }
  return std::min({f1, f2, at(0.0), at(1.0)});
}

}  // namespace

double capsule_distance(const Capsule& first, const Capsule& second) noexcept {
  if (first.upright && second.upright) {
    return combine(std::hypot(first.a.x() - second.a.x(), first.a.y() - second.a.y()) - first.radius - second.radius,
                   height_gap(first.a.z(), first.b.z(), second.a.z(), second.b.z()));
  }
  if (second.upright) return segment_upright_distance(first.a, first.b, second) - first.radius;
  if (first.upright) return segment_upright_distance(second.a, second.b, first) - second.radius;
  return segment_distance(first.a, first.b, second.a, second.b) - first.radius - second.radius;
}

const char* to_string(Part part) noexcept {
  switch (part) {
    case Part::jib: return "jib";
    case Part::counter_jib: return "counter_jib";
    case Part::mast: return "mast";
    case Part::cable: return "cable";
    case Part::load: return "load";
  }
  return "?";
}

const char* to_string(Action action) noexcept {
  switch (action) {
    case Action::clear: return "clear";
    case Action::warning: return "warning";
    case Action::slow_down: return "slow_down";
    case Action::stop: return "stop";
    case Action::emergency_stop: return "emergency_stop";
  }
  return "?";
}

double mast_radius(const SiteCrane& crane) noexcept { return crane.mast_width * std::numbers::sqrt2 / 2.0; }
double jib_radius(const SiteCrane& crane) noexcept { return std::hypot(crane.jib_width, crane.jib_depth) / 2.0; }
double jib_bottom(const SiteCrane& crane) noexcept {
  return crane.jib_height + crane.jib_depth / 2.0 - jib_radius(crane);
}
double top_of_structure(const SiteCrane& crane) noexcept {
  return crane.jib_height + crane.jib_depth / 2.0 + jib_radius(crane);
}

bool is_finite(const CraneMotion& m) noexcept {
  const double fields[] = {m.slew,           m.slew_rate,      m.trolley,
                           m.trolley_velocity, m.cable_length, m.cable_rate,
                           m.swing_in_plane, m.swing_out_of_plane, m.swing_in_plane_rate,
                           m.swing_out_of_plane_rate};
  return std::all_of(std::begin(fields), std::end(fields), [](double x) { return std::isfinite(x); }) &&
         m.cable_length > 0.0;
}

StoppingTravel stopping_travel(const SiteCrane& crane, const CraneMotion& m, StopKind kind) noexcept {
  StoppingTravel out;
  const double cable = std::max(m.cable_length, kMinCable);
  const double omega = std::sqrt(kStandardGravity / cable);
  const double amplitude = std::sqrt(m.swing_in_plane * m.swing_in_plane + m.swing_out_of_plane * m.swing_out_of_plane +
                                     (m.swing_in_plane_rate * m.swing_in_plane_rate +
                                      m.swing_out_of_plane_rate * m.swing_out_of_plane_rate) /
                                         (omega * omega));
  const double angle = std::min(amplitude, std::numbers::pi / 2.0);
  out.swing_radius = cable * std::sin(angle);
  if (kind == StopKind::none) return out;

  const StoppingData& d = crane.stopping;
  const double factor = kind == StopKind::emergency ? d.brake_deceleration_factor : 1.0;
  const bool shaped = kind == StopKind::soft && d.soft_stop_delay_periods > 0.0;
  const double shaping_delay = shaped ? d.soft_stop_delay_periods * 2.0 * std::numbers::pi / omega : 0.0;
  const double a_trolley = d.trolley_deceleration * factor;
  const double a_slew = d.slew_deceleration * factor;
  out.slew = sign(m.slew_rate) * travel(m.slew_rate, a_slew, d.reaction_time, shaping_delay);
  out.trolley = sign(m.trolley_velocity) * travel(m.trolley_velocity, a_trolley, d.reaction_time, shaping_delay);
  out.cable = sign(m.cable_rate) * travel(m.cable_rate, d.hoist_deceleration * factor, d.reaction_time, 0.0);

  // The sheave's horizontal speed and deceleration, at the largest radius of the stop.
  const double radius = std::max(std::abs(m.trolley), std::abs(m.trolley + out.trolley));
  const double v_h = std::hypot(m.trolley_velocity, radius * m.slew_rate);
  const double a_h = std::hypot(m.trolley_velocity != 0.0 ? a_trolley : 0.0, m.slew_rate != 0.0 ? radius * a_slew : 0.0);
  const double stop_cable = std::max(cable, cable + out.cable);
  double extra = 0.0;
  if (kind == StopKind::emergency) {
    extra = std::min(v_h / std::sqrt(kStandardGravity / stop_cable), stop_cable);
  } else {
    extra = std::min((shaped ? 1.0 : 2.0) * stop_cable * a_h / kStandardGravity, stop_cable);
  }
  out.swing_radius = stop_cable * std::sin(angle) + extra;
  return out;
}

CraneEnvelope envelope(const SiteCrane& crane, const CraneMotion& m, StopKind kind) noexcept {
  CraneEnvelope out;
  const StoppingTravel stop = stopping_travel(crane, m, kind);
  const double slew_travel = std::abs(stop.slew);
  std::size_t n = 1;
  if (slew_travel > 0.0 || stop.trolley != 0.0) {
    n = std::clamp<std::size_t>(static_cast<std::size_t>(std::ceil(slew_travel / CraneEnvelope::kMaxSlewStep)) + 1, 2,
                                CraneEnvelope::kMaxSamples);
  }
  out.count = n;
  const double steps = n > 1 ? static_cast<double>(n - 1) : 1.0;
  const double slew_step = slew_travel / steps;
  const double trolley_step = std::abs(stop.trolley) / steps;
  const double reach = std::max({crane.jib_length, crane.counter_jib_length, std::abs(m.trolley) + std::abs(stop.trolley)}) +
                       jib_radius(crane) + stop.swing_radius + crane.load_radius;
  const double pad = n > 1 ? 2.0 * reach * std::sin(slew_step / 4.0) + trolley_step / 2.0 : 0.0;

  const double chord = crane.jib_height + crane.jib_depth / 2.0;
  const double cable_short = std::min(m.cable_length, m.cable_length + stop.cable);
  const double cable_long = std::max(m.cable_length, m.cable_length + stop.cable);
  // The load's centre, swung stop.swing_radius sideways on the shortest cable, is this far below
  // the sheave (0 when the envelope is wider than the cable).
  const double swung = std::min(stop.swing_radius, cable_short);
  const double highest_load = std::sqrt(std::max(0.0, cable_short * cable_short - swung * swung));
  const Vector3 axis(crane.base[0], crane.base[1], chord);
  for (std::size_t i = 0; i < n; ++i) {
    const double f = n > 1 ? static_cast<double>(i) / steps : 0.0;
    const double heading = crane.slew_zero_heading + m.slew + f * stop.slew;
    const double trolley = m.trolley + f * stop.trolley;
    const Vector3 u(std::cos(heading), std::sin(heading), 0.0);
    auto& parts = out.samples[i];
    parts[static_cast<std::size_t>(Part::jib)] = {axis, axis + crane.jib_length * u, jib_radius(crane) + pad};
    parts[static_cast<std::size_t>(Part::counter_jib)] = {axis, axis - crane.counter_jib_length * u,
                                                          jib_radius(crane) + pad};
    parts[static_cast<std::size_t>(Part::mast)] = {Vector3(crane.base[0], crane.base[1], 0.0),
                                                   Vector3(crane.base[0], crane.base[1], crane.jib_height),
                                                   mast_radius(crane)};
    const Vector3 sheave(crane.base[0] + trolley * u.x(), crane.base[1] + trolley * u.y(), crane.jib_height);
    parts[static_cast<std::size_t>(Part::cable)] = {sheave - Vector3(0.0, 0.0, cable_long), sheave,
                                                    stop.swing_radius + pad, true};
    parts[static_cast<std::size_t>(Part::load)] = {sheave - Vector3(0.0, 0.0, cable_long + crane.load_radius),
                                                   sheave - Vector3(0.0, 0.0, highest_load - crane.load_radius),
                                                   crane.load_radius + stop.swing_radius + pad, true};
  }
  return out;
}

PairDistance distance(const CraneEnvelope& first, const CraneEnvelope& second) noexcept {
  PairDistance best{std::numeric_limits<double>::infinity(), Part::jib, Part::jib};
  for (std::size_t i = 0; i < first.count; ++i) {
    for (std::size_t j = 0; j < second.count; ++j) {
      for (std::size_t p = 0; p < kPartCount; ++p) {
        for (std::size_t q = 0; q < kPartCount; ++q) {
          const double d = capsule_distance(first.samples[i][p], second.samples[j][q]);
          if (d < best.distance || std::isnan(d)) {
            best = {d, static_cast<Part>(p), static_cast<Part>(q)};
            if (std::isnan(d)) return best;
          }
        }
      }
    }
  }
  return best;
}

Action classify(double soft_distance, double emergency_distance, const Margins& margins) noexcept {
  if (std::isnan(soft_distance) || !(emergency_distance >= margins.stop)) return Action::emergency_stop;
  if (soft_distance < margins.stop) return Action::stop;
  if (soft_distance < margins.slow_down) return Action::slow_down;
  if (soft_distance < margins.warning) return Action::warning;
  return Action::clear;
}

}  // namespace crane::anti_collision
