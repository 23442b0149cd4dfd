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

}  // namespace crane::plant
