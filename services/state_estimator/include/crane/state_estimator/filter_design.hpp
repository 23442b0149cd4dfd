#pragma once
// Coefficient design for the estimator's low-pass filter and differentiators (section 4.3).

#include "crane/state_estimator/discrete_filter.hpp"

namespace crane::state_estimator {

/// The numerical differentiators compared in section 4.3 (figure 4.5).
enum class DifferentiatorKind {
  backward,                 // (4.8)  y(k) = fs [x(k) - x(k-1)]
  al_alaoui_first_order,    // (4.9)  y(k) = -y(k-1)/7 + (8 fs/7) [x(k) - x(k-1)]
  al_alaoui_second_order,   // (4.10) Simpson-based, see differentiator_coefficients()
};

/// Second-order Butterworth low-pass by the bilinear transform with frequency pre-warping, so the
/// gain is exactly -3 dB (1/sqrt 2) at `cutoff_frequency` and exactly 1 at DC.
/// Preconditions (asserted by callers' parameter validation): 0 < cutoff_frequency < sample_rate/2,
/// both in [Hz].
[[nodiscard]] DiscreteTransferFunction butterworth_low_pass(double cutoff_frequency,
                                                            double sample_rate) noexcept;

/// Differentiator coefficients; output unit is [input unit / s]. `sample_rate` [Hz] > 0.
///
/// (4.10) as printed, y(k) = -0.5358 y(k-1) - 0.0718 y(k-2) + (3 fs/3.7321)[x(k) - x(k-1)], has a
/// ramp gain of 1/2: Al-Alaoui (1994) inverts the Simpson integrator (T/3)(1+4z^-1+z^-2)/(1-z^-2)
/// and reflects its unstable pole -(2+sqrt 3) to -(2-sqrt 3), giving
///   H(z) = 3 r fs (1 - z^-2) / (1 + r z^-1)^2,  r = 2 - sqrt 3 = 1/3.7321,
/// i.e. x(k) - x(k-2) in the bracket, a1 = 2r = 0.5359, a2 = r^2 = 0.0718. We use the exact r, for
/// which the ramp gain is exactly 1 (3r*2/(1+r)^2 = 6r/(6r)).
[[nodiscard]] DiscreteTransferFunction differentiator_coefficients(DifferentiatorKind kind,
                                                                   double sample_rate) noexcept;

/// The lag a differentiator adds to the rate it measures: G(z) = D(z) / (fs (1 - z^-1)), D its
/// coefficients (`differentiator`, a differentiator_coefficients() result: b0 + b1 + b2 = 0, a zero at
/// DC) and fs (1 - z^-1) the backward difference (4.8), the rate over the last sample period. So
/// D(z) x = G(z) [fs (x(k) - x(k-1))]: G is 1 for (4.8), (8/7) / (1 + z^-1/7) for (4.9) and
/// 3 r (1 + z^-1) / (1 + r z^-1)^2 for (4.10); its DC gain is 1 (each differentiator's ramp gain).
/// Dimensionless. A filter that must lag as the estimator's rates do runs it after the low-pass
/// (tracking::FrictionMomentumBalance). `sample_rate` [Hz] > 0.
[[nodiscard]] DiscreteTransferFunction differentiator_lag(const DiscreteTransferFunction& differentiator,
                                                          double sample_rate) noexcept;

}  // namespace crane::state_estimator
