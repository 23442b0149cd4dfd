#pragma once
// The rigid-body model interface the plant integrates: one per crane kind (tower, gantry, overhead),
// all in the same four-slot coordinate layout so that one integrator (hybrid_integrator.hpp), one
// friction model per drive axis (axis_friction.hpp) and one drives-and-sensors model serve them all.
//
// Coordinates q (SI), by slot:
//   0  x      [m]   trolley position (along the jib, the gantry rail or the bridge girder)
//   1  phi    [rad] swing in the trolley's plane of motion (tower convention, ERRATA: the load sits at
//                   x - L cos(theta) sin(phi) along the trolley axis)
//   2  second drive axis: slew angle gamma [rad] (tower), bridge position y [m] (overhead), held at 0
//                   (gantry: no second axis)
//   3  theta  [rad] swing out of that plane
// The cable length L [m] is a prescribed kinematic input (L, L_dot, L_ddot) from the hoist.
// A model may have two more coordinates (coordinate_count() == 6, the tower crane with its hook as a
// double pendulum, TowerCraneModel with HookParameters): slots 4 and 5 are the rigging's direction
// from the hook to the load (phi2, theta2 [rad], absolute angles in the convention of phi, theta);
// phi and theta are then the cable's direction from the trolley to the hook (what the swing
// encoders measure). Such a model is evaluated through the Extended* functions.
//
// Equations of motion in mass-matrix form  M(q, L) q_ddot + b(q, q_dot, L, L_dot, L_ddot) = Q,
// with generalized forces Q = (F_trolley, 0, F_second_axis, 0) [N, -, N or N m, -]. The rows of the
// two drive axes are forces [N] (torques [N m] for the slew); the integrator reads the force that
// holds a stuck axis from them. The swing rows may be scaled freely (each model documents its own).
//
// Errors: implementations validate their parameters in their constructors (common::ConfigError);
// evaluation functions are noexcept, allocation-free, and assume finite inputs with L > 0 and
// |theta| < pi/2.

#include <memory>

#include <Eigen/Core>

#include "crane/common/crane_parameters.hpp"

namespace crane::plant {

/// Index of each generalized coordinate in q.
enum CoordinateIndex : int {
  kTrolleyIndex = 0,          // x [m]
  kInPlaneSwingIndex = 1,     // phi [rad]
  kSlewIndex = 2,             // gamma [rad] (tower crane)
  kBridgeIndex = 2,           // y [m] (overhead crane): the same slot as the slew
  kOutOfPlaneSwingIndex = 3,  // theta [rad]
};
inline constexpr int kNumCoordinates = 4;
/// Slots of a model with a hook (coordinate_count() == 6).
inline constexpr int kRiggingInPlaneIndex = 4;      // phi2 [rad]
inline constexpr int kRiggingOutOfPlaneIndex = 5;   // theta2 [rad]
/// Slot of a model with an elastic rope and no hook (coordinate_count() == 5).
inline constexpr int kRopeStretchIndex = 4;         // s [m], the rope's stretch
inline constexpr int kMaxCoordinates = 6;

using CoordinateVector = Eigen::Matrix<double, kNumCoordinates, 1>;
using CoordinateMatrix = Eigen::Matrix<double, kNumCoordinates, kNumCoordinates>;

/// Generalized positions and velocities.
struct ModelState {
  CoordinateVector position{CoordinateVector::Zero()};  // q [m, rad, rad or m, rad]
  CoordinateVector velocity{CoordinateVector::Zero()};  // q_dot [m/s, rad/s, rad/s or m/s, rad/s]
};

using ExtendedVector = Eigen::Matrix<double, kMaxCoordinates, 1>;
using ExtendedMatrix = Eigen::Matrix<double, kMaxCoordinates, kMaxCoordinates>;

/// Generalized positions and velocities of a model with up to six coordinates (unused slots 0).
struct ExtendedState {
  ExtendedVector position{ExtendedVector::Zero()};  // [m, rad, rad or m, rad, rad, rad]
  ExtendedVector velocity{ExtendedVector::Zero()};  // [m/s, rad/s, rad/s or m/s, rad/s, rad/s, rad/s]
};

/// Prescribed hoist motion at one instant.
struct HoistMotion {
  double cable_length{1.0};               // [m] L > 0
  double cable_length_rate{0.0};          // [m/s] L_dot
  double cable_length_acceleration{0.0};  // [m/s^2] L_ddot
};

/// The two drive axes with friction and brakes (slot 0 and slot 2 of q).
enum class DriveAxis : int { trolley = 0, second = 1 };

class CraneDynamics {
 public:
  virtual ~CraneDynamics() = default;
  /// A copy of the same model (the integrator keeps its own).
  [[nodiscard]] virtual std::unique_ptr<CraneDynamics> clone() const = 0;

  /// Mass matrix M(q, L) and bias b(q, q_dot, L, L_dot, L_ddot) with M q_ddot + b = Q.
  virtual void compute_dynamics(const ModelState& state, const HoistMotion& hoist, CoordinateMatrix& mass_matrix,
                                CoordinateVector& bias) const noexcept = 0;
  /// Kinetic energy T [J] (uses L and L_dot; L_ddot is ignored).
  [[nodiscard]] virtual double kinetic_energy(const ModelState& state, const HoistMotion& hoist) const noexcept = 0;
  /// Potential energy V = -m g L cos(theta) cos(phi) [J].
  [[nodiscard]] virtual double potential_energy(const ModelState& state, double cable_length) const noexcept = 0;
  /// Drive force [N] (torque [N m] for the slew) per volt of `axis`; 0 for an axis the crane lacks.
  [[nodiscard]] virtual double drive_force_per_volt(DriveAxis axis) const noexcept = 0;
  /// Load, trolley, hoist, drive and sensor parameters shared by every kind.
  [[nodiscard]] virtual const common::CraneParameters& parameters() const noexcept = 0;

  /// 4 (x, phi, second axis, theta), or 6 for a model with a hook (the rigging's phi2, theta2).
  [[nodiscard]] virtual int coordinate_count() const noexcept { return kNumCoordinates; }
  /// M and b over all coordinate_count() coordinates (unused slots: identity row, zero bias). The
  /// default embeds compute_dynamics().
  virtual void compute_extended_dynamics(const ExtendedState& state, const HoistMotion& hoist, ExtendedMatrix& mass_matrix,
                                         ExtendedVector& bias) const noexcept;
  /// Generalized force [rows' units] of a horizontal force (force_x, force_y) [N] on the load, in
  /// the inertial frame (x along the jib at slew 0), rows scaled like compute_extended_dynamics:
  /// Q_j = (dp_load/dq_j) . F. Needs load_mass > 0 (the swing rows are divided by it). The default
  /// returns 0 (a model without a load force).
  [[nodiscard]] virtual ExtendedVector load_force(const ExtendedState& state, const HoistMotion& hoist, double force_x,
                                                  double force_y) const noexcept;
  /// T + V [J] over all coordinates (the default: total_energy of the first four).
  [[nodiscard]] virtual double extended_total_energy(const ExtendedState& state, const HoistMotion& hoist) const noexcept;

  /// Unconstrained accelerations q_ddot for generalized forces Q (units of the rows).
  [[nodiscard]] CoordinateVector acceleration(const ModelState& state, const HoistMotion& hoist,
                                              const CoordinateVector& generalized_force) const noexcept;
  /// T + V [J]. Conserved when Q = 0 and L is constant.
  [[nodiscard]] double total_energy(const ModelState& state, const HoistMotion& hoist) const noexcept {
    return kinetic_energy(state, hoist) + potential_energy(state, hoist.cable_length);
  }
  /// Unconstrained accelerations over all coordinate_count() coordinates.
  [[nodiscard]] ExtendedVector extended_acceleration(const ExtendedState& state, const HoistMotion& hoist,
                                                     const ExtendedVector& generalized_force) const noexcept;

 protected:
  CraneDynamics() = default;
  CraneDynamics(const CraneDynamics&) = default;
  CraneDynamics& operator=(const CraneDynamics&) = default;
};

}  // namespace crane::plant
