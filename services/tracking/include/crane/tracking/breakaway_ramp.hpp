#pragma once
// Breaking a drive loose at the target: integral action with a deadband, for the follower's hold
// (docs/optimal_control.md, "Breaking the drive loose at the target").
//
// A drive whose static friction is larger than the compensation assumes (the plant's friction 30 %
// above the model's) stops a few millimetres off the target, where the regulator's voltage for that
// error is below the breakaway voltage; with the drive stuck the swing is not damped through it. Per
// drive axis, from the position error e = position - target and the speed v of each cycle:
//   |e| <  deadband:                       r = 0 (in the band: nothing to correct), the rest count 0
//   |e| >= deadband, |v| <  rest_speed:    counted at rest; after rest_time at rest,
//                                          r <- clamp(r - sign(e) rate T_s, -limit, limit)
//   |e| >= deadband, |v| >= rest_speed:    r held (the drive moves; the rest count 0)
// and the drive gets the regulator's voltage plus r. This is the integral of a bang-bang error,
// started only once the drive has been at rest off the target for rest_time (a drive passing
// through zero speed while it damps a swing is not stuck: the ramp would bias it), and forgotten
// inside the band, so it cannot wind up against a drive that moves or hold a bias at the target.
// (B. Armstrong-Helouvry, P. Dupont, C. Canudas de Wit, "A survey of models, analysis tools and
// compensation methods for the control of machines with friction", Automatica 30(7), 1994:
// integral action against static friction, and the hunting it causes without a deadband.)
//
// Real-time: step() and reset() are noexcept and allocate nothing; a non-finite input resets the
// axis and gives 0 V. Errors: the constructor throws common::ConfigError naming the field, the value
// and the bound.

#include <array>

namespace crane::tracking {

struct BreakawayRampParams {
  double deadband{0.003};   // [m or rad] > 0: no ramp within it (inside the demo table's 5 mm / 5 mrad settle band)
  double rest_speed{0.005};  // [m/s or rad/s] > 0: a drive slower than this is at rest
  double rest_time{0.1};     // [s] >= 0: at rest off the target this long before the ramp starts
  double rate{2.0};          // [V/s] > 0: the ramp's slope
  double limit{1.0};         // [V] > 0: |r| at most
};

class BreakawayRamp {
 public:
  /// `sample_period` [s] > 0, the cycle. Throws common::ConfigError naming the field
  /// ("tracking.breakaway.<name>").
  BreakawayRamp(const BreakawayRampParams& params, double sample_period);

  /// Forgets both axes (a new move, or the reference moving again).
  void reset() noexcept;

  /// One cycle of drive `axis` (0: trolley, 1: slew or bridge) at rest on the target: the position
  /// error [m or rad] and speed [m/s or rad/s]; returns r [V], to add to the drive's voltage.
  [[nodiscard]] double step(int axis, double position_error, double speed) noexcept;

 private:
  BreakawayRampParams params_;
  double period_;
  int rest_cycles_needed_;
  std::array<double, 2> ramp_{};
  std::array<int, 2> rest_cycles_{};
};

}  // namespace crane::tracking
