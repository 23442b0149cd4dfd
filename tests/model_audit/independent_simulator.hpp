#pragma once
// A second simulator of the audited plants, written for the test only (it shares no code with the
// audit's replay, audit_models.hpp, nor with the hidden-effect generator, nor with plant/): fixed-
// step classical Runge-Kutta 4 with its own stick-slip rule, its own friction, saturation, dead zone,
// gain, delay, backlash and encoder-offset injections, its own maneuvers and sensors. Test-only
// (tests/model_audit), seeded with std::mt19937_64.
//
// Axis (one drive under a digital PD loop, as in section 3.1 of Omar 2003 but with other gains and
// another reference): the true plant is
//   x'' = K (1 + g) sat(dz(u(t - tau))) - b_s x' - s [max(0, c_s + gamma x) + D exp(-(x'/v_s)^2)]
// with s = sign(x'), b_s = b +- db, c_s = c +- dc, and at rest a breakaway only when the drive
// exceeds max(0, c_s + gamma x) + D + D_s (sticking otherwise). RK4 steps of h = T / kAxisSteps with
// the sign held over the step; a step whose end velocity changes sign is cut at the reversal (linear
// interpolation of the velocity), and the axis rests there and the rest rule decides. The sensor is
// y = play(x) (backlash), Gaussian noise and an encoder quantum.
// Pendulum (free swing): theta'' = -(g / L_true) sin theta - (d + d_v) theta' - mu sign(theta')
// - q theta' |theta'|, RK4 with h = T / kPendulumSteps, the same reversal cut and stick rule
// (|g/L sin theta| <= mu); measured theta + zero + offset, noise and quantum.
//
// Cause names are the audit's catalog names (model_audit.hpp); "none" is a clean case.

#include <cstdint>
#include <string>

#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit::test {

/// Everything the independent plant can carry (all zero: the nominal plant).
struct AxisTruth {
  double gain{1.7};            // K [m/s^2/V]
  double viscous{5.0};         // b [1/s]
  double coulomb{1.7};         // c [m/s^2]
  double coulomb_asymmetry{0.0};
  double viscous_asymmetry{0.0};
  double stiction{0.0};        // D_s [m/s^2]
  double stribeck_level{0.0};  // D [m/s^2]
  double stribeck_velocity{0.03};
  double deadzone{0.0};        // [V]
  double saturation{0.0};      // [V], 0 = none
  double backlash{0.0};        // [m] total play
  double delay{0.0};           // tau [s]
  double gain_error{0.0};      // g [-]
  double position_slope{0.0};  // gamma [m/s^2/m]
};

struct PendulumTruth {
  double length{1.0};       // true L [m]
  double damping{0.01};     // [1/s]
  double extra_viscous{0.0};
  double coulomb{0.0};      // mu [rad/s^2]
  double quadratic{0.0};    // q [1/rad]
  double zero{3.14159265358979323846};  // measured angle of hanging down [rad]
  double offset{0.0};       // encoder offset [rad]
  double gravity{9.80665};
};

struct IndependentCase {
  std::string cause{"none"};         // first cause (catalog name or "none")
  std::string second_cause;          // second cause ("" if one)
  AuditNominal nominal;              // what the audit is told
  AuditData data;
};

/// One axis case with `causes` (zero, one or two catalog names), magnitudes drawn from `seed`.
[[nodiscard]] IndependentCase independent_axis_case(const std::string& cause, std::uint64_t seed,
                                                    const std::string& second_cause = "");
/// One free-swing case (three swings, one per segment) with `cause` ("none" or a pendulum entry).
[[nodiscard]] IndependentCase independent_pendulum_case(const std::string& cause, std::uint64_t seed,
                                                        const std::string& second_cause = "");

/// The long large-amplitude free swing with Coulomb pivot friction (issue 17): one swing from
/// `start` [rad] with viscous `damping` [1/s] and Coulomb `coulomb` [rad/s^2], `duration` [s],
/// length `length` [m], a 4096-count encoder with noise `noise` [rad], sampled at `rate` [Hz].
[[nodiscard]] IndependentCase long_coulomb_swing(double start, double length, double damping, double coulomb,
                                                 double duration, double noise, double rate, std::uint64_t seed);

/// Simulates an axis with the truth (for the direct checks).
[[nodiscard]] AuditData simulate_axis(const AxisTruth& truth, double duration, std::uint64_t seed, double* max_input = nullptr);
[[nodiscard]] AuditData simulate_free_swings(const PendulumTruth& truth, const double* starts, int swings,
                                             double swing_duration, double sample_time, double noise, double quantum,
                                             std::uint64_t seed);

}  // namespace crane::model_audit::test
