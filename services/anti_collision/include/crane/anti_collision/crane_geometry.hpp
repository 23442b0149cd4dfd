#pragma once
// The parts of a tower crane on a site as capsules and upright cylinders, the space they may
// occupy until the crane is at rest after a stop, and the distance between two cranes: what the
// site's anti-collision rules are made of (issue 34). Pure functions, noexcept, no allocation: the
// site service and each crane's supervisor call them every cycle.
//
// Parts (site frame of site_layout.hpp, [m]); each an outer bound of the real part, so that a
// distance computed here never exceeds the real one. The structure's are capsules (a segment swept
// by a sphere); what hangs from the trolley is an upright cylinder with flat ends about the
// sheave's vertical (Capsule::upright), since a pendulum's swing widens it sideways and raises
// the load, but never lowers it below the cable's length:
//   jib          slew axis -> jib tip, at the jib's cross-section centre (jib_height + depth/2),
//                radius = half the cross-section's diagonal (the capsule contains the jib box)
//   counter_jib  slew axis -> tail, the same cross-section
//   mast         ground -> jib_height on the slew axis, radius = half the square section's diagonal
//   cable        upright: the sheave down to the stop's longest cable, radius = the swing envelope s
//                (below): a point of the cable at angle A from the vertical is at most L sin(A) from it
//   load         upright: from the stop's longest cable less load_radius below the sheave up to
//                sqrt(L_s^2 - s^2) less load_radius below it (L_s the stop's shortest cable: the
//                load's centre swung s sideways on a cable of L_s rises to that), radius =
//                load_radius + s. Before session 35 a capsule, whose sphere-swept ends put the swing
//                envelope below the load too, where a pendulum's load never goes (docs/site.md,
//                "The load's shape").
//
// The stopping envelope: every part over the motion from the current state to rest after a stop
// decided now (StopKind), sampled along the slew and trolley travel and inflated by how far a
// point can be between two samples (2 R sin(delta/4) of the slew step delta at the largest
// radius R, plus half the trolley step), so the union of the samples contains the whole sweep.
//   travel of an axis at speed v, deceleration a, reaction time t_r:
//     s = |v| t_r + v^2 / (2 a)  (+ |v| k T when the soft stop is input shaped, k the shaper's mean
//     delay sum A_i t_i in periods, StoppingData::soft_stop_delay_periods: ZV 1/4 (its second
//     half-impulse T/2 later), ZVD 1/2; T = 2 pi sqrt(L / g))
//   swing envelope (horizontal radius of the load about the sheave's vertical):
//     L sin(A), A = sqrt(phi^2 + theta^2 + (phi'^2 + theta'^2) / omega^2), omega = sqrt(g / L)
//     (the amplitude of the measured swing, small-angle pendulum), plus during the stop
//     soft, shaped:   L a_h / g       (a deceleration step shaped by positive impulses (ZV, ZVD)
//                                       never swings past its static deflection a_h / g)
//     soft, unshaped: 2 L a_h / g     (a deceleration step overshoots to twice the deflection)
//     emergency:      v_h / omega     (the brakes stop the trolley at once; the load keeps v_h)
//   a_h, v_h: the sheave's horizontal deceleration and speed (trolley and r x slew rate).

#include <Eigen/Core>

#include <array>
#include <cstddef>
#include <cstdint>

#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

using Vector3 = Eigen::Vector3d;

/// Standard gravity [m/s^2] of the site's swing envelopes.
inline constexpr double kStandardGravity = 9.80665;

/// A part's shape: the segment [a, b] swept by a sphere of `radius` (a capsule); or, when
/// `upright`, the cylinder of `radius` about [a, b] with flat ends, a and b then on one vertical
/// (the same x and y; capsule_distance reads x and y from a).
struct Capsule {
  Vector3 a{Vector3::Zero()};  // [m] segment ends, site frame
  Vector3 b{Vector3::Zero()};
  double radius{0.0};          // [m] >= 0
  bool upright{false};
};

/// Closest distance [m] between the segments [p0, p1] and [q0, q1] (either may be a point):
/// C. Ericson, Real-Time Collision Detection (2005), 5.1.9.
[[nodiscard]] double segment_distance(const Vector3& p0, const Vector3& p1, const Vector3& q0,
                                      const Vector3& q1) noexcept;

/// Distance [m] between the two shapes' surfaces; negative when they overlap. Two capsules: the
/// segment distance less both radii. An upright cylinder against a capsule: the distance from the
/// capsule's segment to the solid cylinder, less the capsule's radius (exact for a horizontal or
/// vertical segment, or a point; along any other segment the distance, convex there, minimised by
/// golden-section search to about 1e-15 of the segment). Two upright cylinders: the plan distance
/// of their axes less both radii, and the gap between their height intervals, combined by
/// Pythagoras (exact). Overlapping, the plan distance less the radii where the heights overlap,
/// else minus the capsule's radius.
[[nodiscard]] double capsule_distance(const Capsule& first, const Capsule& second) noexcept;

enum class Part : std::uint8_t { jib, counter_jib, mast, cable, load };
inline constexpr std::size_t kPartCount = 5;
/// "jib", "counter_jib", "mast", "cable", "load".
[[nodiscard]] const char* to_string(Part part) noexcept;

// The structure's capsules (see the header): radii and heights [m].
[[nodiscard]] double mast_radius(const SiteCrane& crane) noexcept;
[[nodiscard]] double jib_radius(const SiteCrane& crane) noexcept;
/// Lowest point of the jib's capsule above the ground [m].
[[nodiscard]] double jib_bottom(const SiteCrane& crane) noexcept;
/// Highest point of the crane's capsules (the jib's) above the ground [m].
[[nodiscard]] double top_of_structure(const SiteCrane& crane) noexcept;

/// A crane's measured state in its own coordinates (the estimator's CraneState fields).
struct CraneMotion {
  double slew{0.0};                     // [rad] slew angle (crane frame)
  double slew_rate{0.0};                // [rad/s]
  double trolley{0.5};                  // [m] trolley from the slew axis
  double trolley_velocity{0.0};         // [m/s]
  double cable_length{1.0};             // [m] sheave to the load's centre, > 0
  double cable_rate{0.0};               // [m/s] > 0 lowering
  double swing_in_plane{0.0};           // [rad] phi, along the jib
  double swing_out_of_plane{0.0};       // [rad] theta, across the jib
  double swing_in_plane_rate{0.0};      // [rad/s]
  double swing_out_of_plane_rate{0.0};  // [rad/s]
  bool operator==(const CraneMotion&) const = default;
};

enum class StopKind : std::uint8_t {
  none,       // the parts where they are now (no motion)
  soft,       // the drives decelerate (input shaped when the crane's StoppingData says so)
  emergency,  // the brakes: brake_deceleration_factor times the soft deceleration, no shaping
};

/// How far each axis travels and how wide the load swings in a stop decided now (see the header).
struct StoppingTravel {
  double slew{0.0};          // [rad] signed, in the direction of the slew rate
  double trolley{0.0};       // [m] signed
  double cable{0.0};         // [m] signed (> 0 lowering)
  double swing_radius{0.0};  // [m] horizontal envelope of the load about the sheave's vertical
};
/// Non-finite motion fields give non-finite travel; callers check the state first (is_finite).
[[nodiscard]] StoppingTravel stopping_travel(const SiteCrane& crane, const CraneMotion& motion, StopKind kind) noexcept;

/// True when every field of `motion` is finite and the cable length is > 0.
[[nodiscard]] bool is_finite(const CraneMotion& motion) noexcept;

/// The crane's parts over its stopping motion (see the header).
struct CraneEnvelope {
  static constexpr std::size_t kMaxSamples = 16;
  static constexpr double kMaxSlewStep = 0.035;  // [rad] (2 deg) between samples while the budget lasts
  std::array<std::array<Capsule, kPartCount>, kMaxSamples> samples{};
  std::size_t count{0};  // samples used, 1..kMaxSamples
};
[[nodiscard]] CraneEnvelope envelope(const SiteCrane& crane, const CraneMotion& motion, StopKind kind) noexcept;

/// The closest parts of two cranes' envelopes.
struct PairDistance {
  double distance{0.0};  // [m] negative: the envelopes overlap
  Part first{Part::jib};  // of the first envelope
  Part second{Part::jib};
};
[[nodiscard]] PairDistance distance(const CraneEnvelope& first, const CraneEnvelope& second) noexcept;

/// What a crane must do about one other crane; ordered by severity.
enum class Action : std::uint8_t { clear, warning, slow_down, stop, emergency_stop };
/// "clear", "warning", "slow_down", "stop", "emergency_stop".
[[nodiscard]] const char* to_string(Action action) noexcept;

/// The site's rule, from the distance between the two cranes' soft-stop envelopes and between
/// their emergency-stop envelopes [m]:
///   emergency_stop  when even the brakes leave less than margins.stop (emergency distance < stop)
///   stop            when a soft stop decided now keeps margins.stop but a later one might not
///                   (soft distance < stop)
///   slow_down       soft distance < slow_down;  warning: soft distance < warning;  else clear.
/// A NaN distance is treated as overlap (emergency_stop).
[[nodiscard]] Action classify(double soft_distance, double emergency_distance, const Margins& margins) noexcept;

}  // namespace crane::anti_collision
