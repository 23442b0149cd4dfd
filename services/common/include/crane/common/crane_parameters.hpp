#pragma once
// Physical parameters of a tower crane (a gantry crane is the same with the slew locked), and the
// bridge of an overhead crane.
//
// Source: H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003, section 4.2 and
// (3.53). Defaults are the dissertation's lab tower crane. All values SI unless the name says
// otherwise. Friction coefficients are kept in the dissertation's "volt-equivalent" form
// (coefficient divided by the motor gain K_m, Tables 3.1-4.2), so the same numbers serve the plant
// and the friction compensator (3.5).

#include <string>

namespace crane::common {

/// Which crane: the config's `crane.kind`, a fact every stage shares (stack_facts.hpp).
enum class CraneKind {
  tower,     // trolley along the jib, slew, hoist, two swings (the lab crane, chapter 4)
  gantry,    // trolley on a rail, hoist, one swing, (2.5)-(2.6): the slew fields are unused
  overhead,  // bridge and trolley at right angles, hoist, two swings: the bridge fields carry the bridge
};
/// "tower", "gantry", "overhead".
[[nodiscard]] const char* to_string(CraneKind kind) noexcept;
/// Parses `text`; throws common::ConfigError naming `field`, the value and the accepted values.
[[nodiscard]] CraneKind crane_kind_from_string(const std::string& text, const std::string& field);

/// Direction-dependent friction of one drive axis, (3.1)-(3.3), in volt-equivalents:
/// a friction force F on an axis with drive gain K_m [accel/V] is stored as F/(mass*K_m) [V].
struct AxisFriction {
  double viscous_positive{0.0};  // [V s/m] or [V s/rad] b+/K_m, velocity > 0
  double viscous_negative{0.0};  // [V s/m] or [V s/rad] b-/K_m, velocity < 0
  double coulomb_positive{0.0};  // [V] c+/K_m, velocity > 0 (opposes the motion)
  double coulomb_negative{0.0};  // [V] c-/K_m, velocity < 0 (opposes the motion)
  double static_positive{0.0};   // [V] fs+/K_m, breakaway threshold toward + (4.13)/(4.15)
  double static_negative{0.0};   // [V] fs-/K_m, breakaway threshold toward -
};

/// Mass properties, drive gains and sensors of the crane.
struct CraneParameters {
  double gravity{9.8};             // [m/s^2] 9.8 reproduces the dissertation's digits (ERRATA)
  double load_mass{2.0};           // [kg] m (section 4.5)
  double cable_length{1.0};        // [m] L, initial cable length
  double min_cable_length{0.2};    // [m] shortest cable the hoist allows (planner targets, controllers'
                                   // floor on the measured L, the plant's hoist stop)
  double max_cable_length{2.0};    // [m] longest cable the hoist allows (sizes the anti-swing delay lines)
  double trolley_drive_mass{22.222};  // [kg] M: mass seen by the trolley drive along the jib,
                                      // trolley plus reflected leadscrew/rotor inertia; m_t = m/M = 0.09
  double trolley_mass{1.93};       // [kg] physical trolley mass (slewing inertia), M_r = M/J_o = 0.27
  double jib_inertia{7.143};       // [kg m^2] J_o about the slew axis; m_r = m/J_o = 0.28
  double trolley_drive_gain{2.0};  // [m/s^2/V] K_mx (4.4): trolley acceleration per volt on mass M
  double slew_drive_gain{1.14};    // [rad/s^2/V] K_mgamma (4.5): slew acceleration per volt on J_o
  AxisFriction trolley_friction{1.5, 6.0, 0.9, 1.2, 1.0, 1.2};   // (4.12), (4.13)
  AxisFriction slew_friction{1.5, 0.05, 0.7, 0.6, 0.7, 0.6};     // (4.16), (4.15)

  // Drives and sensors, section 4.1.
  int dac_bits{13};                     // [bit] analog output resolution
  double dac_range{10.0};               // [V] outputs saturate at +-dac_range
  int motor_encoder_lines{2000};        // [lines/rev] on both motors, read in quadrature (x4)
  int swing_encoder_lines{6000};        // [lines/rev] on both swing axes, read in quadrature (x4)
  double leadscrew_pitch{0.0127 / (2.0 * 3.14159265358979323846)};  // [m/rad] 0.5 in/rev
  double slew_gear_ratio{45.0};         // [-] motor revolutions per jib revolution

  /// m_t = m/M (2.25)
  [[nodiscard]] double mass_ratio() const { return load_mass / trolley_drive_mass; }
  /// m_r = m/J_o (2.25) [1/m^2]
  [[nodiscard]] double load_inertia_ratio() const { return load_mass / jib_inertia; }
  /// M_r = M/J_o (2.25) [1/m^2], with the physical trolley mass
  [[nodiscard]] double trolley_inertia_ratio() const { return trolley_mass / jib_inertia; }
};

/// The bridge of an overhead (bridge) crane: the second horizontal drive axis, at right angles to
/// the trolley's (plant/include/crane/plant/overhead_crane_model.hpp). The trolley rides on the
/// bridge girder; the bridge drive moves girder, end trucks and trolley together.
struct BridgeParameters {
  double drive_mass{60.0};   // [kg] M_y: mass seen by the bridge drive (girder, end trucks, trolley,
                             // reflected drive inertia); > 0
  double drive_gain{2.0};    // [m/s^2/V] K_my: bridge acceleration per volt on mass M_y; > 0
  AxisFriction friction{};   // volt-equivalents as for the trolley ((3.1)-(3.3) with K_my)
};

/// The bridge seen as the trolley of a gantry crane, the way the controllers treat it: the
/// linearized bridge row of the overhead crane, y_dd - m_ty g theta = K_my V_y with
/// L theta_dd + g theta + y_dd = 0 (overhead_crane_model.hpp), is the trolley's (2.7)-(2.8) with
/// phi = -theta, M = M_y, K_mx = K_my and the bridge's friction. Returns `crane` with those
/// replaced (the load, cable and sensors stay the crane's).
[[nodiscard]] CraneParameters bridge_as_trolley(const CraneParameters& crane, const BridgeParameters& bridge) noexcept;

/// Throws crane::common::ConfigError naming the field (prefixed by `prefix`), value and bound
/// if any parameter is non-finite or out of its physical range.
void validate(const CraneParameters& parameters, const char* prefix = "crane");
void validate(const BridgeParameters& bridge, const char* prefix);
void validate(const AxisFriction& friction, const char* prefix);

}  // namespace crane::common
