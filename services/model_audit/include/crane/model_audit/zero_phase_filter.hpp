#pragma once
// Zero-phase low-pass prefilter for offline identification (section 3.1 of H. M. Omar, "Control of
// Gantry and Tower Cranes", 2003: "a Butterworth filter ... with zero-phase response", Oppenheim
// et al. 1989). The dissertation used order 5; this one runs the estimator's second-order
// Butterworth biquad (crane::state_estimator::butterworth_low_pass, bilinear transform with
// pre-warping) forward and then backward, so the phase is exactly zero and the magnitude is
// |H(f)|^2: 1 at DC, 1/2 (-6 dB) at the cutoff, falling 80 dB/decade above it.
//
// Edges: the signal is extended at both ends by an odd reflection about its end values
// (2 x_0 - x_i), as MATLAB/SciPy filtfilt do, by as many samples as the filter's start-up transient
// needs to decay to 1e-9 (about 20 / (sqrt2 pi fc/fs) samples: 900 at fc = 0.5 Hz, fs = 100 Hz; at
// most the signal length - 1), and each pass starts at rest on its first extended value; so a
// constant or a ramp passes unchanged. Offline only: allocates, not real-time (a zero-phase filter
// cannot run causally).

#include <span>
#include <string_view>
#include <vector>

namespace crane::model_audit {

/// Forward-backward second-order Butterworth low-pass of `signal` (uniformly sampled at
/// `sample_rate` [Hz] > 0) with cutoff `cutoff_frequency` [Hz] (the -3 dB point of one pass).
/// Returns a vector of the same length (empty for an empty signal).
/// Throws common::ConfigError naming `field` unless 0 < cutoff_frequency < sample_rate / 2 and the
/// sample rate is positive and finite.
[[nodiscard]] std::vector<double> zero_phase_low_pass(std::span<const double> signal, double cutoff_frequency,
                                                      double sample_rate, std::string_view field = "cutoff_hz");

}  // namespace crane::model_audit
