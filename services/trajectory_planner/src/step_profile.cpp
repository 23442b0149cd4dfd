#include "crane/trajectory_planner/step_profile.hpp"

#include <cassert>
#include <cmath>

namespace crane::trajectory_planner {

void StepProfile::plan(double target) noexcept {
  assert(std::isfinite(target));
  target_ = target;
}

common::AxisReference StepProfile::sample(double /*time*/) const noexcept {
  common::AxisReference reference;
  reference.position = target_;
  return reference;
}

}  // namespace crane::trajectory_planner
