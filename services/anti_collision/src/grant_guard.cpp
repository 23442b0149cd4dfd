#include "crane/anti_collision/grant_guard.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "crane/anti_collision/site_arbiter.hpp"

namespace crane::anti_collision {
namespace {

bool within(double x, double low, double high, double tolerance) noexcept {
  return x >= low - tolerance && x <= high + tolerance;
}

bool in_box(const JointBox& b, const Pose& p, double tolerance) noexcept {
  return within(p.slew, b.slew_low, b.slew_high, tolerance) &&
         within(p.trolley, b.trolley_low, b.trolley_high, tolerance) &&
         within(p.cable_length, b.cable_low, b.cable_high, tolerance);
}

bool same(const Pose& a, const Pose& b) noexcept {
  return std::abs(a.slew - b.slew) <= kPathTolerance && std::abs(a.trolley - b.trolley) <= kPathTolerance &&
         std::abs(a.cable_length - b.cable_length) <= kPathTolerance;
}

// A place on a granted path: segment k (granted[k] -> granted[k + 1]) and the point of it.
struct Place {
  std::size_t segment{0};
  Pose at{};
};

// x between the segment's ends a and b (either order), within kPathTolerance.
bool between(double a, double b, double x) noexcept {
  return within(x, std::min(a, b), std::max(a, b), kPathTolerance);
}

// Where part[0] lies on `granted` when part's other waypoints are granted's last ones (narrows());
// nullopt when it is not on it.
std::optional<Place> place_on(std::span<const Pose> granted, std::span<const Pose> part) noexcept {
  const std::size_t n = part.size();
  const std::size_t m = granted.size();
  if (n == 0 || n > m) return std::nullopt;
  for (std::size_t k = 1; k < n; ++k) {
    if (!same(part[k], granted[m - n + k])) return std::nullopt;
  }
  const std::size_t segment = m - n;
  const Pose& p = part[0];
  if (same(p, granted[segment])) return Place{segment, granted[segment]};
  if (segment + 1 >= m) return std::nullopt;
  const Pose& from = granted[segment];
  const Pose& to = granted[segment + 1];
  if (!between(from.slew, to.slew, p.slew) || !between(from.trolley, to.trolley, p.trolley) ||
      !between(from.cable_length, to.cable_length, p.cable_length) || same(p, to)) {
    return std::nullopt;
  }
  return Place{segment, p};
}

// True when `later` is further along the path than `earlier` (see narrows()).
bool further(std::span<const Pose> granted, const Place& later, const Place& earlier) noexcept {
  if (later.segment != earlier.segment) return later.segment > earlier.segment;
  const Pose& from = granted[later.segment];
  bool ahead = false;
  const auto axis = [&](double start, double l, double e) {
    const double dl = std::abs(l - start);
    const double de = std::abs(e - start);
    ahead = ahead || dl > de + kPathTolerance;
    return dl >= de - kPathTolerance;
  };
  const bool slew = axis(from.slew, later.at.slew, earlier.at.slew);
  const bool trolley = axis(from.trolley, later.at.trolley, earlier.at.trolley);
  const bool cable = axis(from.cable_length, later.at.cable_length, earlier.at.cable_length);
  return slew && trolley && cable && ahead;
}

// One axis of passed_point().
double passed_on_axis(double from, double to, double position, double passed) noexcept {
  const double travel = std::abs(to - from);
  // 1e-9: a whole number of steps in decimal (0.6 / 0.1 = 5.999999999999999) counts as whole.
  const double last = std::floor(travel / kProgressStep + 1e-9) - 1.0;  // at least a step short of `to`
  if (!(last >= 1.0) || !std::isfinite(position)) return passed;
  const double come = std::clamp((position - from) / (to - from), 0.0, 1.0) * travel;
  const double steps = std::min(std::floor(come / kProgressStep + 1e-9), last);
  const double here = from + std::copysign(steps * kProgressStep, to - from);
  return std::abs(here - from) > std::abs(passed - from) ? here : passed;
}

}  // namespace

bool contains(const Airspace& airspace, const Pose& pose, double tolerance) noexcept {
  const std::size_t count = std::min(airspace.count, Airspace::kMaxBoxes);
  for (std::size_t i = 0; i < count; ++i) {
    if (in_box(airspace.boxes[i], pose, tolerance)) return true;
  }
  return false;
}

Pose passed_point(const Pose& from, const Pose& to, const Pose& pose, const Pose& passed) noexcept {
  return {passed_on_axis(from.slew, to.slew, pose.slew, passed.slew),
          passed_on_axis(from.trolley, to.trolley, pose.trolley, passed.trolley),
          passed_on_axis(from.cable_length, to.cable_length, pose.cable_length, passed.cable_length)};
}

bool narrows(std::span<const Pose> granted, std::span<const Pose> held, std::span<const Pose> reported) noexcept {
  if (granted.empty()) return false;
  const std::optional<Place> now = held.empty() ? std::optional<Place>(Place{0, granted[0]}) : place_on(granted, held);
  const std::optional<Place> next = place_on(granted, reported);
  return now && next && further(granted, *next, *now);
}

const char* to_string(GrantAction action) noexcept {
  switch (action) {
    case GrantAction::proceed: return "proceed";
    case GrantAction::soft_stop: return "soft_stop";
    case GrantAction::finish_path: return "finish_path";
    case GrantAction::emergency_stop: return "emergency_stop";
  }
  return "unknown";
}

GrantGuard::GrantGuard(const SiteLayout& layout, std::size_t crane) : layout_(layout), crane_(crane) {
  if (crane >= layout_.cranes.size()) {
    throw std::out_of_range("grant guard: crane " + std::to_string(crane) + " is not on the site (" +
                            std::to_string(layout_.cranes.size()) + " cranes)");
  }
}

void GrantGuard::grant(const Airspace& granted, double time) noexcept {
  granted_ = granted;
  has_grant_ = true;
  granted_shared_ = in_shared_airspace(layout_, crane_, granted_);
  heard(time);
}

void GrantGuard::heard(double time) noexcept {
  if (std::isfinite(time)) last_heard_ = std::max(last_heard_, time);
}

void GrantGuard::progress(const Airspace& remaining) noexcept {
  if (!has_grant_) return;
  granted_ = remaining;
  granted_shared_ = in_shared_airspace(layout_, crane_, granted_);
}

bool GrantGuard::link_lost(double time) const noexcept {
  return !(time - last_heard_ < layout_.link_deadline);
}

bool GrantGuard::must_leave_shared_airspace(double time) const noexcept {
  return has_grant_ && granted_shared_ && link_lost(time);
}

namespace {

// Where an axis ends in a soft stop: inside the box by kContainmentTolerance on each axis the stop
// carries further than that (carried 2 x kContainmentTolerance further, then contained with the
// tolerance): the tolerance is the drives' tracking, not the stopping model's error. An axis at
// rest (its measured speed's noise) is contained as it stands; one whose reference rests ends there.
double soft_stop_end(const std::optional<double>& rest, double position, double travel) noexcept {
  if (rest) return std::isfinite(*rest) ? *rest : std::numeric_limits<double>::quiet_NaN();
  return position + travel +
         (travel > kContainmentTolerance    ? 2.0 * kContainmentTolerance
          : travel < -kContainmentTolerance ? -2.0 * kContainmentTolerance
                                            : 0.0);
}

}  // namespace

bool GrantGuard::soft_stop_stays_in_grant(const CraneMotion& m, const ReferenceRest& reference) const noexcept {
  if (!has_grant_ || !is_finite(m)) return false;
  const StoppingTravel stop = stopping_travel(layout_.cranes[crane_], m, StopKind::soft);
  return contains(granted_, {soft_stop_end(reference.slew, m.slew, stop.slew),
                             soft_stop_end(reference.trolley, m.trolley, stop.trolley),
                             soft_stop_end(reference.cable_length, m.cable_length, stop.cable)});
}

std::optional<std::uint8_t> GrantGuard::soft_stop_axes(const CraneMotion& m, const ReferenceRest& reference,
                                                       const Pose& targets) const noexcept {
  if (!has_grant_ || !is_finite(m) || !std::isfinite(targets.slew) || !std::isfinite(targets.trolley) ||
      !std::isfinite(targets.cable_length)) {
    return std::nullopt;
  }
  const StoppingTravel stop = stopping_travel(layout_.cranes[crane_], m, StopKind::soft);
  // Per axis, in the order slew, trolley, cable length.
  const std::array<std::optional<double>, 3> rest{reference.slew, reference.trolley, reference.cable_length};
  const std::array<double, 3> position{m.slew, m.trolley, m.cable_length};
  const std::array<double, 3> travel{stop.slew, stop.trolley, stop.cable};
  const std::array<double, 3> target{targets.slew, targets.trolley, targets.cable_length};
  const std::array<double, 3> speed{m.slew_rate, m.trolley_velocity, m.cable_rate};
  const std::array<std::uint8_t, 3> bit{kStopSlew, kStopTrolley, kStopHoist};
  // The axes that move: their reference does not rest, and their stop carries them further than
  // the tolerance (not the measured speed's noise).
  std::uint8_t moving = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    if (!rest[i] && std::abs(travel[i]) > kContainmentTolerance) moving = static_cast<std::uint8_t>(moving | (1U << i));
  }
  std::optional<std::uint8_t> best;
  int best_stopped = -1;
  double best_time = std::numeric_limits<double>::infinity();
  // Every choice of the moving axes that run on (bit i: axis i); all of them is the move's own end.
  for (unsigned run_on = 0; run_on < 8U; ++run_on) {
    if ((run_on & ~static_cast<unsigned>(moving)) != 0 || (moving != 0 && run_on == moving)) continue;
    std::array<double, 3> end{};
    int stopped = 0;
    double time = 0.0;  // [s] the longest time to go of the axes that run on
    for (std::size_t i = 0; i < 3; ++i) {
      if ((run_on & (1U << i)) != 0) {
        end[i] = target[i];
        // Decelerating evenly to the target takes twice distance over speed.
        time = std::max(time, 2.0 * std::abs(target[i] - position[i]) / std::max(std::abs(speed[i]), 1e-3));
      } else {
        end[i] = soft_stop_end(rest[i], position[i], travel[i]);
        if ((moving & (1U << i)) != 0) ++stopped;
      }
    }
    if (!contains(granted_, {end[0], end[1], end[2]})) continue;
    if (stopped > best_stopped || (stopped == best_stopped && time < best_time)) {
      std::uint8_t axes = 0;
      for (std::size_t i = 0; i < 3; ++i) {
        if ((run_on & (1U << i)) == 0) axes = static_cast<std::uint8_t>(axes | bit[i]);
      }
      best = axes;
      best_stopped = stopped;
      best_time = time;
    }
  }
  return best;
}

GrantCheck GrantGuard::check(const CraneMotion& m, double time) const noexcept {
  if (!is_finite(m)) return {GrantAction::emergency_stop, "the measured motion is not finite"};
  const SiteCrane& crane = layout_.cranes[crane_];
  const Pose pose{m.slew, m.trolley, m.cable_length};
  const StoppingTravel stop = stopping_travel(crane, m, StopKind::emergency);
  const Pose stopped{m.slew + stop.slew, m.trolley + stop.trolley, m.cable_length + stop.cable};
  if (!has_grant_) {
    const bool moving = std::abs(stop.slew) > kContainmentTolerance || std::abs(stop.trolley) > kContainmentTolerance ||
                        std::abs(stop.cable) > kContainmentTolerance;
    if (moving) return {GrantAction::emergency_stop, "moving with no grant"};
    return {GrantAction::proceed, "at rest with no grant"};
  }
  if (!contains(granted_, pose) || !contains(granted_, stopped)) {
    return {GrantAction::emergency_stop, "leaving its grant"};
  }
  if (must_leave_shared_airspace(time)) {
    if (!soft_stop_stays_in_grant(m)) {
      return {GrantAction::finish_path,
              "link to the site service lost, its grant in shared airspace; a soft stop would leave the grant: the "
              "move ends at its waypoint"};
    }
    return {GrantAction::soft_stop, "link to the site service lost, its grant in shared airspace"};
  }
  double allowed = 0.0;
  const std::size_t count = std::min(granted_.count, Airspace::kMaxBoxes);
  for (std::size_t i = 0; i < count; ++i) {
    if (in_box(granted_.boxes[i], pose, kContainmentTolerance)) allowed = std::max(allowed, granted_.boxes[i].swing_radius);
  }
  if (stopping_travel(crane, m, StopKind::none).swing_radius > allowed + kContainmentTolerance) {
    return {GrantAction::soft_stop, "the load swings wider than its grant allows"};
  }
  return {};
}

}  // namespace crane::anti_collision
