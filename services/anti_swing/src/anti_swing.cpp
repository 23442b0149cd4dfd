#include "crane/anti_swing/anti_swing.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::anti_swing {
namespace {

double swing_period(double cable_length, double gravity) {
  return 2.0 * std::numbers::pi * std::sqrt(cable_length / gravity);  // T
}

AntiSwingParams validated(const AntiSwingParams& params) {
  switch (params.kind) {
    case AntiSwingKind::none:
    case AntiSwingKind::pd:
    case AntiSwingKind::delayed_feedback:
      break;
    default:
      throw common::ConfigError("anti_swing.kind = " + std::to_string(static_cast<int>(params.kind)) +
                                " is not an AntiSwingKind");
  }
  common::require_finite("anti_swing.pd_proportional_gain", params.pd_proportional_gain);
  common::require_finite("anti_swing.pd_derivative_gain", params.pd_derivative_gain);
  common::require_finite("anti_swing.delay_gain", params.delay_gain);
  common::require_greater("anti_swing.normalized_delay", params.normalized_delay, 0.0);
  common::require_greater("anti_swing.sample_period", params.sample_period, 0.0);
  common::require_greater("anti_swing.gravity", params.gravity, 0.0);
  common::require_greater("anti_swing.min_cable_length", params.min_cable_length, 0.0);
  common::require_greater("anti_swing.max_cable_length", params.max_cable_length, params.min_cable_length);
  if (params.short_cable.enabled) {
    const auto& g = params.short_cable;
    common::require_greater("anti_swing.short_cable.short_length", g.short_length, 0.0);
    common::require_greater("anti_swing.short_cable.full_gain_length", g.full_gain_length, g.short_length);
    common::require_finite("anti_swing.short_cable.delay_gain", g.gain);
  }
  const double longest = params.normalized_delay *
                         swing_period(params.max_cable_length, params.gravity) / params.sample_period;
  if (!(longest < AntiSwing::kMaxDelaySamples)) {
    throw common::ConfigError(
        "anti_swing.normalized_delay = " + common::format_value(params.normalized_delay) +
        " gives a delay line of " + common::format_value(longest) +
        " samples at max_cable_length: must be < " + std::to_string(AntiSwing::kMaxDelaySamples));
  }
  return params;
}

// K_del at cable length `L` [m] (ShortCableGain).
double short_cable_delay_gain(const AntiSwingParams& params, double L) noexcept {
  const auto& g = params.short_cable;
  if (!g.enabled || L >= g.full_gain_length) return params.delay_gain;
  if (L <= g.short_length) return g.gain;
  const double s = (L - g.short_length) / (g.full_gain_length - g.short_length);
  return g.gain + s * (params.delay_gain - g.gain);
}

int capacity_for(const AntiSwingParams& params) {
  const double longest = params.normalized_delay *
                         swing_period(params.max_cable_length, params.gravity) / params.sample_period;
  return static_cast<int>(std::ceil(longest)) + 2;  // round() may reach ceil; plus the current sample
}

}  // namespace

AntiSwing::AntiSwing(const AntiSwingParams& params)
    : params_(validated(params)),
      in_plane_history_(static_cast<std::size_t>(capacity_for(params_)), 0.0),
      out_of_plane_history_(in_plane_history_.size(), 0.0) {}

void AntiSwing::reset() noexcept {
  head_ = 0;
  count_ = 0;
}

double AntiSwing::delayed(const std::vector<double>& history, int delay) const noexcept {
  const int size = static_cast<int>(history.size());
  int index = head_ - delay;
  if (index < 0) index += size;
  return history[static_cast<std::size_t>(index)];
}

common::StepStatus AntiSwing::step(const common::CraneStateEstimate& estimate,
                                   AntiSwingOutput& output) noexcept {
  const bool uses_rates = params_.kind == AntiSwingKind::pd;
  if (!std::isfinite(estimate.swing_in_plane) || !std::isfinite(estimate.swing_out_of_plane) ||
      !std::isfinite(estimate.cable_length) ||
      (uses_rates && (!std::isfinite(estimate.swing_in_plane_rate) ||
                      !std::isfinite(estimate.swing_out_of_plane_rate)))) {
    output = AntiSwingOutput{};
    return common::StepStatus::rejected_nonfinite;
  }
  const double cable_length =
      std::clamp(estimate.cable_length, params_.min_cable_length, params_.max_cable_length);
  const double period = swing_period(cable_length, params_.gravity);  // T [s]

  // Record the newest sample.
  const int size = static_cast<int>(in_plane_history_.size());
  head_ = (head_ + 1) % size;
  in_plane_history_[static_cast<std::size_t>(head_)] = estimate.swing_in_plane;
  out_of_plane_history_[static_cast<std::size_t>(head_)] = estimate.swing_out_of_plane;
  count_ = std::min(count_ + 1, size);

  output = AntiSwingOutput{};
  output.swing_period = period;
  switch (params_.kind) {
    case AntiSwingKind::none:
      break;
    case AntiSwingKind::pd: {
      // (3.45): V_xs = K_ps phi + K_ds phi', phi' = d phi/d tau = T phi_dot.
      const double k_ps = params_.pd_proportional_gain;
      const double k_ds = params_.pd_derivative_gain;
      output.trolley_action = k_ps * estimate.swing_in_plane + k_ds * period * estimate.swing_in_plane_rate;
      output.slew_action =
          k_ps * estimate.swing_out_of_plane + k_ds * period * estimate.swing_out_of_plane_rate;
      break;
    }
    case AntiSwingKind::delayed_feedback: {
      // (3.47): V_xs = K_del phi(tau - tau_del); tau_del [periods] -> tau_del T / T_s samples,
      // recomputed each cycle from the measured L.
      const double samples = params_.normalized_delay * period / params_.sample_period;
      const int delay = std::min(static_cast<int>(std::lround(samples)), size - 1);
      output.delay_samples = delay;
      if (count_ <= delay) return common::StepStatus::not_ready;
      const double k_del = short_cable_delay_gain(params_, cable_length);
      output.trolley_action = k_del * delayed(in_plane_history_, delay);
      output.slew_action = k_del * delayed(out_of_plane_history_, delay);
      break;
    }
  }
  if (!params_.slew_enabled) output.slew_action = 0.0;
  return common::StepStatus::ok;
}

}  // namespace crane::anti_swing
