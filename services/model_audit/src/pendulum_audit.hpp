#pragma once
// The pendulum audit (private to crane_model_audit): the catalog of candidate causes of the swing
// (audit_models.hpp for the planar pendulum, crane_swing.hpp for the crane's swing) and two
// ChannelAudits: the pendulum (one window per maneuver, the last part of each held out) and the
// crane's swing channel (phi and theta replayed with the measured drive and hoist motion).
//
// A new swing cause is one PendulumCause in pendulum_catalog() (pendulum_audit.cpp): its name, its
// parameter, and what it changes in PendulumModel and in SwingEffects. The crane's catalog gets it
// under the same name.

#include <memory>
#include <string>
#include <vector>

#include "channel_audit.hpp"
#include "crane/model_audit/audit_models.hpp"
#include "crane/model_audit/audit_parameters.hpp"
#include "crane/model_audit/crane_swing.hpp"

namespace crane::model_audit::detail {

/// Scales of a record for the catalog's parameters.
struct SwingScales {
  double omega_squared{1.0};  // g / L [1/s^2]
  double load_weight{0.0};    // m g [N] of the configured (suspended) load; 0 on the planar pendulum
  double cable_length{1.0};   // L [m] (mean)
};

struct PendulumCause {
  const char* name;
  std::vector<ParameterSpec> (*parameters)(const SwingScales& scales);
  void (*apply)(const double* parameters, PendulumModel& model);   // model with its base parameters (nullptr: crane only)
  void (*apply_swing)(const double* parameters, SwingEffects& effects);
  const char* calibration_note{""};  // non-empty: absorbed by the calibrated nominal (skipped)
  bool needs_known_zero{false};      // not identifiable when theta_zero is estimated
  bool crane_only{false};            // an entry of the crane's swing channel only (wind, hook: plant options of the tower crane)
  std::size_t extra_nuisance{0};     // initial-state values per window beyond the swing's (the hook's rigging: 4)
};

/// The pendulum catalog in catalog order.
[[nodiscard]] const std::vector<PendulumCause>& pendulum_catalog();

/// An entry that extends the crane swing replay by states the encoders do not measure (the hook's
/// rigging, the rope's stretch): one of them at a time (replay_crane_swing, follow_swing).
[[nodiscard]] bool extends_swing_state(const PendulumCause& cause);

struct PendulumSeries;
struct SwingSeries;

class PendulumAudit final : public ChannelAudit {
 public:
  /// Checks the data (DataError: too few samples, columns of different lengths).
  PendulumAudit(const AuditData& data, const PendulumAuditParameters& nominal, const AuditOptions& options);
  ~PendulumAudit() override;

  [[nodiscard]] std::string plant() const override { return "pendulum"; }
  [[nodiscard]] std::string channel() const override { return "angle"; }
  [[nodiscard]] std::string unit() const override { return "rad"; }
  [[nodiscard]] const std::string& source() const override { return data_.source; }
  [[nodiscard]] const std::vector<double>& time() const override { return data_.time; }
  [[nodiscard]] std::size_t samples() const override { return data_.time.size(); }
  [[nodiscard]] double sample_time() const override { return sample_time_; }
  [[nodiscard]] const std::vector<double>& base() const override { return base_; }
  [[nodiscard]] const std::vector<ParameterSpec>& base_specs() const override { return base_specs_; }
  [[nodiscard]] std::vector<std::size_t> nominal_free(bool calibrate) const override;
  [[nodiscard]] std::vector<Candidate> candidates() const override;
  [[nodiscard]] std::string unavailable(const Candidate& candidate) const override;
  [[nodiscard]] Problem problem(const Candidate* candidate) const override;
  [[nodiscard]] const std::vector<double>& correlation_input() const override { return no_input_; }
  [[nodiscard]] double quantum() const override { return resolution_quantum(data_.output, 1); }
  [[nodiscard]] double resolution() const override { return measurement_resolution(data_.output, 1); }
  [[nodiscard]] double measured(std::size_t k) const override { return data_.output[k]; }
  [[nodiscard]] std::unique_ptr<ChannelAudit> with_first_cause(const Candidate& first,
                                                               const std::vector<double>& full) const override;

 private:
  const AuditData& data_;
  double sample_time_;
  double holdout_fraction_;
  bool theta_zero_known_;
  double gravity_;
  std::vector<double> base_;
  std::vector<ParameterSpec> base_specs_;
  std::vector<double> no_input_;
  std::shared_ptr<const PendulumSeries> series_;  // the nominal series (the first cause in a second step)
  std::size_t first_entry_{static_cast<std::size_t>(-1)};  // catalog entry of the first cause (second step)
  std::size_t first_base_{0};                                // base parameters before the first cause's
};

/// A second cause on the crane's swing channel passes the practical-significance floor also when it
/// halves the held-out RMS left by the first (ChannelAudit::second_step_gain_fraction). The swing's
/// clean held-out RMS is its encoders' noise (0.105-0.118 mrad, 0.4 quanta, on the independent
/// simulator's 20 clean recordings): no systematic part for a spurious second cause to take up, as
/// the drives' one to three counts are (kCraneResolutionQuanta). With a hook and a cable length
/// error, the hook alone leaves 0.62 mrad (2.4 quanta) and the pair 0.15 mrad: the three-quanta
/// floor could not be reached by any second cause.
inline constexpr double kSwingSecondStepGainFraction = 0.5;

/// The crane's swing channel: `measured` interleaves phi and theta [rad] per sample; `motion` is the
/// drive and hoist motion held per sample (crane_swing.hpp); L is the mean cable length (scales).
class SwingAudit final : public ChannelAudit {
 public:
  SwingAudit(const AuditData& data, std::shared_ptr<const plant::TowerCraneModel> model, std::vector<DriveMotion> motion,
             std::vector<double> measured, double mean_cable_length, double gravity, const AuditOptions& options);
  ~SwingAudit() override;

  [[nodiscard]] std::string plant() const override { return "swing"; }
  [[nodiscard]] std::string channel() const override { return "angle"; }
  [[nodiscard]] std::string unit() const override { return "rad"; }
  [[nodiscard]] const std::string& source() const override { return data_.source; }
  [[nodiscard]] const std::vector<double>& time() const override { return data_.time; }
  [[nodiscard]] std::size_t samples() const override { return data_.time.size(); }
  [[nodiscard]] std::size_t residuals_per_sample() const override { return 2; }
  [[nodiscard]] double sample_time() const override { return sample_time_; }
  [[nodiscard]] const std::vector<double>& base() const override { return base_; }
  [[nodiscard]] const std::vector<ParameterSpec>& base_specs() const override { return base_specs_; }
  /// No base parameters of its own (the cable length is measured); in a second step the first
  /// cause's parameters are the base and are refitted in every fit.
  [[nodiscard]] std::vector<std::size_t> nominal_free(bool) const override;
  /// The swing catalog; in a second step without the first cause, and without the other extended
  /// row (the replay has a hook or an elastic rope, not both).
  [[nodiscard]] std::vector<Candidate> candidates() const override;
  [[nodiscard]] Problem problem(const Candidate* candidate) const override;
  [[nodiscard]] const std::vector<double>& correlation_input() const override { return no_input_; }
  [[nodiscard]] double quantum() const override;
  /// True in a first step: a swing cause alone can miss the floor beside a second one, and the
  /// clean swing residual is its encoders' noise, no systematic part for a spurious pair to take up.
  [[nodiscard]] bool pairs_without_single() const override;
  /// kSwingSecondStepGainFraction in a second step.
  [[nodiscard]] double second_step_gain_fraction() const override;
  [[nodiscard]] double measured(std::size_t k) const override;
  /// The second step (stepwise, two causes at most): the replay with `first` applied, its fitted
  /// values the base.
  [[nodiscard]] std::unique_ptr<ChannelAudit> with_first_cause(const Candidate& first,
                                                               const std::vector<double>& full) const override;

 private:
  const AuditData& data_;
  double sample_time_;
  double holdout_fraction_;
  double window_duration_;
  SwingScales scales_;
  std::vector<double> base_;  // empty, or the first cause's parameters in a second step
  std::vector<ParameterSpec> base_specs_;
  std::vector<double> no_input_;
  std::shared_ptr<const SwingSeries> series_;  // the nominal series (the first cause in a second step)
};

}  // namespace crane::model_audit::detail
