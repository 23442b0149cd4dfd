#pragma once
// Second-order discrete transfer function (direct form I) used for every filter and differentiator
// of the state estimator (section 4.3 of H. M. Omar, "Control of Gantry and Tower Cranes", 2003).
//
//   H(z) = (b0 + b1 z^-1 + b2 z^-2) / (1 + a1 z^-1 + a2 z^-2)
//   y(k) = b0 x(k) + b1 x(k-1) + b2 x(k-2) - a1 y(k-1) - a2 y(k-2)
//
// Coefficients are exposed so frequency responses can be plotted from the exact difference
// equation that runs in the loop. No allocation, no exceptions.

#include <complex>

namespace crane::state_estimator {

/// Coefficients of a biquad with a0 normalized to 1. Units: y has the unit of x times the unit of
/// the numerator gain (e.g. [1/s] for a differentiator).
struct DiscreteTransferFunction {
  double b0{1.0};
  double b1{0.0};
  double b2{0.0};
  double a1{0.0};
  double a2{0.0};

  /// H(e^{j omega T}) at `frequency` [Hz] for sample rate `sample_rate` [Hz].
  [[nodiscard]] std::complex<double> frequency_response(double frequency, double sample_rate) const noexcept;
  /// H(1): the gain to a constant input.
  [[nodiscard]] double dc_gain() const noexcept { return (b0 + b1 + b2) / (1.0 + a1 + a2); }
};

/// State of one biquad running a DiscreteTransferFunction.
class DiscreteFilter {
 public:
  DiscreteFilter() = default;
  explicit DiscreteFilter(const DiscreteTransferFunction& coefficients) noexcept : coefficients_(coefficients) {}

  /// Sets the past inputs to `input` and the past outputs to `output`, i.e. the filter is at rest
  /// with a constant input (no start-up transient). Precondition: finite values.
  void initialize(double input, double output) noexcept;
  /// One sample of the difference equation; returns y(k).
  double update(double input) noexcept;
  [[nodiscard]] const DiscreteTransferFunction& coefficients() const noexcept { return coefficients_; }

 private:
  DiscreteTransferFunction coefficients_{};
  double input_1_{0.0};
  double input_2_{0.0};
  double output_1_{0.0};
  double output_2_{0.0};
};

}  // namespace crane::state_estimator
