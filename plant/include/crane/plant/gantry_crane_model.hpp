#pragma once
// Nonlinear model of the gantry crane with hoisting, section 2.1 of H. M. Omar, "Control of Gantry
// and Tower Cranes", Virginia Tech 2003: (2.5)-(2.6) from the Lagrangian (2.1)-(2.4), and its
// linearization (2.7)-(2.9).
//
// Generalized coordinates q = (x, phi): trolley position x [m] along the rail, swing phi [rad] in the
// vertical plane of the rail. Cable length L [m] prescribed by the hoist (L, L_dot, L_ddot).
// Sign convention: the tower crane's (ERRATA; the dissertation's (2.1) has the opposite sign of phi):
// the load sits at (x - L sin(phi), -L cos(phi)), so with M = trolley_drive_mass, m = load_mass:
//   T = 1/2 m |r_load_dot|^2 + 1/2 M x_dot^2,   V = -m g L cos(phi)                         (2.2)-(2.3)
//   (m + M) x_dd - m L cos(phi) phi_dd - m L_dd sin(phi) - 2 m L_d phi_d cos(phi)
//                                       + m L phi_d^2 sin(phi) = F_x                       (2.5)
//   L phi_dd + g sin(phi) + 2 L_d phi_d - x_dd cos(phi) = 0                                 (2.6)
// and, for small phi and slow hoisting, divided by M (m_t = m/M, F_x/M = K_mx V_x (2.9)-(2.10)):
//   x_dd + m_t g phi = K_mx V_x                                                             (2.7)
//   L phi_dd + g phi - x_dd = 0                                                             (2.8)
// (the printed (2.7)-(2.8) have -m_t g phi and +x_dd: the opposite phi).
//
// In the plant's four-slot layout (crane_dynamics.hpp) slots 2 and 3 are held: their rows are the
// identity with zero bias, so the gantry runs through the same integrator, friction and sensors as
// the tower crane. Rows: slot 0 is (2.5) [N]; slot 1 is (2.6) [m/s^2].
//
// Uses from common::CraneParameters: gravity, load_mass, trolley_drive_mass (M: trolley plus
// reflected drive inertia), trolley_drive_gain (K_mx), cable range; the slew fields are unused.
// Errors: the constructor validates (common::validate) and throws common::ConfigError; the rest is
// noexcept and allocation-free.

#include <Eigen/Core>

#include "crane/common/crane_parameters.hpp"
#include "crane/plant/crane_dynamics.hpp"

namespace crane::plant {

/// Linear model (2.7)-(2.8) in state-space form, state z = (x, phi, x_dot, phi_dot), input V_x [V]:
///   z_dot = state_matrix z + input_matrix V_x.
struct GantryLinearModel {
  Eigen::Matrix4d state_matrix{Eigen::Matrix4d::Zero()};
  Eigen::Vector4d input_matrix{Eigen::Vector4d::Zero()};
};

class GantryCraneModel final : public CraneDynamics {
 public:
  /// Validates `parameters` (common::validate, field names prefixed "crane."); throws common::ConfigError.
  explicit GantryCraneModel(const common::CraneParameters& parameters);

  [[nodiscard]] std::unique_ptr<CraneDynamics> clone() const override;
  /// Rows (2.5), (2.6); slots 2 and 3 identity with zero bias.
  void compute_dynamics(const ModelState& state, const HoistMotion& hoist, CoordinateMatrix& mass_matrix,
                        CoordinateVector& bias) const noexcept override;
  /// (2.2) [J]
  [[nodiscard]] double kinetic_energy(const ModelState& state, const HoistMotion& hoist) const noexcept override;
  /// (2.3) [J]
  [[nodiscard]] double potential_energy(const ModelState& state, double cable_length) const noexcept override;
  /// trolley: M K_mx [N/V] (2.9)-(2.10); second: 0 (a gantry has no second axis).
  [[nodiscard]] double drive_force_per_volt(DriveAxis axis) const noexcept override;
  [[nodiscard]] const common::CraneParameters& parameters() const noexcept override { return parameters_; }

  /// (2.7)-(2.8) at cable length `cable_length` [m] (> 0, unchecked). Closed form, noexcept.
  [[nodiscard]] GantryLinearModel linearize_at_rest(double cable_length) const noexcept;
  /// m_t = m/M (2.9) [-].
  [[nodiscard]] double mass_ratio() const noexcept { return parameters_.mass_ratio(); }
  /// Small-swing angular frequency [rad/s] of (2.7)-(2.8) with the trolley free (F_x = 0):
  /// eliminating x_dd gives L phi_dd + (1 + m_t) g phi = 0, so w = sqrt((1 + m_t) g / L).
  /// With the trolley held (x_dd = 0) it is sqrt(g/L). cable_length [m] > 0 (unchecked).
  [[nodiscard]] double free_trolley_swing_frequency(double cable_length) const noexcept;

 private:
  common::CraneParameters parameters_;
};

}  // namespace crane::plant
