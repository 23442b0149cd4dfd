#pragma once
// Time-optimal swing-free rest-to-rest profile for the linearized load
//   L phi'' + g phi = x''   (trolley; the slew is the same with -x gamma'' as the input),
// with the axis acceleration as the input, |x''| <= a_max and |x'| <= v_max. Ends at the target at
// rest with zero swing (phi, phi') for a load that starts at rest, in (numerically) minimum time.
//
// Structure (Pontryagin): bang-bang acceleration +-a_max with coast arcs only at |v| = v_max, and
// antisymmetric about the midpoint, u(t_f - t) = -u(t), so the final velocity is zero and the
// swing condition reduces to one real equation, int_0^{t_f/2} u(t_f/2 + s) sin(w s) ds = 0.
// The second half is searched over the families (the first half is its mirror)
//   A: [+a d][-a p]                       (v_max not reached; the +,-,+,- command)
//   B: [+a d][0 c][-a p], p = v_max/a     (one velocity dip at the midpoint)
//   C: [0 c0][-a e][+a e][0 c1][-a p]     (a dip inside each half, long moves)
//   D: [0 c][-a p] with t_f - p = k T     (swing-free trapezoid; always feasible, fallback)
// by scanning one parameter with the distance condition solved in closed form and bisecting on the
// swing condition; the shortest candidate wins. Cross-checked against a time-discretized LP in
// tests/trajectory_profiles.
//
// Held by value, no allocation; plan() is noexcept and takes about 10^4 cosine evaluations.

#include <array>
#include <cstddef>

#include "crane/trajectory_planner/axis_profile.hpp"
#include "crane/trajectory_planner/input_shaper.hpp"
#include "crane/trajectory_planner/trapezoid_profile.hpp"

namespace crane::trajectory_planner {

class TimeOptimalProfile final : public AxisProfile {
 public:
  static constexpr std::size_t kMaxSegments = 10;

  /// Which family of the header comment produced the profile.
  enum class Family { none, bang_bang, midpoint_dip, two_dips, swing_free_trapezoid };

  /// A zero-length profile at 0.
  TimeOptimalProfile() = default;
  /// Throws common::ConfigError naming the field, value and bound unless start/target [m or rad]
  /// are finite, limits are finite and > 0 and natural_frequency [rad/s] (sqrt(g/L)) is finite
  /// and > 0.
  TimeOptimalProfile(double start, double target, const AxisLimits& limits,
                     double natural_frequency);

  /// As the constructor without exceptions; on a status other than ok *this is unchanged.
  ProfileStatus plan(double start, double target, const AxisLimits& limits,
                     double natural_frequency) noexcept;

  [[nodiscard]] double duration() const noexcept override { return duration_; }
  [[nodiscard]] common::AxisReference sample(double time) const noexcept override;

  [[nodiscard]] Family family() const noexcept { return family_; }
  [[nodiscard]] std::size_t segment_count() const noexcept { return count_; }
  /// Duration [s] and constant acceleration [unit/s^2] of segment i < segment_count() (asserted).
  [[nodiscard]] double segment_duration(std::size_t i) const noexcept;
  [[nodiscard]] double segment_acceleration(std::size_t i) const noexcept;

 private:
  struct Segment {
    double start_time{0.0};     // [s]
    double duration{0.0};       // [s]
    double acceleration{0.0};   // [unit/s^2], signed
    double start_position{0.0};
    double start_velocity{0.0};
  };
  double start_{0.0};
  double target_{0.0};
  double duration_{0.0};
  std::array<Segment, kMaxSegments> segments_{};
  std::size_t count_{0};
  Family family_{Family::none};
};

}  // namespace crane::trajectory_planner
