#pragma once
// State estimator: low-pass filtering and numerical differentiation of the crane measurements,
// section 4.3 of H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003.
//
// Each channel (trolley position x, slew angle gamma, swings phi and theta, cable length L) runs a
// second-order Butterworth low-pass (cutoff 0.05 fs by default) and then a differentiator (4.8),
// (4.9) or (4.10) on the filtered signal. The trolley and slew positions are also differentiated
// unfiltered (section 4.4.1 uses the unfiltered trolley velocity for friction compensation).
//
// Real-time: step() is noexcept, allocates nothing, takes no locks.

#include "crane/common/crane_signals.hpp"
#include "crane/state_estimator/discrete_filter.hpp"
#include "crane/state_estimator/filter_design.hpp"

namespace crane::state_estimator {

struct StateEstimatorParams {
  double sample_rate{100.0};       // [Hz] fs, the rate step() is called at (section 4.3)
  double cutoff_frequency{5.0};    // [Hz] Butterworth cutoff, 0.05 fs; must be in (0, fs/2)
  DifferentiatorKind differentiator{DifferentiatorKind::al_alaoui_second_order};  // (4.10)
};

/// [m] or [rad]: the largest measurement magnitude step() accepts. Found by tests/fuzz
/// (topic_gates): a trolley position of -1.5e307 m differentiated to a velocity of -Inf, returned ok.
inline constexpr double kMaxMeasurementMagnitude = 1e6;

class StateEstimator {
 public:
  /// Throws common::ConfigError naming the field, value and bound if sample_rate is not finite
  /// and > 0, cutoff_frequency not in (0, sample_rate/2), or differentiator not a listed kind.
  explicit StateEstimator(const StateEstimatorParams& params);

  /// One sample. The first accepted sample initializes every filter at rest on that sample
  /// (filtered outputs equal the measurement, rates 0: no start-up transient).
  /// Returns rejected_nonfinite (and leaves the internal state and `estimate` untouched) if any
  /// measurement field is NaN/Inf or beyond +-kMaxMeasurementMagnitude (no crane measures that;
  /// the differentiators would overflow such a value to Inf); ok otherwise (every field finite).
  [[nodiscard]] common::StepStatus step(const common::CraneMeasurement& measurement,
                                        common::CraneStateEstimate& estimate) noexcept;

  /// Forgets the history; the next sample re-initializes.
  void reset() noexcept { initialized_ = false; }

  [[nodiscard]] const StateEstimatorParams& params() const noexcept { return params_; }
  /// The low-pass filter's coefficients (same for every channel).
  [[nodiscard]] const DiscreteTransferFunction& low_pass_coefficients() const noexcept { return low_pass_; }
  /// The differentiator's coefficients; output in [input unit / s].
  [[nodiscard]] const DiscreteTransferFunction& differentiator_coefficients() const noexcept {
    return differentiator_;
  }

 private:
  struct Channel {
    DiscreteFilter low_pass;
    DiscreteFilter differentiator;
  };
  static constexpr int kChannelCount = 5;  // x, gamma, phi, theta, L

  StateEstimatorParams params_;
  DiscreteTransferFunction low_pass_;
  DiscreteTransferFunction differentiator_;
  Channel channels_[kChannelCount];
  DiscreteFilter raw_trolley_differentiator_;
  DiscreteFilter raw_slew_differentiator_;
  bool initialized_{false};
};

}  // namespace crane::state_estimator
