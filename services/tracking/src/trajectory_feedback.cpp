#include "crane/tracking/trajectory_feedback.hpp"

#include <algorithm>
#include <cmath>

namespace crane::tracking {

std::array<double, 2> trajectory_feedback_voltages(const common::TrajectoryFeedback& law,
                                                   const std::array<double, 4>& position,
                                                   const std::array<double, 4>& velocity,
                                                   double voltage_limit) noexcept {
  std::array<double, 2> u{};
  for (std::size_t r = 0; r < 2; ++r) {
    const double* K = &law.gain[r * 8];
    double feedback = 0.0;
    for (std::size_t j = 0; j < 4; ++j) {
      feedback += K[j] * (position[j] - law.position[j]);
      feedback += K[4 + j] * (velocity[j] - law.velocity[j]);
    }
    const double v = law.feedforward[r] - feedback;
    u[r] = std::isfinite(v) ? std::clamp(v, -voltage_limit, voltage_limit) : v;
  }
  return u;
}

}  // namespace crane::tracking
