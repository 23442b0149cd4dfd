#include "crane/model_audit/audit_parameters.hpp"

#include <algorithm>
#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::model_audit {

namespace {

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) out += (out.empty() ? "" : ", ") + n;
  return out;
}

template <class P>
std::vector<std::string> names_of(const std::vector<ParameterField<P>>& fields) {
  std::vector<std::string> out;
  for (const auto& f : fields) out.emplace_back(f.name);
  return out;
}

template <class P>
std::map<std::string, double> values_of(const P& parameters, const std::vector<ParameterField<P>>& fields) {
  std::map<std::string, double> out;
  for (const auto& f : fields) {
    if (const auto value = f.get(parameters)) out[f.name] = *value;
  }
  return out;
}

// Sets the named fields of `parameters`; with `require`, every required field must be named.
template <class P>
void set_values(P& parameters, const std::vector<ParameterField<P>>& fields, AuditPlant plant,
                const std::map<std::string, double>& values, bool require) {
  for (const auto& [name, value] : values) {
    const auto it = std::find_if(fields.begin(), fields.end(), [&](const auto& f) { return name == f.name; });
    if (it == fields.end()) {
      throw common::ConfigError("param: unknown parameter '" + name + "' for model " +
                                std::string(plant_name(plant)) + " (valid: " + join(audit_parameter_names(plant)) + ")");
    }
    common::require_finite("param " + name, value);
    it->set(parameters, value);
  }
  if (!require) return;
  for (const auto& name : audit_parameter_names(plant)) {
    const auto it = std::find_if(fields.begin(), fields.end(), [&](const auto& f) { return name == f.name; });
    if (it->required && !values.contains(name)) {
      throw common::ConfigError("param: nominal parameter '" + name + "' of model " + std::string(plant_name(plant)) +
                                " is missing (give --param " + name + "=VALUE)");
    }
  }
}

}  // namespace

AuditPlant audit_plant(const AuditNominal& nominal) noexcept { return static_cast<AuditPlant>(nominal.index()); }

std::string_view plant_name(AuditPlant plant) noexcept {
  return plant == AuditPlant::axis ? "axis" : plant == AuditPlant::pendulum ? "pendulum" : "crane";
}

const std::vector<ParameterField<AxisAuditParameters>>& axis_parameter_fields() {
  using P = AxisAuditParameters;
  static const std::vector<ParameterField<P>> fields{
      {"K_m", "m/s^2/V", true, [](const P& p) -> std::optional<double> { return p.motor_constant; },
       [](P& p, double v) { p.motor_constant = v; }},
      {"b", "1/s", true, [](const P& p) -> std::optional<double> { return p.viscous; }, [](P& p, double v) { p.viscous = v; }},
      {"c", "m/s^2", true, [](const P& p) -> std::optional<double> { return p.coulomb; }, [](P& p, double v) { p.coulomb = v; }},
      {"coulomb_asymmetry", "m/s^2", false, [](const P& p) -> std::optional<double> { return p.coulomb_asymmetry; },
       [](P& p, double v) { p.coulomb_asymmetry = v; }},
      {"viscous_asymmetry", "1/s", false, [](const P& p) -> std::optional<double> { return p.viscous_asymmetry; },
       [](P& p, double v) { p.viscous_asymmetry = v; }},
      {"stiction", "m/s^2", false, [](const P& p) -> std::optional<double> { return p.stiction; },
       [](P& p, double v) { p.stiction = v; }},
      {"stiction_asymmetry", "m/s^2", false, [](const P& p) -> std::optional<double> { return p.stiction_asymmetry; },
       [](P& p, double v) { p.stiction_asymmetry = v; }}};
  return fields;
}

const std::vector<ParameterField<PendulumAuditParameters>>& pendulum_parameter_fields() {
  using P = PendulumAuditParameters;
  static const std::vector<ParameterField<P>> fields{
      {"L", "m", true, [](const P& p) -> std::optional<double> { return p.length; }, [](P& p, double v) { p.length = v; }},
      {"damping", "1/s", false, [](const P& p) -> std::optional<double> { return p.damping; },
       [](P& p, double v) { p.damping = v; }},
      {"theta_zero", "rad", false, [](const P& p) { return p.theta_zero; }, [](P& p, double v) { p.theta_zero = v; }},
      {"gravity", "m/s^2", false, [](const P& p) -> std::optional<double> { return p.gravity; },
       [](P& p, double v) { p.gravity = v; }}};
  return fields;
}

// Crane: scalar fields, then the six volt-equivalent friction levels of each drive.
#define CRANE_SCALAR(NAME, UNIT)                                                                  \
  ParameterField<P>{#NAME, UNIT, true, [](const P& p) -> std::optional<double> { return p.NAME; }, \
                    [](P& p, double v) { p.NAME = v; }}
#define CRANE_FRICTION(AXIS, FIELD, UNIT)                                                                     \
  ParameterField<P>{#AXIS "_" #FIELD, UNIT, true,                                                             \
                    [](const P& p) -> std::optional<double> { return p.AXIS##_friction.FIELD; },               \
                    [](P& p, double v) { p.AXIS##_friction.FIELD = v; }}

const std::vector<ParameterField<common::CraneParameters>>& crane_parameter_fields() {
  using P = common::CraneParameters;
  static const std::vector<ParameterField<P>> fields{
      CRANE_SCALAR(gravity, "m/s^2"),
      CRANE_SCALAR(load_mass, "kg"),
      CRANE_SCALAR(trolley_drive_mass, "kg"),
      CRANE_SCALAR(trolley_mass, "kg"),
      CRANE_SCALAR(jib_inertia, "kg m^2"),
      CRANE_SCALAR(trolley_drive_gain, "m/s^2/V"),
      CRANE_SCALAR(slew_drive_gain, "rad/s^2/V"),
      CRANE_FRICTION(trolley, viscous_positive, "V s/m"),
      CRANE_FRICTION(trolley, viscous_negative, "V s/m"),
      CRANE_FRICTION(trolley, coulomb_positive, "V"),
      CRANE_FRICTION(trolley, coulomb_negative, "V"),
      CRANE_FRICTION(trolley, static_positive, "V"),
      CRANE_FRICTION(trolley, static_negative, "V"),
      CRANE_FRICTION(slew, viscous_positive, "V s/rad"),
      CRANE_FRICTION(slew, viscous_negative, "V s/rad"),
      CRANE_FRICTION(slew, coulomb_positive, "V"),
      CRANE_FRICTION(slew, coulomb_negative, "V"),
      CRANE_FRICTION(slew, static_positive, "V"),
      CRANE_FRICTION(slew, static_negative, "V")};
  return fields;
}

#undef CRANE_SCALAR
#undef CRANE_FRICTION

const std::vector<std::string>& audit_parameter_names(AuditPlant plant) {
  static const std::vector<std::string> axis = names_of(axis_parameter_fields());
  static const std::vector<std::string> pendulum = names_of(pendulum_parameter_fields());
  static const std::vector<std::string> crane = [] {
    auto names = names_of(crane_parameter_fields());
    std::sort(names.begin(), names.end());
    return names;
  }();
  return plant == AuditPlant::axis ? axis : plant == AuditPlant::pendulum ? pendulum : crane;
}

std::map<std::string, double> parameter_values(const AuditNominal& nominal) {
  return std::visit(
      [](const auto& p) -> std::map<std::string, double> {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, AxisAuditParameters>) return values_of(p, axis_parameter_fields());
        else if constexpr (std::is_same_v<P, PendulumAuditParameters>) return values_of(p, pendulum_parameter_fields());
        else return values_of(p, crane_parameter_fields());
      },
      nominal);
}

namespace {

AuditNominal set_and_validate(AuditNominal nominal, const std::map<std::string, double>& values, bool require) {
  const AuditPlant plant = audit_plant(nominal);
  std::visit(
      [&](auto& p) {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, AxisAuditParameters>) set_values(p, axis_parameter_fields(), plant, values, require);
        else if constexpr (std::is_same_v<P, PendulumAuditParameters>) {
          set_values(p, pendulum_parameter_fields(), plant, values, require);
        } else {
          set_values(p, crane_parameter_fields(), plant, values, require);
        }
      },
      nominal);
  validate(nominal);
  return nominal;
}

}  // namespace

AuditNominal nominal_from_values(AuditPlant plant, const std::map<std::string, double>& values) {
  const AuditNominal empty = plant == AuditPlant::axis       ? AuditNominal{AxisAuditParameters{}}
                             : plant == AuditPlant::pendulum ? AuditNominal{PendulumAuditParameters{}}
                                                             : AuditNominal{common::CraneParameters{}};
  return set_and_validate(empty, values, true);
}

AuditNominal override_values(AuditNominal base, const std::map<std::string, double>& values) {
  return set_and_validate(std::move(base), values, false);
}

void validate(const AuditNominal& nominal) {
  if (const auto* axis = std::get_if<AxisAuditParameters>(&nominal)) {
    for (const auto& f : axis_parameter_fields()) common::require_finite(std::string("param ") + f.name, *f.get(*axis));
    common::require_greater("param K_m", axis->motor_constant, 0.0);
    common::require_at_least("param b", axis->viscous, 0.0);
    common::require_at_least("param c", axis->coulomb, 0.0);
    common::require_at_least("param stiction", axis->stiction, 0.0);
    common::require_in_range("param stiction_asymmetry", axis->stiction_asymmetry, -axis->stiction, axis->stiction);
  } else if (const auto* pendulum = std::get_if<PendulumAuditParameters>(&nominal)) {
    for (const auto& f : pendulum_parameter_fields()) {
      if (const auto value = f.get(*pendulum)) common::require_finite(std::string("param ") + f.name, *value);
    }
    common::require_greater("param L", pendulum->length, 0.0);
    common::require_at_least("param damping", pendulum->damping, 0.0);
    common::require_greater("param gravity", pendulum->gravity, 0.0);
  } else {
    common::validate(std::get<common::CraneParameters>(nominal), "param");
  }
}

AxisAuditParameters drive_axis_parameters(const common::AxisFriction& f, double gain) noexcept {
  const double excess_plus = std::max(f.static_positive, f.coulomb_positive) - f.coulomb_positive;
  const double excess_minus = std::max(f.static_negative, f.coulomb_negative) - f.coulomb_negative;
  AxisAuditParameters p;
  p.motor_constant = gain;
  p.viscous = gain * 0.5 * (f.viscous_positive + f.viscous_negative);
  p.viscous_asymmetry = gain * 0.5 * (f.viscous_positive - f.viscous_negative);
  p.coulomb = gain * 0.5 * (f.coulomb_positive + f.coulomb_negative);
  p.coulomb_asymmetry = gain * 0.5 * (f.coulomb_positive - f.coulomb_negative);
  p.stiction = gain * 0.5 * (excess_plus + excess_minus);
  p.stiction_asymmetry = gain * 0.5 * (excess_plus - excess_minus);
  return p;
}

DriveParameters drive_parameters_from_axis(const AxisAuditParameters& axis) {
  common::require_greater("K_m", axis.motor_constant, 0.0);
  const double k = axis.motor_constant;
  DriveParameters d;
  d.gain = k;
  auto& f = d.friction;
  f.viscous_positive = (axis.viscous + axis.viscous_asymmetry) / k;
  f.viscous_negative = (axis.viscous - axis.viscous_asymmetry) / k;
  f.coulomb_positive = (axis.coulomb + axis.coulomb_asymmetry) / k;
  f.coulomb_negative = (axis.coulomb - axis.coulomb_asymmetry) / k;
  f.static_positive = f.coulomb_positive + (axis.stiction + axis.stiction_asymmetry) / k;
  f.static_negative = f.coulomb_negative + (axis.stiction - axis.stiction_asymmetry) / k;
  for (const auto& [name, value] : {std::pair{"viscous_positive", f.viscous_positive}, std::pair{"viscous_negative", f.viscous_negative},
                                    std::pair{"coulomb_positive", f.coulomb_positive}, std::pair{"coulomb_negative", f.coulomb_negative}}) {
    common::require_at_least(name, value, 0.0);
  }
  return d;
}

}  // namespace crane::model_audit
