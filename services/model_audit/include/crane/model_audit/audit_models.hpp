#pragma once
// Nominal plant models of the model audit and their catalog extensions ("candidate causes").
//
// Axis (one drive axis, (3.6) of H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech
// 2003), extended by every axis catalog entry at once (an entry at its neutral value is absent):
//   x'' = K_m (1 + g) S(D(u(t - tau))) + a_ext - b_s x' - F_s(x, x') ,      s = sign(x')
//   b_s = b + s db                                   (viscous_friction_asymmetry: db)
//   F_s = s [max(0, c + s dc + gamma x) + Delta exp(-(x'/v_s)^2)]
//        (coulomb_friction_asymmetry: dc; position_dependent_friction: gamma; stribeck: Delta, v_s)
//   at rest (x' = 0) the axis breaks away toward s only if s (K_m(1+g)S(D(u)) + a_ext) exceeds
//   max(0, c + s dc + gamma x) + Delta + Delta_s + s dDelta_s
//        (stiction: Delta_s; dDelta_s: a nominal asymmetry of the breakaway level, as in the
//         crane configuration's static_positive/static_negative; Filippov rest rule)
//   a_ext: an external acceleration [m/s^2] that does not pass through the drive (the crane's
//        swing and slew coupling on a drive axis, model_audit.hpp), zero for a lone axis
//   D(u) = u - clamp(u, -d, d)                       (deadzone: d [V])
//   S(u) = clamp(u, -u_max, u_max)                   (saturation: u_max [V], 0 = none)
//   tau                                              (input_delay [s])
//   g                                                (gain_error [-])
//   measured y = play_w(x): y follows x with a gap of total width w     (backlash: w [m])
// Integration: u is held over each sample (zero-order hold, the delay splits the sample in two
// pieces). Within a substep the friction coefficients are frozen (at the half-substep state: the
// midpoint rule) and the closed-form solution of advance_friction_axis() (exponential approach,
// exact stop time, rest rule) is used; so the nominal model and every entry except stribeck and
// position_dependent_friction are exact for any substep count, those two are O(substep^2).
//
// Pendulum (free or trolley-driven load swing, the planar pendulum of chapter 2 of Omar 2003,
// with the trolley acceleration a = x''):
//   L_t theta'' = -g sin(theta) - a cos(theta)                    L_t = L (1 + e) (cable_length_error: e)
//   theta''    += -(damping + d_v) theta' - mu sign(theta') - q theta' |theta'|
//        (pendulum_viscous_damping: d_v [1/s]; pendulum_coulomb_damping: mu [rad/s^2], the swing
//         sticks when |g sin(theta) + a cos(theta)| / L_t <= mu at zero rate;
//         pendulum_quadratic_damping: q [1/rad])
//   measured angle = theta + theta_zero + offset                 (encoder_offset: offset [rad])
// theta = 0 hangs straight down. Integration: classical Runge-Kutta 4 with the Coulomb sign frozen
// per substep; a sign change of the rate inside a substep ends at rest (then the stick rule
// decides), an O(substep) approximation at the turning points.
//
// Offline: the replay functions allocate nothing but write into caller spans; all are noexcept and
// take validated models (validate() throws crane::common::ConfigError naming the field).

#include <cstddef>
#include <span>

namespace crane::model_audit {

struct AxisModel {
  double motor_constant{1.7};     // K_m [m/s^2/V] > 0
  double viscous{4.76};           // b [1/s] >= 0
  double coulomb{1.7};            // c [m/s^2] >= 0
  double coulomb_asymmetry{0.0};  // dc [m/s^2]: c+ = c + dc, c- = c - dc
  double viscous_asymmetry{0.0};  // db [1/s]: b+ = b + db, b- = b - db (both kept >= 0)
  double stiction{0.0};           // Delta_s [m/s^2] >= 0: breakaway level above Coulomb
  double stiction_asymmetry{0.0}; // dDelta_s [m/s^2]: level Delta_s + dDelta_s toward +, Delta_s - dDelta_s
                                  // toward - (|dDelta_s| <= Delta_s)
  double stribeck_level{0.0};     // Delta [m/s^2] >= 0
  double stribeck_velocity{0.05}; // v_s [m/s] > 0
  double deadzone{0.0};           // d [V] >= 0
  double saturation{0.0};         // u_max [V] >= 0; 0 = no saturation
  double backlash{0.0};           // w [m] >= 0, total play between axis and position sensor
  double input_delay{0.0};        // tau [s] >= 0
  double gain_error{0.0};         // g [-] > -1
  double position_friction{0.0};  // gamma [m/s^2/m]
};

/// Throws common::ConfigError naming the field, the value and the bound.
void validate(const AxisModel& model);

struct AxisState {
  double position{0.0};       // x [m] (the axis; the motor side of the backlash)
  double velocity{0.0};       // x' [m/s]
  double load_position{0.0};  // y [m] measured side of the backlash (= position when w = 0)
};

/// `model` with its acceleration-level terms (K_m, b, db, c, dc, Delta_s, dDelta_s, Stribeck level,
/// gamma) multiplied by `ratio` [-] > 0: the axis of a crane whose row inertia is I_drive / ratio
/// (the drive's own model is written for the inertia I_drive).
[[nodiscard]] AxisModel scale_axis_inertia(AxisModel model, double ratio) noexcept;

/// Effective drive acceleration K_m (1 + g) S(D(u)) [m/s^2] for a command `input` u [V].
[[nodiscard]] double axis_drive_acceleration(const AxisModel& model, double input) noexcept;

/// Advances `state` by `duration` [s] >= 0 under the constant command `input` [V] (already delayed)
/// and the constant external acceleration `external_acceleration` a_ext [m/s^2], with `substeps` >= 1
/// frozen-coefficient closed-form pieces (see the header comment).
void advance_axis(const AxisModel& model, double input, double duration, int substeps, AxisState& state,
                  double external_acceleration = 0.0) noexcept;

/// Replays the recorded commands: input[k] [V] is held over [t_k, t_k + sample_time); the state at
/// sample `first` is `initial`; writes the measured position y(t_k) [m] for k = first ..
/// first + out.size() - 1 into `out`. Delayed inputs before sample 0 are taken as input[0].
/// `external_acceleration` a_ext [m/s^2] and `inertia_ratio` (scale_axis_inertia) per sample, held
/// over [t_k, t_k + sample_time) (not delayed), or empty for none. Preconditions (asserted):
/// first + out.size() <= input.size(), the spans empty or of input's size, sample_time > 0.
void replay_axis(const AxisModel& model, std::span<const double> input, double sample_time, std::size_t first,
                 AxisState initial, int substeps, std::span<double> out,
                 std::span<const double> external_acceleration = {},
                 std::span<const double> inertia_ratio = {}) noexcept;

struct PendulumModel {
  double length{1.0};          // L [m] > 0
  double damping{0.0};         // viscous [1/s] >= 0
  double gravity{9.80665};     // g [m/s^2] > 0
  double theta_zero{0.0};      // [rad] measured angle of the hanging-down position
  double extra_viscous{0.0};   // d_v [1/s] (>= -damping)
  double coulomb{0.0};         // mu [rad/s^2] >= 0
  double quadratic{0.0};       // q [1/rad] >= 0
  double length_error{0.0};    // e [-] > -1
  double encoder_offset{0.0};  // [rad]
};

/// Throws common::ConfigError naming the field, the value and the bound.
void validate(const PendulumModel& model);

struct PendulumState {
  double angle{0.0};  // theta [rad], 0 = hanging down (true, without zero and offset)
  double rate{0.0};   // theta' [rad/s]
};

/// Advances `state` by `duration` [s] with constant trolley acceleration `trolley_acceleration`
/// [m/s^2] using `substeps` >= 1 RK4 steps.
void advance_pendulum(const PendulumModel& model, double trolley_acceleration, double duration, int substeps,
                      PendulumState& state) noexcept;

/// Replays from `initial` at sample `first`: writes the measured angle [rad] (theta + theta_zero +
/// encoder_offset) at samples first .. first + out.size() - 1. `trolley_acceleration` [m/s^2] per
/// sample (held over the sample) or empty for a free swing. Preconditions (asserted): sizes fit.
void replay_pendulum(const PendulumModel& model, std::span<const double> trolley_acceleration, double sample_time,
                     std::size_t first, PendulumState initial, int substeps, std::span<double> out) noexcept;

}  // namespace crane::model_audit
