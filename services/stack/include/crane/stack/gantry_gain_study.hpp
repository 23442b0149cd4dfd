#pragma once
// Section 3.2.2 of H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003, on the
// gantry crane: the gain-scheduling gains over the cable length and the load (Figures 3.5, 3.6),
// and the effect of adapting them (Figures 3.7, 3.8) as measured rows of closed-loop runs.
//
// Closed loop, in process: the gantry plant (plant::CraneSimulator, kind gantry: (2.5)-(2.6) with a
// frictionless trolley, the 13-bit DAC, sampled at 100 Hz) under gain_scheduling::
// GainSchedulingController ((3.19) partial or (3.26) full state feedback, gains from the pole placement
// (3.20)-(3.25) of gain_schedule.hpp). The controller sees the true state (the dissertation's
// simulations feed back the full state); "unadapted" gains are those the controller computes when it
// is told the design cable length and load instead of the true ones (the same law, one place).
// Values of section 3.2.2: K_mx = 1.34, L = 1 m, m_t from 0 to 5 (the trolley drive mass is 10 kg:
// only m_t = m/M enters (2.7)-(2.8)).
//
// Time is scaled by the swing period T = 2 pi sqrt(L/g) of the true cable length, as in the figures.
// Errors: functions throw common::ConfigError (naming the field, value and bound) for invalid cases,
// std::runtime_error naming the cycle if the plant or the controller rejects a step.

#include <string>
#include <vector>

#include "crane/gain_scheduling/gain_scheduling_controller.hpp"

namespace crane::stack {

/// The gantry crane of section 3.2.2.
inline constexpr double kGantryStudyDriveGain = 1.34;  // [m/s^2/V] K_mx
inline constexpr double kGantryStudyDriveMass = 10.0;  // [kg] M (only m_t = m/M matters)

/// One gain row of Figure 3.5 (over L at m_t = 0) or 3.6 (over m_t at L = 1 m), partial feedback.
struct GantryGainRow {
  double cable_length{1.0};  // [m]
  double mass_ratio{0.0};    // [-] m_t
  gain_scheduling::GainSchedulingGains gains;
};

/// Figure 3.5: partial-feedback gains for each of `cable_lengths` [m] (> 0) at m_t = 0.
[[nodiscard]] std::vector<GantryGainRow> gains_over_cable_length(const std::vector<double>& cable_lengths);
/// Figure 3.6: partial-feedback gains for each of `mass_ratios` [-] (>= 0) at L = 1 m.
[[nodiscard]] std::vector<GantryGainRow> gains_over_mass_ratio(const std::vector<double>& mass_ratios);

/// One closed-loop step of the trolley from rest at x = 0 to `step_distance`.
struct GantryStepCase {
  std::string label;
  gain_scheduling::FeedbackKind kind{gain_scheduling::FeedbackKind::partial};
  double forward_gain{3.0};          // [V/m] K of the full law (3.26), > 0; unused for partial
  double cable_length{1.0};          // [m] true L, in [0.2, 10]
  double mass_ratio{0.0};            // [-] true m_t, in [0, 10]
  double design_cable_length{1.0};   // [m] the L the gains are computed for, in [0.2, 10]
  double design_mass_ratio{0.0};     // [-] the m_t the gains are computed for, in [0, 10]
  double step_distance{1.0};         // [m] in (0, 10]
  double duration_periods{8.0};      // [periods of the true L] simulated, in [2, 50]
};

struct GantryStepResult {
  GantryStepCase step;
  double swing_period{0.0};       // [s] 2 pi sqrt(L/g) of the true L
  double overshoot{0.0};          // [-] max(0, max x - target) / step_distance
  double settle_periods{0.0};     // [periods] until |x - target| < 5 mm and |phi| < 0.5 deg for good; NaN if never
  double max_swing{0.0};          // [rad] max |phi|
  double residual_swing{0.0};     // [rad] max |phi| over the last period
  double final_error{0.0};        // [m] |x - target| at the end
  double max_voltage{0.0};        // [V] max |applied voltage|
  gain_scheduling::GainSchedulingGains gains;  // the gains the controller used (design point)
};

/// Runs one case (deterministic, allocates its record). Throws common::ConfigError for a field out
/// of its range, std::runtime_error naming the cycle if a step fails.
[[nodiscard]] GantryStepResult run_gantry_step(const GantryStepCase& step);

/// The cases of Figure 3.7 (partial feedback, L = 1 m, m_t = 5: adapted vs gains for m_t = 0) and
/// Figure 3.8 (full feedback with `full_forward_gain`: L = 1 m adapted, L = 5 m with the gains for
/// L = 1 m, L = 5 m adapted; plus L = 1 m with the gains for L = 5 m, which the text says does not
/// overshoot). m_t = 0 in Figure 3.8.
[[nodiscard]] std::vector<GantryStepCase> section_322_cases(double full_forward_gain = 3.0);

/// Formats results as the table crane_sim gantry-gains prints.
[[nodiscard]] std::string format_step_table(const std::vector<GantryStepResult>& results);
[[nodiscard]] std::string format_gain_table(const std::vector<GantryGainRow>& rows, const char* title);

}  // namespace crane::stack
