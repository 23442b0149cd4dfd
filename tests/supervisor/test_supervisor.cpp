// Tests of the safety supervisor core (supervisor/include/crane/supervisor/supervisor.hpp).
//
// Rules under test (header comment of supervisor.hpp):
//  - brakes released and motion enabled only in ready/operating, and only while every stage is
//    fresh: alive && present && seconds_since_sample <= stage_timeout;
//  - a stage that is not fresh is late: motion inhibited while it lasts, no fault;
//  - a stage dead after start-up (gone, or silent beyond stage_dead_timeout), a limit exceeded or a
//    non-finite value: fault, brakes engaged, fault latched until a reset with a healthy chain;
//  - an emergency stop engages the brakes at once and needs a reset.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/supervisor/supervisor.hpp"

namespace sv = crane::supervisor;

namespace {

// Randomized property test size (STYLE.md habit 11: the count is a parameter).
constexpr int kRandomSequences = 400;
constexpr int kStepsPerSequence = 250;
constexpr std::uint32_t kRandomSeed = 20031103U;

constexpr std::uint32_t kAllStages = (1U << sv::kStageCount) - 1U;  // 0b111111 = 63

/// Every stage alive, a sample 10 ms old (< 50 ms default timeout), trolley mid-jib, no faults.
sv::SupervisorInput healthy_input() {
  sv::SupervisorInput in;
  for (auto& s : in.stages) {
    s.alive = true;
    s.seconds_since_sample = 0.01;
  }
  in.sensors_valid = true;
  in.trolley_position = 0.5;  // inside [0.05, 1.30]
  in.actuators_valid = true;
  return in;
}

sv::SupervisorOutput step(sv::Supervisor& supervisor, const sv::SupervisorInput& in) {
  sv::SupervisorOutput out;
  supervisor.step(in, out);
  return out;
}

sv::SupervisorInput with_command(sv::SupervisorInput in, sv::Command command) {
  in.command = command;
  return in;
}

/// A supervisor (default params, arm_on_start) that has reached ready.
sv::Supervisor ready_supervisor(const sv::SupervisorParams& params = {}) {
  sv::Supervisor supervisor(params);
  auto out = step(supervisor, healthy_input());
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_TRUE(out.motion_enabled);
  EXPECT_FALSE(out.brakes_released) << "brakes open only a cycle after the drives are enabled";
  out = step(supervisor, healthy_input());
  EXPECT_TRUE(out.brakes_released);
  return supervisor;
}

void expect_stopped(const sv::SupervisorOutput& out) {
  EXPECT_FALSE(out.brakes_released);
  EXPECT_FALSE(out.motion_enabled);
}

std::string config_error_message(const sv::SupervisorParams& params) {
  try {
    sv::validate(params);
  } catch (const crane::common::ConfigError& error) {
    return error.what();
  }
  return "<no ConfigError thrown>";
}

}  // namespace

TEST(Supervisor, StartingUntilAllSixStagesAlive) {
  sv::Supervisor supervisor(sv::SupervisorParams{});  // arm_on_start = true, stage_timeout = 0.05
  // Nothing observed yet: starting, brakes on, and no fault (a stage silent during start-up only
  // keeps us waiting).
  auto out = step(supervisor, sv::SupervisorInput{});
  EXPECT_EQ(out.mode, sv::Mode::starting);
  expect_stopped(out);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_EQ(out.latched_faults, 0U);
  EXPECT_EQ(out.stages_alive, 0U);

  for (std::size_t dead = 0; dead < sv::kStageCount; ++dead) {
    SCOPED_TRACE(sv::stage_name(static_cast<sv::Stage>(dead)));
    // Liveliness lost: stage `dead` missing from the mask, five of six is not enough.
    auto in = healthy_input();
    in.stages[dead].alive = false;
    out = step(supervisor, in);
    EXPECT_EQ(out.mode, sv::Mode::starting);
    expect_stopped(out);
    EXPECT_EQ(out.stages_alive, kAllStages & ~(1U << dead));
    EXPECT_EQ(out.latched_faults, 0U);

    // Liveliness asserted but the last sample is 51 ms old > stage_timeout = 50 ms: not alive.
    in = healthy_input();
    in.stages[dead].seconds_since_sample = 0.051;
    out = step(supervisor, in);
    EXPECT_EQ(out.mode, sv::Mode::starting);
    expect_stopped(out);
    EXPECT_EQ(out.stages_alive, kAllStages & ~(1U << dead));
  }

  // All six alive, the oldest sample exactly at the timeout (the rule is <=): ready at once, drives
  // enabled; the brakes open in the next cycle with the chain still alive.
  auto in = healthy_input();
  in.stages[3].seconds_since_sample = 0.05;
  out = step(supervisor, in);
  EXPECT_EQ(out.stages_alive, kAllStages);
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_FALSE(out.brakes_released);
  EXPECT_TRUE(out.motion_enabled);
  out = step(supervisor, in);
  EXPECT_TRUE(out.brakes_released);
  EXPECT_TRUE(out.motion_enabled);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_EQ(out.fault_count, 0U);
}

TEST(Supervisor, WithoutArmOnStartStaysInStandbyUntilArmed) {
  sv::SupervisorParams params;
  params.arm_on_start = false;
  sv::Supervisor supervisor(params);
  for (int i = 0; i < 10; ++i) {
    const auto out = step(supervisor, healthy_input());
    EXPECT_EQ(out.mode, sv::Mode::standby);
    expect_stopped(out);
    EXPECT_EQ(out.latched_faults, 0U);
  }
  auto out = step(supervisor, with_command(healthy_input(), sv::Command::arm));
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_TRUE(out.motion_enabled);
  EXPECT_FALSE(out.brakes_released);
  EXPECT_FALSE(out.command_refused);
  // Armed stays armed without repeating the command; the brakes open one cycle after the drives.
  out = step(supervisor, healthy_input());
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_TRUE(out.brakes_released);
  // Disarm: back to standby, brakes on.
  out = step(supervisor, with_command(healthy_input(), sv::Command::disarm));
  EXPECT_EQ(out.mode, sv::Mode::standby);
  expect_stopped(out);
}

TEST(Supervisor, ArmCommandBeforeChainHealthyDoesNotReleaseBrakes) {
  sv::SupervisorParams params;
  params.arm_on_start = false;
  sv::Supervisor supervisor(params);
  auto in = with_command(healthy_input(), sv::Command::arm);
  in.stages[0].alive = false;  // sensors not up yet
  auto out = step(supervisor, in);
  EXPECT_EQ(out.mode, sv::Mode::starting);
  expect_stopped(out);
}

TEST(Supervisor, SilentStageAfterReadyFaultsAndLatches) {
  auto supervisor = ready_supervisor();

  // Tracking's last sample is 260 ms old > stage_dead_timeout = 250 ms: dead.
  auto silent = healthy_input();
  silent.stages[static_cast<std::size_t>(sv::Stage::tracking)].seconds_since_sample = 0.26;
  auto out = step(supervisor, silent);
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultStageSilent));
  EXPECT_EQ(out.latched_faults, static_cast<std::uint32_t>(sv::kFaultStageSilent));
  EXPECT_EQ(supervisor.newly_raised(), static_cast<std::uint32_t>(sv::kFaultStageSilent));
  EXPECT_EQ(out.fault_count, 1U);

  // Still silent: the same fault is not new and not counted again.
  out = step(supervisor, silent);
  EXPECT_EQ(out.mode, sv::Mode::fault);
  EXPECT_EQ(supervisor.newly_raised(), 0U);
  EXPECT_EQ(out.fault_count, 1U);

  // Reset while the stage is still silent: nothing is cleared.
  out = step(supervisor, with_command(silent, sv::Command::reset));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);
  EXPECT_EQ(out.latched_faults, static_cast<std::uint32_t>(sv::kFaultStageSilent));

  // The stage is back: the fault is no longer active but stays latched until a reset.
  out = step(supervisor, healthy_input());
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_EQ(out.latched_faults, static_cast<std::uint32_t>(sv::kFaultStageSilent));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);

  // Reset with a healthy chain: cleared, back to ready (armed on start), drives enabled, brakes
  // released in the next cycle.
  out = step(supervisor, with_command(healthy_input(), sv::Command::reset));
  EXPECT_EQ(out.latched_faults, 0U);
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_TRUE(out.motion_enabled);
  out = step(supervisor, healthy_input());
  EXPECT_TRUE(out.brakes_released);
  EXPECT_EQ(out.fault_count, 1U);  // the history is kept
}

// Liveliness lost (a process starved for a lease, or dead): late at once, motion inhibited; a fault
// only once its silence exceeds stage_dead_timeout.
TEST(Supervisor, StageLosingLivelinessIsLateThenDead) {
  for (std::size_t dead = 0; dead < sv::kStageCount; ++dead) {
    SCOPED_TRACE(sv::stage_name(static_cast<sv::Stage>(dead)));
    auto supervisor = ready_supervisor();
    auto in = healthy_input();
    in.stages[dead].alive = false;
    auto out = step(supervisor, in);
    EXPECT_EQ(out.mode, sv::Mode::ready);
    expect_stopped(out);
    EXPECT_EQ(out.latched_faults, 0U);
    EXPECT_TRUE(out.warnings & sv::kWarningStageLate);
    EXPECT_EQ(out.stages_alive, kAllStages & ~(1U << dead));
    in.stages[dead].seconds_since_sample = 0.2501;
    out = step(supervisor, in);
    EXPECT_EQ(out.mode, sv::Mode::fault);
    expect_stopped(out);
    EXPECT_TRUE(out.latched_faults & sv::kFaultStageSilent);
    EXPECT_EQ(out.stages_dead, 1U << dead);
  }
}

// A writer that is no longer matched (its process exited, or its participant's lease expired) is
// dead at once, however recent its last sample.
TEST(Supervisor, StageWhoseWriterIsGoneIsDeadAtOnce) {
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.stages[static_cast<std::size_t>(sv::Stage::anti_swing)].present = false;
  const auto out = step(supervisor, in);
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);
  EXPECT_EQ(out.latched_faults, static_cast<std::uint32_t>(sv::kFaultStageSilent));
}

// A few late cycles that recover (a stage starved for 60-240 ms) latch nothing: motion is inhibited
// while the stage is late and comes back, brakes one cycle after the drives, as at start-up.
TEST(Supervisor, LateStageThatRecoversLatchesNothing) {
  auto supervisor = ready_supervisor();
  auto late = healthy_input();
  for (const double silence : {0.06, 0.12, 0.24, 0.25}) {
    late.stages[static_cast<std::size_t>(sv::Stage::tracking)].seconds_since_sample = silence;
    const auto out = step(supervisor, late);
    expect_stopped(out);
    EXPECT_EQ(out.mode, sv::Mode::ready);
    EXPECT_EQ(out.active_faults, 0U);
    EXPECT_EQ(out.latched_faults, 0U);
    EXPECT_TRUE(out.warnings & sv::kWarningStageLate);
  }
  auto out = step(supervisor, healthy_input());
  EXPECT_TRUE(out.motion_enabled);
  EXPECT_FALSE(out.brakes_released);
  EXPECT_EQ(out.warnings & sv::kWarningStageLate, 0U);
  out = step(supervisor, healthy_input());
  EXPECT_TRUE(out.brakes_released);
  EXPECT_EQ(out.fault_count, 0U);
}

// The drives braked under way: brakes on while the supervisor lets the crane move (the actuation
// gate's watchdog after a stalled chain, or a late stage) is warned of for as long as they stay on,
// once the drives have run in this spell of ready/operating; not at start-up, nor in a fault.
TEST(Supervisor, DrivesBrakedUnderWayAreWarnedOfOnceTheyHaveRun) {
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.brakes_engaged = true;  // the gate has not yet opened them: start-up, no warning
  EXPECT_EQ(step(supervisor, in).warnings & sv::kWarningDrivesBraked, 0U);
  in.brakes_engaged = false;
  EXPECT_EQ(step(supervisor, in).warnings & sv::kWarningDrivesBraked, 0U);
  in.brakes_engaged = true;  // the gate's watchdog: braked under way
  for (int k = 0; k < 3; ++k) {
    const auto out = step(supervisor, in);
    EXPECT_TRUE(out.warnings & sv::kWarningDrivesBraked) << "cycle " << k;
    EXPECT_TRUE(out.brakes_released) << "a warning: motion stays permitted";
    EXPECT_EQ(out.latched_faults, 0U);
  }
  in.brakes_engaged = false;
  EXPECT_EQ(step(supervisor, in).warnings & sv::kWarningDrivesBraked, 0U) << "cleared when they open";
  // A late stage inhibits motion: the brakes it engages are braked under way too.
  auto late = in;
  late.brakes_engaged = true;
  late.stages[static_cast<std::size_t>(sv::Stage::tracking)].seconds_since_sample = 0.06;
  const auto late_out = step(supervisor, late);
  EXPECT_TRUE(late_out.warnings & sv::kWarningStageLate);
  EXPECT_TRUE(late_out.warnings & sv::kWarningDrivesBraked);
  // A fault: the brakes are the supervisor's own doing, no warning; after the reset, the drives
  // must run again before braking is warned of.
  auto fault = in;
  fault.brakes_engaged = true;
  fault.swing_in_plane = 1.0;
  EXPECT_EQ(step(supervisor, fault).warnings & sv::kWarningDrivesBraked, 0U);
  fault.swing_in_plane = 0.0;
  EXPECT_EQ(step(supervisor, with_command(fault, sv::Command::reset)).warnings & sv::kWarningDrivesBraked, 0U);
  EXPECT_EQ(step(supervisor, fault).warnings & sv::kWarningDrivesBraked, 0U) << "not run since the fault";
}

TEST(Supervisor, TravelLimitCheckedOnlyOnceSensorsValid) {
  // Limits [0.05, 1.30] m.
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.sensors_valid = false;
  in.trolley_position = 2.0;  // stale/default value before the first sensor sample
  auto out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_EQ(out.mode, sv::Mode::ready);

  in.trolley_position = 1.30;  // exactly on the bound: allowed
  in.sensors_valid = true;
  out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, 0U);

  in.trolley_position = 1.31;
  out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultTrolleyTravel));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);

  // Below the lower bound as well.
  auto low = ready_supervisor();
  in.trolley_position = 0.04;
  out = step(low, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultTrolleyTravel));
  EXPECT_EQ(out.mode, sv::Mode::fault);
}

TEST(Supervisor, VoltageLimitOnEitherDrive) {
  // |V| <= 10 V allowed on both drives.
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.trolley_voltage = 10.0;
  in.slew_voltage = -10.0;
  auto out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, 0U);

  in.trolley_voltage = 10.5;
  in.slew_voltage = 0.0;
  out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultVoltage));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);

  auto slew = ready_supervisor();
  in.trolley_voltage = 0.0;
  in.slew_voltage = -10.5;
  out = step(slew, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultVoltage));
  EXPECT_EQ(out.mode, sv::Mode::fault);
}

TEST(Supervisor, SwingLimitInEitherPlane) {
  // max_swing = 0.35 rad.
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.swing_in_plane = 0.35;
  in.swing_out_of_plane = -0.35;
  auto out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, 0U);

  in.swing_in_plane = 0.36;
  in.swing_out_of_plane = 0.0;
  out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultSwing));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);

  auto out_of_plane = ready_supervisor();
  in.swing_in_plane = 0.0;
  in.swing_out_of_plane = -0.36;
  out = step(out_of_plane, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultSwing));
  EXPECT_EQ(out.mode, sv::Mode::fault);
}

// Regression: the swing check once read `valid && |in_plane| > max || |out_of_plane| > max`, which
// parses as (valid && in_plane) || out_of_plane and checked the out-of-plane swing before any
// sensor sample, unlike the in-plane swing and the travel limit (SupervisorInput::sensors_valid).
TEST(Supervisor, SwingLimitCheckedOnlyOnceSensorsValid) {
  for (const bool out_of_plane : {false, true}) {
    SCOPED_TRACE(out_of_plane ? "out of plane" : "in plane");
    auto supervisor = ready_supervisor();
    auto in = healthy_input();
    in.sensors_valid = false;
    (out_of_plane ? in.swing_out_of_plane : in.swing_in_plane) = 0.5;  // > 0.35, but no sample yet
    const auto out = step(supervisor, in);
    EXPECT_EQ(out.active_faults, 0U);
    EXPECT_EQ(out.mode, sv::Mode::ready);
  }
}

TEST(Supervisor, MultipleSensorWriters) {
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.sensor_writers = 2;  // e.g. a plant and a hardware bridge both running
  const auto out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultMultipleSensorWriters));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);
}

TEST(Supervisor, NonFiniteSampleFlag) {
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.nonfinite_seen = true;
  const auto out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultNonFinite));
  EXPECT_EQ(out.latched_faults, static_cast<std::uint32_t>(sv::kFaultNonFinite));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);
}

TEST(Supervisor, SeveralFaultsInOneStepAreCountedEach) {
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.trolley_position = 1.5;  // travel
  in.slew_voltage = 12.0;     // voltage
  in.nonfinite_seen = true;   // non-finite
  const auto out = step(supervisor, in);
  const std::uint32_t expected = sv::kFaultTrolleyTravel | sv::kFaultVoltage | sv::kFaultNonFinite;
  EXPECT_EQ(out.active_faults, expected);
  EXPECT_EQ(supervisor.newly_raised(), expected);
  EXPECT_EQ(out.fault_count, 3U);  // popcount of three new bits
}

TEST(Supervisor, EmergencyStopCommandBrakesAtOnceAndNeedsReset) {
  auto supervisor = ready_supervisor();
  auto moving = healthy_input();
  moving.move_in_progress = true;
  ASSERT_EQ(step(supervisor, moving).mode, sv::Mode::operating);

  // The very step that carries the command already has the brakes on.
  auto out = step(supervisor, with_command(moving, sv::Command::emergency_stop));
  EXPECT_EQ(out.mode, sv::Mode::emergency_stop);
  expect_stopped(out);
  EXPECT_TRUE(out.latched_faults & sv::kFaultEmergencyStop);
  EXPECT_EQ(supervisor.newly_raised(), static_cast<std::uint32_t>(sv::kFaultEmergencyStop));

  // The command is gone but the stop holds.
  out = step(supervisor, healthy_input());
  EXPECT_EQ(out.mode, sv::Mode::emergency_stop);
  expect_stopped(out);
  // Arming does not override it.
  out = step(supervisor, with_command(healthy_input(), sv::Command::arm));
  EXPECT_EQ(out.mode, sv::Mode::emergency_stop);
  expect_stopped(out);

  out = step(supervisor, with_command(healthy_input(), sv::Command::reset));
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_TRUE(out.motion_enabled);
  EXPECT_TRUE(step(supervisor, healthy_input()).brakes_released);
}

TEST(Supervisor, EmergencyStopInputHeldBlocksReset) {
  auto supervisor = ready_supervisor();
  auto pressed = healthy_input();
  pressed.emergency_stop_input = true;
  auto out = step(supervisor, pressed);
  EXPECT_EQ(out.mode, sv::Mode::emergency_stop);
  expect_stopped(out);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultEmergencyStop));

  // Reset while the button is still pressed: refused.
  out = step(supervisor, with_command(pressed, sv::Command::reset));
  EXPECT_EQ(out.mode, sv::Mode::emergency_stop);
  expect_stopped(out);

  // Released: still stopped until a reset.
  out = step(supervisor, healthy_input());
  EXPECT_EQ(out.mode, sv::Mode::emergency_stop);
  expect_stopped(out);

  out = step(supervisor, with_command(healthy_input(), sv::Command::reset));
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_EQ(out.latched_faults, 0U);
  EXPECT_EQ(out.fault_count, 1U);
}

TEST(Supervisor, EmergencyStopTakesPrecedenceOverOtherFaults) {
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.trolley_voltage = 20.0;
  ASSERT_EQ(step(supervisor, in).mode, sv::Mode::fault);
  in.emergency_stop_input = true;
  EXPECT_EQ(step(supervisor, in).mode, sv::Mode::emergency_stop);
}

TEST(Supervisor, MoveInProgressIsOperating) {
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.move_in_progress = true;
  auto out = step(supervisor, in);
  EXPECT_EQ(out.mode, sv::Mode::operating);
  EXPECT_TRUE(out.brakes_released);
  EXPECT_TRUE(out.motion_enabled);
  in.move_in_progress = false;
  out = step(supervisor, in);
  EXPECT_EQ(out.mode, sv::Mode::ready);
  EXPECT_TRUE(out.brakes_released);
}

TEST(Supervisor, ModeAndStageNames) {
  EXPECT_STREQ(sv::mode_name(sv::Mode::emergency_stop), "emergency_stop");
  EXPECT_STREQ(sv::mode_name(sv::Mode::operating), "operating");
  EXPECT_STREQ(sv::stage_name(sv::Stage::friction_compensation), "friction_compensation");
  EXPECT_STREQ(sv::stage_name(sv::Stage::sensors), "sensors");
}

TEST(Supervisor, DefaultParamsAreValid) {
  EXPECT_NO_THROW(sv::validate(sv::SupervisorParams{}));
}

TEST(Supervisor, InvalidParamsNameFieldAndValue) {
  struct Case {
    const char* expected;  // field = value, as format_value (%.10g) prints it
    void (*edit)(sv::SupervisorParams&);
  };
  const Case cases[] = {
      {"supervisor.stage_timeout = 0.001", [](sv::SupervisorParams& p) { p.stage_timeout = 0.001; }},   // < 0.005
      {"supervisor.stage_timeout = 10", [](sv::SupervisorParams& p) { p.stage_timeout = 10.0; }},       // > 5
      {"supervisor.stage_timeout = nan",
       [](sv::SupervisorParams& p) { p.stage_timeout = std::numeric_limits<double>::quiet_NaN(); }},
      {"supervisor.trolley_min = 200", [](sv::SupervisorParams& p) { p.trolley_min = 200.0; }},         // > 100
      {"supervisor.trolley_max = 0.05", [](sv::SupervisorParams& p) { p.trolley_max = 0.05; }},         // <= min
      {"supervisor.voltage_limit = 0", [](sv::SupervisorParams& p) { p.voltage_limit = 0.0; }},         // < 0.1
      {"supervisor.max_swing = 2", [](sv::SupervisorParams& p) { p.max_swing = 2.0; }},                 // > 1.5
      {"supervisor.max_swing = -0.2", [](sv::SupervisorParams& p) { p.max_swing = -0.2; }},             // < 0.01
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.expected);
    sv::SupervisorParams params;
    c.edit(params);
    const std::string message = config_error_message(params);
    EXPECT_NE(message.find(c.expected), std::string::npos) << message;
    EXPECT_NE(message.find("out of range"), std::string::npos) << message;
    // The constructor validates as well.
    EXPECT_THROW(sv::Supervisor{params}, crane::common::ConfigError);
  }
  // The bound is named too: stage_timeout must be in [0.005, 5].
  sv::SupervisorParams params;
  params.stage_timeout = 0.001;
  EXPECT_NE(config_error_message(params).find("[0.005, 5]"), std::string::npos) << config_error_message(params);
}

// Seeded randomized property: brakes are never released unless, in that very step, all six stages
// were alive (recomputed here from the input: alive && seconds_since_sample <= stage_timeout) and
// nothing is latched. Also: motion_enabled == brakes_released, fault_count grows by exactly the
// popcount of newly_raised(), and an emergency stop in the input always means brakes on.
TEST(Supervisor, RandomizedBrakesOnlyWithHealthyChainAndNoLatchedFault) {
  std::mt19937 rng(kRandomSeed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  auto chance = [&](double p) { return unit(rng) < p; };
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };

  long released_steps = 0;
  long fault_steps = 0;
  for (int sequence = 0; sequence < kRandomSequences; ++sequence) {
    sv::SupervisorParams params;
    params.arm_on_start = chance(0.5);
    params.stage_timeout = uniform(0.01, 0.1);
    sv::Supervisor supervisor(params);
    // Per-sequence disturbance rate: some sequences are mostly healthy, some chaotic.
    const double disturbance = uniform(0.0, 0.3);
    std::uint32_t previous_count = 0;
    bool previous_enabled = false;
    for (int k = 0; k < kStepsPerSequence; ++k) {
      auto in = healthy_input();
      for (auto& s : in.stages) {
        s.seconds_since_sample = uniform(0.0, params.stage_timeout);
        if (chance(disturbance * 0.2)) s.alive = false;
        if (chance(disturbance * 0.2)) s.seconds_since_sample = uniform(0.0, 2.0 * params.stage_timeout);
        if (chance(disturbance * 0.05)) s.seconds_since_sample = uniform(0.0, 2.0 * params.stage_dead_timeout);
        if (chance(disturbance * 0.02)) s.present = false;
      }
      if (chance(disturbance * 0.1)) in.stages[0].seconds_since_sample = params.stage_timeout;  // boundary
      if (chance(disturbance * 0.1)) in.sensors_valid = false;
      if (chance(disturbance * 0.1)) in.trolley_position = uniform(-0.2, 1.6);
      if (chance(disturbance * 0.1)) in.swing_in_plane = uniform(-0.5, 0.5);
      if (chance(disturbance * 0.1)) in.swing_out_of_plane = uniform(-0.5, 0.5);
      if (chance(disturbance * 0.1)) in.trolley_voltage = uniform(-12.0, 12.0);
      if (chance(disturbance * 0.1)) in.slew_voltage = uniform(-12.0, 12.0);
      if (chance(disturbance * 0.02)) in.emergency_stop_input = true;
      if (chance(disturbance * 0.05)) in.sensor_writers = 2;
      if (chance(disturbance * 0.05)) in.nonfinite_seen = true;
      in.move_in_progress = chance(0.3);
      const double c = unit(rng);
      in.command = c < 0.15   ? sv::Command::reset
                   : c < 0.25 ? sv::Command::arm
                   : c < 0.27 ? sv::Command::disarm
                   : c < 0.28 ? sv::Command::emergency_stop
                              : sv::Command::none;

      bool all_alive = true;
      for (const auto& s : in.stages) {
        all_alive = all_alive && s.alive && s.present && s.seconds_since_sample <= params.stage_timeout;
      }

      sv::SupervisorOutput out;
      supervisor.step(in, out);

      if (out.brakes_released) {
        ++released_steps;
        ASSERT_TRUE(all_alive) << "sequence " << sequence << " step " << k;
        ASSERT_EQ(out.latched_faults, 0U) << "sequence " << sequence << " step " << k;
      } else {
        ++fault_steps;
      }
      // Brakes open only with the drives enabled in this and the previous cycle.
      if (out.brakes_released) {
        ASSERT_TRUE(out.motion_enabled && previous_enabled) << "sequence " << sequence << " step " << k;
      }
      previous_enabled = out.motion_enabled;
      ASSERT_EQ(out.fault_count, previous_count + static_cast<std::uint32_t>(std::popcount(supervisor.newly_raised())))
          << "sequence " << sequence << " step " << k;
      if (in.emergency_stop_input || in.command == sv::Command::emergency_stop) {
        ASSERT_FALSE(out.brakes_released) << "sequence " << sequence << " step " << k;
        ASSERT_EQ(out.mode, sv::Mode::emergency_stop) << "sequence " << sequence << " step " << k;
      }
      previous_count = out.fault_count;
    }
  }
  // The property must not hold vacuously: both outcomes occur many times.
  EXPECT_GT(released_steps, kRandomSequences * kStepsPerSequence / 10);
  EXPECT_GT(fault_steps, kRandomSequences * kStepsPerSequence / 10);
}

// ---- Protective functions with approach margins (header: "approach margins") ----

namespace {

/// Feeds two sensor samples one cycle apart so that the supervisor's own differentiation sees
/// `velocity` [m/s] at `position` [m] (trolley), returns the second step's output.
sv::SupervisorOutput trolley_at(sv::Supervisor& supervisor, double position, double velocity, std::uint64_t& seq) {
  auto in = healthy_input();
  seq += 100000;  // a long gap first: whatever came before differentiates to a negligible velocity
  in.sensor_seq = seq++;
  in.trolley_position = position - velocity * 0.01;
  step(supervisor, in);
  in.sensor_seq = seq++;
  in.trolley_position = position;
  return step(supervisor, in);
}

}  // namespace

TEST(SupervisorLimits, VelocityIsDifferentiatedFromTheSensorSamples) {
  auto supervisor = ready_supervisor();
  std::uint64_t seq = 100;
  const auto out = trolley_at(supervisor, 0.6, 0.3, seq);
  EXPECT_NEAR(out.trolley_velocity, 0.3, 1e-9);
  // A gap of three cycles: the difference is divided by 3 sample periods.
  auto in = healthy_input();
  in.sensor_seq = seq + 2;
  in.trolley_position = 0.6 + 3 * 0.01 * (-0.2);
  in.slew_angle = 0.03;  // from 0 over 3 cycles: 1 rad/s
  const double cable = in.cable_length;
  in.cable_length = cable + 0.006;  // the hoist lowering at 0.2 m/s over the same 3 cycles
  const auto later = step(supervisor, in);
  EXPECT_NEAR(later.trolley_velocity, -0.2, 1e-9);
  EXPECT_NEAR(later.slew_rate, 1.0, 1e-9);
  EXPECT_NEAR(later.cable_rate, 0.2, 1e-9) << "the hoist's rate, for the site guard, from the samples too";
  // A cable length not measured (NaN) gives no rate, and no rate from it on the next sample.
  in.sensor_seq += 1;
  in.cable_length = std::nan("");
  EXPECT_EQ(step(supervisor, in).cable_rate, 0.0);
  in.sensor_seq += 1;
  in.cable_length = cable;
  EXPECT_EQ(step(supervisor, in).cable_rate, 0.0);
}

TEST(SupervisorLimits, ApproachMarginLowersTheVoltageLimitOnlyWhenTooFastTowardTheLimit) {
  // trolley_max 1.30, approach 0.15, stop 0.03, approach speed 0.1, max speed 1.0: at 1.21 m the
  // distance is 0.09 m, half way through the band: allowed 0.1 + 0.9 * 0.5 = 0.55 m/s.
  const sv::SupervisorParams p;
  std::uint64_t seq = 1;
  auto supervisor = ready_supervisor();
  auto out = trolley_at(supervisor, 1.21, 0.50, seq);  // below the allowed speed
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_TRUE(out.warnings & sv::kWarningTrolleyApproach);
  EXPECT_FALSE(out.warnings & sv::kWarningSpeedLimited);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
  out = trolley_at(supervisor, 1.21, 0.60, seq);  // above it: the drive may only brake
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_TRUE(out.warnings & sv::kWarningSpeedLimited);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.approach_voltage_limit);
  EXPECT_DOUBLE_EQ(out.slew_voltage_limit, p.voltage_limit);
  EXPECT_TRUE(out.brakes_released);
  // Moving away from the limit at the same place: no warning, full voltage.
  out = trolley_at(supervisor, 1.21, -0.60, seq);
  EXPECT_EQ(out.warnings & (sv::kWarningTrolleyApproach | sv::kWarningSpeedLimited), 0U);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
  // Near the lower limit, moving toward it: the same rule mirrored (0.14 m: 0.09 m from 0.05 m).
  out = trolley_at(supervisor, 0.14, -0.60, seq);
  EXPECT_TRUE(out.warnings & sv::kWarningSpeedLimited);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.approach_voltage_limit);
}

TEST(SupervisorLimits, InsideTheStopMarginMovingTowardTheLimitIsAProtectiveStop) {
  std::uint64_t seq = 1;
  auto supervisor = ready_supervisor();
  // 1.28 m: 0.02 m from trolley_max, inside the 0.03 m stop margin, but standing still (the
  // compensator's dither is far below 0.1 * approach speed): allowed to stay there.
  auto out = trolley_at(supervisor, 1.28, 0.001, seq);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_TRUE(out.brakes_released);
  // Moving away: fine.
  out = trolley_at(supervisor, 1.28, -0.05, seq);
  EXPECT_EQ(out.active_faults, 0U);
  // Creeping toward it: protective stop, latched.
  out = trolley_at(supervisor, 1.28, 0.02, seq);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultTrolleyTravel));
  EXPECT_EQ(out.mode, sv::Mode::fault);
  expect_stopped(out);
  EXPECT_EQ(out.trolley_voltage_limit, 0.0);
  EXPECT_EQ(out.last_fault, static_cast<std::uint32_t>(sv::kFaultTrolleyTravel));
  EXPECT_EQ(out.last_fault_seq, seq - 1);
}

TEST(SupervisorLimits, SlewRangeAndOverspeed) {
  const sv::SupervisorParams p;  // slew [-3.3, 3.3] rad, max rate 2.0 rad/s
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.sensor_seq = 100000;  // long after the last sample: a negligible rate from the jump to 3 rad
  in.slew_angle = 3.2;
  step(supervisor, in);
  in.sensor_seq = 100001;
  // 1.5 rad/s toward the limit, 0.085 rad from it: allowed 0.2 + 1.8 * (0.085 - 0.05) / 0.25 = 0.452 rad/s.
  in.slew_angle = 3.2 + 0.01 * 1.5;
  auto out = step(supervisor, in);
  EXPECT_TRUE(out.warnings & sv::kWarningSlewApproach);
  EXPECT_TRUE(out.warnings & sv::kWarningSpeedLimited);
  EXPECT_DOUBLE_EQ(out.slew_voltage_limit, p.approach_voltage_limit);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
  EXPECT_EQ(out.active_faults, 0U);
  in.sensor_seq = 100002;
  in.slew_angle -= 0.01 * 2.1;  // 2.1 rad/s > 2.0 for one sample: not yet an overspeed (kOverspeedSamples)
  out = step(supervisor, in);
  EXPECT_FALSE(out.active_faults & sv::kFaultSlewOverspeed);
  in.sensor_seq = 100003;
  in.slew_angle -= 0.01 * 2.1;  // and the next: overspeed
  out = step(supervisor, in);
  EXPECT_TRUE(out.active_faults & sv::kFaultSlewOverspeed);
  EXPECT_EQ(out.mode, sv::Mode::fault);

  auto range = ready_supervisor();
  in = healthy_input();
  in.slew_angle = -3.31;
  out = step(range, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultSlewRange));
}

// Without a slew (slew_enabled false: a gantry or overhead crane) the slew angle and rate are not
// looked at (no slew range, approach or overspeed), the slew drive gets 0 V and the slew fields are
// not validated; the trolley is guarded as before.
TEST(SupervisorLimits, WithoutASlewItsLimitsAreNotChecked) {
  sv::SupervisorParams p;
  p.slew_enabled = false;
  p.slew_max = p.slew_min;  // would be refused on a tower crane
  p.slew_braking_deceleration = 0.0;
  EXPECT_EQ(config_error_message(p), "<no ConfigError thrown>");
  sv::Supervisor supervisor(p);
  auto in = healthy_input();
  in.slew_angle = 5.0;  // beyond a tower crane's slew range
  sv::SupervisorOutput out;
  for (int i = 0; i < 3; ++i) out = step(supervisor, in);
  in.sensor_seq = 1;
  out = step(supervisor, in);
  in.sensor_seq = 2;
  in.slew_angle += 0.05;  // 5 rad/s, twice
  out = step(supervisor, in);
  in.sensor_seq = 3;
  in.slew_angle += 0.05;
  out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_EQ(out.warnings & (sv::kWarningSlewApproach | sv::kWarningSpeedLimited), 0U);
  EXPECT_TRUE(out.brakes_released);
  EXPECT_EQ(out.slew_voltage_limit, 0.0);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
  in.trolley_position = 1.31;  // the trolley's travel limit still holds
  EXPECT_EQ(step(supervisor, in).active_faults, static_cast<std::uint32_t>(sv::kFaultTrolleyTravel));
  // The same slew angle on a tower crane is a protective stop.
  sv::Supervisor tower{sv::SupervisorParams{}};
  in = healthy_input();
  in.slew_angle = 5.0;
  EXPECT_EQ(step(tower, in).active_faults, static_cast<std::uint32_t>(sv::kFaultSlewRange));
}

TEST(SupervisorLimits, TrolleyOverspeed) {
  std::uint64_t seq = 1;
  auto supervisor = ready_supervisor();
  EXPECT_EQ(trolley_at(supervisor, 0.6, 0.99, seq).active_faults, 0U);
  // A 0.6 m/s move read as 1.2 m/s for one sample and 0 for the next (one encoder reading a cycle
  // late): no fault. Then 1.01 m/s in two consecutive samples: overspeed (kOverspeedSamples).
  auto in = healthy_input();
  double x = 0.6;
  const auto sample = [&](double dx) {
    in.sensor_seq = seq++;
    x += dx;
    in.trolley_position = x;
    return step(supervisor, in);
  };
  seq += 100000;
  EXPECT_EQ(sample(0.0).active_faults, 0U);
  EXPECT_EQ(sample(-0.006).active_faults, 0U);
  EXPECT_EQ(sample(-0.012).active_faults, 0U) << "one sample at 1.2 m/s";
  EXPECT_EQ(sample(0.0).active_faults, 0U);
  EXPECT_EQ(sample(-0.0101).active_faults, 0U);
  const auto out = sample(-0.0101);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultTrolleyOverspeed));
  expect_stopped(out);
}

// A hardware bridge's cycles jitter: a 0.9 m/s move read at 12.1, 11.5 and 6.5 ms intervals (the
// secured fault-injection stack's samples 427-430) is 1.07 and 1.04 m/s over the nominal 10 ms, two
// samples over 1.0 m/s: a spurious overspeed. Over the measured intervals it is 0.9 m/s; a true
// 1.05 m/s read with the same jitter is still an overspeed; a clock step falls back to the nominal.
TEST(SupervisorLimits, TrolleyOverspeedOverTheMeasuredIntervals) {
  const double intervals[] = {0.010, 0.010, 0.0121, 0.0115, 0.0065, 0.010, 0.010};
  std::vector<double> velocity;  // [m/s] the supervisor's, per sample of the last run
  const auto run = [&](double speed, bool measured, double clock_step = 0.0) {
    auto supervisor = ready_supervisor();
    auto in = healthy_input();
    std::uint64_t seq = 200000;
    double t = 1000.0;  // [s] any epoch
    std::uint32_t faults = 0;
    velocity.clear();
    for (int k = 0; k < 7; ++k) {
      t += intervals[k];
      in.sensor_seq = seq++;
      in.trolley_position = 0.3 + speed * (t - 1000.0);
      in.sensor_time = measured ? t + (k >= 3 ? clock_step : 0.0) : std::numeric_limits<double>::quiet_NaN();
      const auto out = step(supervisor, in);
      faults |= out.active_faults;
      velocity.push_back(out.trolley_velocity);
    }
    return faults;
  };
  EXPECT_EQ(run(0.9, false), static_cast<std::uint32_t>(sv::kFaultTrolleyOverspeed)) << "over the nominal intervals";
  EXPECT_NEAR(velocity[3], 0.9 * 0.0115 / 0.010, 1e-9);
  EXPECT_EQ(run(0.9, true), 0U) << "over the measured intervals";
  for (std::size_t k = 1; k < velocity.size(); ++k) EXPECT_NEAR(velocity[k], 0.9, 1e-6) << k;
  EXPECT_EQ(run(1.05, true), static_cast<std::uint32_t>(sv::kFaultTrolleyOverspeed)) << "a true overspeed";
  // The clock stepped by 1 s before sample 3: that interval falls back to the nominal 10 ms, the
  // next ones are measured again.
  EXPECT_EQ(run(0.9, true, 1.0), 0U);
  EXPECT_NEAR(velocity[3], 0.9 * 0.0115 / 0.010, 1e-9) << "the nominal interval";
  EXPECT_NEAR(velocity[4], 0.9, 1e-6) << "measured again";
}

// An overhead crane's bridge (bridge_enabled): guarded like the trolley, with its own faults,
// warning and voltage limit; a tower crane ignores the bridge fields (always 0 there).
TEST(SupervisorLimits, BridgeTravelOverspeedAndApproach) {
  sv::SupervisorParams p;
  p.bridge_enabled = true;
  p.bridge_min = 1.0;
  p.bridge_max = 59.0;
  p.bridge_approach_margin = 2.0;
  p.bridge_stop_margin = 0.3;
  p.bridge_approach_speed = 0.15;
  p.bridge_max_speed = 0.9;
  sv::Supervisor supervisor(p);
  auto in = healthy_input();
  in.bridge_position = 30.0;
  for (int i = 0; i < 3; ++i) step(supervisor, with_command(in, sv::Command::arm));
  std::uint64_t seq = 1000;
  const auto bridge_at = [&](double position, double velocity) {
    in.sensor_seq = (seq += 100000);
    in.bridge_position = position - velocity * 0.01;
    step(supervisor, in);
    in.sensor_seq = ++seq;
    in.bridge_position = position;
    return step(supervisor, in);
  };
  auto out = bridge_at(30.0, 0.6);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_NEAR(out.bridge_velocity, 0.6, 1e-9);
  EXPECT_DOUBLE_EQ(out.bridge_voltage_limit, p.voltage_limit);
  // 1.5 m from the end stop at 59 m, toward it at 0.6 m/s: allowed 0.15 + 0.75 * (1.5 - 0.3) / 1.7 = 0.68 m/s.
  out = bridge_at(57.5, 0.6);
  EXPECT_TRUE(out.warnings & sv::kWarningBridgeApproach);
  EXPECT_FALSE(out.warnings & sv::kWarningSpeedLimited);
  out = bridge_at(57.5, 0.7);
  EXPECT_TRUE(out.warnings & sv::kWarningSpeedLimited);
  EXPECT_DOUBLE_EQ(out.bridge_voltage_limit, p.approach_voltage_limit);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
  EXPECT_EQ(out.active_faults, 0U);
  // Overspeed: two consecutive samples over 0.9 m/s.
  in.sensor_seq = ++seq;
  in.bridge_position += 0.0095;
  EXPECT_EQ(step(supervisor, in).active_faults, 0U);
  in.sensor_seq = ++seq;
  in.bridge_position += 0.0095;  // and the next sample: 0.95 m/s twice
  out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultBridgeOverspeed));
  expect_stopped(out);
  EXPECT_EQ(out.bridge_voltage_limit, 0.0);
  EXPECT_STREQ(sv::fault_name(sv::kFaultBridgeOverspeed), "bridge_overspeed");

  sv::Supervisor range(p);
  in = healthy_input();
  in.bridge_position = 59.1;
  out = step(range, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultBridgeTravel));
  EXPECT_STREQ(sv::fault_name(sv::kFaultBridgeTravel), "bridge_travel");

  // Without a bridge (tower, gantry), the field is not looked at and the bridge drive gets 0 V.
  sv::Supervisor tower{sv::SupervisorParams{}};
  in = healthy_input();
  in.bridge_position = 500.0;
  for (int i = 0; i < 3; ++i) out = step(tower, with_command(in, sv::Command::arm));
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_TRUE(out.brakes_released);
  EXPECT_EQ(out.bridge_voltage_limit, 0.0);

  // A bridge voltage beyond the limit is a voltage fault like the others.
  sv::Supervisor voltage(p);
  in = healthy_input();
  in.bridge_position = 30.0;
  in.actuators_valid = true;
  in.bridge_voltage = 10.5;
  EXPECT_TRUE(step(voltage, in).active_faults & sv::kFaultVoltage);

  p.bridge_max = p.bridge_min;
  try {
    sv::validate(p);
    FAIL() << "expected a ConfigError";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("supervisor.bridge_max"), std::string::npos) << e.what();
  }
}

TEST(SupervisorLimits, VoltageRateOfChange) {
  // max_voltage_rate 1500 V/s: 15 V between consecutive cycles.
  auto supervisor = ready_supervisor();
  auto in = healthy_input();
  in.actuator_seq = 10;
  in.trolley_voltage = 10.0;
  EXPECT_EQ(step(supervisor, in).active_faults, 0U);
  in.actuator_seq = 11;
  in.trolley_voltage = -4.9;  // 14.9 V in one cycle: allowed
  EXPECT_EQ(step(supervisor, in).active_faults, 0U);
  in.actuator_seq = 13;
  in.trolley_voltage = 10.0;  // 14.9 V over two cycles: 745 V/s
  EXPECT_EQ(step(supervisor, in).active_faults, 0U);
  in.actuator_seq = 14;
  in.slew_voltage = -5.5;
  in.trolley_voltage = 10.0;  // slew 5.5 V: fine
  EXPECT_EQ(step(supervisor, in).active_faults, 0U);
  in.actuator_seq = 15;
  in.slew_voltage = 9.6;  // 15.1 V in one cycle on the slew
  const auto out = step(supervisor, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultVoltageRate));
  expect_stopped(out);
}

TEST(SupervisorLimits, SingleWriterSourceAndLimitSwitchChecks) {
  struct Case {
    const char* name;
    void (*apply)(sv::SupervisorInput&);
    std::uint32_t fault;
  };
  const Case cases[] = {
      {"second actuator writer", [](sv::SupervisorInput& in) { in.actuator_writers = 2; },
       sv::kFaultMultipleActuatorWriters},
      {"second sensor writer", [](sv::SupervisorInput& in) { in.sensor_writers = 2; }, sv::kFaultMultipleSensorWriters},
      {"limit switch", [](sv::SupervisorInput& in) { in.limit_switches = 0x2; }, sv::kFaultLimitSwitch},
      {"the site guard's emergency stop", [](sv::SupervisorInput& in) { in.site = sv::SiteVerdict::emergency_stop; },
       sv::kFaultSiteGrant},
      {"plant where the bridge is expected", [](sv::SupervisorInput& in) { in.sensor_source = 1; },
       sv::kFaultSensorSource},
  };
  sv::SupervisorParams params;
  params.expected_sensor_source = 2;
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    sv::Supervisor supervisor(params);
    auto healthy = healthy_input();
    healthy.sensor_source = 2;
    step(supervisor, healthy);
    ASSERT_TRUE(step(supervisor, healthy).brakes_released);
    auto in = healthy;
    c.apply(in);
    const auto out = step(supervisor, in);
    EXPECT_EQ(out.active_faults, c.fault);
    EXPECT_EQ(out.last_fault, c.fault);
    EXPECT_STREQ(sv::fault_name(c.fault), sv::fault_name(out.last_fault));
    expect_stopped(out);
  }
}

// The site guard (docs/site.md): its soft stop is a warning (the planner stops softly; the
// brakes stay released), proceed and off change nothing, and its emergency stop is a fault (above).
TEST(SupervisorLimits, TheSiteGuardsSoftStopIsAWarning) {
  sv::Supervisor supervisor{sv::SupervisorParams{}};
  const auto healthy = healthy_input();
  step(supervisor, healthy);
  ASSERT_TRUE(step(supervisor, healthy).brakes_released);
  for (const auto verdict : {sv::SiteVerdict::off, sv::SiteVerdict::proceed}) {
    auto in = healthy;
    in.site = verdict;
    const auto out = step(supervisor, in);
    EXPECT_EQ(out.warnings & sv::kWarningSite, 0u);
    EXPECT_TRUE(out.brakes_released);
  }
  auto in = healthy;
  in.site = sv::SiteVerdict::soft_stop;
  const auto out = step(supervisor, in);
  EXPECT_NE(out.warnings & sv::kWarningSite, 0u);
  EXPECT_EQ(out.active_faults, 0u);
  EXPECT_TRUE(out.brakes_released);
  EXPECT_EQ(step(supervisor, healthy).warnings & sv::kWarningSite, 0u);
}

// A site guard that does not hear the site service is a warning on a site only (the crane's site
// link waits for it to clear before it starts: ready_for_site); it changes nothing else.
TEST(SupervisorLimits, AGuardThatDoesNotHearTheSiteServiceIsAWarningOnASiteOnly) {
  sv::Supervisor supervisor{sv::SupervisorParams{}};
  auto healthy = healthy_input();
  healthy.site = sv::SiteVerdict::proceed;
  step(supervisor, healthy);
  ASSERT_TRUE(step(supervisor, healthy).brakes_released);
  EXPECT_EQ(step(supervisor, healthy).warnings & sv::kWarningSiteUnheard, 0u);
  auto unheard = healthy;
  unheard.site_unheard = true;
  const auto out = step(supervisor, unheard);
  EXPECT_NE(out.warnings & sv::kWarningSiteUnheard, 0u);
  EXPECT_EQ(out.warnings & sv::kWarningSite, 0u);
  EXPECT_EQ(out.active_faults, 0u);
  EXPECT_TRUE(out.brakes_released);
  auto off_site = unheard;
  off_site.site = sv::SiteVerdict::off;
  EXPECT_EQ(step(supervisor, off_site).warnings & sv::kWarningSiteUnheard, 0u) << "not on a site";
  EXPECT_EQ(step(supervisor, healthy).warnings & sv::kWarningSiteUnheard, 0u);
}

TEST(SupervisorLimits, ArmAndResetAreRefusedWhileUnsafe) {
  sv::SupervisorParams params;
  params.arm_on_start = false;
  sv::Supervisor supervisor(params);
  auto dead = healthy_input();
  dead.stages[2].alive = false;
  auto out = step(supervisor, with_command(dead, sv::Command::arm));
  EXPECT_TRUE(out.command_refused);
  out = step(supervisor, healthy_input());
  EXPECT_EQ(out.mode, sv::Mode::standby) << "a refused arm is not remembered";
  out = step(supervisor, with_command(healthy_input(), sv::Command::arm));
  EXPECT_FALSE(out.command_refused);
  auto tilted = healthy_input();
  tilted.swing_in_plane = 0.5;
  out = step(supervisor, with_command(tilted, sv::Command::reset));
  EXPECT_TRUE(out.command_refused) << "reset with the swing fault still active";
  out = step(supervisor, with_command(healthy_input(), sv::Command::arm));
  EXPECT_TRUE(out.command_refused) << "arm with a latched fault";
  out = step(supervisor, with_command(healthy_input(), sv::Command::reset));
  EXPECT_FALSE(out.command_refused);
  EXPECT_EQ(out.mode, sv::Mode::ready);
}

TEST(SupervisorLimits, NamesOfEveryFaultBit) {
  for (int bit = 0; bit < sv::kFaultBits; ++bit) {
    EXPECT_STRNE(sv::fault_name(1U << bit), "unknown") << "bit " << bit;
  }
  EXPECT_STREQ(sv::fault_name(1U << sv::kFaultBits), "unknown");
  EXPECT_STREQ(sv::fault_name(3U), "unknown");
}

TEST(SupervisorLimits, ValidationNamesTheMarginField) {
  sv::SupervisorParams params;
  params.trolley_stop_margin = 0.2;  // larger than the approach margin 0.15
  EXPECT_NE(config_error_message(params).find("supervisor.trolley_stop_margin"), std::string::npos)
      << config_error_message(params);
  params = {};
  params.slew_approach_rate = 2.5;  // above slew_max_rate 2.0
  EXPECT_NE(config_error_message(params).find("supervisor.slew_approach_rate"), std::string::npos)
      << config_error_message(params);
}

// --- No-go zones (supervisor.hpp, zone_guard()) ---------------------------------------------

namespace {

// A wall from x = 1.0 m to 1.4 m across the jib at slew 0, up to 10 m; the load at 1 m below a
// jib at 2 m (height 1 m). Cable 1 m: w = sqrt(9.8) = 3.1305 rad/s, period 2.0071 s.
sv::SupervisorParams zone_params() {
  sv::SupervisorParams p;
  p.trolley_max = 3.0;  // the travel limits far away
  p.site.jib_height = 2.0;
  p.site.zones = {{"wall", {{1.0, -0.3}, {1.4, -0.3}, {1.4, 0.3}, {1.0, 0.3}}, 0.0, 10.0, true}};
  return p;
}

}  // namespace

sv::Supervisor supervisor_in_mode(const sv::SupervisorParams& p, std::uint8_t mode) {
  auto supervisor = ready_supervisor(p);
  auto in = with_command(healthy_input(), sv::Command::set_operating_mode);
  in.command_operating_mode = mode;
  EXPECT_EQ(step(supervisor, in).operating_mode, mode);
  return supervisor;
}

TEST(SupervisorZones, TheSoftStopPredictionWarnsThenLimitsTheDrivesUnderOperatorSpeeds) {
  // MANUAL and SEMIAUTOMATIC (the operator's speeds through the manual shaper): at 0.2 m/s the
  // soft stop rests 0.2^2 / (2 0.9929) + 0.2 * 0.5 * 2.0071 = 0.2222 m ahead.
  const auto p = zone_params();
  for (const std::uint8_t mode : {sv::StatusCodes::OPERATION_MANUAL, sv::StatusCodes::OPERATION_SEMIAUTOMATIC}) {
    auto supervisor = supervisor_in_mode(p, mode);
    std::uint64_t seq = 1;
    auto out = trolley_at(supervisor, 0.70, 0.2, seq);  // rests at 0.922 m: 7.8 cm short of the wall
    EXPECT_EQ(out.warnings & (sv::kWarningZoneApproach | sv::kWarningSpeedLimited), 0U);
    EXPECT_EQ(out.zone, -1);
    out = trolley_at(supervisor, 0.75, 0.2, seq);  // 0.972 m: within the 5 cm approach margin
    EXPECT_TRUE(out.warnings & sv::kWarningZoneApproach);
    EXPECT_FALSE(out.warnings & sv::kWarningSpeedLimited);
    EXPECT_EQ(out.zone, 0);
    EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
    // 1.022 m: inside, and the trolley speeding up (from rest to 0.2 m/s in a cycle): its drive may
    // no longer drive it faster; the slew, at rest, keeps its voltage.
    out = trolley_at(supervisor, 0.80, 0.2, seq);
    EXPECT_TRUE(out.warnings & sv::kWarningZoneApproach);
    EXPECT_TRUE(out.warnings & sv::kWarningSpeedLimited);
    EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.approach_voltage_limit);
    EXPECT_DOUBLE_EQ(out.slew_voltage_limit, p.voltage_limit);
    EXPECT_EQ(out.active_faults, 0U);
    EXPECT_TRUE(out.brakes_released);
    // The same place decelerating (0.21 m/s, then 0.2 m/s): the drive keeps its voltage to brake.
    auto in = healthy_input();
    in.sensor_seq = seq += 100000;
    in.trolley_position = 0.80 - 0.0021 - 0.002;
    step(supervisor, in);
    in.sensor_seq = ++seq;
    in.trolley_position = 0.80 - 0.002;
    step(supervisor, in);
    in.sensor_seq = ++seq;
    in.trolley_position = 0.80;
    out = step(supervisor, in);
    ++seq;
    EXPECT_NEAR(out.trolley_velocity, 0.2, 1e-9);
    EXPECT_TRUE(out.warnings & sv::kWarningZoneApproach);
    EXPECT_FALSE(out.warnings & sv::kWarningSpeedLimited);
    EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
    // Slower at the same place: the soft stop fits again (0.05 m/s: rests at 0.851 m).
    out = trolley_at(supervisor, 0.80, 0.05, seq);
    EXPECT_EQ(out.warnings & (sv::kWarningZoneApproach | sv::kWarningSpeedLimited), 0U);
    EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
    // Moving away: nothing.
    out = trolley_at(supervisor, 0.80, -0.2, seq);
    EXPECT_EQ(out.warnings & (sv::kWarningZoneApproach | sv::kWarningSpeedLimited), 0U);
  }
  // MAINTENANCE (ramp only, no shaper delay; plus the swing an unshaped stop excites, 0.2 / 3.1305
  // = 0.0639 m): at 0.80 m the soft stop's load reaches 0.884 m, at 0.87 m 0.954 m (warning).
  auto maintenance = supervisor_in_mode(p, sv::StatusCodes::OPERATION_MAINTENANCE);
  std::uint64_t seq = 1;
  auto out = trolley_at(maintenance, 0.80, 0.2, seq);
  EXPECT_EQ(out.warnings & (sv::kWarningZoneApproach | sv::kWarningSpeedLimited), 0U);
  out = trolley_at(maintenance, 0.87, 0.2, seq);
  EXPECT_TRUE(out.warnings & sv::kWarningZoneApproach);
  // FULLAUTOMATIC (the goal's profile, planned around the zones by the planner): ramp only, no
  // margin: at 0.80 m nothing where MANUAL warned.
  auto automatic = ready_supervisor(p);
  out = trolley_at(automatic, 0.80, 0.2, seq);
  EXPECT_EQ(out.operating_mode, sv::StatusCodes::OPERATION_FULLAUTOMATIC);
  EXPECT_EQ(out.warnings & (sv::kWarningZoneApproach | sv::kWarningSpeedLimited), 0U);
}

TEST(SupervisorZones, TheBrakeEnvelopeStopsTheCraneBeforeTheLoadEnters) {
  // MANUAL. At 0.2 m/s the brakes stop the trolley within 0.0201 m and the load swings on by at
  // most 0.2 / 3.1305 = 0.0639 m: 0.0840 m ahead; the brake margin is 1 cm.
  const auto p = zone_params();
  auto supervisor = supervisor_in_mode(p, sv::StatusCodes::OPERATION_MANUAL);
  std::uint64_t seq = 1;
  auto out = trolley_at(supervisor, 0.90, 0.2, seq);  // reaches 0.984 m
  EXPECT_EQ(out.active_faults, 0U);
  out = trolley_at(supervisor, 0.91, 0.2, seq);  // reaches 0.994 m: within the margin
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultZone));
  EXPECT_EQ(out.zone, 0);
  expect_stopped(out);
  EXPECT_STREQ(sv::fault_name(out.last_fault), "zone");
  // At rest beside the wall (inside the margin): no fault of its own, so the reset is taken.
  auto supervisor2 = supervisor_in_mode(p, sv::StatusCodes::OPERATION_MANUAL);
  out = trolley_at(supervisor2, 0.985, 0.0, seq);
  EXPECT_EQ(out.active_faults, 0U);
  // The swing counts: creeping at 0.02 m/s with the load swung 5 cm ahead of the trolley
  // (in-plane swing -0.05 rad: the load at x + L sin 0.05): it reaches 0.9402 + 0.0504 m.
  auto in = healthy_input();
  in.swing_in_plane = -0.05;
  in.sensor_seq = seq += 100000;
  in.trolley_position = 0.94;
  step(supervisor2, in);
  in.sensor_seq = ++seq;
  in.trolley_position = 0.9402;
  out = step(supervisor2, in);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultZone)) << "the load is 0.99 m out, moving";
}

TEST(SupervisorZones, AZoneSwitchedOffIsIgnoredAndOnAgainIsEnforced) {
  auto p = zone_params();
  auto supervisor = supervisor_in_mode(p, sv::StatusCodes::OPERATION_MANUAL);
  std::uint64_t seq = 1;
  auto in = with_command(healthy_input(), sv::Command::disable_zone);
  in.command_zone = 0;
  auto out = step(supervisor, in);
  EXPECT_FALSE(out.command_refused);
  EXPECT_EQ(out.zones_enabled, 0U);
  out = trolley_at(supervisor, 0.95, 0.3, seq);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_EQ(out.warnings & (sv::kWarningZoneApproach | sv::kWarningSpeedLimited), 0U);
  EXPECT_DOUBLE_EQ(out.trolley_voltage_limit, p.voltage_limit);
  in.command = sv::Command::enable_zone;
  EXPECT_EQ(step(supervisor, in).zones_enabled, 1U);
  out = trolley_at(supervisor, 0.95, 0.3, seq);
  EXPECT_EQ(out.active_faults, static_cast<std::uint32_t>(sv::kFaultZone));
  // Off in the configuration: ignored from the start.
  p.site.zones[0].enabled = false;
  auto off = ready_supervisor(p);
  out = trolley_at(off, 0.95, 0.3, seq);
  EXPECT_EQ(out.active_faults, 0U);
  EXPECT_EQ(out.zones_enabled, 0U);
}

// A trolley driven straight at the wall that does not slow down (the planner and the voltage limit
// ignored; MANUAL and MAINTENANCE in turn): the brakes stop it when the supervisor says so, at once (the largest swing a stop
// excites), and the load, a linear pendulum with a random free swing, never reaches the wall.
// Seeded random speeds, cable lengths, swing amplitudes and phases.
TEST(SupervisorZones, SeededRandomRunsAtTheWallStopBeforeTheLoadEnters) {
  std::mt19937 rng(kRandomSeed);
  std::uniform_real_distribution<double> speed(0.05, 0.9), cable(0.4, 1.9), amplitude(0.0, 0.06), phase(0.0, 6.283);
  constexpr int kRuns = 300;
  constexpr double dt = 0.01, g = 9.8;
  double closest = 1e9;
  int braked = 0;
  for (int run = 0; run < kRuns; ++run) {
    auto p = zone_params();
    const double L = cable(rng);
    const double w = std::sqrt(g / L);
    double v = speed(rng);
    const double a0 = amplitude(rng), ph = phase(rng);
    double u = a0 * std::cos(ph), ud = -a0 * w * std::sin(ph);  // load offset ahead of the trolley [m]
    double x = 0.2;
    auto supervisor = supervisor_in_mode(p, run % 2 == 0 ? sv::StatusCodes::OPERATION_MANUAL
                                                       : sv::StatusCodes::OPERATION_MAINTENANCE);
    bool stopped = false;
    for (std::uint64_t k = 0; k < 1500; ++k) {
      auto in = healthy_input();
      in.sensor_seq = 10 + k;
      in.trolley_position = x;
      in.cable_length = L;
      in.swing_in_plane = std::asin(-u / L);  // load x = trolley + u (site.hpp's convention)
      const auto out = step(supervisor, in);
      ASSERT_LT(x + u, 1.0) << "run " << run << ": the load entered at cycle " << k << " (v " << v << ", L " << L << ")";
      closest = std::min(closest, 1.0 - (x + u));
      if (!stopped && (out.active_faults & sv::kFaultZone) != 0) {
        stopped = true;
        ++braked;
        ud += v;  // the trolley stops at once: the load keeps its speed relative to it
        v = 0.0;
      }
      // Exact step of the free pendulum relative to a trolley at constant speed.
      const double c = std::cos(w * dt), s = std::sin(w * dt);
      const double u1 = u * c + ud / w * s;
      ud = -u * w * s + ud * c;
      u = u1;
      x += v * dt;
    }
    ASSERT_TRUE(stopped) << "run " << run;
  }
  std::printf("%d seeded runs at the wall at 0.05-0.9 m/s: %d braked by the supervisor, the load at least %.1f mm "
              "short of the wall\n", kRuns, braked, 1e3 * closest);
  EXPECT_GT(closest, 0.0);
}

TEST(SupervisorZones, ValidationNamesTheZoneFields) {
  sv::SupervisorParams params;
  params.zone_stop_delay_periods = 4.0;
  EXPECT_NE(config_error_message(params).find("supervisor.zone_stop_delay_periods"), std::string::npos)
      << config_error_message(params);
  params = {};
  params.zone_approach_margin = -0.1;
  EXPECT_NE(config_error_message(params).find("supervisor.zone_approach_margin"), std::string::npos);
  params = {};
  params.zone_brake_margin = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(config_error_message(params).find("supervisor.zone_brake_margin"), std::string::npos);
}

TEST(SupervisorZones, SwitchingAFixedZoneOffIsRefusedNamingIt) {
  auto p = zone_params();
  p.site.zones.push_back({"school yard", {{-1.0, -1.0}, {-0.5, -1.0}, {-0.5, -0.5}}, 0.0, 5.0, true, true});
  auto supervisor = ready_supervisor(p);
  auto in = with_command(healthy_input(), sv::Command::disable_zone);
  in.command_zone = 1;
  auto out = step(supervisor, in);
  EXPECT_TRUE(out.command_refused);
  EXPECT_EQ(out.zone_refusal, sv::ZoneRefusal::fixed);
  EXPECT_EQ(out.zones_enabled, 3U) << "still enforced";
  EXPECT_EQ(sv::describe(out.zone_refusal, p.site, 1),
            "site.zones[1] (school yard) is fixed: it stays enforced (switching it off is refused)");
  // Enabling it (already on) is taken; the other zone switches as before; an unknown index is named.
  in.command = sv::Command::enable_zone;
  out = step(supervisor, in);
  EXPECT_FALSE(out.command_refused);
  EXPECT_EQ(out.zone_refusal, sv::ZoneRefusal::none);
  in.command = sv::Command::disable_zone;
  in.command_zone = 0;
  out = step(supervisor, in);
  EXPECT_FALSE(out.command_refused);
  EXPECT_EQ(out.zones_enabled, 2U);
  in.command_zone = 7;
  out = step(supervisor, in);
  EXPECT_TRUE(out.command_refused);
  EXPECT_EQ(out.zone_refusal, sv::ZoneRefusal::no_such_zone);
  EXPECT_EQ(sv::describe(out.zone_refusal, p.site, 7), "no zone 7: site.zones has 2");
  // A fixed zone must be enabled: refused at start, naming it.
  p.site.zones[1].enabled = false;
  EXPECT_NE(config_error_message(p).find("site.zones[1] (school yard): fixed but not enabled"), std::string::npos)
      << config_error_message(p);
}
