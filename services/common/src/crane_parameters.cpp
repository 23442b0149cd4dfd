#include "crane/common/crane_parameters.hpp"

#include <string>

#include "crane/common/validation.hpp"

namespace crane::common {

void validate(const AxisFriction& friction, const char* prefix) {
  const std::string p(prefix);
  require_in_range(p + ".viscous_positive", friction.viscous_positive, 0.0, 100.0);
  require_in_range(p + ".viscous_negative", friction.viscous_negative, 0.0, 100.0);
  require_in_range(p + ".coulomb_positive", friction.coulomb_positive, 0.0, 10.0);
  require_in_range(p + ".coulomb_negative", friction.coulomb_negative, 0.0, 10.0);
  require_in_range(p + ".static_positive", friction.static_positive, 0.0, 10.0);
  require_in_range(p + ".static_negative", friction.static_negative, 0.0, 10.0);
}

void validate(const CraneParameters& c, const char* prefix) {
  const std::string p(prefix);
  require_in_range(p + ".gravity", c.gravity, 9.0, 10.5);
  require_in_range(p + ".load_mass", c.load_mass, 0.0, 1.0e5);
  require_in_range(p + ".min_cable_length", c.min_cable_length, 0.05, 200.0);
  require_in_range(p + ".max_cable_length", c.max_cable_length, c.min_cable_length, 200.0);
  require_in_range(p + ".cable_length", c.cable_length, 0.05, 200.0);
  require_greater(p + ".trolley_drive_mass", c.trolley_drive_mass, 0.0);
  require_greater(p + ".trolley_mass", c.trolley_mass, 0.0);
  if (c.trolley_mass > c.trolley_drive_mass) {
    throw ConfigError(p + ".trolley_mass = " + format_value(c.trolley_mass) +
                      " is out of range: must be <= trolley_drive_mass = " + format_value(c.trolley_drive_mass));
  }
  require_greater(p + ".jib_inertia", c.jib_inertia, 0.0);
  require_greater(p + ".trolley_drive_gain", c.trolley_drive_gain, 0.0);
  require_greater(p + ".slew_drive_gain", c.slew_drive_gain, 0.0);
  validate(c.trolley_friction, (p + ".trolley_friction").c_str());
  validate(c.slew_friction, (p + ".slew_friction").c_str());
  require_in_range(p + ".dac_bits", c.dac_bits, 8, 24);
  require_in_range(p + ".dac_range", c.dac_range, 0.1, 100.0);
  require_in_range(p + ".motor_encoder_lines", c.motor_encoder_lines, 1, 1 << 20);
  require_in_range(p + ".swing_encoder_lines", c.swing_encoder_lines, 1, 1 << 20);
  require_greater(p + ".leadscrew_pitch", c.leadscrew_pitch, 0.0);
  require_greater(p + ".slew_gear_ratio", c.slew_gear_ratio, 0.0);
}

void validate(const BridgeParameters& b, const char* prefix) {
  const std::string p(prefix);
  require_greater(p + ".drive_mass", b.drive_mass, 0.0);
  require_greater(p + ".drive_gain", b.drive_gain, 0.0);
  validate(b.friction, (p + ".friction").c_str());
}

const char* to_string(CraneKind kind) noexcept {
  switch (kind) {
    case CraneKind::tower: return "tower";
    case CraneKind::gantry: return "gantry";
    case CraneKind::overhead: return "overhead";
  }
  return "unknown";
}

CraneKind crane_kind_from_string(const std::string& text, const std::string& field) {
  for (const CraneKind kind : {CraneKind::tower, CraneKind::gantry, CraneKind::overhead}) {
    if (text == to_string(kind)) return kind;
  }
  throw ConfigError(field + " = \"" + text + "\" is not a crane kind: must be one of tower, gantry, overhead");
}

CraneParameters bridge_as_trolley(const CraneParameters& crane, const BridgeParameters& bridge) noexcept {
  CraneParameters c = crane;
  c.trolley_drive_mass = bridge.drive_mass;
  c.trolley_drive_gain = bridge.drive_gain;
  c.trolley_friction = bridge.friction;
  return c;
}

}  // namespace crane::common
