#pragma once
// One audited channel of a plant model (private to crane_model_audit). A plant model's audit
// implements ChannelAudit: it owns the model's catalog of candidate causes (at the scales of the
// record), builds the residual problem of the nominal model and of each cause, and may add its
// own fits (a linear start, a refinement) and a second opinion. run_channel_audit() is the one
// driver for every model: nominal fit, grid, Ceres fits of each candidate, BIC and held-out
// selection (model_audit.hpp). Implementations: AxisAudit (axis_audit.hpp: the axis, and each
// drive of the crane), PendulumAudit and SwingAudit (pendulum_audit.hpp: the pendulum, and the
// crane's swing).

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "audit_fit.hpp"
#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit::detail {

class ChannelAudit {
 public:
  virtual ~ChannelAudit() = default;

  /// AuditReport::plant, channel and unit of this channel.
  [[nodiscard]] virtual std::string plant() const = 0;
  [[nodiscard]] virtual std::string channel() const = 0;
  [[nodiscard]] virtual std::string unit() const = 0;
  /// The record's name (for messages) and its sample times [s].
  [[nodiscard]] virtual const std::string& source() const = 0;
  [[nodiscard]] virtual const std::vector<double>& time() const = 0;
  /// Samples of the record, and residuals per sample (the swing has phi and theta).
  [[nodiscard]] virtual std::size_t samples() const = 0;
  [[nodiscard]] virtual std::size_t residuals_per_sample() const { return 1; }
  [[nodiscard]] virtual double sample_time() const = 0;

  /// The nominal model's base parameters (start values) and their specs.
  [[nodiscard]] virtual const std::vector<double>& base() const = 0;
  [[nodiscard]] virtual const std::vector<ParameterSpec>& base_specs() const = 0;
  /// Base indices fitted in the nominal fit (calibrate: the calibrated ones, plus nuisance bases).
  [[nodiscard]] virtual std::vector<std::size_t> nominal_free(bool calibrate) const = 0;

  /// The catalog at this record's scales, in catalog order.
  [[nodiscard]] virtual std::vector<Candidate> candidates() const = 0;
  /// Non-empty: why `candidate` cannot be fitted on this channel (beyond --cause and --calibrate).
  [[nodiscard]] virtual std::string unavailable(const Candidate&) const { return {}; }
  /// The residual problem of the nominal model (nullptr) or of the model with `candidate`.
  [[nodiscard]] virtual Problem problem(const Candidate* candidate) const = 0;

  /// Input whose lagged correlation with the residual is reported (empty: none).
  [[nodiscard]] virtual const std::vector<double>& correlation_input() const = 0;
  /// Resolution of the measured channel (0: none).
  [[nodiscard]] virtual double quantum() const = 0;
  /// The sensor's resolution for the practical-significance floor: quantum or noise, the larger
  /// (measurement_resolution(); default: quantum()).
  [[nodiscard]] virtual double resolution() const { return quantum(); }
  /// In a second step (with_first_cause), the fraction [-] in [0, 1) of the held-out RMS left by
  /// the first cause whose removal passes the practical-significance floor even when it is below
  /// the floor (0: the floor alone). For a channel whose clean residual is its sensor's noise (no
  /// systematic part a second cause could take up), where the first cause can leave less than the
  /// floor and a second cause that halves it is still plainly there (SwingAudit).
  [[nodiscard]] virtual double second_step_gain_fraction() const { return 0.0; }
  /// Whether a pair of causes is looked for when no single cause earns its parameters (the
  /// residual not white, max_causes > 1): the best first causes by delta-BIC each get a second
  /// step, and the pair is kept when together they pass the floor (run_channel_audit). False by
  /// default; for a channel whose clean residual is its sensor's noise (SwingAudit).
  [[nodiscard]] virtual bool pairs_without_single() const { return false; }
  /// Measured value at sample k for the plots (the channel's first residual of the sample).
  [[nodiscard]] virtual double measured(std::size_t k) const = 0;

  /// A start value of a one-parameter candidate from a linear least squares (nullopt: none).
  [[nodiscard]] virtual std::optional<double> linear_estimate(const Candidate&, const std::vector<double>&) const {
    return std::nullopt;
  }
  /// Refines the candidate's fit after the Ceres fits (the axis stiction threshold).
  virtual void refine(const Candidate&, const Problem&, const FreeSet&, Fit&) const {}
  /// The second step of the stepwise audit: this channel's model with `first` (a candidate of this
  /// channel) added, its fitted values `values` appended to the base parameters (so they are
  /// refitted in every fit of the step) and `first` no longer a candidate. `base` = the first step's
  /// full parameter vector of the selected fit (base, then the cause's). nullptr: no second step.
  [[nodiscard]] virtual std::unique_ptr<ChannelAudit> with_first_cause(const Candidate& /*first*/,
                                                                       const std::vector<double>& /*full*/) const {
    return nullptr;
  }
  /// Fills AuditReport::effort_holdout_before/after (default: NaN) from the nominal and the
  /// selected fit (`selected` nullptr: none selected).
  virtual void second_opinion(const std::vector<double>& nominal, const Candidate* selected,
                              const std::vector<double>& selected_full, AuditReport& report) const;
};

/// The audit of one channel (validated options): throws DataError when no training window fits.
[[nodiscard]] AuditReport run_channel_audit(const ChannelAudit& channel, const AuditOptions& options);

/// The crane audit (crane_audit.cpp): the trolley and slew AxisAudits and the SwingAudit, combined.
[[nodiscard]] AuditReport run_crane_audit(const AuditData& data, const AuditOptions& options);

/// The sample time [s] of `time` (mean step); throws DataError below 50 samples.
[[nodiscard]] double checked_sample_time(const AuditData& data);

}  // namespace crane::model_audit::detail
