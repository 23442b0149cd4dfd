#pragma once
// Nonlinear model of the overhead (bridge) crane: a bridge travelling on runway rails along y, a
// trolley travelling on the bridge girder along x (at right angles), a hoist paying out the cable L,
// and the load as a spherical pendulum with two swing angles. It generalizes the gantry crane of
// section 2.1 of H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003, the same way
// the tower crane's (2.11)-(2.16) do, with the slew replaced by a translation.
//
// Generalized coordinates (four-slot layout of crane_dynamics.hpp):
//   q = (x, phi, y, theta):  x [m] trolley on the girder, phi [rad] swing in the trolley's vertical
//   plane (x-z), y [m] bridge on the runway, theta [rad] swing out of that plane (toward y).
// The cable length L [m] is prescribed by the hoist (L, L_dot, L_ddot).
//
// Derivation (Lagrange; inertial frame: x along the girder, y along the runway, z up, origin at the
// girder's height):
//   trolley at (x, y, 0); cable direction, tower convention (ERRATA),
//     u(phi, theta) = (-cos(theta) sin(phi), sin(theta), -cos(theta) cos(phi));
//   load at r = (x, y, 0) + L u,  r_dot = x_d e_x + y_d e_y + L_d u + L (u_phi phi_d + u_theta theta_d).
//   T = 1/2 m |r_dot|^2 + 1/2 M_x x_d^2 + 1/2 M_y y_d^2
//     M_x = crane.trolley_drive_mass (trolley plus reflected trolley-drive inertia),
//     M_y = bridge.drive_mass (girder, end trucks, the trolley it carries, reflected bridge-drive inertia);
//   V = -m g L cos(theta) cos(phi);
//   Q = (F_x, 0, F_y, 0), F_x = M_x K_mx V_x, F_y = M_y K_my V_y (the drives, as (2.26)),
//       plus the friction of each drive axis ((3.1)-(3.3), axis_friction.hpp).
// Lagrange's equations d/dt dT/dq_d_j - dT/dq_j + dV/dq_j = Q_j are written in d'Alembert form:
// with c_j = dr/dq_j (c_x = e_x, c_y = e_y, c_phi = L u_phi, c_theta = L u_theta) and
//   r_dd = sum_k c_k q_dd_k + a_rest,
//   a_rest = L_dd u + 2 L_d (u_phi phi_d + u_theta theta_d)
//            + L (u_phiphi phi_d^2 + 2 u_phitheta phi_d theta_d + u_thetatheta theta_d^2),
// row j is  m c_j . (r_dd + g e_z) + (M_x x_dd if j = x) + (M_y y_dd if j = y) = Q_j.
// So M_jk = m c_j . c_k (+ M_x, M_y on the drive diagonals), b_j = m c_j . (a_rest + g e_z).
// The swing rows (phi, theta) are divided by m, as in TowerCraneModel, so a massless load is a
// passive pendulum. In full, with s/c of phi (p) and theta (t):
//   x:     (m + M_x) x_dd - m L c_t c_p phi_dd + m L s_t s_p theta_dd + m e_x . a_rest = F_x
//   y:     (m + M_y) y_dd + m L c_t theta_dd + m e_y . a_rest = F_y
//   phi:   -L c_t c_p x_dd + L^2 c_t^2 phi_dd + L u_phi . (a_rest + g e_z) = 0
//   theta: L s_t s_p x_dd + L c_t y_dd + L^2 theta_dd + L u_theta . (a_rest + g e_z) = 0
// With y held and theta = theta_d = 0, theta stays 0 (its row's right-hand side vanishes) and the
// x and phi rows are (2.5) and L times (2.6) (tower sign): the gantry model (tested to 1e-12).
// Linearized at rest (q_d = 0, L constant):
//   x_dd + m_tx g phi = K_mx V_x,   L phi_dd + g phi - x_dd = 0      (2.7)-(2.8), m_tx = m/M_x
//   y_dd - m_ty g theta = K_my V_y, L theta_dd + g theta + y_dd = 0  (the same with theta's sign:
//                                   positive theta moves the load toward +y), m_ty = m/M_y.
//
// Errors: the constructor validates (common::validate of both parameter sets, fields "crane." and
// "bridge.") and throws common::ConfigError; evaluation is noexcept, allocation-free, and assumes
// finite inputs, L > 0, |theta| < pi/2 (swing coordinate singularity).

#include <Eigen/Core>

#include "crane/common/crane_parameters.hpp"
#include "crane/plant/crane_dynamics.hpp"
#include "crane/plant/tower_crane_model.hpp"

namespace crane::plant {

class OverheadCraneModel final : public CraneDynamics {
 public:
  OverheadCraneModel(const common::CraneParameters& crane, const common::BridgeParameters& bridge);

  [[nodiscard]] std::unique_ptr<CraneDynamics> clone() const override;
  void compute_dynamics(const ModelState& state, const HoistMotion& hoist, CoordinateMatrix& mass_matrix,
                        CoordinateVector& bias) const noexcept override;
  [[nodiscard]] double kinetic_energy(const ModelState& state, const HoistMotion& hoist) const noexcept override;
  [[nodiscard]] double potential_energy(const ModelState& state, double cable_length) const noexcept override;
  /// trolley: M_x K_mx [N/V]; second (the bridge): M_y K_my [N/V].
  [[nodiscard]] double drive_force_per_volt(DriveAxis axis) const noexcept override;
  [[nodiscard]] const common::CraneParameters& parameters() const noexcept override { return crane_; }
  [[nodiscard]] const common::BridgeParameters& bridge() const noexcept { return bridge_; }

  /// Load position (x, y, z) [m] in the runway frame (origin at girder height, z up).
  [[nodiscard]] Eigen::Vector3d load_position(const ModelState& state, double cable_length) const noexcept;
  /// Linearization about rest at cable length `cable_length` [m] (> 0, unchecked), in the row scaling
  /// of compute_dynamics; input columns (V_x, V_y) [V] -> (M_x K_mx, M_y K_my) [N/V]. Closed form.
  [[nodiscard]] LinearizedModel linearize_at_rest(double cable_length) const noexcept;
  /// Small-swing angular frequencies [rad/s] with both drives free (no friction, no input):
  /// in-plane sqrt((1 + m/M_x) g/L), out-of-plane sqrt((1 + m/M_y) g/L). cable_length [m] > 0.
  [[nodiscard]] double free_in_plane_swing_frequency(double cable_length) const noexcept;
  [[nodiscard]] double free_out_of_plane_swing_frequency(double cable_length) const noexcept;

 private:
  common::CraneParameters crane_;
  common::BridgeParameters bridge_;
};

}  // namespace crane::plant
