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
// Integration (replay): classical Runge-Kutta 4 with the drive and hoist motion held per sample.
//
// Offline: noexcept and allocation-free except where stated; the model is validated by its owner.

#include <cstddef>
#include <span>

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
};

/// Drive and hoist motion at one instant (measured, or simulated).
struct DriveMotion {
  double trolley_position{0.0};           // x [m]
  double trolley_velocity{0.0};           // [m/s]
  double trolley_acceleration{0.0};       // [m/s^2]
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

/// The catalog's damping terms [rad/s^2] for the swing rates (phi', theta') [rad/s].
[[nodiscard]] Eigen::Vector2d swing_damping(const SwingEffects& effects, double in_plane_rate,
                                            double out_of_plane_rate) noexcept;

/// Swing accelerations (phi'', theta'') [rad/s^2] of the equations above.
void swing_acceleration(const plant::TowerCraneModel& model, const SwingEffects& effects, const SwingState& state,
                        const DriveMotion& motion, double& in_plane_acceleration,
                        double& out_of_plane_acceleration) noexcept;

/// Replays the swing from `initial` at sample `first`: motion[k] is held over [t_k, t_k + sample_time)
/// with `substeps` >= 1 RK4 steps per sample; writes the measured angles of samples first ..
/// first + count - 1 interleaved: out[2 i] = phi + encoder_offset, out[2 i + 1] = theta [rad].
/// Preconditions (asserted): first + count <= motion.size(), out.size() >= 2 count.
void replay_crane_swing(const plant::TowerCraneModel& model, const SwingEffects& effects,
                        std::span<const DriveMotion> motion, double sample_time, std::size_t first, std::size_t count,
                        SwingState initial, int substeps, std::span<double> out) noexcept;

}  // namespace crane::model_audit
