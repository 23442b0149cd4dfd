// The follower of a minimum-time trajectory (optimal_control/trajectory_follower.hpp) checked on
// its own model by an integration written here (RK4 with the input held over each 10 ms sample),
// and in closed loop on the stack's estimator, friction compensation, supervisor and the plant
// (stack::run_follower): the demo maneuvers of the tower and the gantry crane within 1.2 T*
// (issue 32), no supervisor fault, no brake.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/optimal_control/trajectory_follower.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/stack/follower_run.hpp"
#include "crane/stack/in_process_stack.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/maneuver_bound.hpp"
#include "crane/stack/controller_comparison.hpp"
#include "crane/stack/swing_calibration_run.hpp"

namespace {

using namespace crane;

stack::StackConfig config(const std::string& name) {
  return stack::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/" + name);
}

// The model integrated by RK4 over one sample with the drive voltages held (no friction: the
// follower's voltages are those before the friction compensation).
plant::ModelState advance(const plant::CraneDynamics& model, plant::ModelState s, double period, double trolley_voltage,
                          double second_voltage, double cable_length) {
  plant::CoordinateVector force = plant::CoordinateVector::Zero();
  force[plant::kTrolleyIndex] = model.drive_force_per_volt(plant::DriveAxis::trolley) * trolley_voltage;
  force[plant::kSlewIndex] = model.drive_force_per_volt(plant::DriveAxis::second) * second_voltage;
  const plant::HoistMotion hoist{cable_length, 0.0, 0.0};
  constexpr int kSteps = 10;
  const double h = period / kSteps;
  for (int i = 0; i < kSteps; ++i) {
    const auto f = [&](const plant::ModelState& x) { return model.acceleration(x, hoist, force); };
    const plant::CoordinateVector a1 = f(s);
    const plant::ModelState s2{s.position + 0.5 * h * s.velocity, s.velocity + 0.5 * h * a1};
    const plant::CoordinateVector a2 = f(s2);
    const plant::ModelState s3{s.position + 0.5 * h * s2.velocity, s.velocity + 0.5 * h * a2};
    const plant::CoordinateVector a3 = f(s3);
    const plant::ModelState s4{s.position + h * s3.velocity, s.velocity + h * a3};
    const plant::CoordinateVector a4 = f(s4);
    s.position += h / 6.0 * (s.velocity + 2.0 * s2.velocity + 2.0 * s3.velocity + s4.velocity);
    s.velocity += h / 6.0 * (a1 + 2.0 * a2 + 2.0 * a3 + a4);
  }
  return s;
}

struct Solved {
  optimal_control::MinimumTimeProblem problem;
  optimal_control::MinimumTimeResult result;
};

Solved solve(const stack::StackConfig& cfg, const stack::ManeuverConfig& m) {
  Solved s{stack::bound_problem(cfg, m, 200), {}};
  s.result = optimal_control::solve_minimum_time(s.problem);
  return s;
}

// On its own model with no friction and no error, the follower's law ends the slew at rest at the
// target: the feedforward is the bound's and the feedback holds what the 10 ms hold adds. (No
// friction here and no compensation stage: none of it is fed forward either.)
TEST(TrajectoryFollower, EndsTheSlewAtRestOnItsModel) {
  const auto cfg = config("lab_tower_crane.yaml");
  const auto& m = stack::find_maneuver(cfg, "slew");
  const Solved b = solve(cfg, m);
  ASSERT_TRUE(b.result.solved) << b.result.status;
  optimal_control::FollowerParams params;
  params.trajectory_sliding_friction_scale = 1.0;
  const optimal_control::TrajectoryFollower follower(b.problem, b.result, params);
  EXPECT_EQ(follower.state_size(), 8);
  plant::ModelState s;
  s.position[plant::kTrolleyIndex] = m.initial_trolley_position;
  s.position[plant::kSlewIndex] = m.initial_slew_angle;
  double max_swing = 0.0;
  const std::size_t cycles = follower.samples() + 200;  // 2 s after the trajectory's end
  for (std::size_t k = 0; k < cycles; ++k) {
    optimal_control::FollowerCommand u;
    ASSERT_EQ(follower.step(k, s, u), common::StepStatus::ok);
    EXPECT_LE(std::abs(u.trolley_voltage), 10.0);
    s = advance(*b.problem.model, s, 0.01, u.trolley_voltage, u.second_voltage, cfg.facts.crane.cable_length);
    max_swing = std::max({max_swing, std::abs(s.position[plant::kInPlaneSwingIndex]),
                          std::abs(s.position[plant::kOutOfPlaneSwingIndex])});
  }
  constexpr double deg = 180.0 / std::numbers::pi;
  std::printf("slew on the model: %zu samples, end %.5f m %.5f rad, swing %.4f %.4f deg, max %.2f deg\n",
              follower.samples(), s.position[plant::kTrolleyIndex], s.position[plant::kSlewIndex],
              deg * s.position[plant::kInPlaneSwingIndex], deg * s.position[plant::kOutOfPlaneSwingIndex],
              deg * max_swing);
  EXPECT_NEAR(s.position[plant::kTrolleyIndex], m.trolley_target, 1e-3);
  EXPECT_NEAR(s.position[plant::kSlewIndex], m.slew_target, 1e-3);
  EXPECT_LT(deg * std::abs(s.position[plant::kInPlaneSwingIndex]), 0.05);
  EXPECT_LT(deg * std::abs(s.position[plant::kOutOfPlaneSwingIndex]), 0.05);
  EXPECT_LT(max_swing, b.problem.max_swing);
}

// The hold's slew weight (FollowerHold::slew_sideways, "Robust near the mast"): after a plan robust to
// the pendulum's length and near the mast (the slew at 0.3 m: max(0.01 rad, 6 mm / 0.3 m) = 0.02 rad)
// the hold's slew position gain is smaller than after the same plan not robust; 0.9 m out (6.7 mrad
// < 0.01 rad) the hold is the same either way.
TEST(TrajectoryFollower, TheHoldLoosensTheSlewAfterARobustPlanNearTheMastOnly) {
  auto cfg = config("lab_tower_crane.yaml");
  cfg.trajectory_planner.robust_length_range = 0.0;  // the plain plan: only the result's flag differs
  for (const double radius : {0.3, 0.9}) {
    auto m = stack::find_maneuver(cfg, "slew");
    m.initial_trolley_position = radius;
    m.trolley_target = radius;
    Solved b = solve(cfg, m);
    ASSERT_TRUE(b.result.solved) << b.result.status;
    ASSERT_FALSE(b.result.robust);
    const optimal_control::FollowerParams params;
    const optimal_control::TrajectoryFollower plain(b.problem, b.result, params);
    b.result.robust = true;
    const optimal_control::TrajectoryFollower robust(b.problem, b.result, params);
    const std::size_t end = plain.samples() + 10;
    // Rows: trolley and slew voltage; columns: the model's slots, positions first (trolley, in-plane
    // swing, slew, out-of-plane swing), then their rates.
    const double plain_gain = plain.gain(end)(1, 2);
    const double robust_gain = robust.gain(end)(1, 2);
    std::printf("slew at %.1f m: hold's slew position gain %.3f V/rad plain, %.3f robust\n", radius, plain_gain,
                robust_gain);
    if (radius < 0.6) {
      EXPECT_LT(std::abs(robust_gain), 0.9 * std::abs(plain_gain));
    } else {
      EXPECT_EQ(robust.gain(end), plain.gain(end));
    }
  }
}

// On the reference the output is the feedforward alone: the bound's voltage less the part of its
// friction that the compensation stage adds on the measured speed (trajectory_sliding_friction_scale;
// the rest is fed forward at the reference speed). After the trajectory the hold's scale applies.
TEST(TrajectoryFollower, OnTheReferenceTheOutputIsTheFeedforward) {
  const auto cfg = config("lab_tower_crane.yaml");
  const Solved b = solve(cfg, stack::find_maneuver(cfg, "trolley"));
  ASSERT_TRUE(b.result.solved);
  const double t = 50 * 0.01;
  const auto mid = optimal_control::sample(b.result, t + 0.005);
  const auto at = optimal_control::sample(b.result, t);
  plant::ModelState s;
  s.position = at.state.position.head<plant::kNumCoordinates>();
  s.velocity = at.state.velocity.head<plant::kNumCoordinates>();
  const double friction = optimal_control::drive_voltage(0.0, 1.0, mid.state.velocity[plant::kTrolleyIndex],
                                                         b.problem.trolley_friction, b.problem.friction_smoothing_speed);
  ASSERT_GT(std::abs(friction), 0.5);  // the lab trolley's friction at speed, so that the cases differ
  for (const double scale : {1.0, 0.5, 0.0}) {
    optimal_control::FollowerParams params;
    params.trajectory_sliding_friction_scale = scale;
    const optimal_control::TrajectoryFollower f(b.problem, b.result, params);
    optimal_control::FollowerCommand c;
    ASSERT_EQ(f.step(50, s, c), common::StepStatus::ok);
    EXPECT_NEAR(c.trolley_voltage, mid.trolley_voltage - scale * friction, 1e-9) << scale;
    EXPECT_EQ(c.sliding_friction_scale, scale);
    optimal_control::FollowerCommand after;
    ASSERT_EQ(f.step(f.samples() + 10, s, after), common::StepStatus::ok);
    EXPECT_EQ(after.sliding_friction_scale, params.hold.sliding_friction_scale);
  }
  const optimal_control::TrajectoryFollower follower(b.problem, b.result, {});
  EXPECT_EQ(follower.state_size(), 8);
  optimal_control::FollowerCommand u;
  ASSERT_EQ(follower.step(50, s, u), common::StepStatus::ok);
  EXPECT_DOUBLE_EQ(u.trolley.position, at.state.position[plant::kTrolleyIndex]);
  // A trolley 1 cm behind the reference is driven forward.
  s.position[plant::kTrolleyIndex] -= 0.01;
  optimal_control::FollowerCommand behind;
  ASSERT_EQ(follower.step(50, s, behind), common::StepStatus::ok);
  EXPECT_GT(behind.trolley_voltage, u.trolley_voltage);
}

TEST(TrajectoryFollower, RefusesWhatItCannotFollow) {
  const auto cfg = config("lab_tower_crane.yaml");
  const Solved b = solve(cfg, stack::find_maneuver(cfg, "trolley"));
  ASSERT_TRUE(b.result.solved);
  optimal_control::FollowerParams bad;
  bad.weights.voltage = 0.0;
  EXPECT_THROW(optimal_control::TrajectoryFollower(b.problem, b.result, bad), common::ConfigError);
  optimal_control::FollowerParams bad_scale;
  bad_scale.trajectory_sliding_friction_scale = 1.5;
  EXPECT_THROW(optimal_control::TrajectoryFollower(b.problem, b.result, bad_scale), common::ConfigError);
  optimal_control::MinimumTimeResult unsolved = b.result;
  unsolved.solved = false;
  EXPECT_THROW(optimal_control::TrajectoryFollower(b.problem, unsolved, {}), common::ConfigError);
  auto hooked = b.problem;
  plant::HookParameters hook;
  hook.enabled = true;
  hooked.model = plant::make_crane_dynamics(cfg.plant.kind, cfg.facts.crane, cfg.facts.bridge, hook);
  try {
    (void)optimal_control::TrajectoryFollower(hooked, b.result, {});
    FAIL() << "a hook model was taken";
  } catch (const common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("follower.model"), std::string::npos) << e.what();
  }
  // A non-finite measurement: 0 V and the refusal.
  const optimal_control::TrajectoryFollower follower(b.problem, b.result, {});
  plant::ModelState s;
  s.position[plant::kInPlaneSwingIndex] = std::numeric_limits<double>::quiet_NaN();
  optimal_control::FollowerCommand u;
  u.trolley_voltage = 5.0;
  EXPECT_EQ(follower.step(3, s, u), common::StepStatus::rejected_nonfinite);
  EXPECT_EQ(u.trolley_voltage, 0.0);
  EXPECT_EQ(u.second_voltage, 0.0);
}

// Closed loop on the plant through the estimator, the friction compensation and the supervisor:
// every demo maneuver of the tower and the gantry crane settles (5 mm, 0.005 rad, 0.5 deg) within
// 1.2 T*, with no fault and no brake. Measured (2026-11-25): tower 1.06, 1.06, 1.12, 0.94 T*
// (trolley_hoist: T* is the hoist's; the trolley and the swing settle before it ends), gantry
// 0.94, 0.94.
TEST(TrajectoryFollower, DemoManeuversSettleWithin1_2TStarInClosedLoop) {
  for (const std::string file : {"lab_tower_crane.yaml", "gantry_crane.yaml"}) {
    const auto cfg = config(file);
    for (const auto& m : cfg.maneuvers) {
      stack::FollowerRun run;
      run.maneuver = m;
      const auto r = stack::run_follower(cfg, run);
      const double ratio = r.metrics.settle_time / r.bound.duration;
      std::printf("%s %s: T* %.4f s, settled %.2f s = %.2f T*, %.2f mm, %.2f mrad, swing max %.2f resid %.3f deg, %.2f V\n",
                  file.c_str(), m.name.c_str(), r.bound.duration, r.metrics.settle_time, ratio,
                  1e3 * r.metrics.final_position_error, 1e3 * r.metrics.final_slew_error,
                  r.metrics.max_swing * 180.0 / std::numbers::pi, r.metrics.residual_swing * 180.0 / std::numbers::pi,
                  r.metrics.max_voltage);
      std::printf("  gains (linearization and Riccati): %.3f s\n", r.follower_setup_seconds);
      EXPECT_LE(ratio, 1.2) << file << " " << m.name;
      EXPECT_EQ(r.latched_faults, 0u) << file << " " << m.name;
      EXPECT_EQ(r.braked_cycles, 0u) << file << " " << m.name;
      EXPECT_LE(r.metrics.final_position_error, 0.005) << file << " " << m.name;
      EXPECT_LE(r.metrics.final_slew_error, 0.005) << file << " " << m.name;
    }
  }
}

// The plant off from the follower's model (issue 32): cable length +-20 %, friction +-30 % (the
// load mass at +20 %; it changes the figures by < 0.5 T*). Before the hold (FollowerHold) the
// follower hunted around the target at every such corner (1.5-2.5 Hz with friction compensated
// 30 % too much, a stuck trolley with the swing left at 0.5-0.8 deg with 30 % too little) and
// settled late (6.5-6.9 T*) or never. Measured (2026-11-25): trolley 1.60, 1.43, 2.26, 2.81 T*;
// slew 1.73, 1.97, 2.34, 2.96 T* (L0.8 f0.7, L0.8 f1.3, L1.2 f0.7, L1.2 f1.3). With the hold's
// sliding friction scaled by the factor estimated along the move (tracking/friction_factor_estimate.hpp,
// 2026-11-27): trolley 1.51, 1.34, 1.73, 1.90 T*; slew 1.68, 1.65, 1.96, 2.04 T*; with its stiction
// scaled too: trolley 1.50, 1.34, 1.71, 1.71 T*; slew 1.68, 1.63, 1.96, 2.20 T* (the slew at L1.2 f1.3
// slower: of the comparison's 192 tower runs on seed 1, 10 got more than 0.05 T* slower and 49 as
// much faster; docs/optimal_control.md, "The friction the hold compensates"). With the slew held
// looser, its swing tighter and the breakaway ramp at the target (2026-11-27, "Breaking the drive
// loose at the target"): trolley 1.47, 1.34, 1.72, 1.69 T*; slew 1.74, 1.39, 1.90, 2.19 T*. The
// bound was 3 T* before the estimate.
TEST(TrajectoryFollower, MismatchCornersSettleWithin2_25TStarInClosedLoop) {
  const auto cfg = config("lab_tower_crane.yaml");
  for (const std::string name : {"trolley", "slew"}) {
    for (const double length : {0.8, 1.2}) {
      for (const double friction : {0.7, 1.3}) {
        stack::FollowerRun run;
        run.maneuver = stack::find_maneuver(cfg, name);
        run.mismatch.cable_length_factor = length;
        run.mismatch.load_mass_factor = 1.2;
        run.mismatch.friction_factor = friction;
        const auto r = stack::run_follower(cfg, run);
        const double ratio = r.metrics.settle_time / r.bound.duration;
        std::printf("%s L x%.1f friction x%.1f: settled %.2f s = %.2f T*, %.2f mm, %.2f mrad, resid swing %.3f deg\n",
                    name.c_str(), length, friction, r.metrics.settle_time, ratio, 1e3 * r.metrics.final_position_error,
                    1e3 * r.metrics.final_slew_error, r.metrics.residual_swing * 180.0 / std::numbers::pi);
        EXPECT_LE(ratio, 2.25) << name << " L x" << length << " friction x" << friction;  // NaN (never) fails
        EXPECT_EQ(r.latched_faults, 0u) << name << " L x" << length << " friction x" << friction;
        EXPECT_EQ(r.braked_cycles, 0u) << name << " L x" << length << " friction x" << friction;
      }
    }
  }
}

// Near the mast (docs/optimal_control.md, "Robust near the mast"): random move 12 of seed 1 ends at
// 0.21 m from the slew axis, on a plant whose cable is 20 % longer, its load 20 % heavier and its
// friction 30 % lower than the model's. As shipped (the lab config: a robust plan within 0.5 m, the
// slew held at the target to 6 mm sideways) it settles within 2 T* (measured 1.89). Planned on the
// configured pendulum alone, the slew held at 0.01 rad (session 23's follower), it takes more
// (measured 2.44): the slew and the out-of-plane swing ring together for periods.
TEST(TrajectoryFollower, NearTheMastALongerCableSettlesWithin2TStar) {
  const auto shipped = config("lab_tower_crane.yaml");
  ASSERT_GT(shipped.trajectory_planner.robust_length_range, 0.0);
  ASSERT_GT(shipped.trajectory_planner.robust_within_radius, 0.21);
  const auto move = stack::random_moves(shipped, 13, 1)[12];
  ASSERT_LT(move.trolley_target, 0.25);
  for (const bool as_shipped : {true, false}) {
    auto cfg = shipped;
    stack::FollowerRun run;
    run.maneuver = move;
    run.mismatch.cable_length_factor = 1.2;
    run.mismatch.load_mass_factor = 1.2;
    run.mismatch.friction_factor = 0.7;
    if (!as_shipped) {
      cfg.trajectory_planner.robust_length_range = 0.0;
      run.follower.hold.slew_sideways = 1e-6;  // max(0.01 rad, 1e-6 m / 0.21 m): 0.01 rad
    }
    const auto r = stack::run_follower(cfg, run);
    const double ratio = r.metrics.settle_time / r.bound.duration;
    std::printf("%s: trajectory %.2f s, settled %.2f s = %.2f T* (%.4f s), %.2f mm, %.2f mrad\n",
                as_shipped ? "as shipped" : "session 23", r.bound.trajectory_duration, r.metrics.settle_time, ratio,
                r.bound.duration, 1e3 * r.metrics.final_position_error, 1e3 * r.metrics.final_slew_error);
    EXPECT_EQ(r.latched_faults, 0u);
    EXPECT_EQ(r.braked_cycles, 0u);
    if (as_shipped) {
      EXPECT_TRUE(r.bound.robust) << "planned robustly near the mast";
      EXPECT_LE(ratio, 2.0);  // NaN (never) fails
    } else {
      EXPECT_FALSE(r.bound.robust);
      EXPECT_GT(ratio, 2.0) << "the premise: near the mast, without either, the move is slow";
    }
  }
}

// The hold's out-of-plane swing weight (docs/optimal_control.md, "The out-of-plane swing's hold
// weight, chosen again"): random move 12 of seed 1, 0.21 m from the slew axis, on a plant whose cable
// is 20 % longer, its load 20 % heavier and its friction 30 % higher than the model's. With the
// shipped 0.0025 rad it settles within 2 T* (crane_sim compare: 1.96); with the former 0.003 rad it
// does not (2.61): the slew, damping the longer pendulum's out-of-plane swing, rings outside its band.
TEST(TrajectoryFollower, TheHoldsOutOfPlaneSwingWeightSettlesTheSlowNearMastCorner) {
  const auto cfg = config("lab_tower_crane.yaml");
  const optimal_control::FollowerParams defaults;
  ASSERT_EQ(defaults.hold.weights.out_of_plane_swing, 0.0025);
  const auto move = stack::random_moves(cfg, 13, 1)[12];
  for (const double weight : {0.0025, 0.003}) {
    stack::FollowerRun run;
    run.maneuver = move;
    run.mismatch.cable_length_factor = 1.2;
    run.mismatch.load_mass_factor = 1.2;
    run.mismatch.friction_factor = 1.3;
    run.follower.hold.weights.out_of_plane_swing = weight;
    const auto r = stack::run_follower(cfg, run);
    const double ratio = r.metrics.settle_time / r.bound.duration;
    std::printf("out-of-plane swing held at %.4f rad: settled %.2f s = %.2f T* (%.4f s), %.2f mrad\n", weight,
                r.metrics.settle_time, ratio, r.bound.duration, 1e3 * r.metrics.final_slew_error);
    EXPECT_EQ(r.latched_faults, 0u);
    EXPECT_EQ(r.braked_cycles, 0u);
    if (weight == defaults.hold.weights.out_of_plane_swing) {
      EXPECT_LE(ratio, 2.0);  // NaN (never) fails
    } else {
      EXPECT_GT(ratio, 2.0) << "the premise: with the former weight the move is slow";
    }
  }
}

// Calibrated on the crane (docs/optimal_control.md, "Calibrated on the crane"): the plant's cable
// 20 % longer than configured, the load 20 % heavier. One recorded demo trolley move fitted
// (stack::calibrate_swing_on) finds the equivalent pendulum 1.0 L + 0.2 m within 5 mm (measured
// 0.2029 m; the fit's g is the config's); then random move 6 of seed 1, which took 2.45 T* with the
// controllers on the configured length (crane_sim compare ... --corners), settles within 1.2 T* of
// the nominal bound (measured 1.02; its own bound on the calibrated model is 2.80 s, not 2.70 s).
TEST(TrajectoryFollower, CalibratedOnALongerCableTheSlowestMoveSettlesAsOnTheNominalPlant) {
  const auto cfg = config("lab_tower_crane.yaml");
  plant::PlantMismatch plant;
  plant.cable_length_factor = 1.2;
  plant.load_mass_factor = 1.2;
  const auto calibrated = stack::calibrate_swing_on(cfg, plant);
  std::printf("fitted a %.4f, c %.4f m on %s (rms %.2e rad)\n", calibrated.fit.length_scale, calibrated.fit.length_offset,
              calibrated.maneuver.c_str(), calibrated.fit.rms_residual);
  EXPECT_EQ(calibrated.fit.length_scale, 1.0) << "one cable length: the scale is held";
  EXPECT_NEAR(calibrated.fit.length_offset, 0.2 * cfg.facts.crane.cable_length, 0.005);
  EXPECT_EQ(calibrated.config.trajectory_planner.manual.swing_length_offset, calibrated.fit.length_offset);

  const auto move = stack::random_moves(cfg, 7, 1)[6];
  const double nominal_bound = optimal_control::solve_minimum_time(stack::follower_problem(cfg, move, 200)).duration;
  for (const bool calibrate : {false, true}) {
    stack::FollowerRun run;
    run.maneuver = move;
    run.mismatch = plant;
    const auto r = stack::run_follower(calibrate ? calibrated.config : cfg, run);
    const double ratio = r.metrics.settle_time / nominal_bound;
    std::printf("%s: own T* %.4f s, settled %.2f s = %.2f nominal T* (%.4f s)\n", calibrate ? "calibrated" : "configured",
                r.bound.duration, r.metrics.settle_time, ratio, nominal_bound);
    EXPECT_EQ(r.latched_faults, 0u);
    EXPECT_EQ(r.braked_cycles, 0u);
    if (calibrate) {
      EXPECT_LE(ratio, 1.2);
    } else {
      EXPECT_GT(ratio, 1.5) << "the premise: on the configured length this move is slow";
    }
  }
}

// Learnt while working (docs/optimal_control.md, "Learnt while working"): the same plant and move,
// with no calibration. The crane first makes an ordinary move (stack::learning_move: the demo
// trolley move backwards, to where move 6 starts, minimum-time), and the state estimator
// (state_estimator.swing_length) learns the pendulum from its swing; the planner then plans move 6
// on what it learnt. Measured: 1.0 L + 0.1995 m learnt, 2.46 -> 1.01 nominal T* (calibrated: 1.02).
// With the estimator off, the same two moves: the configured pendulum, as slow as uncalibrated.
TEST(TrajectoryFollower, LearntWhileWorkingOnALongerCableTheSlowestMoveSettlesAsCalibrated) {
  auto cfg = config("lab_tower_crane.yaml");
  plant::PlantMismatch plant;
  plant.cable_length_factor = 1.2;
  plant.load_mass_factor = 1.2;
  const auto move = stack::random_moves(cfg, 7, 1)[6];
  const double nominal_bound = optimal_control::solve_minimum_time(stack::follower_problem(cfg, move, 200)).duration;
  for (const bool learn : {false, true}) {
    cfg.state_estimator.swing_length.enabled = learn;
    stack::FollowerRun run;
    run.maneuver = move;
    run.mismatch = plant;
    run.first_move = stack::learning_move(cfg, move);
    const auto r = stack::run_follower(cfg, run);
    const double ratio = r.metrics.settle_time / nominal_bound;
    std::printf("%s: planned on %.4f L + %.4f m, settled %.2f s = %.2f nominal T* (%.4f s)\n",
                learn ? "learnt" : "estimator off", r.planned_swing.scale, r.planned_swing.offset, r.metrics.settle_time,
                ratio, nominal_bound);
    EXPECT_EQ(r.latched_faults, 0u);
    EXPECT_EQ(r.braked_cycles, 0u);
    EXPECT_EQ(r.unsolved_plans, 0u) << "the learning move and the move, each followed on its own plan";
    if (learn) {
      EXPECT_EQ(r.planned_swing.scale, 1.0) << "one cable length: the scale is held";
      EXPECT_NEAR(r.planned_swing.offset, 0.2 * cfg.facts.crane.cable_length, 0.01);
      EXPECT_LE(ratio, 1.2);
    } else {
      EXPECT_EQ(r.planned_swing.scale, cfg.trajectory_planner.manual.swing_length_scale);
      EXPECT_EQ(r.planned_swing.offset, cfg.trajectory_planner.manual.swing_length_offset);
      EXPECT_GT(ratio, 1.5) << "the premise: on the configured length this move is slow";
    }
  }
}

// The gantry's random move 10 (seed 1), learnt while working, on a plant with a 20 % longer cable,
// a 20 % heavier load and 30 % less friction than the model: its learning move runs the trolley to
// 0.12 m, 41 mm above where the travel limiter's stop margin begins. While the friction factor was
// handed to the compensation only at the target, the compensation pushed the model's friction along
// the move, the trolley led its reference by 30-36 mm and the limiter latched a fault (bit 2) at the
// end of the learning move (docs/optimal_control.md, "The friction factor along the move"). Handed
// along the move, neither move faults or brakes, and the measured one settles within 1.2 T*.
TEST(TrajectoryFollower, TheGantrysLearningMoveOnLessFrictionStaysClearOfTheTravelLimiter) {
  auto cfg = config("gantry_crane.yaml");
  cfg.state_estimator.swing_length.enabled = true;  // crane_sim compare --learn
  plant::PlantMismatch plant;
  plant.cable_length_factor = 1.2;
  plant.load_mass_factor = 1.2;
  plant.friction_factor = 0.7;
  const auto move = stack::random_moves(cfg, 20, 1)[10];
  const double nominal_bound = optimal_control::solve_minimum_time(stack::follower_problem(cfg, move, 200)).duration;
  stack::FollowerRun run;
  run.maneuver = move;
  run.mismatch = plant;
  run.first_move = stack::learning_move(cfg, move);
  stack::FollowerResult r;
  ASSERT_NO_THROW(r = stack::run_follower(cfg, run)) << "a supervisor fault in the learning move throws";
  const double ratio = r.metrics.settle_time / nominal_bound;
  std::printf("random move 10 after its learning move: settled %.2f s = %.2f T* (%.4f s), error %.2f mm\n",
              r.metrics.settle_time, ratio, nominal_bound, 1e3 * r.metrics.final_position_error);
  EXPECT_EQ(r.latched_faults, 0u);
  EXPECT_EQ(r.braked_cycles, 0u);
  EXPECT_LE(ratio, 1.2);
}

// A minimum-time goal that the planner does not plan (no plan solved) runs the time-optimal
// profile, which the run counts (InProcessResult::unsolved_plans, the planner stage's
// unsolved_plans): a failure of the solve is not silent in a comparison (crane_sim compare prints
// the runs that had one). The lab crane's trolley move still arrives (the profile is swing-free on
// the linear model).
TEST(TrajectoryFollower, AGoalThePlannerDoesNotPlanRunsTheTimeOptimalProfileAndIsCounted) {
  const auto cfg = config("lab_tower_crane.yaml");
  stack::InProcessRun run;
  run.maneuver = stack::find_maneuver(cfg, "trolley");
  run.controller = stack::choose_controller("follower", run.maneuver, false);
  run.profile = protocol::MoveRequest::PROFILE_MINIMUM_TIME;
  run.plan_move = [](const trajectory_planner::PlanRequest&) {
    return std::shared_ptr<const trajectory_planner::PlannedPath>();
  };
  const auto unplanned = stack::run_in_process(cfg, run);
  run.plan_move = nullptr;  // the planner's own solve (planner_node_way)
  const auto planned = stack::run_in_process(cfg, run);
  std::printf("trolley, no plan: settle %.2f s, error %.2f mm; planned: settle %.2f s\n",
              unplanned.metrics.settle_time, 1e3 * unplanned.metrics.final_position_error, planned.metrics.settle_time);
  EXPECT_EQ(unplanned.unsolved_plans, 1u);
  EXPECT_EQ(planned.unsolved_plans, 0u);
  EXPECT_EQ(unplanned.latched_faults, 0u);
  EXPECT_LT(unplanned.metrics.final_position_error, 0.005);
}

}  // namespace
