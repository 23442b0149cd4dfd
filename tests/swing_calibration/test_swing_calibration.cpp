// Shaper calibration (crane::swing_calibration) on simulated recordings of the plant with its hook
// as a double pendulum (plant.hook), one at a fixed cable length and one while hoisting: the fitted
// frequency against the plant's first mode (analytic, plant::double_pendulum_frequencies), and the
// recommended shaper's residual swing, measured open loop through the plant, against a ZV designed on
// the nominal single pendulum sqrt(g/L). Seeded (the plant is deterministic; the recordings' encoder
// quantization is the plant's), seconds long.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numbers>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/model_audit/measured_data.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/plant/tower_crane_model.hpp"
#include "crane/stack/in_process_stack.hpp"
#include "crane/stack/stack_config.hpp"
#include "crane/swing_calibration/swing_calibration.hpp"
#include "crane/trajectory_planner/input_shaper.hpp"

namespace crane::swing_calibration {
namespace {

namespace tp = crane::trajectory_planner;
using plant::CraneSimulator;
using plant::DriveInput;
using plant::SimulatorParameters;

constexpr double kRigging = 0.3;    // [m] the config's plant.hook values
constexpr double kHookMass = 0.5;   // [kg]
constexpr double kServoGain = 20.0; // [V/(m/s)] trolley velocity servo of the test (not the stack's)

SimulatorParameters hooked_crane(double cable_length) {
  SimulatorParameters p;
  p.crane.trolley_friction = {};  // the test's servo drives the trolley; the brake holds it
  p.crane.slew_friction = {};
  p.hook = plant::HookParameters{true, kRigging, kHookMass};
  p.initial_state.trolley_position = 0.3;
  p.initial_state.cable_length = cable_length;
  return p;
}

double first_mode(const SimulatorParameters& p, double cable_length) {
  return plant::double_pendulum_frequencies(cable_length, p.hook.rigging_length, p.hook.hook_mass, p.crane.load_mass,
                                            p.crane.gravity)
      .first;
}

// A trolley velocity reference: trapezoid (acceleration 1 m/s^2, speed 0.4 m/s, 0.5 m) convolved
// with `shaper` (identity: unshaped). Returns (velocity, acceleration) at t [s].
struct Reference {
  tp::InputShaper shaper;
  [[nodiscard]] static std::pair<double, double> trapezoid(double t) {
    const double a = 1.0, v = 0.4, distance = 0.5;
    const double ramp = v / a, cruise = distance / v - ramp, end = 2.0 * ramp + cruise;
    if (t < 0.0 || t >= end) return {0.0, 0.0};
    if (t < ramp) return {a * t, a};
    if (t < ramp + cruise) return {v, 0.0};
    return {v - a * (t - ramp - cruise), -a};
  }
  [[nodiscard]] std::pair<double, double> at(double t) const {
    double v = 0.0, acc = 0.0;
    for (std::size_t i = 0; i < shaper.impulse_count(); ++i) {
      const auto [vi, ai] = trapezoid(t - shaper.time(i));
      v += shaper.amplitude(i) * vi;
      acc += shaper.amplitude(i) * ai;
    }
    return {v, acc};
  }
  [[nodiscard]] double end() const { return 1.25 + 0.4 + shaper.length(); }  // trapezoid 1.65 s + shaper
};

// One sample of the servo: V = a_ref / K_mx + K_v (v_ref - v).
DriveInput servo(const CraneSimulator& sim, std::pair<double, double> reference, double hoist_speed) {
  DriveInput in;
  in.brakes_engaged = false;
  in.trolley_voltage =
      reference.second / sim.parameters().crane.trolley_drive_gain + kServoGain * (reference.first - sim.state().trolley_velocity);
  in.hoist_speed = hoist_speed;
  return in;
}

// Records an unshaped move, then the free swing with the brakes on (and the hoist at `hoist_speed`
// [m/s] from `hoist_start` [s] for `hoist_duration` [s]), to a CSV in the audit's format; returns its path.
std::filesystem::path record_calibration_run(const SimulatorParameters& p, const std::string& name, double seconds,
                                             double hoist_speed = 0.0, double hoist_start = 0.0,
                                             double hoist_duration = 0.0) {
  CraneSimulator sim(p);
  const Reference move{tp::InputShaper{}};
  std::vector<double> t, x, gamma, phi, theta, L;
  const auto sample = [&] {
    const auto m = sim.output().measurement;  // quantized encoders, as a recording has them
    t.push_back(sim.time());
    x.push_back(m.trolley_position);
    gamma.push_back(m.slew_angle);
    phi.push_back(m.swing_in_plane);
    theta.push_back(m.swing_out_of_plane);
    L.push_back(m.cable_length);
  };
  sample();
  while (sim.time() < seconds) {
    const double now = sim.time();
    const double hoist = now >= hoist_start && now < hoist_start + hoist_duration ? hoist_speed : 0.0;
    DriveInput in;
    if (now < move.end()) {
      in = servo(sim, move.at(now), hoist);
    } else {
      in.brakes_engaged = true;  // free swing on a held trolley
      in.hoist_speed = hoist;
    }
    EXPECT_EQ(sim.step(in), common::StepStatus::ok);
    sample();
  }
  const std::filesystem::path file = std::filesystem::path(testing::TempDir()) / (name + ".csv");
  std::ofstream out(file);
  model_audit::write_time_series_csv(out, {"simulated calibration run: " + name}, {"t", "x", "gamma", "phi", "theta", "L"},
                                     {t, x, gamma, phi, theta, L});
  return file;
}

// Residual swing of a shaped move at cable length `cable_length`: the largest |phi| (the cable angle
// the encoder reads) over the 3 s after the move and its shaper end, trolley braked.
double residual_swing(const SimulatorParameters& base, double cable_length, const tp::InputShaper& shaper) {
  SimulatorParameters p = base;
  p.initial_state.cable_length = cable_length;
  CraneSimulator sim(p);
  const Reference move{shaper};
  double worst = 0.0;
  while (sim.time() < move.end() + 3.0) {
    DriveInput in;
    if (sim.time() < move.end()) {
      in = servo(sim, move.at(sim.time()), 0.0);
    } else {
      in.brakes_engaged = true;
      worst = std::max(worst, std::abs(sim.state().swing_in_plane));
    }
    EXPECT_EQ(sim.step(in), common::StepStatus::ok);
  }
  return worst;
}

tp::InputShaper design(tp::ShaperKind kind, double frequency, double zeta, double tolerance) {
  tp::ShaperParams s;
  s.kind = kind;
  s.natural_frequency = frequency;
  s.damping_ratio = zeta;
  s.vibration_tolerance = tolerance;
  return tp::InputShaper(s);
}

// The recommended shaper (at the fitted frequency of `cable_length`) against ZV on sqrt(g/L), both
// measured through the plant.
void expect_recommended_beats_nominal_zv(const SimulatorParameters& p, const SwingFit& fit, double cable_length,
                                         const CalibrationOptions& options) {
  const ShaperRecommendation rec = recommend_shaper(fit, cable_length, options);
  const ShaperRow& best = rec.rows[rec.recommended];
  const tp::InputShaper recommended = design(best.kind, best.design_frequency, fit.damping_ratio, options.vibration_tolerance);
  const tp::InputShaper nominal_zv = design(tp::ShaperKind::zv, std::sqrt(p.crane.gravity / cable_length), 0.0, 0.05);
  const double unshaped = residual_swing(p, cable_length, tp::InputShaper{});
  const double calibrated = residual_swing(p, cable_length, recommended);
  const double nominal = residual_swing(p, cable_length, nominal_zv);
  std::printf("L = %.2f m: residual swing unshaped %.3f deg, ZV on sqrt(g/L) %.3f deg, recommended %s %.3f deg "
              "(delay %.2f s against ZV's %.2f s)\n",
              cable_length, unshaped * 180.0 / std::numbers::pi, nominal * 180.0 / std::numbers::pi, best.name.c_str(),
              calibrated * 180.0 / std::numbers::pi, recommended.length(), nominal_zv.length());
  EXPECT_LT(calibrated, nominal) << "L = " << cable_length;
  EXPECT_LT(nominal, unshaped);  // the reference itself does something
}

TEST(SwingCalibration, DoublePendulumAtOneLengthFitsTheFirstModeAndItsShaperBeatsNominalZv) {
  const SimulatorParameters p = hooked_crane(1.0);
  const auto file = record_calibration_run(p, "double_pendulum", 14.0);
  const SwingRecord record = read_swing_record(file);
  const CalibrationOptions options;
  const SwingFit fit = fit_swing(record, options);
  std::printf("%s", format_report(fit, recommend_shaper(fit, 1.0, options), options).c_str());
  const double plant = first_mode(p, 1.0), nominal = std::sqrt(p.crane.gravity / 1.0);
  std::printf("first mode of the plant %.4f rad/s (sqrt(g/L) %.4f), fitted %.4f rad/s: error %+.3f %%\n", plant, nominal,
              fit.natural_frequency(1.0), 100.0 * (fit.natural_frequency(1.0) / plant - 1.0));
  ASSERT_FALSE(fit.segments.empty());
  EXPECT_NEAR(fit.natural_frequency(1.0) / plant, 1.0, 0.02);
  EXPECT_GT(std::abs(nominal / plant - 1.0), 0.1);  // the case matters: sqrt(g/L) is 12 % off
  EXPECT_FALSE(fit.length_scale_fitted);
  expect_recommended_beats_nominal_zv(p, fit, 1.0, options);
}

TEST(SwingCalibration, DoublePendulumWhileHoistingFitsTheFirstModeOverTheLengths) {
  const SimulatorParameters p = hooked_crane(0.8);
  // Move, brakes on, then lower the load 0.8 -> 1.6 m at 0.1 m/s while it swings, then 4 s at 1.6 m.
  const auto file = record_calibration_run(p, "double_pendulum_hoisting", 16.0, 0.1, 3.0, 8.0);
  const SwingRecord record = read_swing_record(file);
  const CalibrationOptions options;
  const SwingFit fit = fit_swing(record, options);
  std::printf("%s", format_report(fit, recommend_shaper(fit, 1.2, options), options).c_str());
  EXPECT_TRUE(fit.length_scale_fitted);
  EXPECT_NEAR(fit.min_cable_length, 0.8, 0.01);
  EXPECT_NEAR(fit.max_cable_length, 1.6, 0.01);
  for (double L : {0.8, 1.0, 1.2, 1.4, 1.6}) {
    const double plant = first_mode(p, L);
    std::printf("L = %.1f m: first mode %.4f rad/s, fitted %.4f rad/s (%+.3f %%), sqrt(g/L) %.4f rad/s (%+.1f %%)\n", L,
                plant, fit.natural_frequency(L), 100.0 * (fit.natural_frequency(L) / plant - 1.0),
                std::sqrt(p.crane.gravity / L), 100.0 * (std::sqrt(p.crane.gravity / L) / plant - 1.0));
    EXPECT_NEAR(fit.natural_frequency(L) / plant, 1.0, 0.02) << "L = " << L;
  }
  for (double L : {0.8, 1.6}) expect_recommended_beats_nominal_zv(p, fit, L, options);
}

// Control: the single pendulum while hoisting gives back sqrt(g/L) (a = 1, c = 0 within the fit).
TEST(SwingCalibration, SinglePendulumWhileHoistingGivesBackSqrtGOverL) {
  SimulatorParameters p = hooked_crane(0.8);
  p.hook.enabled = false;
  const auto file = record_calibration_run(p, "single_pendulum_hoisting", 14.0, 0.1, 3.0, 8.0);
  const SwingFit fit = fit_swing(read_swing_record(file), CalibrationOptions{});
  for (double L : {0.8, 1.2, 1.6}) {
    const double exact = std::sqrt(p.crane.gravity / L);
    std::printf("single pendulum L = %.1f m: fitted %.4f rad/s, sqrt(g/L) %.4f (%+.3f %%)\n", L, fit.natural_frequency(L),
                exact, 100.0 * (fit.natural_frequency(L) / exact - 1.0));
    EXPECT_NEAR(fit.natural_frequency(L) / exact, 1.0, 0.005) << "L = " << L;
  }
  EXPECT_LT(fit.damping_ratio, 0.005);  // the plant's swing has no damping of its own
}

// The planner loads what the tool writes: the manual lines put into the lab config parse, and the
// planner's parameters hold the fitted swing model and the recommended shaping.
TEST(SwingCalibration, ThePlannerLoadsTheResult) {
  SwingFit fit;
  fit.length_scale = 0.9951;
  fit.length_offset = 0.2566;
  fit.damping_ratio = 0.0012;
  fit.min_cable_length = fit.max_cable_length = 1.0;
  const CalibrationOptions options;
  const ShaperRecommendation rec = recommend_shaper(fit, 1.0, options);
  const std::string lines = planner_manual_yaml(fit, rec, "run.csv");
  const std::string supervisor_line = supervisor_yaml(fit, rec);
  std::ifstream in(std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  // Replace the four manual lines (shaping and the swing model) by the tool's.
  std::istringstream config_lines(yaml);
  std::string line, edited;
  bool inserted = false;
  while (std::getline(config_lines, line)) {
    const bool replaced = line.rfind("    shaping:", 0) == 0 || line.rfind("    swing_length_scale:", 0) == 0 ||
                          line.rfind("    swing_length_offset:", 0) == 0 || line.rfind("    swing_damping_ratio:", 0) == 0 ||
                          (line.rfind("                               # robust", 0) == 0);
    if (replaced) {
      if (!inserted) edited += lines;
      inserted = true;
      continue;
    }
    if (line.rfind("  zone_stop_delay_periods:", 0) == 0) {
      edited += supervisor_line;
      continue;
    }
    edited += line + "\n";
  }
  ASSERT_TRUE(inserted);
  const auto config = stack::parse_stack_config(edited, "calibrated.yaml");
  const auto& manual = config.trajectory_planner.manual;
  EXPECT_EQ(manual.shaping, speed_shaping(rec.rows[rec.recommended].kind));
  EXPECT_NEAR(manual.swing_length_scale, 0.9951, 1e-12);
  EXPECT_NEAR(manual.swing_length_offset, 0.2566, 1e-12);
  EXPECT_NEAR(manual.swing_damping_ratio, 0.0012, 1e-12);
  EXPECT_NEAR(config.supervisor.zone_stop_delay_periods,
              tp::shaper_delay_periods(manual.shaping, manual.swing_damping_ratio), 1e-6);
}

// Closed loop through the whole stack in one process (stack::InProcessStack, every stage object and
// the plant with its hook): manual mode, a full trolley stick for 3 s, released; sway control by the
// planner's shaper alone (anti-swing law none, so the shaper is what is measured). The planner with
// the calibration's lines against the planner with ZV on sqrt(g/L): largest swing of the cable from
// 2 s after the reference stops, for 4 s.
double manual_stop_residual_swing(stack::StackConfig config) {
  config.trajectory_planner.trolley_max_position = 2.8;  // a 3 m jib: 3 s at full speed fits
  config.supervisor.trolley_max = 3.0;
  stack::InProcessOptions options;
  options.controller.anti_swing = anti_swing::AntiSwingLaw::none;
  stack::InProcessStack s(config, options);
  protocol::SupervisorCommand manual;
  manual.request_id = 1;
  manual.command = protocol::SupervisorCommand::COMMAND_SET_OPERATING_MODE;
  manual.operating_mode = protocol::SupervisorStatus::OPERATION_MANUAL;
  std::optional<std::uint64_t> stopped;
  double residual = 0.0;
  for (std::uint64_t k = 0; k < 3000; ++k) {
    protocol::OperatorSpeed speed;
    speed.header.seq = k;
    speed.device = protocol::OperatorSpeed::DEVICE_SCRIPT;
    speed.range = protocol::OperatorSpeed::RANGE_NORMAL;
    speed.trolley = k >= 400 && k < 700 ? 1.0 : 0.0;
    s.step({}, k >= 400 ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(), k == 10 ? &manual : nullptr);
    if (k > 700 && !stopped && !s.planner().under_speed_control()) stopped = k;
    const auto& p = s.plant().simulator().state();
    if (stopped && k >= *stopped + 200) residual = std::max({residual, std::abs(p.swing_in_plane), std::abs(p.swing_out_of_plane)});
    if (stopped && k >= *stopped + 600) break;
  }
  EXPECT_TRUE(stopped.has_value());
  EXPECT_EQ(s.status().latched_faults, 0U);
  return residual;
}

TEST(SwingCalibration, ThePlannerWithTheCalibrationStopsTheHookedLoadWithLessSwing) {
  stack::StackConfig config = stack::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml");
  config.plant.hook = plant::HookParameters{true, kRigging, kHookMass};
  // The calibration of this crane: the recording of the first test (the plant alone, 1.0 m).
  const SwingFit fit = fit_swing(read_swing_record(record_calibration_run(hooked_crane(1.0), "stack_calibration", 14.0)),
                                 CalibrationOptions{});
  const ShaperRecommendation rec = recommend_shaper(fit, config.facts.crane.cable_length, CalibrationOptions{});
  stack::StackConfig nominal = config;
  nominal.trajectory_planner.manual.shaping = tp::SpeedShaping::zv;  // ZV on sqrt(g/L): 1, 0, 0
  stack::StackConfig calibrated = config;
  calibrated.trajectory_planner.manual.shaping = speed_shaping(rec.rows[rec.recommended].kind);
  calibrated.trajectory_planner.manual.swing_length_scale = fit.length_scale;
  calibrated.trajectory_planner.manual.swing_length_offset = fit.length_offset;
  calibrated.trajectory_planner.manual.swing_damping_ratio = fit.damping_ratio;
  stack::StackConfig shipped = config;  // the config's ZVD on sqrt(g/L), for the record (not asserted)
  shipped.trajectory_planner.manual.shaping = tp::SpeedShaping::zvd;
  const double with_nominal = manual_stop_residual_swing(nominal);
  const double with_calibration = manual_stop_residual_swing(calibrated);
  const double with_shipped = manual_stop_residual_swing(shipped);
  std::printf("stack, manual trolley stick 3 s with the hook on, shaper only: residual swing %.3f deg with ZV on "
              "sqrt(g/L), %.3f deg with the calibration (%s on sqrt(g / (%.4f L + %.4f))); the shipped ZVD on "
              "sqrt(g/L) %.3f deg\n",
              with_nominal * 180.0 / std::numbers::pi, with_calibration * 180.0 / std::numbers::pi,
              rec.rows[rec.recommended].name.c_str(), fit.length_scale, fit.length_offset,
              with_shipped * 180.0 / std::numbers::pi);
  EXPECT_LT(with_calibration, with_nominal);
  // For the record: every kind on the calibrated swing model (the ranking's band is +-15 %; a
  // zero-vibration shaper at an exact frequency does better than EI's designed 5 %).
  for (const ShaperRow& row : rec.rows) {
    if (row.name == "zv_nominal") continue;
    stack::StackConfig c = calibrated;
    c.trajectory_planner.manual.shaping = speed_shaping(row.kind);
    std::printf("  calibrated %-11s delay %.2f s: residual swing %.3f deg\n", row.name.c_str(), row.delay,
                manual_stop_residual_swing(c) * 180.0 / std::numbers::pi);
  }
}

TEST(SwingCalibration, ARecordWithoutSwingIsRefusedNamingTheThresholds) {
  SwingRecord r;
  r.source = "still.csv";
  for (int i = 0; i < 500; ++i) {
    r.time.push_back(0.01 * i);
    r.trolley_position.push_back(0.5);
    r.slew_angle.push_back(0.0);
    r.swing_in_plane.push_back(0.0);
    r.swing_out_of_plane.push_back(0.0);
    r.cable_length.push_back(1.0);
  }
  try {
    (void)fit_swing(r, CalibrationOptions{});
    ADD_FAILURE() << "no CalibrationError";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("still.csv: no swing to fit"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("0.003 rad"), std::string::npos) << e.what();
  }
  CalibrationOptions whole;
  whole.whole_record = true;
  try {
    (void)fit_swing(r, whole);
    ADD_FAILURE() << "no CalibrationError";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("still.csv: no swing to fit: the record never swings more than 0.003 rad"),
              std::string::npos)
        << e.what();
  }
  CalibrationOptions bad;
  bad.frequency_band = 0.8;
  EXPECT_THROW((void)fit_swing(r, bad), common::ConfigError);
}

}  // namespace
}  // namespace crane::swing_calibration
