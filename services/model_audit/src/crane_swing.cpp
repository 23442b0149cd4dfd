#include "crane/model_audit/crane_swing.hpp"

#include <Eigen/LU>
#include <cassert>
#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

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

HookedSwingElimination eliminate_hooked_swing(const plant::ExtendedMatrix& mass, const plant::ExtendedVector& bias,
                                              const Eigen::Vector2d& swing_extra) noexcept {
  constexpr int kSwing[4] = {plant::kInPlaneSwingIndex, plant::kOutOfPlaneSwingIndex, plant::kRiggingInPlaneIndex,
                             plant::kRiggingOutOfPlaneIndex};
  constexpr int kDrive[2] = {plant::kTrolleyIndex, plant::kSlewIndex};
  Eigen::Matrix4d m_ss;
  Eigen::Matrix<double, 4, 2> m_sa;
  Eigen::Matrix<double, 2, 4> m_as;
  Eigen::Matrix2d m_aa;
  Eigen::Vector4d b_s;
  Eigen::Vector2d b_a;
  for (int r = 0; r < 4; ++r) {
    b_s(r) = bias[kSwing[r]];
    for (int c = 0; c < 4; ++c) m_ss(r, c) = mass(kSwing[r], kSwing[c]);
    for (int c = 0; c < 2; ++c) {
      m_sa(r, c) = mass(kSwing[r], kDrive[c]);
      m_as(c, r) = mass(kDrive[c], kSwing[r]);
    }
  }
  for (int r = 0; r < 2; ++r) {
    b_a(r) = bias[kDrive[r]];
    for (int c = 0; c < 2; ++c) m_aa(r, c) = mass(kDrive[r], kDrive[c]);
  }
  const auto lu = m_ss.partialPivLu();
  HookedSwingElimination e;
  e.swing_gain = -lu.solve(m_sa);
  e.swing_free = -lu.solve(b_s);
  e.swing_free.head<2>() += swing_extra;
  e.drive_inertia = m_aa + m_as * e.swing_gain;
  e.drive_bias = b_a + m_as * e.swing_free;
  return e;
}

HookedSwingElimination eliminate_swing_at(const plant::TowerCraneModel& model, const SwingEffects& effects,
                                          const plant::ExtendedState& state, const plant::HoistMotion& hoist,
                                          const Eigen::Vector2d& swing_extra) noexcept {
  if (model.coordinate_count() > plant::kNumCoordinates) {
    plant::ExtendedMatrix mass;
    plant::ExtendedVector bias;
    model.compute_extended_dynamics(state, hoist, mass, bias);
    bias -= wind_generalized_force(model, effects, state, hoist);
    return eliminate_hooked_swing(mass, bias, swing_extra);
  }
  plant::ModelState q;
  q.position = state.position.head<plant::kNumCoordinates>();
  q.velocity = state.velocity.head<plant::kNumCoordinates>();
  plant::CoordinateMatrix mass;
  plant::CoordinateVector bias;
  model.compute_dynamics(q, hoist, mass, bias);
  if (effects.wind_force_x != 0.0 || effects.wind_force_y != 0.0) {
    bias -= wind_generalized_force(model, effects, state, hoist).head<plant::kNumCoordinates>();
  }
  const SwingElimination e = eliminate_swing(mass, bias, swing_extra);
  HookedSwingElimination out;
  out.swing_gain.setZero();
  out.swing_gain.topRows<2>() = e.swing_gain;
  out.swing_free.setZero();
  out.swing_free.head<2>() = e.swing_free;
  out.drive_inertia = e.drive_inertia;
  out.drive_bias = e.drive_bias;
  return out;
}

plant::TowerCraneModel hooked_model(const common::CraneParameters& suspended, const SwingEffects& effects) {
  common::CraneParameters p = suspended;
  const double total = suspended.load_mass > 0.0 ? suspended.load_mass : 1.0;
  const double share = std::clamp(effects.hook_mass_share, kMinHookMassShare, kMaxHookMassShare);
  plant::HookParameters hook;
  hook.enabled = true;
  hook.rigging_length = std::clamp(effects.rigging_length, kMinRiggingLength, kMaxRiggingLength);
  hook.hook_mass = share * total;
  p.load_mass = (1.0 - share) * total;
  return plant::TowerCraneModel(p, hook);
}

plant::TowerCraneModel roped_model(const common::CraneParameters& suspended, const SwingEffects& effects) {
  common::CraneParameters p = suspended;
  if (!(p.load_mass > 0.0)) p.load_mass = 1.0;
  plant::RopeParameters rope;
  rope.enabled = true;
  rope.axial_stiffness =
      p.load_mass * p.gravity / std::clamp(effects.rope_stretch_ratio, kMinRopeStretchRatio, kMaxRopeStretchRatio);
  return plant::TowerCraneModel(p, {}, rope);
}

plant::ExtendedVector wind_generalized_force(const plant::TowerCraneModel& model, const SwingEffects& effects,
                                             const plant::ExtendedState& state,
                                             const plant::HoistMotion& hoist) noexcept {
  if (effects.wind_force_x == 0.0 && effects.wind_force_y == 0.0) return plant::ExtendedVector::Zero();
  return model.load_force(state, hoist, effects.wind_force_x, effects.wind_force_y);
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
  q.position[kSlewIndex] = motion.slew_angle;  // cyclic: only the wind's direction depends on it
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
  if (effects.wind_force_x != 0.0 || effects.wind_force_y != 0.0) {
    plant::ExtendedState extended;
    extended.position.head<plant::kNumCoordinates>() = q.position;
    extended.velocity.head<plant::kNumCoordinates>() = q.velocity;
    bias -= wind_generalized_force(model, effects, extended, hoist).head<plant::kNumCoordinates>();
  }
  const SwingElimination e = eliminate_swing(mass, bias, swing_damping(effects, state.in_plane_rate, state.out_of_plane_rate));
  const Eigen::Vector2d s = e.swing_gain * Eigen::Vector2d(motion.trolley_acceleration, motion.slew_acceleration) + e.swing_free;
  in_plane_acceleration = s(0);
  out_of_plane_acceleration = s(1);
}

namespace {

using SwingVector = Eigen::Matrix<double, 8, 1>;  // phi, phi', theta, theta', phi2, phi2', theta2, theta2'

// Swing accelerations of the hooked model (phi'', theta'', phi2'', theta2''), or of the roped one
// (phi'', theta'', s'', 0).
Eigen::Vector4d hooked_acceleration(const plant::TowerCraneModel& model, const SwingEffects& effects,
                                    const SwingVector& s, const DriveMotion& motion) noexcept {
  plant::ExtendedState q;
  q.position << motion.trolley_position, s(0), motion.slew_angle, s(2), s(4), s(6);
  q.velocity << motion.trolley_velocity, s(1), motion.slew_rate, s(3), s(5), s(7);
  const double scale = 1.0 + effects.length_error;
  const plant::HoistMotion hoist{motion.cable_length * scale, motion.cable_length_rate * scale,
                                 motion.cable_length_acceleration * scale};
  plant::ExtendedMatrix mass;
  plant::ExtendedVector bias;
  model.compute_extended_dynamics(q, hoist, mass, bias);
  bias -= wind_generalized_force(model, effects, q, hoist);
  // The swing rows only (eliminate_hooked_swing without the drive rows): s'' = -M_ss^-1 (M_sa a'' + b_s).
  constexpr int kSwing[4] = {plant::kInPlaneSwingIndex, plant::kOutOfPlaneSwingIndex, plant::kRiggingInPlaneIndex,
                             plant::kRiggingOutOfPlaneIndex};
  Eigen::Matrix4d m_ss;
  Eigen::Vector4d rhs;
  for (int r = 0; r < 4; ++r) {
    rhs(r) = bias[kSwing[r]] + mass(kSwing[r], plant::kTrolleyIndex) * motion.trolley_acceleration +
             mass(kSwing[r], plant::kSlewIndex) * motion.slew_acceleration;
    for (int c = 0; c < 4; ++c) m_ss(r, c) = mass(kSwing[r], kSwing[c]);
  }
  Eigen::Vector4d acceleration = -(m_ss.inverse() * rhs);  // closed-form 4x4 inverse (M_ss is regular for |theta| < pi/2)
  acceleration.head<2>() += swing_damping(effects, s(1), s(3));
  return acceleration;
}

}  // namespace

namespace {

// One sample of the swing replay: classical RK4 with the drive and hoist motion held (the trolley
// position and the slew angle following their held rates and accelerations within the sample), the
// hooked or roped model built once (noexcept: the clamped hook and rope parameters are within the
// model's bounds; both go through the extended rows, slots 4 and 5: the rigging's angles, or the
// stretch and an unused slot).
class SwingStepper {
 public:
  SwingStepper(const plant::TowerCraneModel& model, const SwingEffects& effects, double first_length, double sample_time,
               int substeps)
      : model_(model), effects_(effects) {
    const bool hooked = effects.rigging_length > 0.0;
    const bool roped = !hooked && effects.rope_stretch_ratio > 0.0;
    if (hooked) extended_.emplace(hooked_model(model.parameters(), effects));
    if (roped) extended_.emplace(roped_model(model.parameters(), effects));
    int steps = substeps < 1 ? 1 : substeps;
    if (roped) {
      // The load's bounce on the rope, sqrt(k / m) = sqrt(g / (e_r L)): h omega <= 0.3 as for the hook.
      const double omega = std::sqrt(extended_->parameters().gravity /
                                     (std::clamp(effects.rope_stretch_ratio, kMinRopeStretchRatio, kMaxRopeStretchRatio) *
                                      first_length));
      if (std::isfinite(omega)) steps = std::max(steps, static_cast<int>(std::ceil(omega * sample_time / 0.3)));
      static_stretch_ = extended_->parameters().load_mass * extended_->parameters().gravity * first_length /
                        extended_->rope().axial_stiffness;
    }
    if (hooked) {
      // The rigging's mode is fast for a short rigging or a light hook: at least as many RK4 steps as
      // keep h omega_2 <= 0.3 (omega_2 of the double pendulum at rest, at the first sample's length).
      const common::CraneParameters& p = extended_->parameters();
      const double omega = plant::double_pendulum_frequencies(first_length, extended_->hook().rigging_length,
                                                              extended_->hook().hook_mass, p.load_mass, p.gravity)
                               .second;
      if (std::isfinite(omega)) steps = std::max(steps, static_cast<int>(std::ceil(omega * sample_time / 0.3)));
    }
    steps_ = steps;
    h_ = sample_time / steps;
  }

  // The rope's stretch at rest under the load's weight at the first sample's length [m] (0 without a rope).
  [[nodiscard]] double static_stretch() const noexcept { return static_stretch_; }

  // Advances `state` over one sample with `held`; false (the state left at its last step inside the
  // domain) when a step leaves the model's domain: a fit may try parameters or initial states far from the data, so a
  // swing beyond 1.5 rad (the model is singular at pi/2) or a non-finite state is held where it
  // was, and the prediction stays finite (and far from the data).
  bool advance(SwingVector& state, const DriveMotion& held) const noexcept {
    DriveMotion d = held;
    const double h = h_;
    for (int step = 0; step < steps_; ++step) {
      const double tau = step * h;
      d.trolley_position = held.trolley_position + held.trolley_velocity * tau + 0.5 * held.trolley_acceleration * tau * tau;
      d.trolley_velocity = held.trolley_velocity + held.trolley_acceleration * tau;
      d.slew_angle = held.slew_angle + held.slew_rate * tau + 0.5 * held.slew_acceleration * tau * tau;
      d.slew_rate = held.slew_rate + held.slew_acceleration * tau;
      DriveMotion mid = d;
      mid.trolley_position += d.trolley_velocity * 0.5 * h + 0.125 * held.trolley_acceleration * h * h;
      mid.trolley_velocity += 0.5 * h * held.trolley_acceleration;
      mid.slew_angle += d.slew_rate * 0.5 * h + 0.125 * held.slew_acceleration * h * h;
      mid.slew_rate += 0.5 * h * held.slew_acceleration;
      DriveMotion end = d;
      end.trolley_position += d.trolley_velocity * h + 0.5 * held.trolley_acceleration * h * h;
      end.trolley_velocity += h * held.trolley_acceleration;
      end.slew_angle += d.slew_rate * h + 0.5 * held.slew_acceleration * h * h;
      end.slew_rate += h * held.slew_acceleration;
      const SwingVector k1 = derivative(state, d);
      const SwingVector k2 = derivative(state + 0.5 * h * k1, mid);
      const SwingVector k3 = derivative(state + 0.5 * h * k2, mid);
      const SwingVector k4 = derivative(state + h * k3, end);
      const SwingVector next = state + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      if (!next.allFinite() || std::abs(next(0)) > 1.5 || std::abs(next(2)) > 1.5 || std::abs(next(4)) > 1.5 ||
          std::abs(next(6)) > 1.5) {
        return false;
      }
      state = next;
    }
    return true;
  }

 private:
  SwingVector derivative(const SwingVector& s, const DriveMotion& d) const noexcept {
    SwingVector k = SwingVector::Zero();
    k(0) = s(1);
    k(2) = s(3);
    if (extended_) {
      const Eigen::Vector4d a = hooked_acceleration(*extended_, effects_, s, d);
      k(1) = a(0);
      k(3) = a(1);
      k(4) = s(5);
      k(5) = a(2);
      k(6) = s(7);
      k(7) = a(3);
    } else {
      const SwingState single{s(0), s(1), s(2), s(3)};
      swing_acceleration(model_, effects_, single, d, k(1), k(3));
    }
    return k;
  }

  const plant::TowerCraneModel& model_;
  const SwingEffects& effects_;
  std::optional<plant::TowerCraneModel> extended_;
  double static_stretch_{0.0};
  int steps_{1};
  double h_{0.0};
};

}  // namespace

void replay_crane_swing(const plant::TowerCraneModel& model, const SwingEffects& effects,
                        std::span<const DriveMotion> motion, double sample_time, std::size_t first, std::size_t count,
                        SwingState initial, int substeps, std::span<double> out) noexcept {
  assert(first + count <= motion.size());
  assert(out.size() >= 2 * count);
  const bool roped = effects.rigging_length <= 0.0 && effects.rope_stretch_ratio > 0.0;
  const SwingStepper stepper(model, effects, motion[first].cable_length * (1.0 + effects.length_error), sample_time,
                             substeps);
  SwingVector state;
  state << initial.in_plane, initial.in_plane_rate, initial.out_of_plane, initial.out_of_plane_rate,
      initial.rigging_in_plane, initial.rigging_in_plane_rate, initial.rigging_out_of_plane,
      initial.rigging_out_of_plane_rate;
  if (roped) state.tail<4>() << stepper.static_stretch(), 0.0, 0.0, 0.0;  // at rest under the load's weight; slot 5 unused
  for (std::size_t i = 0; i < count; ++i) {
    out[2 * i] = state(0) + effects.encoder_offset;
    out[2 * i + 1] = state(2);
    if (i + 1 == count) break;
    (void)stepper.advance(state, motion[first + i]);  // a step out of the domain: held where it was
  }
}

std::vector<SwingState> follow_swing(const plant::TowerCraneModel& model, const SwingEffects& effects,
                                     std::span<const DriveMotion> motion, std::span<const SwingState> cable,
                                     double sample_time) {
  assert(cable.size() == motion.size());
  std::vector<SwingState> out(cable.begin(), cable.end());
  const bool hooked = effects.rigging_length > 0.0;
  const bool roped = !hooked && effects.rope_stretch_ratio > 0.0;
  if (out.empty() || (!hooked && !roped)) return out;
  const SwingStepper stepper(model, effects, motion.front().cable_length * (1.0 + effects.length_error), sample_time, 1);
  // At rest at the first sample: the rigging hanging on the cable's line, or the rope stretched by
  // the load's weight.
  SwingVector extended;
  extended << cable[0].in_plane, 0.0, cable[0].out_of_plane, 0.0, 0.0, 0.0, 0.0, 0.0;
  if (hooked) extended.tail<4>() << cable[0].in_plane, 0.0, cable[0].out_of_plane, 0.0;
  if (roped) extended.tail<4>() << stepper.static_stretch(), 0.0, 0.0, 0.0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    out[k].rigging_in_plane = extended(4);
    out[k].rigging_in_plane_rate = extended(5);
    out[k].rigging_out_of_plane = extended(6);
    out[k].rigging_out_of_plane_rate = extended(7);
    if (k + 1 == out.size()) break;
    SwingVector state = extended;
    state.head<4>() << cable[k].in_plane, cable[k].in_plane_rate, cable[k].out_of_plane, cable[k].out_of_plane_rate;
    if (stepper.advance(state, motion[k])) extended.tail<4>() = state.tail<4>();
  }
  return out;
}

}  // namespace crane::model_audit
