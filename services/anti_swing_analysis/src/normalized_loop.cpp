#include "crane/anti_swing_analysis/normalized_loop.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace crane::anti_swing_analysis {

NormalizedReference transfer_reference(const TransferProfile& profile, double tau) noexcept {
  // Trapezoidal velocity: accelerate for t_a, coast, decelerate for t_a; v_max = Z/(t_f - t_a).
  const double t_f = profile.duration;
  const double t_a = profile.acceleration_fraction * t_f;
  const double v_max = profile.distance / (t_f - t_a);
  const double accel = v_max / t_a;
  NormalizedReference reference;
  if (tau <= 0.0) return reference;
  if (tau >= t_f) {
    reference.position = profile.distance;
    return reference;
  }
  if (tau < t_a) {
    reference.position = 0.5 * accel * tau * tau;
    reference.rate = accel * tau;
  } else if (tau < t_f - t_a) {
    reference.position = 0.5 * accel * t_a * t_a + v_max * (tau - t_a);
    reference.rate = v_max;
  } else {
    const double remaining = t_f - tau;
    reference.position = profile.distance - 0.5 * accel * remaining * remaining;
    reference.rate = accel * remaining;
  }
  return reference;
}

std::vector<NormalizedSample> simulate_delayed_feedback_loop(const NormalizedLoopRun& run) {
  if (!(run.time_step > 0.0) || !(run.duration > 0.0) || !(run.normalized_delay >= 0.0))
    throw std::invalid_argument("simulate_delayed_feedback_loop: time_step, duration > 0, delay >= 0");
  const double cutoff = run.loop.swing_filter_cutoff;
  if (!(cutoff >= 0.0) || !std::isfinite(cutoff))
    throw std::invalid_argument("simulate_delayed_feedback_loop: swing_filter_cutoff must be finite and >= 0");
  const auto steps = static_cast<std::size_t>(std::llround(run.duration / run.time_step));
  const auto delay = static_cast<std::size_t>(std::llround(run.normalized_delay / run.time_step));
  std::vector<double> swing_history(steps + 1, run.initial_swing);  // phi at step k
  std::vector<NormalizedSample> samples;
  samples.reserve(steps);
  double position = 0.0, rate = 0.0, swing = run.initial_swing, swing_rate = 0.0;
  // The estimator's low-pass on the measured swing (TrackingLoop::swing_filter_cutoff), at rest on
  // phi(0): p'' = w_c^2 (phi - p) - sqrt(2) w_c p'.
  double filtered = run.initial_swing, filtered_rate = 0.0;
  const double h = run.time_step;
  for (std::size_t k = 0; k < steps; ++k) {
    const double tau = static_cast<double>(k) * h;
    swing_history[k] = cutoff > 0.0 ? filtered : swing;
    const double delayed_swing = k >= delay ? swing_history[k - delay] : run.initial_swing;
    const double action = run.delay_gain * delayed_swing;  // (3.47)
    samples.push_back({tau, swing, swing_rate, action});
    const NormalizedReference reference = transfer_reference(run.transfer, tau);
    // (3.27) with (3.40): x_bar'' = K_px e + K_dx e' + V_xs; (3.28), our sign: phi'' = x_bar'' - a phi
    const double acceleration = run.loop.proportional_gain * (reference.position - position) +
                                run.loop.derivative_gain * (reference.rate - rate) + action;
    const double swing_acceleration = acceleration - run.loop.swing_stiffness * swing;
    if (cutoff > 0.0) {
      filtered_rate += h * (cutoff * cutoff * (swing - filtered) - std::sqrt(2.0) * cutoff * filtered_rate);
      filtered += h * filtered_rate;
    }
    rate += h * acceleration;
    swing_rate += h * swing_acceleration;
    position += h * rate;
    swing += h * swing_rate;
  }
  return samples;
}

}  // namespace crane::anti_swing_analysis
