#include "crane/tracking/breakaway_ramp.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "crane/common/validation.hpp"

namespace crane::tracking {

BreakawayRamp::BreakawayRamp(const BreakawayRampParams& params, double sample_period)
    : params_(params), period_(sample_period) {
  common::require_greater("tracking.breakaway.deadband", params.deadband, 0.0);
  common::require_greater("tracking.breakaway.rest_speed", params.rest_speed, 0.0);
  common::require_in_range("tracking.breakaway.rest_time", params.rest_time, 0.0, 60.0);
  common::require_greater("tracking.breakaway.rate", params.rate, 0.0);
  common::require_greater("tracking.breakaway.limit", params.limit, 0.0);
  common::require_greater("tracking.breakaway.sample_period", sample_period, 0.0);
  rest_cycles_needed_ = static_cast<int>(std::ceil(params.rest_time / sample_period - 1e-9));
}

void BreakawayRamp::reset() noexcept {
  ramp_ = {};
  rest_cycles_ = {};
}

double BreakawayRamp::step(int axis, double position_error, double speed) noexcept {
  if (axis < 0 || axis > 1) return 0.0;
  const auto a = static_cast<std::size_t>(axis);
  if (!std::isfinite(position_error) || !std::isfinite(speed) || std::abs(position_error) < params_.deadband) {
    ramp_[a] = 0.0;
    rest_cycles_[a] = 0;
    return 0.0;
  }
  if (std::abs(speed) >= params_.rest_speed) {
    rest_cycles_[a] = 0;
    return ramp_[a];
  }
  rest_cycles_[a] = std::min(rest_cycles_[a] + 1, std::numeric_limits<int>::max() - 1);
  if (rest_cycles_[a] >= rest_cycles_needed_) {
    const double toward_target = position_error > 0.0 ? -1.0 : 1.0;
    ramp_[a] = std::clamp(ramp_[a] + toward_target * params_.rate * period_, -params_.limit, params_.limit);
  }
  return ramp_[a];
}

}  // namespace crane::tracking
