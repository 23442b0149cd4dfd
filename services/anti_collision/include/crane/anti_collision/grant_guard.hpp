#pragma once
// Each crane's own enforcement of its grant (issue 34, item 4; docs/site.md, "The crane's own
// guard"): what a crane checks every cycle against the airspace the site service granted it,
// without the service. A pure core (no clock, no DDS, no allocation): the crane's supervisor, the
// simulated site and the tests call it the same way.
//
// The crane keeps the last grant it heard (the airspace the service holds for it: a rest box, a
// path or a yield; airspace.hpp) and the time it last heard the service. check() answers, in this
// order (the first that holds):
//   1. emergency_stop  the measured motion is not finite (is_finite);
//   2. emergency_stop  no grant heard yet and the crane moves (its emergency stop would carry an
//                      axis further than kContainmentTolerance): nothing is allowed by default;
//   3. emergency_stop  the crane's emergency stop decided now (the pose plus stopping_travel(...,
//                      StopKind::emergency) on each axis) ends outside every box of its grant,
//                      or the pose itself is outside: it has left, or is about to leave, what it
//                      was granted (a crane that disobeys; the site service's geometry assumes
//                      it never does);
//   4. soft_stop       the link is lost (nothing heard for the site's link_deadline, or never) and
//                      the grant is in shared airspace (in_shared_airspace: within
//                      margins.slow_down of another crane's whole reach): the service now holds
//                      this crane's whole reach, and the crane keeps out of shared airspace on its
//                      own; a grant outside shared airspace is finished;
//      finish_path     the same, when a soft stop decided now would end outside the grant
//                      (soft_stop_stays_in_grant: a fast move near its goal, the shaped stop running
//                      past it): the move under way ends at its waypoint, inside the grant, sooner.
//                      check() judges the measured motion alone (the supervisor trusts no control
//                      process); the crane's site link, which sends the stop, also tells
//                      soft_stop_stays_in_grant where the planner's reference rests;
//   5. soft_stop       the load swings wider than the grant's allowance where the crane is (the
//                      largest swing radius of the boxes that contain the pose);
//   6. proceed.
// Containment is per box of joint space with `kContainmentTolerance` on each axis: slew, trolley
// and cable length each within the box's interval widened by it. A box's intervals are the
// plan's (a slew-only segment has a zero-width trolley interval); the tolerance is what the
// drives' tracking may deviate across them (the trolley held by its position loop while the jib
// slews, the dither of the friction compensation). It is paid for by the site's margins: a grant
// keeps margins.slow_down, and 0.02 m of trolley plus 0.02 rad at the lab jib's 1.4 m is 0.05 m,
// within the 0.10 m between slow_down and stop. The stop's end point is tested, not the stop's sweep: a box is convex in joint space
// and the boxes of a path share their waypoints, so a stop that starts in one box and ends in it
// or in the next stays in the union.
//
// Errors: std::out_of_range for a crane index not on the site; check() itself never throws.

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

/// [m] and [rad]: how far outside a box a pose may be and still count as inside it (see the header).
inline constexpr double kContainmentTolerance = 0.02;

/// True when `pose` lies within `tolerance` of at least one box of `airspace` on every axis.
[[nodiscard]] bool contains(const Airspace& airspace, const Pose& pose, double tolerance = kContainmentTolerance) noexcept;

// Progress within a segment (docs/site.md, "Progress within a segment"). A crane moving from one
// waypoint of its grant to the next tells the site service, every kProgressStep of an axis's
// travel, the point of the segment it has passed on each axis; it then holds the segment from
// that point on, and the service frees what lies behind it for the other cranes. The crane's guard
// holds the same. It only narrows: each axis of the point lies between the segment's ends, so the
// box from it to the segment's end lies in the segment's box, and keeps the tracking allowance
// on either side of the new start.

/// [m or rad] of an axis's travel on a segment between two reports of a crane's progress on it;
/// none is made on an axis within its last step (the waypoint's own report follows).
inline constexpr double kProgressStep = 0.1;
/// [m or rad] how far a reported pose may lie outside the grant's own waypoints, or the segment
/// between two of them, and still be on the path (a double sent over DDS is exact; the site link
/// rounds a cable length within 1e-9 of its travel length to it).
inline constexpr double kPathTolerance = 1e-6;

/// The point of the segment `from` -> `to` that a crane at `pose` has passed, given the point
/// `passed` it had passed before (`from` at first): on each axis the further of `passed` and the
/// whole kProgressStep the pose has come from `from` toward `to`, at least a step short of `to`. An
/// axis that travels less than two steps stays at `from`; a pose behind, or not finite, passes
/// nothing new.
[[nodiscard]] Pose passed_point(const Pose& from, const Pose& to, const Pose& pose, const Pose& passed) noexcept;

/// True when `reported` is a crane's progress on the grant through `granted` past `held`: both are
/// the rest of that path from a place on it (their waypoints after the first are granted's last
/// ones, each axis within kPathTolerance; their first is the waypoint before those, or a point of
/// the segment from it to the next: each axis between the two ends), and `reported` starts
/// further along: on a later segment, or on the same one with every axis at least as far from the
/// segment's start and one further (an empty `held`: the whole grant). What the crane holds only
/// narrows: the site service and the crane's supervisor take a report only when this holds.
/// noexcept, no allocation; false for anything else (an empty `reported`, one longer than
/// `granted`, a point off the segment).
[[nodiscard]] bool narrows(std::span<const Pose> granted, std::span<const Pose> held,
                           std::span<const Pose> reported) noexcept;

/// Where the planner's reference rests on each axis a grant bounds: set for an axis whose reference
/// speed and acceleration are both within kReferenceAtRest of zero, std::nullopt for one that moves
/// (or when the reference is not known).
struct ReferenceRest {
  std::optional<double> slew;          // [rad]
  std::optional<double> trolley;       // [m]
  std::optional<double> cable_length;  // [m]
};
/// The axes of a stop (GrantGuard::soft_stop_axes): MoveRequest's AXIS_TROLLEY, AXIS_SLEW,
/// AXIS_HOIST (crane_site_link.cpp checks that they are the same).
inline constexpr std::uint8_t kStopTrolley = 1;
inline constexpr std::uint8_t kStopSlew = 2;
inline constexpr std::uint8_t kStopHoist = 4;
/// [m/s, rad/s, m/s^2, rad/s^2]: a reference axis's speed and acceleration this close to zero is at rest.
inline constexpr double kReferenceAtRest = 1e-9;

enum class GrantAction : std::uint8_t { proceed, soft_stop, finish_path, emergency_stop };
/// "proceed", "soft_stop", "finish_path", "emergency_stop".
[[nodiscard]] const char* to_string(GrantAction action) noexcept;

struct GrantCheck {
  GrantAction action{GrantAction::proceed};
  const char* reason{"within its grant"};  // a static string naming the rule (see the header)
};

class GrantGuard {
 public:
  /// The guard of crane `crane` of `layout` (copied). std::out_of_range for a crane index not on
  /// the site.
  GrantGuard(const SiteLayout& layout, std::size_t crane);

  /// A grant heard at `time` [s]: the airspace the service now holds for this crane. Also a
  /// message from the service (heard).
  void grant(const Airspace& granted, double time) noexcept;
  /// Any message from the site service heard at `time` [s] (its heartbeat, an instruction to
  /// another crane): the link is alive.
  void heard(double time) noexcept;
  /// The crane's own progress: it holds only `remaining` now (the part of its path ahead). The
  /// service is told the same (SiteArbiter::progress); the guard does not wait for it.
  void progress(const Airspace& remaining) noexcept;

  /// The rules of the header for `motion` measured at `time` [s]. noexcept, no allocation.
  [[nodiscard]] GrantCheck check(const CraneMotion& motion, double time) const noexcept;

  [[nodiscard]] bool has_grant() const noexcept { return has_grant_; }
  [[nodiscard]] const Airspace& granted() const noexcept { return granted_; }
  /// True when nothing was heard from the service for link_deadline at `time` (or never).
  [[nodiscard]] bool link_lost(double time) const noexcept;
  /// Rule 4 alone: the link is lost at `time` and the grant is in shared airspace.
  [[nodiscard]] bool must_leave_shared_airspace(double time) const noexcept;
  /// True when a soft stop decided now (stopping_travel(..., StopKind::soft): shaped when the
  /// crane's stopping data says so) ends inside the grant, and inside a box by kContainmentTolerance
  /// on each axis the stop carries further than that (the tolerance is for the drives' tracking;
  /// a stop decided while the drive still accelerates runs further than the model, which takes
  /// the speed as constant: 0.26 rad against 0.237 predicted from 0.41 rad/s, a seeded lost-link
  /// case of the simulated site). An axis whose planner reference rests (`reference`, when the
  /// caller knows it) ends where its reference rests, whatever its measured speed: the planner's
  /// soft stop brings the reference's speed to zero from where it is, so a reference at rest stays,
  /// and the drive's tracking brings the crane to it, as the move's own end would (a load settling
  /// at its goal, the measured slew still swinging past it). When the stop would not stay inside
  /// (a fast slew near its goal: the shaped stop runs past it), the crane's move to its next
  /// waypoint is the shorter way to rest inside what it holds.
  [[nodiscard]] bool soft_stop_stays_in_grant(const CraneMotion& motion,
                                              const ReferenceRest& reference = {}) const noexcept;
  /// The axes a soft stop decided now should stop so that the crane rests inside its grant, when
  /// the others run on to `targets` ([rad, m, m]: the targets of the move under way): bits
  /// kStopTrolley, kStopSlew, kStopHoist (the MoveRequest AXIS_* bits its COMMAND_STOP names).
  /// Every axis when soft_stop_stays_in_grant(motion, reference). Otherwise, of the choices whose
  /// end (a stopped axis as soft_stop_stays_in_grant ends it, one that runs on at its target) lies
  /// inside the grant, the one that stops the most moving axes (an axis whose reference rests, or
  /// whose stop carries it no further than kContainmentTolerance, is not moving: it is named), then
  /// the one whose axes that run on have the least time to go (twice their distance to go over
  /// their measured speed). A fast trolley just short of its
  /// goal, whose shaped stop would run past it, goes on to the goal while the slew stops. nullopt
  /// when no choice but every moving axis running on (the move's own end) stays inside, or with no
  /// grant, a non-finite motion or target: the move under way ends at its waypoint.
  [[nodiscard]] std::optional<std::uint8_t> soft_stop_axes(const CraneMotion& motion, const ReferenceRest& reference,
                                                           const Pose& targets) const noexcept;

 private:
  SiteLayout layout_;
  std::size_t crane_;
  Airspace granted_{};
  bool has_grant_{false};
  bool granted_shared_{false};  // in_shared_airspace(granted_), computed when the grant changes
  double last_heard_{-std::numeric_limits<double>::infinity()};
};

}  // namespace crane::anti_collision
