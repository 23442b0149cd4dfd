#include "crane/state_estimator/discrete_filter.hpp"

#include <numbers>

namespace crane::state_estimator {

std::complex<double> DiscreteTransferFunction::frequency_response(double frequency,
                                                                  double sample_rate) const noexcept {
  const double omega_t = 2.0 * std::numbers::pi * frequency / sample_rate;
  const std::complex<double> z_inv = std::polar(1.0, -omega_t);
  const std::complex<double> numerator = b0 + z_inv * (b1 + z_inv * b2);
  const std::complex<double> denominator = 1.0 + z_inv * (a1 + z_inv * a2);
  return numerator / denominator;
}

void DiscreteFilter::initialize(double input, double output) noexcept {
  input_1_ = input;
  input_2_ = input;
  output_1_ = output;
  output_2_ = output;
}

double DiscreteFilter::update(double input) noexcept {
  const auto& c = coefficients_;
  const double output =
      c.b0 * input + c.b1 * input_1_ + c.b2 * input_2_ - c.a1 * output_1_ - c.a2 * output_2_;
  input_2_ = input_1_;
  input_1_ = input;
  output_2_ = output_1_;
  output_1_ = output;
  return output;
}

}  // namespace crane::state_estimator
