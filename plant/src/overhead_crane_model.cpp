#include "crane/plant/overhead_crane_model.hpp"

#include <cmath>

#include "cable_direction.hpp"
#include "crane/common/validation.hpp"

namespace crane::plant {

namespace {

using Eigen::Vector3d;

bool is_swing_row(int j) { return j == kInPlaneSwingIndex || j == kOutOfPlaneSwingIndex; }

struct LoadKinematics {
  Vector3d r;                        // load position [m]
  Vector3d velocity;                 // [m/s]
  Vector3d column[kNumCoordinates];  // c_j = dr/dq_j
  Vector3d a_rest;                   // velocity-product and hoist terms of the acceleration [m/s^2]
};

// The kinematics of the header's derivation.
LoadKinematics load_kinematics(const ModelState& state, const HoistMotion& hoist) {
  const double phi = state.position[kInPlaneSwingIndex];
  const double theta = state.position[kOutOfPlaneSwingIndex];
  const double phi_d = state.velocity[kInPlaneSwingIndex];
  const double theta_d = state.velocity[kOutOfPlaneSwingIndex];
  const double L = hoist.cable_length;
  const double L_d = hoist.cable_length_rate;
  const double L_dd = hoist.cable_length_acceleration;
  const detail::CableDirection d = detail::cable_direction(phi, theta);
  const Vector3d u_dot = d.u_p * phi_d + d.u_t * theta_d;

  LoadKinematics k;
  k.r = Vector3d(state.position[kTrolleyIndex], state.position[kBridgeIndex], 0.0) + L * d.u;
  k.velocity = Vector3d(state.velocity[kTrolleyIndex], state.velocity[kBridgeIndex], 0.0) + L_d * d.u + L * u_dot;
  k.column[kTrolleyIndex] = Vector3d::UnitX();
  k.column[kInPlaneSwingIndex] = L * d.u_p;
  k.column[kBridgeIndex] = Vector3d::UnitY();
  k.column[kOutOfPlaneSwingIndex] = L * d.u_t;
  k.a_rest = L_dd * d.u + 2.0 * L_d * u_dot +
             L * (d.u_pp * (phi_d * phi_d) + 2.0 * d.u_pt * (phi_d * theta_d) + d.u_tt * (theta_d * theta_d));
  return k;
}

}  // namespace

OverheadCraneModel::OverheadCraneModel(const common::CraneParameters& crane, const common::BridgeParameters& bridge)
    : crane_(crane), bridge_(bridge) {
  common::validate(crane_, "crane");
  common::validate(bridge_, "bridge");
}

std::unique_ptr<CraneDynamics> OverheadCraneModel::clone() const { return std::make_unique<OverheadCraneModel>(*this); }

void OverheadCraneModel::compute_dynamics(const ModelState& state, const HoistMotion& hoist,
                                          CoordinateMatrix& mass_matrix, CoordinateVector& bias) const noexcept {
  const double m = crane_.load_mass;
  const LoadKinematics k = load_kinematics(state, hoist);
  const Vector3d a_plus_gravity = k.a_rest + Vector3d(0.0, 0.0, crane_.gravity);
  for (int j = 0; j < kNumCoordinates; ++j) {
    const double row_scale = is_swing_row(j) ? 1.0 : m;
    for (int c = 0; c < kNumCoordinates; ++c) mass_matrix(j, c) = row_scale * k.column[j].dot(k.column[c]);
    bias[j] = row_scale * k.column[j].dot(a_plus_gravity);
  }
  mass_matrix(kTrolleyIndex, kTrolleyIndex) += crane_.trolley_drive_mass;
  mass_matrix(kBridgeIndex, kBridgeIndex) += bridge_.drive_mass;
}

double OverheadCraneModel::kinetic_energy(const ModelState& state, const HoistMotion& hoist) const noexcept {
  const LoadKinematics k = load_kinematics(state, hoist);
  const double x_d = state.velocity[kTrolleyIndex];
  const double y_d = state.velocity[kBridgeIndex];
  return 0.5 * crane_.load_mass * k.velocity.squaredNorm() + 0.5 * crane_.trolley_drive_mass * x_d * x_d +
         0.5 * bridge_.drive_mass * y_d * y_d;
}

double OverheadCraneModel::potential_energy(const ModelState& state, double cable_length) const noexcept {
  return -crane_.load_mass * crane_.gravity * cable_length * std::cos(state.position[kOutOfPlaneSwingIndex]) *
         std::cos(state.position[kInPlaneSwingIndex]);
}

double OverheadCraneModel::drive_force_per_volt(DriveAxis axis) const noexcept {
  return axis == DriveAxis::trolley ? crane_.trolley_drive_mass * crane_.trolley_drive_gain
                                    : bridge_.drive_mass * bridge_.drive_gain;
}

Eigen::Vector3d OverheadCraneModel::load_position(const ModelState& state, double cable_length) const noexcept {
  HoistMotion hoist;
  hoist.cable_length = cable_length;
  return load_kinematics(state, hoist).r;
}

LinearizedModel OverheadCraneModel::linearize_at_rest(double cable_length) const noexcept {
  ModelState rest;
  HoistMotion hoist;
  hoist.cable_length = cable_length;
  LinearizedModel lin;
  CoordinateVector bias_at_rest;
  compute_dynamics(rest, hoist, lin.mass, bias_at_rest);
  // Hessian of V = -m g L cos(theta) cos(phi) at rest, swing rows divided by m.
  lin.stiffness(kInPlaneSwingIndex, kInPlaneSwingIndex) = crane_.gravity * cable_length;
  lin.stiffness(kOutOfPlaneSwingIndex, kOutOfPlaneSwingIndex) = crane_.gravity * cable_length;
  lin.input(kTrolleyIndex, 0) = drive_force_per_volt(DriveAxis::trolley);
  lin.input(kBridgeIndex, 1) = drive_force_per_volt(DriveAxis::second);
  return lin;
}

double OverheadCraneModel::free_in_plane_swing_frequency(double cable_length) const noexcept {
  return std::sqrt((1.0 + crane_.load_mass / crane_.trolley_drive_mass) * crane_.gravity / cable_length);
}

double OverheadCraneModel::free_out_of_plane_swing_frequency(double cable_length) const noexcept {
  return std::sqrt((1.0 + crane_.load_mass / bridge_.drive_mass) * crane_.gravity / cable_length);
}

}  // namespace crane::plant
