// The plant's options beyond the dissertation (tower crane): the hook as a double pendulum
// (HookParameters) and wind on the load (WindParameters). Analytic cases, a cross-check with the
// single-pendulum model in the limit of short rigging, conservation, seeded determinism.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/plant/tower_crane_model.hpp"

namespace crane::plant {
namespace {

common::CraneParameters frictionless_crane() {
  common::CraneParameters p;
  p.trolley_friction = {};
  p.slew_friction = {};
  return p;
}

// M and K = d(bias)/dq of the model at rest (q = (x0, 0, gamma, 0, 0, 0), q_dot = 0), K by central
// differences of the bias (at rest the bias is the gradient of the potential).
void linearize(const CraneDynamics& model, double trolley_position, double cable_length, ExtendedMatrix& mass,
               ExtendedMatrix& stiffness) {
  ExtendedState rest;
  rest.position[kTrolleyIndex] = trolley_position;
  const HoistMotion hoist{cable_length, 0.0, 0.0};
  ExtendedVector bias;
  model.compute_extended_dynamics(rest, hoist, mass, bias);
  constexpr double h = 1e-6;
  for (int c = 0; c < kMaxCoordinates; ++c) {
    ExtendedState plus = rest, minus = rest;
    plus.position[c] += h;
    minus.position[c] -= h;
    ExtendedMatrix unused;
    ExtendedVector b_plus, b_minus;
    model.compute_extended_dynamics(plus, hoist, unused, b_plus);
    model.compute_extended_dynamics(minus, hoist, unused, b_minus);
    stiffness.col(c) = (b_plus - b_minus) / (2.0 * h);
  }
}

// Squared natural frequencies [rad^2/s^2] (eigenvalues of M^-1 K) over the coordinates `keep`, sorted.
std::vector<double> squared_frequencies(const ExtendedMatrix& mass, const ExtendedMatrix& stiffness,
                                        const std::vector<int>& keep) {
  const int n = static_cast<int>(keep.size());
  Eigen::MatrixXd m(n, n), k(n, n);
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      m(i, j) = mass(keep[i], keep[j]);
      k(i, j) = stiffness(keep[i], keep[j]);
    }
  }
  const Eigen::MatrixXd a = m.partialPivLu().solve(k);
  Eigen::EigenSolver<Eigen::MatrixXd> solver(a);
  std::vector<double> w2;
  for (int i = 0; i < n; ++i) w2.push_back(solver.eigenvalues()[i].real());
  std::sort(w2.begin(), w2.end());
  return w2;
}

// ---------------------------------------------------------------------------------------------
// Held trolley and jib: the linearized swing of the model equals the analytic double pendulum
// (Singhose, Kim, Kenison 2008), each mode once in plane and once out of plane.
TEST(HookModel, HeldTrolleyModesEqualTheAnalyticDoublePendulum) {
  for (const auto& [L, l, m_h, m] : std::vector<std::array<double, 4>>{{1.0, 0.3, 0.5, 2.0}, {1.5, 0.1, 2.0, 1.0},
                                                                        {0.5, 0.8, 0.2, 3.0}}) {
    common::CraneParameters crane = frictionless_crane();
    crane.load_mass = m;
    const TowerCraneModel model(crane, HookParameters{true, l, m_h});
    ExtendedMatrix mass, stiffness;
    linearize(model, 0.6, L, mass, stiffness);
    const auto w2 = squared_frequencies(mass, stiffness,
                                        {kInPlaneSwingIndex, kOutOfPlaneSwingIndex, kRiggingInPlaneIndex,
                                         kRiggingOutOfPlaneIndex});
    const DoublePendulumFrequencies f = double_pendulum_frequencies(L, l, m_h, m, crane.gravity);
    std::printf("L=%g l=%g m_h=%g m=%g: model %.6f %.6f %.6f %.6f rad/s, analytic %.6f %.6f rad/s\n", L, l, m_h, m,
                std::sqrt(w2[0]), std::sqrt(w2[1]), std::sqrt(w2[2]), std::sqrt(w2[3]), f.first, f.second);
    for (int i = 0; i < 2; ++i) EXPECT_NEAR(std::sqrt(w2[i]) / f.first, 1.0, 1e-6);
    for (int i = 2; i < 4; ++i) EXPECT_NEAR(std::sqrt(w2[i]) / f.second, 1.0, 1e-6);
  }
}

// Free trolley and jib, rigging -> 0: the slow modes tend to those of the single-pendulum model
// carrying the hook and the load together (m + m_h), trolley and slew coupling included; the
// rigging's own modes go to sqrt(g/l) and beyond.
TEST(HookModel, ShortRiggingTendsToTheSinglePendulumWithHookAndLoad) {
  const common::CraneParameters crane = frictionless_crane();
  const double m_h = 0.5, L = 1.2, x0 = 0.7;
  common::CraneParameters lumped = crane;
  lumped.load_mass = crane.load_mass + m_h;
  const TowerCraneModel single(lumped);
  ExtendedMatrix single_mass, single_stiffness;
  linearize(single, x0, L, single_mass, single_stiffness);
  const auto single_w2 =
      squared_frequencies(single_mass, single_stiffness, {kTrolleyIndex, kInPlaneSwingIndex, kSlewIndex, kOutOfPlaneSwingIndex});
  ASSERT_NEAR(single_w2[0], 0.0, 1e-9);  // the trolley and the slew are free: two rigid-body modes
  ASSERT_NEAR(single_w2[1], 0.0, 1e-9);
  double previous_error = 1.0;
  for (double l : {1e-1, 1e-2, 1e-3}) {
    const TowerCraneModel hooked(crane, HookParameters{true, l, m_h});
    ExtendedMatrix mass, stiffness;
    linearize(hooked, x0, L, mass, stiffness);
    const auto w2 = squared_frequencies(mass, stiffness, {0, 1, 2, 3, 4, 5});
    double error = 0.0;
    for (int i = 2; i < 4; ++i) error = std::max(error, std::abs(w2[i] / single_w2[i] - 1.0));
    std::printf("l=%g: slow modes %.6f %.6f rad/s (single %.6f %.6f), relative error %.3g; rigging modes %.1f %.1f\n",
                l, std::sqrt(w2[2]), std::sqrt(w2[3]), std::sqrt(single_w2[2]), std::sqrt(single_w2[3]), error,
                std::sqrt(w2[4]), std::sqrt(w2[5]));
    EXPECT_LT(error, 2.0 * l / L) << "l=" << l;  // first order in l / L
    EXPECT_LT(error, previous_error);
    EXPECT_GT(std::sqrt(w2[4]), std::sqrt(crane.gravity / l));
    previous_error = error;
  }
}

// No friction, no input, brakes released, constant L: T + V (hook included) is conserved.
TEST(HookModel, FrictionlessFreeMotionKeepsEnergy) {
  SimulatorParameters p;
  p.crane = frictionless_crane();
  p.hook = HookParameters{true, 0.3, 0.5};
  p.initial_state.trolley_position = 0.5;
  p.initial_state.trolley_velocity = 0.2;
  p.initial_state.swing_in_plane = 0.3;
  p.initial_state.swing_out_of_plane = 0.2;
  p.initial_state.rigging_in_plane = -0.2;
  p.initial_state.rigging_out_of_plane = 0.1;
  p.initial_state.slew_rate = 0.5;
  CraneSimulator sim(p);
  ASSERT_EQ(sim.model().coordinate_count(), 6);
  const double energy0 = sim.total_energy();
  DriveInput input;
  input.brakes_engaged = false;
  double worst = 0.0, largest_rigging = 0.0;
  for (int k = 0; k < 2000; ++k) {  // 20 s
    ASSERT_EQ(sim.step(input), common::StepStatus::ok);
    worst = std::max(worst, std::abs(sim.total_energy() - energy0) / std::abs(energy0));
    largest_rigging = std::max(largest_rigging, std::abs(sim.state().rigging_in_plane - sim.state().swing_in_plane));
  }
  std::printf("energy %.6g J, worst relative drift %.3g, largest rigging-cable angle %.3f rad\n", energy0, worst,
              largest_rigging);
  EXPECT_LT(worst, 1e-6);
  EXPECT_EQ(sim.friction_event_count(), 0);
  EXPECT_GT(largest_rigging, 0.1);  // the rigging swung on its own: a double pendulum, not a rigid one
}

TEST(HookModel, ConfigurationErrorsNameTheField) {
  const auto expect_error = [](const SimulatorParameters& p, const std::string& text) {
    try {
      CraneSimulator sim(p);
      ADD_FAILURE() << "no ConfigError for " << text;
    } catch (const common::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  SimulatorParameters p;
  p.hook = HookParameters{true, 0.0, 0.5};
  expect_error(p, "plant.hook.rigging_length");
  p.hook = HookParameters{true, 0.3, -1.0};
  expect_error(p, "plant.hook.hook_mass");
  p = {};
  p.initial_state.rigging_in_plane = 0.1;  // no hook: no rigging
  expect_error(p, "simulator.initial_state.rigging_in_plane (no plant.hook)");
  p = {};
  p.kind = PlantKind::gantry;
  p.hook.enabled = true;
  expect_error(p, "plant.hook.enabled = true needs crane.kind = tower");
  p = {};
  p.wind.enabled = true;
  p.wind.gust_time_constant = 0.0;
  expect_error(p, "plant.wind.gust_time_constant");
  p = {};
  p.wind.enabled = true;
  p.crane.load_mass = 0.0;
  expect_error(p, "crane.load_mass");
}

// ---------------------------------------------------------------------------------------------
// Wind: a constant horizontal force F on the load tilts the effective gravity, m g_eff =
// (F, -m g): the braked pendulum swings symmetrically about the tilted vertical, so the midpoint of
// its swing is the static deflection atan(F / (m g)) (tower convention: a force toward +x gives
// phi < 0, one toward +y theta > 0).
TEST(Wind, MeanForceGivesTheStaticDeflection) {
  for (const auto& [fx, fy] : std::vector<std::pair<double, double>>{{2.0, 0.0}, {0.0, -3.0}}) {
    SimulatorParameters p;
    p.wind.enabled = true;
    p.wind.mean_force_x = fx;
    p.wind.mean_force_y = fy;
    p.initial_state.trolley_position = 0.6;
    CraneSimulator sim(p);
    const double mg = p.crane.load_mass * p.crane.gravity;
    double phi_min = 1.0, phi_max = -1.0, theta_min = 1.0, theta_max = -1.0;
    for (int k = 0; k < 1000; ++k) {  // 10 s, about 5 periods, braked
      ASSERT_EQ(sim.step(DriveInput{}), common::StepStatus::ok);
      phi_min = std::min(phi_min, sim.state().swing_in_plane);
      phi_max = std::max(phi_max, sim.state().swing_in_plane);
      theta_min = std::min(theta_min, sim.state().swing_out_of_plane);
      theta_max = std::max(theta_max, sim.state().swing_out_of_plane);
    }
    const double phi_mid = 0.5 * (phi_min + phi_max), theta_mid = 0.5 * (theta_min + theta_max);
    std::printf("F=(%g, %g) N: swing midpoints phi %.6f theta %.6f rad, analytic %.6f %.6f rad\n", fx, fy, phi_mid,
                theta_mid, -std::atan(fx / mg), std::atan(fy / mg));
    // 2e-4 rad: the extremes are sampled at 100 Hz (error (omega T)^2 / 8 of the amplitude, 1.3e-5 rad).
    EXPECT_NEAR(phi_mid, -std::atan(fx / mg), 2e-4);
    EXPECT_NEAR(theta_mid, std::atan(fy / mg), 2e-4);
    EXPECT_EQ(sim.state().trolley_position, 0.6);  // braked
  }
}

// With the hook: at the equilibrium the cable carries hook and load, the rigging the load only:
// tan(phi) = -F / ((m + m_h) g), tan(phi2) = -F / (m g). Started there, the crane stays there.
TEST(Wind, HookAndLoadRestAtTheirAnalyticDeflections) {
  SimulatorParameters p;
  p.hook = HookParameters{true, 0.4, 0.8};
  p.wind.enabled = true;
  p.wind.mean_force_x = 3.0;
  p.initial_state.trolley_position = 0.6;
  const double g = p.crane.gravity, m = p.crane.load_mass;
  p.initial_state.swing_in_plane = -std::atan(3.0 / ((m + 0.8) * g));
  p.initial_state.rigging_in_plane = -std::atan(3.0 / (m * g));
  CraneSimulator sim(p);
  double worst = 0.0;
  for (int k = 0; k < 500; ++k) {
    ASSERT_EQ(sim.step(DriveInput{}), common::StepStatus::ok);
    worst = std::max({worst, std::abs(sim.state().swing_in_plane - p.initial_state.swing_in_plane),
                      std::abs(sim.state().rigging_in_plane - p.initial_state.rigging_in_plane)});
  }
  std::printf("largest departure from the analytic equilibrium over 5 s: %.3g rad\n", worst);
  EXPECT_LT(worst, 1e-6);
  // The same start without the wind swings away (the equilibrium above is the wind's).
  p.wind.enabled = false;
  CraneSimulator calm(p);
  for (int k = 0; k < 50; ++k) ASSERT_EQ(calm.step(DriveInput{}), common::StepStatus::ok);
  EXPECT_GT(std::abs(calm.state().rigging_in_plane - p.initial_state.rigging_in_plane), 1e-2);
}

std::vector<double> gusty_run(std::uint64_t seed) {
  SimulatorParameters p;
  p.wind = WindParameters{true, 1.0, 0.5, 2.0, 0.5, seed};
  p.initial_state.trolley_position = 0.6;
  CraneSimulator sim(p);
  std::vector<double> record;
  for (int k = 0; k < 300; ++k) {
    EXPECT_EQ(sim.step(DriveInput{}), common::StepStatus::ok);
    record.push_back(sim.state().swing_in_plane);
    record.push_back(sim.state().swing_out_of_plane);
    record.push_back(sim.wind().force_x());
  }
  return record;
}

TEST(Wind, SameSeedSameRunOtherSeedOtherRun) {
  const std::vector<double> a = gusty_run(7), b = gusty_run(7), c = gusty_run(8);
  EXPECT_EQ(a, b);  // bit for bit
  EXPECT_NE(a, c);
}

// The gust process alone: over 2000 correlation times its mean, standard deviation and lag-tau
// autocorrelation are the Gauss-Markov process's (mean F, std sigma, exp(-1)); the sample
// statistics' spread is about sigma / sqrt(1000) for the mean, so the bounds are 5-6 of those.
TEST(Wind, GustsHaveTheConfiguredMeanSpreadAndCorrelationTime) {
  const WindParameters wind{true, 1.0, -0.5, 2.0, 0.5, 11};
  WindForce force(wind, 0.01);
  const int lag = 50;  // tau / T_s
  std::vector<double> x;
  for (int k = 0; k < 100000; ++k) {  // 1000 s
    x.push_back(force.force_x());
    force.advance();
  }
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(x.size());
  double var = 0.0, cov = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    var += (x[i] - mean) * (x[i] - mean);
    if (i + lag < x.size()) cov += (x[i] - mean) * (x[i + lag] - mean);
  }
  const double stddev = std::sqrt(var / static_cast<double>(x.size()));
  const double correlation = cov / var;
  std::printf("gust force x over 1000 s: mean %.3f N, std %.3f N, autocorrelation at tau %.3f (configured 1.0, 2.0, %.3f)\n",
              mean, stddev, correlation, std::exp(-1.0));
  EXPECT_NEAR(mean, 1.0, 0.35);
  EXPECT_NEAR(stddev, 2.0, 0.2);
  EXPECT_NEAR(correlation, std::exp(-1.0), 0.05);
  force.reset();
  EXPECT_EQ(force.force_x(), 1.0);  // gusts start at 0
  EXPECT_EQ(force.force_y(), -0.5);
}

}  // namespace
}  // namespace crane::plant

namespace crane::plant {
namespace {

// ---------------------------------------------------------------------------------------------
// Elastic rope (RopeParameters): the load on a spring of stiffness k = EA / L along the cable.
// A soft rope (EA = 2000 N, k = 2000 N/m at 1 m, bounce sqrt(k/m) = 31.6 rad/s) keeps the tests short.
SimulatorParameters roped(double damping_ratio) {
  SimulatorParameters p;
  p.crane.trolley_friction = {};
  p.crane.slew_friction = {};
  p.rope = RopeParameters{true, 2000.0, damping_ratio};
  p.initial_state.trolley_position = 0.6;
  p.initial_state.cable_length = 1.0;
  return p;
}

// Braked, hanging still: the static stretch m g / k holds; 1 mm more bounces at sqrt(k/m).
TEST(Rope, StaticStretchHoldsAndTheLoadBouncesAtSqrtKOverM) {
  SimulatorParameters p = roped(0.0);
  const double m = p.crane.load_mass, g = p.crane.gravity, k = 2000.0 / 1.0;
  p.initial_state.rope_stretch = m * g / k;
  CraneSimulator still(p);
  ASSERT_EQ(still.model().coordinate_count(), 5);
  double worst = 0.0;
  for (int i = 0; i < 200; ++i) {
    ASSERT_EQ(still.step(DriveInput{}), common::StepStatus::ok);
    worst = std::max(worst, std::abs(still.state().rope_stretch - m * g / k));
  }
  EXPECT_LT(worst, 1e-9);
  p.initial_state.rope_stretch = m * g / k + 0.001;
  CraneSimulator bouncing(p);
  std::vector<double> crossings;
  double previous = bouncing.state().rope_stretch - m * g / k;
  while (crossings.size() < 21 && bouncing.time() < 5.0) {
    const double t0 = bouncing.time();
    ASSERT_EQ(bouncing.step(DriveInput{}), common::StepStatus::ok);
    const double now = bouncing.state().rope_stretch - m * g / k;
    if (previous > 0.0 && now <= 0.0) crossings.push_back(t0 + 0.01 * previous / (previous - now));
    previous = now;
  }
  ASSERT_EQ(crossings.size(), 21U);
  const double period = (crossings.back() - crossings.front()) / 20.0;
  const double expected = 2.0 * std::numbers::pi / std::sqrt(k / m);
  std::printf("rope: static stretch held to %.3g m; bounce period %.6f s, 2 pi / sqrt(k/m) = %.6f s\n", worst, period,
              expected);
  EXPECT_NEAR(period / expected, 1.0, 2e-3);  // crossings interpolated between 10 ms samples
}

// Damped bounce: the amplitude falls by exp(-2 pi zeta / sqrt(1 - zeta^2)) per period.
TEST(Rope, BounceDecaysWithTheConfiguredDampingRatio) {
  SimulatorParameters p = roped(0.05);
  const double m = p.crane.load_mass, g = p.crane.gravity, k = 2000.0;
  p.initial_state.rope_stretch = m * g / k + 0.002;
  CraneSimulator sim(p);
  // Peak of |s - s_eq| in the first and the sixth period (0.199 s each).
  const double period = 2.0 * std::numbers::pi / std::sqrt(k / m);
  double first = 0.0, sixth = 0.0;
  while (sim.time() < 6.0 * period) {
    ASSERT_EQ(sim.step(DriveInput{}), common::StepStatus::ok);
    const double a = std::abs(sim.state().rope_stretch - m * g / k);
    if (sim.time() > 0.5 * period && sim.time() <= 1.5 * period) first = std::max(first, a);
    if (sim.time() > 5.5 * period && sim.time() <= 6.0 * period + 1e-9) sixth = std::max(sixth, a);
  }
  const double expected = std::exp(-5.0 * 2.0 * std::numbers::pi * 0.05 / std::sqrt(1.0 - 0.05 * 0.05));
  std::printf("rope: amplitude ratio over 5 periods %.4f, expected %.4f\n", sixth / first, expected);
  EXPECT_NEAR(sixth / first, expected, 0.03);  // peaks sampled every 10 ms (period 199 ms)
}

// No damping, no friction, no input, constant L: T + V + 1/2 k s^2 is conserved while the load
// swings, the trolley moves and the rope bounces.
TEST(Rope, FrictionlessFreeMotionKeepsEnergy) {
  SimulatorParameters p = roped(0.0);
  p.initial_state.trolley_velocity = 0.2;
  p.initial_state.swing_in_plane = 0.3;
  p.initial_state.swing_out_of_plane = 0.2;
  p.initial_state.slew_rate = 0.5;
  p.initial_state.rope_stretch = 0.005;
  CraneSimulator sim(p);
  const double energy0 = sim.total_energy();
  DriveInput input;
  input.brakes_engaged = false;
  double worst = 0.0, smallest = 1.0, largest = -1.0;
  for (int i = 0; i < 500; ++i) {  // 5 s
    ASSERT_EQ(sim.step(input), common::StepStatus::ok);
    worst = std::max(worst, std::abs(sim.total_energy() - energy0) / std::abs(energy0));
    smallest = std::min(smallest, sim.state().rope_stretch);
    largest = std::max(largest, sim.state().rope_stretch);
  }
  std::printf("rope: energy %.6g J, worst relative drift %.3g; stretch between %.4f and %.4f m\n", energy0, worst,
              smallest, largest);
  EXPECT_LT(worst, 1e-6);
  EXPECT_GT(largest - smallest, 0.005);  // it bounced
}

// Hoisting: paying out rope softens it (k = EA / L); after lowering from 1.0 m to about 1.5 m and settling, the
// stretch is m g L / EA at the new length.
TEST(Rope, HoistingChangesTheStretchWithTheLength) {
  SimulatorParameters p = roped(0.3);
  const double m = p.crane.load_mass, g = p.crane.gravity;
  p.initial_state.rope_stretch = m * g * 1.0 / 2000.0;
  CraneSimulator sim(p);
  DriveInput lower;
  lower.hoist_speed = 0.2;
  while (sim.state().cable_length < 1.5 - 1e-9 && sim.time() < 5.0) {
    if (sim.state().cable_length > 1.5 - 0.2 * 0.01) lower.hoist_speed = (1.5 - sim.state().cable_length) / 0.01;
    ASSERT_EQ(sim.step(lower), common::StepStatus::ok);
  }
  DriveInput hold;
  for (int i = 0; i < 300; ++i) ASSERT_EQ(sim.step(hold), common::StepStatus::ok);
  const double L = sim.state().cable_length;
  std::printf("rope: at L = %.4f m the stretch is %.6f m, m g L / EA = %.6f m\n", L, sim.state().rope_stretch,
              m * g * L / 2000.0);
  EXPECT_NEAR(sim.state().rope_stretch, m * g * L / 2000.0, 1e-5);
  EXPECT_GT(L, 1.45);
}

TEST(Rope, ConfigurationErrorsNameTheField) {
  SimulatorParameters p = roped(0.0);
  p.rope.axial_stiffness = 0.5;
  EXPECT_THROW(CraneSimulator{p}, common::ConfigError);
  try {
    SimulatorParameters q = roped(0.0);
    q.hook.enabled = true;
    CraneSimulator sim(q);
    ADD_FAILURE() << "no ConfigError";
  } catch (const common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("plant.rope.enabled = true needs plant.hook.enabled = false"), std::string::npos)
        << e.what();
  }
  SimulatorParameters off;
  off.initial_state.rope_stretch = 0.01;
  EXPECT_THROW(CraneSimulator{off}, common::ConfigError);
}

}  // namespace
}  // namespace crane::plant
