#pragma once
// Second delayed-feedback anti-swing controller (3.50), Masoud's configuration (figure 3.18) of
// H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003: the delayed swing does not
// add to the control action; it CORRECTS THE TRAJECTORY the tracking PD follows,
//   x_bar_ref -> x_bar_ref + K_del phi(tau - tau_del),
// so the tracking PD (3.40) acts on it through (K_dx s + K_px). In this project's convention
// (phi'' + a phi = +x_bar'') the characteristic equation is
//   (s^2 + a)(s^2 + K_dx s + K_px) - K_del s^2 (K_dx s + K_px) e^{-tau_del s} = 0,
// (3.50) as printed (derivation in characteristic_equation.hpp). The damping map in this
// convention peaks at K_del < 0 (see the defaults and damping_map.hpp); K_del > 0 near the
// dissertation's |K_del| = 0.33 is unstable or poorly damped here.
//
// Outputs, for a reference in SI units (L constant over the delay):
//   trolley_position_correction = L K_del phi(t - tau_del T)           [m]   add to x_ref
//   trolley_velocity_correction = L K_del phi_dot(t - tau_del T)       [m/s] add to x_ref_dot
// and for the slew axis, in y = -(x/L) gamma (3.34): Delta y_bar = K_del theta(t - tau_del T), i.e.
//   slew_angle_correction = -(L/x) K_del theta(t - tau_del T)          [rad]  add to gamma_ref
//   slew_rate_correction  = -(L/x) K_del theta_dot(t - tau_del T)      [rad/s]
// with x the trolley radius, clamped to >= min_trolley_radius.
//
// Real-time: step() is noexcept, allocates nothing (delay line sized at construction from
// max_cable_length), takes no locks.

#include <vector>

#include "crane/common/crane_signals.hpp"

namespace crane::anti_swing_analysis {

struct DelayedTrajectoryAntiSwingParams {
  double delay_gain{-0.26};         // [-] K_del (3.50), our sign (map maximum -0.262, 0.279)
  double normalized_delay{0.28};    // [swing periods] tau_del (3.50), > 0
  double sample_period{0.01};       // [s] time between step() calls, > 0
  double gravity{9.8};              // [m/s^2] g in T = 2 pi sqrt(L/g), > 0
  double min_cable_length{0.1};     // [m] measured L is clamped to [min, max], > 0
  double max_cable_length{5.0};     // [m] sizes the delay line, > min_cable_length
  double min_trolley_radius{0.1};   // [m] x used in the slew conversion is clamped to >= this, > 0
  bool slew_enabled{true};          // also correct the slew reference from theta
};

struct TrajectoryCorrection {
  double trolley_position_correction{0.0};  // [m]
  double trolley_velocity_correction{0.0};  // [m/s]
  double slew_angle_correction{0.0};        // [rad]
  double slew_rate_correction{0.0};         // [rad/s]
  double swing_period{0.0};                 // [s] T from the clamped cable length
  int delay_samples{0};                     // [samples] round(tau_del T / sample_period)
};

class DelayedTrajectoryAntiSwing {
 public:
  /// Throws common::ConfigError naming the field, value and bound for: non-finite delay_gain,
  /// normalized_delay <= 0, sample_period <= 0, gravity <= 0, min_cable_length <= 0,
  /// max_cable_length <= min_cable_length, min_trolley_radius <= 0, or a delay line longer than
  /// kMaxDelaySamples.
  explicit DelayedTrajectoryAntiSwing(const DelayedTrajectoryAntiSwingParams& params);

  /// Uses trolley_position [m], swing_in_plane [rad], swing_in_plane_rate [rad/s],
  /// swing_out_of_plane [rad], swing_out_of_plane_rate [rad/s], cable_length [m].
  /// - rejected_nonfinite: a used input is NaN/Inf; zero corrections, history unchanged.
  /// - not_ready: fewer than delay_samples+1 samples of history; zero corrections.
  /// - ok otherwise.
  [[nodiscard]] common::StepStatus step(const common::CraneStateEstimate& estimate,
                                        TrajectoryCorrection& output) noexcept;

  /// Empties the delay line.
  void reset() noexcept;

  [[nodiscard]] const DelayedTrajectoryAntiSwingParams& params() const noexcept { return params_; }
  [[nodiscard]] int delay_line_capacity() const noexcept { return static_cast<int>(history_.size()); }

  static constexpr int kMaxDelaySamples = 1'000'000;

 private:
  struct SwingSample {
    double swing_in_plane{0.0};
    double swing_in_plane_rate{0.0};
    double swing_out_of_plane{0.0};
    double swing_out_of_plane_rate{0.0};
  };

  DelayedTrajectoryAntiSwingParams params_;
  std::vector<SwingSample> history_;  // ring buffer, newest at head_
  int head_{0};
  int count_{0};
};

}  // namespace crane::anti_swing_analysis
