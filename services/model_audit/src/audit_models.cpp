#include "crane/model_audit/audit_models.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::model_audit {

void validate(const AxisModel& model) {
  using common::require_at_least;
  common::require_greater("K_m", model.motor_constant, 0.0);
  require_at_least("b", model.viscous, 0.0);
  require_at_least("c", model.coulomb, 0.0);
  common::require_finite("coulomb_asymmetry", model.coulomb_asymmetry);
  common::require_finite("viscous_asymmetry", model.viscous_asymmetry);
  require_at_least("stiction", model.stiction, 0.0);
  common::require_in_range("stiction_asymmetry", model.stiction_asymmetry, -model.stiction, model.stiction);
  require_at_least("stribeck_level", model.stribeck_level, 0.0);
  common::require_greater("stribeck_velocity", model.stribeck_velocity, 0.0);
  require_at_least("deadzone", model.deadzone, 0.0);
  require_at_least("saturation", model.saturation, 0.0);
  require_at_least("backlash", model.backlash, 0.0);
  require_at_least("input_delay", model.input_delay, 0.0);
  common::require_greater("gain_error", model.gain_error, -1.0);
  common::require_finite("position_friction", model.position_friction);
}

double axis_drive_acceleration(const AxisModel& model, double input) noexcept {
  double u = input - std::clamp(input, -model.deadzone, model.deadzone);  // D(u)
  if (model.saturation > 0.0) u = std::clamp(u, -model.saturation, model.saturation);  // S(.)
  return model.motor_constant * (1.0 + model.gain_error) * u;
}

AxisModel scale_axis_inertia(AxisModel m, double ratio) noexcept {
  for (double* v : {&m.motor_constant, &m.viscous, &m.coulomb, &m.coulomb_asymmetry, &m.viscous_asymmetry, &m.stiction,
                    &m.stiction_asymmetry, &m.stribeck_level, &m.position_friction}) {
    *v *= ratio;
  }
  return m;
}

namespace {

// One frozen-coefficient piece: the closed form of advance_friction_axis() with direction-dependent
// b_s, c_s (here c_s already includes the position and Stribeck terms) and breakaway levels.
void advance_piece(double drive, double duration, double b_plus, double b_minus, double c_plus, double c_minus,
                   double break_plus, double break_minus, double& position, double& velocity) noexcept {
  double remaining = duration;
  for (int phase = 0; phase < 4 && remaining > 0.0; ++phase) {
    int direction = velocity > 0.0 ? 1 : (velocity < 0.0 ? -1 : 0);
    if (direction == 0) {
      if (drive > break_plus) {
        direction = 1;
      } else if (drive < -break_minus) {
        direction = -1;
      } else {
        return;  // held by friction
      }
    }
    const double b = direction > 0 ? b_plus : b_minus;
    const double acceleration_constant = drive - (direction > 0 ? c_plus : c_minus) * direction;
    double step = remaining;
    bool stops = false;
    if (b < 1e-12) {  // no viscous friction: constant acceleration
      if (acceleration_constant * direction < 0.0) {
        const double t_stop = -velocity / acceleration_constant;
        if (t_stop <= remaining) {
          step = t_stop;
          stops = true;
        }
      }
      position += velocity * step + 0.5 * acceleration_constant * step * step;
      velocity = stops ? 0.0 : velocity + acceleration_constant * step;
    } else {
      const double v_inf = acceleration_constant / b;
      if (v_inf * direction < 0.0) {
        const double t_stop = std::log1p(-velocity / v_inf) / b;
        if (t_stop <= remaining) {
          step = t_stop;
          stops = true;
        }
      }
      const double decayed = -std::expm1(-b * step);
      position += v_inf * step + (velocity - v_inf) * decayed / b;
      velocity = stops ? 0.0 : v_inf + (velocity - v_inf) * (1.0 - decayed);
    }
    remaining -= step;
  }
}

}  // namespace

void advance_axis(const AxisModel& model, double input, double duration, int substeps, AxisState& state,
                  double external_acceleration) noexcept {
  const double drive = axis_drive_acceleration(model, input) + external_acceleration;
  const int pieces = std::max(substeps, 1);
  const double h = duration / pieces;
  const double half_gap = 0.5 * model.backlash;
  const double b_plus = std::max(0.0, model.viscous + model.viscous_asymmetry);
  const double b_minus = std::max(0.0, model.viscous - model.viscous_asymmetry);
  const double static_extra = model.stribeck_level + model.stiction;
  // Kinetic friction levels c_s(x, x') (position term and Stribeck term included).
  const auto kinetic = [&](double position, double velocity, double& c_plus, double& c_minus) {
    const double position_term = model.position_friction * position;
    const double stribeck =
        model.stribeck_level > 0.0 ? model.stribeck_level * std::exp(-(velocity / model.stribeck_velocity) * (velocity / model.stribeck_velocity))
                                   : 0.0;
    c_plus = std::max(0.0, model.coulomb + model.coulomb_asymmetry + position_term) + stribeck;
    c_minus = std::max(0.0, model.coulomb - model.coulomb_asymmetry + position_term) + stribeck;
  };
  const bool state_dependent = model.stribeck_level > 0.0 || model.position_friction != 0.0;
  for (int i = 0; i < pieces; ++i) {
    double c_plus = 0.0;
    double c_minus = 0.0;
    kinetic(state.position, state.velocity, c_plus, c_minus);
    // Breakaway levels use the static (x' = 0) friction at the piece's start.
    const double break_plus = std::max(0.0, model.coulomb + model.coulomb_asymmetry +
                                                model.position_friction * state.position) + static_extra +
                              model.stiction_asymmetry;
    const double break_minus = std::max(0.0, model.coulomb - model.coulomb_asymmetry +
                                                 model.position_friction * state.position) + static_extra -
                               model.stiction_asymmetry;
    if (state_dependent) {
      // Midpoint rule: freeze the friction at the state of a half piece (closed form with the start
      // values): second order in the piece length instead of first. A half piece that stops keeps
      // the start values (advance_piece locates the stop).
      double mid_position = state.position;
      double mid_velocity = state.velocity;
      advance_piece(drive, 0.5 * h, b_plus, b_minus, c_plus, c_minus, break_plus, break_minus, mid_position,
                    mid_velocity);
      if (mid_velocity * state.velocity > 0.0 || (state.velocity == 0.0 && mid_velocity != 0.0)) {
        kinetic(mid_position, mid_velocity, c_plus, c_minus);
      }
    }
    advance_piece(drive, h, b_plus, b_minus, c_plus, c_minus, break_plus, break_minus, state.position, state.velocity);
    if (model.backlash > 0.0) {
      if (state.position - state.load_position > half_gap) state.load_position = state.position - half_gap;
      if (state.position - state.load_position < -half_gap) state.load_position = state.position + half_gap;
    } else {
      state.load_position = state.position;
    }
  }
}

void replay_axis(const AxisModel& model, std::span<const double> input, double sample_time, std::size_t first,
                 AxisState initial, int substeps, std::span<double> out,
                 std::span<const double> external_acceleration, std::span<const double> inertia_ratio) noexcept {
  assert(first + out.size() <= input.size());
  assert(external_acceleration.empty() || external_acceleration.size() == input.size());
  assert(inertia_ratio.empty() || inertia_ratio.size() == input.size());
  assert(sample_time > 0.0);
  const double delay_samples = model.input_delay / sample_time;
  const auto whole = static_cast<std::ptrdiff_t>(std::floor(delay_samples));
  const double fraction = delay_samples - static_cast<double>(whole);
  const auto last = static_cast<std::ptrdiff_t>(input.size()) - 1;
  const auto held = [&](std::ptrdiff_t index) {
    return input[static_cast<std::size_t>(std::clamp<std::ptrdiff_t>(index, 0, last))];
  };
  AxisState state = initial;
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = state.load_position;
    if (i + 1 == out.size()) break;
    const auto k = static_cast<std::ptrdiff_t>(first + i);
    const double external = external_acceleration.empty() ? 0.0 : external_acceleration[first + i];
    const AxisModel& m = inertia_ratio.empty() ? model : scale_axis_inertia(model, inertia_ratio[first + i]);
    if (fraction > 1e-12) {
      advance_axis(m, held(k - whole - 1), fraction * sample_time, substeps, state, external);
      advance_axis(m, held(k - whole), (1.0 - fraction) * sample_time, substeps, state, external);
    } else {
      advance_axis(m, held(k - whole), sample_time, substeps, state, external);
    }
  }
}

void validate(const PendulumModel& model) {
  common::require_greater("L", model.length, 0.0);
  common::require_at_least("damping", model.damping, 0.0);
  common::require_greater("gravity", model.gravity, 0.0);
  common::require_finite("theta_zero", model.theta_zero);
  common::require_at_least("extra_viscous", model.extra_viscous, -model.damping);
  common::require_at_least("coulomb", model.coulomb, 0.0);
  common::require_at_least("quadratic", model.quadratic, 0.0);
  common::require_greater("length_error", model.length_error, -1.0);
  common::require_finite("encoder_offset", model.encoder_offset);
}

void advance_pendulum(const PendulumModel& model, double trolley_acceleration, double duration, int substeps,
                      PendulumState& state) noexcept {
  const int steps = std::max(substeps, 1);
  const double h = duration / steps;
  const double length = model.length * (1.0 + model.length_error);
  const double viscous = model.damping + model.extra_viscous;
  const auto restoring = [&](double angle) {
    return -(model.gravity * std::sin(angle) + trolley_acceleration * std::cos(angle)) / length;
  };
  const auto rk4 = [&](PendulumState from, double sign, double dt) {
    const auto f = [&](double angle, double rate) {
      return restoring(angle) - viscous * rate - model.coulomb * sign - model.quadratic * rate * std::abs(rate);
    };
    const double k1a = from.rate;
    const double k1r = f(from.angle, from.rate);
    const double k2a = from.rate + 0.5 * dt * k1r;
    const double k2r = f(from.angle + 0.5 * dt * k1a, k2a);
    const double k3a = from.rate + 0.5 * dt * k2r;
    const double k3r = f(from.angle + 0.5 * dt * k2a, k3a);
    const double k4a = from.rate + dt * k3r;
    const double k4r = f(from.angle + dt * k3a, k4a);
    return PendulumState{from.angle + dt / 6.0 * (k1a + 2.0 * k2a + 2.0 * k3a + k4a),
                         from.rate + dt / 6.0 * (k1r + 2.0 * k2r + 2.0 * k3r + k4r)};
  };
  for (int i = 0; i < steps; ++i) {
    double remaining = h;
    for (int piece = 0; piece < 3 && remaining > 0.0; ++piece) {
      double sign = state.rate > 0.0 ? 1.0 : (state.rate < 0.0 ? -1.0 : 0.0);
      if (sign == 0.0 && model.coulomb > 0.0) {
        const double torque = restoring(state.angle);
        if (std::abs(torque) <= model.coulomb) break;  // sticks for the rest of the substep
        sign = torque > 0.0 ? 1.0 : -1.0;
      }
      const PendulumState next = rk4(state, sign, remaining);
      if (model.coulomb > 0.0 && sign != 0.0 && next.rate * sign < 0.0) {
        // The rate reaches zero inside: stop there (linear estimate of the instant, then one
        // RK4 step to it) and let the stick rule decide the rest.
        const double fraction = state.rate / (state.rate - next.rate);
        const double to_stop = std::max(fraction * remaining, 1e-12);
        state = rk4(state, sign, to_stop);
        state.rate = 0.0;
        remaining -= to_stop;
        continue;
      }
      state = next;
      remaining = 0.0;
    }
  }
}

void replay_pendulum(const PendulumModel& model, std::span<const double> trolley_acceleration, double sample_time,
                     std::size_t first, PendulumState initial, int substeps, std::span<double> out) noexcept {
  assert(trolley_acceleration.empty() || first + out.size() <= trolley_acceleration.size());
  PendulumState state = initial;
  const double zero = model.theta_zero + model.encoder_offset;
  for (std::size_t i = 0; i < out.size(); ++i) {
    out[i] = state.angle + zero;
    if (i + 1 == out.size()) break;
    const double a = trolley_acceleration.empty() ? 0.0 : trolley_acceleration[first + i];
    advance_pendulum(model, a, sample_time, substeps, state);
  }
}

}  // namespace crane::model_audit
