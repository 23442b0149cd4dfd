#include "crane/model_audit/zero_phase_filter.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/state_estimator/discrete_filter.hpp"
#include "crane/state_estimator/filter_design.hpp"

namespace crane::model_audit {

namespace {

// Runs the biquad over `data` in place, starting at rest on data.front() (DC gain 1, so rest means
// past inputs and outputs equal to that value).
void run_in_place(std::vector<double>& data, const state_estimator::DiscreteTransferFunction& tf) {
  state_estimator::DiscreteFilter filter(tf);
  filter.initialize(data.front(), data.front() * tf.dc_gain());
  for (double& value : data) value = filter.update(value);
}

}  // namespace

std::vector<double> zero_phase_low_pass(std::span<const double> signal, double cutoff_frequency, double sample_rate,
                                        std::string_view field) {
  const std::string name(field);
  common::require_greater(name + " (sample rate)", sample_rate, 0.0);
  common::require_greater(name, cutoff_frequency, 0.0);
  if (!(cutoff_frequency < 0.5 * sample_rate)) {
    throw common::ConfigError(name + " = " + common::format_value(cutoff_frequency) +
                              " is out of range: must be < half the sample rate " +
                              common::format_value(0.5 * sample_rate));
  }
  if (signal.empty()) return {};
  const std::size_t n = signal.size();
  if (n == 1) return {signal.front()};

  const auto tf = state_estimator::butterworth_low_pass(cutoff_frequency, sample_rate);
  // Padding: long enough for a start-up transient to decay to 1e-9 inside it. The poles are a
  // complex pair of radius sqrt(a2) (a2 = (1 - sqrt2 K + K^2)/(1 + sqrt2 K + K^2) in (0, 1)), so
  // that takes ln(1e-9) / ln(sqrt a2) samples. At least 9 (3 x filter length, as filtfilt), never
  // more than the signal offers for reflection.
  const double decay_per_sample = 0.5 * std::log(tf.a2);  // ln |pole| < 0
  const double wanted = std::ceil(std::log(1e-9) / decay_per_sample);
  const std::size_t pad =
      std::min(n - 1, std::max<std::size_t>(9, wanted < 1e7 ? static_cast<std::size_t>(wanted) : 10000000));

  std::vector<double> extended;
  extended.reserve(n + 2 * pad);
  for (std::size_t i = pad; i >= 1; --i) extended.push_back(2.0 * signal.front() - signal[i]);
  extended.insert(extended.end(), signal.begin(), signal.end());
  for (std::size_t i = 1; i <= pad; ++i) extended.push_back(2.0 * signal.back() - signal[n - 1 - i]);

  run_in_place(extended, tf);
  std::reverse(extended.begin(), extended.end());
  run_in_place(extended, tf);
  std::reverse(extended.begin(), extended.end());
  return {extended.begin() + static_cast<std::ptrdiff_t>(pad),
          extended.begin() + static_cast<std::ptrdiff_t>(pad + n)};
}

}  // namespace crane::model_audit
