// The crane model of the audit: bad input refused naming the row/column/cause, the parameter
// mapping, the inverse dynamics against the plant model, and a simulated stack recording (the
// hidden-effect generator with effect none: closed-loop trolley and slew PD on the full plant with
// encoder quantization) audited against the right and against a wrong payload mass.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <fstream>
#include <limits>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/model_audit/crane_swing.hpp"
#include "crane/model_audit/hidden_effect_generator.hpp"
#include "crane/model_audit/model_audit.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "audit_test_files.hpp"
#include "audit_test_report.hpp"

#if !defined(CRANE_AUDIT_EXECUTABLE) || !defined(CRANE_LAB_CONFIG)
#error "CRANE_AUDIT_EXECUTABLE and CRANE_LAB_CONFIG must name crane_audit and the lab configuration"
#endif

namespace ma = crane::model_audit;
namespace fs = std::filesystem;

namespace {

// n rows of a plausible crane record; data row `bad_at` replaced by `bad_row`.
std::string crane_rows(std::size_t n, const std::string& header = "t,u_x,u_gamma,x,gamma,phi,theta,L",
                       const std::string& bad_row = "", std::size_t bad_at = 0) {
  return ma::test::rows(n, header, [](std::size_t k) {
    const double t = 0.01 * static_cast<double>(k);
    std::ostringstream row;
    row << t << ",0.5,0.2," << 0.5 + 1e-3 * static_cast<double>(k) << "," << 1e-3 * static_cast<double>(k) << ","
        << 0.01 * std::sin(t) << "," << 0.01 * std::cos(t) << ",1.0";
    return row.str();
  }, bad_row, bad_at);
}

void expect_refused(const fs::path& path, const std::string& needle) {
  ma::test::expect_refused(path, ma::AuditPlant::crane, needle);
}

using ma::test::env_count;
using ma::test::run_tool;
using ma::test::write_file;

TEST(CraneAuditData, BadInputIsRefusedNamingRowColumnOrCause) {
  // Data rows start at file line 3 (comment, header): data row 50 is "row 53".
  std::string without_length = crane_rows(100, "t,u_x,u_gamma,x,gamma,phi,theta");
  for (auto at = without_length.find(",1.0\n"); at != std::string::npos; at = without_length.find(",1.0\n", at)) {
    without_length.erase(at, 4);  // drop the L cell of every row
  }
  expect_refused(write_file("missing.csv", without_length), "'L'");
  expect_refused(write_file("nan.csv", crane_rows(100, "t,u_x,u_gamma,x,gamma,phi,theta,L",
                                                  "0.5,0.5,0.2,0.55,0.05,nan,0.0,1.0", 50)),
                 "row 53");
  expect_refused(write_file("nan_column.csv", crane_rows(100, "t,u_x,u_gamma,x,gamma,phi,theta,L",
                                                         "0.5,0.5,0.2,0.55,0.05,nan,0.0,1.0", 50)),
                 "phi");
  expect_refused(write_file("time.csv", crane_rows(100, "t,u_x,u_gamma,x,gamma,phi,theta,L",
                                                   "0.3,0.5,0.2,0.55,0.05,0.0,0.0,1.0", 50)),
                 "row 53");
  expect_refused(write_file("few.csv", crane_rows(10)), "at least 50");
  expect_refused(write_file("length.csv", crane_rows(100, "t,u_x,u_gamma,x,gamma,phi,theta,L",
                                                     "0.5,0.5,0.2,0.55,0.05,0.0,0.0,-1.0", 50)),
                 "cable length");
  // Columns mapped from other names.
  const auto data = ma::read_audit_data(write_file("mapped.csv", crane_rows(100, "time,ux,ug,x,gamma,phi,theta,L")),
                                        ma::AuditPlant::crane, "t=time,u_x=ux,u_gamma=ug", 0.0);
  EXPECT_EQ(data.slew_input.size(), 100U);
  EXPECT_EQ(data.cable_length.size(), 100U);

  ma::AuditOptions options;
  options.nominal = crane::common::CraneParameters{};
  options.causes = {"trolley_stiction", "slew_friction_of_the_gods"};
  try {
    ma::validate(options);
    FAIL() << "unknown cause accepted";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("slew_friction_of_the_gods"), std::string::npos) << e.what();
  }
  options.causes = {"stiction"};  // an axis name without the drive prefix is not a crane cause
  EXPECT_THROW(ma::validate(options), crane::common::ConfigError);
  options.causes = {"trolley_stiction", "payload_mass_error", "encoder_offset"};
  EXPECT_NO_THROW(ma::validate(options));
  auto values = ma::parameter_values(options.nominal);
  values.erase("jib_inertia");
  try {
    (void)ma::nominal_from_values(ma::AuditPlant::crane, values);
    FAIL() << "missing parameter accepted";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("jib_inertia"), std::string::npos) << e.what();
  }
}

TEST(CraneAuditData, ParameterMappingRoundTripsAndDriveAxisFollowsThePlantRule) {
  crane::common::CraneParameters crane;
  crane.load_mass = 2.4;
  const auto back = std::get<crane::common::CraneParameters>(
      ma::nominal_from_values(ma::AuditPlant::crane, ma::parameter_values(crane)));
  EXPECT_EQ(back.load_mass, 2.4);
  EXPECT_EQ(back.slew_friction.static_negative, crane.slew_friction.static_negative);
  EXPECT_THROW((void)ma::override_values(crane::common::CraneParameters{}, {{"load_mass", -1.0}}),
               crane::common::ConfigError);
  // Trolley of the lab crane (K = 2): b+ = 1.5, b- = 6 V s/m -> b = 2 * 3.75 = 7.5, db = 2 * (-2.25) = -4.5;
  // c+ = 0.9, c- = 1.2 V -> c = 2.1, dc = -0.3; static 1.0 / 1.2 V -> excess 0.1 / 0 V -> stiction
  // 2 * 0.05 = 0.1 and asymmetry 0.1 [m/s^2].
  const auto axis = ma::drive_axis_parameters(crane.trolley_friction, crane.trolley_drive_gain);
  EXPECT_NEAR(axis.viscous, 7.5, 1e-12);
  EXPECT_NEAR(axis.viscous_asymmetry, -4.5, 1e-12);
  EXPECT_NEAR(axis.coulomb, 2.1, 1e-12);
  EXPECT_NEAR(axis.coulomb_asymmetry, -0.3, 1e-12);
  EXPECT_NEAR(axis.stiction, 0.1, 1e-12);
  EXPECT_NEAR(axis.stiction_asymmetry, 0.1, 1e-12);
}

// The configuration's drive terms back from the axis nominal: the inverse of drive_axis_parameters,
// to rounding, for both drives of the lab crane; a negative coefficient is refused naming it.
TEST(CraneAuditData, DriveParametersFromTheAxisNominalInvertTheMapping) {
  const crane::common::CraneParameters crane;
  for (const auto& [friction, gain] : {std::pair{crane.trolley_friction, crane.trolley_drive_gain},
                                       std::pair{crane.slew_friction, crane.slew_drive_gain}}) {
    const auto back = ma::drive_parameters_from_axis(ma::drive_axis_parameters(friction, gain));
    EXPECT_NEAR(back.gain, gain, 1e-15);
    EXPECT_NEAR(back.friction.viscous_positive, friction.viscous_positive, 1e-12);
    EXPECT_NEAR(back.friction.viscous_negative, friction.viscous_negative, 1e-12);
    EXPECT_NEAR(back.friction.coulomb_positive, friction.coulomb_positive, 1e-12);
    EXPECT_NEAR(back.friction.coulomb_negative, friction.coulomb_negative, 1e-12);
    // The plant's rule keeps max(static, coulomb): a static below Coulomb comes back as Coulomb.
    EXPECT_NEAR(back.friction.static_positive, std::max(friction.static_positive, friction.coulomb_positive), 1e-12);
    EXPECT_NEAR(back.friction.static_negative, std::max(friction.static_negative, friction.coulomb_negative), 1e-12);
  }
  auto axis = ma::drive_axis_parameters(crane.trolley_friction, crane.trolley_drive_gain);
  axis.coulomb = -1.0;
  try {
    (void)ma::drive_parameters_from_axis(axis);
    ADD_FAILURE() << "a negative Coulomb coefficient was accepted";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("coulomb_positive"), std::string::npos) << e.what();
  }
}

// Cross-check of the swing elimination against the plant model's own forward dynamics: with the
// drive forces that eliminate_swing says the motion needs, TowerCraneModel::acceleration must give
// back the same drive and swing accelerations (two independent computations).
TEST(CraneSwing, EliminationMatchesTheForwardDynamics) {
  crane::common::CraneParameters parameters;
  const crane::plant::TowerCraneModel model(parameters);
  crane::plant::ModelState state;
  state.position << 0.8, 0.2, 0.3, -0.15;
  state.velocity << 0.3, -0.4, 0.5, 0.2;
  const crane::plant::HoistMotion hoist{1.2, 0.1, -0.05};
  crane::plant::CoordinateMatrix mass;
  crane::plant::CoordinateVector bias;
  model.compute_dynamics(state, hoist, mass, bias);
  const ma::SwingElimination e = ma::eliminate_swing(mass, bias);
  const Eigen::Vector2d drive_acceleration(0.7, -1.1);
  const Eigen::Vector2d force = e.drive_inertia * drive_acceleration + e.drive_bias;
  crane::plant::CoordinateVector q;
  q << force(0), 0.0, force(1), 0.0;
  const crane::plant::CoordinateVector forward = model.acceleration(state, hoist, q);
  EXPECT_NEAR(forward[crane::plant::kTrolleyIndex], 0.7, 1e-9);
  EXPECT_NEAR(forward[crane::plant::kSlewIndex], -1.1, 1e-9);
  const Eigen::Vector2d swing = e.swing_gain * drive_acceleration + e.swing_free;
  EXPECT_NEAR(forward[crane::plant::kInPlaneSwingIndex], swing(0), 1e-9);
  EXPECT_NEAR(forward[crane::plant::kOutOfPlaneSwingIndex], swing(1), 1e-9);
}

TEST(CraneAudit, StackRecordingGivesNoneAndAWrongPayloadIsFound) {
  const auto c = ma::generate_hidden_effect_case(ma::AuditPlant::crane, "none", 77);
  ma::AuditOptions options;
  options.nominal = c.nominal;
  const auto clean = ma::run_audit(c.data, options);
  EXPECT_EQ(clean.cause, "none") << clean.stop_reason;
  ASSERT_EQ(clean.channels.size(), 3U);

  const double true_mass = std::get<crane::common::CraneParameters>(c.nominal).load_mass;
  std::get<crane::common::CraneParameters>(options.nominal).load_mass = 1.25 * true_mass;  // the configuration is 25 % off
  const auto wrong = ma::run_audit(c.data, options);
  ASSERT_EQ(wrong.cause, "payload_mass_error") << wrong.stop_reason;
  double fitted_mass = 0.0;
  for (const auto& p : wrong.parameters) {
    if (p.name == "load_mass") fitted_mass = p.value;
  }
  EXPECT_NEAR(fitted_mass, true_mass, 0.1 * true_mass);
}

// --calibrate on the crane: a clean recording audited against a configuration whose drive gains
// and Coulomb friction are off (trolley gain -15 %, Coulomb +0.4 V both ways (+33-44 %); slew gain +10 %). Without
// calibration the audit blames a drive; with it, each drive's K_m, b, c are fitted first, the
// answer is `none`, and the report's nominal gives the true gains and Coulomb levels back in the
// configuration's terms. A payload 25 % off is not a drive parameter: calibrated, it is still found.
TEST(CraneAudit, CalibrateRecoversTheDrivesAndStillFindsAWrongPayload) {
  const auto c = ma::generate_hidden_effect_case(ma::AuditPlant::crane, "none", 77);
  const auto& truth = std::get<crane::common::CraneParameters>(c.nominal);
  crane::common::CraneParameters off = truth;
  off.trolley_drive_gain *= 0.85;
  off.trolley_friction.coulomb_positive += 0.4;  // [V] both directions alike: the asymmetry as configured
  off.trolley_friction.coulomb_negative += 0.4;
  // The breakaway excess over Coulomb as configured (calibration fits K_m, b, c, not stiction).
  off.trolley_friction.static_positive += off.trolley_friction.coulomb_positive - truth.trolley_friction.coulomb_positive;
  off.trolley_friction.static_negative += off.trolley_friction.coulomb_negative - truth.trolley_friction.coulomb_negative;
  off.slew_drive_gain *= 1.1;
  ma::AuditOptions options;
  options.nominal = off;
  const auto plain = ma::run_audit(c.data, options);
  EXPECT_NE(plain.cause, "none") << "the wrong drives went unnoticed: " << plain.stop_reason;
  std::printf("[ figure   ] uncalibrated: cause %s\n", plain.cause.c_str());

  options.calibrate = true;
  const auto calibrated = ma::run_audit(c.data, options);
  EXPECT_EQ(calibrated.cause, "none") << calibrated.stop_reason;
  std::map<std::string, ma::FittedParameter> nominal;
  for (const auto& p : calibrated.nominal) nominal[p.name] = p;
  const auto expect_within = [&](const std::string& name, double true_value, double tolerance) {
    ASSERT_EQ(nominal.count(name), 1U) << name;
    const double relative = nominal[name].value / true_value - 1.0;
    std::printf("[ figure   ] calibrated %s = %.6g (true %.6g, %+.3f %%, standard error %.3g)\n", name.c_str(),
                nominal[name].value, true_value, 100.0 * relative, nominal[name].standard_error);
    EXPECT_LT(std::fabs(relative), tolerance) << name;
    EXPECT_GT(nominal[name].standard_error, 0.0) << name;
  };
  expect_within("trolley_drive_gain", truth.trolley_drive_gain, 0.02);
  expect_within("slew_drive_gain", truth.slew_drive_gain, 0.02);
  expect_within("trolley_coulomb_positive", truth.trolley_friction.coulomb_positive, 0.10);
  expect_within("trolley_coulomb_negative", truth.trolley_friction.coulomb_negative, 0.10);
  EXPECT_EQ(nominal["load_mass"].value, truth.load_mass);  // not a drive parameter: as configured

  std::get<crane::common::CraneParameters>(options.nominal).load_mass = 1.25 * truth.load_mass;
  const auto heavy = ma::run_audit(c.data, options);
  ASSERT_EQ(heavy.cause, "payload_mass_error") << heavy.stop_reason;
  double fitted_mass = 0.0;
  for (const auto& p : heavy.parameters) {
    if (p.name == "load_mass") fitted_mass = p.value;
  }
  std::printf("[ figure   ] calibrated, load 25 %% off: payload_mass_error, load_mass %.5g kg (true %.5g)\n", fitted_mass,
              truth.load_mass);
  EXPECT_NEAR(fitted_mass, truth.load_mass, 0.1 * truth.load_mass);
}

// A recording of the project's own plant simulator (plant::CraneSimulator: SUNDIALS with exact
// stick-slip event location, the DAC and the encoders; an integrator independent of the audit's
// and of the generator's) under a PD on each drive, 18 s at 100 Hz, the generator's sines without
// its creep phase. The recorder reports the middle of each encoder count (the simulator's counts
// are lower edges); `phi_offset` [rad] is added to the recorded in-plane swing (an encoder offset).
ma::AuditData record_plant_simulator(const crane::plant::SimulatorParameters& parameters, double phi_offset = 0.0) {
  crane::plant::CraneSimulator simulator(parameters);
  const auto& sensors = simulator.drives_and_sensors();
  const double period = parameters.sample_period;
  const double centre = parameters.initial_state.trolley_position;
  ma::AuditData data;
  data.source = "plant::CraneSimulator recording";
  double previous_x = centre;
  double previous_gamma = 0.0;
  for (std::size_t k = 0; k <= 1800; ++k) {
    const double t = static_cast<double>(k) * period;
    const auto m = simulator.output().measurement;
    const double x = m.trolley_position + 0.5 * sensors.trolley_resolution();
    const double gamma = m.slew_angle + 0.5 * sensors.slew_resolution();
    const double trolley_reference = centre + 0.2 * std::sin(2.0 * std::numbers::pi * 0.25 * t) - 0.2 * std::sin(2.0 * std::numbers::pi * t / 3.0);
    const double slew_reference = 0.25 * std::sin(2.0 * std::numbers::pi * 0.15 * t) - 0.25 * std::sin(2.0 * std::numbers::pi * 0.3 * t);
    const double v_x = k == 0 ? 0.0 : (x - previous_x) / period;
    const double v_gamma = k == 0 ? 0.0 : (gamma - previous_gamma) / period;
    previous_x = x;
    previous_gamma = gamma;
    crane::plant::DriveInput input;
    input.trolley_voltage = 100.0 * (trolley_reference - x - 0.2 * v_x);
    input.slew_voltage = 40.0 * (slew_reference - gamma - 0.2 * v_gamma);
    input.brakes_engaged = false;
    EXPECT_EQ(simulator.step(input), crane::common::StepStatus::ok);
    data.time.push_back(t);
    data.input.push_back(simulator.output().applied_trolley_voltage);  // held over [t_k, t_k+1)
    data.slew_input.push_back(simulator.output().applied_slew_voltage);
    data.output.push_back(x);
    data.slew_angle.push_back(gamma);
    data.swing_in_plane.push_back(m.swing_in_plane + 0.5 * sensors.swing_resolution() + phi_offset);
    data.swing_out_of_plane.push_back(m.swing_out_of_plane + 0.5 * sensors.swing_resolution());
    data.cable_length.push_back(m.cable_length);
  }
  return data;
}

// Audited against its own configuration: none; with the load mass 20 % low in the nominal:
// payload_mass_error with the plant's mass within 10 %.
TEST(CraneAudit, PlantSimulatorRecordingGivesNoneAndAWrongPayloadIsFound) {
  crane::plant::SimulatorParameters parameters;
  parameters.initial_state.trolley_position = 0.65;
  parameters.initial_state.cable_length = parameters.crane.cable_length;
  const ma::AuditData data = record_plant_simulator(parameters);
  ma::AuditOptions options;
  options.nominal = parameters.crane;
  const auto right = ma::run_audit(data, options);
  EXPECT_EQ(right.cause, "none") << right.stop_reason;
  for (const auto& c : right.channels) {
    std::printf("plant simulator, right nominal: %s %s held-out RMS %.3g %s, Ljung-Box p %.3g, effort RMS %.3g V\n",
                c.plant.c_str(), c.channel.c_str(), c.holdout_before, c.unit.c_str(), c.before.whiteness.p_value,
                c.effort_holdout_before);
  }
  std::get<crane::common::CraneParameters>(options.nominal).load_mass = 0.8 * parameters.crane.load_mass;
  const auto wrong = ma::run_audit(data, options);
  ASSERT_EQ(wrong.cause, "payload_mass_error") << wrong.stop_reason;
  for (const auto& p : wrong.parameters) {
    if (p.name == "load_mass") {
      EXPECT_NEAR(p.value, parameters.crane.load_mass, 0.1 * parameters.crane.load_mass);
      std::printf("plant simulator: nominal load 0.8 x %g kg -> fitted %.6g kg on the %s channel\n",
                  parameters.crane.load_mass, p.value, wrong.channel.c_str());
    }
  }
}


// The wind and hook entries on recordings of the project's plant simulator with its own options
// (plant.wind: a steady force; plant.hook: the hook as a double pendulum, integrated by SUNDIALS over
// six coordinates), seeded random magnitudes in the generator's ranges (hidden_effect_generator.hpp),
// load 1-3 kg and cable 0.6-1.6 m drawn per case. Case i: wind_force, hook_double_pendulum and
// encoder_offset in turn (the offset tests the other direction: wind must not take it), then clean
// cases. The nominal is the configuration with the suspended mass (hook and load). Env
// CRANE_AUDIT_PLANT_CASES (default 3), CRANE_AUDIT_PLANT_CLEAN (default 0: the test above is a clean
// recording audited with these entries in the catalog), CRANE_AUDIT_PLANT_FIRST (first case index,
// for shards).
TEST(CraneAudit, PlantSimulatorWindHookAndOffsetAreNamed) {
  const std::size_t cases = env_count("CRANE_AUDIT_PLANT_CASES", 3);
  const std::size_t clean = env_count("CRANE_AUDIT_PLANT_CLEAN", 0);
  const char* entries[] = {"wind_force", "hook_double_pendulum", "encoder_offset"};
  std::size_t effect_cases = 0;
  std::size_t right = 0;
  std::size_t clean_cases = 0;
  std::size_t clean_none = 0;
  std::size_t within = 0;
  for (std::size_t i = env_count("CRANE_AUDIT_PLANT_FIRST", 0); i < cases + clean; ++i) {
    const std::uint64_t seed = 4700 + i;
    std::mt19937_64 rng(seed);
    const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
    const std::string effect = i < cases ? entries[i % 3] : "none";
    crane::plant::SimulatorParameters parameters;
    parameters.crane.load_mass = uniform(1.0, 3.0);
    parameters.crane.cable_length = uniform(0.6, 1.6);
    parameters.initial_state.trolley_position = 0.65;
    parameters.initial_state.cable_length = parameters.crane.cable_length;
    crane::common::CraneParameters nominal = parameters.crane;
    std::string main_parameter;
    double main_value = 0.0;
    double phi_offset = 0.0;
    if (effect == "wind_force") {
      const double force = uniform(0.01, 0.05) * parameters.crane.load_mass * parameters.crane.gravity;
      const double direction = uniform(0.0, 2.0 * std::numbers::pi);
      parameters.wind.enabled = true;
      parameters.wind.mean_force_x = force * std::cos(direction);
      parameters.wind.mean_force_y = force * std::sin(direction);
      const bool x = std::abs(parameters.wind.mean_force_x) >= std::abs(parameters.wind.mean_force_y);
      main_parameter = x ? "wind_force_x" : "wind_force_y";
      main_value = x ? parameters.wind.mean_force_x : parameters.wind.mean_force_y;
    } else if (effect == "hook_double_pendulum") {
      const double share = uniform(0.1, 0.4);
      parameters.hook.enabled = true;
      parameters.hook.rigging_length = uniform(0.15, 0.5);
      parameters.hook.hook_mass = share * nominal.load_mass;
      parameters.crane.load_mass = (1.0 - share) * nominal.load_mass;
      main_parameter = "rigging_length";
      main_value = parameters.hook.rigging_length;
    } else if (effect == "encoder_offset") {
      phi_offset = (uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * uniform(0.01, 0.05);
      main_parameter = "encoder_offset";
      main_value = phi_offset;
    }
    const ma::AuditData data = record_plant_simulator(parameters, phi_offset);
    ma::AuditOptions options;
    options.nominal = nominal;
    const auto report = ma::run_audit(data, options);
    double fitted = std::numeric_limits<double>::quiet_NaN();
    for (const auto& p : report.parameters) {
      if (p.name == main_parameter) fitted = p.value;
    }
    const auto delta_bic = [&](const std::string& name) {
      for (const auto& c : report.candidates) {
        if (c.name == name && c.fitted) return c.delta_bic;
      }
      return std::numeric_limits<double>::quiet_NaN();
    };
    std::printf("case %zu seed %llu %s: %s=%g -> %s (fitted %g); delta-BIC wind %.0f, offset %.0f, hook %.0f, length %.0f\n",
                i, static_cast<unsigned long long>(seed), effect.c_str(), main_parameter.c_str(), main_value,
                report.cause.c_str(), fitted, delta_bic("wind_force"), delta_bic("encoder_offset"),
                delta_bic("hook_double_pendulum"), delta_bic("cable_length_error"));
    if (effect == "none") {
      ++clean_cases;
      clean_none += report.cause == "none" ? 1 : 0;
      continue;
    }
    ++effect_cases;
    if (report.cause != effect) continue;
    ++right;
    within += std::abs(fitted - main_value) <= 0.1 * std::abs(main_value) ? 1 : 0;
  }
  std::printf("plant simulator: right cause %zu/%zu, main parameter within 10 %% %zu/%zu, clean none %zu/%zu\n", right,
              effect_cases, within, right, clean_none, clean_cases);
  EXPECT_GE(right, static_cast<std::size_t>(std::ceil(0.95 * static_cast<double>(effect_cases))));
  EXPECT_EQ(within, right);
  EXPECT_EQ(clean_none, clean_cases);
}

// The elastic rope (plant.rope: the load on a spring of stiffness EA / L in series with the cable,
// integrated by SUNDIALS over five coordinates) with its catalog entry elastic_rope (the static stretch
// ratio e_r = m g / EA). The lab's rope (EA = 2e5 N: e_r = 1e-4) is below the audit's resolution
// floor: a recording of the plant simulator with it is clean (none), started at the static stretch
// as the plant stage does.
TEST(CraneAudit, PlantSimulatorWithTheLabsElasticRopeGivesNone) {
  crane::plant::SimulatorParameters parameters;
  parameters.rope.enabled = true;
  parameters.rope.axial_stiffness = 2.0e5;
  parameters.initial_state.trolley_position = 0.65;
  parameters.initial_state.cable_length = parameters.crane.cable_length;
  parameters.initial_state.rope_stretch = parameters.crane.load_mass * parameters.crane.gravity *
                                          parameters.crane.cable_length / parameters.rope.axial_stiffness;
  const ma::AuditData data = record_plant_simulator(parameters);
  ma::AuditOptions options;
  options.nominal = parameters.crane;
  const auto report = ma::run_audit(data, options);
  EXPECT_EQ(report.cause, "none") << report.stop_reason;
}

// A soft or long rope (e_r drawn in the generator's [0.01, 0.04]: EA = m g / e_r) on recordings of
// the plant simulator, load 1-3 kg and cable 0.6-1.6 m drawn per case, seeds 4800 + i: named
// elastic_rope with e_r within 10 %, not the cable length error its static stretch also is. Env
// CRANE_AUDIT_ROPE_CASES (default 2), CRANE_AUDIT_ROPE_CLEAN (default 0), CRANE_AUDIT_ROPE_FIRST.
TEST(CraneAudit, PlantSimulatorElasticRopeIsNamed) {
  const std::size_t cases = env_count("CRANE_AUDIT_ROPE_CASES", 2);
  const std::size_t clean = env_count("CRANE_AUDIT_ROPE_CLEAN", 0);
  std::size_t right = 0;
  std::size_t within = 0;
  std::size_t clean_none = 0;
  const std::size_t first = env_count("CRANE_AUDIT_ROPE_FIRST", 0);
  for (std::size_t i = first; i < cases + clean; ++i) {
    const std::uint64_t seed = 4800 + i;
    std::mt19937_64 rng(seed);
    const auto uniform = [&](double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); };
    const bool rope = i < cases;
    crane::plant::SimulatorParameters parameters;
    parameters.crane.load_mass = uniform(1.0, 3.0);
    parameters.crane.cable_length = uniform(0.6, 1.6);
    parameters.initial_state.trolley_position = 0.65;
    parameters.initial_state.cable_length = parameters.crane.cable_length;
    const double ratio = uniform(0.01, 0.04);
    if (rope) {
      parameters.rope.enabled = true;
      parameters.rope.axial_stiffness = parameters.crane.load_mass * parameters.crane.gravity / ratio;
      parameters.initial_state.rope_stretch = ratio * parameters.crane.cable_length;
    }
    const ma::AuditData data = record_plant_simulator(parameters);
    ma::AuditOptions options;
    options.nominal = parameters.crane;
    const auto report = ma::run_audit(data, options);
    double fitted = std::numeric_limits<double>::quiet_NaN();
    for (const auto& p : report.parameters) {
      if (p.name == "rope_stretch_ratio") fitted = p.value;
    }
    const auto delta_bic = [&](const std::string& name) {
      for (const auto& c : report.candidates) {
        if (c.name == name && c.fitted) return c.delta_bic;
      }
      return std::numeric_limits<double>::quiet_NaN();
    };
    std::printf("rope case %zu seed %llu: %s (EA %.0f N, load %.3f kg, cable %.3f m) -> %s (fitted e_r %g); "
                "delta-BIC rope %.0f, length %.0f, hook %.0f\n",
                i, static_cast<unsigned long long>(seed), rope ? ("e_r " + std::to_string(ratio)).c_str() : "no rope",
                rope ? parameters.rope.axial_stiffness : 0.0, parameters.crane.load_mass, parameters.crane.cable_length,
                report.cause.c_str(), fitted, delta_bic("elastic_rope"), delta_bic("cable_length_error"),
                delta_bic("hook_double_pendulum"));
    if (!rope) {
      clean_none += report.cause == "none" ? 1 : 0;
      continue;
    }
    if (report.cause != "elastic_rope") continue;
    ++right;
    within += std::abs(fitted - ratio) <= 0.1 * ratio ? 1 : 0;
  }
  const std::size_t rope_cases = cases > first ? cases - first : 0;
  std::printf("plant simulator, rope: right cause %zu/%zu, e_r within 10 %% %zu/%zu, clean none %zu/%zu\n", right,
              rope_cases, within, right, clean_none, cases + clean - std::max(cases, first));
  EXPECT_EQ(right, rope_cases);
  EXPECT_EQ(within, right);
  EXPECT_EQ(clean_none, cases + clean - std::max(cases, first));
}

// The crane's catalog by channel (audit_catalog(crane)): the trolley entries, the slew entries and
// the swing entries (payload_mass_error, fitted on both drives, in none of them).
struct CraneEntries {
  std::vector<std::string> trolley;
  std::vector<std::string> slew;
  std::vector<std::string> swing;
};

CraneEntries crane_entries() {
  CraneEntries out;
  for (const auto& name : ma::audit_catalog(ma::AuditPlant::crane)) {
    if (name == "payload_mass_error") continue;
    (name.rfind("trolley_", 0) == 0 ? out.trolley : name.rfind("slew_", 0) == 0 ? out.slew : out.swing).push_back(name);
  }
  return out;
}

// Cases of two simultaneous causes: a generator pair "A+B" audited; both named, one, none. A name
// counts when it is the cause or the second cause, or one of an ambiguous pair reported for either
// (the data cannot separate the two: the single-cause tests' rule); those are counted apart too.
struct PairTally {
  std::size_t cases{0}, both{0}, one{0}, none{0}, via_ambiguous{0};

  void audit(const char* kind, std::size_t i, std::uint64_t seed, const std::string& a, const std::string& b) {
    const auto c = ma::generate_hidden_effect_case(ma::AuditPlant::crane, a + "+" + b, seed);
    ASSERT_EQ(c.effect, a);
    ASSERT_EQ(c.second_effect, b);
    ma::AuditOptions options;
    options.nominal = c.nominal;
    const auto report = ma::run_audit(c.data, options);
    const auto in = [](const std::vector<std::string>& v, const std::string& name) {
      return std::find(v.begin(), v.end(), name) != v.end();
    };
    const auto exact = [&](const std::string& name) { return report.cause == name || report.second_cause == name; };
    const auto named = [&](const std::string& name) {
      return exact(name) || in(report.ambiguous_with, name) || in(report.second_ambiguous_with, name);
    };
    const int found = (named(a) ? 1 : 0) + (named(b) ? 1 : 0);
    ++cases;
    both += found == 2 ? 1 : 0;
    one += found == 1 ? 1 : 0;
    none += found == 0 ? 1 : 0;
    via_ambiguous += found == 2 && !(exact(a) && exact(b)) ? 1 : 0;
    std::printf("%s case %zu seed %llu: %s %s=%g + %s %s=%g -> %s + %s (%s)%s\n", kind, i,
                static_cast<unsigned long long>(seed), a.c_str(), c.main_parameter.c_str(), c.main_value, b.c_str(),
                c.second_main_parameter.c_str(), c.second_main_value, report.cause.c_str(), report.second_cause.c_str(),
                report.second_channel.empty() ? "-" : report.second_channel.c_str(),
                found == 2 ? "" : found == 1 ? "  [one]" : "  [none]");
    if (found < 2) std::printf("  stop reason: %s\n", report.stop_reason.c_str());
  }
  // Prints the tally under `title` and expects both named in >= 90 % of the cases (issue 17).
  void expect_both_named(const char* title) const {
    std::printf("%s: both named %zu/%zu (%zu of them through an ambiguous pair), one %zu, none %zu\n", title, both, cases,
                via_ambiguous, one, none);
    EXPECT_GE(both, static_cast<std::size_t>(std::ceil(0.9 * static_cast<double>(cases))));
  }
};

// One entry of `list`, drawn uniformly.
std::string pick(const std::vector<std::string>& list, std::mt19937_64& rng) {
  return list[std::uniform_int_distribution<std::size_t>(0, list.size() - 1)(rng)];
}

// Cases first .. first + cases - 1 of pairs drawn by draw(i, rng) with rng = std::mt19937_64(seed_base
// + i), generated with that seed, audited and counted by PairTally; both named in >= 90 %.
void audit_pairs(const char* kind, const char* title, std::uint64_t seed_base, std::size_t first, std::size_t cases,
                 const std::function<std::pair<std::string, std::string>(std::size_t, std::mt19937_64&)>& draw) {
  PairTally tally;
  for (std::size_t i = first; i < first + cases; ++i) {
    const std::uint64_t seed = seed_base + i;
    std::mt19937_64 rng(seed);
    const auto [a, b] = draw(i, rng);
    tally.audit(kind, i, seed, a, b);
  }
  tally.expect_both_named(title);
}

// Issue 17 item 5 on the crane: two simultaneous causes on different channels, the cross-channel
// second cause (model_audit.hpp, "combination"). Generator pairs "A+B" (hidden_effect_generator.hpp),
// seeds 9700 + i, both magnitudes drawn in the generator's ranges; case i: kind i % 4 = a trolley
// entry + a slew entry, a trolley entry + a swing entry, a slew entry + a swing entry,
// payload_mass_error + a swing entry; the entries drawn uniformly (std::mt19937_64(seed)). Counted by
// PairTally.
// Env CRANE_AUDIT_PAIR_CASES (default 2), CRANE_AUDIT_PAIR_FIRST (first case index, for shards).
TEST(CraneAudit, TwoCausesOnDifferentChannelsAreBothNamed) {
  const CraneEntries entries = crane_entries();
  audit_pairs("pair", "crane pairs on different channels", 9700, env_count("CRANE_AUDIT_PAIR_FIRST", 0),
              env_count("CRANE_AUDIT_PAIR_CASES", 2), [&](std::size_t i, std::mt19937_64& rng) {
                switch (i % 4) {
                  case 0: { auto a = pick(entries.trolley, rng); return std::pair{a, pick(entries.slew, rng)}; }
                  case 1: { auto a = pick(entries.trolley, rng); return std::pair{a, pick(entries.swing, rng)}; }
                  case 2: { auto a = pick(entries.slew, rng); return std::pair{a, pick(entries.swing, rng)}; }
                  default: return std::pair{std::string("payload_mass_error"), pick(entries.swing, rng)};
                }
              });
}

// Two simultaneous causes on one drive channel: the crane's second cause stepwise on the first's own
// channel (crane_audit.cpp). Seeds 9600 + i; case i: two distinct trolley entries (even i) or two
// distinct slew entries (odd i), drawn uniformly (std::mt19937_64(seed)), both magnitudes in the
// generator's ranges. Env CRANE_AUDIT_SAME_CHANNEL_CASES (default 1), CRANE_AUDIT_SAME_CHANNEL_FIRST
// (default 11: slew stiction and a viscous asymmetry, where the crane's lowest delta-BIC takes
// slew_stribeck alone and the channel's pair, with another first cause, wins on joint delta-BIC).
TEST(CraneAudit, TwoCausesOnOneDriveChannelAreBothNamed) {
  const CraneEntries entries = crane_entries();
  audit_pairs("same-channel", "crane pairs on one drive channel", 9600, env_count("CRANE_AUDIT_SAME_CHANNEL_FIRST", 11),
              env_count("CRANE_AUDIT_SAME_CHANNEL_CASES", 1), [&](std::size_t i, std::mt19937_64& rng) {
                const auto& list = i % 2 == 0 ? entries.trolley : entries.slew;
                const std::string a = pick(list, rng);
                std::string b = pick(list, rng);
                while (b == a) b = pick(list, rng);
                return std::pair{a, b};
              });
}

// Two simultaneous causes on the swing channel: the swing channel's second cause stepwise
// (crane_audit.cpp; a swing first cause's drive seconds compete with it by delta-BIC). Seeds 9500 +
// i; case i: two distinct swing entries drawn uniformly (std::mt19937_64(seed); not a hook with an
// elastic rope, which the generator's plant cannot carry together), both magnitudes in the
// generator's ranges. Env CRANE_AUDIT_SWING_PAIR_CASES (default 1), CRANE_AUDIT_SWING_PAIR_FIRST
// (default 20, seed 9520: an elastic rope and Coulomb damping, where neither cause alone earns its
// parameters and the slew took up the rope's echo; the pair is found only by the swing channel's
// pair search, SwingAudit::pairs_without_single).
TEST(CraneAudit, TwoCausesOnTheSwingChannelAreBothNamed) {
  const CraneEntries entries = crane_entries();
  const auto extended = [](const std::string& name) { return name == "hook_double_pendulum" || name == "elastic_rope"; };
  audit_pairs("swing-pair", "crane pairs on the swing channel", 9500, env_count("CRANE_AUDIT_SWING_PAIR_FIRST", 20),
              env_count("CRANE_AUDIT_SWING_PAIR_CASES", 1), [&](std::size_t, std::mt19937_64& rng) {
                const std::string a = pick(entries.swing, rng);
                std::string b = pick(entries.swing, rng);
                while (b == a || (extended(a) && extended(b))) b = pick(entries.swing, rng);
                return std::pair{a, b};
              });
}

// The swing channel's cause enters the drives' coupling (crane_audit.cpp): the cable length error of
// case 9 of CleanRecordingsGiveNoSecondCauseAndSingleCausesAreCounted (seed 9909) made the drives
// name payload_mass_error as a second cause while the coupling used the nominal swing rows
// (docs/model_audit.md, "Two causes on different channels"); with the length error in their
// coupling they name none. Likewise the hook of case 19 (seed 9919), whose rigging no encoder
// measures: in the coupling it is followed from the cable angles (follow_swing).
TEST(CraneAudit, ASwingCauseInTheDrivesCouplingLeavesThemNoEchoOfIt) {
  for (const auto& [entry, seed] : {std::pair{"cable_length_error", 9909}, std::pair{"hook_double_pendulum", 9919}}) {
    const auto c = ma::generate_hidden_effect_case(ma::AuditPlant::crane, entry, seed);
    ma::AuditOptions options;
    options.nominal = c.nominal;
    const auto report = ma::run_audit(c.data, options);
    EXPECT_EQ(report.cause, entry) << report.stop_reason;
    EXPECT_EQ(report.second_cause, "none") << report.stop_reason;
    EXPECT_NE(report.stop_reason.find("audited again with the swing's " + std::string(entry) + " in its coupling: none"),
              std::string::npos)
        << report.stop_reason;
  }
}

// The cross-channel second cause invents nothing: clean recordings (seeds 9800 + i) give none with
// no second cause; single-cause recordings (seeds 9900 + i, entry 9 i modulo the catalog, as the
// crane hidden-effect test steps) are counted: right first cause, and a spurious second cause
// (printed, not asserted). Env CRANE_AUDIT_SINGLE_CASES (default 1), CRANE_AUDIT_SINGLE_CLEAN
// (default 1).
TEST(CraneAudit, CleanRecordingsGiveNoSecondCauseAndSingleCausesAreCounted) {
  const std::size_t cases = env_count("CRANE_AUDIT_SINGLE_CASES", 1);
  const std::size_t clean = env_count("CRANE_AUDIT_SINGLE_CLEAN", 1);
  const auto& catalog = ma::audit_catalog(ma::AuditPlant::crane);
  std::size_t right = 0;
  std::size_t spurious = 0;
  std::size_t clean_none = 0;
  for (std::size_t i = 0; i < cases + clean; ++i) {
    const bool effect = i < cases;
    const std::string entry = effect ? catalog[(9 * i) % catalog.size()] : "none";
    const std::uint64_t seed = effect ? 9900 + i : 9800 + (i - cases);
    const auto c = ma::generate_hidden_effect_case(ma::AuditPlant::crane, entry, seed);
    ma::AuditOptions options;
    options.nominal = c.nominal;
    const auto report = ma::run_audit(c.data, options);
    std::printf("single case %zu seed %llu: %s -> %s + %s (%s)\n", i, static_cast<unsigned long long>(seed),
                entry.c_str(), report.cause.c_str(), report.second_cause.c_str(),
                report.second_channel.empty() ? "-" : report.second_channel.c_str());
    if (!effect) {
      EXPECT_EQ(report.cause, "none") << report.stop_reason;
      EXPECT_EQ(report.second_cause, "none") << report.stop_reason;
      clean_none += report.cause == "none" && report.second_cause == "none" ? 1 : 0;
      continue;
    }
    right += report.cause == entry ? 1 : 0;
    spurious += report.second_cause != "none" ? 1 : 0;
  }
  std::printf("crane single causes: right first cause %zu/%zu, a spurious second cause %zu/%zu; clean none with no "
              "second cause %zu/%zu\n", right, cases, spurious, cases, clean_none, clean);
}

// crane_audit end to end: the nominal from the lab configuration (--config) with the recording's
// load mass given by --param; a clean recording gives none, a missing column exit code 2.
TEST(CraneAuditCli, ConfigAndParamGiveTheNominalAndBadDataIsRefused) {
  const fs::path dir = crane::model_audit::test::test_directory() / "crane_cli_test";
  fs::remove_all(dir);
  const fs::path data = dir.string() + "_case.csv";
  ASSERT_EQ(run_tool("generate --model crane --effect none --seed 31 --out " + data.string()), 0);
  const auto c = ma::generate_hidden_effect_case(ma::AuditPlant::crane, "none", 31);
  const std::string mass = " --param load_mass=" + crane::common::format_value(std::get<crane::common::CraneParameters>(c.nominal).load_mass);
  ASSERT_EQ(run_tool("--model crane --data " + data.string() + " --config " + CRANE_LAB_CONFIG + mass + " --out " +
                     dir.string()),
            0);
  std::ifstream report(dir / "report.json");
  std::stringstream text;
  text << report.rdbuf();
  EXPECT_NE(text.str().find("\"cause\": \"none\""), std::string::npos) << text.str().substr(0, 600);
  EXPECT_NE(text.str().find("\"channels\""), std::string::npos);
  EXPECT_EQ(run_tool("--model crane --data " + data.string() + " --out " + dir.string()), 2);  // no nominal
  ASSERT_EQ(run_tool("--model crane --data " + data.string() + " --config " + CRANE_LAB_CONFIG + mass +
                     " --calibrate --cause payload_mass_error --out " + dir.string()),
            0);
  std::ifstream calibrated(dir / "report.json");
  std::stringstream calibrated_text;
  calibrated_text << calibrated.rdbuf();
  EXPECT_NE(calibrated_text.str().find("\"trolley_drive_gain\""), std::string::npos) << calibrated_text.str().substr(0, 600);
  EXPECT_EQ(run_tool("--model crane --data " + data.string() + " --config " + CRANE_LAB_CONFIG + mass +
                     " --columns L=hoist --out " + dir.string()),
            2);
}

}  // namespace
