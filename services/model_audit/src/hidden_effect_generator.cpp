#include "crane/model_audit/hidden_effect_generator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include "crane/common/validation.hpp"
#include "crane/model_audit/audit_models.hpp"

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

}  // namespace

HiddenEffectCase generate_hidden_effect_case(AuditPlant plant, const std::string& effect, std::uint64_t seed,
                                             double duration) {
  std::mt19937_64 rng(seed * 7919 + 17);
  const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
  const auto signed_uniform = [&](double a, double b) { return (uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * uniform(a, b); };
  const auto& catalog = audit_catalog(plant);
  HiddenEffectCase out;
  out.effect = effect;
  if (effect == "random") {
    out.effect = catalog[std::uniform_int_distribution<std::size_t>(0, catalog.size() - 1)(rng)];
  } else if (effect != "none" && std::find(catalog.begin(), catalog.end(), effect) == catalog.end()) {
    throw common::ConfigError("effect: '" + effect + "' is not in the catalog");
  }
  const std::string& e = out.effect;

  if (plant == AuditPlant::axis) {
    AxisModel model;
    model.motor_constant = uniform(1.5, 2.0);
    model.viscous = uniform(2.5, 4.5) * model.motor_constant;
    model.coulomb = uniform(0.8, 1.2) * model.motor_constant;
    out.nominal = {{"K_m", model.motor_constant}, {"b", model.viscous}, {"c", model.coulomb}};
    const double c = model.coulomb;
    const double b = model.viscous;
    const Sensor sensor{5e-6, 1e-5};
    const double length = duration > 0.0 ? duration : kCreepDuration + 12.0;
    if (e == "coulomb_friction_asymmetry") {
      model.coulomb_asymmetry = signed_uniform(0.2, 0.5) * c;
      out.main_parameter = "coulomb_asymmetry";
      out.main_value = model.coulomb_asymmetry;
    } else if (e == "viscous_friction_asymmetry") {
      model.viscous_asymmetry = signed_uniform(0.15, 0.4) * b;
      out.main_parameter = "viscous_asymmetry";
      out.main_value = model.viscous_asymmetry;
    } else if (e == "stiction") {
      model.stiction = uniform(0.4, 1.0) * c;
      out.main_parameter = "stiction";
      out.main_value = model.stiction;
    } else if (e == "stribeck") {
      model.stribeck_level = uniform(0.4, 1.0) * c;
      model.stribeck_velocity = uniform(0.02, 0.06);
      out.main_parameter = "stribeck_level";
      out.main_value = model.stribeck_level;
    } else if (e == "deadzone") {
      model.deadzone = uniform(0.3, 0.8) * c / model.motor_constant;
      out.main_parameter = "deadzone";
      out.main_value = model.deadzone;
    } else if (e == "saturation") {
      const double max_input = run_axis(model, length, sensor, seed, nullptr);
      model.saturation = uniform(0.45, 0.75) * max_input;
      out.main_parameter = "saturation";
      out.main_value = model.saturation;
    } else if (e == "backlash") {
      model.backlash = uniform(0.001, 0.004);
      out.main_parameter = "backlash";
      out.main_value = model.backlash;
    } else if (e == "input_delay") {
      model.input_delay = uniform(0.005, 0.025);
      out.main_parameter = "input_delay";
      out.main_value = model.input_delay;
    } else if (e == "gain_error") {
      model.gain_error = signed_uniform(0.1, 0.3);
      out.main_parameter = "gain_error";
      out.main_value = model.gain_error;
    } else if (e == "position_dependent_friction") {
      model.position_friction = signed_uniform(0.3, 0.7) * c / 0.6;
      out.main_parameter = "position_friction_slope";
      out.main_value = model.position_friction;
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
  out.nominal = {{"L", model.length}, {"damping", model.damping}, {"theta_zero", zero}};
  if (e == "pendulum_viscous_damping") {
    model.extra_viscous = uniform(0.05, 0.3);
    out.main_parameter = "extra_viscous_damping";
    out.main_value = model.extra_viscous;
  } else if (e == "pendulum_coulomb_damping") {
    model.coulomb = uniform(0.002, 0.006) * model.gravity / model.length;
    out.main_parameter = "coulomb_damping";
    out.main_value = model.coulomb;
  } else if (e == "pendulum_quadratic_damping") {
    model.quadratic = uniform(0.1, 0.5);
    out.main_parameter = "quadratic_damping";
    out.main_value = model.quadratic;
  } else if (e == "cable_length_error") {
    model.length_error = signed_uniform(0.05, 0.15);
    out.main_parameter = "length_error";
    out.main_value = model.length_error;
  } else if (e == "encoder_offset") {
    model.encoder_offset = signed_uniform(0.01, 0.05);
    out.main_parameter = "encoder_offset";
    out.main_value = model.encoder_offset;
  }
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
