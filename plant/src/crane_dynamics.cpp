#include "crane/plant/crane_dynamics.hpp"

#include <Eigen/LU>

namespace crane::plant {

CoordinateVector CraneDynamics::acceleration(const ModelState& state, const HoistMotion& hoist,
                                             const CoordinateVector& generalized_force) const noexcept {
  CoordinateMatrix mass;
  CoordinateVector bias;
  compute_dynamics(state, hoist, mass, bias);
  return mass.partialPivLu().solve(generalized_force - bias);
}

namespace {
ModelState first_four(const ExtendedState& state) {
  ModelState m;
  m.position = state.position.head<kNumCoordinates>();
  m.velocity = state.velocity.head<kNumCoordinates>();
  return m;
}
}  // namespace

void CraneDynamics::compute_extended_dynamics(const ExtendedState& state, const HoistMotion& hoist,
                                              ExtendedMatrix& mass_matrix, ExtendedVector& bias) const noexcept {
  CoordinateMatrix mass;
  CoordinateVector b;
  compute_dynamics(first_four(state), hoist, mass, b);
  mass_matrix.setIdentity();
  mass_matrix.topLeftCorner<kNumCoordinates, kNumCoordinates>() = mass;
  bias.setZero();
  bias.head<kNumCoordinates>() = b;
}

ExtendedVector CraneDynamics::load_force(const ExtendedState&, const HoistMotion&, double, double) const noexcept {
  return ExtendedVector::Zero();
}

double CraneDynamics::extended_total_energy(const ExtendedState& state, const HoistMotion& hoist) const noexcept {
  return total_energy(first_four(state), hoist);
}

ExtendedVector CraneDynamics::extended_acceleration(const ExtendedState& state, const HoistMotion& hoist,
                                                    const ExtendedVector& generalized_force) const noexcept {
  ExtendedMatrix mass;
  ExtendedVector bias;
  compute_extended_dynamics(state, hoist, mass, bias);
  return mass.partialPivLu().solve(generalized_force - bias);
}

}  // namespace crane::plant
