#pragma once
// Nonlinear rigid-body model of the tower crane, derived from the Lagrangian (2.11)-(2.16) of
// H. M. Omar, "Control of Gantry and Tower Cranes", 2003. It replaces the printed (2.17)-(2.20),
// which lost parentheses in extraction (see seed/ERRATA.md); the linearization reproduces
// (2.28)-(2.31).
//
// Coordinates (all SI): q = (x, phi, gamma, theta)
//   x      [m]   trolley position along the jib
//   phi    [rad] in-plane swing (in the vertical plane of the jib)
//   gamma  [rad] slew angle of the jib about the vertical z axis
//   theta  [rad] out-of-plane swing
// The cable length L [m] is a prescribed kinematic input (L, L_dot, L_ddot) from the hoist.
//
// Geometry, tower sign convention (ERRATA): in the jib frame, which rotates by gamma about the
// vertical z axis (z up), the load sits at
//   r = (x - L cos(theta) sin(phi),  L sin(theta),  -L cos(theta) cos(phi)).
// Energies:
//   T = 1/2 m |v_load|^2 + 1/2 M_drive x_dot^2 + 1/2 M_trolley x^2 gamma_dot^2 + 1/2 J_o gamma_dot^2
//   V = -m g L cos(theta) cos(phi)                                                        (2.14)
// where v_load is the inertial velocity r_dot + omega x r (2.12), omega = (0, 0, gamma_dot).
//
// Deliberate improvement over (2.13): the dissertation uses one trolley mass M both for the drive
// (m_t = m/M = 0.09) and for the slewing inertia (M_r = M/J_o = 0.27), which cannot both hold for one
// physical mass. Here the motion along the jib sees M_drive = CraneParameters::trolley_drive_mass
// (trolley plus reflected leadscrew/rotor inertia) and the slewing motion sees the physical
// M_trolley = CraneParameters::trolley_mass. Both ratios of (2.25) then hold as printed.
//
// Equations of motion in mass-matrix form, from the Lagrange/d'Alembert form
//   sum_i m_i (dp_i/dq_j) . (a_i + g e_z) = Q_j:
//   mass_matrix(q, L) * q_ddot + bias(q, q_dot, L, L_dot, L_ddot) = Q
// with generalized forces Q = (F_x, 0, T_gamma, 0) [N, -, N m, -]. The swing rows (phi, theta) are
// divided by the load mass m, so the model stays well posed for a massless load (then the load is a
// passive pendulum driven by the trolley and the jib). The rows of x and gamma are forces [N] and
// torques [N m]; the swing rows are [m^2/s^2] per unit load mass. Consequently mass_matrix is
// symmetric only when m = 1 kg.
//
// Errors: the constructor validates the parameters and throws common::ConfigError. Evaluation
// functions are noexcept, allocation-free, and assume finite inputs with L > 0 and
// |theta| < pi/2 (the mass matrix is singular at theta = +-pi/2: a swing coordinate singularity).

#include <Eigen/Core>

#include "crane/common/crane_parameters.hpp"
#include "crane/plant/crane_dynamics.hpp"

namespace crane::plant {

/// Linearization about rest (q = (x0, 0, gamma0, 0), q_dot = 0, L_dot = L_ddot = 0):
///   mass * q_ddot + stiffness * q_deviation = input * (V_x, V_gamma)
/// in the same row scaling as TowerCraneModel (swing rows divided by m). Combining rows gives
/// (2.28)-(2.31), see the tests.
struct LinearizedModel {
  CoordinateMatrix mass{CoordinateMatrix::Zero()};
  CoordinateMatrix stiffness{CoordinateMatrix::Zero()};
  Eigen::Matrix<double, kNumCoordinates, 2> input{Eigen::Matrix<double, kNumCoordinates, 2>::Zero()};
  // input columns: trolley voltage [V] -> force M_drive*K_mx [N/V]; slew voltage -> J_o*K_mgamma [N m/V]
};

class TowerCraneModel final : public CraneDynamics {
 public:
  /// Validates `parameters` (common::validate, plus load_mass >= 0); throws common::ConfigError.
  explicit TowerCraneModel(const common::CraneParameters& parameters);

  /// Mass matrix M(q, L) and bias b(q, q_dot, L, L_dot, L_ddot) with M q_ddot + b = Q.
  void compute_dynamics(const ModelState& state, const HoistMotion& hoist, CoordinateMatrix& mass_matrix,
                        CoordinateVector& bias) const noexcept override;
  // acceleration() (Q = (F_x [N], 0, T_gamma [N m], 0)) and total_energy() come from CraneDynamics.
  [[nodiscard]] std::unique_ptr<CraneDynamics> clone() const override;

  /// Kinetic energy T [J] (uses L and L_dot; L_ddot is ignored).
  [[nodiscard]] double kinetic_energy(const ModelState& state, const HoistMotion& hoist) const noexcept override;
  /// Potential energy V = -m g L cos(theta) cos(phi) [J] (2.14).
  [[nodiscard]] double potential_energy(const ModelState& state, double cable_length) const noexcept override;

  /// Generalized momentum of the slew coordinate dT/d(gamma_dot) [kg m^2/s]; conserved when T_gamma = 0
  /// (gamma is cyclic).
  [[nodiscard]] double slew_momentum(const ModelState& state, const HoistMotion& hoist) const noexcept;

  /// Load position in the inertial frame (origin on the slew axis at jib height, z up) [m].
  [[nodiscard]] Eigen::Vector3d load_position(const ModelState& state, double cable_length) const noexcept;

  /// Linearization about rest at trolley position `trolley_position` [m] and cable length
  /// `cable_length` [m] (> 0). Allocation-free.
  [[nodiscard]] LinearizedModel linearize_at_rest(double trolley_position, double cable_length) const noexcept;

  [[nodiscard]] const common::CraneParameters& parameters() const noexcept override { return parameters_; }
  /// trolley: trolley_force_per_volt(); second (the slew): slew_torque_per_volt().
  [[nodiscard]] double drive_force_per_volt(DriveAxis axis) const noexcept override;
  /// Drive force per volt M_drive*K_mx [N/V].
  [[nodiscard]] double trolley_force_per_volt() const noexcept;
  /// Drive torque per volt J_o*K_mgamma [N m/V].
  [[nodiscard]] double slew_torque_per_volt() const noexcept;

 private:
  common::CraneParameters parameters_;
};

}  // namespace crane::plant
