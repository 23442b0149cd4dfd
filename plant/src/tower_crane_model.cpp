#include "crane/plant/tower_crane_model.hpp"

#include <Eigen/LU>
#include <cmath>
#include <limits>

#include "cable_direction.hpp"
#include "crane/common/validation.hpp"

namespace crane::plant {

namespace {

using Eigen::Vector3d;

// Kinematics of the load in the rotating jib frame, tower convention (2.11) with ERRATA:
//   r = x e_x + L u(phi, theta),  u = (-cos(theta) sin(phi), sin(theta), -cos(theta) cos(phi)).
// Columns c_j = dr/dq_j of the load position (c_gamma = e_z x r is the rotation about z), and the
// acceleration split a = sum_j c_j q_ddot_j + a_rest where, with omega = gamma_dot e_z,
//   a_rest = L_dd u + 2 L_d u_dot + L (u_pp phi_d^2 + 2 u_pt phi_d theta_d + u_tt theta_d^2)
//            + 2 omega x r_dot + omega x (omega x r)
// (relative acceleration + Coriolis + centripetal; the Euler term omega_dot x r is c_gamma gamma_dd).
struct LoadKinematics {
  Vector3d r;          // load position in the jib frame [m]
  Vector3d r_dot;      // its derivative in the jib frame [m/s]
  Vector3d velocity;   // inertial velocity, jib-frame components r_dot + omega x r [m/s]
  Vector3d column[kNumCoordinates];  // dp/dq_j, jib-frame components
  Vector3d a_rest;     // velocity-product and hoist terms of the acceleration [m/s^2]
};

Vector3d cross_z(double omega, const Vector3d& v) { return Vector3d(-omega * v.y(), omega * v.x(), 0.0); }

LoadKinematics load_kinematics(const ModelState& state, const HoistMotion& hoist) {
  const double x = state.position[kTrolleyIndex];
  const double phi = state.position[kInPlaneSwingIndex];
  const double theta = state.position[kOutOfPlaneSwingIndex];
  const double x_d = state.velocity[kTrolleyIndex];
  const double phi_d = state.velocity[kInPlaneSwingIndex];
  const double gamma_d = state.velocity[kSlewIndex];
  const double theta_d = state.velocity[kOutOfPlaneSwingIndex];
  const double L = hoist.cable_length;
  const double L_d = hoist.cable_length_rate;
  const double L_dd = hoist.cable_length_acceleration;

  const detail::CableDirection d = detail::cable_direction(phi, theta);
  const Vector3d& u = d.u;
  const Vector3d& u_p = d.u_p;    // du/dphi
  const Vector3d& u_t = d.u_t;    // du/dtheta
  const Vector3d& u_pp = d.u_pp;  // d2u/dphi2
  const Vector3d& u_pt = d.u_pt;  // d2u/dphi dtheta
  const Vector3d& u_tt = d.u_tt;  // d2u/dtheta2
  const Vector3d u_dot = u_p * phi_d + u_t * theta_d;

  LoadKinematics k;
  k.r = Vector3d(x, 0.0, 0.0) + L * u;
  k.r_dot = Vector3d(x_d, 0.0, 0.0) + L_d * u + L * u_dot;
  k.velocity = k.r_dot + cross_z(gamma_d, k.r);
  k.column[kTrolleyIndex] = Vector3d(1.0, 0.0, 0.0);
  k.column[kInPlaneSwingIndex] = L * u_p;
  k.column[kSlewIndex] = Vector3d(-k.r.y(), k.r.x(), 0.0);
  k.column[kOutOfPlaneSwingIndex] = L * u_t;
  k.a_rest = L_dd * u + 2.0 * L_d * u_dot +
             L * (u_pp * (phi_d * phi_d) + 2.0 * u_pt * (phi_d * theta_d) + u_tt * (theta_d * theta_d)) +
             2.0 * cross_z(gamma_d, k.r_dot) + cross_z(gamma_d, cross_z(gamma_d, k.r));
  return k;
}

bool is_swing_row(int j) { return j == kInPlaneSwingIndex || j == kOutOfPlaneSwingIndex; }

// Hook and load of the double pendulum (header): the same split as LoadKinematics, per point mass,
// over six coordinates (x, phi, gamma, theta, phi2, theta2).
struct PointKinematics {
  Vector3d r;
  Vector3d r_dot;
  Vector3d velocity;
  Vector3d column[kMaxCoordinates];
  Vector3d a_rest;
};

void hook_and_load_kinematics(const ExtendedState& state, const HoistMotion& hoist, double rigging_length,
                              PointKinematics& hook, PointKinematics& load) {
  const double x = state.position[kTrolleyIndex];
  const double x_d = state.velocity[kTrolleyIndex];
  const double phi_d = state.velocity[kInPlaneSwingIndex];
  const double gamma_d = state.velocity[kSlewIndex];
  const double theta_d = state.velocity[kOutOfPlaneSwingIndex];
  const double phi2_d = state.velocity[kRiggingInPlaneIndex];
  const double theta2_d = state.velocity[kRiggingOutOfPlaneIndex];
  const double L = hoist.cable_length;
  const double L_d = hoist.cable_length_rate;
  const double L_dd = hoist.cable_length_acceleration;
  const double l = rigging_length;

  const detail::CableDirection d =
      detail::cable_direction(state.position[kInPlaneSwingIndex], state.position[kOutOfPlaneSwingIndex]);
  const detail::CableDirection w =
      detail::cable_direction(state.position[kRiggingInPlaneIndex], state.position[kRiggingOutOfPlaneIndex]);
  const Vector3d u_dot = d.u_p * phi_d + d.u_t * theta_d;
  const Vector3d w_dot = w.u_p * phi2_d + w.u_t * theta2_d;
  const Vector3d hook_relative = L_dd * d.u + 2.0 * L_d * u_dot +
                                 L * (d.u_pp * (phi_d * phi_d) + 2.0 * d.u_pt * (phi_d * theta_d) +
                                      d.u_tt * (theta_d * theta_d));
  const Vector3d load_relative =
      hook_relative +
      l * (w.u_pp * (phi2_d * phi2_d) + 2.0 * w.u_pt * (phi2_d * theta2_d) + w.u_tt * (theta2_d * theta2_d));

  hook.r = Vector3d(x, 0.0, 0.0) + L * d.u;
  hook.r_dot = Vector3d(x_d, 0.0, 0.0) + L_d * d.u + L * u_dot;
  load.r = hook.r + l * w.u;
  load.r_dot = hook.r_dot + l * w_dot;
  for (PointKinematics* p : {&hook, &load}) {
    p->velocity = p->r_dot + cross_z(gamma_d, p->r);
    p->column[kTrolleyIndex] = Vector3d(1.0, 0.0, 0.0);
    p->column[kInPlaneSwingIndex] = L * d.u_p;
    p->column[kSlewIndex] = Vector3d(-p->r.y(), p->r.x(), 0.0);
    p->column[kOutOfPlaneSwingIndex] = L * d.u_t;
    p->column[kRiggingInPlaneIndex] = Vector3d::Zero();
    p->column[kRiggingOutOfPlaneIndex] = Vector3d::Zero();
    p->a_rest = (p == &hook ? hook_relative : load_relative) + 2.0 * cross_z(gamma_d, p->r_dot) +
                cross_z(gamma_d, cross_z(gamma_d, p->r));
  }
  load.column[kRiggingInPlaneIndex] = l * w.u_p;
  load.column[kRiggingOutOfPlaneIndex] = l * w.u_t;
}

// The elastic rope (header): the single pendulum's kinematics with the length L + s, its rate
// L' + s' and, in a_rest, the hoist's L'' only (s'' is the column u).
LoadKinematics rope_kinematics(const ExtendedState& state, const HoistMotion& hoist) {
  ModelState m;
  m.position = state.position.head<kNumCoordinates>();
  m.velocity = state.velocity.head<kNumCoordinates>();
  const HoistMotion stretched{hoist.cable_length + state.position[kRopeStretchIndex],
                              hoist.cable_length_rate + state.velocity[kRopeStretchIndex], hoist.cable_length_acceleration};
  return load_kinematics(m, stretched);
}

// Row weights of the double pendulum (header): hook and load mass per row, cable rows divided by
// m_h + m, rigging rows by m (unit weight of the load's own row when m = 0).
struct RowWeights {
  double hook;
  double load;
};
RowWeights row_weights(int j, double hook_mass, double load_mass) {
  if (j == kRiggingInPlaneIndex || j == kRiggingOutOfPlaneIndex) return {0.0, 1.0};
  if (is_swing_row(j)) return {hook_mass / (hook_mass + load_mass), load_mass / (hook_mass + load_mass)};
  return {hook_mass, load_mass};
}

ModelState first_four(const ExtendedState& state) {
  ModelState m;
  m.position = state.position.head<kNumCoordinates>();
  m.velocity = state.velocity.head<kNumCoordinates>();
  return m;
}

}  // namespace

void validate(const RopeParameters& rope, const std::string& prefix) {
  if (!rope.enabled) return;
  common::require_in_range(prefix + "axial_stiffness", rope.axial_stiffness, 1.0, 1e10);
  common::require_in_range(prefix + "damping_ratio", rope.damping_ratio, 0.0, 1.0);
}

void validate(const HookParameters& hook, const std::string& prefix) {
  if (!hook.enabled) return;
  common::require_in_range(prefix + "rigging_length", hook.rigging_length, 0.001, 10.0);
  common::require_in_range(prefix + "hook_mass", hook.hook_mass, 0.001, 1e4);
}

DoublePendulumFrequencies double_pendulum_frequencies(double cable_length, double rigging_length, double hook_mass,
                                                      double load_mass, double gravity) noexcept {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (!(cable_length > 0.0) || !(rigging_length > 0.0) || !(hook_mass > 0.0) || !(load_mass >= 0.0) ||
      !(gravity > 0.0)) {
    return {nan, nan};
  }
  const double R = load_mass / hook_mass;
  const double a = (1.0 + R) * (1.0 / cable_length + 1.0 / rigging_length);
  const double root = std::sqrt(a * a - 4.0 * (1.0 + R) / (cable_length * rigging_length));
  return {std::sqrt(0.5 * gravity * (a - root)), std::sqrt(0.5 * gravity * (a + root))};
}

TowerCraneModel::TowerCraneModel(const common::CraneParameters& parameters, const HookParameters& hook,
                                 const RopeParameters& rope)
    : parameters_(parameters), hook_(hook), rope_(rope) {
  common::validate(parameters_, "crane");
  validate(hook_, "plant.hook.");
  validate(rope_, "plant.rope.");
  if (rope_.enabled && hook_.enabled) {
    throw common::ConfigError("plant.rope.enabled = true needs plant.hook.enabled = false (an elastic rope with a hook "
                              "is not modelled)");
  }
  if (rope_.enabled) common::require_greater("plant.rope: crane.load_mass", parameters_.load_mass, 0.0);
}

int TowerCraneModel::coordinate_count() const noexcept {
  if (hook_.enabled) return kMaxCoordinates;
  return rope_.enabled ? kNumCoordinates + 1 : kNumCoordinates;
}

double TowerCraneModel::rope_stiffness(double cable_length) const noexcept { return rope_.axial_stiffness / cable_length; }

void TowerCraneModel::compute_extended_dynamics(const ExtendedState& state, const HoistMotion& hoist,
                                                ExtendedMatrix& mass_matrix, ExtendedVector& bias) const noexcept {
  if (rope_.enabled) {
    // The single pendulum's rows over (x, phi, gamma, theta, s), swing and stretch rows per unit
    // mass, plus the rope's force (k s + c s') / m on the stretch row; slot 5 unused (identity).
    const double m = parameters_.load_mass;
    LoadKinematics k = rope_kinematics(state, hoist);
    Vector3d column[kNumCoordinates + 1];
    for (int j = 0; j < kNumCoordinates; ++j) column[j] = k.column[j];
    column[kRopeStretchIndex] = detail::cable_direction(state.position[kInPlaneSwingIndex],
                                                        state.position[kOutOfPlaneSwingIndex]).u;
    const Vector3d a_plus_gravity = k.a_rest + Vector3d(0.0, 0.0, parameters_.gravity);
    mass_matrix.setIdentity();
    bias.setZero();
    for (int j = 0; j <= kRopeStretchIndex; ++j) {
      const double row_scale = (is_swing_row(j) || j == kRopeStretchIndex) ? 1.0 : m;
      for (int c = 0; c <= kRopeStretchIndex; ++c) mass_matrix(j, c) = row_scale * column[j].dot(column[c]);
      bias[j] = row_scale * column[j].dot(a_plus_gravity);
    }
    const double stiffness = rope_stiffness(hoist.cable_length);
    const double damping = 2.0 * rope_.damping_ratio * std::sqrt(stiffness * m);
    bias[kRopeStretchIndex] +=
        (stiffness * state.position[kRopeStretchIndex] + damping * state.velocity[kRopeStretchIndex]) / m;
    const double x = state.position[kTrolleyIndex];
    const double x_d = state.velocity[kTrolleyIndex];
    const double gamma_d = state.velocity[kSlewIndex];
    mass_matrix(kTrolleyIndex, kTrolleyIndex) += parameters_.trolley_drive_mass;
    bias[kTrolleyIndex] -= parameters_.trolley_mass * x * gamma_d * gamma_d;
    mass_matrix(kSlewIndex, kSlewIndex) += parameters_.trolley_mass * x * x + parameters_.jib_inertia;
    bias[kSlewIndex] += 2.0 * parameters_.trolley_mass * x * x_d * gamma_d;
    return;
  }
  if (!hook_.enabled) {
    CraneDynamics::compute_extended_dynamics(state, hoist, mass_matrix, bias);
    return;
  }
  const double m = parameters_.load_mass;
  const double m_h = hook_.hook_mass;
  PointKinematics hook, load;
  hook_and_load_kinematics(state, hoist, hook_.rigging_length, hook, load);
  const Vector3d gravity(0.0, 0.0, parameters_.gravity);
  for (int j = 0; j < kMaxCoordinates; ++j) {
    const RowWeights w = row_weights(j, m_h, m);
    for (int c = 0; c < kMaxCoordinates; ++c) {
      mass_matrix(j, c) = w.hook * hook.column[j].dot(hook.column[c]) + w.load * load.column[j].dot(load.column[c]);
    }
    bias[j] = w.hook * hook.column[j].dot(hook.a_rest + gravity) + w.load * load.column[j].dot(load.a_rest + gravity);
  }
  // Trolley and jib, as in compute_dynamics.
  const double x = state.position[kTrolleyIndex];
  const double x_d = state.velocity[kTrolleyIndex];
  const double gamma_d = state.velocity[kSlewIndex];
  mass_matrix(kTrolleyIndex, kTrolleyIndex) += parameters_.trolley_drive_mass;
  bias[kTrolleyIndex] -= parameters_.trolley_mass * x * gamma_d * gamma_d;
  mass_matrix(kSlewIndex, kSlewIndex) += parameters_.trolley_mass * x * x + parameters_.jib_inertia;
  bias[kSlewIndex] += 2.0 * parameters_.trolley_mass * x * x_d * gamma_d;
}

ExtendedVector TowerCraneModel::load_force(const ExtendedState& state, const HoistMotion& hoist, double force_x,
                                           double force_y) const noexcept {
  ExtendedVector q = ExtendedVector::Zero();
  const double m = parameters_.load_mass;
  if (!(m > 0.0)) return q;
  // The force in the jib frame (rotated by -gamma).
  const double gamma = state.position[kSlewIndex];
  const double cg = std::cos(gamma), sg = std::sin(gamma);
  const Vector3d force(cg * force_x + sg * force_y, -sg * force_x + cg * force_y, 0.0);
  if (rope_.enabled) {
    const LoadKinematics k = rope_kinematics(state, hoist);
    for (int j = 0; j < kNumCoordinates; ++j) q[j] = (is_swing_row(j) ? 1.0 / m : 1.0) * k.column[j].dot(force);
    q[kRopeStretchIndex] = detail::cable_direction(state.position[kInPlaneSwingIndex],
                                                   state.position[kOutOfPlaneSwingIndex])
                               .u.dot(force) /
                           m;
    return q;
  }
  if (!hook_.enabled) {
    const LoadKinematics k = load_kinematics(first_four(state), hoist);
    for (int j = 0; j < kNumCoordinates; ++j) q[j] = (is_swing_row(j) ? 1.0 / m : 1.0) * k.column[j].dot(force);
    return q;
  }
  PointKinematics hook, load;
  hook_and_load_kinematics(state, hoist, hook_.rigging_length, hook, load);
  for (int j = 0; j < kMaxCoordinates; ++j) {
    const double scale = row_weights(j, hook_.hook_mass, m).load / m;  // the load's weight per unit load mass
    q[j] = scale * load.column[j].dot(force);
  }
  return q;
}

double TowerCraneModel::extended_total_energy(const ExtendedState& state, const HoistMotion& hoist) const noexcept {
  if (rope_.enabled) {
    const double s_stretch = state.position[kRopeStretchIndex];
    const double s_rate = state.velocity[kRopeStretchIndex];
    const ModelState m = first_four(state);
    const HoistMotion stretched{hoist.cable_length + s_stretch, hoist.cable_length_rate + s_rate, 0.0};
    return kinetic_energy(m, stretched) + potential_energy(m, hoist.cable_length + s_stretch) +
           0.5 * rope_stiffness(hoist.cable_length) * s_stretch * s_stretch;
  }
  if (!hook_.enabled) return CraneDynamics::extended_total_energy(state, hoist);
  PointKinematics hook, load;
  hook_and_load_kinematics(state, hoist, hook_.rigging_length, hook, load);
  const double x = state.position[kTrolleyIndex];
  const double x_d = state.velocity[kTrolleyIndex];
  const double gamma_d = state.velocity[kSlewIndex];
  const double m = parameters_.load_mass;
  const double m_h = hook_.hook_mass;
  const double kinetic = 0.5 * m_h * hook.velocity.squaredNorm() + 0.5 * m * load.velocity.squaredNorm() +
                         0.5 * parameters_.trolley_drive_mass * x_d * x_d +
                         0.5 * (parameters_.trolley_mass * x * x + parameters_.jib_inertia) * gamma_d * gamma_d;
  const double potential = parameters_.gravity * (m_h * hook.r.z() + m * load.r.z());
  return kinetic + potential;
}

double TowerCraneModel::trolley_force_per_volt() const noexcept {
  return parameters_.trolley_drive_mass * parameters_.trolley_drive_gain;
}

double TowerCraneModel::slew_torque_per_volt() const noexcept {
  return parameters_.jib_inertia * parameters_.slew_drive_gain;
}

void TowerCraneModel::compute_dynamics(const ModelState& state, const HoistMotion& hoist,
                                       CoordinateMatrix& mass_matrix, CoordinateVector& bias) const noexcept {
  const double m = parameters_.load_mass;
  const double g = parameters_.gravity;
  const double M_drive = parameters_.trolley_drive_mass;
  const double M_trolley = parameters_.trolley_mass;
  const double J_o = parameters_.jib_inertia;
  const LoadKinematics k = load_kinematics(state, hoist);
  const Vector3d a_plus_gravity = k.a_rest + Vector3d(0.0, 0.0, g);

  // Load: m c_j . (sum_k c_k q_dd_k + a_rest + g e_z); swing rows divided by m.
  for (int j = 0; j < kNumCoordinates; ++j) {
    const double row_scale = is_swing_row(j) ? 1.0 : m;
    for (int c = 0; c < kNumCoordinates; ++c) mass_matrix(j, c) = row_scale * k.column[j].dot(k.column[c]);
    bias[j] = row_scale * k.column[j].dot(a_plus_gravity);
  }
  // Trolley and jib: T = 1/2 M_drive x_d^2 + 1/2 (M_trolley x^2 + J_o) gamma_d^2.
  //   x:     M_drive x_dd - M_trolley x gamma_d^2
  //   gamma: (M_trolley x^2 + J_o) gamma_dd + 2 M_trolley x x_d gamma_d
  const double x = state.position[kTrolleyIndex];
  const double x_d = state.velocity[kTrolleyIndex];
  const double gamma_d = state.velocity[kSlewIndex];
  mass_matrix(kTrolleyIndex, kTrolleyIndex) += M_drive;
  bias[kTrolleyIndex] -= M_trolley * x * gamma_d * gamma_d;
  mass_matrix(kSlewIndex, kSlewIndex) += M_trolley * x * x + J_o;
  bias[kSlewIndex] += 2.0 * M_trolley * x * x_d * gamma_d;
}

double TowerCraneModel::kinetic_energy(const ModelState& state, const HoistMotion& hoist) const noexcept {
  const LoadKinematics k = load_kinematics(state, hoist);
  const double x = state.position[kTrolleyIndex];
  const double x_d = state.velocity[kTrolleyIndex];
  const double gamma_d = state.velocity[kSlewIndex];
  return 0.5 * parameters_.load_mass * k.velocity.squaredNorm() + 0.5 * parameters_.trolley_drive_mass * x_d * x_d +
         0.5 * (parameters_.trolley_mass * x * x + parameters_.jib_inertia) * gamma_d * gamma_d;
}

double TowerCraneModel::potential_energy(const ModelState& state, double cable_length) const noexcept {
  // (2.14)
  return -parameters_.load_mass * parameters_.gravity * cable_length *
         std::cos(state.position[kOutOfPlaneSwingIndex]) * std::cos(state.position[kInPlaneSwingIndex]);
}

double TowerCraneModel::drive_force_per_volt(DriveAxis axis) const noexcept {
  return axis == DriveAxis::trolley ? trolley_force_per_volt() : slew_torque_per_volt();
}

std::unique_ptr<CraneDynamics> TowerCraneModel::clone() const { return std::make_unique<TowerCraneModel>(*this); }

double TowerCraneModel::slew_momentum(const ModelState& state, const HoistMotion& hoist) const noexcept {
  const LoadKinematics k = load_kinematics(state, hoist);
  const double x = state.position[kTrolleyIndex];
  return parameters_.load_mass * k.velocity.dot(k.column[kSlewIndex]) +
         (parameters_.trolley_mass * x * x + parameters_.jib_inertia) * state.velocity[kSlewIndex];
}

Eigen::Vector3d TowerCraneModel::load_position(const ModelState& state, double cable_length) const noexcept {
  HoistMotion hoist;
  hoist.cable_length = cable_length;
  const Vector3d r = load_kinematics(state, hoist).r;
  const double gamma = state.position[kSlewIndex];
  const double cg = std::cos(gamma), sg = std::sin(gamma);
  return Vector3d(cg * r.x() - sg * r.y(), sg * r.x() + cg * r.y(), r.z());
}

LinearizedModel TowerCraneModel::linearize_at_rest(double trolley_position, double cable_length) const noexcept {
  ModelState rest;
  rest.position[kTrolleyIndex] = trolley_position;
  HoistMotion hoist;
  hoist.cable_length = cable_length;
  LinearizedModel lin;
  CoordinateVector bias_at_rest;
  compute_dynamics(rest, hoist, lin.mass, bias_at_rest);
  // At rest the bias is the gravity gradient dV/dq; its Jacobian is the Hessian of
  // V = -m g L cos(theta) cos(phi) at phi = theta = 0: diag(0, m g L, 0, m g L), swing rows / m.
  lin.stiffness(kInPlaneSwingIndex, kInPlaneSwingIndex) = parameters_.gravity * cable_length;
  lin.stiffness(kOutOfPlaneSwingIndex, kOutOfPlaneSwingIndex) = parameters_.gravity * cable_length;
  lin.input(kTrolleyIndex, 0) = trolley_force_per_volt();
  lin.input(kSlewIndex, 1) = slew_torque_per_volt();
  return lin;
}

}  // namespace crane::plant
