#pragma once
// Swing of the tower crane's load driven by the measured motion of the trolley, the jib and the
// hoist, for the `crane` model of the audit (model_audit.hpp), extended by the pendulum catalog.
//
// The swing rows (phi, theta) of the Lagrangian model of plant::TowerCraneModel ((2.11)-(2.16) of
// H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003, rows divided by the load
// mass, so the swing does not depend on it):
//   M_ss(q, L) s'' = -(M_sx x'' + M_sg gamma'' + bias_s(q, q', L, L', L''))      s = (phi, theta)
// are solved for s'' with the drive motion (x, x', x'', gamma', gamma'') and the hoist motion
// (L, L', L'') given, then each swing angle a in {phi, theta} gets the catalog terms
//   a'' += -d_v a' - mu tanh(a' / kSwingCoulombRate) - q a' |a'|
//        (pendulum_viscous_damping d_v [1/s], pendulum_coulomb_damping mu [rad/s^2] with the sign
//         regularized over kSwingCoulombRate, pendulum_quadratic_damping q [1/rad])
//   the true cable length is L (1 + e), L' (1 + e), L'' (1 + e) for the recorded L (cable_length_error e)
//   measured phi = phi + offset                              (encoder_offset [rad], in-plane encoder)
//   Q += (dp_load/dq) . F for a steady horizontal force F = (F_x, F_y, 0) [N] on the load in the
//        inertial frame (wind_force; TowerCraneModel::load_force: it turns with the slew angle in
//        the jib frame, and the drive rows get it too)
//   the hook as a double pendulum (hook_double_pendulum): the cable (phi, theta, length L) ends at
//        a hook of mass m_h and the load hangs l below it (TowerCraneModel with HookParameters:
//        coordinates (x, phi, gamma, theta, phi2, theta2)); the configured load_mass M is the
//        suspended mass, hook and load: m_h = s M, m = (1 - s) M (the share s [-]); the swing rows
//        depend on s and l only. The swing rows (phi, theta, phi2, theta2) are eliminated as below.
//   an elastic rope (elastic_rope): the load hangs at the paid-out length plus a stretch s
//        (TowerCraneModel with RopeParameters: coordinates (x, phi, gamma, theta, s), k = EA / L);
//        the parameter is the static stretch ratio e_r = M g / EA [-] of the configured load mass
//        M (EA = M g / e_r, the rope's damping ratio the plant's default), the stretch starts each
//        replay at its static value e_r L (1 + e) at rest; the rows (phi, theta, s) are eliminated
//        as for the hook (slot 5 unused). A constant stretch alone is a cable_length_error; the
//        rope's own signature is the stretch following the tension (the swing's centripetal and
//        gravity terms at twice the swing frequency) and the load's bounce at sqrt(g / (e_r L)).
// Integration (replay): classical Runge-Kutta 4 with the drive and hoist motion held per sample.
//
// Offline: noexcept and allocation-free except where stated; the model is validated by its owner.

#include <cstddef>
#include <span>
#include <vector>

#include "crane/plant/tower_crane_model.hpp"

namespace crane::model_audit {

/// Coulomb swing friction: sign(rate) is regularized as tanh(rate / kSwingCoulombRate) [rad/s].
inline constexpr double kSwingCoulombRate = 1e-3;

struct SwingEffects {
  double extra_viscous{0.0};   // d_v [1/s]
  double coulomb{0.0};         // mu [rad/s^2] >= 0
  double quadratic{0.0};       // q [1/rad] >= 0
  double length_error{0.0};    // e [-] > -1
  double encoder_offset{0.0};  // [rad] added to the measured in-plane swing phi
  double wind_force_x{0.0};     // [N] steady horizontal force on the load, inertial x (x along the jib at slew 0)
  double wind_force_y{0.0};     // [N] inertial y
  double rigging_length{0.0};   // l [m], hook to the load's centre of mass; 0: no hook (the single pendulum)
  double hook_mass_share{0.0};  // s = m_h / (m_h + m) [-] in (0, 1), with a hook
  double rope_stretch_ratio{0.0};  // e_r = M g / EA [-]; 0: an inextensible cable (not with a hook)
};

/// Bounds of the hook entry in the replay (its fits are clamped to them): l [m] and s [-].
inline constexpr double kMinRiggingLength = 0.02;
inline constexpr double kMaxRiggingLength = 5.0;
inline constexpr double kMinHookMassShare = 0.01;
inline constexpr double kMaxHookMassShare = 0.95;

/// Bounds of the rope entry in the replay (its fits are clamped to them): e_r [-].
inline constexpr double kMinRopeStretchRatio = 1e-3;
inline constexpr double kMaxRopeStretchRatio = 0.2;

/// Drive and hoist motion at one instant (measured, or simulated).
struct DriveMotion {
  double trolley_position{0.0};           // x [m]
  double trolley_velocity{0.0};           // [m/s]
  double trolley_acceleration{0.0};       // [m/s^2]
  double slew_angle{0.0};                 // gamma [rad] (turns the wind force into the jib frame)
  double slew_rate{0.0};                  // gamma' [rad/s]
  double slew_acceleration{0.0};          // gamma'' [rad/s^2]
  double cable_length{1.0};               // L [m] > 0 as recorded
  double cable_length_rate{0.0};          // [m/s]
  double cable_length_acceleration{0.0};  // [m/s^2]
};

struct SwingState {
  double in_plane{0.0};           // phi [rad]
  double in_plane_rate{0.0};      // [rad/s]
  double out_of_plane{0.0};       // theta [rad]
  double out_of_plane_rate{0.0};  // [rad/s]
  // With a hook (SwingEffects::rigging_length > 0): the rigging's absolute angles (phi2, theta2).
  double rigging_in_plane{0.0};           // [rad]
  double rigging_in_plane_rate{0.0};      // [rad/s]
  double rigging_out_of_plane{0.0};       // [rad]
  double rigging_out_of_plane_rate{0.0};  // [rad/s]
};

/// The swing eliminated from M q'' + bias = Q (TowerCraneModel::compute_dynamics at one state; a =
/// (x'', gamma''), s = (phi, theta)): s'' = swing_gain a'' + swing_free with
///   swing_gain = -M_ss^-1 M_sa,  swing_free = -M_ss^-1 bias_s + swing_extra
/// (swing_extra [rad/s^2]: the catalog's damping terms), and the drive rows become
///   drive_inertia a'' + drive_bias = (F_x [N], T_gamma [N m]),
///   drive_inertia = M_aa + M_as swing_gain,  drive_bias = bias_a + M_as swing_free.
struct SwingElimination {
  Eigen::Matrix2d swing_gain;
  Eigen::Vector2d swing_free;
  Eigen::Matrix2d drive_inertia;  // [kg, kg m; kg m, kg m^2]
  Eigen::Vector2d drive_bias;     // [N, N m]
};
[[nodiscard]] SwingElimination eliminate_swing(const plant::CoordinateMatrix& mass, const plant::CoordinateVector& bias,
                                               const Eigen::Vector2d& swing_extra = Eigen::Vector2d::Zero()) noexcept;

/// The same with a hook: the four swing rows (phi, theta, phi2, theta2) of
/// TowerCraneModel::compute_extended_dynamics eliminated (swing_extra: damping of phi and theta).
struct HookedSwingElimination {
  Eigen::Matrix<double, 4, 2> swing_gain;  // rows phi, theta, phi2, theta2
  Eigen::Vector4d swing_free;
  Eigen::Matrix2d drive_inertia;
  Eigen::Vector2d drive_bias;
};
[[nodiscard]] HookedSwingElimination eliminate_hooked_swing(const plant::ExtendedMatrix& mass,
                                                            const plant::ExtendedVector& bias,
                                                            const Eigen::Vector2d& swing_extra) noexcept;

/// The swing eliminated at one state of `model` (its swing rows: four with a hook or a rope, whose
/// models have 6 or 5 coordinates, else two, the other rows of swing_gain and swing_free zero), with
/// the wind's generalized force of `effects` in the bias and `swing_extra` [rad/s^2] (the catalog's
/// damping, swing_damping()) added to phi'' and theta''. `state`: every coordinate of `model`.
[[nodiscard]] HookedSwingElimination eliminate_swing_at(const plant::TowerCraneModel& model, const SwingEffects& effects,
                                                        const plant::ExtendedState& state, const plant::HoistMotion& hoist,
                                                        const Eigen::Vector2d& swing_extra) noexcept;

/// The model with the hook of `effects` (rigging_length clamped to [kMinRiggingLength,
/// kMaxRiggingLength], hook_mass_share to [kMinHookMassShare, kMaxHookMassShare]): `suspended`'s
/// load_mass M (> 0; 1 kg when not) split into the hook's s M and the load's (1 - s) M. Allocates.
[[nodiscard]] plant::TowerCraneModel hooked_model(const common::CraneParameters& suspended, const SwingEffects& effects);

/// The model with the elastic rope of `effects` (rope_stretch_ratio clamped to
/// [kMinRopeStretchRatio, kMaxRopeStretchRatio]): EA = M g / e_r with `suspended`'s load_mass M
/// (> 0; 1 kg when not) and gravity g. Allocates.
[[nodiscard]] plant::TowerCraneModel roped_model(const common::CraneParameters& suspended, const SwingEffects& effects);

/// The wind's generalized force (TowerCraneModel::load_force with the effects' F_x, F_y [N]) at
/// `state` (slot 2 = the slew angle gamma [rad]); zero without wind or without a load mass.
[[nodiscard]] plant::ExtendedVector wind_generalized_force(const plant::TowerCraneModel& model, const SwingEffects& effects,
                                                           const plant::ExtendedState& state,
                                                           const plant::HoistMotion& hoist) noexcept;

/// The catalog's damping terms [rad/s^2] for the swing rates (phi', theta') [rad/s].
[[nodiscard]] Eigen::Vector2d swing_damping(const SwingEffects& effects, double in_plane_rate,
                                            double out_of_plane_rate) noexcept;

/// Swing accelerations (phi'', theta'') [rad/s^2] of the equations above (without a hook; a
/// hooked replay goes through replay_crane_swing).
void swing_acceleration(const plant::TowerCraneModel& model, const SwingEffects& effects, const SwingState& state,
                        const DriveMotion& motion, double& in_plane_acceleration,
                        double& out_of_plane_acceleration) noexcept;

/// Replays the swing from `initial` at sample `first`: motion[k] is held over [t_k, t_k + sample_time)
/// with `substeps` >= 1 RK4 steps per sample; writes the measured angles of samples first ..
/// first + count - 1 interleaved: out[2 i] = phi + encoder_offset, out[2 i + 1] = theta [rad].
/// With a hook (effects.rigging_length > 0) `model` is the single pendulum with the suspended mass
/// (hooked_model() builds the double pendulum; allocates once per call) and `initial` carries the
/// rigging's state. With a rope (effects.rope_stretch_ratio > 0, no hook) likewise roped_model(),
/// the stretch starting at its static value.
/// Preconditions (asserted): first + count <= motion.size(), out.size() >= 2 count.
void replay_crane_swing(const plant::TowerCraneModel& model, const SwingEffects& effects,
                        std::span<const DriveMotion> motion, double sample_time, std::size_t first, std::size_t count,
                        SwingState initial, int substeps, std::span<double> out) noexcept;

/// The swing states the encoders do not measure, along a record whose cable angles are measured:
/// with a hook (effects.rigging_length > 0) the rigging's angles and rates; with an elastic rope
/// (no hook) the stretch [m] and its rate [m/s] in rigging_in_plane and rigging_in_plane_rate.
/// `cable[k]` is the cable's state at sample k (phi without the encoder offset, theta, their rates;
/// its rigging fields are ignored); the result is `cable` with the extended fields filled. They start
/// at rest at the first sample (the rigging on the cable's line, the rope stretched by the load's
/// weight) and are carried from sample to sample by one sample of the replay's integration
/// (replay_crane_swing, the same model) started from the measured cable state, so the cable's part
/// never drifts from the measurement (an observer that injects the measured cable state; the
/// extended part follows the model's response to it). Without a hook or a rope: `cable` unchanged.
/// `model` as for replay_crane_swing. Preconditions (asserted): cable.size() == motion.size().
/// Allocates the result.
[[nodiscard]] std::vector<SwingState> follow_swing(const plant::TowerCraneModel& model, const SwingEffects& effects,
                                                   std::span<const DriveMotion> motion, std::span<const SwingState> cable,
                                                   double sample_time);

}  // namespace crane::model_audit
