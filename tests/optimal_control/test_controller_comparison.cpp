// Issue 32's comparison (crane/stack/controller_comparison.hpp): the seeded random moves, the
// summary's arithmetic, and a few random tower moves in closed loop, where T* must respect the
// rigid-body bound of each axis and the follower must settle within the worst-case goal.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "crane/stack/controller_comparison.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace {

using namespace crane;

stack::StackConfig config(const std::string& name) {
  return stack::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/" + name);
}

// [s] a rigid body's fastest rest-to-rest move over `distance` with speed and acceleration limits:
// bang-bang with a coast. No swing-free move can be faster on that axis.
double rigid_time(double distance, double velocity, double acceleration) {
  distance = std::abs(distance);
  if (distance * acceleration > velocity * velocity) return distance / velocity + velocity / acceleration;
  return 2.0 * std::sqrt(distance / acceleration);
}

// The moves a tool runs by name (crane_sim and crane_demo alike): the demo maneuvers, then the
// random ones, those named kept in that order; an unknown name refused naming it and what exists.
TEST(ControllerComparison, MovesAreSelectedByNameAndAnUnknownOneIsNamed) {
  const auto cfg = config("lab_tower_crane.yaml");
  const auto names = [](const std::vector<stack::ManeuverConfig>& moves) {
    std::vector<std::string> out;
    for (const auto& m : moves) out.push_back(m.name);
    return out;
  };
  const auto all = stack::select_moves(cfg, {}, 3, 1);
  ASSERT_EQ(all.size(), cfg.maneuvers.size() + 3);
  EXPECT_EQ(all.front().name, cfg.maneuvers.front().name);
  EXPECT_EQ(all.back().name, "random_2");
  EXPECT_EQ(all.back().trolley_target, stack::random_moves(cfg, 3, 1)[2].trolley_target);
  EXPECT_EQ(names(stack::select_moves(cfg, {"random_1", "trolley"}, 3, 1)), (std::vector<std::string>{"trolley", "random_1"}));
  EXPECT_EQ(names(stack::select_moves(cfg, {}, 2, 1, false)), (std::vector<std::string>{"random_0", "random_1"}));
  EXPECT_EQ(stack::select_moves(cfg, {}).size(), cfg.maneuvers.size());
  const auto message = [&](const std::vector<std::string>& asked, int count, bool demo) {
    try {
      (void)stack::select_moves(cfg, asked, count, 1, demo);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({"random_3"}, 3, true),
            "--maneuver 'random_3' is neither a demo maneuver of the configuration nor one of the 3 random moves "
            "(random_0 .. random_2, --moves)");
  EXPECT_EQ(message({"random_0"}, 0, true), "--maneuver 'random_0' is not a demo maneuver of the configuration");
  EXPECT_EQ(message({"trolley"}, 2, false),
            "--maneuver 'trolley' is not one of the 2 random moves (random_0 .. random_1, --moves)");
  EXPECT_EQ(message({"trolley"}, 0, false),
            "--maneuver 'trolley' is not a move: no demo maneuvers and no random moves asked for");
}

TEST(ControllerComparison, RandomMovesAreSeededAndStayInThePlannersRange) {
  for (const char* file : {"lab_tower_crane.yaml", "gantry_crane.yaml", "overhead_crane.yaml"}) {
    const auto cfg = config(file);
    const auto& p = cfg.trajectory_planner;
    const auto moves = stack::random_moves(cfg, 40, 7);
    ASSERT_EQ(moves.size(), 40u);
    const auto again = stack::random_moves(cfg, 40, 7);
    const auto other = stack::random_moves(cfg, 40, 8);
    int hoisting = 0, differs = 0;
    for (std::size_t i = 0; i < moves.size(); ++i) {
      const auto& m = moves[i];
      SCOPED_TRACE(std::string(file) + " " + m.name);
      EXPECT_EQ(m.trolley_target, again[i].trolley_target);
      EXPECT_EQ(m.slew_target, again[i].slew_target);
      EXPECT_EQ(m.cable_length_target, again[i].cable_length_target);
      differs += m.trolley_target != other[i].trolley_target ? 1 : 0;
      for (const double x : {m.initial_trolley_position, m.trolley_target}) {
        EXPECT_GE(x, p.trolley_min_position);
        EXPECT_LE(x, p.trolley_max_position);
      }
      EXPECT_GE(std::abs(m.trolley_target - m.initial_trolley_position),
                0.2 * (p.trolley_max_position - p.trolley_min_position) - 1e-12);
      if (cfg.facts.crane_kind == common::CraneKind::tower) {
        const double slew = std::abs(m.slew_target - m.initial_slew_angle);
        EXPECT_GE(slew, std::numbers::pi / 18.0 - 1e-12);
        EXPECT_LE(slew, std::numbers::pi + 1e-12);
        for (const double a : {m.initial_slew_angle, m.slew_target}) {
          EXPECT_GE(a, p.slew_min_angle);
          EXPECT_LE(a, p.slew_max_angle);
        }
      } else {
        EXPECT_EQ(m.slew_target, 0.0);
        EXPECT_EQ(m.initial_slew_angle, 0.0);
      }
      if (cfg.facts.crane_kind == common::CraneKind::overhead) {
        for (const double y : {m.initial_bridge_position, m.bridge_target}) {
          EXPECT_GE(y, p.bridge_min_position);
          EXPECT_LE(y, p.bridge_max_position);
        }
        EXPECT_GE(std::abs(m.bridge_target - m.initial_bridge_position),
                  0.2 * (p.bridge_max_position - p.bridge_min_position) - 1e-12);
      }
      if (m.cable_length_target != cfg.facts.crane.cable_length) {
        ++hoisting;
        EXPECT_GE(m.cable_length_target, std::max(p.cable_min_length, 0.5 * cfg.facts.crane.cable_length));
        EXPECT_LE(m.cable_length_target, std::min(p.cable_max_length, 1.5 * cfg.facts.crane.cable_length));
      }
      // The record holds four linear profiles' times and ten swing periods.
      const double period = 2.0 * std::numbers::pi * std::sqrt(m.cable_length_target / cfg.facts.crane.gravity);
      EXPECT_GE(m.duration, 4.0 * rigid_time(m.trolley_target - m.initial_trolley_position, m.trolley_max_velocity,
                                             m.trolley_max_acceleration) +
                                10.0 * period);
    }
    // About a quarter hoist (binomial, 40 draws at 1/4: 1..20 holds with probability > 0.999).
    EXPECT_GE(hoisting, 1) << file;
    EXPECT_LE(hoisting, 20) << file;
    EXPECT_GT(differs, 35) << file;
  }
  const auto cfg = config("lab_tower_crane.yaml");
  EXPECT_THROW((void)stack::random_moves(cfg, 0, 1), std::invalid_argument);
  EXPECT_THROW((void)stack::random_moves(cfg, 1001, 1), std::invalid_argument);
  EXPECT_THROW((void)stack::compared_controllers({"delay1", "lqr"}), std::invalid_argument);
}

TEST(ControllerComparison, SummaryCountsNeverSettledAsInfiniteAndFaultsApart) {
  const auto outcome = [](double ratio, std::uint32_t faults, const char* error = "") {
    stack::ControllerOutcome o;
    o.controller = "c";
    o.ratio = ratio;
    o.metrics.settle_time = ratio;
    o.metrics.residual_swing = 0.001 * ratio;
    o.metrics.final_position_error = 0.001 * ratio;
    o.metrics.max_voltage = ratio;
    o.latched_faults = faults;
    o.error = error;
    return o;
  };
  std::vector<stack::MoveComparison> moves(5);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<stack::ControllerOutcome> outcomes{outcome(1.1, 0), outcome(0.9, 0), outcome(nan, 0),
                                                       outcome(1.3, 4), outcome(2.0, 0, "refused")};
  for (std::size_t i = 0; i < moves.size(); ++i) moves[i].outcomes = {outcomes[i]};
  const auto s = stack::summarize(moves);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].runs, 5);
  EXPECT_EQ(s[0].settled, 3);
  EXPECT_EQ(s[0].faulted, 1);
  EXPECT_EQ(s[0].failed, 1);
  // Ratios 0.9, 1.1, 1.3, inf (never), inf (error): the median is the third.
  EXPECT_DOUBLE_EQ(s[0].median_ratio, 1.3);
  EXPECT_TRUE(std::isinf(s[0].worst_ratio));
  EXPECT_DOUBLE_EQ(s[0].peak_voltage, 1.3);
  EXPECT_DOUBLE_EQ(s[0].worst_position_error, 0.0013);

  // A comparison none of whose runs could be made (a calibrated corner's bound not solved): one
  // error per controller, NaN figures, the given T*; the summary counts each as failed, not settled.
  const auto controllers = stack::compared_controllers({"follower", "delay1"});
  const auto failed = stack::failed_comparison(stack::random_moves(config("lab_tower_crane.yaml"), 1, 1)[0], {},
                                               controllers, 2.5, "the bound was not solved");
  ASSERT_EQ(failed.outcomes.size(), 2u);
  EXPECT_EQ(failed.bound, 2.5);
  for (const auto& o : failed.outcomes) {
    EXPECT_EQ(o.error, "the bound was not solved");
    EXPECT_TRUE(std::isnan(o.ratio));
    EXPECT_TRUE(std::isnan(o.metrics.settle_time));
  }
  const auto f = stack::summarize({failed});
  ASSERT_EQ(f.size(), 2u);
  EXPECT_EQ(f[0].failed, 1);
  EXPECT_EQ(f[0].settled, 0);
}

// Three seeded random tower moves (trolley and slew together, some hoisting): T* is no faster than
// either axis alone as a rigid body at its rated limits, and the follower settles within the
// issue's worst-case goal (1.5 T*) with no supervisor fault and no brake, where delay1 needs more
// or never settles.
TEST(ControllerComparison, RandomTowerMovesInClosedLoop) {
  const auto cfg = config("lab_tower_crane.yaml");
  const auto controllers = stack::compared_controllers({"follower", "delay1"});
  for (const auto& m : stack::random_moves(cfg, 3, 32)) {
    SCOPED_TRACE(m.name);
    const auto bound = stack::comparison_bound(cfg, m, 100);
    const double rigid = std::max(
        rigid_time(m.trolley_target - m.initial_trolley_position, m.trolley_max_velocity, m.trolley_max_acceleration),
        rigid_time(m.slew_target - m.initial_slew_angle, m.slew_max_velocity, m.slew_max_acceleration));
    EXPECT_GE(bound.duration, rigid * (1.0 - 1e-6));
    const auto c = stack::compare_move(cfg, m, bound, controllers, {}, 100);
    ASSERT_EQ(c.outcomes.size(), 2u);
    const auto& follower = c.outcomes[0];
    const auto& delay1 = c.outcomes[1];
    EXPECT_TRUE(follower.error.empty()) << follower.error;
    EXPECT_LE(follower.ratio, 1.5);
    EXPECT_EQ(follower.latched_faults, 0u);
    EXPECT_EQ(follower.braked_cycles, 0u);
    EXPECT_LT(follower.metrics.final_position_error, 0.005);
    EXPECT_LT(follower.metrics.final_slew_error, 0.005);
    EXPECT_TRUE(delay1.error.empty()) << delay1.error;
    // delay1 is slower, or never settles (NaN: on an inward slew it trips the slew overspeed).
    EXPECT_FALSE(delay1.ratio <= follower.ratio) << delay1.ratio;
    std::printf("%s: T* %.3f s (rigid %.3f s), follower %.2f T*, delay1 %.2f T*\n", m.name.c_str(), bound.duration,
                rigid, follower.ratio, delay1.ratio);
  }
}

}  // namespace
