#include "crane/optimal_control/trajectory_follower.hpp"

#include <array>

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Dense>

#include "crane/common/validation.hpp"
#include "crane/plant/tower_crane_model.hpp"

#include "crane/tracking/trajectory_feedback.hpp"

namespace crane::optimal_control {
namespace {

using plant::kInPlaneSwingIndex;
using plant::kOutOfPlaneSwingIndex;
using plant::kSlewIndex;
using plant::kTrolleyIndex;

constexpr int kSubsteps = 4;                // RK4 steps per sample of the zero-order-hold map
constexpr int kMaxRiccatiIterations = 200000;  // the stationary solution (a few thousand suffice)

plant::HoistMotion hoist_at(const MinimumTimeResult& trajectory, double t) {
  const TrajectoryNode n = sample(trajectory, t);
  return {n.cable_length, n.cable_length_rate, t >= trajectory.trajectory_duration ? 0.0 : n.hoist_acceleration};
}

// The model's state after one sample T_s from `start` at time t0 with the drive forces `force`
// [N or N m] held, the hoist following the trajectory (RK4).
plant::ModelState zero_order_hold(const plant::CraneDynamics& model, const MinimumTimeResult& trajectory,
                                  const plant::ModelState& start, double t0, double period,
                                  const plant::CoordinateVector& force) {
  const double h = period / kSubsteps;
  plant::ModelState s = start;
  const auto derivative = [&](const plant::ModelState& x, double t, plant::CoordinateVector& dq,
                              plant::CoordinateVector& dv) {
    dq = x.velocity;
    dv = model.acceleration(x, hoist_at(trajectory, t), force);
  };
  for (int i = 0; i < kSubsteps; ++i) {
    const double t = t0 + i * h;
    plant::CoordinateVector q1, v1, q2, v2, q3, v3, q4, v4;
    derivative(s, t, q1, v1);
    derivative({s.position + 0.5 * h * q1, s.velocity + 0.5 * h * v1}, t + 0.5 * h, q2, v2);
    derivative({s.position + 0.5 * h * q2, s.velocity + 0.5 * h * v2}, t + 0.5 * h, q3, v3);
    derivative({s.position + h * q3, s.velocity + h * v3}, t + h, q4, v4);
    s.position += h / 6.0 * (q1 + 2.0 * q2 + 2.0 * q3 + q4);
    s.velocity += h / 6.0 * (v1 + 2.0 * v2 + 2.0 * v3 + v4);
  }
  return s;
}

}  // namespace

TrajectoryFollower::TrajectoryFollower(const MinimumTimeProblem& problem, const MinimumTimeResult& trajectory,
                                       const FollowerParams& params)
    : voltage_limit_(params.voltage_limit),
      sliding_friction_scale_(params.hold.sliding_friction_scale),
      trajectory_sliding_friction_scale_(params.trajectory_sliding_friction_scale) {
  if (!problem.model) throw common::ConfigError("follower.model: no model");
  const plant::CraneDynamics& model = *problem.model;
  if (model.coordinate_count() != plant::kNumCoordinates) {
    throw common::ConfigError("follower.model: " + std::to_string(model.coordinate_count()) +
                              " coordinates (a hook or a rope); the follower takes the rigid four-coordinate model");
  }
  common::require_greater("follower.sample_period", params.sample_period, 0.0);
  common::require_greater("follower.voltage_limit", params.voltage_limit, 0.0);
  const FollowerWeights& w = params.weights;
  common::require_greater("follower.weights.position", w.position, 0.0);
  common::require_greater("follower.weights.second_position", w.second_position, 0.0);
  common::require_greater("follower.weights.swing", w.swing, 0.0);
  common::require_greater("follower.weights.out_of_plane_swing", w.out_of_plane_swing, 0.0);
  common::require_greater("follower.weights.speed", w.speed, 0.0);
  common::require_greater("follower.weights.swing_rate", w.swing_rate, 0.0);
  common::require_greater("follower.weights.voltage", w.voltage, 0.0);
  const FollowerWeights& h = params.hold.weights;
  common::require_greater("follower.hold.weights.position", h.position, 0.0);
  common::require_greater("follower.hold.weights.second_position", h.second_position, 0.0);
  common::require_greater("follower.hold.weights.swing", h.swing, 0.0);
  common::require_greater("follower.hold.weights.out_of_plane_swing", h.out_of_plane_swing, 0.0);
  common::require_greater("follower.hold.weights.speed", h.speed, 0.0);
  common::require_greater("follower.hold.weights.swing_rate", h.swing_rate, 0.0);
  common::require_greater("follower.hold.weights.voltage", h.voltage, 0.0);
  common::require_in_range("follower.hold.sliding_friction_scale", params.hold.sliding_friction_scale, 0.0, 1.0);
  common::require_greater("follower.hold.slew_sideways", params.hold.slew_sideways, 0.0);
  common::require_in_range("follower.trajectory_sliding_friction_scale", params.trajectory_sliding_friction_scale, 0.0,
                           1.0);
  if (!(trajectory.solved || trajectory.fallback) || trajectory.nodes.size() < 2 ||
      !(trajectory.trajectory_duration > 0.0)) {
    throw common::ConfigError("follower.trajectory: not solved (" + trajectory.status + ")");
  }

  const double fpv_trolley = model.drive_force_per_volt(plant::DriveAxis::trolley);
  const double fpv_second = model.drive_force_per_volt(plant::DriveAxis::second);
  second_drive_ = fpv_second > 0.0;
  slots_ = second_drive_ ? std::vector<int>{kTrolleyIndex, kInPlaneSwingIndex, kSlewIndex, kOutOfPlaneSwingIndex}
                         : std::vector<int>{kTrolleyIndex, kInPlaneSwingIndex};
  const int c = static_cast<int>(slots_.size());
  const int n = 2 * c;
  const int m = second_drive_ ? 2 : 1;

  // The reference at the samples, and the feedforward (the bound's voltage less its friction).
  const double period = params.sample_period;
  const auto count = static_cast<std::size_t>(std::ceil(trajectory.trajectory_duration / period - 1e-9));
  const auto model_state = [](const TrajectoryNode& node) {
    plant::ModelState s;
    s.position = node.state.position.head<plant::kNumCoordinates>();
    s.velocity = node.state.velocity.head<plant::kNumCoordinates>();
    return s;
  };
  // The model's friction [V] at the trajectory's speeds of time t.
  const auto friction = [&](double t) {
    if (t >= trajectory.trajectory_duration) return Eigen::Vector2d::Zero().eval();
    const TrajectoryNode node = sample(trajectory, t);
    Eigen::Vector2d f;
    f[0] = drive_voltage(0.0, fpv_trolley, node.state.velocity[kTrolleyIndex], problem.trolley_friction,
                         problem.friction_smoothing_speed);
    f[1] = second_drive_ ? drive_voltage(0.0, fpv_second, node.state.velocity[kSlewIndex], problem.second_friction,
                                         problem.friction_smoothing_speed)
                         : 0.0;
    return f;
  };
  const auto feedforward = [&](double t) {
    if (t >= trajectory.trajectory_duration) return Eigen::Vector2d::Zero().eval();
    const TrajectoryNode node = sample(trajectory, t);
    return (Eigen::Vector2d(node.trolley_voltage, second_drive_ ? node.second_voltage : 0.0) - friction(t)).eval();
  };
  samples_.resize(count + 1);
  for (std::size_t k = 0; k <= count; ++k) {
    const double t = static_cast<double>(k) * period;
    samples_[k].node = sample(trajectory, t);
    samples_[k].state = model_state(samples_[k].node);
    samples_[k].input = k == count ? Eigen::Vector2d::Zero().eval() : feedforward(t + 0.5 * period);
    samples_[k].friction = k == count ? Eigen::Vector2d::Zero().eval()
                                      : ((1.0 - params.trajectory_sliding_friction_scale) * friction(t + 0.5 * period)).eval();
  }

  // z <-> the model's state, the forces of an input.
  const auto to_z = [&](const plant::ModelState& s) {
    Eigen::VectorXd z(n);
    for (int i = 0; i < c; ++i) {
      z[i] = s.position[slots_[i]];
      z[c + i] = s.velocity[slots_[i]];
    }
    return z;
  };
  const auto from_z = [&](const Eigen::VectorXd& z, const plant::ModelState& base) {
    plant::ModelState s = base;
    for (int i = 0; i < c; ++i) {
      s.position[slots_[i]] = z[i];
      s.velocity[slots_[i]] = z[c + i];
    }
    return s;
  };
  const auto forces = [&](const Eigen::VectorXd& u) {
    plant::CoordinateVector f = plant::CoordinateVector::Zero();
    f[kTrolleyIndex] = fpv_trolley * u[0];
    if (second_drive_) f[kSlewIndex] = fpv_second * u[1];
    return f;
  };
  // The Jacobians of the zero-order-hold map at (reference state, input) of time t.
  const auto linearize = [&](const plant::ModelState& base, const Eigen::VectorXd& u0, double t, Eigen::MatrixXd& A,
                             Eigen::MatrixXd& B) {
    const Eigen::VectorXd z0 = to_z(base);
    A.resize(n, n);
    B.resize(n, m);
    for (int j = 0; j < n + m; ++j) {
      Eigen::VectorXd z = z0, u = u0;
      double& x = j < n ? z[j] : u[j - n];
      const double delta = 1e-6 * std::max(1.0, std::abs(x));
      const double x0 = x;
      x = x0 + delta;
      const Eigen::VectorXd plus = to_z(zero_order_hold(model, trajectory, from_z(z, base), t, period, forces(u)));
      x = x0 - delta;
      const Eigen::VectorXd minus = to_z(zero_order_hold(model, trajectory, from_z(z, base), t, period, forces(u)));
      (j < n ? A.col(j) : B.col(j - n)) = (plus - minus) / (2.0 * delta);
    }
  };

  // Bryson's weights.
  const auto bryson = [&](const FollowerWeights& bw, Eigen::MatrixXd& Qw, Eigen::MatrixXd& Rw) {
    Eigen::VectorXd q(n);
    for (int i = 0; i < c; ++i) {
      const int slot = slots_[i];
      const bool swing = slot == kInPlaneSwingIndex || slot == kOutOfPlaneSwingIndex;
      const double acceptable = slot == kTrolleyIndex      ? bw.position
                                : slot == kSlewIndex         ? bw.second_position
                                : slot == kInPlaneSwingIndex ? bw.swing
                                                             : bw.out_of_plane_swing;
      q[i] = 1.0 / (acceptable * acceptable);
      q[c + i] = 1.0 / std::pow(swing ? bw.swing_rate : bw.speed, 2);
    }
    Qw = q.asDiagonal();
    Rw = Eigen::MatrixXd::Identity(m, m) / (bw.voltage * bw.voltage);
  };
  // The hold's slew weight at the target's radius (FollowerHold::slew_sideways): a tower crane's slew
  // (not an overhead crane's bridge), after a plan robust to the pendulum's length.
  FollowerWeights hold = h;
  const double radius = samples_[count].state.position[kTrolleyIndex];
  if (trajectory.robust && second_drive_ && dynamic_cast<const plant::TowerCraneModel*>(&model) != nullptr &&
      radius > 0.0) {
    hold.second_position = std::max(h.second_position, params.hold.slew_sideways / radius);
  }
  Eigen::MatrixXd Q, R;
  bryson(hold, Q, R);  // the hold's, for the stationary solution; the trajectory's below
  const auto riccati_step = [&](const Eigen::MatrixXd& A, const Eigen::MatrixXd& B, const Eigen::MatrixXd& P,
                                Eigen::MatrixXd& K) {
    K = (R + B.transpose() * P * B).ldlt().solve(B.transpose() * P * A);
    Eigen::MatrixXd next = Q + A.transpose() * P * (A - B * K);
    return (0.5 * (next + next.transpose())).eval();
  };

  // The stationary regulator at the target's rest state, then backwards along the trajectory.
  gains_.resize(count + 1);
  Eigen::MatrixXd A, B, K;
  const Eigen::VectorXd u_rest = Eigen::VectorXd::Zero(m);
  linearize(samples_[count].state, u_rest, trajectory.trajectory_duration + period, A, B);
  Eigen::MatrixXd P = Q;
  int iteration = 0;
  for (; iteration < kMaxRiccatiIterations; ++iteration) {
    const Eigen::MatrixXd next = riccati_step(A, B, P, K);
    const double change = (next - P).norm();
    P = next;
    if (change <= 1e-12 * P.norm()) break;
  }
  if (iteration == kMaxRiccatiIterations) {
    throw common::ConfigError("follower: the stationary Riccati equation at the target did not converge");
  }
  gains_[count] = K;
  bryson(w, Q, R);
  for (std::size_t k = count; k-- > 0;) {
    const Eigen::VectorXd u = samples_[k].input.head(m);
    linearize(samples_[k].state, u, static_cast<double>(k) * period, A, B);
    P = riccati_step(A, B, P, K);
    gains_[k] = K;
  }
}

const Eigen::MatrixXd& TrajectoryFollower::gain(std::size_t k) const noexcept {
  return gains_[std::min(k, gains_.size() - 1)];
}

common::TrajectoryFeedback TrajectoryFollower::law(std::size_t k) const noexcept {
  const std::size_t i = std::min(k, samples_.size() - 1);
  const Sample& s = samples_[i];
  const Eigen::MatrixXd& K = gains_[i];
  const int c = static_cast<int>(slots_.size());
  common::TrajectoryFeedback law;
  for (int slot = 0; slot < 4; ++slot) {
    law.position[static_cast<std::size_t>(slot)] = s.state.position[slot];
    law.velocity[static_cast<std::size_t>(slot)] = s.state.velocity[slot];
  }
  law.feedforward = {s.input[0] + s.friction[0], s.input[1] + s.friction[1]};
  for (int r = 0; r < K.rows(); ++r) {
    for (int j = 0; j < c; ++j) {
      const auto slot = static_cast<std::size_t>(slots_[static_cast<std::size_t>(j)]);
      law.gain[static_cast<std::size_t>(r) * 8 + slot] = K(r, j);
      law.gain[static_cast<std::size_t>(r) * 8 + 4 + slot] = K(r, c + j);
    }
  }
  law.sliding_friction_reduction = 1.0 - (moving(k) ? trajectory_sliding_friction_scale_ : sliding_friction_scale_);
  return law;
}

const TrajectoryNode& TrajectoryFollower::node(std::size_t k) const noexcept {
  return samples_[std::min(k, samples_.size() - 1)].node;
}

common::StepStatus TrajectoryFollower::step(std::size_t k, const plant::ModelState& measured,
                                            FollowerCommand& command) const noexcept {
  command = FollowerCommand{};
  if (!measured.position.allFinite() || !measured.velocity.allFinite()) return common::StepStatus::rejected_nonfinite;
  std::array<double, 4> position{}, velocity{};
  for (int slot = 0; slot < 4; ++slot) {
    position[static_cast<std::size_t>(slot)] = measured.position[slot];
    velocity[static_cast<std::size_t>(slot)] = measured.velocity[slot];
  }
  const common::TrajectoryFeedback feedback = law(k);
  const std::array<double, 2> u = tracking::trajectory_feedback_voltages(feedback, position, velocity, voltage_limit_);
  if (!std::isfinite(u[0]) || !std::isfinite(u[1])) return common::StepStatus::rejected_nonfinite;
  command.trolley_voltage = u[0];
  command.second_voltage = second_drive_ ? u[1] : 0.0;
  const TrajectoryNode& n = node(k);
  const bool in_move = moving(k);
  command.sliding_friction_scale = 1.0 - feedback.sliding_friction_reduction;
  command.hoist_speed = n.cable_length_rate;
  command.trolley = {n.state.position[kTrolleyIndex], n.state.velocity[kTrolleyIndex], in_move ? n.trolley_acceleration : 0.0};
  command.second = {n.state.position[kSlewIndex], n.state.velocity[kSlewIndex], in_move ? n.second_acceleration : 0.0};
  command.cable = {n.cable_length, n.cable_length_rate, in_move ? n.hoist_acceleration : 0.0};
  command.swing_in_plane = n.state.position[kInPlaneSwingIndex];
  command.swing_out_of_plane = n.state.position[kOutOfPlaneSwingIndex];
  return common::StepStatus::ok;
}

}  // namespace crane::optimal_control
