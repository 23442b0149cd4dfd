#include "crane/anti_swing_analysis/filter_delay_sensitivity.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace crane::anti_swing_analysis {
namespace {

void require_positive(const char* field, double value) {
  if (!(value > 0.0) || !std::isfinite(value))
    throw std::invalid_argument(std::string(field) + " = " + std::to_string(value) + " must be finite and > 0");
}

}  // namespace

double swing_period(double cable_length, double gravity) noexcept {
  return 2.0 * std::numbers::pi * std::sqrt(cable_length / gravity);
}

double butterworth_phase_delay(double cutoff, double frequency) noexcept {
  const double w = 2.0 * std::numbers::pi * frequency;
  const double wc = 2.0 * std::numbers::pi * cutoff;
  // arg F(j w) = -atan2(sqrt(2) w wc, wc^2 - w^2)
  return std::atan2(std::sqrt(2.0) * w * wc, wc * wc - w * w) / w;
}

FilterDelayMap compute_filter_delay_map(const FilterDelaySpec& spec) {
  if (spec.cutoffs.empty()) throw std::invalid_argument("cutoffs: at least one cut-off frequency is needed");
  if (spec.cable_lengths.empty()) throw std::invalid_argument("cable_lengths: at least one cable length is needed");
  for (const double f : spec.cutoffs) require_positive("cutoff [Hz]", f);
  for (const double l : spec.cable_lengths) require_positive("cable_length [m]", l);
  require_positive("gravity [m/s^2]", spec.gravity);
  if (spec.pade_order < 1) throw std::invalid_argument("pade_order = " + std::to_string(spec.pade_order) + " must be >= 1");

  FilterDelayMap map;
  map.spec = spec;
  TrackingLoop loop = spec.loop;
  loop.swing_filter_cutoff = 0.0;
  map.unfiltered_damping = evaluate_damping(spec.law, loop, spec.pade_order).pade.damping;
  map.points.reserve(spec.cutoffs.size() * spec.cable_lengths.size());
  for (const double cable : spec.cable_lengths) {
    const double period = swing_period(cable, spec.gravity);
    for (const double cutoff : spec.cutoffs) {
      FilterDelayPoint point;
      point.cutoff = cutoff;
      point.cable_length = cable;
      point.normalized_cutoff = 2.0 * std::numbers::pi * cutoff * period;
      loop.swing_filter_cutoff = point.normalized_cutoff;
      const DampingEvaluation evaluation = evaluate_damping(spec.law, loop, spec.pade_order);
      point.damping = evaluation.pade.damping;
      point.direct_damping = evaluation.direct.damping;
      point.stable = evaluation.pade.stable;
      point.added_delay = butterworth_phase_delay(cutoff, 1.0 / period);
      point.added_delay_periods = point.added_delay / period;
      map.points.push_back(point);
    }
  }
  return map;
}

}  // namespace crane::anti_swing_analysis
