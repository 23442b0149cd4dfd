#include "crane/adaptation/limit_cycle_detector.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"

namespace crane::adaptation {

void validate(const LimitCycleParams& p, const char* prefix) {
  const std::string f = prefix;
  common::require_in_range(f + ".window", p.window, 0.1, 60.0);
  common::require_greater(f + ".rest_span", p.rest_span, 0.0);
  common::require_finite(f + ".rest_span", p.rest_span);
  common::require_at_least(f + ".min_voltage", p.min_voltage, 0.0);
  common::require_finite(f + ".min_voltage", p.min_voltage);
  common::require_in_range(f + ".max_reversals", p.max_reversals, 2, 1000);
}

LimitCycleDetector::LimitCycleDetector(const LimitCycleParams& params, double sample_period,
                                       double zero_velocity_band, const char* prefix)
    : params_(params), sample_period_(sample_period), zero_velocity_band_(zero_velocity_band) {
  validate(params_, prefix);
  common::require_in_range(std::string(prefix) + ".sample_period", sample_period, 1e-6, 1.0);
  common::require_at_least(std::string(prefix) + ".zero_velocity_band", zero_velocity_band, 0.0);
  positions_.assign(static_cast<std::size_t>(std::ceil(params_.window / sample_period_)) + 1, 0.0);
  reversal_at_.assign(static_cast<std::size_t>(params_.max_reversals), 0);
  reset();
}

void LimitCycleDetector::reset() noexcept {
  std::fill(reversal_at_.begin(), reversal_at_.end(), 0);
  sample_ = 0;
  last_voltage_sign_ = 0;
  last_breakaway_ = 0;
  moving_ = 0;
  sign_changes_ = 0;
  reversals_total_ = 0;
  fired_ = false;
}

void LimitCycleDetector::step(double position, double voltage) noexcept {
  if (!std::isfinite(position) || !std::isfinite(voltage)) return;
  const std::size_t n = positions_.size();
  if (sample_ == 0) std::fill(positions_.begin(), positions_.end(), position);
  positions_[sample_ % n] = position;
  const auto [lowest, highest] = std::minmax_element(positions_.begin(), positions_.end());
  const bool at_rest = *highest - *lowest <= params_.rest_span;

  const int voltage_sign = voltage >= params_.min_voltage ? 1 : (voltage <= -params_.min_voltage ? -1 : 0);
  if (voltage_sign != 0) {
    if (at_rest && last_voltage_sign_ != 0 && voltage_sign != last_voltage_sign_) ++sign_changes_;
    last_voltage_sign_ = voltage_sign;
  }

  const double velocity = sample_ == 0 ? 0.0 : (position - last_position_) / sample_period_;  // (4.8)
  const int direction = friction_compensation::friction_direction(velocity, zero_velocity_band_);
  if (direction != 0 && moving_ == 0) {  // a breakaway
    if (at_rest && last_breakaway_ != 0 && direction != last_breakaway_ && direction == voltage_sign) {
      reversal_at_[reversals_total_ % reversal_at_.size()] = sample_;
      ++reversals_total_;
      const std::uint64_t window_samples = n - 1;
      if (reversals_total_ >= reversal_at_.size()) {
        const std::uint64_t oldest = reversal_at_[reversals_total_ % reversal_at_.size()];
        if (sample_ - oldest <= window_samples) fired_ = true;
      }
    }
    last_breakaway_ = direction;
  }
  moving_ = direction;
  last_position_ = position;
  ++sample_;
}

}  // namespace crane::adaptation
