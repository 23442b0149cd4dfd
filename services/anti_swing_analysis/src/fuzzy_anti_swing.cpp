#include "crane/anti_swing_analysis/fuzzy_anti_swing.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::anti_swing_analysis {
namespace {

constexpr double kSetSpacing = 1.0 / 3.0;  // a = 1/3, b = 2/3 (figure 3.20)

FuzzyAntiSwingParams validated(const FuzzyAntiSwingParams& params) {
  for (int i = 0; i < kFuzzySetCount; ++i) {
    for (int j = 0; j < kFuzzySetCount; ++j) {
      const auto value = static_cast<int>(params.rules[static_cast<std::size_t>(i)][static_cast<std::size_t>(j)]);
      if (value < 0 || value >= kFuzzySetCount) {
        throw common::ConfigError("fuzzy_anti_swing.rules[" + std::to_string(i) + "][" + std::to_string(j) +
                                  "] = " + std::to_string(value) + " is not a FuzzySet (0..6)");
      }
    }
  }
  common::require_greater("fuzzy_anti_swing.max_swing_angle", params.max_swing_angle, 0.0);
  common::require_greater("fuzzy_anti_swing.max_normalized_swing_rate", params.max_normalized_swing_rate, 0.0);
  common::require_finite("fuzzy_anti_swing.output_scale", params.output_scale);
  if (params.output_scale == 0.0)
    throw common::ConfigError("fuzzy_anti_swing.output_scale = 0 is out of range: must be != 0");
  common::require_greater("fuzzy_anti_swing.gravity", params.gravity, 0.0);
  common::require_greater("fuzzy_anti_swing.min_cable_length", params.min_cable_length, 0.0);
  common::require_greater("fuzzy_anti_swing.max_cable_length", params.max_cable_length,
                          params.min_cable_length);
  return params;
}

}  // namespace

std::string_view fuzzy_set_name(FuzzySet set) noexcept {
  static constexpr std::array<std::string_view, kFuzzySetCount> kNames{"NB", "NM", "NS", "ZO",
                                                                       "PS", "PM", "PB"};
  const auto index = static_cast<std::size_t>(set);
  return index < kNames.size() ? kNames[index] : std::string_view{"??"};
}

double fuzzy_set_center(FuzzySet set) noexcept {
  return (static_cast<double>(static_cast<int>(set)) - 3.0) * kSetSpacing;
}

std::array<double, kFuzzySetCount> fuzzy_membership(double x) noexcept {
  std::array<double, kFuzzySetCount> degrees{};
  if (std::isnan(x)) return degrees;
  const double clamped = std::clamp(x, -1.0, 1.0);
  for (int k = 0; k < kFuzzySetCount; ++k) {
    const double center = (k - 3) * kSetSpacing;
    degrees[static_cast<std::size_t>(k)] = std::max(0.0, 1.0 - std::abs(clamped - center) / kSetSpacing);
  }
  return degrees;
}

FuzzyRuleTable dissertation_rule_table() noexcept {
  using enum FuzzySet;
  // Table 3.7: rows phi NB..PB, columns phi_dot NB..PB.
  return {{{ns, nb, nb, nb, nb, nb, nb},
           {pb, ps, ns, nm, nm, nb, nb},
           {pb, zo, zo, ns, nm, nb, nb},
           {pb, pm, ps, zo, ns, nm, nb},
           {pb, pb, pm, ps, zo, zo, nb},
           {pb, pb, pm, pm, ps, ns, nb},
           {pb, pb, pb, pb, pm, pb, ps}}};
}

double fuzzy_inference(const FuzzyRuleTable& rules, double x1, double x2) noexcept {
  const auto swing_degrees = fuzzy_membership(x1);
  const auto rate_degrees = fuzzy_membership(x2);
  double weighted = 0.0;
  double total = 0.0;
  for (std::size_t i = 0; i < swing_degrees.size(); ++i) {
    if (swing_degrees[i] == 0.0) continue;
    for (std::size_t j = 0; j < rate_degrees.size(); ++j) {
      const double strength = swing_degrees[i] * rate_degrees[j];  // product inference
      weighted += strength * fuzzy_set_center(rules[i][j]);
      total += strength;
    }
  }
  return total > 0.0 ? weighted / total : 0.0;  // weighted average of centres
}

FuzzyAntiSwing::FuzzyAntiSwing(const FuzzyAntiSwingParams& params) : params_(validated(params)) {}

common::StepStatus FuzzyAntiSwing::step(const common::CraneStateEstimate& estimate,
                                        anti_swing::AntiSwingOutput& output) noexcept {
  output = anti_swing::AntiSwingOutput{};
  if (!std::isfinite(estimate.swing_in_plane) || !std::isfinite(estimate.swing_in_plane_rate) ||
      !std::isfinite(estimate.swing_out_of_plane) || !std::isfinite(estimate.swing_out_of_plane_rate) ||
      !std::isfinite(estimate.cable_length)) {
    return common::StepStatus::rejected_nonfinite;
  }
  const double cable_length =
      std::clamp(estimate.cable_length, params_.min_cable_length, params_.max_cable_length);
  const double period = 2.0 * std::numbers::pi * std::sqrt(cable_length / params_.gravity);  // T
  output.swing_period = period;
  // (3.51): x1 = K_phi phi, x2 = K_phidot phi', V = K_v y.
  const double k_phi = 1.0 / params_.max_swing_angle;
  const double k_phidot = 1.0 / params_.max_normalized_swing_rate;
  const double k_v = params_.output_scale;
  output.trolley_action =
      k_v * fuzzy_inference(params_.rules, k_phi * estimate.swing_in_plane,
                            k_phidot * period * estimate.swing_in_plane_rate);
  if (params_.slew_enabled) {
    output.slew_action =
        k_v * fuzzy_inference(params_.rules, k_phi * estimate.swing_out_of_plane,
                              k_phidot * period * estimate.swing_out_of_plane_rate);
  }
  return common::StepStatus::ok;
}

}  // namespace crane::anti_swing_analysis
