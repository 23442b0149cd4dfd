#include "crane/anti_collision/grant_guard.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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

}  // namespace

bool contains(const Airspace& airspace, const Pose& pose, double tolerance) noexcept {
  const std::size_t count = std::min(airspace.count, Airspace::kMaxBoxes);
  for (std::size_t i = 0; i < count; ++i) {
    if (in_box(airspace.boxes[i], pose, tolerance)) return true;
  }
  return false;
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

bool GrantGuard::soft_stop_stays_in_grant(const CraneMotion& m, const ReferenceRest& reference) const noexcept {
  if (!has_grant_ || !is_finite(m)) return false;
  const StoppingTravel stop = stopping_travel(layout_.cranes[crane_], m, StopKind::soft);
  // The predicted end inside the box by kContainmentTolerance on each axis the stop carries further
  // than that (carried 2 x kContainmentTolerance further, then contained with the tolerance): the
  // tolerance is the drives' tracking, not the stopping model's error. An axis at rest (its
  // measured speed's noise) is contained as it stands; one whose reference rests ends there.
  const auto end = [](const std::optional<double>& rest, double position, double travel) {
    if (rest) return std::isfinite(*rest) ? *rest : std::numeric_limits<double>::quiet_NaN();
    return position + travel +
           (travel > kContainmentTolerance    ? 2.0 * kContainmentTolerance
            : travel < -kContainmentTolerance ? -2.0 * kContainmentTolerance
                                              : 0.0);
  };
  return contains(granted_, {end(reference.slew, m.slew, stop.slew), end(reference.trolley, m.trolley, stop.trolley),
                             end(reference.cable_length, m.cable_length, stop.cable)});
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
