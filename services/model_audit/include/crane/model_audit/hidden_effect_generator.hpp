#pragma once
// Hidden-effect generator for testing the model audit (model_audit.hpp): simulates maneuvers of a
// plant with one catalog effect (audit_models.hpp) drawn at random (seeded, std::mt19937_64) with a
// random magnitude in a realistic range, plus Gaussian sensor noise and encoder quantization.
//
// Axis: the section-3.1 experiment of Omar 2003 (as friction_experiment.hpp): the digital PD loop
// (3.17) V = K (X_ref - x_meas - K_d (x_meas(k) - x_meas(k-1)) / T_s) tracks, after a 4 s slow
// breakaway phase (a reference triangle at 0.03 m/s: stick thresholds and Stribeck speeds), the
// persistently exciting reference (3.18) at T_s = 0.01 s, 16 s in all; the plant is the extended
// axis model integrated with
// 20 substeps per sample. Nominal K_m, b, c are themselves drawn around Tables 3.1-3.5
// (K_m in [1.5, 2.0] m/s^2/V, b/K_m in [2.5, 4.5] V s/m, c/K_m in [0.8, 1.2] V).
// Pendulum: free swings from several initial angles (one maneuver per "segment" id), cable length L
// in [0.5, 3] m, nominal damping in [0.005, 0.03] 1/s, integrated with 20 RK4 substeps per sample.
//
// Magnitude ranges (main parameter first):
//  coulomb_friction_asymmetry dc = +-[0.2, 0.5] c      viscous_friction_asymmetry db = +-[0.15, 0.4] b
//  stiction Delta_s = [0.4, 1.0] c                     stribeck Delta = [0.4, 1.0] c, v_s in [0.02, 0.06] m/s
//  deadzone d = [0.3, 0.8] c/K_m V                     saturation u_max = [0.45, 0.75] max|u| of the nominal run
//  backlash w = [1, 4] mm                              input_delay tau = [5, 25] ms
//  gain_error g = +-[0.1, 0.3]                         position_dependent_friction gamma = +-[0.3, 0.7] c / 0.6 m
//  pendulum_viscous_damping d_v = [0.05, 0.3] 1/s      pendulum_coulomb_damping mu = [0.002, 0.006] g/L rad/s^2
//  pendulum_quadratic_damping q = [0.1, 0.5] 1/rad     cable_length_error e = +-[0.05, 0.15]
//  encoder_offset = +-[0.01, 0.05] rad
// Sensors: axis noise sigma = 5 um, quantum 10 um; pendulum noise 1e-4 rad, quantum 2 pi / 40000 rad.
//
// Crane: the lab tower crane of the configuration (common::CraneParameters defaults = deploy/config/
// lab_tower_crane.yaml) with the load mass drawn in [1, 3] kg and the cable length in [0.6, 1.6] m
// (constant), 18 s at the plant's 100 Hz: a digital PD per drive (trolley 100 V/m, slew 40 V/rad,
// K_d = 0.2 s, as (3.17)) tracks a 4 s breakaway triangle at 0.03 m/s (0.03 rad/s) and then two
// sines per drive (trolley 0.65 m + 0.2 sin(2 pi 0.25 t) - 0.2 sin(2 pi t / 3), slew 0.25 sin(2 pi
// 0.15 t) - 0.25 sin(2 pi 0.3 t): swings up to about 0.3-0.5 rad); commands through the plant's
// DAC (13 bit, +-10 V). Plant: TowerCraneModel's rows with the swing eliminated (crane_swing.hpp)
// and each drive advanced as the extended axis model of audit_models.hpp scaled to its effective
// inertia (the other drive's acceleration from the previous substep), 320 substeps per sample; the
// swing by semi-implicit Euler with the swing entries' damping. Sensors: the plant's encoders
// (drives_and_sensors.hpp: trolley 1.6 um, slew 17 urad, swing 0.26 mrad per count) with a
// Gaussian edge jitter of 0.5 count, recorded as the middle of the count.
// Crane magnitudes: the axis ranges above per drive with c, b the drive's mean Coulomb and viscous
// levels in its own units (slew: [rad]), except viscous_friction_asymmetry db = +-[0.15, 0.3] b (the
// trolley's nominal b- is four times b+; 0.3 b keeps b+ positive), position_dependent_friction over
// 0.6 m (trolley) or 0.5 rad (slew), input_delay rounded to whole substeps (31 us); the pendulum
// ranges with g/L; payload_mass_error: the nominal load mass is off by dm = +-[0.15, 0.4] m_true
// (main parameter load_mass_error = m_true - m_nominal [kg]); encoder_offset on phi;
// wind_force: a steady force of [0.01, 0.05] m g in a direction drawn in [0, 2 pi) (inertial frame;
// the swing's equilibrium moves by 0.6-2.9 deg; main parameter the larger of wind_force_x,
// wind_force_y); hook_double_pendulum: rigging l = [0.15, 0.5] m, hook share s = [0.1, 0.4] of the
// suspended mass M (the drawn load mass; the nominal keeps M, the single pendulum on the cable);
// main parameter rigging_length. With the hook the plant is TowerCraneModel with HookParameters
// (six coordinates, the four swing rows eliminated, the same substeps); elastic_rope: the static
// stretch ratio e_r = m g / EA in [0.01, 0.04] (a soft or long rope: EA = 250 to 2900 N for the
// drawn loads; the lab's rope is 1e-4), the plant TowerCraneModel with RopeParameters (five
// coordinates, the rows phi, theta and the stretch eliminated), started at the static stretch.
// Offline, allocates; throws common::ConfigError for an unknown effect name.

#include <cstdint>
#include <string>
#include <vector>

#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit {

struct HiddenEffectCase {
  std::string effect{"none"};                 // catalog name or "none"
  std::string main_parameter;                 // name as reported by the audit ("" for none)
  double main_value{0.0};                     // true value of the main parameter
  // Crane pairs ("A+B"): the second entry, its main parameter and true value ("none", "", 0 else).
  std::string second_effect{"none"};
  std::string second_main_parameter;
  double second_main_value{0.0};
  AuditNominal nominal;                       // nominal model to pass to the audit
  AuditData data;
};

/// Draws and simulates one case. `effect` = catalog name, "none" (clean), or "random" (uniform over
/// the plant's catalog); crane also "A+B", two distinct entries acting together (each drawn in its
/// range above, A first; not hook_double_pendulum with elastic_rope). `duration` [s] per axis or
/// crane run or per pendulum swing (0 = default). Throws common::ConfigError for a name not in the
/// catalog or a pair that is not allowed.
[[nodiscard]] HiddenEffectCase generate_hidden_effect_case(AuditPlant plant, const std::string& effect,
                                                           std::uint64_t seed, double duration = 0.0);

}  // namespace crane::model_audit
