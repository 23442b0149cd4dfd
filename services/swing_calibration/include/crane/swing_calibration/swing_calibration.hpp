#pragma once
// Shaper calibration from a recording (issue 17, item 3; `deploy/crane calibrate swing`): fits the
// load's swing frequency and damping against the cable length, then ranks the planner's input
// shapers (ZV, ZVD, EI, MZV, two-hump EI; trajectory_planner/input_shaper.hpp) by the residual swing
// they leave over a band of frequency error against the delay they add, and writes the result in
// the form the planner's `manual:` block loads.
//
// Swing model (an equivalent pendulum of length L_e = a L + c, the recorded cable length L):
//   in plane:      L_e phi''   + 2 L_e' phi'   + g phi   = x''            - 2 zeta w L_e phi'
//   out of plane:  L_e theta'' + 2 L_e' theta' + g theta = -x gamma''     - 2 zeta w L_e theta'
// with w = sqrt(g / L_e): the linearized swing rows (2.29) and (2.31) of H. M. Omar, "Control of
// Gantry and Tower Cranes", Virginia Tech 2003, with the hoist's term d/dt(L^2 s') = L (L s'' + 2 L' s')
// of the time-varying length, and viscous damping zeta. a = 1, c = 0, zeta = 0 is the dissertation's
// pendulum sqrt(g/L); a hook on rigging (a double pendulum) makes the first mode slower: for the
// lab crane's hook (l = 0.3 m, m_h = 0.5 kg, m = 2 kg) its equivalent length g / w_1^2 is
// 0.995 L + 0.257 m within 0.1 % over L in [0.6, 1.8] m (plant::double_pendulum_frequencies).
//
// Fit: segments of the record are chosen (free swing: the trolley and the slew at rest for at least
// `min_segment_periods` periods with a swing above `min_swing_amplitude`; or the whole record, the
// measured trolley and slew accelerations as input), each swing channel of each segment is replayed
// by the model (RK4 at the sample period, inputs linear between samples) from its own initial angle,
// rate and encoder bias, and Ceres fits (c, zeta, and a when the segments span more than 20 % of
// cable length) with every segment's three nuisances by least squares on the measured angle.
//
// Errors: the readers throw model_audit::DataError (file content); fit_swing throws
// CalibrationError when no segment qualifies (naming the record and the thresholds) and
// common::ConfigError for invalid options (field, value, bound). Offline: allocates, no I/O except
// read_swing_record.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "crane/model_audit/measured_data.hpp"
#include "crane/trajectory_planner/input_shaper.hpp"
#include "crane/trajectory_planner/speed_reference.hpp"

namespace crane::swing_calibration {

class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One recording, SI, all columns of equal length (time strictly increasing).
struct SwingRecord {
  std::string source;
  std::vector<double> time;                // [s]
  std::vector<double> trolley_position;    // x [m]
  std::vector<double> slew_angle;          // gamma [rad]
  std::vector<double> swing_in_plane;      // phi [rad] (measured: cable angle at the trolley)
  std::vector<double> swing_out_of_plane;  // theta [rad]
  std::vector<double> cable_length;        // L [m] > 0
};

/// The CSV of crane_demo, crane_sim and `crane_topic convert` (columns t, x, gamma, phi, theta, L;
/// `mapping` renames them, model_audit::parse_column_mapping). Throws model_audit::DataError.
[[nodiscard]] SwingRecord read_swing_record(const std::filesystem::path& file,
                                            const model_audit::ColumnMapping& mapping = {});

struct CalibrationOptions {
  double gravity{9.8};                // [m/s^2] > 0
  bool whole_record{false};           // fit the whole record with the drive accelerations as input
  double min_segment_periods{3.0};    // [-] free-swing segment at least this many periods of sqrt(g/L), >= 1
  double still_trolley_speed{0.005};  // [m/s] the trolley counts as at rest below, > 0
  double still_slew_rate{0.005};      // [rad/s] the slew likewise, > 0
  double min_swing_amplitude{0.003};  // [rad] a channel whose swing stays below is not fitted, >= 0
  double frequency_band{0.15};        // [-] +- relative frequency error the shaper must cover, in (0, 0.5]
  double vibration_tolerance{0.05};   // [-] residual swing allowed over the band (and EI's V), in (0, 0.2]
};
/// Throws common::ConfigError naming "calibration.<field>", the value and the bound.
void validate(const CalibrationOptions& options);

/// One fitted channel of one segment, samples [begin, end).
struct SwingSegment {
  std::size_t begin{0};
  std::size_t end{0};
  bool in_plane{true};                // phi (true) or theta
  bool driven{false};                 // the drive accelerations are the model's input (whole record)
  double start_time{0.0};             // [s] time of sample begin
  double end_time{0.0};               // [s] time of sample end - 1
  double mean_cable_length{0.0};      // [m]
  double amplitude{0.0};              // [rad] largest |angle - mean|
  double rms_residual{0.0};           // [rad] measured minus model after the fit
  double zero_crossing_frequency{0.0};  // [rad/s] the initial guess (mean half period between crossings)
};

struct SwingFit {
  double gravity{9.8};          // [m/s^2]
  double length_scale{1.0};     // a [-]
  double length_offset{0.0};    // c [m]
  double damping_ratio{0.0};    // zeta [-]
  bool length_scale_fitted{false};
  double rms_residual{0.0};     // [rad] over every fitted sample
  double min_cable_length{0.0}; // [m] over the fitted segments
  double max_cable_length{0.0};
  std::vector<SwingSegment> segments;
  /// w = sqrt(g / (a L + c)) [rad/s] at cable length `cable_length` [m]; NaN if a L + c <= 0.
  [[nodiscard]] double natural_frequency(double cable_length) const noexcept;
};

/// Fits the swing model above. Throws CalibrationError (no segment) or common::ConfigError (options).
[[nodiscard]] SwingFit fit_swing(const SwingRecord& record, const CalibrationOptions& options);

/// The model's replay of one fitted segment with the fitted parameters (for the plot): the modelled
/// measured angle [rad] at samples [segment.begin, segment.end).
[[nodiscard]] std::vector<double> replay_segment(const SwingRecord& record, const SwingFit& fit, std::size_t index);

/// One shaper of the table.
struct ShaperRow {
  std::string name;                  // "zv", ..., or "zv_nominal" (ZV on sqrt(g/L), the uncalibrated reference)
  trajectory_planner::ShaperKind kind{trajectory_planner::ShaperKind::zv};
  double design_frequency{0.0};      // [rad/s]
  double delay{0.0};                 // [s] the shaper's length
  double delay_periods{0.0};         // [-] delay / fitted period
  double residual_at_fit{0.0};       // [-] residual swing at the fitted frequency (1 = unshaped)
  double worst_residual_in_band{0.0};  // [-] largest over the fitted frequency +- band
  bool meets_tolerance{false};
};

struct ShaperRecommendation {
  double cable_length{0.0};        // [m] where the shapers were designed
  double fitted_frequency{0.0};    // [rad/s]
  double nominal_frequency{0.0};   // [rad/s] sqrt(g/L)
  std::vector<ShaperRow> rows;     // zv, zvd, ei, mzv, two_hump_ei, zv_nominal
  double vibration_tolerance{0.05};  // [-] of the EI designs and the ranking
  std::size_t recommended{0};      // index into rows: the shortest delay meeting the tolerance over
                                   // the band; if none does, the smallest worst residual
  /// The residual curve of row `row` at frequency ratios `ratios` (w' / fitted frequency).
  [[nodiscard]] std::vector<double> residual_curve(std::size_t row, const std::vector<double>& ratios,
                                                   double damping_ratio) const;
};

/// Designs and ranks the shapers at `cable_length` [m] (> 0). Throws common::ConfigError.
[[nodiscard]] ShaperRecommendation recommend_shaper(const SwingFit& fit, double cable_length,
                                                    const CalibrationOptions& options);

/// The planner's shaping for a kind (trajectory_planner::SpeedShaping has every ShaperKind).
[[nodiscard]] trajectory_planner::SpeedShaping speed_shaping(trajectory_planner::ShaperKind kind) noexcept;

/// The four lines of the planner's `trajectory_planner.manual:` block (shaping, swing_length_scale,
/// swing_length_offset, swing_damping_ratio) with a comment naming the record, indented for the block.
[[nodiscard]] std::string planner_manual_yaml(const SwingFit& fit, const ShaperRecommendation& recommendation,
                                              const std::string& source);

/// The supervisor's line that goes with them: `zone_stop_delay_periods`, the recommended shaper's
/// mean delay in swing periods (trajectory_planner::shaper_delay_periods at the fitted damping),
/// which the stack's config loader requires to match manual.shaping. Indented for the
/// `supervisor:` block.
[[nodiscard]] std::string supervisor_yaml(const SwingFit& fit, const ShaperRecommendation& recommendation);

/// The table (fit and shapers) as printed by the tool.
[[nodiscard]] std::string format_report(const SwingFit& fit, const ShaperRecommendation& recommendation,
                                        const CalibrationOptions& options);

}  // namespace crane::swing_calibration
