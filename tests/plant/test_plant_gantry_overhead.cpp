// Tests of the gantry crane model ((2.5)-(2.8) of Omar 2003, section 2.1) and of the overhead
// (bridge) crane model derived from its Lagrangian (overhead_crane_model.hpp):
//   - the overhead model with the bridge locked and no out-of-plane swing reduces to the gantry
//     model (two independent implementations: the gantry's rows are (2.5)-(2.6) written out, the
//     overhead's come from the load kinematics), 1e-12 on seeded random states with hoisting;
//   - linearization: the numerical Jacobian of each nonlinear right-hand side equals (2.7)-(2.8);
//   - energy conservation of the simulated plants (no friction, no input, constant L) from seeded
//     random initial states;
//   - small-swing periods, with the exact linear frequency of the free trolley (and bridge);
//   - the simulated gantry equals the simulated overhead crane with its bridge held;
//   - the plant kind's configuration errors name the field and the value.
#include <gtest/gtest.h>

#include <Eigen/LU>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/plant/gantry_crane_model.hpp"
#include "crane/plant/overhead_crane_model.hpp"

namespace crane::plant {
namespace {

constexpr int kRandomStates = 200;     // count of the randomized model cross-checks
constexpr int kRandomEnergyRuns = 6;   // count of the randomized simulations per kind
constexpr unsigned kSeed = 20031118u;  // fixed: the tests are deterministic

common::CraneParameters gantry_crane(double mass_ratio) {
  // Section 3.2.2: K_mx = 1.34; the trolley (drive) mass M = 10 kg, load m = m_t M.
  common::CraneParameters p;
  p.trolley_drive_gain = 1.34;
  p.trolley_drive_mass = 10.0;
  p.trolley_mass = 10.0;
  p.load_mass = mass_ratio * p.trolley_drive_mass;
  p.min_cable_length = 0.2;
  p.max_cable_length = 6.0;
  return p;
}

common::BridgeParameters bridge(double drive_mass = 35.0) {
  common::BridgeParameters b;
  b.drive_mass = drive_mass;
  b.drive_gain = 0.9;
  return b;
}

// Accelerations with the bridge slot held (row and column replaced by the identity, as the
// integrator holds a stuck axis).
CoordinateVector accelerations_with_bridge_held(const CraneDynamics& model, const ModelState& state,
                                                const HoistMotion& hoist, const CoordinateVector& force) {
  CoordinateMatrix mass;
  CoordinateVector bias;
  model.compute_dynamics(state, hoist, mass, bias);
  CoordinateVector rhs = force - bias;
  mass.row(kBridgeIndex).setZero();
  mass.col(kBridgeIndex).setZero();
  mass(kBridgeIndex, kBridgeIndex) = 1.0;
  rhs[kBridgeIndex] = 0.0;
  return mass.partialPivLu().solve(rhs);
}

TEST(OverheadCrane, BridgeHeldReducesToTheGantryModelTo1e12) {
  std::mt19937 rng(kSeed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double worst = 0.0;
  for (int i = 0; i < kRandomStates; ++i) {
    const double m_t = 5.0 * (0.5 + 0.5 * unit(rng));
    const common::CraneParameters p = gantry_crane(m_t);
    const GantryCraneModel gantry(p);
    const OverheadCraneModel overhead(p, bridge());
    ModelState s;
    s.position[kTrolleyIndex] = 3.0 * unit(rng);
    s.position[kInPlaneSwingIndex] = 1.2 * unit(rng);
    s.position[kBridgeIndex] = 5.0 * unit(rng);  // any held bridge position
    s.velocity[kTrolleyIndex] = 2.0 * unit(rng);
    s.velocity[kInPlaneSwingIndex] = 3.0 * unit(rng);
    const HoistMotion hoist{3.0 + 2.5 * unit(rng), 0.8 * unit(rng), 0.5 * unit(rng)};
    CoordinateVector force = CoordinateVector::Zero();
    force[kTrolleyIndex] = 200.0 * unit(rng);
    const CoordinateVector a_gantry = gantry.acceleration(s, hoist, force);
    const CoordinateVector a_overhead = accelerations_with_bridge_held(overhead, s, hoist, force);
    for (int j : {kTrolleyIndex, kInPlaneSwingIndex}) {
      const double scale = std::max(1.0, std::abs(a_gantry[j]));
      EXPECT_NEAR(a_overhead[j], a_gantry[j], 1e-12 * scale) << "state " << i << " coordinate " << j;
      worst = std::max(worst, std::abs(a_overhead[j] - a_gantry[j]) / scale);
    }
    EXPECT_EQ(a_overhead[kOutOfPlaneSwingIndex], 0.0) << "theta stays 0 by symmetry, state " << i;
    // The same energy: T and V of the two derivations agree with y_d = 0, theta = 0.
    EXPECT_NEAR(overhead.total_energy(s, hoist), gantry.total_energy(s, hoist),
                1e-12 * std::max(1.0, std::abs(gantry.total_energy(s, hoist))));
  }
  std::printf("overhead (bridge held) vs gantry: worst relative acceleration difference %.3g over %d states\n",
              worst, kRandomStates);
}

// Central-difference Jacobian of z_dot = f(z, u), z = (q, q_dot) restricted to `coordinates`.
template <typename Rhs>
Eigen::MatrixXd numerical_jacobian(const Rhs& rhs, int n, double h = 1e-6) {
  const Eigen::VectorXd z0 = Eigen::VectorXd::Zero(n);
  Eigen::MatrixXd J(rhs(z0).size(), n);
  for (int k = 0; k < n; ++k) {
    Eigen::VectorXd plus = z0, minus = z0;
    plus[k] += h;
    minus[k] -= h;
    J.col(k) = (rhs(plus) - rhs(minus)) / (2.0 * h);
  }
  return J;
}

void expect_matrix_near(const Eigen::MatrixXd& actual, const Eigen::MatrixXd& expected, const std::string& label) {
  ASSERT_EQ(actual.rows(), expected.rows());
  ASSERT_EQ(actual.cols(), expected.cols());
  for (int r = 0; r < actual.rows(); ++r) {
    for (int c = 0; c < actual.cols(); ++c) {
      EXPECT_NEAR(actual(r, c), expected(r, c), 1e-6 * std::max(1.0, std::abs(expected(r, c))))
          << label << " entry (" << r << ", " << c << ")";
    }
  }
}

// (2.7)-(2.8), tower sign: x_dd = -m_t g phi + K_mx V, phi_dd = (-(1 + m_t) g phi + K_mx V)/L.
// The nonlinear gantry (2.5)-(2.6) at rest, differentiated numerically in (x, phi, x_d, phi_d, V),
// must give these coefficients, and GantryCraneModel::linearize_at_rest must state them.
TEST(GantryCrane, NumericalJacobianEqualsEquations27And28) {
  for (double m_t : {0.0, 0.09, 1.0, 5.0}) {
    for (double L : {0.5, 1.0, 5.0}) {
      SCOPED_TRACE(testing::Message() << "m_t=" << m_t << " L=" << L);
      const common::CraneParameters p = gantry_crane(m_t);
      const GantryCraneModel model(p);
      const double force_per_volt = model.drive_force_per_volt(DriveAxis::trolley);
      const auto rhs = [&](const Eigen::VectorXd& z) {  // z = (x, phi, x_d, phi_d, V)
        ModelState s;
        s.position[kTrolleyIndex] = 0.7 + z[0];
        s.position[kInPlaneSwingIndex] = z[1];
        s.velocity[kTrolleyIndex] = z[2];
        s.velocity[kInPlaneSwingIndex] = z[3];
        CoordinateVector force = CoordinateVector::Zero();
        force[kTrolleyIndex] = force_per_volt * z[4];
        const CoordinateVector a = model.acceleration(s, HoistMotion{L, 0.0, 0.0}, force);
        Eigen::VectorXd out(4);
        out << z[2], z[3], a[kTrolleyIndex], a[kInPlaneSwingIndex];
        return out;
      };
      const Eigen::MatrixXd J = numerical_jacobian(rhs, 5);
      const double g = p.gravity, K_mx = p.trolley_drive_gain;
      Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(4, 5);
      expected(0, 2) = 1.0;
      expected(1, 3) = 1.0;
      expected(2, 1) = -m_t * g;  // (2.7)
      expected(2, 4) = K_mx;
      expected(3, 1) = -(1.0 + m_t) * g / L;  // (2.8) with (2.7) substituted
      expected(3, 4) = K_mx / L;
      expect_matrix_near(J, expected, "numerical Jacobian");
      const GantryLinearModel lin = model.linearize_at_rest(L);
      Eigen::MatrixXd stated(4, 5);
      stated << lin.state_matrix, lin.input_matrix;
      expect_matrix_near(stated, expected, "linearize_at_rest");
    }
  }
}

// Overhead crane at rest: per axis the gantry's (2.7)-(2.8), with m_tx = m/M_x on the trolley and
// m_ty = m/M_y on the bridge, where positive theta moves the load toward +y:
//   y_dd = m_ty g theta + K_my V_y,  theta_dd = (-(1 + m_ty) g theta - K_my V_y)/L.
TEST(OverheadCrane, NumericalJacobianIsTwoDecoupledGantries) {
  for (double m_t : {0.09, 2.0}) {
    for (double L : {1.0, 8.0}) {
      SCOPED_TRACE(testing::Message() << "m_t=" << m_t << " L=" << L);
      const common::CraneParameters p = gantry_crane(m_t);
      const common::BridgeParameters b = bridge();
      const OverheadCraneModel model(p, b);
      const auto rhs = [&](const Eigen::VectorXd& z) {  // z = (q, q_dot, V_x, V_y)
        ModelState s;
        s.position = z.segment<4>(0) + CoordinateVector(0.7, 0.0, 3.0, 0.0);
        s.velocity = z.segment<4>(4);
        CoordinateVector force = CoordinateVector::Zero();
        force[kTrolleyIndex] = model.drive_force_per_volt(DriveAxis::trolley) * z[8];
        force[kBridgeIndex] = model.drive_force_per_volt(DriveAxis::second) * z[9];
        const CoordinateVector a = model.acceleration(s, HoistMotion{L, 0.0, 0.0}, force);
        Eigen::VectorXd out(8);
        out << s.velocity, a;
        return out;
      };
      const Eigen::MatrixXd J = numerical_jacobian(rhs, 10);
      const double g = p.gravity, m_tx = p.load_mass / p.trolley_drive_mass, m_ty = p.load_mass / b.drive_mass;
      Eigen::MatrixXd expected = Eigen::MatrixXd::Zero(8, 10);
      for (int j = 0; j < 4; ++j) expected(j, 4 + j) = 1.0;
      expected(4 + kTrolleyIndex, kInPlaneSwingIndex) = -m_tx * g;
      expected(4 + kTrolleyIndex, 8) = p.trolley_drive_gain;
      expected(4 + kInPlaneSwingIndex, kInPlaneSwingIndex) = -(1.0 + m_tx) * g / L;
      expected(4 + kInPlaneSwingIndex, 8) = p.trolley_drive_gain / L;
      expected(4 + kBridgeIndex, kOutOfPlaneSwingIndex) = m_ty * g;
      expected(4 + kBridgeIndex, 9) = b.drive_gain;
      expected(4 + kOutOfPlaneSwingIndex, kOutOfPlaneSwingIndex) = -(1.0 + m_ty) * g / L;
      expected(4 + kOutOfPlaneSwingIndex, 9) = -b.drive_gain / L;
      expect_matrix_near(J, expected, "numerical Jacobian");
      // The stated linearization: q_dd = mass^-1 (input V - stiffness q).
      const LinearizedModel lin = model.linearize_at_rest(L);
      Eigen::MatrixXd stated(4, 6);
      stated << -lin.mass.inverse() * lin.stiffness, lin.mass.inverse() * lin.input;
      Eigen::MatrixXd expected_rows(4, 6);
      expected_rows << expected.block(4, 0, 4, 4), expected.block(4, 8, 4, 2);
      expect_matrix_near(stated, expected_rows, "linearize_at_rest");
    }
  }
}

SimulatorParameters frictionless(PlantKind kind, double mass_ratio) {
  SimulatorParameters p;
  p.kind = kind;
  p.crane = gantry_crane(mass_ratio);
  p.crane.trolley_friction = {};
  p.bridge = bridge();
  p.bridge.friction = {};
  return p;
}

// T + V is a first integral of the conservative system (no friction, no input, brakes released,
// L constant). Seeded random initial states, 10 s each.
void check_energy(PlantKind kind) {
  std::mt19937 rng(kSeed + static_cast<unsigned>(kind));
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int run = 0; run < kRandomEnergyRuns; ++run) {
    SimulatorParameters p = frictionless(kind, 2.5 + 2.5 * unit(rng));
    PlantState& s = p.initial_state;
    s.cable_length = 3.0 + 2.5 * unit(rng);
    s.trolley_position = unit(rng);
    s.trolley_velocity = 0.5 * unit(rng);
    s.swing_in_plane = 0.6 * unit(rng);
    s.swing_in_plane_rate = unit(rng);
    if (kind == PlantKind::overhead) {
      s.bridge_position = 2.0 * unit(rng);
      s.bridge_velocity = 0.5 * unit(rng);
      s.swing_out_of_plane = 0.6 * unit(rng);
      s.swing_out_of_plane_rate = unit(rng);
    }
    CraneSimulator sim(p);
    const double energy0 = sim.total_energy();
    DriveInput input;
    input.brakes_engaged = false;
    double worst = 0.0;
    for (int k = 0; k < 1000; ++k) {
      ASSERT_EQ(sim.step(input), common::StepStatus::ok) << to_string(kind) << " run " << run;
      worst = std::max(worst, std::abs(sim.total_energy() - energy0) / std::abs(energy0));
    }
    std::printf("%s run %d: m_t %.3f, L %.3f m, energy %.6g J, worst relative drift %.3g\n", to_string(kind), run,
                p.crane.mass_ratio(), s.cable_length, energy0, worst);
    EXPECT_LT(worst, 1e-6) << to_string(kind) << " run " << run;
    EXPECT_EQ(sim.friction_event_count(), 0);
    // Not a trivial rest: the load still swings.
    EXPECT_GT(std::abs(sim.state().swing_in_plane) + std::abs(sim.state().swing_in_plane_rate), 1e-3);
  }
}

TEST(GantryCrane, FrictionlessFreeMotionKeepsEnergy) { check_energy(PlantKind::gantry); }
TEST(OverheadCrane, FrictionlessFreeMotionKeepsEnergy) { check_energy(PlantKind::overhead); }

// Period from downward zero crossings of `angle`, linear interpolation between samples.
template <typename Angle>
double measured_period(CraneSimulator& sim, const DriveInput& input, Angle angle, int periods, double bound) {
  std::vector<double> crossings;
  double previous = angle(sim.state());
  while (static_cast<int>(crossings.size()) < periods + 1) {
    const double t0 = sim.time();
    if (sim.step(input) != common::StepStatus::ok) return -1.0;
    const double now = angle(sim.state());
    if (previous > 0.0 && now <= 0.0) crossings.push_back(t0 + sim.parameters().sample_period * previous / (previous - now));
    previous = now;
    if (sim.time() > bound) return -1.0;
  }
  return (crossings.back() - crossings.front()) / periods;
}

// Gantry, trolley free and frictionless: eliminating x_dd from (2.7)-(2.8) with F_x = 0 gives
// L phi_dd + (1 + m_t) g phi = 0, period 2 pi sqrt(L / ((1 + m_t) g)). Trolley braked: x_dd = 0,
// period 2 pi sqrt(L/g). Amplitude 2 mrad: the nonlinear correction phi0^2/16 = 2.5e-7.
TEST(GantryCrane, SmallSwingPeriodFreeAndBrakedTrolley) {
  for (double m_t : {0.0, 1.0, 5.0}) {
    for (double L : {1.0, 5.0}) {
      SCOPED_TRACE(testing::Message() << "m_t=" << m_t << " L=" << L);
      SimulatorParameters p = frictionless(PlantKind::gantry, m_t);
      p.sample_period = 0.002;
      p.initial_state.cable_length = L;
      p.initial_state.swing_in_plane = 0.002;
      const GantryCraneModel model(p.crane);
      const double g = p.crane.gravity;
      const double free_expected = 2.0 * std::numbers::pi / model.free_trolley_swing_frequency(L);
      EXPECT_NEAR(free_expected, 2.0 * std::numbers::pi * std::sqrt(L / ((1.0 + m_t) * g)), 1e-12);
      const auto phi = [](const PlantState& s) { return s.swing_in_plane; };
      {
        CraneSimulator sim(p);
        DriveInput released;
        released.brakes_engaged = false;
        const double period = measured_period(sim, released, phi, 10, 20.0 * free_expected);
        std::printf("gantry m_t=%g L=%g free trolley: period %.6f s, expected %.6f s\n", m_t, L, period, free_expected);
        EXPECT_NEAR(period / free_expected, 1.0, 1e-4);
      }
      {
        CraneSimulator sim(p);
        const double braked_expected = 2.0 * std::numbers::pi * std::sqrt(L / g);
        const double period = measured_period(sim, DriveInput{}, phi, 10, 20.0 * braked_expected);
        std::printf("gantry m_t=%g L=%g braked trolley: period %.6f s, expected %.6f s\n", m_t, L, period,
                    braked_expected);
        EXPECT_NEAR(period / braked_expected, 1.0, 1e-4);
        EXPECT_EQ(sim.state().trolley_position, 0.0);
      }
    }
  }
}

// Overhead crane, both drives free: in-plane 2 pi sqrt(L/((1 + m/M_x) g)), out-of-plane
// 2 pi sqrt(L/((1 + m/M_y) g)); each swing started alone (a small swing stays in its plane).
TEST(OverheadCrane, SmallSwingPeriodsWithBothDrivesFree) {
  for (double L : {1.0, 6.0}) {
    SimulatorParameters p = frictionless(PlantKind::overhead, 2.0);
    p.sample_period = 0.002;
    p.crane.max_cable_length = 8.0;
    p.initial_state.cable_length = L;
    const OverheadCraneModel model(p.crane, p.bridge);
    DriveInput released;
    released.brakes_engaged = false;
    {
      SimulatorParameters in_plane = p;
      in_plane.initial_state.swing_in_plane = 0.002;
      CraneSimulator sim(in_plane);
      const double expected = 2.0 * std::numbers::pi / model.free_in_plane_swing_frequency(L);
      const double period = measured_period(sim, released, [](const PlantState& s) { return s.swing_in_plane; }, 10,
                                            20.0 * expected);
      std::printf("overhead L=%g in-plane: period %.6f s, expected %.6f s\n", L, period, expected);
      EXPECT_NEAR(period / expected, 1.0, 1e-4);
    }
    {
      SimulatorParameters out_of_plane = p;
      out_of_plane.initial_state.swing_out_of_plane = 0.002;
      CraneSimulator sim(out_of_plane);
      const double expected = 2.0 * std::numbers::pi / model.free_out_of_plane_swing_frequency(L);
      const double period = measured_period(sim, released, [](const PlantState& s) { return s.swing_out_of_plane; },
                                            10, 20.0 * expected);
      std::printf("overhead L=%g out-of-plane: period %.6f s, expected %.6f s\n", L, period, expected);
      EXPECT_NEAR(period / expected, 1.0, 1e-4);
      EXPECT_NE(sim.state().bridge_position, 0.0);  // the bridge moved with the swing
    }
  }
}

// The simulated gantry equals the simulated overhead crane whose bridge never breaks away (its
// static friction is never loaded: theta stays 0), under the same trolley voltages and hoisting,
// with the trolley's friction. Integration tolerance, not 1e-12: the two integrate different
// systems (4 vs 3 moving coordinates) with their own steps.
TEST(OverheadCrane, SimulatedWithTheBridgeHeldMatchesTheSimulatedGantry) {
  SimulatorParameters gantry_params = frictionless(PlantKind::gantry, 2.0);
  gantry_params.crane.trolley_friction = common::CraneParameters{}.trolley_friction;
  gantry_params.integrator.relative_tolerance = 1e-10;
  gantry_params.integrator.absolute_tolerance = 1e-12;
  gantry_params.initial_state.cable_length = 2.0;
  SimulatorParameters overhead_params = gantry_params;
  overhead_params.kind = PlantKind::overhead;
  overhead_params.bridge.friction = {0.0, 0.0, 0.0, 0.0, 5.0, 5.0};
  CraneSimulator gantry(gantry_params);
  CraneSimulator overhead(overhead_params);
  double worst_position = 0.0, worst_swing = 0.0;
  for (int k = 0; k < 800; ++k) {
    DriveInput input;
    input.brakes_engaged = false;
    input.trolley_voltage = k < 150 ? 4.0 : (k < 300 ? -3.0 : 0.0);
    input.hoist_speed = k < 400 ? 0.3 : -0.2;
    input.slew_voltage = 0.0;
    ASSERT_EQ(gantry.step(input), common::StepStatus::ok);
    ASSERT_EQ(overhead.step(input), common::StepStatus::ok);
    worst_position = std::max(worst_position, std::abs(gantry.state().trolley_position - overhead.state().trolley_position));
    worst_swing = std::max(worst_swing, std::abs(gantry.state().swing_in_plane - overhead.state().swing_in_plane));
    ASSERT_EQ(overhead.state().bridge_position, 0.0);
    ASSERT_EQ(overhead.state().swing_out_of_plane, 0.0);
  }
  std::printf("gantry vs overhead with the bridge held, 8 s: worst trolley difference %.3g m, swing %.3g rad\n",
              worst_position, worst_swing);
  EXPECT_GT(gantry.friction_event_count(), 0);  // the trolley stuck and broke away
  EXPECT_LT(worst_position, 1e-6);
  EXPECT_LT(worst_swing, 1e-6);
  EXPECT_GT(std::abs(gantry.state().trolley_position), 0.1);  // it moved
}

// A gantry has no second drive: a voltage on the slew or bridge channel moves nothing (the load at
// rest stays at rest to the bit, and no friction event happens), while on the overhead crane the
// bridge channel drives the bridge and the slew channel nothing.
TEST(GantryCrane, TheSecondDriveChannelMovesNothing) {
  SimulatorParameters p = frictionless(PlantKind::gantry, 1.0);
  CraneSimulator gantry(p);
  DriveInput input;
  input.brakes_engaged = false;
  input.slew_voltage = 10.0;
  input.bridge_voltage = 10.0;
  for (int k = 0; k < 100; ++k) ASSERT_EQ(gantry.step(input), common::StepStatus::ok);
  const PlantState& s = gantry.state();
  EXPECT_EQ(s.trolley_position, 0.0);
  EXPECT_EQ(s.swing_in_plane, 0.0);
  EXPECT_EQ(s.slew_angle, 0.0);
  EXPECT_EQ(s.swing_out_of_plane, 0.0);
  EXPECT_EQ(gantry.output().measurement.slew_angle, 0.0);
  EXPECT_EQ(gantry.friction_event_count(), 0);

  p.kind = PlantKind::overhead;
  CraneSimulator overhead(p);
  CraneSimulator overhead_slew_only(p);
  DriveInput slew_only = input;
  slew_only.bridge_voltage = 0.0;
  for (int k = 0; k < 100; ++k) {
    ASSERT_EQ(overhead.step(input), common::StepStatus::ok);
    ASSERT_EQ(overhead_slew_only.step(slew_only), common::StepStatus::ok);
  }
  EXPECT_EQ(overhead_slew_only.state().bridge_position, 0.0);
  EXPECT_NEAR(overhead.output().applied_bridge_voltage, 10.0, 0.01);  // through the DAC
  EXPECT_NEAR(overhead.output().measurement.bridge_position, overhead.state().bridge_position, 1e-5);
  // Linear (2.7)-(2.8) per axis with F = M_y K_my V from rest: y(t) = a_r t^2/2 + c (1 - cos(w t))
  // with a_r = F/(M_y + m) (load rigidly attached) and c w^2 = F/M_y - a_r > 0; since
  // 0 <= 1 - cos(x) <= x^2/2, y lies between the rigid a_r t^2/2 and the bridge-alone F/M_y t^2/2.
  const double rigid = 0.5 * p.bridge.drive_mass * p.bridge.drive_gain * 10.0 / (p.bridge.drive_mass + p.crane.load_mass);
  const double free_load = 0.5 * p.bridge.drive_gain * 10.0;
  EXPECT_GT(overhead.state().bridge_position, rigid);
  EXPECT_LT(overhead.state().bridge_position, free_load);
  EXPECT_EQ(overhead.state().slew_angle, 0.0);
}

void expect_config_error(const SimulatorParameters& p, const std::string& fragment) {
  try {
    CraneSimulator sim(p);
    FAIL() << "expected a ConfigError naming " << fragment;
  } catch (const common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

TEST(PlantKind, ErrorsNameTheFieldAndTheValue) {
  try {
    (void)crane::common::crane_kind_from_string("gantri", "crane.kind");
    FAIL() << "expected a ConfigError";
  } catch (const common::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("crane.kind"), std::string::npos) << what;
    EXPECT_NE(what.find("gantri"), std::string::npos) << what;
    EXPECT_NE(what.find("overhead"), std::string::npos) << what;
  }
  for (PlantKind kind : {PlantKind::tower, PlantKind::gantry, PlantKind::overhead}) {
    EXPECT_EQ(crane::common::crane_kind_from_string(to_string(kind), "crane.kind"), kind);
  }
  SimulatorParameters p = frictionless(PlantKind::gantry, 1.0);
  p.initial_state.slew_angle = 0.3;  // a gantry has no slew
  expect_config_error(p, "simulator.initial_state.slew_angle (gantry crane)");
  p = frictionless(PlantKind::overhead, 1.0);
  p.bridge.drive_mass = -1.0;
  expect_config_error(p, "simulator.bridge.drive_mass");
  p = frictionless(PlantKind::tower, 1.0);
  p.initial_state.bridge_position = 1.0;
  expect_config_error(p, "simulator.initial_state.bridge_position (tower crane)");
}

}  // namespace
}  // namespace crane::plant
