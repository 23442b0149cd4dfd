#pragma once
// The axis audit (private to crane_model_audit): the catalog of candidate causes of the axis model
// (audit_models.hpp, (3.6) of Omar 2003 extended) and the ChannelAudit of an axis, alone or as a
// drive of the crane (AuditData's coupling, model_audit.hpp). Channels: position (windows replayed
// from nuisance initial states) or effort (inverse dynamics).
//
// A new axis cause is one AxisCause in axis_catalog() (axis_catalog.cpp): its name, parameters at the
// record's scales, what it changes in AxisModel, and optionally its regressor when it is linear in
// the effort domain. The crane's catalog gets it as trolley_NAME and slew_NAME.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "channel_audit.hpp"
#include "crane/model_audit/audit_models.hpp"
#include "crane/model_audit/audit_parameters.hpp"

namespace crane::model_audit::detail {

/// Scales of a record that set an axis candidate's grid and bounds.
struct AxisScales {
  double motor_constant{0.0};  // nominal K_m [m/s^2/V]
  double c_scale{0.0};         // max(c, 0.05 K_m) [m/s^2]
  double b_scale{0.0};         // max(b, 0.1) [1/s]
  double volt{0.0};            // c_scale / K_m [V]
  double max_input{0.0};       // max |u| [V]
  double range{0.0};           // position range [m], >= 1e-6
  double half_range{0.0};      // range / 2 [m]
  double sample_time{0.0};     // [s]
  double load_mass{0.0};       // nominal load mass of a crane drive [kg]
};

/// What a cause changes: the axis model, and on a crane drive the load mass (I and C of the row).
struct AxisTerms {
  AxisModel model;
  double load_mass_error{0.0};  // dm [kg]
};

/// One moving sample of the effort-domain regression K_m u - needed - friction = phi theta.
struct AxisRegressorSample {
  double drive{0.0};      // K_m u [m/s^2] (nominal K_m, mean command of the stencil)
  double velocity{0.0};   // v [m/s]
  double sign{0.0};       // sign(v)
  double position{0.0};   // x [m]
  double mass_term{0.0};  // (dI a + dC) / I_drive [m/s^2/kg] on a crane drive, else 0
};

struct AxisCause {
  const char* name;
  std::vector<ParameterSpec> (*parameters)(const AxisScales&);
  void (*apply)(const double* parameters, AxisTerms& terms);  // adds the cause to the nominal terms
  // Linear in the effort domain: the regressor phi of the cause's one parameter theta, and the
  // factor from theta to the parameter (nullptr: not linear).
  double (*regressor)(const AxisRegressorSample&){nullptr};
  double regressor_factor{1.0};
  bool substeps{false};             // frozen-coefficient substeps are O(h^2): AuditOptions::substeps
  bool gap_state{false};            // the nuisance includes where the axis sits in a gap (backlash)
  bool breakaway_threshold{false};  // a stick threshold: read from the breakaways (axis_breakaway_bracket)
  bool effort_channel{true};        // defined in the effort channel
  const char* calibration_note{""};  // non-empty: absorbed by the calibrated nominal (skipped)
  bool crane_drive_only{false};      // needs the crane's coupling (payload_mass_error)
  const char* limit_of{""};          // Candidate::limit_of (with limit_parameter and limit_value)
  std::size_t limit_parameter{0};
  double (*limit_value)(const AxisScales&){nullptr};
};

/// The axis catalog in catalog order (audit_catalog(axis) lists the entries that are not
/// crane_drive_only).
[[nodiscard]] const std::vector<AxisCause>& axis_catalog();

struct AxisSeries;

class AxisAudit final : public ChannelAudit {
 public:
  /// Checks the data (DataError: too few samples, columns of different lengths).
  AxisAudit(const AuditData& data, const AxisAuditParameters& nominal, const AuditOptions& options);
  ~AxisAudit() override;

  [[nodiscard]] std::string plant() const override { return "axis"; }
  [[nodiscard]] std::string channel() const override { return effort_ ? "effort" : "position"; }
  [[nodiscard]] std::string unit() const override { return effort_ ? "V" : "m"; }
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
  [[nodiscard]] const std::vector<double>& correlation_input() const override { return data_.input; }
  [[nodiscard]] double quantum() const override;
  [[nodiscard]] double resolution() const override;
  [[nodiscard]] double measured(std::size_t k) const override;
  [[nodiscard]] std::optional<double> linear_estimate(const Candidate& candidate,
                                                      const std::vector<double>& nominal) const override;
  void refine(const Candidate& candidate, const Problem& problem, const FreeSet& nominal_free, Fit& fit) const override;
  void second_opinion(const std::vector<double>& nominal, const Candidate* selected,
                      const std::vector<double>& selected_full, AuditReport& report) const override;
  [[nodiscard]] std::unique_ptr<ChannelAudit> with_first_cause(const Candidate& first,
                                                               const std::vector<double>& full) const override;

 private:
  [[nodiscard]] std::shared_ptr<AxisSeries> series(const AxisCause* cause) const;

  const AuditData& data_;
  double sample_time_;
  bool effort_;
  double holdout_fraction_;
  double window_duration_;
  int substeps_;
  std::vector<double> base_;
  std::vector<ParameterSpec> base_specs_;
  std::shared_ptr<const AxisSeries> series_;  // the nominal series (no cause; the first cause in a second step)
  std::size_t first_entry_{static_cast<std::size_t>(-1)};  // catalog entry of the first cause (second step)
  std::size_t first_base_{0};                                // base parameters before the first cause's
};

}  // namespace crane::model_audit::detail
