#include "crane/state_estimator/state_estimator.hpp"

#include <cmath>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::state_estimator {
namespace {

StateEstimatorParams validated(const StateEstimatorParams& params) {
  common::require_greater("state_estimator.sample_rate", params.sample_rate, 0.0);
  common::require_greater("state_estimator.cutoff_frequency", params.cutoff_frequency, 0.0);
  const double nyquist = 0.5 * params.sample_rate;
  if (!(params.cutoff_frequency < nyquist)) {
    throw common::ConfigError("state_estimator.cutoff_frequency = " +
                              common::format_value(params.cutoff_frequency) +
                              " is out of range: must be < sample_rate/2 = " +
                              common::format_value(nyquist));
  }
  switch (params.differentiator) {
    case DifferentiatorKind::backward:
    case DifferentiatorKind::al_alaoui_first_order:
    case DifferentiatorKind::al_alaoui_second_order:
      break;
    default:
      throw common::ConfigError("state_estimator.differentiator = " +
                                std::to_string(static_cast<int>(params.differentiator)) +
                                " is not a DifferentiatorKind");
  }
  return params;
}

}  // namespace

StateEstimator::StateEstimator(const StateEstimatorParams& params)
    : params_(validated(params)),
      low_pass_(butterworth_low_pass(params_.cutoff_frequency, params_.sample_rate)),
      differentiator_(state_estimator::differentiator_coefficients(params_.differentiator,
                                                                  params_.sample_rate)) {
  for (auto& channel : channels_) {
    channel.low_pass = DiscreteFilter(low_pass_);
    channel.differentiator = DiscreteFilter(differentiator_);
  }
  raw_trolley_differentiator_ = DiscreteFilter(differentiator_);
  raw_slew_differentiator_ = DiscreteFilter(differentiator_);
}

common::StepStatus StateEstimator::step(const common::CraneMeasurement& measurement,
                                        common::CraneStateEstimate& estimate) noexcept {
  const double inputs[kChannelCount] = {measurement.trolley_position, measurement.slew_angle,
                                        measurement.swing_in_plane, measurement.swing_out_of_plane,
                                        measurement.cable_length};
  for (const double value : inputs) {
    if (!std::isfinite(value) || std::abs(value) > kMaxMeasurementMagnitude) {
      return common::StepStatus::rejected_nonfinite;
    }
  }
  if (!initialized_) {
    for (int i = 0; i < kChannelCount; ++i) {
      channels_[i].low_pass.initialize(inputs[i], inputs[i]);  // DC gain 1: at rest on x0
      channels_[i].differentiator.initialize(inputs[i], 0.0);
    }
    raw_trolley_differentiator_.initialize(inputs[0], 0.0);
    raw_slew_differentiator_.initialize(inputs[1], 0.0);
    initialized_ = true;
  }
  double positions[kChannelCount];
  double rates[kChannelCount];
  for (int i = 0; i < kChannelCount; ++i) {
    positions[i] = channels_[i].low_pass.update(inputs[i]);
    rates[i] = channels_[i].differentiator.update(positions[i]);
  }
  estimate.trolley_position = positions[0];
  estimate.trolley_velocity = rates[0];
  estimate.slew_angle = positions[1];
  estimate.slew_rate = rates[1];
  estimate.swing_in_plane = positions[2];
  estimate.swing_in_plane_rate = rates[2];
  estimate.swing_out_of_plane = positions[3];
  estimate.swing_out_of_plane_rate = rates[3];
  estimate.cable_length = positions[4];
  estimate.cable_length_rate = rates[4];
  estimate.trolley_velocity_raw = raw_trolley_differentiator_.update(inputs[0]);
  estimate.slew_rate_raw = raw_slew_differentiator_.update(inputs[1]);
  return common::StepStatus::ok;
}

}  // namespace crane::state_estimator
