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
// With a hook (HookParameters::enabled, plant.hook; beyond the dissertation) the cable ends at a
// hook of mass m_h and the load hangs from it on rigging of length l: a double pendulum on the
// trolley and the jib, coordinates (x, phi, gamma, theta, phi2, theta2) with (phi, theta) the
// cable's direction (trolley to hook, what the swing encoders measure) and (phi2, theta2) the
// rigging's, both absolute and in the same convention u(.,.):
//   r_hook = x e_x + L u(phi, theta),   r_load = r_hook + l u(phi2, theta2).
// The equations of motion are the same d'Alembert form summed over the two point masses,
//   sum_i m_i (dp_i/dq_j) . (a_i + g e_z) = Q_j,  i in {hook, load},
// (the Lagrange equations of T = 1/2 m_h |v_hook|^2 + 1/2 m |v_load|^2 + trolley and jib terms,
// V = g (m_h z_hook + m z_load); the standard double-pendulum crane model, e.g. W. Singhose, D. Kim,
// M. Kenison, "Input shaping control of double-pendulum bridge crane oscillations", J. Dyn. Sys.
// Meas. Control 130(3), 2008, extended here by the slew and the hoist as in (2.11)-(2.16)). Row
// scaling: the cable rows (phi, theta) are divided by m_h + m, the rigging rows by m (a massless
// load: the rigging rows of a unit mass, a passive pendulum on the hook).
//
// With an elastic rope (RopeParameters::enabled, plant.rope; no hook) the load hangs at
//   r_load = x e_x + (L + s) u(phi, theta),
// s [m] the rope's stretch, a fifth coordinate (slot 4): the same d'Alembert form with the column
// dr/ds = u, plus the rope's force on it, k s + c s', with k = EA / L (EA the rope's axial stiffness
// [N], L the paid-out length: a longer rope is softer) and c = 2 zeta sqrt(k m). The s row is divided
// by m like the swing rows. Energy: + 1/2 k s^2.
//
// Errors: the constructor validates the parameters and throws common::ConfigError. Evaluation
// functions are noexcept, allocation-free, and assume finite inputs with L > 0 and
// |theta| < pi/2 (the mass matrix is singular at theta = +-pi/2: a swing coordinate singularity).

#include <Eigen/Core>
#include <string>

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

/// The hook as a second pendulum (config plant.hook). Off by default: the single pendulum above.
struct HookParameters {
  bool enabled{false};
  double rigging_length{0.3};  // [m] l, hook to the load's centre of mass, in [0.001, 10]
  double hook_mass{0.5};       // [kg] m_h, in [0.001, 1e4]
};
/// Throws common::ConfigError naming `prefix` + field, the value and the bound (checked when enabled).
void validate(const HookParameters& hook, const std::string& prefix);

/// The rope as a spring (config plant.rope). Off by default: an inextensible cable.
struct RopeParameters {
  bool enabled{false};
  double axial_stiffness{2.0e5};  // [N] EA, in [1, 1e10]: k = EA / L [N/m]
  double damping_ratio{0.02};     // [-] zeta of the load's bounce on the rope, in [0, 1]
};
/// Throws common::ConfigError naming `prefix` + field, the value and the bound (checked when enabled).
void validate(const RopeParameters& rope, const std::string& prefix);

/// Swing frequencies [rad/s] of the double pendulum hanging from a held trolley, linearized about
/// rest (Singhose, Kim, Kenison 2008, eq. (2)): with R = m/m_h,
///   omega^2 = g/2 (1 + R)(1/L + 1/l) -+ g/2 sqrt((1 + R)^2 (1/L + 1/l)^2 - 4 (1 + R)/(L l)).
/// first: the lower (-) mode, tending to sqrt(g/L) as l -> 0; second: the higher. Arguments in
/// [m], [m], [kg], [kg], [m/s^2], all > 0 (load_mass >= 0); NaN otherwise.
struct DoublePendulumFrequencies {
  double first{0.0};   // [rad/s]
  double second{0.0};  // [rad/s]
};
[[nodiscard]] DoublePendulumFrequencies double_pendulum_frequencies(double cable_length, double rigging_length,
                                                                    double hook_mass, double load_mass,
                                                                    double gravity) noexcept;

class TowerCraneModel final : public CraneDynamics {
 public:
  /// Validates `parameters` (common::validate, plus load_mass >= 0), `hook` and `rope` (field names
  /// "plant.hook.*", "plant.rope.*"; a rope needs load_mass > 0 and no hook); throws common::ConfigError.
  explicit TowerCraneModel(const common::CraneParameters& parameters, const HookParameters& hook = {},
                           const RopeParameters& rope = {});

  /// 6 with a hook, 5 with an elastic rope, 4 otherwise.
  [[nodiscard]] int coordinate_count() const noexcept override;
  /// Without a hook or rope: compute_dynamics() embedded. With one: the models above.
  void compute_extended_dynamics(const ExtendedState& state, const HoistMotion& hoist, ExtendedMatrix& mass_matrix,
                                 ExtendedVector& bias) const noexcept override;
  /// Q_j = (dp_load/dq_j) . F for a horizontal force F = (force_x, force_y, 0) [N] in the inertial
  /// frame, rows scaled as above (swing rows per unit mass: needs load_mass > 0).
  [[nodiscard]] ExtendedVector load_force(const ExtendedState& state, const HoistMotion& hoist, double force_x,
                                          double force_y) const noexcept override;
  /// T + V [J], the hook's energy included.
  [[nodiscard]] double extended_total_energy(const ExtendedState& state, const HoistMotion& hoist) const noexcept override;
  [[nodiscard]] const HookParameters& hook() const noexcept { return hook_; }
  [[nodiscard]] const RopeParameters& rope() const noexcept { return rope_; }
  /// k = EA / L [N/m] of the elastic rope at paid-out length `cable_length` [m] (> 0).
  [[nodiscard]] double rope_stiffness(double cable_length) const noexcept;

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
  HookParameters hook_;
  RopeParameters rope_;
};

}  // namespace crane::plant
