#pragma once
// One demo run of a maneuver, whoever runs it (crane_demo over DDS, crane_sim in one process): the
// controller a name stands for, the move request, the record of each cycle (the CSV), the figures
// of merit and the table row. One place, so the two runners print the same table from the same
// numbers.

#include <cstdint>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/common/stack_facts.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/stack/maneuver_metrics.hpp"
#include "crane/stack/stack_config.hpp"
#include "crane/tracking/tracking_stage.hpp"

namespace crane::stack {

/// Lockstep moves start at this cycle (4 s of simulated rest; docs/architecture.md).
inline constexpr std::uint64_t kMoveStartCycle = 400;

/// What a demo controller name stands for.
struct ControllerChoice {
  anti_swing::AntiSwingLaw anti_swing{anti_swing::AntiSwingLaw::delay1};
  tracking::TrackingLaw tracking{tracking::TrackingLaw::tracking};
  bool acceleration_feedforward{false};
  std::string label;  // "delay1", "gain_scheduling_full", "none+feedforward", ...
  /// The state estimator filters at state_estimator.follower_cutoff_frequency
  /// (state_estimator::for_follower): the tracking law is the follower.
  [[nodiscard]] bool follower_filter() const noexcept { return tracking == tracking::TrackingLaw::follower; }
};

/// The demo's controller names: none | pd | delay1 | delay2 | fuzzy (anti-swing with PD tracking),
/// gain_scheduling_partial | gain_scheduling_full (no anti-swing), follower (the minimum-time
/// bound followed in closed loop: tracking law follower, no anti-swing), auto (per maneuver the best
/// measured with the time-optimal profile: none for a trolley move, delay2 when the jib slews, both
/// with acceleration feedforward). Throws std::invalid_argument for another name.
[[nodiscard]] ControllerChoice choose_controller(std::string_view controller, const ManeuverConfig& maneuver,
                                                 bool acceleration_feedforward);

/// The demo's controller when none is named (crane_demo, crane_sim): follower, where it wins
/// (issue 32: every demo maneuver of every crane kind within 1.2 T*; docs/optimal_control.md); with
/// a profile asked for, the controller measured best for it: auto for time_optimal, delay1 for the
/// others (`profile`: the asked profile's name, empty when none was asked for).
[[nodiscard]] std::string default_controller(std::string_view profile);

/// The profile a controller name runs with unless one is asked for: step for the gain-scheduling
/// controllers (section 3.2), minimum_time for the follower; empty for the others.
[[nodiscard]] std::optional<std::string_view> implied_profile(std::string_view controller);

/// MoveRequest.profile code of a profile name (step | trapezoid | zv | zvd | ei | time_optimal | minimum_time, the
/// IDL's PROFILE_* names). Throws std::invalid_argument for another name.
[[nodiscard]] std::uint8_t profile_code(std::string_view profile);

/// The move request of `maneuver`: its targets and limits, the hoist axis when its cable length
/// target differs from the crane's, starting at cycle `start_cycle` (header.seq).
[[nodiscard]] protocol::MoveRequest move_request(const ManeuverConfig& maneuver, const common::StackFacts& facts,
                                                 std::uint32_t request_id, std::uint8_t profile,
                                                 std::uint64_t start_cycle);

/// [s] T = 2 pi sqrt(L/g) at the cable length the move ends with (the one the load settles at).
[[nodiscard]] double swing_period(const ManeuverConfig& maneuver, const common::StackFacts& facts);

/// One cycle of the move, the CSV's row: the sensors of cycle k and what was applied over [k, k+1)
/// (reported by the sample of k + 1), the reference, linear and actuator commands of cycle k (NaN
/// where one is missing from a recording).
struct CycleRecord {
  double t{0.0};  // [s] since the move's first cycle
  double u_x{0.0}, u_gamma{0.0};              // [V] applied (after the DAC)
  double x{0.0}, gamma{0.0}, phi{0.0}, theta{0.0}, L{0.0};  // [m], [rad], [rad], [rad], [m] measured
  double x_ref{0.0}, gamma_ref{0.0};          // [m], [rad]
  double V_x{0.0}, V_gamma{0.0};              // [V] tracking output
  double friction_x{0.0}, friction_gamma{0.0};  // [V] F_f/K_m added by the compensation
  double u_x_cmd{0.0}, u_gamma_cmd{0.0};      // [V] actuator command
  bool brakes{false};                         // brakes engaged over [k, k+1)
  // An overhead crane's bridge (0 elsewhere; written to the CSV for an overhead crane only):
  double y{0.0}, u_y{0.0}, y_ref{0.0}, V_y{0.0}, friction_y{0.0}, u_y_cmd{0.0};  // [m], [V], [m], [V], [V], [V]
};
[[nodiscard]] CycleRecord record_of(double t, const protocol::SensorSample& sensors, const protocol::SensorSample& next,
                                    const protocol::Reference* reference, const protocol::LinearCommand* linear,
                                    const protocol::ActuatorCommand* actuators) noexcept;
/// The CSV: header line, rows with 9 significant digits. Every column is a function of the
/// simulation alone, so two lockstep runs give the same file to the last bit.
/// `bridge` (an overhead crane): the bridge's columns y, u_y, y_ref, V_y, friction_y, u_y_cmd follow.
void write_csv(std::ostream& out, const std::vector<CycleRecord>& records, bool bridge = false);

/// T* of a run from the reference of its first cycle (ManeuverMetrics::minimum_time): its
/// move_duration when it carries a feedback law (a minimum-time plan), NaN otherwise.
[[nodiscard]] double minimum_time_of(const protocol::Reference& first) noexcept;

/// The figures of merit of the recorded move (throws std::invalid_argument when empty).
[[nodiscard]] ManeuverMetrics evaluate(const std::vector<CycleRecord>& records, const ManeuverConfig& maneuver);

/// One printed figure of a table row: its column, value in the printed unit (NaN: never reached)
/// and decimals. The decimals are those the convergence study justifies (docs/integration.md):
/// the plant's numerical error at the configured integrator settings stays below half a unit of
/// the last one on every demo maneuver (tests/integration ConvergenceStudy.*).
struct PrintedFigure {
  const char* name;
  double value;
  int decimals;
};
/// The row's figures in the table's order (settle_s, settle_T, T*_s, settle/T*, pos_err_mm,
/// slew_err_mrad, max_swing_deg, resid_swing_deg, max_V[, bridge_err_mm]); T* and the ratio are
/// NaN ("-") unless the move ran a minimum-time plan (ManeuverMetrics::minimum_time).
[[nodiscard]] std::vector<PrintedFigure> printed_figures(const ManeuverMetrics& metrics, double swing_period,
                                                         bool bridge = false);

/// The table (README, crane_demo, crane_sim): header line and one row per run, numbers rounded as
/// printed ("-" for a settle time never reached): printed_figures.
/// `bridge` (an overhead crane): a column bridge_err_mm follows.
[[nodiscard]] std::string table_header(bool bridge = false);
[[nodiscard]] std::string table_row(const std::string& maneuver, bool friction_compensation,
                                    const ManeuverMetrics& metrics, double swing_period, bool bridge = false);
/// `value` with `precision` decimals, "-" when not finite.
[[nodiscard]] std::string format_number(double value, int precision);

}  // namespace crane::stack
