// The test's own simulator of the audited plants (independent_simulator.hpp). Shares no code with
// the audit or the plant: its own RK4, stick-slip rule, injections, maneuvers and sensors.
#include "independent_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace crane::model_audit::test {

namespace {

constexpr double kSampleTime = 0.01;  // [s] 100 Hz, both plants
constexpr int kAxisSteps = 400;       // RK4 steps per sample (axis)
constexpr int kPendulumSteps = 40;    // RK4 steps per sample (pendulum)
constexpr double kAxisNoise = 4e-6;   // [m] Gaussian sensor noise
constexpr double kAxisQuantum = 2e-6; // [m] encoder count
constexpr double kPendulumNoise = 1.5e-4;                         // [rad]
constexpr double kPendulumQuantum = 2.0 * std::numbers::pi / 16384;  // [rad] 14-bit encoder
// PD loop (another tuning than section 3.1's K = 100 V/m, K_d = 0.2 s).
constexpr double kProportional = 80.0;  // [V/m]
constexpr double kDerivative = 0.15;    // [s]
constexpr double kCreepSpeed = 0.025;   // [m/s]

double sign(double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); }

// Reference: a slow triangle (breakaways at creep speed, 4.5 s) then three sines faded in over 1 s
// (a smoothstep envelope: no velocity step in the reference, whose PD command spike would be the
// run's one largest command; a saturation drawn relative to it would act on 3-4 samples only).
double reference(double t) {
  if (t < 1.5) return kCreepSpeed * t;
  if (t < 3.0) return kCreepSpeed * (1.5 - (t - 1.5));
  if (t < 4.5) return kCreepSpeed * (t - 3.0);
  const double s = t - 4.5;
  const double w = 2.0 * std::numbers::pi;
  const double fade = s < 1.0 ? s * s * (3.0 - 2.0 * s) : 1.0;
  return kCreepSpeed * 1.5 + fade * (0.25 * std::sin(w * 0.2 * s) + 0.12 * std::sin(w * 0.55 * s + 1.0) -
                                     0.08 * std::sin(w * 0.9 * s));
}

struct AxisPlant {
  const AxisTruth& p;
  // Friction level (without viscous) toward direction s at position x and speed v.
  [[nodiscard]] double kinetic(double s, double x, double v) const {
    const double coulomb = std::max(0.0, p.coulomb + s * p.coulomb_asymmetry + p.position_slope * x);
    const double stribeck = p.stribeck_level > 0.0 ? p.stribeck_level * std::exp(-(v / p.stribeck_velocity) * (v / p.stribeck_velocity)) : 0.0;
    return coulomb + stribeck;
  }
  [[nodiscard]] double breakaway(double s, double x) const {
    return std::max(0.0, p.coulomb + s * p.coulomb_asymmetry + p.position_slope * x) + p.stribeck_level + p.stiction;
  }
  [[nodiscard]] double drive(double u) const {
    double v = u;
    if (p.deadzone > 0.0) v = u - std::clamp(u, -p.deadzone, p.deadzone);
    if (p.saturation > 0.0) v = std::clamp(v, -p.saturation, p.saturation);
    return p.gain * (1.0 + p.gain_error) * v;
  }
  // Acceleration while sliding in direction s (held over an RK4 step).
  [[nodiscard]] double acceleration(double s, double x, double v, double force) const {
    const double b = std::max(0.0, p.viscous + s * p.viscous_asymmetry);
    return force - b * v - s * kinetic(s, x, v);
  }
};

struct AxisState {
  double x{0.0};
  double v{0.0};
  double y{0.0};  // measured side of the play
};

void axis_step(const AxisPlant& plant, double force, double h, AxisState& st) {
  double s = sign(st.v);
  if (s == 0.0) {
    const double d = sign(force);
    if (d == 0.0 || std::abs(force) <= plant.breakaway(d, st.x)) return;  // sticks
    s = d;
  }
  const auto f = [&](double x, double v) { return plant.acceleration(s, x, v, force); };
  const double k1x = st.v, k1v = f(st.x, st.v);
  const double k2x = st.v + 0.5 * h * k1v, k2v = f(st.x + 0.5 * h * k1x, st.v + 0.5 * h * k1v);
  const double k3x = st.v + 0.5 * h * k2v, k3v = f(st.x + 0.5 * h * k2x, st.v + 0.5 * h * k2v);
  const double k4x = st.v + h * k3v, k4v = f(st.x + h * k3x, st.v + h * k3v);
  const double x1 = st.x + h / 6.0 * (k1x + 2 * k2x + 2 * k3x + k4x);
  const double v1 = st.v + h / 6.0 * (k1v + 2 * k2v + 2 * k3v + k4v);
  if (v1 * s < 0.0) {
    // Reversal inside the step: cut where the (linearly interpolated) velocity is zero; rest there.
    const double a = st.v / (st.v - v1);
    st.x += a * (x1 - st.x);
    st.v = 0.0;
  } else {
    st.x = x1;
    st.v = v1;
  }
}

double measure(double value, double noise, double quantum, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  const double m = value + noise * normal(rng);
  return quantum > 0.0 ? quantum * std::round(m / quantum) : m;
}

struct Draw {
  std::mt19937_64 rng;
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  double signed_uniform(double a, double b) { return (uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * uniform(a, b); }
};

constexpr double kAxisDuration = 16.0;

void inject_axis(const std::string& cause, AxisTruth& t, Draw& d, double nominal_max_input) {
  const double c = t.coulomb;
  if (cause.empty() || cause == "none") return;
  if (cause == "coulomb_friction_asymmetry") t.coulomb_asymmetry = d.signed_uniform(0.2, 0.5) * c;
  else if (cause == "viscous_friction_asymmetry") t.viscous_asymmetry = d.signed_uniform(0.15, 0.4) * t.viscous;
  else if (cause == "stiction") t.stiction = d.uniform(0.4, 1.0) * c;
  else if (cause == "stribeck") {
    t.stribeck_level = d.uniform(0.4, 1.0) * c;
    t.stribeck_velocity = d.uniform(0.02, 0.06);
  } else if (cause == "deadzone") t.deadzone = d.uniform(0.3, 0.8) * c / t.gain;
  else if (cause == "saturation") t.saturation = d.uniform(0.45, 0.75) * nominal_max_input;
  else if (cause == "backlash") t.backlash = d.uniform(0.001, 0.004);
  else if (cause == "input_delay") t.delay = d.uniform(0.005, 0.025);
  else if (cause == "gain_error") t.gain_error = d.signed_uniform(0.1, 0.3);
  else if (cause == "position_dependent_friction") t.position_slope = d.signed_uniform(0.3, 0.7) * c / 0.6;
  else throw std::invalid_argument("independent axis: unknown cause " + cause);
}

void inject_pendulum(const std::string& cause, PendulumTruth& t, Draw& d, double nominal_length) {
  const double omega2 = t.gravity / nominal_length;
  if (cause.empty() || cause == "none") return;
  if (cause == "pendulum_viscous_damping") t.extra_viscous = d.uniform(0.05, 0.3);
  else if (cause == "pendulum_coulomb_damping") t.coulomb = d.uniform(0.002, 0.006) * omega2;
  else if (cause == "pendulum_quadratic_damping") t.quadratic = d.uniform(0.1, 0.5);
  else if (cause == "cable_length_error") t.length = nominal_length * (1.0 + d.signed_uniform(0.05, 0.15));
  else if (cause == "encoder_offset") t.offset = d.signed_uniform(0.01, 0.05);
  else throw std::invalid_argument("independent pendulum: unknown cause " + cause);
}

struct PendulumSwing {
  const PendulumTruth& p;
  [[nodiscard]] double acceleration(double s, double a, double r) const {
    return -p.gravity / p.length * std::sin(a) - (p.damping + p.extra_viscous) * r - s * p.coulomb -
           p.quadratic * r * std::abs(r);
  }
  void step(double h, double& a, double& r) const {
    double s = sign(r);
    if (s == 0.0) {
      const double pull = -p.gravity / p.length * std::sin(a);
      if (std::abs(pull) <= p.coulomb || pull == 0.0) return;  // sticks
      s = sign(pull);
    }
    const double k1a = r, k1r = acceleration(s, a, r);
    const double k2a = r + 0.5 * h * k1r, k2r = acceleration(s, a + 0.5 * h * k1a, r + 0.5 * h * k1r);
    const double k3a = r + 0.5 * h * k2r, k3r = acceleration(s, a + 0.5 * h * k2a, r + 0.5 * h * k2r);
    const double k4a = r + h * k3r, k4r = acceleration(s, a + h * k3a, r + h * k3r);
    const double a1 = a + h / 6.0 * (k1a + 2 * k2a + 2 * k3a + k4a);
    const double r1 = r + h / 6.0 * (k1r + 2 * k2r + 2 * k3r + k4r);
    if (r1 * s < 0.0 && p.coulomb > 0.0) {
      const double f0 = r / (r - r1);
      a += f0 * (a1 - a);
      r = 0.0;
    } else {
      a = a1;
      r = r1;
    }
  }
};

}  // namespace

AuditData simulate_axis(const AxisTruth& truth, double duration, std::uint64_t seed, double* max_input) {
  std::mt19937_64 rng(seed);
  const AxisPlant plant{truth};
  const auto samples = static_cast<std::size_t>(std::llround(duration / kSampleTime)) + 1;
  AuditData data;
  data.source = "independent axis (seed " + std::to_string(seed) + ")";
  std::vector<double> commands;
  AxisState st;
  double previous = 0.0;
  double largest = 0.0;
  const double h = kSampleTime / kAxisSteps;
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * kSampleTime;
    const double y = measure(st.y, kAxisNoise, kAxisQuantum, rng);
    const double rate = k == 0 ? 0.0 : (y - previous) / kSampleTime;
    previous = y;
    const double u = kProportional * (reference(t) - y - kDerivative * rate);
    commands.push_back(u);
    largest = std::max(largest, std::abs(u));
    data.time.push_back(t);
    data.input.push_back(u);
    data.output.push_back(y);
    for (int i = 0; i < kAxisSteps; ++i) {
      // The command acting at the middle of this step: the one issued at or before (t - tau).
      const double at = t + (i + 0.5) * h - truth.delay;
      const auto index = at <= 0.0 ? std::size_t{0} : std::min(k, static_cast<std::size_t>(std::floor(at / kSampleTime + 1e-12)));
      axis_step(plant, plant.drive(commands[index]), h, st);
      const double half = 0.5 * truth.backlash;
      if (st.x - st.y > half) st.y = st.x - half;
      if (st.x - st.y < -half) st.y = st.x + half;
    }
  }
  if (max_input != nullptr) *max_input = largest;
  return data;
}

AuditData simulate_free_swings(const PendulumTruth& truth, const double* starts, int swings, double swing_duration,
                               double sample_time, double noise, double quantum, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  const PendulumSwing swing{truth};
  const auto per_swing = static_cast<std::size_t>(std::llround(swing_duration / sample_time));
  const double h = sample_time / kPendulumSteps;
  AuditData data;
  data.source = "independent free swing (seed " + std::to_string(seed) + ")";
  double t = 0.0;
  for (int s = 0; s < swings; ++s) {
    double a = starts[s];
    double r = 0.0;
    for (std::size_t k = 0; k < per_swing; ++k) {
      data.time.push_back(t);
      data.output.push_back(measure(a + truth.zero + truth.offset, noise, quantum, rng));
      data.segment.push_back(static_cast<double>(s));
      for (int i = 0; i < kPendulumSteps; ++i) swing.step(h, a, r);
      t += sample_time;
    }
  }
  return data;
}

IndependentCase independent_axis_case(const std::string& cause, std::uint64_t seed, const std::string& second_cause) {
  Draw d{std::mt19937_64(seed * 7919 + 17)};
  AxisTruth truth;
  truth.gain = d.uniform(1.4, 2.1);
  truth.viscous = d.uniform(2.5, 4.0) * truth.gain;
  truth.coulomb = d.uniform(0.8, 1.2) * truth.gain;
  IndependentCase out;
  out.cause = cause;
  out.second_cause = second_cause;
  out.nominal = AxisAuditParameters{truth.gain, truth.viscous, truth.coulomb};
  double nominal_max = 0.0;
  if (cause == "saturation" || second_cause == "saturation") (void)simulate_axis(truth, kAxisDuration, seed, &nominal_max);
  inject_axis(cause, truth, d, nominal_max);
  inject_axis(second_cause, truth, d, nominal_max);
  out.data = simulate_axis(truth, kAxisDuration, seed);
  out.data.source += " " + cause + (second_cause.empty() ? "" : "+" + second_cause);
  return out;
}

IndependentCase independent_pendulum_case(const std::string& cause, std::uint64_t seed, const std::string& second_cause) {
  Draw d{std::mt19937_64(seed * 104729 + 3)};
  PendulumTruth truth;
  const double nominal_length = d.uniform(0.4, 2.5);
  truth.length = nominal_length;
  truth.damping = d.uniform(0.005, 0.03);
  inject_pendulum(cause, truth, d, nominal_length);
  inject_pendulum(second_cause, truth, d, nominal_length);
  IndependentCase out;
  out.cause = cause;
  out.second_cause = second_cause;
  PendulumAuditParameters nominal;
  nominal.length = nominal_length;
  nominal.damping = truth.damping;
  nominal.theta_zero = truth.zero;
  out.nominal = nominal;
  const double starts[3] = {d.uniform(0.12, 0.25), -d.uniform(0.3, 0.5), d.uniform(0.55, 0.8)};
  out.data = simulate_free_swings(truth, starts, 3, 8.0, kSampleTime, kPendulumNoise, kPendulumQuantum, seed);
  out.data.source += " " + cause + (second_cause.empty() ? "" : "+" + second_cause);
  return out;
}

IndependentCase long_coulomb_swing(double start, double length, double damping, double coulomb, double duration,
                                   double noise, double rate, std::uint64_t seed) {
  PendulumTruth truth;
  truth.length = length;
  truth.damping = damping;
  truth.coulomb = coulomb;
  IndependentCase out;
  out.cause = coulomb > 0.0 ? "pendulum_coulomb_damping" : "none";
  PendulumAuditParameters nominal;
  nominal.length = length;
  nominal.damping = damping;
  nominal.theta_zero = truth.zero;
  out.nominal = nominal;
  const double starts[1] = {start};
  out.data = simulate_free_swings(truth, starts, 1, duration, 1.0 / rate, noise, 2.0 * std::numbers::pi / 4096, seed);
  out.data.segment.clear();
  return out;
}

}  // namespace crane::model_audit::test
