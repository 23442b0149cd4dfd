#include "crane/plant/gantry_crane_model.hpp"

#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::plant {

GantryCraneModel::GantryCraneModel(const common::CraneParameters& parameters) : parameters_(parameters) {
  common::validate(parameters_, "crane");
}

std::unique_ptr<CraneDynamics> GantryCraneModel::clone() const { return std::make_unique<GantryCraneModel>(*this); }

void GantryCraneModel::compute_dynamics(const ModelState& state, const HoistMotion& hoist,
                                        CoordinateMatrix& mass_matrix, CoordinateVector& bias) const noexcept {
  const double m = parameters_.load_mass;
  const double M = parameters_.trolley_drive_mass;
  const double g = parameters_.gravity;
  const double phi = state.position[kInPlaneSwingIndex];
  const double phi_d = state.velocity[kInPlaneSwingIndex];
  const double L = hoist.cable_length;
  const double L_d = hoist.cable_length_rate;
  const double L_dd = hoist.cable_length_acceleration;
  const double s = std::sin(phi), c = std::cos(phi);

  mass_matrix.setZero();
  bias.setZero();
  // (2.5), tower sign of phi.
  mass_matrix(kTrolleyIndex, kTrolleyIndex) = m + M;
  mass_matrix(kTrolleyIndex, kInPlaneSwingIndex) = -m * L * c;
  bias[kTrolleyIndex] = -m * L_dd * s - 2.0 * m * L_d * phi_d * c + m * L * phi_d * phi_d * s;
  // (2.6), tower sign of phi.
  mass_matrix(kInPlaneSwingIndex, kTrolleyIndex) = -c;
  mass_matrix(kInPlaneSwingIndex, kInPlaneSwingIndex) = L;
  bias[kInPlaneSwingIndex] = g * s + 2.0 * L_d * phi_d;
  // No second axis, no out-of-plane swing: held.
  mass_matrix(kSlewIndex, kSlewIndex) = 1.0;
  mass_matrix(kOutOfPlaneSwingIndex, kOutOfPlaneSwingIndex) = 1.0;
}

double GantryCraneModel::kinetic_energy(const ModelState& state, const HoistMotion& hoist) const noexcept {
  // r_load = (x - L sin(phi), -L cos(phi)) (2.1, tower sign)
  const double phi = state.position[kInPlaneSwingIndex];
  const double x_d = state.velocity[kTrolleyIndex];
  const double phi_d = state.velocity[kInPlaneSwingIndex];
  const double L = hoist.cable_length;
  const double L_d = hoist.cable_length_rate;
  const double s = std::sin(phi), c = std::cos(phi);
  const double v_horizontal = x_d - L_d * s - L * c * phi_d;
  const double v_vertical = -L_d * c + L * s * phi_d;
  return 0.5 * parameters_.load_mass * (v_horizontal * v_horizontal + v_vertical * v_vertical) +
         0.5 * parameters_.trolley_drive_mass * x_d * x_d;
}

double GantryCraneModel::potential_energy(const ModelState& state, double cable_length) const noexcept {
  return -parameters_.load_mass * parameters_.gravity * cable_length * std::cos(state.position[kInPlaneSwingIndex]);
}

double GantryCraneModel::drive_force_per_volt(DriveAxis axis) const noexcept {
  return axis == DriveAxis::trolley ? parameters_.trolley_drive_mass * parameters_.trolley_drive_gain : 0.0;
}

GantryLinearModel GantryCraneModel::linearize_at_rest(double cable_length) const noexcept {
  // (2.7): x_dd = -m_t g phi + K_mx V;  (2.8): phi_dd = (x_dd - g phi)/L = (-(1 + m_t) g phi + K_mx V)/L.
  const double g = parameters_.gravity;
  const double m_t = mass_ratio();
  const double K_mx = parameters_.trolley_drive_gain;
  const double L = cable_length;
  GantryLinearModel lin;
  lin.state_matrix(0, 2) = 1.0;
  lin.state_matrix(1, 3) = 1.0;
  lin.state_matrix(2, 1) = -m_t * g;
  lin.state_matrix(3, 1) = -(1.0 + m_t) * g / L;
  lin.input_matrix(2) = K_mx;
  lin.input_matrix(3) = K_mx / L;
  return lin;
}

double GantryCraneModel::free_trolley_swing_frequency(double cable_length) const noexcept {
  return std::sqrt((1.0 + mass_ratio()) * parameters_.gravity / cable_length);
}

}  // namespace crane::plant
