#include "crane/model_audit/crane_swing.hpp"

#include <Eigen/LU>
#include <cassert>
#include <cmath>

namespace crane::model_audit {

SwingElimination eliminate_swing(const plant::CoordinateMatrix& mass, const plant::CoordinateVector& bias,
                                 const Eigen::Vector2d& swing_extra) noexcept {
  constexpr int kSwing[2] = {plant::kInPlaneSwingIndex, plant::kOutOfPlaneSwingIndex};
  constexpr int kDrive[2] = {plant::kTrolleyIndex, plant::kSlewIndex};
  Eigen::Matrix2d m_ss;
  Eigen::Matrix2d m_sa;
  Eigen::Matrix2d m_as;
  Eigen::Matrix2d m_aa;
  Eigen::Vector2d b_s;
  Eigen::Vector2d b_a;
  for (int r = 0; r < 2; ++r) {
    b_s(r) = bias[kSwing[r]];
    b_a(r) = bias[kDrive[r]];
    for (int c = 0; c < 2; ++c) {
      m_ss(r, c) = mass(kSwing[r], kSwing[c]);
      m_sa(r, c) = mass(kSwing[r], kDrive[c]);
      m_as(r, c) = mass(kDrive[r], kSwing[c]);
      m_aa(r, c) = mass(kDrive[r], kDrive[c]);
    }
  }
  const auto lu = m_ss.partialPivLu();
  SwingElimination e;
  e.swing_gain = -lu.solve(m_sa);
  e.swing_free = -lu.solve(b_s) + swing_extra;
  e.drive_inertia = m_aa + m_as * e.swing_gain;
  e.drive_bias = b_a + m_as * e.swing_free;
  return e;
}

Eigen::Vector2d swing_damping(const SwingEffects& effects, double in_plane_rate, double out_of_plane_rate) noexcept {
  const auto damping = [&](double rate) {
    return -effects.extra_viscous * rate - effects.coulomb * std::tanh(rate / kSwingCoulombRate) -
           effects.quadratic * rate * std::abs(rate);
  };
  return {damping(in_plane_rate), damping(out_of_plane_rate)};
}

void swing_acceleration(const plant::TowerCraneModel& model, const SwingEffects& effects, const SwingState& state,
                        const DriveMotion& motion, double& in_plane_acceleration,
                        double& out_of_plane_acceleration) noexcept {
  using plant::kInPlaneSwingIndex;
  using plant::kOutOfPlaneSwingIndex;
  using plant::kSlewIndex;
  using plant::kTrolleyIndex;
  plant::ModelState q;
  q.position[kTrolleyIndex] = motion.trolley_position;
  q.position[kInPlaneSwingIndex] = state.in_plane;
  q.position[kSlewIndex] = 0.0;  // gamma is cyclic
  q.position[kOutOfPlaneSwingIndex] = state.out_of_plane;
  q.velocity[kTrolleyIndex] = motion.trolley_velocity;
  q.velocity[kInPlaneSwingIndex] = state.in_plane_rate;
  q.velocity[kSlewIndex] = motion.slew_rate;
  q.velocity[kOutOfPlaneSwingIndex] = state.out_of_plane_rate;
  const double scale = 1.0 + effects.length_error;
  const plant::HoistMotion hoist{motion.cable_length * scale, motion.cable_length_rate * scale,
                                 motion.cable_length_acceleration * scale};
  plant::CoordinateMatrix mass;
  plant::CoordinateVector bias;
  model.compute_dynamics(q, hoist, mass, bias);
  const SwingElimination e = eliminate_swing(mass, bias, swing_damping(effects, state.in_plane_rate, state.out_of_plane_rate));
  const Eigen::Vector2d s = e.swing_gain * Eigen::Vector2d(motion.trolley_acceleration, motion.slew_acceleration) + e.swing_free;
  in_plane_acceleration = s(0);
  out_of_plane_acceleration = s(1);
}

void replay_crane_swing(const plant::TowerCraneModel& model, const SwingEffects& effects,
                        std::span<const DriveMotion> motion, double sample_time, std::size_t first, std::size_t count,
                        SwingState initial, int substeps, std::span<double> out) noexcept {
  assert(first + count <= motion.size());
  assert(out.size() >= 2 * count);
  const int steps = substeps < 1 ? 1 : substeps;
  const double h = sample_time / steps;
  SwingState state = initial;
  const auto derivative = [&](const SwingState& s, const DriveMotion& d) {
    double a0 = 0.0;
    double a1 = 0.0;
    swing_acceleration(model, effects, s, d, a0, a1);
    return SwingState{s.in_plane_rate, a0, s.out_of_plane_rate, a1};
  };
  const auto add = [](const SwingState& s, const SwingState& k, double dt) {
    return SwingState{s.in_plane + dt * k.in_plane, s.in_plane_rate + dt * k.in_plane_rate,
                      s.out_of_plane + dt * k.out_of_plane, s.out_of_plane_rate + dt * k.out_of_plane_rate};
  };
  for (std::size_t i = 0; i < count; ++i) {
    out[2 * i] = state.in_plane + effects.encoder_offset;
    out[2 * i + 1] = state.out_of_plane;
    if (i + 1 == count) break;
    const DriveMotion& held = motion[first + i];
    DriveMotion d = held;
    for (int step = 0; step < steps; ++step) {
      // The trolley position follows its held velocity and acceleration within the sample.
      const double tau = step * h;
      d.trolley_position = held.trolley_position + held.trolley_velocity * tau + 0.5 * held.trolley_acceleration * tau * tau;
      d.trolley_velocity = held.trolley_velocity + held.trolley_acceleration * tau;
      d.slew_rate = held.slew_rate + held.slew_acceleration * tau;
      DriveMotion mid = d;
      mid.trolley_position += d.trolley_velocity * 0.5 * h + 0.125 * held.trolley_acceleration * h * h;
      mid.trolley_velocity += 0.5 * h * held.trolley_acceleration;
      mid.slew_rate += 0.5 * h * held.slew_acceleration;
      DriveMotion end = d;
      end.trolley_position += d.trolley_velocity * h + 0.5 * held.trolley_acceleration * h * h;
      end.trolley_velocity += h * held.trolley_acceleration;
      end.slew_rate += h * held.slew_acceleration;
      const SwingState k1 = derivative(state, d);
      const SwingState k2 = derivative(add(state, k1, 0.5 * h), mid);
      const SwingState k3 = derivative(add(state, k2, 0.5 * h), mid);
      const SwingState k4 = derivative(add(state, k3, h), end);
      state.in_plane += h / 6.0 * (k1.in_plane + 2.0 * k2.in_plane + 2.0 * k3.in_plane + k4.in_plane);
      state.in_plane_rate +=
          h / 6.0 * (k1.in_plane_rate + 2.0 * k2.in_plane_rate + 2.0 * k3.in_plane_rate + k4.in_plane_rate);
      state.out_of_plane += h / 6.0 * (k1.out_of_plane + 2.0 * k2.out_of_plane + 2.0 * k3.out_of_plane + k4.out_of_plane);
      state.out_of_plane_rate += h / 6.0 * (k1.out_of_plane_rate + 2.0 * k2.out_of_plane_rate +
                                            2.0 * k3.out_of_plane_rate + k4.out_of_plane_rate);
    }
  }
}

}  // namespace crane::model_audit
