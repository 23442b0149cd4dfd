#include "crane/anti_swing_analysis/fuzzy_rule_generation.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace crane::anti_swing_analysis {

bool GeneratedRules::fully_populated() const noexcept {
  for (const auto& row : degree)
    for (double value : row)
      if (!(value > 0.0)) return false;
  return true;
}

GeneratedRules generate_fuzzy_rules(const RuleGenerationSpec& spec) {
  if (!(spec.max_swing_angle > 0.0) || !(spec.max_normalized_swing_rate > 0.0) || spec.output_scale == 0.0 ||
      !std::isfinite(spec.output_scale))
    throw std::invalid_argument("generate_fuzzy_rules: scaling factors must be positive/nonzero");
  constexpr double kDeg = std::numbers::pi / 180.0;
  std::vector<double> swings = spec.initial_swings;
  if (swings.empty()) swings = {0.0, 5 * kDeg, -5 * kDeg, 10 * kDeg, -10 * kDeg, 15 * kDeg, -15 * kDeg,
                                20 * kDeg, -20 * kDeg};
  std::vector<double> distances = spec.transfer_distances;
  if (distances.empty()) distances = {0.0, 0.75, -0.75};

  GeneratedRules generated;
  for (auto& row : generated.rules) row.fill(FuzzySet::zo);
  for (double swing : swings) {
    for (double distance : distances) {
      NormalizedLoopRun run;
      run.loop = spec.loop;
      run.delay_gain = spec.delay_gain;
      run.normalized_delay = spec.normalized_delay;
      run.initial_swing = swing;
      run.transfer.distance = distance;
      run.duration = spec.run_duration;
      run.time_step = spec.time_step;
      ++generated.runs;
      for (const NormalizedSample& sample : simulate_delayed_feedback_loop(run)) {
        ++generated.samples;
        const auto mu_swing = fuzzy_membership(sample.swing / spec.max_swing_angle);
        const auto mu_rate = fuzzy_membership(sample.swing_rate / spec.max_normalized_swing_rate);
        const auto mu_output = fuzzy_membership(sample.action / spec.output_scale);
        const auto best_output = static_cast<std::size_t>(
            std::max_element(mu_output.begin(), mu_output.end()) - mu_output.begin());
        for (std::size_t i = 0; i < mu_swing.size(); ++i) {
          if (mu_swing[i] == 0.0) continue;
          for (std::size_t j = 0; j < mu_rate.size(); ++j) {
            if (mu_rate[j] == 0.0) continue;
            const double degree = mu_swing[i] * mu_rate[j] * mu_output[best_output];  // (3.52)
            ++generated.candidate_rules;
            if (degree > generated.degree[i][j]) {  // conflict: keep the maximum degree
              generated.degree[i][j] = degree;
              generated.rules[i][j] = static_cast<FuzzySet>(best_output);
            }
          }
        }
      }
    }
  }
  return generated;
}

int count_agreements(const FuzzyRuleTable& lhs, const FuzzyRuleTable& rhs) noexcept {
  int agreements = 0;
  for (std::size_t i = 0; i < lhs.size(); ++i)
    for (std::size_t j = 0; j < lhs[i].size(); ++j)
      if (lhs[i][j] == rhs[i][j]) ++agreements;
  return agreements;
}

}  // namespace crane::anti_swing_analysis
