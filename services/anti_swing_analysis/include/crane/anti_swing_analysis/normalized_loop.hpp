#pragma once
// Simulation of the normalized linear anti-swing tracking loop (3.27)-(3.28) in this project's
// convention (phi'' + a phi = +x_bar''), with the tracking PD (3.40) and the delayed-feedback
// anti-swing law (3.47). Used to generate the fuzzy rules (section 3.3.2, "we map the performance
// of the first delay controller"). Time is normalized by the swing period T, positions by L.
// Allocates (returns the sampled history); offline use only.

#include <vector>

#include "crane/anti_swing_analysis/characteristic_equation.hpp"

namespace crane::anti_swing_analysis {

/// Rest-to-rest transfer with a trapezoidal velocity (the bang-coast-bang acceleration of
/// figure 3.15), reaching distance/|distance| * v_max after acceleration_fraction * duration.
struct TransferProfile {
  double distance{0.0};               // [-] Z/L, may be negative
  double duration{1.0};               // [swing periods] t_f/T (section 3.3.3 uses t_f = T)
  double acceleration_fraction{0.25}; // [-] Delta t / t_f, in (0, 0.5]
};

/// Reference position [-] (units of L) and rate [-] (d/dtau) at normalized time tau.
struct NormalizedReference {
  double position{0.0};
  double rate{0.0};
};
[[nodiscard]] NormalizedReference transfer_reference(const TransferProfile& profile, double tau) noexcept;

struct NormalizedLoopRun {
  TrackingLoop loop{};
  double delay_gain{-90.0};         // [-] K_del (3.47), our sign convention
  double normalized_delay{0.1};     // [swing periods] tau_del
  double initial_swing{0.0};        // [rad] phi(0), also the history phi(tau < 0)
  TransferProfile transfer{};       // starts at tau = 0 from x_bar = 0
  double duration{4.0};             // [swing periods] simulated time
  double time_step{1e-3};           // [swing periods] semi-implicit Euler step
};

/// One sample: the anti-swing controller's inputs and output at tau.
struct NormalizedSample {
  double time{0.0};        // [swing periods] tau
  double swing{0.0};       // [rad] phi
  double swing_rate{0.0};  // [rad/period] phi' = d phi/d tau
  double action{0.0};      // [-] V_xs = K_del phi(tau - tau_del)
};

/// Simulates the loop and returns one sample per time step. With loop.swing_filter_cutoff > 0 the
/// law's delay line takes the filtered swing (the estimator's low-pass, at rest on phi(0)); the
/// samples' `swing` stays the true phi. Throws std::invalid_argument for a non-positive time step
/// or duration, a negative delay, or a negative or non-finite swing_filter_cutoff.
[[nodiscard]] std::vector<NormalizedSample> simulate_delayed_feedback_loop(const NormalizedLoopRun& run);

}  // namespace crane::anti_swing_analysis
