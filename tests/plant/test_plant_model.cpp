// Tests of the tower-crane model (Lagrangian, (2.11)-(2.16)) and its linearization (2.28)-(2.31),
// plus conservation laws and the pendulum period of the simulated plant.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "crane/plant/crane_simulator.hpp"
#include "crane/plant/tower_crane_model.hpp"
#include "crane/tracking/tracking_controller.hpp"

namespace crane::plant {
namespace {

constexpr int kRandomStates = 200;  // count of the randomized cross-check

common::CraneParameters lab_crane(double load_mass = 2.0) {
  common::CraneParameters p;
  p.load_mass = load_mass;
  return p;
}

// ---------------------------------------------------------------------------------------------
// Linearization equals (2.28)-(2.31).
//
// The model rows (swing rows divided by m) at rest, with m_t = m/M_drive, M_r = M_trolley/J_o,
// m_r = m/J_o, read
//   x:     (M + m) x_dd - m L phi_dd                     = F_x
//   phi:   -L x_dd + L^2 phi_dd + g L phi                = 0
//   gamma: (J_o + (M_t + m) x0^2) gamma_dd + m x0 L theta_dd = T_gamma
//   theta: L x0 gamma_dd + L^2 theta_dd + g L theta      = 0
// so (x + (m/L) phi)/M     gives x_dd + m_t g phi = K_mx V_x                        (2.28)
//    phi / L               gives L phi_dd + g phi - x_dd = 0                        (2.29)
//    (gamma - (m x0/L) theta)/J_o gives (1 + M_r x0^2) gamma_dd - m_r g x0 theta = K_mg V_g (2.30)
//    theta / L             gives L theta_dd + g theta + x0 gamma_dd = 0             (2.31)
struct Row {
  Eigen::Matrix<double, 1, 4> mass, stiffness;
  Eigen::Matrix<double, 1, 2> input;
};

Row combine(const LinearizedModel& lin, int row_a, double weight_a, int row_b, double weight_b) {
  Row r;
  r.mass = weight_a * lin.mass.row(row_a) + weight_b * lin.mass.row(row_b);
  r.stiffness = weight_a * lin.stiffness.row(row_a) + weight_b * lin.stiffness.row(row_b);
  r.input = weight_a * lin.input.row(row_a) + weight_b * lin.input.row(row_b);
  return r;
}

void expect_row(const Row& row, const std::array<double, 4>& mass, const std::array<double, 4>& stiffness,
                const std::array<double, 2>& input, const char* label) {
  constexpr double kTol = 1e-12;
  for (int k = 0; k < 4; ++k) {
    EXPECT_NEAR(row.mass(k), mass[k], kTol) << label << " mass coefficient " << k;
    EXPECT_NEAR(row.stiffness(k), stiffness[k], kTol) << label << " stiffness coefficient " << k;
  }
  for (int k = 0; k < 2; ++k) EXPECT_NEAR(row.input(k), input[k], kTol) << label << " input " << k;
}

TEST(Linearization, MatchesDissertationEquations228To231) {
  for (double m : {0.5, 2.0, 5.0}) {
    const common::CraneParameters p = lab_crane(m);
    const TowerCraneModel model(p);
    const double g = p.gravity, m_t = m / p.trolley_drive_mass, M_r = p.trolley_mass / p.jib_inertia,
                 m_r = m / p.jib_inertia, K_mx = p.trolley_drive_gain, K_mg = p.slew_drive_gain;
    for (double x0 : {0.0, 0.5, 1.2}) {
      for (double L : {0.5, 1.0, 3.0}) {
        SCOPED_TRACE(testing::Message() << "m=" << m << " x0=" << x0 << " L=" << L);
        const LinearizedModel lin = model.linearize_at_rest(x0, L);
        const double M = p.trolley_drive_mass, J = p.jib_inertia;
        expect_row(combine(lin, kTrolleyIndex, 1.0 / M, kInPlaneSwingIndex, m / (L * M)), {1, 0, 0, 0},
                   {0, m_t * g, 0, 0}, {K_mx, 0}, "(2.28)");
        expect_row(combine(lin, kInPlaneSwingIndex, 1.0 / L, kTrolleyIndex, 0.0), {-1, L, 0, 0}, {0, g, 0, 0},
                   {0, 0}, "(2.29)");
        expect_row(combine(lin, kSlewIndex, 1.0 / J, kOutOfPlaneSwingIndex, -m * x0 / (L * J)),
                   {0, 0, 1 + M_r * x0 * x0, 0}, {0, 0, 0, -m_r * g * x0}, {0, K_mg}, "(2.30)");
        expect_row(combine(lin, kOutOfPlaneSwingIndex, 1.0 / L, kTrolleyIndex, 0.0), {0, 0, x0, L},
                   {0, 0, 0, g}, {0, 0}, "(2.31)");
      }
    }
  }
}

// The analytic stiffness of linearize_at_rest equals the Jacobian of the nonlinear bias at rest
// (central differences), so the linear model really is the linearization of the nonlinear one.
TEST(Linearization, StiffnessIsJacobianOfNonlinearBias) {
  const TowerCraneModel model(lab_crane());
  for (double x0 : {0.0, 0.7}) {
    const double L = 1.3;
    const LinearizedModel lin = model.linearize_at_rest(x0, L);
    const HoistMotion hoist{L, 0.0, 0.0};
    const double h = 1e-6;
    for (int j = 0; j < kNumCoordinates; ++j) {
      ModelState plus, minus;
      plus.position[kTrolleyIndex] = minus.position[kTrolleyIndex] = x0;
      plus.position[j] += h;
      minus.position[j] -= h;
      CoordinateMatrix mass;
      CoordinateVector bias_plus, bias_minus;
      model.compute_dynamics(plus, hoist, mass, bias_plus);
      model.compute_dynamics(minus, hoist, mass, bias_minus);
      const CoordinateVector column = (bias_plus - bias_minus) / (2 * h);
      for (int i = 0; i < kNumCoordinates; ++i) EXPECT_NEAR(column[i], lin.stiffness(i, j), 1e-6) << i << "," << j;
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Independent numerical Lagrangian: T - V from the inertial load position p = R(gamma) r (2.11)-(2.14)
// only, in long double, with every derivative by finite differences. The Euler-Lagrange residual
//   d/dt(dLag/dq_dot_j) - dLag/dq_j - Q_j
// evaluated with the model's accelerations must vanish, and d2T/dq_dot2 must equal the mass matrix.
using Real = long double;
using Vec4 = std::array<Real, 4>;
struct RefParams {
  Real m, g, M_drive, M_trolley, J_o;
};

std::array<Real, 3> inertial_load_position(const Vec4& q, Real L) {
  const Real x = q[0], phi = q[1], gamma = q[2], theta = q[3];
  const Real rx = x - L * std::cos(theta) * std::sin(phi), ry = L * std::sin(theta),
             rz = -L * std::cos(theta) * std::cos(phi);
  return {std::cos(gamma) * rx - std::sin(gamma) * ry, std::sin(gamma) * rx + std::cos(gamma) * ry, rz};
}

// Inertial velocity: Jacobian of p w.r.t. (q, L) by central differences, times (q_dot, L_dot).
// (Linear in q_dot by construction, so T is exactly quadratic in q_dot.)
std::array<Real, 3> inertial_load_velocity(const Vec4& q, const Vec4& q_dot, Real L, Real L_dot) {
  const Real h = 1e-6L;
  std::array<Real, 3> v{0, 0, 0};
  for (int j = 0; j < 5; ++j) {
    Vec4 qp = q, qm = q;
    Real Lp = L, Lm = L;
    if (j < 4) {
      qp[j] += h;
      qm[j] -= h;
    } else {
      Lp += h;
      Lm -= h;
    }
    const auto pp = inertial_load_position(qp, Lp), pm = inertial_load_position(qm, Lm);
    const Real rate = j < 4 ? q_dot[j] : L_dot;
    for (int i = 0; i < 3; ++i) v[i] += (pp[i] - pm[i]) / (2 * h) * rate;
  }
  return v;
}

Real lagrangian(const RefParams& p, const Vec4& q, const Vec4& q_dot, Real L, Real L_dot) {
  const auto v = inertial_load_velocity(q, q_dot, L, L_dot);
  const Real T = 0.5L * p.m * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) + 0.5L * p.M_drive * q_dot[0] * q_dot[0] +
                 0.5L * (p.M_trolley * q[0] * q[0] + p.J_o) * q_dot[2] * q_dot[2];
  const Real V = p.m * p.g * inertial_load_position(q, L)[2];
  return T - V;
}

// dLag/dq_dot_j: exact central difference (Lag is quadratic in q_dot), step 1.
Real momentum(const RefParams& p, int j, const Vec4& q, const Vec4& q_dot, Real L, Real L_dot) {
  Vec4 plus = q_dot, minus = q_dot;
  plus[j] += 1;
  minus[j] -= 1;
  return (lagrangian(p, q, plus, L, L_dot) - lagrangian(p, q, minus, L, L_dot)) / 2;
}

TEST(NonlinearModel, MatchesNumericalLagrangianAtRandomStates) {
  std::mt19937 rng(20031);  // seeded
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (double m : {2.0, 0.3}) {
    const common::CraneParameters params = lab_crane(m);
    const TowerCraneModel model(params);
    const RefParams ref{m, params.gravity, params.trolley_drive_mass, params.trolley_mass, params.jib_inertia};
    double worst_residual = 0.0, worst_mass = 0.0;
    for (int sample = 0; sample < kRandomStates; ++sample) {
      ModelState s;
      s.position << 0.5 + 1.5 * unit(rng), 0.6 * unit(rng), std::numbers::pi * unit(rng), 0.6 * unit(rng);
      s.velocity << unit(rng), 1.5 * unit(rng), unit(rng), 1.5 * unit(rng);
      const HoistMotion hoist{1.25 + 0.75 * unit(rng), 0.5 * unit(rng), unit(rng)};
      CoordinateVector Q = CoordinateVector::Zero();
      Q[kTrolleyIndex] = 20.0 * unit(rng);
      Q[kSlewIndex] = 10.0 * unit(rng);
      const CoordinateVector q_dd = model.acceleration(s, hoist, Q);

      CoordinateMatrix mass;
      CoordinateVector bias;
      model.compute_dynamics(s, hoist, mass, bias);

      Vec4 q, qd, qdd;
      for (int j = 0; j < 4; ++j) {
        q[j] = s.position[j];
        qd[j] = s.velocity[j];
        qdd[j] = q_dd[j];
      }
      const Real L = hoist.cable_length, Ld = hoist.cable_length_rate, Ldd = hoist.cable_length_acceleration;
      for (int j = 0; j < 4; ++j) {
        const double row_scale = (j == kInPlaneSwingIndex || j == kOutOfPlaneSwingIndex) ? m : 1.0;
        // Mass matrix: d2T/dq_dot_j dq_dot_k = momentum_j(q_dot + e_k) - momentum_j(q_dot) (exact: linear).
        for (int k = 0; k < 4; ++k) {
          Vec4 shifted = qd;
          shifted[k] += 1;
          const double reference =
              static_cast<double>(momentum(ref, j, q, shifted, L, Ld) - momentum(ref, j, q, qd, L, Ld));
          const double error = std::abs(row_scale * mass(j, k) - reference);
          worst_mass = std::max(worst_mass, error / (1.0 + std::abs(reference)));
        }
        // d/dt of the momentum along the trajectory (central difference in time, step dt).
        const Real dt = 1e-4L;
        auto momentum_at = [&](Real tau) {
          Vec4 qt, qdt;
          for (int k = 0; k < 4; ++k) {
            qt[k] = q[k] + tau * qd[k] + 0.5L * tau * tau * qdd[k];
            qdt[k] = qd[k] + tau * qdd[k];
          }
          return momentum(ref, j, qt, qdt, L + tau * Ld + 0.5L * tau * tau * Ldd, Ld + tau * Ldd);
        };
        const Real momentum_rate = (momentum_at(dt) - momentum_at(-dt)) / (2 * dt);
        // dLag/dq_j by central difference.
        const Real h = 1e-5L;
        Vec4 qp = q, qm = q;
        qp[j] += h;
        qm[j] -= h;
        const Real dLag_dq = (lagrangian(ref, qp, qd, L, Ld) - lagrangian(ref, qm, qd, L, Ld)) / (2 * h);
        const double residual = static_cast<double>(momentum_rate - dLag_dq) - Q[j];
        const double scale = 1.0 + std::abs(static_cast<double>(momentum_rate)) + std::abs(static_cast<double>(dLag_dq));
        worst_residual = std::max(worst_residual, std::abs(residual) / scale);
      }
    }
    RecordProperty("worst_relative_euler_lagrange_residual", std::to_string(worst_residual));
    EXPECT_LT(worst_mass, 1e-7) << "m=" << m;
    EXPECT_LT(worst_residual, 1e-5) << "m=" << m;
    std::printf("m=%g: worst mass-matrix error %.3g, worst Euler-Lagrange residual %.3g\n", m, worst_mass,
                worst_residual);
  }
}

// The tracking law's momenta (tracking_controller.hpp), which the PD law's friction factor balances
// its voltage against (friction_momentum_balance.hpp), are this independent Lagrangian's: dLag/dx_dot
// and dLag/dgamma_dot over the drives' force per volt, and dLag/dx (= dT/dx: V does not depend on x)
// over the trolley's, at seeded random states with the hoist moving.
TEST(NonlinearModel, TheTrackingLawsMomentaAreTheLagrangiansAtRandomStates) {
  std::mt19937 rng(20032);  // seeded
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (double m : {2.0, 0.3}) {
    const common::CraneParameters params = lab_crane(m);
    const tracking::TrackingController law(tracking::tracking_params_from(params));
    const RefParams ref{m, params.gravity, params.trolley_drive_mass, params.trolley_mass, params.jib_inertia};
    const double trolley_force_per_volt = params.trolley_drive_mass * params.trolley_drive_gain;
    const double slew_torque_per_volt = params.jib_inertia * params.slew_drive_gain;
    double worst = 0.0;
    for (int sample = 0; sample < kRandomStates; ++sample) {
      const Vec4 q{0.5 + 1.5 * unit(rng), 0.6 * unit(rng), std::numbers::pi * unit(rng), 0.6 * unit(rng)};
      const Vec4 qd{unit(rng), 1.5 * unit(rng), unit(rng), 1.5 * unit(rng)};
      const Real L = 1.25 + 0.75 * unit(rng), Ld = 0.5 * unit(rng);
      tracking::TrackingInput in;
      in.estimate.trolley_position = static_cast<double>(q[0]);
      in.estimate.swing_in_plane = static_cast<double>(q[1]);
      in.estimate.slew_angle = static_cast<double>(q[2]);
      in.estimate.swing_out_of_plane = static_cast<double>(q[3]);
      in.estimate.trolley_velocity = static_cast<double>(qd[0]);
      in.estimate.swing_in_plane_rate = static_cast<double>(qd[1]);
      in.estimate.slew_rate = static_cast<double>(qd[2]);
      in.estimate.swing_out_of_plane_rate = static_cast<double>(qd[3]);
      in.estimate.cable_length = static_cast<double>(L);
      in.estimate.cable_length_rate = static_cast<double>(Ld);
      tracking::TrackingOutput out;
      ASSERT_EQ(law.step(in, out), common::StepStatus::ok);
      const Real h = 1e-5L;
      Vec4 qp = q, qm = q;
      qp[0] += h;
      qm[0] -= h;
      const Real dLag_dx = (lagrangian(ref, qp, qd, L, Ld) - lagrangian(ref, qm, qd, L, Ld)) / (2 * h);
      const double expected[] = {static_cast<double>(momentum(ref, 0, q, qd, L, Ld)) / trolley_force_per_volt,
                                 static_cast<double>(momentum(ref, 2, q, qd, L, Ld)) / slew_torque_per_volt,
                                 static_cast<double>(dLag_dx) / trolley_force_per_volt};
      const double got[] = {out.trolley_momentum, out.slew_momentum, out.trolley_centripetal_voltage};
      for (int i = 0; i < 3; ++i) {
        EXPECT_NEAR(got[i], expected[i], 1e-7 * (1.0 + std::abs(expected[i]))) << "m=" << m << " sample " << sample << " " << i;
        worst = std::max(worst, std::abs(got[i] - expected[i]));
      }
    }
    std::printf("m=%g: worst momentum error %.3g V s\n", m, worst);
  }
}

// ---------------------------------------------------------------------------------------------
// Energy conservation of the simulated plant: no friction, no input, brakes released, constant L.
// T + V is a first integral of a conservative Lagrangian system, and so is the slew momentum
// dT/d(gamma_dot) (gamma is cyclic). Both must stay constant to integration accuracy.
SimulatorParameters frictionless(double relative_tolerance, double absolute_tolerance) {
  SimulatorParameters p;
  p.crane.trolley_friction = {};
  p.crane.slew_friction = {};
  p.integrator.relative_tolerance = relative_tolerance;
  p.integrator.absolute_tolerance = absolute_tolerance;
  p.initial_state.trolley_position = 0.5;
  p.initial_state.trolley_velocity = 0.2;
  p.initial_state.swing_in_plane = 0.3;
  p.initial_state.swing_out_of_plane = 0.2;
  p.initial_state.slew_rate = 0.5;
  p.initial_state.cable_length = 1.0;
  return p;
}

class EnergyConservation : public testing::TestWithParam<std::pair<double, double>> {};

TEST_P(EnergyConservation, FrictionlessFreeMotionKeepsEnergyAndSlewMomentum) {
  const SimulatorParameters params = frictionless(GetParam().first, GetParam().second);
  CraneSimulator sim(params);
  const auto hoist = [&] { return HoistMotion{sim.state().cable_length, 0.0, 0.0}; };
  const auto model_state = [&] {
    ModelState m;
    const PlantState& s = sim.state();
    m.position << s.trolley_position, s.swing_in_plane, s.slew_angle, s.swing_out_of_plane;
    m.velocity << s.trolley_velocity, s.swing_in_plane_rate, s.slew_rate, s.swing_out_of_plane_rate;
    return m;
  };
  const double energy0 = sim.total_energy();
  const double momentum0 = static_cast<const TowerCraneModel&>(sim.model()).slew_momentum(model_state(), hoist());
  DriveInput input;
  input.brakes_engaged = false;
  double worst_energy = 0.0, worst_momentum = 0.0;
  for (int k = 0; k < 2000; ++k) {  // 20 s
    ASSERT_EQ(sim.step(input), common::StepStatus::ok);
    worst_energy = std::max(worst_energy, std::abs(sim.total_energy() - energy0) / std::abs(energy0));
    worst_momentum = std::max(worst_momentum,
                              std::abs(static_cast<const TowerCraneModel&>(sim.model()).slew_momentum(model_state(), hoist()) - momentum0) / std::abs(momentum0));
  }
  std::printf("energy %.6g J, worst relative drift %.3g; slew momentum worst relative drift %.3g\n", energy0,
              worst_energy, worst_momentum);
  EXPECT_LT(worst_energy, 1e-6);
  EXPECT_LT(worst_momentum, 1e-6);
  EXPECT_EQ(sim.friction_event_count(), 0);
  // The motion was not trivial: the swing is still large and the trolley moved.
  EXPECT_GT(std::abs(sim.state().trolley_position - 0.5), 0.1);
}

// (rtol, atol): the simulator defaults and a tight setting.
INSTANTIATE_TEST_SUITE_P(Tolerances, EnergyConservation,
                         testing::Values(std::make_pair(1e-8, 1e-10), std::make_pair(1e-10, 1e-12)));

// ---------------------------------------------------------------------------------------------
// Small-swing period with both brakes engaged: the trolley is held, so the in-plane swing obeys
// L phi_dd + g sin(phi) = 0; for amplitude phi0 the period is 2 pi sqrt(L/g) (1 + phi0^2/16 + ...),
// i.e. 6e-6 relative above the linear value for phi0 = 0.01 rad.
TEST(PendulumPeriod, BrakedTrolleyGivesTwoPiSqrtLOverG) {
  for (double L : {0.5, 1.0, 3.0}) {
    SimulatorParameters params;
    params.crane.max_cable_length = 3.0;  // a hoist that reaches 3 m
    params.initial_state.cable_length = L;
    params.initial_state.trolley_position = 0.6;
    params.initial_state.swing_in_plane = 0.01;
    CraneSimulator sim(params);
    const double expected = 2.0 * std::numbers::pi * std::sqrt(L / params.crane.gravity);
    const DriveInput braked{};  // 0 V, brakes engaged
    std::vector<double> crossings;  // downward zero crossings, linear interpolation between samples
    double previous = sim.state().swing_in_plane;
    while (crossings.size() < 11) {
      const double t0 = sim.time();
      ASSERT_EQ(sim.step(braked), common::StepStatus::ok);
      const double now = sim.state().swing_in_plane;
      if (previous > 0.0 && now <= 0.0) crossings.push_back(t0 + sim.parameters().sample_period * previous / (previous - now));
      previous = now;
      ASSERT_LT(sim.time(), 20 * expected);
    }
    const double period = (crossings.back() - crossings.front()) / 10.0;
    std::printf("L=%g: period %.6f s, expected %.6f s\n", L, period, expected);
    EXPECT_NEAR(period / expected, 1.0, 1e-3) << "L=" << L;
    EXPECT_EQ(sim.state().trolley_position, 0.6);  // held exactly by the brake
    EXPECT_EQ(sim.state().slew_angle, 0.0);
    EXPECT_EQ(sim.axis_mode(FrictionAxis::trolley), AxisMode::stuck);
  }
}

}  // namespace
}  // namespace crane::plant
