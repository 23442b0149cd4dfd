#include "crane/state_estimator/filter_design.hpp"

#include <cmath>
#include <numbers>

namespace crane::state_estimator {

DiscreteTransferFunction butterworth_low_pass(double cutoff_frequency, double sample_rate) noexcept {
  // Analog prototype H(s) = 1/(s^2 + sqrt2 s + 1) with s -> (1/K)(1-z^-1)/(1+z^-1),
  // K = tan(pi fc/fs) (pre-warped so the -3 dB point lands exactly on fc).
  const double k = std::tan(std::numbers::pi * cutoff_frequency / sample_rate);
  const double k2 = k * k;
  const double norm = 1.0 / (1.0 + std::numbers::sqrt2 * k + k2);
  DiscreteTransferFunction tf;
  tf.b0 = k2 * norm;
  tf.b1 = 2.0 * tf.b0;
  tf.b2 = tf.b0;
  tf.a1 = 2.0 * (k2 - 1.0) * norm;
  tf.a2 = (1.0 - std::numbers::sqrt2 * k + k2) * norm;
  return tf;
}

DiscreteTransferFunction differentiator_coefficients(DifferentiatorKind kind,
                                                     double sample_rate) noexcept {
  DiscreteTransferFunction tf;
  switch (kind) {
    case DifferentiatorKind::backward:  // (4.8)
      tf = {sample_rate, -sample_rate, 0.0, 0.0, 0.0};
      break;
    case DifferentiatorKind::al_alaoui_first_order: {  // (4.9)
      const double gain = 8.0 * sample_rate / 7.0;
      tf = {gain, -gain, 0.0, 1.0 / 7.0, 0.0};
      break;
    }
    case DifferentiatorKind::al_alaoui_second_order: {  // (4.10), corrected: see header
      const double r = 2.0 - std::sqrt(3.0);
      const double gain = 3.0 * r * sample_rate;
      tf = {gain, 0.0, -gain, 2.0 * r, r * r};
      break;
    }
  }
  return tf;
}

DiscreteTransferFunction differentiator_lag(const DiscreteTransferFunction& differentiator,
                                           double sample_rate) noexcept {
  // b0 + b1 z^-1 + b2 z^-2 = (1 - z^-1)(c0 + c1 z^-1) with c0 = b0, c1 = b0 + b1 (= -b2).
  const double c0 = differentiator.b0 / sample_rate;
  const double c1 = (differentiator.b0 + differentiator.b1) / sample_rate;
  return {c0, c1, 0.0, differentiator.a1, differentiator.a2};
}

}  // namespace crane::state_estimator
