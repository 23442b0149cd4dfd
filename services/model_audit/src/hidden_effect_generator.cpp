#include "crane/model_audit/hidden_effect_generator.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <functional>
#include <numbers>
#include <random>

#include "crane/common/validation.hpp"
#include <Eigen/LU>

#include "crane/model_audit/audit_models.hpp"
#include "crane/model_audit/crane_swing.hpp"
#include "crane/plant/drives_and_sensors.hpp"
#include "crane/plant/tower_crane_model.hpp"

namespace crane::model_audit {

namespace {

struct Sensor {
  double noise{0.0};
  double quantum{0.0};
};

double measure(double value, const Sensor& sensor, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  double m = value + sensor.noise * normal(rng);
  if (sensor.quantum > 0.0) m = sensor.quantum * std::round(m / sensor.quantum);
  return m;
}

// Breakaway (creep) phase before the section-3.1 reference: a triangle at kCreepSpeed with legs
// of 1, 1.5 and 1.5 s. While the axis sticks at a reversal the PD command ramps by only
// K kCreepSpeed T_s = 0.03 V per sample, so each breakaway brackets the stick threshold to 0.03 V
// (the fast (3.18) reversals ramp by 0.2-0.4 V per sample), and the slow legs show the friction
// at speeds of the order of a Stribeck velocity. A friction audit would ask for such a slow run.
constexpr double kCreepSpeed = 0.03;   // [m/s]
constexpr double kCreepDuration = 4.0;  // [s]

double axis_reference(double t) {
  if (t < 1.0) return kCreepSpeed * t;
  if (t < 2.5) return kCreepSpeed * (1.0 - (t - 1.0));
  if (t < kCreepDuration) return kCreepSpeed * (-0.5 + (t - 2.5));
  const double s = t - kCreepDuration;
  return kCreepSpeed + 0.3 * std::sin(2.0 * std::numbers::pi * 0.25 * s) -
         0.4 * std::sin(2.0 * std::numbers::pi * s / 3.0);  // (3.18)
}

// Closed-loop section-3.1 run; returns the max |u| when `record` is false.
double run_axis(const AxisModel& model, double duration, const Sensor& sensor, std::uint64_t seed, AuditData* record) {
  constexpr double kSampleTime = 0.01;
  constexpr double kGain = 100.0;          // K [V/m] (3.17)
  constexpr double kDerivativeTime = 0.2;  // K_d [s]
  constexpr int kSubsteps = 20;
  std::mt19937_64 rng(seed);
  const auto samples = static_cast<std::size_t>(std::llround(duration / kSampleTime)) + 1;
  const double delay_samples = model.input_delay / kSampleTime;
  const auto whole = static_cast<std::ptrdiff_t>(std::floor(delay_samples));
  const double fraction = delay_samples - static_cast<double>(whole);
  std::vector<double> inputs;
  AxisState state;
  double previous = 0.0;
  double max_input = 0.0;
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * kSampleTime;
    const double measured = measure(state.load_position, sensor, rng);
    const double velocity = k == 0 ? 0.0 : (measured - previous) / kSampleTime;
    previous = measured;
    const double reference = axis_reference(t);
    const double u = kGain * (reference - measured - kDerivativeTime * velocity);
    inputs.push_back(u);
    max_input = std::max(max_input, std::abs(u));
    if (record != nullptr) {
      record->time.push_back(t);
      record->input.push_back(u);
      record->output.push_back(measured);
    }
    const auto held = [&](std::ptrdiff_t i) { return inputs[static_cast<std::size_t>(std::max<std::ptrdiff_t>(i, 0))]; };
    const auto kk = static_cast<std::ptrdiff_t>(k);
    if (fraction > 1e-12) {
      advance_axis(model, held(kk - whole - 1), fraction * kSampleTime, kSubsteps, state);
      advance_axis(model, held(kk - whole), (1.0 - fraction) * kSampleTime, kSubsteps, state);
    } else {
      advance_axis(model, held(kk - whole), kSampleTime, kSubsteps, state);
    }
  }
  return max_input;
}

using Uniform = std::function<double(double, double)>;

struct AxisScales {
  double coulomb{0.0};        // c [m/s^2] (slew: [rad/s^2])
  double viscous{0.0};        // b [1/s]
  double span{0.6};           // [m] (slew: [rad]) travel over which position-dependent friction changes by gamma span
  double unit{1.0};           // 1 m (trolley, axis) or 1 rad (slew): scales v_s and the backlash
  double viscous_fraction{0.4};  // largest |db| / b drawn
};

struct Drawn {
  std::string parameter;  // main parameter as the audit reports it
  double value{0.0};      // saturation: the fraction of the nominal run's largest |u| (the caller scales)
};

// Draws the magnitude of one axis catalog entry (ranges in hidden_effect_generator.hpp) into `model`.
Drawn draw_axis_effect(const std::string& e, AxisModel& model, const AxisScales& s, const Uniform& uniform,
                       const Uniform& signed_uniform) {
  const double c = s.coulomb;
  if (e == "coulomb_friction_asymmetry") {
    const double dc = signed_uniform(0.2, 0.5) * c;
    model.coulomb_asymmetry += dc;
    return {"coulomb_asymmetry", dc};
  }
  if (e == "viscous_friction_asymmetry") {
    const double db = signed_uniform(0.15, s.viscous_fraction) * s.viscous;
    model.viscous_asymmetry += db;
    return {"viscous_asymmetry", db};
  }
  if (e == "stiction") {
    const double extra = uniform(0.4, 1.0) * c;
    model.stiction += extra;
    return {"stiction", extra};
  }
  if (e == "stribeck") {
    model.stribeck_level = uniform(0.4, 1.0) * c;
    model.stribeck_velocity = uniform(0.02, 0.06) * s.unit;
    return {"stribeck_level", model.stribeck_level};
  }
  if (e == "deadzone") {
    model.deadzone = uniform(0.3, 0.8) * c / model.motor_constant;
    return {"deadzone", model.deadzone};
  }
  if (e == "saturation") return {"saturation", uniform(0.45, 0.75)};
  if (e == "backlash") {
    model.backlash = uniform(0.001, 0.004) * s.unit;
    return {"backlash", model.backlash};
  }
  if (e == "input_delay") {
    model.input_delay = uniform(0.005, 0.025);
    return {"input_delay", model.input_delay};
  }
  if (e == "gain_error") {
    model.gain_error = signed_uniform(0.1, 0.3);
    return {"gain_error", model.gain_error};
  }
  if (e == "position_dependent_friction") {
    model.position_friction = signed_uniform(0.3, 0.7) * c / s.span;
    return {"position_friction_slope", model.position_friction};
  }
  return {"", 0.0};
}

// Draws the magnitude of one pendulum catalog entry into `model` (PendulumModel or SwingEffects:
// the same field names); `omega2` = g / L [1/s^2].
template <typename Model>
Drawn draw_pendulum_effect(const std::string& e, Model& model, double omega2, const Uniform& uniform,
                           const Uniform& signed_uniform) {
  if (e == "pendulum_viscous_damping") {
    model.extra_viscous = uniform(0.05, 0.3);
    return {"extra_viscous_damping", model.extra_viscous};
  }
  if (e == "pendulum_coulomb_damping") {
    model.coulomb = uniform(0.002, 0.006) * omega2;
    return {"coulomb_damping", model.coulomb};
  }
  if (e == "pendulum_quadratic_damping") {
    model.quadratic = uniform(0.1, 0.5);
    return {"quadratic_damping", model.quadratic};
  }
  if (e == "cable_length_error") {
    model.length_error = signed_uniform(0.05, 0.15);
    return {"length_error", model.length_error};
  }
  if (e == "encoder_offset") {
    model.encoder_offset = signed_uniform(0.01, 0.05);
    return {"encoder_offset", model.encoder_offset};
  }
  return {"", 0.0};
}

// ---------------------------------------------------------------------------------------------
// Crane.

constexpr double kCraneSampleTime = 0.01;  // [s] the plant's cycle
constexpr int kCraneSubsteps = 320;
constexpr double kTrolleyGain = 100.0;     // [V/m] trolley PD (3.17)
constexpr double kSlewGain = 40.0;         // [V/rad] slew PD
constexpr double kDerivativeTime = 0.2;    // [s] K_d of both PDs
constexpr double kTrolleyCentre = 0.65;    // [m]

// Creep triangle (as the axis run) then two sines per drive; the slew's differ in period from the
// trolley's so that the two drives are not in phase.
double crane_trolley_reference(double t) {
  if (t < kCreepDuration) return kTrolleyCentre + axis_reference(t);
  const double s = t - kCreepDuration;
  return kTrolleyCentre + kCreepSpeed + 0.2 * std::sin(2.0 * std::numbers::pi * 0.25 * s) -
         0.2 * std::sin(2.0 * std::numbers::pi * s / 3.0);
}

double crane_slew_reference(double t) {
  if (t < kCreepDuration) return axis_reference(t);
  const double s = t - kCreepDuration;
  return kCreepSpeed + 0.25 * std::sin(2.0 * std::numbers::pi * 0.15 * s) - 0.25 * std::sin(2.0 * std::numbers::pi * 0.3 * s);
}

struct CraneTruth {
  common::CraneParameters crane;  // true plant (load mass and cable length as simulated)
  AxisModel trolley;              // nominal friction plus the drawn entry, [m/s^2] on M_drive
  AxisModel slew;                 // [rad/s^2] on J_o
  SwingEffects swing;
};

// Closed-loop run of the crane (see the header). Returns max |u| of each drive (x, gamma) when
// `record` is null.
std::pair<double, double> run_crane(const CraneTruth& truth, double duration, std::uint64_t seed, AuditData* record) {
  const plant::TowerCraneModel model([&] {
    common::CraneParameters p = truth.crane;
    p.cable_length = truth.crane.cable_length * (1.0 + truth.swing.length_error);
    return p;
  }());
  // A hook or an elastic rope: the extended rows (slots 4 and 5: the rigging, or the stretch).
  const bool hooked = truth.swing.rigging_length > 0.0;
  const bool roped = !hooked && truth.swing.rope_stretch_ratio > 0.0;
  const std::optional<plant::TowerCraneModel> hook =
      hooked  ? std::optional<plant::TowerCraneModel>(hooked_model(model.parameters(), truth.swing))
      : roped ? std::optional<plant::TowerCraneModel>(roped_model(model.parameters(), truth.swing))
              : std::nullopt;
  const bool extended_rows = hook.has_value();
  const plant::DrivesAndSensors sensors(truth.crane);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> normal(0.0, 0.5);  // encoder edge jitter [counts]
  const auto read = [&](double value, double resolution) {  // the middle of the count
    return (std::floor(value / resolution + normal(rng)) + 0.5) * resolution;
  };
  const double length = truth.crane.cable_length * (1.0 + truth.swing.length_error);
  const plant::HoistMotion hoist{length, 0.0, 0.0};
  const auto samples = static_cast<std::size_t>(std::llround(duration / kCraneSampleTime)) + 1;
  const double h = kCraneSampleTime / kCraneSubsteps;
  AxisState trolley;
  trolley.position = trolley.load_position = kTrolleyCentre;
  AxisState slew;
  SwingState swing;
  if (roped) {  // the rope starts stretched by the load's weight, at rest (slot 4)
    swing.rigging_in_plane = hook->parameters().load_mass * hook->parameters().gravity * length / hook->rope().axial_stiffness;
  }
  double trolley_acceleration = 0.0;
  double slew_acceleration = 0.0;
  std::vector<double> u_x;
  std::vector<double> u_gamma;
  double previous_x = kTrolleyCentre;
  double previous_gamma = 0.0;
  std::pair<double, double> max_input{0.0, 0.0};
  using plant::kInPlaneSwingIndex;
  using plant::kOutOfPlaneSwingIndex;
  using plant::kSlewIndex;
  using plant::kTrolleyIndex;
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * kCraneSampleTime;
    const double x = read(trolley.load_position, sensors.trolley_resolution());
    const double gamma = read(slew.load_position, sensors.slew_resolution());
    const double phi = read(swing.in_plane, sensors.swing_resolution()) + truth.swing.encoder_offset;
    const double theta = read(swing.out_of_plane, sensors.swing_resolution());
    const double v_x = k == 0 ? 0.0 : (x - previous_x) / kCraneSampleTime;
    const double v_gamma = k == 0 ? 0.0 : (gamma - previous_gamma) / kCraneSampleTime;
    previous_x = x;
    previous_gamma = gamma;
    u_x.push_back(sensors.applied_voltage(kTrolleyGain * (crane_trolley_reference(t) - x - kDerivativeTime * v_x)));
    u_gamma.push_back(sensors.applied_voltage(kSlewGain * (crane_slew_reference(t) - gamma - kDerivativeTime * v_gamma)));
    max_input.first = std::max(max_input.first, std::abs(u_x.back()));
    max_input.second = std::max(max_input.second, std::abs(u_gamma.back()));
    if (record != nullptr) {
      record->time.push_back(t);
      record->input.push_back(u_x.back());
      record->output.push_back(x);
      record->slew_input.push_back(u_gamma.back());
      record->slew_angle.push_back(gamma);
      record->swing_in_plane.push_back(phi);
      record->swing_out_of_plane.push_back(theta);
      record->cable_length.push_back(truth.crane.cable_length);
    }
    // Delayed commands: u(t - tau) is u[j] on [t_j, t_j+1); a delay splits the sample at fraction * T.
    const auto held = [&](const std::vector<double>& u, double delay, double at) {
      const auto j = static_cast<std::ptrdiff_t>(std::floor((t + at - delay) / kCraneSampleTime + 1e-9));
      return u[static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(j, 0, static_cast<std::ptrdiff_t>(k)))];
    };
    for (int i = 0; i < kCraneSubsteps; ++i) {
      const double at = (i + 0.5) * h;  // delays are whole substeps: a substep never straddles a sample edge
      // Swing rows eliminated (with the swing entries' damping and the wind's generalized force):
      // s'' = S a'' + s0, M_eff a'' + b_eff = Q; s = (phi, theta) or, with the hook, (phi, theta, phi2, theta2).
      const Eigen::Vector2d damping = swing_damping(truth.swing, swing.in_plane_rate, swing.out_of_plane_rate);
      plant::ExtendedState extended;
      extended.position << trolley.position, swing.in_plane, slew.position, swing.out_of_plane, swing.rigging_in_plane,
          swing.rigging_out_of_plane;
      extended.velocity << trolley.velocity, swing.in_plane_rate, slew.velocity, swing.out_of_plane_rate,
          swing.rigging_in_plane_rate, swing.rigging_out_of_plane_rate;
      const HookedSwingElimination e =
          eliminate_swing_at(extended_rows ? *hook : model, truth.swing, extended, hoist, damping);
      const Eigen::Matrix<double, 4, 2>& swing_gain = e.swing_gain;
      const Eigen::Vector4d& swing_free = e.swing_free;
      const Eigen::Matrix2d& m_eff = e.drive_inertia;
      const Eigen::Vector2d& b_eff = e.drive_bias;
      // Each drive with its own effective inertia; the small cross term from the other drive's
      // acceleration of the previous substep.
      const double ratio_x = truth.crane.trolley_drive_mass / m_eff(0, 0);
      const double ratio_g = truth.crane.jib_inertia / m_eff(1, 1);
      const double ext_x = -(b_eff(0) + m_eff(0, 1) * slew_acceleration) / m_eff(0, 0);
      const double ext_g = -(b_eff(1) + m_eff(1, 0) * trolley_acceleration) / m_eff(1, 1);
      const double v_x0 = trolley.velocity;
      const double v_g0 = slew.velocity;
      advance_axis(scale_axis_inertia(truth.trolley, ratio_x), held(u_x, truth.trolley.input_delay, at), h, 1, trolley, ext_x);
      advance_axis(scale_axis_inertia(truth.slew, ratio_g), held(u_gamma, truth.slew.input_delay, at), h, 1, slew, ext_g);
      trolley_acceleration = (trolley.velocity - v_x0) / h;
      slew_acceleration = (slew.velocity - v_g0) / h;
      const Eigen::Vector4d s_dd = swing_gain * Eigen::Vector2d(trolley_acceleration, slew_acceleration) + swing_free;
      swing.in_plane_rate += h * s_dd(0);
      swing.out_of_plane_rate += h * s_dd(1);
      swing.in_plane += h * swing.in_plane_rate;
      swing.out_of_plane += h * swing.out_of_plane_rate;
      if (extended_rows) {
        swing.rigging_in_plane_rate += h * s_dd(2);
        swing.rigging_out_of_plane_rate += h * s_dd(3);
        swing.rigging_in_plane += h * swing.rigging_in_plane_rate;
        swing.rigging_out_of_plane += h * swing.rigging_out_of_plane_rate;
      }
    }
  }
  return max_input;
}

// Draws the magnitude of one crane catalog entry `e` into `truth` (and `nominal` for the payload).
Drawn draw_crane_effect(const std::string& e, CraneTruth& truth, common::CraneParameters& nominal, double length,
                        std::uint64_t seed, const Uniform& uniform, const Uniform& signed_uniform) {
  const std::string trolley_prefix = "trolley_";
  const std::string slew_prefix = "slew_";
  Drawn drawn;
  if (e.rfind(trolley_prefix, 0) == 0 || e.rfind(slew_prefix, 0) == 0) {
    const bool on_trolley = e.rfind(trolley_prefix, 0) == 0;
    const std::string entry = e.substr(on_trolley ? trolley_prefix.size() : slew_prefix.size());
    AxisModel& axis = on_trolley ? truth.trolley : truth.slew;
    // Trolley: the lab crane's b- is four times b+, so |db| <= 0.3 b keeps b+ = b + db > 0.
    drawn = draw_axis_effect(entry, axis, {axis.coulomb, axis.viscous, on_trolley ? 0.6 : 0.5, 1.0, 0.3}, uniform,
                             signed_uniform);
    if (entry == "input_delay") {  // whole substeps, so that no substep straddles a delayed sample edge
      const double h = kCraneSampleTime / kCraneSubsteps;
      axis.input_delay = std::round(axis.input_delay / h) * h;
      drawn.value = axis.input_delay;
    }
    if (entry == "saturation") {
      const auto [max_x, max_gamma] = run_crane(truth, length, seed, nullptr);
      axis.saturation = drawn.value * (on_trolley ? max_x : max_gamma);
      drawn.value = axis.saturation;
    }
  } else if (e == "payload_mass_error") {
    const double dm = -signed_uniform(0.15, 0.4) * truth.crane.load_mass;  // the nominal is off by -dm
    nominal.load_mass = truth.crane.load_mass - dm;
    drawn = {"load_mass_error", dm};
  } else if (e == "wind_force") {
    const double force = uniform(0.01, 0.05) * truth.crane.load_mass * truth.crane.gravity;
    const double direction = uniform(0.0, 2.0 * std::numbers::pi);
    truth.swing.wind_force_x = force * std::cos(direction);
    truth.swing.wind_force_y = force * std::sin(direction);
    drawn = std::abs(truth.swing.wind_force_x) >= std::abs(truth.swing.wind_force_y)
                ? Drawn{"wind_force_x", truth.swing.wind_force_x}
                : Drawn{"wind_force_y", truth.swing.wind_force_y};
  } else if (e == "hook_double_pendulum") {
    truth.swing.rigging_length = uniform(0.15, 0.5);
    truth.swing.hook_mass_share = uniform(0.1, 0.4);
    drawn = {"rigging_length", truth.swing.rigging_length};
  } else if (e == "elastic_rope") {
    truth.swing.rope_stretch_ratio = uniform(0.01, 0.04);
    drawn = {"rope_stretch_ratio", truth.swing.rope_stretch_ratio};
  } else if (e != "none") {
    drawn = draw_pendulum_effect(e, truth.swing, truth.crane.gravity / truth.crane.cable_length, uniform, signed_uniform);
  }
  return drawn;
}

// `effects`: one or two catalog entries (or "none"), drawn in this order.
HiddenEffectCase generate_crane_case(const std::vector<std::string>& effects, std::uint64_t seed, double duration,
                                     const Uniform& uniform, const Uniform& signed_uniform) {
  HiddenEffectCase out;
  CraneTruth truth;
  truth.crane.load_mass = uniform(1.0, 3.0);
  truth.crane.cable_length = uniform(0.6, 1.6);
  common::CraneParameters nominal = truth.crane;
  const auto axis_truth = [](const common::AxisFriction& f, double gain) {
    const AxisAuditParameters p = drive_axis_parameters(f, gain);
    AxisModel m;
    m.motor_constant = p.motor_constant;
    m.viscous = p.viscous;
    m.viscous_asymmetry = p.viscous_asymmetry;
    m.coulomb = p.coulomb;
    m.coulomb_asymmetry = p.coulomb_asymmetry;
    m.stiction = p.stiction;
    m.stiction_asymmetry = p.stiction_asymmetry;
    return m;
  };
  truth.trolley = axis_truth(truth.crane.trolley_friction, truth.crane.trolley_drive_gain);
  truth.slew = axis_truth(truth.crane.slew_friction, truth.crane.slew_drive_gain);
  const double length = duration > 0.0 ? duration : kCreepDuration + 14.0;
  const Drawn first = draw_crane_effect(effects.front(), truth, nominal, length, seed, uniform, signed_uniform);
  out.effect = effects.front();
  out.main_parameter = first.parameter;
  out.main_value = first.value;
  if (effects.size() > 1) {
    const Drawn second = draw_crane_effect(effects[1], truth, nominal, length, seed, uniform, signed_uniform);
    out.second_effect = effects[1];
    out.second_main_parameter = second.parameter;
    out.second_main_value = second.value;
  }
  out.nominal = nominal;
  out.data.source = "generated crane case (seed " + std::to_string(seed) + ", effect " + out.effect +
                    (effects.size() > 1 ? " + " + out.second_effect : std::string()) + ")";
  run_crane(truth, length, seed, &out.data);
  return out;
}

}  // namespace

HiddenEffectCase generate_hidden_effect_case(AuditPlant plant, const std::string& effect, std::uint64_t seed,
                                             double duration) {
  std::mt19937_64 rng(seed * 7919 + 17);
  const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const auto signed_uniform = [&](double a, double b) { return (uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * uniform(a, b); };
  const auto& catalog = audit_catalog(plant);
  HiddenEffectCase out;
  out.effect = effect;
  const auto in_catalog = [&](const std::string& name) {
    return std::find(catalog.begin(), catalog.end(), name) != catalog.end();
  };
  if (const std::size_t plus = effect.find('+'); plus != std::string::npos) {  // a pair (crane only)
    const std::string first = effect.substr(0, plus);
    const std::string second = effect.substr(plus + 1);
    if (plant != AuditPlant::crane) throw common::ConfigError("effect: a pair '" + effect + "' is for the crane only");
    for (const auto& name : {first, second}) {
      if (!in_catalog(name)) throw common::ConfigError("effect: '" + name + "' (in '" + effect + "') is not in the catalog");
    }
    if (first == second) throw common::ConfigError("effect: the pair '" + effect + "' names one entry twice");
    const std::vector<std::string> extended_rows = {"hook_double_pendulum", "elastic_rope"};
    if (std::count_if(extended_rows.begin(), extended_rows.end(),
                      [&](const std::string& name) { return name == first || name == second; }) == 2) {
      throw common::ConfigError("effect: the pair '" + effect + "': the generator's plant has a hook or an elastic rope, not both");
    }
    return generate_crane_case({first, second}, seed, duration, uniform, signed_uniform);
  }
  if (effect == "random") {
    out.effect = catalog[std::uniform_int_distribution<std::size_t>(0, catalog.size() - 1)(rng)];
  } else if (effect != "none" && !in_catalog(effect)) {
    throw common::ConfigError("effect: '" + effect + "' is not in the catalog");
  }
  const std::string& e = out.effect;
  if (plant == AuditPlant::crane) return generate_crane_case({e}, seed, duration, uniform, signed_uniform);

  if (plant == AuditPlant::axis) {
    AxisModel model;
    model.motor_constant = uniform(1.5, 2.0);
    model.viscous = uniform(2.5, 4.5) * model.motor_constant;
    model.coulomb = uniform(0.8, 1.2) * model.motor_constant;
    AxisAuditParameters nominal;
    nominal.motor_constant = model.motor_constant;
    nominal.viscous = model.viscous;
    nominal.coulomb = model.coulomb;
    out.nominal = nominal;
    const double c = model.coulomb;
    const double b = model.viscous;
    const Sensor sensor{5e-6, 1e-5};
    const double length = duration > 0.0 ? duration : kCreepDuration + 12.0;
    const Drawn drawn = draw_axis_effect(e, model, {c, b, 0.6, 1.0, 0.4}, uniform, signed_uniform);
    out.main_parameter = drawn.parameter;
    out.main_value = drawn.value;
    if (e == "saturation") {  // a fraction of the largest command of the nominal run
      model.saturation = drawn.value * run_axis(model, length, sensor, seed, nullptr);
      out.main_value = model.saturation;
    }
    out.data.source = "generated axis case (seed " + std::to_string(seed) + ", effect " + e + ")";
    run_axis(model, length, sensor, seed, &out.data);
    return out;
  }

  PendulumModel model;
  model.length = uniform(0.5, 3.0);
  model.damping = uniform(0.005, 0.03);
  const double zero = std::numbers::pi;
  model.theta_zero = zero;
  PendulumAuditParameters nominal;
  nominal.length = model.length;
  nominal.damping = model.damping;
  nominal.theta_zero = zero;
  out.nominal = nominal;
  const Drawn drawn = draw_pendulum_effect(e, model, model.gravity / model.length, uniform, signed_uniform);
  out.main_parameter = drawn.parameter;
  out.main_value = drawn.value;
  constexpr double kSampleTime = 0.01;
  const Sensor sensor{1e-4, 2.0 * std::numbers::pi / 40000.0};
  const double swing = duration > 0.0 ? duration : 6.0;
  const auto per_swing = static_cast<std::size_t>(std::llround(swing / kSampleTime));
  const double starts[3] = {uniform(0.1, 0.2), -uniform(0.3, 0.45), uniform(0.5, 0.7)};
  std::mt19937_64 noise_rng(seed);
  double t = 0.0;
  for (int s = 0; s < 3; ++s) {
    PendulumState state{starts[s], 0.0};
    for (std::size_t k = 0; k < per_swing; ++k) {
      out.data.time.push_back(t);
      out.data.output.push_back(measure(state.angle + model.theta_zero + model.encoder_offset, sensor, noise_rng));
      out.data.segment.push_back(static_cast<double>(s));
      advance_pendulum(model, 0.0, kSampleTime, 20, state);
      t += kSampleTime;
    }
  }
  out.data.source = "generated pendulum case (seed " + std::to_string(seed) + ", effect " + e + ")";
  return out;
}

}  // namespace crane::model_audit
