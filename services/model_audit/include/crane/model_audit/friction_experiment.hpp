#pragma once
// Simulated friction-identification experiment "like section 3.1" of H. M. Omar, "Control of Gantry
// and Tower Cranes", Virginia Tech 2003: one axis with direction-dependent viscous and Coulomb
// friction (3.6),
//   x'' = K_m u - b_s x' - c_s sign(x'),   (b_s, c_s) = (b+, c+) for x' > 0, (b-, c-) for x' < 0,
// stabilized by the digital PD loop (3.17) V = K (X_ref - x - K_d x') tracking the persistently
// exciting reference (3.18) X_ref = 0.3 sin(2 pi t / 4) - 0.4 sin(2 pi t / 3), sampled at
// T_s = 0.01 s (f_s = 100 Hz, section 4.3), with the command held between samples (zero-order
// hold). Defaults: K_m = 1.7 and the ratios of Tables 3.1-3.5 (b+/K_m = 2.8, b-/K_m = 5.5,
// c+/K_m = 1.0, c-/K_m = 1.2, ERRATA), the tracking gains K = 100, K_d = 0.2 (Tables 3.4-3.5).
//
// Integration is exact, not approximate: between samples u is constant, so in each direction (3.6)
// is linear with constant input and has the closed form v(t) = v_inf + (v0 - v_inf) e^{-b t}; the
// instant the velocity reaches zero is solved in closed form too. At zero velocity the axis moves
// off toward + if K_m u > c+, toward - if K_m u < -c-, and otherwise rests (the Filippov solution
// of (3.6): Coulomb friction holds the axis while the drive is below it; (3.6) has no separate
// stiction, so the breakaway level is the Coulomb level).
//
// Measurement: optional Gaussian position noise (seeded) and encoder quantization, applied to the
// position the controller sees and that is recorded. The recorded u(k) is the command held over
// [t_k, t_k+1).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace crane::model_audit {

/// One sinusoid amplitude * sin(2 pi frequency t + phase).
struct ReferenceSinusoid {
  double amplitude{0.0};  // [m] or [rad]
  double frequency{0.0};  // [Hz]
  double phase{0.0};      // [rad]
};

/// How the PD loop obtains x'.
enum class VelocityFeedback {
  backward_difference,  // [x_meas(k) - x_meas(k-1)] / T_s, as the real loop does (section 4.4)
  exact,                // the true velocity (a continuous-model study)
};

struct FrictionExperimentParams {
  double motor_constant{1.7};    // K_m [m/s^2/V] > 0
  double viscous_positive{2.8};  // b+/K_m [V s/m] > 0
  double viscous_negative{5.5};  // b-/K_m [V s/m] > 0
  double coulomb_positive{1.0};  // c+/K_m [V] >= 0
  double coulomb_negative{1.2};  // c-/K_m [V] >= 0
  double proportional_gain{100.0};  // K [V/m] > 0 in (3.17) (tracking gains; 4.4 = gain scheduling)
  double derivative_time{0.2};      // K_d [s] >= 0 in (3.17) (tracking gains; 1.33 = gain scheduling)
  VelocityFeedback velocity_feedback{VelocityFeedback::backward_difference};
  std::vector<ReferenceSinusoid> reference{{0.3, 0.25, 0.0}, {-0.4, 1.0 / 3.0, 0.0}};  // (3.18), not empty
  double sample_time{0.01};     // T_s [s] > 0
  double duration{24.0};        // [s] > 2 T_s; two periods of (3.18)
  double initial_position{0.0};  // [m], starts at rest
  double noise_standard_deviation{0.0};  // [m] >= 0, Gaussian noise on the measured position
  double encoder_quantum{0.0};           // [m] >= 0, measured position rounded to multiples; 0 = none
  std::uint64_t seed{1};                 // noise generator seed (std::mt19937_64)
};

/// Throws common::ConfigError naming the field and the bound.
void validate(const FrictionExperimentParams& params);

struct FrictionExperimentRecord {
  std::vector<double> time;               // t_k = k T_s [s]
  std::vector<double> input;              // u(k) [V], held over [t_k, t_k+1)
  std::vector<double> position;           // measured x(k) [m] (noise, quantization)
  std::vector<double> true_position;      // x(t_k) [m]
  std::vector<double> true_velocity;      // x'(t_k) [m/s]
  std::vector<double> reference;          // X_ref(t_k) [m]
};

/// Runs the experiment (validates first; throws common::ConfigError). Samples:
/// floor(duration / T_s + 0.5) + 1. Allocates.
[[nodiscard]] FrictionExperimentRecord simulate_friction_experiment(const FrictionExperimentParams& params);

/// Exact solution of (3.6) over `duration` [s] >= 0 with constant `input` u [V] from position
/// `position` [m] and velocity `velocity` [m/s] (updated in place), with the rest rule above.
/// `params` supplies K_m and the friction; it is not validated here (precondition: validated).
void advance_friction_axis(const FrictionExperimentParams& params, double input, double duration, double& position,
                           double& velocity) noexcept;

}  // namespace crane::model_audit
