#pragma once
// Model audit: replays measured data through a nominal model, analyses the residual, fits a catalog
// of candidate model extensions ("causes", audit_models.hpp) and selects the one that earns its
// parameters, by the Bayesian information criterion (Schwarz 1978)
//   BIC = n ln(RSS / n) + k ln(n),  delta-BIC = BIC(candidate) - BIC(nominal)   (k = added parameters)
// and by the error on a held-out part of the data. A candidate qualifies when delta-BIC <
// -bic_threshold and it lowers the held-out RMS by at least min_holdout_gain_percent; the cause is
// the qualifying candidate with the lowest delta-BIC, else "none". The audit stops at once ("none")
// when the nominal residual is already white (Ljung-Box p >= 0.05).
//
// Channels (what the residual is):
//  - position (axis) / angle (pendulum): output error. The record is cut into windows (axis:
//    window_duration; pendulum: one window per maneuver, given by an optional "segment" column),
//    each simulated from its own initial state (position and velocity, fitted as nuisance
//    parameters) with the recorded input held per sample. Axis: windows in the last holdout_fraction
//    of the record are held out (their initial states are refitted with the model fixed). Pendulum:
//    the last holdout_fraction of each maneuver is held out and predicted by continuing the fit.
//  - effort (axis, inverse dynamics, for closed-loop data where position cannot tell models apart):
//    the drive command that the model needs for the measured motion, from centred differences
//    (acc = second difference / T^2, vel = central difference, input = mean of the two held commands
//    under the stencil), against the recorded command [V]. Samples whose two one-sided velocities lie
//    within dead_band are "at rest": their residual is the distance of the needed drive from the
//    static friction interval. Backlash is not defined in this channel (skipped).
// Fitting: a candidate that is linear in its parameters in the effort domain (friction asymmetries,
// gain error, position-dependent friction) is first solved by linear least squares (Eigen,
// column-pivoted QR); every candidate is then refined by nonlinear least squares (Ceres,
// Levenberg-Marquardt, central numeric derivatives, bounds) over the simulated response, starting
// from the best point of a coarse grid. Standard errors: sqrt(diag(s^2 (J^T J)^-1)) at the optimum,
// s^2 = RSS / (n - parameters). With calibrate, the nominal model's own parameters (axis K_m, b, c;
// pendulum L, damping) are fitted first and refitted with every candidate, and candidates that they
// absorb are skipped (gain_error; cable_length_error, pendulum_viscous_damping).
//
// Offline: allocates; throws common::ConfigError for bad options and DataError (measured_data.hpp)
// for bad data, each naming the field, row or column.

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "crane/model_audit/measured_data.hpp"
#include "crane/model_audit/residual_analysis.hpp"

namespace crane::model_audit {

enum class AuditPlant { axis, pendulum };
enum class AuditChannel { position, effort };  // effort: axis only

/// Catalog entry names of a plant, in catalog order.
[[nodiscard]] const std::vector<std::string>& audit_catalog(AuditPlant plant);
/// Nominal parameter names accepted by --param: axis K_m [m/s^2/V], b [1/s], c [m/s^2];
/// pendulum L [m], damping [1/s], theta_zero [rad] (measured angle of hanging down; unknown =
/// estimated), gravity [m/s^2].
[[nodiscard]] const std::vector<std::string>& audit_parameter_names(AuditPlant plant);

/// Uniformly sampled measured data. Axis: input u [V], output x [m]. Pendulum: output theta [rad]
/// as measured, optional trolley_position x [m] (driven swing); input unused.
struct AuditData {
  std::string source;
  std::vector<double> time;              // [s], strictly increasing, uniform within 1 %
  std::vector<double> input;             // [V] (axis)
  std::vector<double> output;            // [m] or [rad]
  std::vector<double> trolley_position;  // [m] (pendulum, optional, else empty)
  std::vector<double> segment;           // maneuver id per sample (optional, else empty)
};

/// Reads `file` with read_time_series_csv(): axis columns t, u, x; pendulum t, theta and optional
/// x and segment (all through `columns`, "t=COL,..."); a canonical name other than these is refused
/// (ConfigError). Decimates by the smallest integer factor that brings the rate to <= max_rate
/// [Hz] (0 = never). Throws DataError naming the row/column for missing columns, non-numeric or
/// non-finite cells, time not increasing, fewer than minimum_samples rows, or non-uniform sampling.
[[nodiscard]] AuditData read_audit_data(const std::filesystem::path& file, AuditPlant plant,
                                        const std::string& columns, double max_rate,
                                        std::size_t minimum_samples = 50);

struct AuditOptions {
  AuditPlant plant{AuditPlant::axis};
  std::map<std::string, double> parameters;  // nominal, names from audit_parameter_names()
  bool calibrate{false};
  std::vector<std::string> causes;           // restrict to these catalog names; empty = all
  AuditChannel channel{AuditChannel::position};
  double holdout_fraction{0.3};     // [-] in [0.1, 0.6]
  double window_duration{1.0};      // [s] > 0 (axis position windows)
  double dead_band{0.01};           // [m/s] >= 0 (axis effort channel)
  double bic_threshold{10.0};       // [-] >= 0
  double min_holdout_gain_percent{1.0};  // [%] >= 0
  int substeps{4};                  // >= 1, for the non-closed-form entries
  std::size_t max_lag{20};          // [samples] Ljung-Box lags
};

/// Throws common::ConfigError naming the field: unknown --param name (lists the valid ones),
/// missing required nominal parameter, unknown cause (lists the catalog), out-of-range option.
void validate(const AuditOptions& options);

struct FittedParameter {
  std::string name;
  std::string unit;
  double value{0.0};
  double standard_error{0.0};
};

struct CandidateReport {
  std::string name;
  std::vector<FittedParameter> parameters;
  bool fitted{false};
  std::string note;                    // why skipped, when not fitted
  double delta_bic{0.0};               // [-]
  double train_rms{0.0};               // [channel unit]
  double holdout_rms{0.0};             // [channel unit]
  double holdout_gain_percent{0.0};    // [%]
  double signature_correlation{0.0};   // [-] nominal residual vs the candidate's signature
  bool qualifies{false};
};

struct ResidualSummary {
  double train_rms{0.0};
  double holdout_rms{0.0};
  WhitenessTest whiteness;         // of the training residual
  double input_correlation{0.0};   // max |corr| with the input over lags 0..max_lag (axis)
};

struct AuditReport {
  std::string plant;
  std::string channel;
  std::string unit;          // of the channel: m, V or rad
  std::string cause{"none"};
  std::string stop_reason;
  std::vector<FittedParameter> parameters;  // of the cause
  std::vector<FittedParameter> nominal;     // nominal model used (calibrated if asked)
  std::vector<FittedParameter> extended_nominal;  // base parameters refitted with the cause
  double holdout_before{0.0};
  double holdout_after{0.0};
  double holdout_percent{0.0};
  ResidualSummary before;
  ResidualSummary after;
  double effort_holdout_before{0.0};  // axis: effort-channel held-out RMS [V] (NaN if undefined)
  double effort_holdout_after{0.0};
  std::vector<CandidateReport> candidates;  // ranked by delta-BIC (fitted first)
  double sample_time{0.0};
  std::size_t samples{0};
  // Series for the plots (all samples of the channel; NaN where undefined).
  std::vector<double> time;
  std::vector<double> measured;
  std::vector<double> nominal_prediction;
  std::vector<double> extended_prediction;
  std::vector<double> holdout;  // 1 = held out
};

/// Runs the audit (validates first). Throws common::ConfigError / DataError (too few samples for the
/// windows, a channel the plant does not have).
[[nodiscard]] AuditReport run_audit(const AuditData& data, const AuditOptions& options);

/// Writes DIR/report.json, DIR/report.md and DIR/series.csv (t, measured, nominal, extended,
/// holdout). `command_line` goes into the markdown. Creates DIR. Throws DataError on I/O failure.
void write_audit_report(const AuditReport& report, const std::filesystem::path& directory,
                        const std::string& command_line);

}  // namespace crane::model_audit
