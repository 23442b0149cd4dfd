#include "crane/stack/maneuver_metrics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace crane::stack {

double nearest_rank_quantile(std::vector<double> values, double q) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(values.begin(), values.end());
  const auto i = static_cast<std::size_t>(std::llround(std::clamp(q, 0.0, 1.0) * static_cast<double>(values.size() - 1)));
  return values[std::min(i, values.size() - 1)];
}

ManeuverMetrics evaluate_maneuver(const std::vector<RecordedCycle>& cycles, double trolley_target,
                                  double slew_target, const SettleCriteria& criteria, double bridge_target) {
  if (cycles.empty()) throw std::invalid_argument("evaluate_maneuver: the recording has no cycles");
  ManeuverMetrics m;
  const double end_time = cycles.back().time;
  std::ptrdiff_t last_violation = -1;
  for (std::size_t i = 0; i < cycles.size(); ++i) {
    const auto& c = cycles[i];
    const double swing = std::max(std::fabs(c.swing_in_plane), std::fabs(c.swing_out_of_plane));
    m.max_swing = std::max(m.max_swing, swing);
    m.max_voltage =
        std::max({m.max_voltage, std::fabs(c.trolley_voltage), std::fabs(c.slew_voltage), std::fabs(c.bridge_voltage)});
    if (c.time >= end_time - criteria.residual_window) m.residual_swing = std::max(m.residual_swing, swing);
    const bool settled = std::fabs(c.trolley_position - trolley_target) < criteria.trolley_tolerance &&
                         std::fabs(c.slew_angle - slew_target) < criteria.slew_tolerance &&
                         std::fabs(c.bridge_position - bridge_target) < criteria.trolley_tolerance &&
                         std::fabs(c.swing_in_plane) < criteria.swing_tolerance &&
                         std::fabs(c.swing_out_of_plane) < criteria.swing_tolerance;
    if (!settled) last_violation = static_cast<std::ptrdiff_t>(i);
  }
  const auto first_good = static_cast<std::size_t>(last_violation + 1);
  m.settle_time = first_good < cycles.size() ? std::max(0.0, cycles[first_good].time)
                                             : std::numeric_limits<double>::quiet_NaN();
  m.final_position_error = std::fabs(cycles.back().trolley_position - trolley_target);
  m.final_slew_error = std::fabs(cycles.back().slew_angle - slew_target);
  m.final_bridge_error = std::fabs(cycles.back().bridge_position - bridge_target);
  return m;
}

}  // namespace crane::stack
