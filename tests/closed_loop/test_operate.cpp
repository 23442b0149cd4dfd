// Operating the crane without DDS (crane::stack::InProcessStack: every stage object and the plant
// in the lockstep order): manual mode with sway control from a scripted stick, the controlled
// anti-sway stop, the dead-man rule, the operating modes, and the no-go zones over seeded random
// goals and manual sessions (counts: CRANE_ZONE_GOALS, CRANE_ZONE_SESSIONS).
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/stack/in_process_stack.hpp"
#include "crane/stack/stack_config.hpp"
#include "crane/trajectory_planner/zone_guard.hpp"
#include "crane/trajectory_planner/zone_paths.hpp"

namespace {
using namespace crane;
using Status = protocol::SupervisorStatus;
using Feedback = protocol::MoveStatus;
using Request = protocol::MoveRequest;
constexpr double kDeg = 180.0 / std::numbers::pi;

stack::StackConfig lab() { return stack::load_stack_config(CRANE_SOURCE_DIR "/deploy/config/lab_tower_crane.yaml"); }

// The lab crane's jib is 1.2 m; a full trolley stick for 3 s travels 1.5 m. These tests lengthen
// it to 3 m (planner and supervisor travel), with the same drives, cable and load.
stack::StackConfig long_jib(stack::StackConfig c) {
  c.trajectory_planner.trolley_max_position = 2.8;
  c.supervisor.trolley_max = 3.0;
  return c;
}

protocol::SupervisorCommand set_mode(std::uint32_t id, std::uint8_t mode) {
  protocol::SupervisorCommand c;
  c.request_id = id;
  c.command = protocol::SupervisorCommand::COMMAND_SET_OPERATING_MODE;
  c.operating_mode = mode;
  return c;
}

protocol::OperatorSpeed stick(std::uint64_t seq, double trolley, double slew, double hoist = 0.0, bool micro = false) {
  protocol::OperatorSpeed s;
  s.header.seq = seq;
  s.device = protocol::OperatorSpeed::DEVICE_SCRIPT;
  s.range = micro ? protocol::OperatorSpeed::RANGE_MICRO : protocol::OperatorSpeed::RANGE_NORMAL;
  s.trolley = trolley;
  s.slew = slew;
  s.hoist = hoist;
  return s;
}

// Largest swing angle [rad] (either plane) of the plant itself.
double swing_of(const stack::InProcessStack& s) {
  const auto& p = s.plant().simulator().state();
  return std::max(std::abs(p.swing_in_plane), std::abs(p.swing_out_of_plane));
}

struct StickResult {
  double residual_swing{0.0};   // [rad] largest swing from 2 s after the reference stops, for 4 s
  double predicted_distance{0.0};  // [m] or [rad] published rest - measured position at the release
  double measured_distance{0.0};   // [m] or [rad] final - measured position at the release
  double max_swing{0.0};
};

// Cycles to rest (4 s), MANUAL, then a full stick on one axis for 3 s, released; the reference's
// stop, 2 s, then 4 s of swing measured.
StickResult scripted_stick(stack::StackConfig config, bool sway_control, int axis) {
  stack::InProcessOptions options;
  options.initial_trolley_position = axis == 0 ? 0.25 : 0.9;
  options.initial_slew_angle = axis == 0 ? 0.0 : -1.5;
  if (!sway_control) {
    config.trajectory_planner.manual.shaping = trajectory_planner::SpeedShaping::none;
    options.controller.anti_swing = anti_swing::AntiSwingLaw::none;
  }
  stack::InProcessStack s(config, options);
  const auto manual = set_mode(1, Status::OPERATION_MANUAL);
  StickResult r;
  std::optional<double> rest;
  double at_release = 0.0;
  std::optional<std::uint64_t> stopped;
  const auto measured = [&] { return axis == 0 ? s.next_sensors().trolley_position : s.next_sensors().slew_angle; };
  for (std::uint64_t k = 0; k < 3000; ++k) {
    const bool held = k >= 400 && k < 700;
    const auto speed = stick(k, axis == 0 && held ? 1.0 : 0.0, axis == 1 && held ? 1.0 : 0.0);
    s.step({}, k >= 400 ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(), k == 10 ? &manual : nullptr);
    if (k == 700) at_release = axis == 0 ? s.sensors().trolley_position : s.sensors().slew_angle;
    for (const auto& f : s.planner().move_statuses()) {
      if (k == 700 && f.result == Feedback::RESULT_MANUAL) rest = axis == 0 ? f.rest_trolley_position : f.rest_slew_angle;
    }
    r.max_swing = std::max(r.max_swing, swing_of(s));
    if (k > 700 && !stopped && !s.planner().under_speed_control()) stopped = k;
    if (stopped && k >= *stopped + 200) r.residual_swing = std::max(r.residual_swing, swing_of(s));
    if (stopped && k >= *stopped + 600) break;
  }
  EXPECT_EQ(s.status().latched_faults, 0U);
  EXPECT_TRUE(stopped.has_value());
  EXPECT_TRUE(rest.has_value()) << "no stopping position published at the release";
  r.predicted_distance = rest.value_or(NAN) - at_release;
  r.measured_distance = measured() - at_release;
  return r;
}

TEST(ManualMode, ScriptedStickStopsWithoutSwingAndWherePredicted) {
  const auto config = long_jib(lab());
  for (const int axis : {0, 1}) {
    const char* name = axis == 0 ? "trolley" : "slew";
    const auto with = scripted_stick(config, true, axis);
    const auto without = scripted_stick(config, false, axis);
    std::printf("%s: full stick 3 s, released: residual swing 2 s after the stop %.3f deg with sway control (max %.1f "
                "deg on the way), %.3f deg without (ramp only, no anti-swing law; max %.1f deg); stopping distance "
                "published %.4f, measured %.4f (%.2f %%)\n",
                name, with.residual_swing * kDeg, with.max_swing * kDeg, without.residual_swing * kDeg,
                without.max_swing * kDeg, with.predicted_distance, with.measured_distance,
                100.0 * std::abs(with.measured_distance - with.predicted_distance) / std::abs(with.predicted_distance));
    EXPECT_LT(with.residual_swing * kDeg, 0.5) << name;
    EXPECT_GT(without.residual_swing * kDeg, 2.0) << name << ": the figure without sway control";
    EXPECT_NEAR(with.measured_distance, with.predicted_distance, 0.05 * std::abs(with.predicted_distance)) << name;
  }
}

// A goal's fast move stopped half-way (deploy/crane stop): the planner publishes the stopping
// position before it decelerates, the load comes to rest there without swing.
TEST(SoftStop, AFastMoveStoppedHalfWayRestsWithoutSwingWherePredicted) {
  const auto config = lab();
  stack::InProcessOptions options;
  stack::InProcessStack s(config, options);
  Request goal;
  goal.request_id = 1;
  goal.profile = Request::PROFILE_TIME_OPTIMAL;
  goal.axes = Request::AXIS_TROLLEY | Request::AXIS_SLEW;
  goal.trolley_target = 1.1;
  goal.slew_target = 1.5;
  Request stop;
  stop.request_id = 2;
  stop.command = Request::COMMAND_STOP;
  std::optional<std::array<double, 2>> predicted;
  std::array<double, 2> at_stop{};
  bool arrived = false, aborted = false;
  double residual = 0.0;
  std::optional<std::uint64_t> rest_cycle;
  for (std::uint64_t k = 0; k < 2500; ++k) {
    const std::span<const Request> goals = k == 300 ? std::span(&goal, 1) : k == 420 ? std::span(&stop, 1)
                                                                                       : std::span<const Request>();
    s.step(goals);
    if (k == 420) at_stop = {s.sensors().trolley_position, s.sensors().slew_angle};
    for (const auto& f : s.planner().move_statuses()) {
      if (f.request_id == 2 && f.result == Feedback::RESULT_STOPPING) {
        predicted = std::array<double, 2>{f.rest_trolley_position, f.rest_slew_angle};
      }
      if (f.request_id == 2 && f.result == Feedback::RESULT_ARRIVED) {
        arrived = true;
        rest_cycle = k;
      }
      if (f.request_id == 1 && f.result == Feedback::RESULT_ABORTED) aborted = f.reason == Feedback::REASON_STOPPED;
    }
    if (rest_cycle && k >= *rest_cycle + 200) residual = std::max(residual, swing_of(s));
    if (rest_cycle && k >= *rest_cycle + 600) break;
  }
  ASSERT_TRUE(predicted.has_value());
  EXPECT_TRUE(arrived);
  EXPECT_TRUE(aborted) << "the goal is aborted with the reason stopped";
  const std::array<double, 2> final{s.next_sensors().trolley_position, s.next_sensors().slew_angle};
  for (int i = 0; i < 2; ++i) {
    const double p = (*predicted)[i] - at_stop[i], m = final[i] - at_stop[i];
    std::printf("soft stop half-way (%s): stopping distance predicted %.4f, measured %.4f (%.2f %%)\n",
                i == 0 ? "trolley, m" : "slew, rad", p, m, 100.0 * std::abs(m - p) / std::abs(p));
    EXPECT_NEAR(m, p, 0.05 * std::abs(p));
  }
  std::printf("soft stop half-way: residual swing 2 s after rest %.3f deg\n", residual * kDeg);
  EXPECT_LT(residual * kDeg, 0.5);
  EXPECT_EQ(s.status().latched_faults, 0U);
}

// The site's kind of move (a crane of deploy/config/site_three_towers.yaml): the trolley out and in
// while the jib slews at 0.7 rad/s, as the site link asks, and the trolley out on a short slew.
struct SiteMove {
  double trolley_from, trolley_to, slew_from, slew_to;
};
constexpr SiteMove kSiteMoves[] = {{0.3, 0.9, -1.2, 1.3}, {1.0, 0.3, -1.2, 1.3}, {0.2, 1.0, 0.5, 0.0}};
// The move's goal, and `options` with the move's initial pose.
Request site_move_goal(const SiteMove& m) {
  Request goal;
  goal.request_id = 1;
  goal.profile = Request::PROFILE_TRAPEZOID;
  goal.axes = Request::AXIS_TROLLEY | Request::AXIS_SLEW;
  goal.trolley_target = m.trolley_to;
  goal.slew_target = m.slew_to;
  goal.slew_max_velocity = 0.7;
  return goal;
}
stack::InProcessOptions at_site_move_start(const SiteMove& m, stack::InProcessOptions options) {
  options.initial_trolley_position = m.trolley_from;
  options.initial_slew_angle = m.slew_from;
  return options;
}

// A stalled command chain (a starved machine, a stage paused) brakes the drives under way: the
// plant's actuation gate holds the last command for its watchdog_timeout, then brakes. The
// supervisor warns (WARNING_DRIVES_BRAKED); the planner pauses the goal where the brakes stopped
// the crane and starts the rest of it from there when they open. Before, the reference ran on
// through the stall and the tracking law chased it at full voltage when the brakes opened: both
// drives at about twice their speed, the supervisor's overspeed stop (6 of these 90 windows: trolley
// 1.06 m/s, slew 2.2 rad/s; docs/site.md). Every window of lost commands across three moves (the
// trolley out and in while the jib slews at 0.7 rad/s, as the site's cranes do, and the trolley out
// on a short slew): no fault, speeds within the limits, every goal arrives at its targets (none
// aborted), the load at rest at the end.
TEST(Stall, DrivesBrakedByAStalledChainPauseTheMoveWhichGoesOnWithoutOverspeed) {
  const auto config = lab();
  int runs = 0, paused_moves = 0;
  double peak_trolley = 0.0, peak_slew = 0.0, worst_residual = 0.0, worst_error = 0.0, longest = 0.0, peak_swing = 0.0;
  for (const SiteMove& m : kSiteMoves) {
    for (const std::uint64_t lost : {4U, 10U, 20U}) {
      for (std::uint64_t from = 320; from < 700; from += 40) {
        stack::InProcessOptions options;
        options.lost_commands_from = from;
        options.lost_commands = lost;
        stack::InProcessStack s(config, at_site_move_start(m, options));
        const Request goal = site_move_goal(m);
        bool aborted = false, warned = false;
        std::optional<std::uint64_t> arrived;
        double residual = 0.0;
        for (std::uint64_t k = 0; k < 2000; ++k) {
          s.step(k == 300 ? std::span(&goal, 1) : std::span<const Request>());
          const auto& p = s.plant().simulator().state();
          peak_trolley = std::max(peak_trolley, std::abs(p.trolley_velocity));
          peak_slew = std::max(peak_slew, std::abs(p.slew_rate));
          peak_swing = std::max(peak_swing, swing_of(s));
          warned = warned || (s.status().warnings & Status::WARNING_DRIVES_BRAKED) != 0;
          for (const auto& f : s.planner().move_statuses()) {
            aborted = aborted || f.result == Feedback::RESULT_ABORTED;
            if (f.result == Feedback::RESULT_ARRIVED && !arrived) arrived = k;
          }
          if (k >= 1700) residual = std::max(residual, swing_of(s));
        }
        ++runs;
        paused_moves += warned ? 1 : 0;
        worst_residual = std::max(worst_residual, residual);
        const auto where = "move " + std::to_string(&m - kSiteMoves) + ", " + std::to_string(lost) + " commands lost from cycle " +
                           std::to_string(from);
        const auto& p = s.plant().simulator().state();
        const double error = std::max(std::abs(p.trolley_position - m.trolley_to), std::abs(p.slew_angle - m.slew_to));
        worst_error = std::max(worst_error, error);
        if (arrived) longest = std::max(longest, static_cast<double>(*arrived - 300) * config.facts.sample_period);
        EXPECT_EQ(s.status().latched_faults, 0U) << where;
        EXPECT_FALSE(aborted) << where << ": a paused goal goes on";
        EXPECT_TRUE(arrived.has_value()) << where;
        EXPECT_LT(error, 0.01) << where << ": at its targets";
        EXPECT_LT(residual * kDeg, 0.5) << where;
      }
    }
  }
  std::printf("stalled chain: %d runs, %d moves paused by the brakes, all arrived (the longest reference %.2f s), "
              "peak trolley speed %.3f m/s (limit %.1f), peak slew rate %.3f rad/s (limit %.1f), worst final error "
              "%.4f, peak swing %.2f deg, worst swing 14 s after the start %.3f deg\n",
              runs, paused_moves, longest, peak_trolley, config.supervisor.trolley_max_speed, peak_slew,
              config.supervisor.slew_max_rate, worst_error, peak_swing * kDeg, worst_residual * kDeg);
  EXPECT_GT(paused_moves, runs / 2) << "the windows fall mostly inside the moves";
  EXPECT_LT(peak_trolley, config.supervisor.trolley_max_speed);
  EXPECT_LT(peak_slew, config.supervisor.slew_max_rate);
}

// A starved machine (two stacks on two cores, a VM's stolen time) does not lose commands in one
// window but here and there: each cycle's command late with some probability, the plant holding
// the last one for a cycle or two and braking after that. The same three moves as above, at 5, 10
// and 20 % of the commands lost, over seeds: no fault, speeds within the limits, every goal at its
// targets and the load at rest.
TEST(Stall, CommandsLostHereAndThereDoNotDriveTheCraneFasterThanItsLimits) {
  const auto config = lab();
  int runs = 0;
  double peak_trolley = 0.0, peak_slew = 0.0, worst_residual = 0.0, worst_error = 0.0, peak_swing = 0.0;
  for (const SiteMove& m : kSiteMoves) {
    for (const double p : {0.05, 0.1, 0.2}) {
      for (std::uint64_t seed = 1; seed <= 5; ++seed) {
        stack::InProcessOptions options;
        options.lost_command_probability = p;
        options.lost_command_seed = seed;
        stack::InProcessStack s(config, at_site_move_start(m, options));
        const Request goal = site_move_goal(m);
        double run_trolley = 0.0, run_slew = 0.0, residual = 0.0;
        std::optional<std::uint64_t> arrived;
        for (std::uint64_t k = 0; k < 3000; ++k) {
          s.step(k == 300 ? std::span(&goal, 1) : std::span<const Request>());
          const auto& st = s.plant().simulator().state();
          run_trolley = std::max(run_trolley, std::abs(st.trolley_velocity));
          run_slew = std::max(run_slew, std::abs(st.slew_rate));
          peak_swing = std::max(peak_swing, swing_of(s));
          for (const auto& f : s.planner().move_statuses()) {
            if (f.result == Feedback::RESULT_ARRIVED && !arrived) arrived = k;
          }
          if (k >= 2700) residual = std::max(residual, swing_of(s));
        }
        ++runs;
        const auto where = "move " + std::to_string(&m - kSiteMoves) + ", " + std::to_string(p) + " of the commands lost, seed " +
                           std::to_string(seed);
        const auto& st = s.plant().simulator().state();
        const double error = std::max(std::abs(st.trolley_position - m.trolley_to), std::abs(st.slew_angle - m.slew_to));
        std::printf("%s: peak %.3f m/s %.3f rad/s, faults 0x%x, error %.4f, residual %.3f deg\n", where.c_str(), run_trolley,
                    run_slew, s.status().latched_faults, error, residual * kDeg);
        peak_trolley = std::max(peak_trolley, run_trolley);
        peak_slew = std::max(peak_slew, run_slew);
        worst_error = std::max(worst_error, error);
        worst_residual = std::max(worst_residual, residual);
        EXPECT_EQ(s.status().latched_faults, 0U) << where;
        EXPECT_TRUE(arrived.has_value()) << where;
        EXPECT_LT(error, 0.01) << where << ": at its targets";
        EXPECT_LT(residual * kDeg, 0.5) << where;
      }
    }
  }
  std::printf("commands lost here and there: %d runs, peak trolley speed %.3f m/s (limit %.1f), peak slew rate %.3f "
              "rad/s (limit %.1f), worst final error %.4f, peak swing %.2f deg, worst swing at the end %.3f deg\n",
              runs, peak_trolley, config.supervisor.trolley_max_speed, peak_slew, config.supervisor.slew_max_rate,
              worst_error, peak_swing * kDeg, worst_residual * kDeg);
  EXPECT_LT(peak_trolley, config.supervisor.trolley_max_speed);
  EXPECT_LT(peak_slew, config.supervisor.slew_max_rate);
}

// The same stall under a held stick (MANUAL): the speed reference starts again from rest where the
// brakes stopped the crane and the stick drives it on, shaped: no fault, within the speed limits,
// and the load comes to rest without swing after the release. Before, the speed reference ran on.
TEST(Stall, AStickHeldThroughAStalledChainDrivesOnFromRestWithoutOverspeed) {
  const auto config = long_jib(lab());
  int runs = 0;
  double peak_trolley = 0.0, peak_slew = 0.0, worst_residual = 0.0;
  for (const int axis : {0, 1}) {
    for (const std::uint64_t lost : {4U, 10U, 20U}) {
      for (std::uint64_t from = 450; from < 700; from += 50) {
        stack::InProcessOptions options;
        options.initial_trolley_position = axis == 0 ? 0.25 : 0.9;
        options.initial_slew_angle = axis == 0 ? 0.0 : -1.5;
        options.lost_commands_from = from;
        options.lost_commands = lost;
        stack::InProcessStack s(config, options);
        const auto manual = set_mode(1, Status::OPERATION_MANUAL);
        double residual = 0.0;
        for (std::uint64_t k = 0; k < 2000; ++k) {
          const bool held = k >= 400 && k < 700;
          const auto speed = stick(k, axis == 0 && held ? 1.0 : 0.0, axis == 1 && held ? 1.0 : 0.0);
          s.step({}, k >= 400 ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(), k == 10 ? &manual : nullptr);
          const auto& p = s.plant().simulator().state();
          peak_trolley = std::max(peak_trolley, std::abs(p.trolley_velocity));
          peak_slew = std::max(peak_slew, std::abs(p.slew_rate));
          if (k >= 1500) residual = std::max(residual, swing_of(s));
        }
        ++runs;
        worst_residual = std::max(worst_residual, residual);
        const auto where = std::string(axis == 0 ? "trolley" : "slew") + " stick, " + std::to_string(lost) +
                           " commands lost from cycle " + std::to_string(from);
        EXPECT_EQ(s.status().latched_faults, 0U) << where;
        EXPECT_LT(residual * kDeg, 0.5) << where;
      }
    }
  }
  std::printf("stalled chain under a held stick: %d runs, peak trolley speed %.3f m/s (limit %.1f), peak slew rate "
              "%.3f rad/s (limit %.1f), worst swing 8 s after the release %.3f deg\n",
              runs, peak_trolley, config.supervisor.trolley_max_speed, peak_slew, config.supervisor.slew_max_rate,
              worst_residual * kDeg);
  EXPECT_LT(peak_trolley, config.supervisor.trolley_max_speed);
  EXPECT_LT(peak_slew, config.supervisor.slew_max_rate);
}

// The operator's input stops mid-jog (device unplugged, process killed): 200 ms later every axis
// is released and the load stops softly.
TEST(ManualMode, DeadManStopsSoftlyWhenTheInputStops) {
  stack::InProcessStack s(long_jib(lab()), {});
  const auto manual = set_mode(1, Status::OPERATION_MANUAL);
  std::optional<std::uint64_t> released;
  double residual = 0.0;
  std::optional<std::uint64_t> stopped;
  for (std::uint64_t k = 0; k < 2000; ++k) {
    const auto speed = stick(k, 0.6, 0.0);
    const bool input = k >= 400 && k < 600;  // the last sample at 599
    s.step({}, input ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(), k == 10 ? &manual : nullptr);
    // Released: the planner's speed target drops to 0.
    if (k >= 600 && !released && s.planner().speed_targets()[0] == 0.0) released = k;
    if (k > 600 && !stopped && !s.planner().under_speed_control()) stopped = k;
    if (stopped && k >= *stopped + 200) residual = std::max(residual, swing_of(s));
    if (stopped && k >= *stopped + 600) break;
  }
  ASSERT_TRUE(released.has_value());
  // Released at the first cycle more than 200 ms after the last sample.
  EXPECT_EQ(*released, 599U + 21U);
  ASSERT_TRUE(stopped.has_value());
  std::printf("dead man: input lost at cycle 600, axes released at %llu, residual swing %.3f deg\n",
              static_cast<unsigned long long>(*released), residual * kDeg);
  EXPECT_LT(residual * kDeg, 0.5);
}

TEST(OperatingModes, GoalsAndSpeedsFollowTheModeAndAChangeWhileMovingStopsFirst) {
  stack::InProcessStack s(long_jib(lab()), {});
  Request goal;
  goal.request_id = 1;
  goal.profile = Request::PROFILE_ZV;
  goal.axes = Request::AXIS_TROLLEY;
  goal.trolley_target = 1.0;
  const auto manual = set_mode(1, Status::OPERATION_MANUAL);
  const auto automatic = set_mode(2, Status::OPERATION_FULLAUTOMATIC);
  std::vector<Feedback> feedback;
  const auto nan_speed = stick(0, NAN, 0.0);
  const auto too_fast = stick(0, 1.5, 0.0);
  const auto speed = stick(0, 0.5, 0.0);
  for (std::uint64_t k = 0; k < 1500; ++k) {
    std::span<const Request> goals;
    std::span<const protocol::OperatorSpeed> speeds;
    const protocol::SupervisorCommand* command = nullptr;
    if (k == 50) speeds = std::span(&speed, 1);  // FULLAUTOMATIC: counted, not taken
    if (k == 60) command = &manual;
    if (k == 100) goals = std::span(&goal, 1);  // MANUAL: refused naming the mode
    if (k == 110) speeds = std::span(&nan_speed, 1);
    if (k == 111) speeds = std::span(&too_fast, 1);
    if (k >= 200 && k < 300) speeds = std::span(&speed, 1);  // moving in MANUAL
    if (k == 250) command = &automatic;                       // a mode change while moving: soft stop
    s.step(goals, speeds, command);
    for (const auto& f : s.planner().move_statuses()) feedback.push_back(f);
  }
  // One at cycle 50, and those after the change back to FULLAUTOMATIC (commanded at 250, applied by
  // the planner from 251 with the status of 250): 251..299.
  EXPECT_EQ(s.planner().speeds_outside_manual(), 1U + 49U);
  EXPECT_EQ(s.planner().rejected_speeds(), 2U);
  bool refused = false;
  for (const auto& f : feedback) {
    if (f.request_id == 1 && f.result == Feedback::RESULT_REJECTED) {
      refused = true;
      EXPECT_EQ(f.reason, Feedback::REASON_MODE);
      EXPECT_EQ(f.value, Status::OPERATION_MANUAL);
    }
  }
  EXPECT_TRUE(refused);
  EXPECT_EQ(s.status().operating_mode, Status::OPERATION_FULLAUTOMATIC);
  EXPECT_FALSE(s.planner().under_speed_control()) << "stopped and holding after the mode change";
  EXPECT_LT(swing_of(s) * kDeg, 0.5);
  EXPECT_EQ(s.status().latched_faults, 0U);
}

// MAINTENANCE (OPC 40020: reduced speeds, no anti-swing): every operator speed at
// manual.maintenance_speed_fraction of the rated speed, no sway control of the operator's speeds
// (ramp only: the reference stops as soon as its ramp ends, where MANUAL's shaper lets it run on for
// its length) and none in the feedback (the anti-swing stage's output is 0 from the supervisor's
// mode on): the load is left swinging by degrees where MANUAL stops it within 0.5 deg. Then, the load
// still swinging, the mode back to MANUAL at the worst moment (the law's action at its peak): the
// feedback fades in over a swing period (no step in the drive) and damps the swing.
TEST(OperatingModes, MaintenanceRunsAtTheReducedSpeedWithoutSwayControl) {
  const auto config = long_jib(lab());
  const auto& m = config.trajectory_planner.manual;
  struct Run {
    double top_speed{0.0};        // [m/s] the reference's largest trolley speed
    double stop_time{0.0};        // [s] from the release to the reference at rest
    double residual{0.0};         // [rad] swing 2 s after the reference stopped, for 4 s
    double largest_action{0.0};   // [-] the anti-swing command's largest action from cycle 20 on
    // Then MANUAL (MAINTENANCE's run only), the load swinging:
    double swing_at_switch{0.0};  // [rad] the swing's amplitude (its largest in the 2 s before)
    double law_step{0.0};         // [V] what the law's action adds to the trolley drive (3.37) at the switch:
                                  // the step an instant switch would make
    double fade_change{0.0};      // [V] the trolley drive's largest change in a cycle, the swing period after it
    double before_change{0.0};    // [V] the same in the swing period before it (tracking alone)
    double residual_after{0.0};   // [rad] swing from 2 s after the fade, for 4 s
  };
  const auto run = [&](std::uint8_t mode) {
    stack::InProcessStack s(config, {});
    // The law on the same estimates as the stack's stage, never switched: its action, ungated.
    anti_swing::AntiSwingStage law(config.anti_swing);
    protocol::AntiSwingCommand law_action;
    const auto command = set_mode(1, mode);
    const auto back_to_manual = set_mode(2, Status::OPERATION_MANUAL);
    const bool then_manual = mode == Status::OPERATION_MAINTENANCE;
    Run r;
    std::optional<std::uint64_t> stopped, switched;
    double previous_voltage = 0.0, peak_action = 0.0, swing_before = 0.0;
    bool switch_now = false;
    for (std::uint64_t k = 0; k < 5000; ++k) {
      const auto speed = stick(k, k >= 400 && k < 700 ? 1.0 : 0.0, 0.0);
      s.step({}, k >= 400 ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(),
             k == 10 ? &command : switch_now ? &back_to_manual : nullptr);
      EXPECT_NE(law.step(s.estimate(), law_action), common::StepStatus::rejected_nonfinite);
      const double voltage = s.linear().trolley_voltage;
      if (k >= 20 && !switched) r.largest_action = std::max(r.largest_action, std::abs(s.anti_swing().trolley_action));
      r.top_speed = std::max(r.top_speed, std::abs(s.reference().trolley_velocity));
      if (k >= 700 && !stopped) {
        if (!s.planner().under_speed_control()) {
          stopped = k;
          r.stop_time = static_cast<double>(k - 700) * 0.01;
        }
      }
      if (stopped && k >= *stopped + 200 && k < *stopped + 600) r.residual = std::max(r.residual, swing_of(s));
      if (switch_now) {
        // The status of cycle k reaches the anti-swing stage at k + 1.
        switched = k + 1;
        r.swing_at_switch = swing_before;
        switch_now = false;
      }
      // MANUAL at the law's peak, 6 s after the reference stopped (its peak over the 2 s before).
      if (then_manual && stopped && !switched && k >= *stopped + 400) {
        if (k < *stopped + 600) {
          peak_action = std::max(peak_action, std::abs(law_action.trolley_action));
          swing_before = std::max(swing_before, swing_of(s));
        } else {
          switch_now = std::abs(law_action.trolley_action) >= 0.95 * peak_action;
        }
      }
      if (switched && k == *switched) {
        const double cable = s.estimate().cable_length;
        const double period = 2.0 * std::numbers::pi * std::sqrt(cable / config.facts.crane.gravity);
        r.law_step = std::abs(cable / (period * period) * law_action.trolley_action /
                              config.tracking.tracking.trolley_drive_gain);
      }
      if (stopped && then_manual && !switched && k >= *stopped + 400) {
        r.before_change = std::max(r.before_change, std::abs(voltage - previous_voltage));
      }
      if (switched && k >= *switched && k < *switched + 201) {
        r.fade_change = std::max(r.fade_change, std::abs(voltage - previous_voltage));
      }
      if (switched && k >= *switched + 400) r.residual_after = std::max(r.residual_after, swing_of(s));
      previous_voltage = voltage;
      if (stopped && !then_manual && k >= *stopped + 600) break;
      if (switched && k >= *switched + 800) break;
    }
    EXPECT_EQ(s.status().operating_mode, then_manual ? Status::OPERATION_MANUAL : mode);
    EXPECT_EQ(s.status().latched_faults, 0U);
    EXPECT_TRUE(stopped.has_value());
    EXPECT_EQ(switched.has_value(), then_manual);
    return r;
  };
  const Run maintenance = run(Status::OPERATION_MAINTENANCE);
  const Run manual = run(Status::OPERATION_MANUAL);
  const double reduced = m.maintenance_speed_fraction * m.trolley.rated_speed;
  std::printf("full trolley stick 3 s, released: MAINTENANCE top speed %.4f m/s (%.0f %% of rated), reference at rest "
              "%.2f s after the release, residual swing %.3f deg (largest anti-swing action %.3g); MANUAL %.4f m/s, "
              "%.2f s, %.3f deg (largest anti-swing action %.3f)\n",
              maintenance.top_speed, 100.0 * maintenance.top_speed / m.trolley.rated_speed, maintenance.stop_time,
              maintenance.residual * kDeg, maintenance.largest_action, manual.top_speed, manual.stop_time,
              manual.residual * kDeg, manual.largest_action);
  std::printf("then MANUAL with %.3f deg of swing: the trolley drive's largest change in a cycle %.4f V over the fade's "
              "swing period (%.4f V in the 2 s before, the tracking alone; an instant switch: a step of %.4f V); "
              "residual swing 2 s after the fade %.3f deg\n",
              maintenance.swing_at_switch * kDeg, maintenance.fade_change, maintenance.before_change,
              maintenance.law_step, maintenance.residual_after * kDeg);
  EXPECT_NEAR(maintenance.top_speed, reduced, 1e-9);
  EXPECT_NEAR(manual.top_speed, m.trolley.rated_speed, 1e-9);
  // Ramp only: at rest one ramp (v / a) after the release, give or take the cycles of the
  // hand-over and the at-rest check; MANUAL's shaper adds its length (ZVD: a swing period, > 2 s).
  EXPECT_LT(maintenance.stop_time, reduced / m.trolley.acceleration + 0.1);
  EXPECT_GT(manual.stop_time, m.trolley.rated_speed / m.trolley.acceleration + 1.5);
  // No sway control at all in MAINTENANCE: the anti-swing action 0, the load left swinging by degrees.
  EXPECT_EQ(maintenance.largest_action, 0.0);
  EXPECT_GT(manual.largest_action, 0.0);
  EXPECT_GT(maintenance.residual * kDeg, 2.0);
  EXPECT_LT(manual.residual * kDeg, 0.5);
  // Back in MANUAL the feedback returns without a step and damps the swing.
  EXPECT_GT(maintenance.swing_at_switch * kDeg, 2.0);
  EXPECT_LT(maintenance.fade_change, 0.25 * maintenance.law_step);
  EXPECT_LT(maintenance.residual_after * kDeg, 0.5);
}

// SEMIAUTOMATIC: goals are taken, and the operator's stick takes over from a running goal (aborted:
// manual motion); released, the load stops without swing; a new goal is taken again at rest.
TEST(OperatingModes, SemiautomaticStickTakesOverFromAGoal) {
  stack::InProcessStack s(long_jib(lab()), {});
  const auto semi = set_mode(1, Status::OPERATION_SEMIAUTOMATIC);
  Request goal;
  goal.request_id = 1;
  goal.profile = Request::PROFILE_ZVD;
  goal.axes = Request::AXIS_TROLLEY;
  goal.trolley_target = 2.0;
  Request second = goal;
  second.request_id = 2;
  second.trolley_target = 0.5;
  bool moving = false, taken_over = false, second_arrived = false;
  std::optional<std::uint64_t> stopped;
  double at_takeover = 0.0, residual = 0.0, furthest = 0.0;
  for (std::uint64_t k = 0; k < 5000; ++k) {
    std::span<const Request> goals;
    if (k == 100) goals = std::span(&goal, 1);
    if (stopped && k == *stopped + 600) goals = std::span(&second, 1);
    // The stick, pulled back at 50 % from cycle 200 (1 s into the goal) to 300, then neutral.
    const auto speed = stick(k, k >= 200 && k < 300 ? -0.5 : 0.0, 0.0);
    s.step(goals, k >= 150 ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(), k == 10 ? &semi : nullptr);
    for (const auto& f : s.planner().move_statuses()) {
      if (f.request_id == 1 && f.result == Feedback::RESULT_MOVING) moving = true;
      if (f.request_id == 1 && f.result == Feedback::RESULT_ABORTED) {
        taken_over = f.reason == Feedback::REASON_MANUAL_MOTION;
        at_takeover = s.sensors().trolley_position;
      }
      if (f.request_id == 2 && f.result == Feedback::RESULT_ARRIVED) second_arrived = true;
    }
    furthest = std::max(furthest, s.sensors().trolley_position);
    if (k > 300 && !stopped && !s.planner().under_speed_control()) stopped = k;
    if (stopped && k >= *stopped + 200 && k < *stopped + 600) residual = std::max(residual, swing_of(s));
    if (second_arrived) break;
  }
  std::printf("SEMIAUTOMATIC: goal to 2.0 m taken over by the stick at %.3f m (furthest %.3f m), stopped without swing "
              "(%.3f deg 2 s after), a second goal then %s\n",
              at_takeover, furthest, residual * kDeg, second_arrived ? "arrived" : "did not arrive");
  EXPECT_TRUE(moving) << "the goal was taken in SEMIAUTOMATIC";
  EXPECT_TRUE(taken_over) << "the stick takes over: the goal is aborted, reason manual motion";
  EXPECT_LT(furthest, 1.9) << "the goal did not run on to its target";
  ASSERT_TRUE(stopped.has_value());
  EXPECT_LT(residual * kDeg, 0.5);
  EXPECT_TRUE(second_arrived);
  EXPECT_EQ(s.status().latched_faults, 0U);
}

// --- No-go zones -----------------------------------------------------------------------------

std::size_t count_from_env(const char* name, std::size_t fallback) {
  const char* v = std::getenv(name);
  return v != nullptr ? static_cast<std::size_t>(std::strtoul(v, nullptr, 10)) : fallback;
}

// The lab crane (jib at 2.5 m) with three zones: a tall building, a low wall the load can be
// hoisted over, and a non-convex (L-shaped) yard.
stack::StackConfig with_zones() {
  auto c = lab();
  common::Site site;
  site.jib_height = 2.5;
  site.zone_clearance = 0.05;
  site.zones = {
      {"building", {{0.5, 0.3}, {0.8, 0.3}, {0.8, 0.6}, {0.5, 0.6}}, 0.0, 10.0, true},
      {"low wall", {{-0.2, -1.0}, {0.2, -1.0}, {0.2, -0.6}, {-0.2, -0.6}}, 0.0, 0.8, true},
      {"yard", {{-0.7, 0.5}, {-0.4, 0.5}, {-0.4, 0.7}, {-0.55, 0.7}, {-0.55, 1.0}, {-0.7, 1.0}}, 0.0, 10.0, true},
  };
  common::validate(site);
  c.facts.site = site;
  c.trajectory_planner.site = site;
  c.supervisor.site = site;
  return c;
}

std::string fault_name_list(std::uint32_t faults) {
  std::string names;
  for (int bit = 0; bit < 32; ++bit) {
    if ((faults & (1U << bit)) == 0) continue;
    if (!names.empty()) names += ",";
    names += protocol::code_name(Status::kCodes, "FAULT", 1U << bit);
  }
  return names;
}

// The load (the plant's own state, swing included) inside an enabled zone.
int load_zone(const stack::InProcessStack& s, const common::Site& site, std::uint32_t enabled) {
  const auto& p = s.plant().simulator().state();
  const auto load = common::load_position(site, p.trolley_position, p.slew_angle, p.swing_in_plane,
                                          p.swing_out_of_plane, p.cable_length);
  return common::intruded_zone(site, enabled, {load[0], load[1]}, load[2], 0.0);
}

TEST(Zones, SeededRandomGoalsNeverPutTheLoadInAZoneAndEveryReachableGoalIsReached) {
  const auto config = with_zones();
  const auto& site = config.facts.site;
  const std::size_t goals = count_from_env("CRANE_ZONE_GOALS", 1000);
  std::mt19937 rng(2026);
  // Targets from 0.3 m out: a stop at the trolley's minimum (0.2 m) with a long cable overshoots
  // into the supervisor's travel stop (up to 12 cm at L = 1.4 m; a tracking limit of its own,
  // docs/operation.md), not a zone matter.
  std::uniform_real_distribution<double> radius(0.3, 1.1), slew(-2.9, 2.9), cable(0.5, 1.9);
  stack::InProcessOptions options;
  options.initial_trolley_position = 0.3;
  stack::InProcessStack s(config, options);
  std::size_t inside_samples = 0, refused_in_zone = 0, refused_otherwise = 0, reached = 0, accepted = 0;
  std::size_t no_route = 0;  // refused with the target outside every zone: no route of the planner's set
  double worst_error = 0.0, settle_worst = 0.0, slowest_cycle = 0.0;
  std::uint64_t k = 0;
  for (; k < 300; ++k) s.step();
  for (std::uint32_t id = 1; id <= goals; ++id) {
    Request goal;
    goal.request_id = id;
    // Input-shaped profiles (the delayed-feedback law with the time-optimal profile overshoots the
    // trolley past its overspeed limit on some long moves: a controller matter, docs/operation.md).
    goal.profile = (id % 2 == 0) ? Request::PROFILE_ZVD : Request::PROFILE_ZV;
    goal.axes = Request::AXIS_TROLLEY | Request::AXIS_SLEW | Request::AXIS_HOIST;
    goal.trolley_target = radius(rng);
    goal.slew_target = slew(rng);
    goal.cable_length_target = cable(rng);
    // Half the rated slew rate: at (3.55)'s 1.04 rad/s and the jib's full reach the load's
    // centrifugal pull moves the trolley up to 20 cm off its reference, into the supervisor's
    // travel stop (a tracking limit of its own, docs/operation.md; not a zone matter).
    goal.slew_max_velocity = 0.5;
    goal.slew_max_acceleration = 1.0;
    bool done = false, ok = false, counted = false;
    std::optional<std::uint64_t> arrived;
    const std::uint64_t started = k;
    for (; !done && k < started + 20000; ++k) {
      const auto before = std::chrono::steady_clock::now();
      s.step(k == started ? std::span(&goal, 1) : std::span<const Request>());
      if (k == started) {
        // The cycle that plans the goal among the zones (the whole stack's cycle, plant included).
        slowest_cycle = std::max(slowest_cycle, std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count());
      }
      if (load_zone(s, site, s.status().zones_enabled) >= 0) ++inside_samples;
      for (const auto& f : s.planner().move_statuses()) {
        if (f.request_id != id) continue;
        if (f.result == Feedback::RESULT_REJECTED) {
          done = true;
          if (f.reason == Feedback::REASON_ZONE) {
            ++refused_in_zone;
            // Refused only when the target is in a zone, with the clearance and the swing allowance
            // of the slowest approach (1/25 of the goal's accelerations, zone_paths.hpp).
            auto wider = site;
            wider.zone_clearance += trajectory_planner::swing_allowance(
                goal.cable_length_target, 0.04 * std::hypot(0.9929, 1.1 * goal.slew_max_acceleration), 1e9, 9.8);
            common::MotionReference target;
            target.trolley.position = goal.trolley_target;
            target.slew.position = goal.slew_target;
            target.cable_length.position = goal.cable_length_target;
            if (trajectory_planner::intruded_zone(wider, 7, target, 9.8) < 0) {
              ++no_route;
              std::printf("no route: goal %u to (%.3f m, %.3f rad, %.3f m) from (%.3f m, %.3f rad, %.3f m), zone %g\n",
                          id, goal.trolley_target, goal.slew_target, goal.cable_length_target,
                          s.sensors().trolley_position, s.sensors().slew_angle, s.sensors().cable_length, f.value);
            }
          } else {
            ++refused_otherwise;
            ADD_FAILURE() << "goal " << id << " refused, reason " << int(f.reason);
          }
        }
        if (f.result == Feedback::RESULT_ABORTED) {
          done = true;
          ADD_FAILURE() << "goal " << id << " aborted, reason " << int(f.reason);
        }
        if ((f.result == Feedback::RESULT_MOVING || f.result == Feedback::RESULT_ARRIVED) && !counted) {
          ++accepted;
          counted = true;
        }
        if (f.result == Feedback::RESULT_ARRIVED) arrived = k;
      }
      // Reached: the trolley's point within 1 cm of the target (the slew's error as an arc) and the
      // cable within 1 cm, within 10 s of the reference's arrival.
      if (arrived) {
        const auto& m = s.next_sensors();
        const double error = std::max({std::abs(m.trolley_position - goal.trolley_target),
                                        std::abs(m.slew_angle - goal.slew_target) * m.trolley_position,
                                        std::abs(m.cable_length - goal.cable_length_target)});
        if (error < 0.01 || k >= *arrived + 1000) {
          worst_error = std::max(worst_error, error);
          settle_worst = std::max(settle_worst, static_cast<double>(k - *arrived) * 0.01);
          ok = error < 0.01;
          done = true;
        }
      }
    }
    if (ok) ++reached;
    // A stopped move (zone approach) comes to rest before the next goal.
    for (int c = 0; c < 1000 && s.planner().under_speed_control(); ++c, ++k) s.step();
    ASSERT_TRUE(done) << "goal " << id << " neither refused nor arrived";
    ASSERT_EQ(s.status().latched_faults, 0U)
        << "goal " << id << " to (" << goal.trolley_target << " m, " << goal.slew_target << " rad, "
        << goal.cable_length_target << " m): fault at x = " << s.sensors().trolley_position
        << " m, slew = " << s.sensors().slew_angle << " rad, L = " << s.sensors().cable_length;
  }
  std::printf("%zu seeded random goals among 3 zones: %zu accepted, %zu reached (within 1 cm, at most %.1f s after the "
              "reference arrived; worst final error %.1f mm), %zu refused naming a zone (%zu of them with the target outside "
              "every zone: no route of the planner's set), %zu otherwise; %zu samples with the load in a zone (%.0f s "
              "simulated); the slowest cycle that planned a goal: %.1f ms (a figure, on this machine)\n",
              goals, accepted, reached, settle_worst, 1e3 * worst_error, refused_in_zone, no_route, refused_otherwise,
              inside_samples, static_cast<double>(k) * 0.01, 1e3 * slowest_cycle);
  EXPECT_EQ(inside_samples, 0U);
  // Every reachable goal is reached: refused only with the target in a zone (with the clearance and
  // the slowest approach's swing allowance), every other one accepted and reached.
  EXPECT_EQ(no_route, 0U);
  EXPECT_EQ(reached, goals - refused_in_zone);
  EXPECT_GT(refused_in_zone, 0U);  // the zones do cover some targets
}

TEST(Zones, SeededRandomManualSessionsNeverPutTheLoadInAZone) {
  const auto config = with_zones();
  const auto& site = config.facts.site;
  const std::size_t sessions = count_from_env("CRANE_ZONE_SESSIONS", 100);
  std::mt19937 rng(1903);
  std::uniform_real_distribution<double> axis(-1.0, 1.0);
  std::uniform_int_distribution<int> hold(50, 200), coin(0, 3);
  stack::InProcessOptions options;
  options.initial_trolley_position = 0.3;
  stack::InProcessStack s(config, options);
  const auto manual = set_mode(1, Status::OPERATION_MANUAL);
  std::size_t inside_samples = 0, held_cycles = 0;
  std::uint64_t k = 0;
  double max_swing = 0.0;
  for (; k < 100; ++k) s.step({}, {}, k == 10 ? &manual : nullptr);
  for (std::size_t session = 0; session < sessions; ++session) {
    // A session: 5 stick positions held 0.5-2 s each (a quarter of them neutral), then released.
    for (int segment = 0; segment < 6; ++segment) {
      const bool neutral = segment == 5 || coin(rng) == 0;
      const auto speed = stick(0, neutral ? 0.0 : axis(rng), neutral ? 0.0 : axis(rng),
                               neutral ? 0.0 : 0.5 * axis(rng), coin(rng) == 1);
      const int cycles = segment == 5 ? 400 : hold(rng);
      for (int c = 0; c < cycles; ++c, ++k) {
        auto sample = speed;
        sample.header.seq = k;
        s.step({}, std::span(&sample, 1));
        if (load_zone(s, site, s.status().zones_enabled) >= 0) ++inside_samples;
        if (s.planner().held_axes() != 0) ++held_cycles;
        max_swing = std::max(max_swing, swing_of(s));
      }
    }
    ASSERT_EQ(s.status().latched_faults, 0U) << "session " << session;
  }
  std::printf("%zu seeded random manual sessions among 3 zones: %zu samples with the load in a zone, %zu cycles with "
              "an axis held back by a zone or the travel, max swing %.1f deg (%.0f s simulated)\n",
              sessions, inside_samples, held_cycles, max_swing * kDeg, static_cast<double>(k) * 0.01);
  EXPECT_EQ(inside_samples, 0U);
  EXPECT_GT(held_cycles, 0U);         // the sessions did run into the bounds
  EXPECT_GT(max_swing * kDeg, 1.0);   // and did move the crane
}


// The supervisor enforces the zones on its own, from the measured state: the planner's zone guard
// bypassed (its site has no zones; the supervisor's has), a full stick drives the load straight at
// the building for 12 s (radially with the trolley, or around with the slew), in MANUAL and in
// MAINTENANCE (no sway control), and a goal runs straight through it in FULLAUTOMATIC (a printed
// figure: there the supervisor relies on the planner's paths). The
// supervisor's warning zone_approach makes the planner stop softly (its only zone reaction left);
// where that stop overshoots the prediction (a stop begun while the shaped speed still rises) the
// drives' voltage limit and then the brakes (a protective stop) follow, before the load enters.
// Then the stick back in neutral and, after a protective stop, a reset (the operator's way out).
// Every sample: the load (the plant's own state, swing included) outside the zone; at the end the
// crane at rest, the swing below 0.5 deg.
TEST(Zones, TheSupervisorAloneKeepsTheLoadOutWhenThePlannerGuardIsBypassed) {
  auto config = with_zones();
  const auto site = config.facts.site;
  config.trajectory_planner.site.zones.clear();  // the planner's guard bypassed
  const double bearing = std::atan2(0.45, 0.65);  // the building's middle seen from the slew axis
  struct Case {
    const char* name;
    std::uint8_t mode;
    int axis;  // 0 trolley stick, 1 slew stick, 2 a goal through the building
  };
  const Case cases[] = {{"MANUAL, trolley stick", Status::OPERATION_MANUAL, 0},
                        {"MANUAL, slew stick", Status::OPERATION_MANUAL, 1},
                        {"MAINTENANCE, trolley stick", Status::OPERATION_MAINTENANCE, 0},
                        {"MAINTENANCE, slew stick", Status::OPERATION_MAINTENANCE, 1},
                        {"FULLAUTOMATIC, goal through it", Status::OPERATION_FULLAUTOMATIC, 2}};
  for (const auto& c : cases) {
    stack::InProcessOptions options;
    options.initial_trolley_position = c.axis == 1 ? 0.7 : 0.25;
    options.initial_slew_angle = c.axis == 1 ? -0.6 : bearing;
    stack::InProcessStack s(config, options);
    const auto mode = set_mode(1, c.mode);
    protocol::SupervisorCommand reset;
    reset.request_id = 2;
    reset.command = protocol::SupervisorCommand::COMMAND_RESET;
    Request goal;
    goal.request_id = 1;
    goal.profile = Request::PROFILE_ZV;
    goal.axes = Request::AXIS_TROLLEY;
    goal.trolley_target = 1.1;
    std::size_t inside = 0, warned = 0, limited = 0;
    double closest = 1e9, moved = 0.0;
    std::uint32_t faults = 0;
    std::int64_t quiet = -1;  // the cycle the crane came to rest (-1: not at rest)
    double swing_left = 0.0;  // [rad] the largest swing in the 2 s at rest
    // [rad] MAINTENANCE: the swing's largest angle (both planes together) in the first and the last
    // 10 s at rest: no damping, a figure.
    double swing_first = 0.0, swing_last = 0.0;
    bool zone_abort = false;
    std::optional<std::uint64_t> reset_cycle;
    int resets = 0;
    for (std::uint64_t k = 0; k < 9000; ++k) {
      // The stick pushed at the zone for 12 s, then neutral; after a protective stop (from 16 s, at
      // most once a second), a reset and the stick pulled back at 30 % for 2 s (the operator's way
      // out: the anti-swing law moving the crane toward the zone with the load swinging beside it
      // may stop it again), then neutral.
      const double push = c.axis < 2 && k >= 300 && k < 1500 ? 1.0
                          : reset_cycle && k >= *reset_cycle + 20 && k < *reset_cycle + 220 ? -0.3 : 0.0;
      const auto speed = stick(k, c.axis == 0 ? push : 0.0, c.axis == 1 ? push : 0.0);
      const protocol::SupervisorCommand* command = k == 10 && c.axis < 2 ? &mode : nullptr;
      if (k >= 1600 && (!reset_cycle || k >= *reset_cycle + 100) && s.status().latched_faults != 0 &&
          s.status().active_faults == 0) {
        reset.request_id = static_cast<std::uint32_t>(k);
        command = &reset;
        reset_cycle = k;
        ++resets;
      }
      s.step(c.axis == 2 && k == 300 ? std::span(&goal, 1) : std::span<const Request>(),
             k >= 300 ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(), command);
      const auto& p = s.plant().simulator().state();
      const auto load = common::load_position(site, p.trolley_position, p.slew_angle, p.swing_in_plane,
                                              p.swing_out_of_plane, p.cable_length);
      if (load_zone(s, site, s.status().zones_enabled) >= 0) ++inside;
      closest = std::min(closest, common::signed_distance(site.zones[0], {load[0], load[1]}));
      moved = std::max(moved, std::abs(c.axis == 1 ? p.slew_angle - options.initial_slew_angle
                                                   : p.trolley_position - options.initial_trolley_position));
      if (s.status().warnings & Status::WARNING_ZONE_APPROACH) ++warned;
      if (s.status().motion_enabled && s.status().trolley_voltage_limit < config.supervisor.voltage_limit) ++limited;
      faults |= s.status().latched_faults;
      for (const auto& f : s.planner().move_statuses()) {
        if (f.request_id == 1 && f.result == Feedback::RESULT_ABORTED && f.reason == Feedback::REASON_ZONE) zone_abort = true;
      }
      // At rest, after the push, for 2 s with the brakes released: trolley and slew still and the
      // swing below 0.5 deg. MAINTENANCE has no sway control (no anti-swing): the load keeps the
      // swing the stop left (a figure) and its pull moves the drives about their reference, so
      // there the reference at rest.
      const bool still =
          s.status().brakes_released &&
          (c.mode == Status::OPERATION_MAINTENANCE
               ? !s.planner().under_speed_control() && s.reference().trolley_velocity == 0.0 &&
                     s.reference().slew_rate == 0.0
               : std::abs(p.trolley_velocity) < 1e-3 && std::abs(p.slew_rate) < 1e-3 && swing_of(s) * kDeg < 0.5);
      if (!still) quiet = -1;
      if (k >= 1500 && (!reset_cycle || k >= *reset_cycle + 220) && still && quiet < 0) {
        quiet = static_cast<std::int64_t>(k);
        swing_left = 0.0;
      }
      if (quiet >= 0) swing_left = std::max(swing_left, swing_of(s));
      const double swing_angle = std::hypot(p.swing_in_plane, p.swing_out_of_plane);
      if (quiet >= 0 && static_cast<std::int64_t>(k) < quiet + 1000) swing_first = std::max(swing_first, swing_angle);
      if (k >= 8000) swing_last = std::max(swing_last, swing_angle);
      // MAINTENANCE runs on to 90 s: the load swinging freely beside the building all that time.
      if (quiet >= 0 && static_cast<std::int64_t>(k) >= quiet + 200 && c.mode != Status::OPERATION_MAINTENANCE) break;
    }
    std::printf("supervisor alone, %s: moved %.3f %s toward the building, the load's closest approach %.3f m, %zu cycles "
                "warned, %zu with the drives limited, protective stop: %s (%d resets, pulled back), at rest at %.1f s "
                "(swing %.2f deg from then to the end); %zu samples inside\n",
                c.name, moved, c.axis == 1 ? "rad" : "m", closest, warned, limited,
                faults != 0 ? fault_name_list(faults).c_str() : "none", resets,
                static_cast<double>(quiet) * 0.01, swing_left * kDeg, inside);
    if (c.mode == Status::OPERATION_MAINTENANCE) {
      std::printf("  no sway control: the swing's largest angle %.2f deg in the first 10 s at rest, %.2f deg in the "
                  "last 10 s (80-90 s)\n", swing_first * kDeg, swing_last * kDeg);
    }
    // In FULLAUTOMATIC the supervisor relies on the planner's paths (supervisor.hpp, zone_guard()):
    // a goal planned through the zone is a figure here, not a bound.
    if (c.axis < 2) {
      EXPECT_EQ(inside, 0U) << c.name;
      EXPECT_GT(closest, 0.0) << c.name;
    }
    // Under operator speeds the warning (the planner's soft stop) comes first; in FULLAUTOMATIC the
    // supervisor predicts the ramp only (supervisor.hpp, SoftStop::planned): its drive limit or brakes.
    EXPECT_TRUE(warned > 0 || (c.axis == 2 && (limited > 0 || faults != 0))) << c.name << ": the supervisor saw it";
    EXPECT_GT(moved, c.axis == 1 ? 0.3 : 0.15) << c.name << ": the crane did drive at the zone";
    EXPECT_TRUE(faults == 0 || faults == Status::FAULT_ZONE) << c.name << ": " << fault_name_list(faults);
    EXPECT_GE(quiet, 0) << c.name << ": the load comes to rest";
    if (c.axis == 2) {
      EXPECT_TRUE(zone_abort || faults != 0) << "the goal is aborted (the zone, or the protective stop)";
    }
  }
}
}  // namespace

namespace {

// The overhead crane's bridge under operator speed control (OperatorSpeed_.bridge): a full bridge
// stick for 3 s, released; the load stops without swing where the planner published it would
// (the bridge's speed reference is the trolley's, on the bridge's rated motion). Then a goal's
// bridge move stopped half-way (COMMAND_STOP) rests without swing where predicted.
TEST(OverheadCrane, BridgeStickAndSoftStopStopWithoutSwingWherePredicted) {
  const auto config = stack::load_stack_config(CRANE_SOURCE_DIR "/deploy/config/overhead_crane.yaml");
  stack::InProcessOptions options;
  options.initial_trolley_position = 5.0;
  options.initial_bridge_position = 10.0;
  {
    stack::InProcessStack s(config, options);
    const auto manual = set_mode(1, Status::OPERATION_MANUAL);
    std::optional<double> rest;
    double at_release = 0.0, residual = 0.0, max_swing = 0.0;
    std::optional<std::uint64_t> stopped;
    for (std::uint64_t k = 0; k < 6000; ++k) {
      auto speed = stick(k, 0.0, 0.0);
      speed.bridge = k >= 400 && k < 700 ? 1.0 : 0.0;
      s.step({}, k >= 400 ? std::span(&speed, 1) : std::span<const protocol::OperatorSpeed>(), k == 10 ? &manual : nullptr);
      if (k == 700) at_release = s.sensors().bridge_position;
      for (const auto& f : s.planner().move_statuses()) {
        if (k == 700 && f.result == Feedback::RESULT_MANUAL) rest = f.rest_bridge_position;
      }
      max_swing = std::max(max_swing, swing_of(s));
      if (k > 700 && !stopped && !s.planner().under_speed_control()) stopped = k;
      if (stopped && k >= *stopped + 200) residual = std::max(residual, swing_of(s));
      if (stopped && k >= *stopped + 600) break;
    }
    ASSERT_TRUE(stopped.has_value());
    ASSERT_TRUE(rest.has_value()) << "no stopping position published at the release";
    const double predicted = *rest - at_release;
    const double measured = s.next_sensors().bridge_position - at_release;
    std::printf("overhead bridge: full stick 3 s, released: residual swing 2 s after the stop %.3f deg (max %.2f deg on "
                "the way); stopping distance published %.4f m, measured %.4f m (%.2f %%)\n",
                residual * kDeg, max_swing * kDeg, predicted, measured, 100.0 * std::abs(measured - predicted) / predicted);
    EXPECT_EQ(s.status().latched_faults, 0U);
    EXPECT_GT(s.next_sensors().bridge_position, 10.5) << "the bridge moved";
    EXPECT_LT(residual * kDeg, 0.5);
    EXPECT_NEAR(measured, predicted, 0.05 * std::abs(predicted));
  }
  {
    stack::InProcessStack s(config, options);
    Request goal;
    goal.request_id = 1;
    goal.profile = Request::PROFILE_TRAPEZOID;
    goal.axes = Request::AXIS_BRIDGE;
    goal.bridge_target = 40.0;
    Request stop;
    stop.request_id = 2;
    stop.command = Request::COMMAND_STOP;
    std::optional<double> predicted;
    double at_stop = 0.0, residual = 0.0;
    std::optional<std::uint64_t> rest_cycle;
    for (std::uint64_t k = 0; k < 8000; ++k) {
      const std::span<const Request> goals = k == 300 ? std::span(&goal, 1) : k == 1800 ? std::span(&stop, 1)
                                                                                        : std::span<const Request>();
      s.step(goals);
      if (k == 1800) at_stop = s.sensors().bridge_position;
      for (const auto& f : s.planner().move_statuses()) {
        if (f.request_id == 2 && f.result == Feedback::RESULT_STOPPING) predicted = f.rest_bridge_position;
        if (f.request_id == 2 && f.result == Feedback::RESULT_ARRIVED && !rest_cycle) rest_cycle = k;
      }
      if (rest_cycle && k >= *rest_cycle + 200) residual = std::max(residual, swing_of(s));
      if (rest_cycle && k >= *rest_cycle + 800) break;
    }
    ASSERT_TRUE(predicted.has_value());
    ASSERT_TRUE(rest_cycle.has_value());
    const double final_position = s.next_sensors().bridge_position;
    std::printf("overhead bridge soft stop at %.3f m: predicted rest %.3f m, measured %.3f m (%.2f %% of the stopping "
                "distance), residual swing %.3f deg\n",
                at_stop, *predicted, final_position,
                100.0 * std::abs(final_position - *predicted) / std::abs(*predicted - at_stop), residual * kDeg);
    EXPECT_EQ(s.status().latched_faults, 0U);
    EXPECT_LT(final_position, 39.0) << "stopped short of the goal";
    EXPECT_NEAR(final_position - at_stop, *predicted - at_stop, 0.05 * std::abs(*predicted - at_stop));
    EXPECT_LT(residual * kDeg, 0.5);
  }
}

namespace {

// One move hook up: from trolley 0.9 m, slew -1.2 rad at rest, the hook to `cable_length` [m]
// (request 1), then trolley and slew to their targets [m, rad] at 0.7 rad/s (request 2), 35 s in
// all on the plant of `friction` times the configured friction. After the arrival of request 2:
struct HookUpMove {
  bool arrived;
  double swinging_s;  // [s] the last cycle with more than 0.5 deg of swing (99: not arrived)
  double off_s;       // [s] the last cycle more than 5 mm or 5 mrad off the target (99: never arrived)
  std::uint32_t faults;
  double friction_factor;  // handed with the last command (0: unset)
};
HookUpMove hook_up_move(const stack::StackConfig& config, double cable_length, double slew_to, double trolley_to,
                        double friction = 1.0) {
  stack::InProcessOptions options;
  options.initial_trolley_position = 0.9;
  options.initial_slew_angle = -1.2;
  options.mismatch.friction_factor = friction;
  stack::InProcessStack s(config, options);
  Request up;
  up.request_id = 1;
  up.profile = Request::PROFILE_TRAPEZOID;
  up.axes = Request::AXIS_HOIST;
  up.cable_length_target = cable_length;
  Request goal = up;
  goal.request_id = 2;
  goal.axes = Request::AXIS_TROLLEY | Request::AXIS_SLEW | Request::AXIS_HOIST;
  goal.trolley_target = trolley_to;
  goal.slew_target = slew_to;
  goal.slew_max_velocity = 0.7;
  std::optional<std::uint64_t> arrived;
  std::uint64_t swinging = 0;
  std::uint64_t off = 0;
  for (std::uint64_t k = 0; k < 3500; ++k) {
    const Request* g = k == 100 ? &up : k == 1000 ? &goal : nullptr;
    s.step(g != nullptr ? std::span(g, 1) : std::span<const Request>());
    for (const auto& f : s.planner().move_statuses()) {
      if (f.request_id == 2 && f.result == Feedback::RESULT_ARRIVED && !arrived) arrived = k;
    }
    if (k > 1000 && swing_of(s) * kDeg > 0.5) swinging = k;
    if (k > 1000 && (std::abs(s.estimate().trolley_position - trolley_to) > 0.005 ||
                     std::abs(s.estimate().slew_angle - slew_to) > 0.005)) {
      off = k;
    }
  }
  if (!arrived) return HookUpMove{false, 99.0, 99.0, s.status().latched_faults, s.linear().friction_factor};
  const auto after = [&](std::uint64_t k) { return (static_cast<double>(k) - static_cast<double>(*arrived)) * 0.01; };
  return HookUpMove{true, after(swinging), after(off), s.status().latched_faults, s.linear().friction_factor};
}

}  // namespace

}  // namespace
// The site's cranes travel hook up, at the lab crane's shortest cable (0.2 m). There, with the
// dissertation's K_del = -90 on the slew, the slew and its load limit-cycled after every slew (about
// 2 deg, beating, for 20 s and more): in the simulated site 3-4 travel moves per crane and set waited
// out the link's 8 s settle timeout. The chain's fixed lags (the slew drive, the estimator's filter, a
// cycle of latency) are a larger part of a 0.9 s swing period than of the 2 s one at 1 m the gain was
// tuned at. The short-cable gain (anti_swing.short_cable: -65 at and below 0.25 m, -90 from 0.4 m)
// settles the load within 3 s of the reference's arrival at every length, as the site
// link asks (slew at 0.7 rad/s), each of three slews with the trolley coming in to 0.25-0.9 m;
// without it the shortest cable still swings more than 0.5 deg 10 s after the arrival. Near the
// mast the slew moves more for the same sideways action ((3.38) divides by the radius): with -75
// (session 9's gain, tuned with the trolley at 0.6 m) a slew ending at 0.25-0.36 m still
// limit-cycled at 0.2 m (session 43: in the simulated site about one travel move in four per crane
// and set waited out the link's 8 s settle timeout there).
TEST(ShortCable, TheLoadSettlesHookUpAfterASlew) {
  const auto config = lab();
  ASSERT_TRUE(config.anti_swing.anti_swing.short_cable.enabled) << "the shipped config schedules the gain";
  double longest = 0.0;
  for (const double trolley_to : {0.25, 0.3, 0.36, 0.45, 0.6, 0.9}) {
    for (const double cable_length : {0.2, 0.25, 0.3, 0.4}) {
      for (const double slew_to : {1.3, 0.3, -0.9}) {
        const HookUpMove r = hook_up_move(config, cable_length, slew_to, trolley_to);
        std::printf("hook up at L = %.2f m, slew -1.2 -> %.1f rad, trolley 0.9 -> %.2f m: swing under 0.5 deg from %.2f s "
                    "after the arrival\n",
                    cable_length, slew_to, trolley_to, r.swinging_s);
        EXPECT_TRUE(r.arrived) << "L = " << cable_length << ", slew to " << slew_to << ", trolley to " << trolley_to;
        EXPECT_LT(r.swinging_s, 3.0) << "L = " << cable_length << ", slew to " << slew_to << ", trolley to " << trolley_to;
        EXPECT_EQ(r.faults, 0U) << "L = " << cable_length << ", slew to " << slew_to << ", trolley to " << trolley_to;
        longest = std::max(longest, r.swinging_s);
      }
    }
  }
  auto unscheduled = config;
  unscheduled.anti_swing.anti_swing.short_cable.enabled = false;
  double longest_unscheduled = 0.0;
  for (const double slew_to : {1.3, 0.3, -0.9}) {
    longest_unscheduled = std::max(longest_unscheduled, hook_up_move(unscheduled, 0.2, slew_to, 0.6).swinging_s);
  }
  auto session9 = config;
  session9.anti_swing.anti_swing.short_cable.gain = -75.0;
  double longest_session9 = 0.0;
  for (const double slew_to : {1.3, 0.3, -0.9}) {
    longest_session9 = std::max(longest_session9, hook_up_move(session9, 0.2, slew_to, 0.3).swinging_s);
  }
  std::printf("settled within %.2f s of the arrival with the short-cable gain; at 0.2 m without it still over 0.5 deg "
              "%.2f s after; with -75 at 0.3 m from the mast %.2f s after\n",
              longest, longest_unscheduled, longest_session9);
  EXPECT_GT(longest_unscheduled, 10.0) << "without the schedule the shortest cable limit-cycles (the cause)";
  EXPECT_GT(longest_session9, 10.0) << "near the mast -75 limit-cycles (why the gain is lower)";
}

// The PD law's friction factor (tracking.estimate_friction_factor, tracking_stage.hpp; on in the
// shipped configuration) on plants whose friction is off the configuration by -30 % to +30 %:
// delay1 with the compensation (3.5) of the configured friction limit-cycles where the plant has
// less (the compensation pushes the drive on at rest) and leaves the drive stuck with the swing
// undamped where it has more, hook up (0.2 m) and at 1 m alike. With the factor the law estimates
// along the move (the momentum balance, friction_momentum_balance.hpp), every move of the grid
// settles, the nominal plant's too, and ends with the plant's factor to within 0.05; without it
// most do not (the cause). The short slew alone slides too briefly to know the factor, and is run
// on the nominal plant only (docs/optimal_control.md, "The friction factor under delay1").
TEST(FrictionOffTheModel, Delay1SettlesWithTheFrictionFactorItEstimatesAlongTheMove) {
  const auto estimated = lab();
  ASSERT_TRUE(estimated.tracking.estimate_friction_factor) << "on in the shipped configuration";
  auto configured = estimated;
  configured.tracking.estimate_friction_factor = false;  // the dissertation's (3.5)
  int unsettled_without = 0;
  int moves = 0;
  for (const double friction : {0.7, 0.9, 1.0, 1.1, 1.3}) {
    for (const double cable_length : {0.2, 1.0}) {
      for (const double trolley_to : {0.3, 0.6, 0.9}) {
        for (const double slew_to : {1.3, 0.3, -0.9}) {
          // The short slew alone (0.3 rad, the trolley still) on the nominal plant only: it slides
          // for less than the three blocks of 0.5 s the estimate needs, so a plant off the model
          // keeps the model's factor there (on a crane the last move's carries; session 44's rows
          // handed 1.07 on the nominal plant here, which limit-cycled the hold).
          if (slew_to == -0.9 && trolley_to == 0.9 && friction != 1.0) continue;
          const HookUpMove with = hook_up_move(estimated, cable_length, slew_to, trolley_to, friction);
          const HookUpMove without = hook_up_move(configured, cable_length, slew_to, trolley_to, friction);
          std::printf("friction x%.1f, L = %.1f m, slew -1.2 -> %.1f rad, trolley 0.9 -> %.1f m: settled %.2f s (swing) "
                      "and %.2f s (position) after the arrival with the factor %.3f; without it %.2f and %.2f s, faults "
                      "0x%x\n",
                      friction, cable_length, slew_to, trolley_to, with.swinging_s, with.off_s, with.friction_factor,
                      without.swinging_s, without.off_s, without.faults);
          const std::string where = "friction x" + std::to_string(friction) + ", L " + std::to_string(cable_length) +
                                    ", slew to " + std::to_string(slew_to) + ", trolley to " + std::to_string(trolley_to);
          EXPECT_TRUE(with.arrived) << where;
          EXPECT_LT(with.swinging_s, 6.0) << where;
          EXPECT_LT(with.off_s, 6.0) << where;
          EXPECT_EQ(with.faults, 0U) << where;
          EXPECT_NEAR(with.friction_factor, friction, 0.05) << where;
          if (without.swinging_s > 10.0 || without.off_s > 10.0 || without.faults != 0U) ++unsettled_without;
          ++moves;
        }
      }
    }
  }
  std::printf("without the factor %d of %d moves still swing or sit off the target 10 s after the arrival, or fault\n",
              unsettled_without, moves);
  EXPECT_GT(unsettled_without, moves / 2) << "the configured friction on a plant off it (the cause)";
}
