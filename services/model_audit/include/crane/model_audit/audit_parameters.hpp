#pragma once
// Nominal parameters of the model audit (model_audit.hpp), one typed struct per plant model, and
// one table per model that names each field as --param and the report (report.json "nominal")
// spell it. The names are generated from these tables only.
//
//  - axis: (3.6) of H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003,
//      x'' = K_m u - b x' - c sign(x'), with the nominal asymmetries and stiction of audit_models.hpp
//      (the catalog entries add to them);
//  - pendulum: the planar pendulum of audit_models.hpp;
//  - crane: common::CraneParameters (the fields that plant::TowerCraneModel and the drives use;
//      friction in volt equivalents, as in the configuration).
//
// Offline: allocates; throws common::ConfigError naming the field (as "param NAME"), the value and
// the bound.

#include <limits>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "crane/common/crane_parameters.hpp"

namespace crane::model_audit {

enum class AuditPlant { axis, pendulum, crane };

/// Nominal axis model. The first three are required (no default: NaN until given).
struct AxisAuditParameters {
  double motor_constant{std::numeric_limits<double>::quiet_NaN()};  // K_m [m/s^2/V] > 0
  double viscous{std::numeric_limits<double>::quiet_NaN()};         // b [1/s] >= 0
  double coulomb{std::numeric_limits<double>::quiet_NaN()};         // c [m/s^2] >= 0
  double coulomb_asymmetry{0.0};   // dc [m/s^2]
  double viscous_asymmetry{0.0};   // db [1/s]
  double stiction{0.0};            // Delta_s [m/s^2] >= 0
  double stiction_asymmetry{0.0};  // dDelta_s [m/s^2], |dDelta_s| <= Delta_s
};

/// Nominal pendulum model. `length` is required.
struct PendulumAuditParameters {
  double length{std::numeric_limits<double>::quiet_NaN()};  // L [m] > 0
  double damping{0.0};                                      // viscous [1/s] >= 0
  std::optional<double> theta_zero;  // [rad] measured angle of hanging down; empty = estimated
  double gravity{9.80665};           // g [m/s^2] > 0
};

/// The nominal model of one audit; the alternative chooses the plant (index = AuditPlant).
using AuditNominal = std::variant<AxisAuditParameters, PendulumAuditParameters, common::CraneParameters>;

[[nodiscard]] AuditPlant audit_plant(const AuditNominal& nominal) noexcept;
/// "axis", "pendulum" or "crane".
[[nodiscard]] std::string_view plant_name(AuditPlant plant) noexcept;

/// One row of a model's name table: `name` as --param and the report spell it, and the field.
template <class Parameters>
struct ParameterField {
  const char* name;
  const char* unit;
  bool required;                                 // must be given (no default)
  std::optional<double> (*get)(const Parameters&);  // empty: not set (pendulum theta_zero)
  void (*set)(Parameters&, double);
};

/// The name tables. Axis: K_m, b, c (required), coulomb_asymmetry, viscous_asymmetry, stiction,
/// stiction_asymmetry. Pendulum: L (required), damping, theta_zero, gravity. Crane (all required):
/// gravity, load_mass, trolley_drive_mass, trolley_mass, jib_inertia, trolley_drive_gain,
/// slew_drive_gain, and trolley_/slew_ + viscous_positive, viscous_negative, coulomb_positive,
/// coulomb_negative, static_positive, static_negative.
[[nodiscard]] const std::vector<ParameterField<AxisAuditParameters>>& axis_parameter_fields();
[[nodiscard]] const std::vector<ParameterField<PendulumAuditParameters>>& pendulum_parameter_fields();
[[nodiscard]] const std::vector<ParameterField<common::CraneParameters>>& crane_parameter_fields();

/// Parameter names of a plant (axis and pendulum in table order, crane sorted by name).
[[nodiscard]] const std::vector<std::string>& audit_parameter_names(AuditPlant plant);

/// Name -> value of every set field (for the report, the CLI and the generated cases' comment).
[[nodiscard]] std::map<std::string, double> parameter_values(const AuditNominal& nominal);

/// The nominal of `plant` from named values. Throws common::ConfigError for an unknown name (lists
/// the valid ones), a non-finite value, a missing required name, or a value out of its bounds
/// (validate()).
[[nodiscard]] AuditNominal nominal_from_values(AuditPlant plant, const std::map<std::string, double>& values);
/// `base` with the named fields of `values` overridden; throws as nominal_from_values().
[[nodiscard]] AuditNominal override_values(AuditNominal base, const std::map<std::string, double>& values);

/// Throws common::ConfigError naming the field ("param K_m"), the value and the bound: axis K_m > 0,
/// b, c, stiction >= 0, |stiction_asymmetry| <= stiction; pendulum L > 0, damping >= 0, gravity > 0,
/// theta_zero finite; crane common::validate(crane, "param"). Every value finite.
void validate(const AuditNominal& nominal);

/// Axis nominal of a crane drive from its volt-equivalent friction `friction` and drive gain `gain`
/// K_m [m/s^2/V] (trolley) or [rad/s^2/V] (slew): b = K_m (b+ + b-)/2, viscous_asymmetry =
/// K_m (b+ - b-)/2, likewise c and coulomb_asymmetry, and the breakaway excess
/// K_m (max(static, coulomb) - coulomb) of each direction as stiction +- stiction_asymmetry (the
/// plant's rule, axis_friction.hpp).
[[nodiscard]] AxisAuditParameters drive_axis_parameters(const common::AxisFriction& friction, double gain) noexcept;

/// A crane drive in the configuration's terms: volt-equivalent friction and the drive gain.
struct DriveParameters {
  common::AxisFriction friction;  // [V s/m], [V] (slew: [V s/rad], [V])
  double gain{0.0};               // K_m [m/s^2/V] (slew: [rad/s^2/V])
};

/// The inverse of drive_axis_parameters(): gain = K_m, b+- = (b +- viscous_asymmetry)/K_m,
/// c+- = (c +- coulomb_asymmetry)/K_m, static+- = c+- + (stiction +- stiction_asymmetry)/K_m.
/// Throws common::ConfigError naming the field if K_m <= 0 or a resulting coefficient is negative
/// (the configuration's rule, common::validate).
[[nodiscard]] DriveParameters drive_parameters_from_axis(const AxisAuditParameters& axis);

}  // namespace crane::model_audit
