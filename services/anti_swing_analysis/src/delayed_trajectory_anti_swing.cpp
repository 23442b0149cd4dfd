#include "crane/anti_swing_analysis/delayed_trajectory_anti_swing.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::anti_swing_analysis {
namespace {

double swing_period(double cable_length, double gravity) {
  return 2.0 * std::numbers::pi * std::sqrt(cable_length / gravity);  // T
}

double longest_delay_samples(const DelayedTrajectoryAntiSwingParams& params) {
  return params.normalized_delay * swing_period(params.max_cable_length, params.gravity) / params.sample_period;
}

DelayedTrajectoryAntiSwingParams validated(const DelayedTrajectoryAntiSwingParams& params) {
  common::require_finite("delayed_trajectory_anti_swing.delay_gain", params.delay_gain);
  common::require_greater("delayed_trajectory_anti_swing.normalized_delay", params.normalized_delay, 0.0);
  common::require_greater("delayed_trajectory_anti_swing.sample_period", params.sample_period, 0.0);
  common::require_greater("delayed_trajectory_anti_swing.gravity", params.gravity, 0.0);
  common::require_greater("delayed_trajectory_anti_swing.min_cable_length", params.min_cable_length, 0.0);
  common::require_greater("delayed_trajectory_anti_swing.max_cable_length", params.max_cable_length,
                          params.min_cable_length);
  common::require_greater("delayed_trajectory_anti_swing.min_trolley_radius", params.min_trolley_radius, 0.0);
  const double longest = longest_delay_samples(params);
  if (!(longest < DelayedTrajectoryAntiSwing::kMaxDelaySamples)) {
    throw common::ConfigError("delayed_trajectory_anti_swing.normalized_delay = " +
                              common::format_value(params.normalized_delay) + " gives a delay line of " +
                              common::format_value(longest) + " samples at max_cable_length: must be < " +
                              std::to_string(DelayedTrajectoryAntiSwing::kMaxDelaySamples));
  }
  return params;
}

}  // namespace

DelayedTrajectoryAntiSwing::DelayedTrajectoryAntiSwing(const DelayedTrajectoryAntiSwingParams& params)
    : params_(validated(params)),
      history_(static_cast<std::size_t>(std::ceil(longest_delay_samples(params_))) + 2) {}

void DelayedTrajectoryAntiSwing::reset() noexcept {
  head_ = 0;
  count_ = 0;
}

common::StepStatus DelayedTrajectoryAntiSwing::step(const common::CraneStateEstimate& estimate,
                                                     TrajectoryCorrection& output) noexcept {
  output = TrajectoryCorrection{};
  if (!std::isfinite(estimate.trolley_position) || !std::isfinite(estimate.swing_in_plane) ||
      !std::isfinite(estimate.swing_in_plane_rate) || !std::isfinite(estimate.swing_out_of_plane) ||
      !std::isfinite(estimate.swing_out_of_plane_rate) || !std::isfinite(estimate.cable_length)) {
    return common::StepStatus::rejected_nonfinite;
  }
  const double cable_length =
      std::clamp(estimate.cable_length, params_.min_cable_length, params_.max_cable_length);
  const double period = swing_period(cable_length, params_.gravity);
  output.swing_period = period;

  const int size = static_cast<int>(history_.size());
  head_ = (head_ + 1) % size;
  history_[static_cast<std::size_t>(head_)] = {estimate.swing_in_plane, estimate.swing_in_plane_rate,
                                               estimate.swing_out_of_plane, estimate.swing_out_of_plane_rate};
  count_ = std::min(count_ + 1, size);

  // tau_del [periods] -> tau_del T / T_s samples, recomputed each cycle from the measured L.
  const int delay = std::min(static_cast<int>(std::lround(params_.normalized_delay * period / params_.sample_period)),
                             size - 1);
  output.delay_samples = delay;
  if (count_ <= delay) return common::StepStatus::not_ready;
  int index = head_ - delay;
  if (index < 0) index += size;
  const SwingSample& delayed = history_[static_cast<std::size_t>(index)];

  // (3.50): x_bar_ref correction K_del phi(tau - tau_del); x = L x_bar, d/dt = (1/T) d/dtau.
  const double gain = params_.delay_gain * cable_length;
  output.trolley_position_correction = gain * delayed.swing_in_plane;
  output.trolley_velocity_correction = gain * delayed.swing_in_plane_rate;
  if (params_.slew_enabled) {
    // Delta y_bar = K_del theta(tau - tau_del), y = -(x/L) gamma (3.34) -> Delta gamma = -(L/x) Delta y_bar.
    const double radius = std::max(estimate.trolley_position, params_.min_trolley_radius);
    output.slew_angle_correction = -gain / radius * delayed.swing_out_of_plane;
    output.slew_rate_correction = -gain / radius * delayed.swing_out_of_plane_rate;
  }
  return common::StepStatus::ok;
}

}  // namespace crane::anti_swing_analysis
