#pragma once
// Sensitivity of the anti-swing laws to the state estimator's filter delay: the question section
// 5.1 of H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003, leaves open ("The
// swing angle is first filtered and then used in implementing the control algorithms. The
// filtering process is associated with time delay. A sensitivity analysis is needed to investigate
// the effect of the filter delay on the performance of the anti-swing delayed-feedback controller").
//
// The law sees the swing through the estimator's second-order Butterworth low-pass (section 4.3),
// modelled by its continuous prototype F(s) = w_c^2/(s^2 + sqrt(2) w_c s + w_c^2) in the normalized
// loop of characteristic_equation.hpp (TrackingLoop::swing_filter_cutoff). In normalized time the
// loop without the filter does not depend on the cable length; with it, only through the
// normalized cut-off w_c T = 2 pi f_c 2 pi sqrt(L/g): a short cable has a fast swing, which the
// same filter delays by a larger fraction of a period. The map is the damping ratio of the dominant
// closed-loop pair over (f_c [Hz], L [m]).
//
// Allocates; offline use only.

#include <vector>

#include "crane/anti_swing_analysis/characteristic_equation.hpp"

namespace crane::anti_swing_analysis {

/// The map's grid and the law it analyses.
struct FilterDelaySpec {
  LawPoint law{};                     // the law and its two parameters (characteristic_equation.hpp)
  TrackingLoop loop{};                // the tracking loop; its swing_filter_cutoff is ignored (the map sets it)
  double gravity{9.8};                // [m/s^2] g, > 0
  std::vector<double> cutoffs{};      // [Hz] f_c, each > 0 and finite
  std::vector<double> cable_lengths{};  // [m] L, each > 0 and finite
  int pade_order{20};                 // l in (3.49), >= 1
};

/// One point of the map.
struct FilterDelayPoint {
  double cutoff{0.0};             // [Hz] f_c
  double cable_length{0.0};       // [m] L
  double normalized_cutoff{0.0};  // [-] w_c T
  double damping{0.0};            // [-] dominant pair, Pade (3.49); NaN: no complex pair
  double direct_damping{0.0};     // [-] the same pair by Newton on the exact equation
  bool stable{false};
  double added_delay{0.0};        // [s] the filter's phase delay at the swing frequency 2 pi/T: -arg F(j w)/w
  double added_delay_periods{0.0};  // [swing periods] the same, over T
};

struct FilterDelayMap {
  FilterDelaySpec spec;
  double unfiltered_damping{0.0};      // [-] the law without the filter (independent of L)
  std::vector<FilterDelayPoint> points;  // row-major [i_cable * cutoffs.size() + i_cutoff]
};

/// Swing period T = 2 pi sqrt(L/g) [s]. No checks (callers validate).
[[nodiscard]] double swing_period(double cable_length, double gravity) noexcept;

/// Phase delay [s] of the continuous Butterworth prototype with cut-off `cutoff` [Hz] at
/// `frequency` [Hz]: -arg F(j 2 pi f)/(2 pi f), in (0, 2/(2 pi f_c) ...]; sqrt(2)/(2 pi f_c) as f -> 0.
[[nodiscard]] double butterworth_phase_delay(double cutoff, double frequency) noexcept;

/// Computes the map. Throws std::invalid_argument naming the field and value for: an empty or
/// non-positive/non-finite cutoff or cable length, gravity <= 0, pade_order < 1, a negative tau_del.
[[nodiscard]] FilterDelayMap compute_filter_delay_map(const FilterDelaySpec& spec);

}  // namespace crane::anti_swing_analysis
