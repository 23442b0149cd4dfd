// The online payload mass and friction estimation (crane::adaptation in the state estimator stage)
// in closed loop: every stage object and the plant, in one process, lockstep (deterministic: no
// seed needed, the plant's integration is the same every time). The plant differs from the
// configuration (plant::PlantMismatch): it carries 3.0 kg where the configuration says 2.0 kg, or
// its friction rises by 50 % on both drives in the middle of a run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "crane/common/protocol_signals.hpp"
#include "crane/plant/drives_and_sensors.hpp"
#include "crane/stack/in_process_stack.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace {

using crane::stack::find_maneuver;
using crane::stack::InProcessStack;
using crane::stack::ManeuverConfig;
using crane::stack::StackConfig;
using crane::protocol::CraneState;

constexpr double kHeavy = 1.5;  // plant load mass factor: 3.0 kg against the configured 2.0 kg

StackConfig lab(bool adaptation) {
  StackConfig c = crane::stack::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml");
  c.state_estimator.adaptation.enabled = adaptation;
  return c;
}

// ---- Payload mass ---------------------------------------------------------------------------------

struct MassRun {
  std::vector<double> t, mass, bound;
  std::vector<bool> confident;
};

// The combined maneuver of section 3.3.3 (delay1, trapezoid) on the heavy plant, the estimate of
// every cycle from the move's start on.
MassRun heavy_combined_run() {
  const StackConfig cfg = lab(true);
  const ManeuverConfig& m = find_maneuver(cfg, "combined");
  crane::stack::InProcessOptions options;
  options.controller = crane::stack::choose_controller("delay1", m, false);
  options.mismatch.load_mass_factor = kHeavy;
  options.initial_trolley_position = m.initial_trolley_position;
  options.initial_slew_angle = m.initial_slew_angle;
  InProcessStack stack(cfg, options);
  const auto goal = crane::stack::move_request(m, cfg.facts, 1, crane::protocol::MoveRequest::PROFILE_TRAPEZOID,
                                               crane::stack::kMoveStartCycle);
  MassRun run;
  const auto total = crane::stack::kMoveStartCycle + static_cast<std::uint64_t>(m.duration / cfg.facts.sample_period);
  for (std::uint64_t k = 0; k < total; ++k) {
    stack.step(k == 0 ? std::span(&goal, 1) : std::span<const crane::protocol::MoveRequest>());
    if (k < crane::stack::kMoveStartCycle) continue;
    const CraneState& e = stack.estimate();
    run.t.push_back(static_cast<double>(k - crane::stack::kMoveStartCycle) * cfg.facts.sample_period);
    run.mass.push_back(e.payload_mass);
    run.bound.push_back(e.payload_mass_bound);
    run.confident.push_back(e.payload_confident);
  }
  return run;
}

TEST(Adaptation, PayloadMassWithinFivePercentWithinThreeSecondsOfMotion) {
  const MassRun run = heavy_combined_run();
  const double truth = kHeavy * lab(true).facts.crane.load_mass;  // 3.0 kg
  // First cycle from which the used estimate stays confident and within 5 % of the truth.
  std::size_t settled = run.t.size();
  for (std::size_t i = run.t.size(); i-- > 0;) {
    if (!(run.confident[i] && std::abs(run.mass[i] - truth) <= 0.05 * truth)) break;
    settled = i;
  }
  ASSERT_LT(settled, run.t.size()) << "never within 5 %: last " << run.mass.back() << " kg";
  std::printf("payload: plant %.2f kg, configured %.2f kg; the estimate is confident and within 5 %% from "
              "t = %.2f s of the move on: %.3f kg +- %.3f kg (2 sigma) then, %.3f kg +- %.3f kg at the end (t = %.1f s)\n",
              truth, lab(true).facts.crane.load_mass, run.t[settled], run.mass[settled], run.bound[settled],
              run.mass.back(), run.bound.back(), run.t.back());
  EXPECT_LE(run.t[settled], 3.0);
  EXPECT_LE(std::abs(run.mass.back() - truth), run.bound.back()) << "the truth outside the printed bound";
  EXPECT_GT(run.bound.back(), 0.0);
}

// Settle time, trolley overshoot, residual swing and final position error of a maneuver, on a plant
// carrying `plant_factor` x the lab's 2.0 kg, configured with `configured_factor` x 2.0 kg.
struct Row {
  double settle{0.0};          // [s] NaN: never
  double overshoot{0.0};       // [mm] trolley beyond its target
  double residual{0.0};        // [deg]
  double position_error{0.0};  // [mm]
};
struct RowCase {
  double plant_factor{1.0};
  double configured_factor{1.0};
  bool adaptation{false};      // the online estimate (state_estimator.adaptation.enabled)
  bool adapt_friction{true};   // adaptation.adapt_friction: false, the payload mass only
  bool after_learning{false};  // measured after the learning move (learning_move below)
};

// The move made first when a row is measured after one: the combined maneuver backwards, to where the
// measured maneuver starts (a slewing move: the load is identified by the slew, (3.32), not by a
// trolley move alone). delay1 makes it with half the slew's limits: at full limits, the trolley moving
// in, its slew lagged the reference by 0.18 rad and caught up at 2.03 rad/s, and the supervisor
// stopped it (slew_overspeed; architecture.md); the gain schedule with full ones.
ManeuverConfig learning_move(const StackConfig& cfg, const ManeuverConfig& measured, const std::string& controller) {
  ManeuverConfig back = find_maneuver(cfg, "combined");
  back.name = "combined backwards";
  back.initial_trolley_position = back.trolley_target;
  back.initial_slew_angle = back.slew_target;
  back.trolley_target = measured.initial_trolley_position;
  back.slew_target = measured.initial_slew_angle;
  if (controller == "delay1") {
    back.slew_max_velocity *= 0.5;
    back.slew_max_acceleration *= 0.5;
  }
  return back;
}

Row run_row(const std::string& controller, const std::string& maneuver_name, const RowCase& c) {
  StackConfig cfg = lab(c.adaptation);
  cfg.state_estimator.adaptation.adapt_friction = c.adapt_friction;
  cfg.facts.crane.load_mass *= c.configured_factor;
  const ManeuverConfig& m = find_maneuver(cfg, maneuver_name);
  crane::stack::InProcessRun run;
  run.maneuver = m;
  run.controller = crane::stack::choose_controller(controller, m, false);
  run.profile = controller.rfind("gain_scheduling", 0) == 0 ? crane::protocol::MoveRequest::PROFILE_STEP
                                                            : crane::protocol::MoveRequest::PROFILE_TRAPEZOID;
  run.mismatch.load_mass_factor = c.plant_factor;
  if (c.after_learning) run.first_move = learning_move(cfg, m, controller);
  const auto result = crane::stack::run_in_process(cfg, run);
  Row r;
  r.settle = result.metrics.settle_time;
  r.residual = result.metrics.residual_swing * 180.0 / 3.14159265358979323846;
  r.position_error = 1e3 * result.metrics.final_position_error;
  const double direction = m.trolley_target > m.initial_trolley_position ? 1.0 : -1.0;
  for (const auto& rec : result.records) r.overshoot = std::max(r.overshoot, 1e3 * direction * (rec.x - m.trolley_target));
  return r;
}

// The heavy plant (3.0 kg) with the configured 2.0 kg, with the online estimate, and configured
// right (3.0 kg: what a perfect estimate gives), against the nominal 2.0 kg plant: the first move
// from rest, and a move after the learning move. Asserted, after the learning move: with the payload
// mass estimate (adapt_friction false) every figure is at least as close to the nominal load's as
// without it (the criterion). With friction adaptation too, the trolley step's settle time
// moves away (printed, docs/architecture.md "Online estimation": the released friction, not the load).
TEST(Adaptation, GainSchedulingAndTrackingWithTheEstimateAgainstTheNominalLoad) {
  std::printf("%-24s %-9s %-44s %8s %13s %15s %11s\n", "controller", "maneuver", "plant / model", "settle_s",
              "overshoot_mm", "resid_swing_deg", "pos_err_mm");
  for (const std::string controller : {"gain_scheduling_partial", "delay1"}) {
    const std::string m = controller == "delay1" ? "combined" : "trolley";
    const auto print = [&](const char* label, const Row& r) {
      std::printf("%-24s %-9s %-44s %8.2f %13.2f %15.3f %11.2f\n", controller.c_str(), m.c_str(), label, r.settle,
                  r.overshoot, r.residual, r.position_error);
    };
    for (const bool after : {false, true}) {
      const Row nominal = run_row(controller, m, {1.0, 1.0, false, true, after});
      const Row configured = run_row(controller, m, {kHeavy, 1.0, false, true, after});
      const Row estimated = run_row(controller, m, {kHeavy, 1.0, true, true, after});
      const Row mass_only = run_row(controller, m, {kHeavy, 1.0, true, false, after});
      const Row known = run_row(controller, m, {1.0, kHeavy, false, true, after});
      print(after ? "2.0 kg / 2.0 kg, after learning" : "2.0 kg / configured 2.0 kg", nominal);
      print(after ? "3.0 kg / 2.0 kg, after learning" : "3.0 kg / configured 2.0 kg", configured);
      print(after ? "3.0 kg / estimate, after learning" : "3.0 kg / online estimate", estimated);
      print(after ? "3.0 kg / mass estimate only, after learning" : "3.0 kg / mass estimate only", mass_only);
      print(after ? "3.0 kg / 3.0 kg, after learning" : "3.0 kg / configured 3.0 kg", known);
      if (!after) {
        EXPECT_LE(std::abs(estimated.residual - nominal.residual), std::abs(configured.residual - nominal.residual) + 1e-3)
            << controller;
        continue;
      }
      ASSERT_TRUE(std::isfinite(nominal.settle) && std::isfinite(mass_only.settle)) << controller;
      EXPECT_LE(std::abs(mass_only.settle - nominal.settle), std::abs(configured.settle - nominal.settle) + 1e-9)
          << controller;
      EXPECT_LE(std::abs(mass_only.residual - nominal.residual), std::abs(configured.residual - nominal.residual) + 1e-3)
          << controller;
      // The final error is read by the trolley's encoder: a difference within one count (7.9 um)
      // is which count the friction compensation's dither ends on, not the load (the convergence
      // study, docs/integration.md: an integration error of 1e-7 m moved such figures by a count).
      const double count_mm = 1e3 * crane::plant::DrivesAndSensors(lab(true).facts.crane).trolley_resolution();
      EXPECT_LE(std::abs(mass_only.position_error - nominal.position_error),
                std::abs(configured.position_error - nominal.position_error) + count_mm + 1e-9)
          << controller;
    }
  }
}

// ---- Friction ---------------------------------------------------------------------------------------

struct FrictionRun {
  std::vector<double> move_end_t;         // [s] since the friction change (negative: before it)
  std::vector<double> trolley_error_mm;   // at the end of each move
  std::vector<double> slew_error_mrad;
  double adapted_after{-1.0};             // [s] after the change: in-use Coulomb within 10 % of the plant's, for good
  std::uint32_t trolley_sign_changes{0};
  std::uint32_t slew_sign_changes{0};
  bool limit_cycle{false};
  crane::common::AxisFriction trolley_in_use{}, slew_in_use{};
  std::uint8_t adaptation{0};
};

// Ordinary moves of both axes (trapezoids with the combined maneuver's limits, delay1), 8 s each;
// the plant's friction is `change` times the configured from the end of the first move on.
FrictionRun friction_run(bool adaptation, double change, int moves, double step_size) {
  const StackConfig cfg = lab(adaptation);
  const ManeuverConfig& base = find_maneuver(cfg, "combined");
  crane::stack::InProcessOptions options;
  options.controller = crane::stack::choose_controller("delay1", base, false);
  options.initial_trolley_position = 0.6;
  options.initial_slew_angle = 0.0;
  const double dt = cfg.facts.sample_period;
  const std::uint64_t move_cycles = static_cast<std::uint64_t>(8.0 / dt);
  const std::uint64_t change_cycle = crane::stack::kMoveStartCycle + move_cycles;
  options.mismatch.friction_change_factor = change;
  options.mismatch.friction_change_cycle = change_cycle;
  InProcessStack stack(cfg, options);
  // Targets: a step_size [m] and step_size [rad] back and forth around 0.6 m and 0.5 rad, varied.
  const double trolley[] = {0.6 + step_size, 0.6 - 0.5 * step_size, 0.6 + 0.8 * step_size, 0.6 - step_size};
  const double slew[] = {step_size, -0.6 * step_size, 0.9 * step_size, -step_size};
  const auto plant_coulomb = [&](const crane::common::AxisFriction& f) {
    return std::array<double, 2>{change * f.coulomb_positive, change * f.coulomb_negative};
  };
  const auto t_pos = plant_coulomb(cfg.facts.crane.trolley_friction);
  const auto s_pos = plant_coulomb(cfg.facts.crane.slew_friction);
  FrictionRun run;
  std::uint64_t k = 0;
  double within_since = -1.0;
  for (int move = 0; move < moves; ++move) {
    ManeuverConfig m = base;
    m.trolley_target = trolley[move % 4];
    m.slew_target = slew[move % 4];
    const std::uint64_t start = crane::stack::kMoveStartCycle + static_cast<std::uint64_t>(move) * move_cycles;
    const auto goal = crane::stack::move_request(m, cfg.facts, static_cast<std::uint32_t>(move + 1),
                                                 crane::protocol::MoveRequest::PROFILE_TRAPEZOID, start);
    const std::uint64_t first = k;  // the goal is sent once, ahead of (or at) its start cycle
    for (; k < start + move_cycles; ++k) {
      stack.step(k == first ? std::span(&goal, 1) : std::span<const crane::protocol::MoveRequest>());
      const CraneState& e = stack.estimate();
      const double t = (static_cast<double>(k) - static_cast<double>(change_cycle)) * dt;
      const auto tf = crane::common::trolley_friction_in_use(e);
      const auto sf = crane::common::slew_friction_in_use(e);
      const bool within = std::abs(tf.coulomb_positive - t_pos[0]) <= 0.1 * t_pos[0] &&
                          std::abs(tf.coulomb_negative - t_pos[1]) <= 0.1 * t_pos[1] &&
                          std::abs(sf.coulomb_positive - s_pos[0]) <= 0.1 * s_pos[0] &&
                          std::abs(sf.coulomb_negative - s_pos[1]) <= 0.1 * s_pos[1];
      if (t >= 0.0) {
        if (!within) within_since = -1.0;
        if (within && within_since < 0.0) within_since = t;
      }
    }
    const auto& s = stack.sensors();
    run.move_end_t.push_back((static_cast<double>(k) - static_cast<double>(change_cycle)) * dt);
    run.trolley_error_mm.push_back(1e3 * std::abs(s.trolley_position - m.trolley_target));
    run.slew_error_mrad.push_back(1e3 * std::abs(s.slew_angle - m.slew_target));
  }
  const CraneState& e = stack.estimate();
  run.adapted_after = within_since;
  run.trolley_sign_changes = e.trolley_voltage_sign_changes;
  run.slew_sign_changes = e.slew_voltage_sign_changes;
  run.limit_cycle = (e.adaptation & (CraneState::ADAPTATION_TROLLEY_LIMIT_CYCLE | CraneState::ADAPTATION_SLEW_LIMIT_CYCLE)) != 0;
  run.trolley_in_use = crane::common::trolley_friction_in_use(e);
  run.slew_in_use = crane::common::slew_friction_in_use(e);
  run.adaptation = e.adaptation;
  return run;
}

void print_run(const char* label, const FrictionRun& r) {
  char adapted[64] = "never";
  if (r.adapted_after >= 0.0) std::snprintf(adapted, sizeof adapted, "%.1f s after the change", r.adapted_after);
  if ((r.adaptation & CraneState::ADAPTATION_ENABLED) == 0) {
    std::printf("%s: online estimation off (no detector, configured friction)\n", label);
  } else {
    std::printf("%s: in-use Coulomb friction within 10 %% of the plant's from %s on; drive-voltage sign changes at "
                "rest: trolley %u, slew %u; limit cycle %s\n",
                label, adapted, r.trolley_sign_changes, r.slew_sign_changes, r.limit_cycle ? "yes" : "no");
  }
  std::printf("  move end [s after change]  trolley error [mm]  slew error [mrad]\n");
  for (std::size_t i = 0; i < r.move_end_t.size(); ++i) {
    std::printf("  %24.1f  %18.2f  %17.2f\n", r.move_end_t[i], r.trolley_error_mm[i], r.slew_error_mrad[i]);
  }
  std::printf("  trolley friction in use: b+ %.3f b- %.3f c+ %.3f c- %.3f fs+ %.3f fs- %.3f\n",
              r.trolley_in_use.viscous_positive, r.trolley_in_use.viscous_negative, r.trolley_in_use.coulomb_positive,
              r.trolley_in_use.coulomb_negative, r.trolley_in_use.static_positive, r.trolley_in_use.static_negative);
  std::printf("  slew friction in use:    b+ %.3f b- %.3f c+ %.3f c- %.3f fs+ %.3f fs- %.3f\n",
              r.slew_in_use.viscous_positive, r.slew_in_use.viscous_negative, r.slew_in_use.coulomb_positive,
              r.slew_in_use.coulomb_negative, r.slew_in_use.static_positive, r.slew_in_use.static_negative);
}

TEST(Adaptation, FrictionRaisedFiftyPercentMidRunIsCompensatedAgain) {
  constexpr int kMoves = 7;  // the change after the first; 48 s of moves after it
  const FrictionRun fixed = friction_run(false, 1.5, kMoves, 0.3);
  const FrictionRun adapted = friction_run(true, 1.5, kMoves, 0.3);
  print_run("configured friction", fixed);
  print_run("online re-estimate ", adapted);
  ASSERT_GE(adapted.adapted_after, 0.0) << "the in-use Coulomb friction never came within 10 % of the plant's";
  EXPECT_LE(adapted.adapted_after, 30.0);
  EXPECT_FALSE(adapted.limit_cycle);
  // Every move that ends after the adaptation settles within 5 mm (and 5 mrad on the slew).
  int checked = 0;
  for (std::size_t i = 0; i < adapted.move_end_t.size(); ++i) {
    if (adapted.move_end_t[i] < adapted.adapted_after + 8.0) continue;
    ++checked;
    EXPECT_LT(adapted.trolley_error_mm[i], 5.0) << "move " << i;
    EXPECT_LT(adapted.slew_error_mrad[i], 5.0) << "move " << i;
  }
  EXPECT_GE(checked, 1);
}

TEST(Adaptation, DataThatCannotIdentifyFrictionLeaveItUnchanged) {
  // Moves of 3 mm and 3 mrad: the drives barely leave the zero-velocity band, never long enough for a
  // row; the plant's friction is 1.5 times the configured from the end of the first move.
  const FrictionRun r = friction_run(true, 1.5, 4, 0.003);
  const auto cfg = lab(true).facts.crane;
  print_run("unidentifiable", r);
  EXPECT_EQ(r.adaptation & (CraneState::ADAPTATION_TROLLEY_FRICTION_ADAPTED | CraneState::ADAPTATION_SLEW_FRICTION_ADAPTED), 0);
  EXPECT_EQ(r.trolley_in_use.coulomb_positive, cfg.trolley_friction.coulomb_positive);
  EXPECT_EQ(r.trolley_in_use.coulomb_negative, cfg.trolley_friction.coulomb_negative);
  EXPECT_EQ(r.trolley_in_use.viscous_positive, cfg.trolley_friction.viscous_positive);
  EXPECT_EQ(r.slew_in_use.coulomb_positive, cfg.slew_friction.coulomb_positive);
  EXPECT_EQ(r.slew_in_use.static_negative, cfg.slew_friction.static_negative);
}

}  // namespace
