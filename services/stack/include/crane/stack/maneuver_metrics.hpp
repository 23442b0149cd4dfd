#pragma once
// Figures of merit of one recorded maneuver (the demo's table and summary.json).

#include <limits>
#include <vector>

namespace crane::stack {

/// One cycle of a recorded maneuver, as measured by the sensors.
struct RecordedCycle {
  double time{0.0};                 // [s] since the start of the move
  double trolley_position{0.0};     // [m]
  double slew_angle{0.0};           // [rad]
  double swing_in_plane{0.0};       // [rad]
  double swing_out_of_plane{0.0};   // [rad]
  double trolley_voltage{0.0};      // [V] applied
  double slew_voltage{0.0};         // [V] applied
  double bridge_position{0.0};      // [m] overhead crane (0 elsewhere)
  double bridge_voltage{0.0};       // [V] applied
};

struct SettleCriteria {
  double trolley_tolerance{0.005};          // [m]
  double slew_tolerance{0.005};             // [rad]
  double swing_tolerance{0.5 * 3.14159265358979323846 / 180.0};  // [rad] 0.5 deg
  double residual_window{2.0};              // [s] residual swing: max |swing| over the last window
};

struct ManeuverMetrics {
  double settle_time{0.0};            // [s] from the move start until every criterion holds for good; NaN if never
  double final_position_error{0.0};   // [m] |x - target| at the last cycle
  double final_slew_error{0.0};       // [rad] |gamma - target| at the last cycle
  double final_bridge_error{0.0};     // [m] |y - target| at the last cycle (overhead crane; settles within
                                      // trolley_tolerance like the trolley)
  double max_swing{0.0};              // [rad] max over the run of max(|phi|, |theta|)
  double residual_swing{0.0};         // [rad] same over the last residual_window
  double max_voltage{0.0};            // [V] max |applied voltage| over every drive
  // [s] T*, the move's minimum time on the controllers' model, when its plan was the minimum-time
  // bound (the reference's move_duration of a move that carries a feedback law); NaN otherwise.
  // Set by the runners, not by evaluate_maneuver.
  double minimum_time{std::numeric_limits<double>::quiet_NaN()};
};

/// The nearest-rank q-quantile of `values` (q in [0, 1]: 0 the smallest, 1 the largest, 0.5 the
/// median, the upper one of an even count's two middles); NaN when `values` is empty. The
/// distributions the benchmarks print (crane_sim compare, crane_site demo).
[[nodiscard]] double nearest_rank_quantile(std::vector<double> values, double q);

/// Evaluates a recording (cycles in time order, at least one). Throws std::invalid_argument when
/// `cycles` is empty.
ManeuverMetrics evaluate_maneuver(const std::vector<RecordedCycle>& cycles, double trolley_target,
                                  double slew_target, const SettleCriteria& criteria = {}, double bridge_target = 0.0);

}  // namespace crane::stack
