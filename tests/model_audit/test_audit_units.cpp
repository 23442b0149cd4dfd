// Unit tests of the model-audit building blocks: the extended models against independent
// computations, the residual statistics, option and data validation, and crane_audit end to end.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/model_audit/audit_models.hpp"
#include "crane/model_audit/crane_swing.hpp"
#include "crane/model_audit/friction_experiment.hpp"
#include "crane/model_audit/hidden_effect_generator.hpp"
#include "crane/model_audit/model_audit.hpp"
#include "crane/model_audit/residual_analysis.hpp"
#include "audit_test_files.hpp"

#ifndef CRANE_AUDIT_EXECUTABLE
#error "CRANE_AUDIT_EXECUTABLE must name the crane_audit binary"
#endif

namespace ma = crane::model_audit;
namespace fs = std::filesystem;

namespace {

// Cross-check: the nominal extended axis equals the section-3.1 simulator's exact solution
// (advance_friction_axis, symmetric friction b+ = b-, c+ = c-), two independent codes.
TEST(AuditModels, NominalAxisMatchesFrictionExperimentIntegrator) {
  ma::AxisModel model;
  model.motor_constant = 1.7;
  model.viscous = 2.8 * 1.7;
  model.coulomb = 1.0 * 1.7;
  ma::FrictionExperimentParams params;
  params.viscous_negative = 2.8;
  params.coulomb_negative = 1.0;
  ma::AxisState state;
  double position = 0.0;
  double velocity = 0.0;
  for (int k = 0; k < 400; ++k) {
    const double u = 3.0 * std::sin(0.05 * k) + (k % 50 < 25 ? 0.5 : -0.5);
    ma::advance_axis(model, u, 0.01, 3, state);
    ma::advance_friction_axis(params, u, 0.01, position, velocity);
    ASSERT_NEAR(state.position, position, 1e-12) << k;
    ASSERT_NEAR(state.velocity, velocity, 1e-12) << k;
  }
}

// Stiction: with drive K_m u = 1.5 c the nominal axis moves, an axis with Delta_s = c stays put
// (breakaway needs 2 c).
TEST(AuditModels, StictionHoldsTheAxisBelowBreakaway) {
  ma::AxisModel model;
  const double u = 1.5 * model.coulomb / model.motor_constant;
  ma::AxisState free_state;
  ma::advance_axis(model, u, 0.1, 1, free_state);
  EXPECT_GT(free_state.position, 0.0);
  model.stiction = model.coulomb;
  ma::AxisState stuck;
  ma::advance_axis(model, u, 0.1, 1, stuck);
  EXPECT_EQ(stuck.position, 0.0);
}

// Backlash: the measured side lags by half the gap once engaged: motor moving + at the end.
TEST(AuditModels, BacklashLagsByHalfTheGap) {
  ma::AxisModel model;
  model.backlash = 0.004;
  ma::AxisState state;
  ma::advance_axis(model, 20.0, 0.5, 4, state);
  EXPECT_NEAR(state.position - state.load_position, 0.002, 1e-12);
}

// Small-angle pendulum: period 2 pi sqrt(L / g); after one period the angle returns.
TEST(AuditModels, PendulumSmallAnglePeriod) {
  ma::PendulumModel model;
  model.length = 2.0;
  const double period = 2.0 * std::numbers::pi * std::sqrt(model.length / model.gravity);
  ma::PendulumState state{1e-3, 0.0};
  ma::advance_pendulum(model, 0.0, period, 2000, state);
  EXPECT_NEAR(state.angle, 1e-3, 1e-8);  // (1 - cos) nonlinearity at 1 mrad is ~1e-7 relative
}

// follow_swing against the plant's own dynamics: the lab crane with a hook (or an elastic rope),
// driven by a trolley force and a slew torque, integrated over all its rows (TowerCraneModel::
// extended_acceleration, RK4 at 1 ms: no swing elimination, no held motion); its cable angles and
// rates at 100 Hz, with the drive motion as the crane audit holds it, go to follow_swing, whose
// rigging angles (stretch) must follow the simulation's. Returns the largest error of the followed
// extended coordinate against the largest motion of it relative to the cable (the rigging's angle
// to the cable; the stretch's excursion from its static value).
double follow_swing_error(const crane::model_audit::SwingEffects& effects, double* largest_motion) {
  namespace plant = crane::plant;
  crane::common::CraneParameters crane;
  crane.load_mass = 2.0;
  crane.cable_length = 0.9;
  const bool hooked = effects.rigging_length > 0.0;
  const plant::TowerCraneModel model = hooked ? ma::hooked_model(crane, effects) : ma::roped_model(crane, effects);
  const plant::HoistMotion hoist{crane.cable_length, 0.0, 0.0};
  plant::ExtendedState q;
  q.position[plant::kTrolleyIndex] = 0.6;
  if (!hooked) q.position[4] = model.parameters().load_mass * crane.gravity * crane.cable_length / model.rope().axial_stiffness;
  const double rest_stretch = q.position[4];
  const auto force = [](double t) {  // [N], [N m]: a trolley push and return, a slew swing, then free
    plant::ExtendedVector f = plant::ExtendedVector::Zero();
    if (t < 4.0) {
      f[plant::kTrolleyIndex] = 30.0 * std::sin(std::numbers::pi * t / 2.0);
      f[plant::kSlewIndex] = 15.0 * std::sin(std::numbers::pi * t);
    }
    return f;
  };
  const auto rates = [&](const plant::ExtendedState& s, double t, plant::ExtendedVector& acc) {
    acc = model.extended_acceleration(s, hoist, force(t));
  };
  constexpr double kSample = 0.01;
  constexpr int kSubsteps = 10;
  constexpr std::size_t kSamples = 800;
  std::vector<plant::ExtendedState> states;
  std::vector<plant::ExtendedVector> accelerations;
  double t = 0.0;
  for (std::size_t k = 0; k < kSamples; ++k) {
    plant::ExtendedVector a;
    rates(q, t, a);
    states.push_back(q);
    accelerations.push_back(a);
    const double h = kSample / kSubsteps;
    for (int i = 0; i < kSubsteps; ++i) {
      plant::ExtendedVector a1, a2, a3, a4;
      plant::ExtendedState s = q;
      rates(s, t, a1);
      s.position = q.position + 0.5 * h * q.velocity;
      s.velocity = q.velocity + 0.5 * h * a1;
      const plant::ExtendedVector v2 = s.velocity;
      rates(s, t + 0.5 * h, a2);
      s.position = q.position + 0.5 * h * v2;
      s.velocity = q.velocity + 0.5 * h * a2;
      const plant::ExtendedVector v3 = s.velocity;
      rates(s, t + 0.5 * h, a3);
      s.position = q.position + h * v3;
      s.velocity = q.velocity + h * a3;
      const plant::ExtendedVector v4 = s.velocity;
      rates(s, t + h, a4);
      q.position += h / 6.0 * (q.velocity + 2.0 * v2 + 2.0 * v3 + v4);
      q.velocity += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
      t += h;
    }
  }
  // The drive motion held per sample as the crane audit holds it: positions and rates at t_k, the
  // mean acceleration of the interval.
  std::vector<ma::DriveMotion> motion(kSamples);
  std::vector<ma::SwingState> cable(kSamples);
  for (std::size_t k = 0; k < kSamples; ++k) {
    const std::size_t next = std::min(k + 1, kSamples - 1);
    const auto& s = states[k];
    motion[k] = {s.position[plant::kTrolleyIndex], s.velocity[plant::kTrolleyIndex],
                 0.5 * (accelerations[k][plant::kTrolleyIndex] + accelerations[next][plant::kTrolleyIndex]),
                 s.position[plant::kSlewIndex], s.velocity[plant::kSlewIndex],
                 0.5 * (accelerations[k][plant::kSlewIndex] + accelerations[next][plant::kSlewIndex]),
                 crane.cable_length, 0.0, 0.0};
    cable[k] = {s.position[plant::kInPlaneSwingIndex], s.velocity[plant::kInPlaneSwingIndex],
                s.position[plant::kOutOfPlaneSwingIndex], s.velocity[plant::kOutOfPlaneSwingIndex]};
  }
  const auto followed = ma::follow_swing(plant::TowerCraneModel(crane), effects, motion, cable, kSample);
  double error = 0.0;
  double largest = 0.0;
  for (std::size_t k = 0; k < kSamples; ++k) {
    const auto& s = states[k];
    if (hooked) {
      error = std::max({error, std::abs(followed[k].rigging_in_plane - s.position[4]),
                        std::abs(followed[k].rigging_out_of_plane - s.position[5])});
      largest = std::max({largest, std::abs(s.position[4] - s.position[plant::kInPlaneSwingIndex]),
                          std::abs(s.position[5] - s.position[plant::kOutOfPlaneSwingIndex])});
    } else {
      error = std::max(error, std::abs(followed[k].rigging_in_plane - s.position[4]));
      largest = std::max(largest, std::abs(s.position[4] - rest_stretch));
    }
  }
  *largest_motion = largest;
  return error;
}

TEST(CraneSwing, FollowSwingTracksTheHooksRiggingOfTheFullModel) {
  ma::SwingEffects hook;
  hook.rigging_length = 0.3;
  hook.hook_mass_share = 0.2;
  double largest = 0.0;
  const double error = follow_swing_error(hook, &largest);
  std::printf("hook: rigging angle to the cable up to %.4g rad, followed within %.3g rad\n", largest, error);
  EXPECT_GT(largest, 0.02);  // the rigging does swing against the cable
  EXPECT_LT(error, 0.01 * largest);  // measured: 0.03 % (hook), 0.13 % (rope)
}

TEST(CraneSwing, FollowSwingTracksTheRopesStretchOfTheFullModel) {
  ma::SwingEffects rope;
  rope.rope_stretch_ratio = 0.02;
  double largest = 0.0;
  const double error = follow_swing_error(rope, &largest);
  std::printf("rope: stretch excursion up to %.4g m, followed within %.3g m\n", largest, error);
  EXPECT_GT(largest, 1e-4);
  EXPECT_LT(error, 0.01 * largest);  // measured: 0.03 % (hook), 0.13 % (rope)
}

// Coulomb pendulum: the amplitude drops by 4 mu / omega^2 per cycle (linear decay).
TEST(AuditModels, PendulumCoulombLinearDecay) {
  ma::PendulumModel model;
  model.length = 1.0;
  model.coulomb = 0.02;
  const double omega2 = model.gravity / model.length;
  const double period = 2.0 * std::numbers::pi / std::sqrt(omega2);
  ma::PendulumState state{0.05, 0.0};
  ma::advance_pendulum(model, 0.0, period, 4000, state);
  EXPECT_NEAR(state.angle, 0.05 - 4.0 * model.coulomb / omega2, 2e-5);  // small-angle estimate
}

TEST(ResidualAnalysis, ChiSquareAndLjungBox) {
  EXPECT_NEAR(ma::chi_square_survival(3.841458820694124, 1.0), 0.05, 1e-9);
  EXPECT_NEAR(ma::chi_square_survival(18.307038053275146, 10.0), 0.05, 1e-9);
  std::mt19937_64 rng(3);
  std::normal_distribution<double> normal;
  std::vector<double> white(2000);
  for (auto& e : white) e = normal(rng);
  EXPECT_GT(ma::ljung_box(white, 20).p_value, 0.01);
  std::vector<double> ar(2000);
  for (std::size_t i = 1; i < ar.size(); ++i) ar[i] = 0.8 * ar[i - 1] + normal(rng);
  const auto test = ma::ljung_box(ar, 20);
  EXPECT_LT(test.p_value, 1e-9);
  EXPECT_NEAR(test.autocorrelation[0], 0.8, 0.05);
}

TEST(AuditOptions, UnknownParameterAndCauseAreRefusedByName) {
  try {
    (void)ma::nominal_from_values(ma::AuditPlant::axis, {{"K_m", 1.7}, {"b", 4.0}, {"c", 1.7}, {"mass", 3.0}});
    FAIL() << "unknown parameter accepted";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'mass'"), std::string::npos) << e.what();
  }
  ma::AuditOptions options;
  options.nominal = ma::nominal_from_values(ma::AuditPlant::axis, {{"K_m", 1.7}, {"b", 4.0}, {"c", 1.7}});
  options.causes = {"friction_of_the_gods"};
  try {
    ma::validate(options);
    FAIL() << "unknown cause accepted";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("friction_of_the_gods"), std::string::npos) << e.what();
  }
  options.causes = {"stiction"};
  EXPECT_NO_THROW(ma::validate(options));
  EXPECT_THROW((void)ma::nominal_from_values(ma::AuditPlant::axis, {{"K_m", 1.7}, {"b", 4.0}}),
               crane::common::ConfigError);
  // A nominal never given (the required fields are NaN until set) is refused too.
  options.nominal = ma::AxisAuditParameters{};
  EXPECT_THROW(ma::validate(options), crane::common::ConfigError);
}

// Each model's catalog: non-empty, names unique; the crane's is the axis catalog once per drive, the
// pendulum catalog, the crane-only swing entries (wind_force, hook_double_pendulum, elastic_rope)
// and payload_mass_error (29 entries).
TEST(AuditCatalog, EveryModelHasAUniqueNonEmptyCatalog) {
  for (const auto plant : {ma::AuditPlant::axis, ma::AuditPlant::pendulum, ma::AuditPlant::crane}) {
    const auto& catalog = ma::audit_catalog(plant);
    EXPECT_FALSE(catalog.empty()) << ma::plant_name(plant);
    std::vector<std::string> sorted = catalog;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << ma::plant_name(plant);
  }
  const auto& axis = ma::audit_catalog(ma::AuditPlant::axis);
  const auto& pendulum = ma::audit_catalog(ma::AuditPlant::pendulum);
  const auto& crane = ma::audit_catalog(ma::AuditPlant::crane);
  EXPECT_EQ(axis.size(), 10U);
  EXPECT_EQ(pendulum.size(), 5U);
  ASSERT_EQ(crane.size(), 2 * axis.size() + pendulum.size() + 4);
  for (std::size_t i = 0; i < axis.size(); ++i) {
    EXPECT_EQ(crane[i], "trolley_" + axis[i]);
    EXPECT_EQ(crane[axis.size() + i], "slew_" + axis[i]);
  }
  for (std::size_t i = 0; i < pendulum.size(); ++i) EXPECT_EQ(crane[2 * axis.size() + i], pendulum[i]);
  const std::size_t crane_only = 2 * axis.size() + pendulum.size();
  EXPECT_EQ(crane[crane_only], "wind_force");
  EXPECT_EQ(crane[crane_only + 1], "hook_double_pendulum");
  EXPECT_EQ(crane[crane_only + 2], "elastic_rope");
  EXPECT_EQ(crane.back(), "payload_mass_error");
  // The crane-only swing entries are not in the lab pendulum's catalog.
  for (const char* name : {"wind_force", "hook_double_pendulum", "elastic_rope"}) {
    EXPECT_EQ(std::find(pendulum.begin(), pendulum.end(), name), pendulum.end()) << name;
  }
}

// Typed parameters round-trip through their report names: every field of each model's table set to
// a distinct value, written as names and read back, gives the same struct; the names are those of
// audit_parameter_names() and of the JSON report.
TEST(AuditParameters, TypedParametersRoundTripThroughTheReportNames) {
  ma::AxisAuditParameters axis;
  axis.motor_constant = 1.5;
  axis.viscous = 4.25;
  axis.coulomb = 1.75;
  axis.coulomb_asymmetry = -0.125;
  axis.viscous_asymmetry = 0.375;
  axis.stiction = 0.5;
  axis.stiction_asymmetry = -0.25;
  const auto axis_values = ma::parameter_values(axis);
  EXPECT_EQ(axis_values.at("K_m"), 1.5);
  EXPECT_EQ(axis_values.at("b"), 4.25);
  EXPECT_EQ(axis_values.at("c"), 1.75);
  EXPECT_EQ(axis_values.at("stiction_asymmetry"), -0.25);
  const auto axis_back = std::get<ma::AxisAuditParameters>(ma::nominal_from_values(ma::AuditPlant::axis, axis_values));
  EXPECT_EQ(axis_back.motor_constant, axis.motor_constant);
  EXPECT_EQ(axis_back.viscous, axis.viscous);
  EXPECT_EQ(axis_back.coulomb, axis.coulomb);
  EXPECT_EQ(axis_back.coulomb_asymmetry, axis.coulomb_asymmetry);
  EXPECT_EQ(axis_back.viscous_asymmetry, axis.viscous_asymmetry);
  EXPECT_EQ(axis_back.stiction, axis.stiction);
  EXPECT_EQ(axis_back.stiction_asymmetry, axis.stiction_asymmetry);

  ma::PendulumAuditParameters pendulum;
  pendulum.length = 0.75;
  pendulum.damping = 0.0625;
  pendulum.gravity = 9.81;
  EXPECT_FALSE(ma::parameter_values(pendulum).contains("theta_zero"));  // estimated: not a value
  pendulum.theta_zero = 3.0;
  const auto pendulum_values = ma::parameter_values(pendulum);
  EXPECT_EQ(pendulum_values.size(), ma::audit_parameter_names(ma::AuditPlant::pendulum).size());
  const auto pendulum_back =
      std::get<ma::PendulumAuditParameters>(ma::nominal_from_values(ma::AuditPlant::pendulum, pendulum_values));
  EXPECT_EQ(pendulum_back.length, 0.75);
  EXPECT_EQ(pendulum_back.damping, 0.0625);
  EXPECT_EQ(pendulum_back.gravity, 9.81);
  EXPECT_EQ(pendulum_back.theta_zero, std::optional<double>(3.0));

  for (const auto plant : {ma::AuditPlant::axis, ma::AuditPlant::pendulum, ma::AuditPlant::crane}) {
    const auto& names = ma::audit_parameter_names(plant);
    std::vector<std::string> sorted = names;
    std::sort(sorted.begin(), sorted.end());
    EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << ma::plant_name(plant);
  }
  const auto crane_values = ma::parameter_values(crane::common::CraneParameters{});
  std::vector<std::string> crane_names;
  for (const auto& [name, value] : crane_values) crane_names.push_back(name);
  EXPECT_EQ(crane_names, ma::audit_parameter_names(ma::AuditPlant::crane));
}

std::string rows(std::size_t n, const std::string& bad_row = "", std::size_t bad_at = 0) {
  return ma::test::rows(n, "t,u,x", [](std::size_t k) {
    std::ostringstream row;
    row << 0.01 * static_cast<double>(k) << ",0.5," << 1e-3 * static_cast<double>(k);
    return row.str();
  }, bad_row, bad_at);
}

void expect_refused(const fs::path& path, const std::string& needle) {
  ma::test::expect_refused(path, ma::AuditPlant::axis, needle);
}

using ma::test::run_tool;
using ma::test::write_file;

TEST(AuditData, BadInputIsRefusedNamingRowOrColumn) {
  expect_refused(write_file("nan.csv", rows(100, "0.5,nan,0.0", 50)), "row 53");
  expect_refused(write_file("time.csv", rows(100, "0.3,0.5,0.0", 50)), "row 53");
  expect_refused(write_file("few.csv", rows(10)), "at least 50");
  expect_refused(write_file("missing.csv", "t,u\n0,1\n0.01,1\n"), "'x'");
  std::string uneven = rows(100);
  uneven.replace(uneven.find("\n0.5,"), 5, "\n0.505,");
  expect_refused(write_file("uneven.csv", uneven), "not uniform");
  EXPECT_NO_THROW((void)ma::read_audit_data(write_file("good.csv", rows(100)), ma::AuditPlant::axis, "", 0.0));
}

TEST(CraneAuditCli, WritesTheReportAndRefusesBadOptions) {
  const fs::path dir = crane::model_audit::test::test_directory() / "cli_test";
  fs::remove_all(dir);
  const fs::path data = dir.string() + "_case.csv";
  ASSERT_EQ(run_tool("generate --model axis --effect gain_error --seed 4 --out " + data.string()), 0);
  const auto c = ma::generate_hidden_effect_case(ma::AuditPlant::axis, "gain_error", 4);
  std::string params;
  for (const auto& [k, v] : ma::parameter_values(c.nominal)) params += " --param " + k + "=" + crane::common::format_value(v);
  EXPECT_EQ(run_tool("--model axis --data " + data.string() + params + " --out " + dir.string()), 0);
  std::ifstream report(dir / "report.json");
  std::stringstream text;
  text << report.rdbuf();
  EXPECT_NE(text.str().find("\"cause\": \"gain_error\""), std::string::npos) << text.str().substr(0, 400);
  EXPECT_NE(text.str().find("\"gain\""), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "report.md"));
  EXPECT_EQ(run_tool("--model axis --data " + data.string() + params + " --param mass=3 --out " + dir.string()), 2);
  EXPECT_EQ(run_tool("--model axis --data " + data.string() + params + " --cause nonsense --out " + dir.string()), 2);
  EXPECT_EQ(run_tool("--model axis --data " + data.string() + params + " --columns t=time --out " + dir.string()), 2);
  EXPECT_EQ(run_tool("--model crane --data " + data.string() + " --out " + dir.string()), 2);
}

}  // namespace
