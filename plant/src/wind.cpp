#include "crane/plant/wind.hpp"

#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::plant {

void validate(const WindParameters& wind, const std::string& prefix) {
  if (!wind.enabled) return;
  common::require_in_range(prefix + "mean_force_x", wind.mean_force_x, -1e4, 1e4);
  common::require_in_range(prefix + "mean_force_y", wind.mean_force_y, -1e4, 1e4);
  common::require_in_range(prefix + "gust_force_std", wind.gust_force_std, 0.0, 1e4);
  common::require_in_range(prefix + "gust_time_constant", wind.gust_time_constant, 0.01, 1e4);
}

WindForce::WindForce(const WindParameters& wind, double sample_period) : wind_(wind) {
  validate(wind_, "plant.wind.");
  common::require_greater("plant.wind sample_period", sample_period, 0.0);
  decay_ = std::exp(-sample_period / wind_.gust_time_constant);
  innovation_ = std::sqrt(1.0 - decay_ * decay_) * wind_.gust_force_std;
  reset();
}

void WindForce::reset() noexcept {
  random_.seed(wind_.seed);
  normal_.reset();
  gust_x_ = 0.0;
  gust_y_ = 0.0;
}

void WindForce::advance() noexcept {
  if (!wind_.enabled) return;
  gust_x_ = decay_ * gust_x_ + innovation_ * normal_(random_);
  gust_y_ = decay_ * gust_y_ + innovation_ * normal_(random_);
}

}  // namespace crane::plant
