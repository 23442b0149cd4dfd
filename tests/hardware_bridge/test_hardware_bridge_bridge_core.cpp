// BridgeCore: the safe-state rules, the watchdog timing at 100 Hz, command validation, clamping to
// the supervisor's limits, the emergency stop, and that step() never allocates.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <new>
#include <random>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/hardware_bridge/bridge_core.hpp"

// Counts every allocation of this test program (operator new replaced), to check step() makes none.
// GCC's -Wmismatched-new-delete cannot see that these replacements pair malloc with free.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* memory = std::malloc(size == 0 ? 1 : size)) return memory;
  throw std::bad_alloc();
}
void operator delete(void* memory) noexcept { std::free(memory); }
void operator delete(void* memory, std::size_t) noexcept { std::free(memory); }
#pragma GCC diagnostic pop

namespace crane::hardware_bridge {
namespace {

constexpr double kPeriod = 0.01;     // [s] 100 Hz
constexpr double kWatchdog = 0.030;  // [s]
constexpr double kStep = 20.0 / 8192.0;  // [V/code] the plant's 13-bit DAC over +-10 V
constexpr std::uint32_t kZeroVoltCode = 4096U;  // 0 V on that DAC (offset binary)
constexpr int kRandomTrials = 2000;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::array<AnalogRange, kAnalogOutputCount> plant_ranges() {
  const AnalogRange range = plant_dac_range(common::CraneParameters{});
  return {range, range, range, range};
}

SupervisorPermit permit(double trolley_limit = 10.0, double slew_limit = 10.0) {
  return SupervisorPermit{true, true, trolley_limit, slew_limit};
}

/// Cycle at `time` with a fresh permitting status (arrived at the cycle instant) and no command.
BridgeInput cycle(double time) {
  BridgeInput input;
  input.time = time;
  input.status_received = true;
  input.status = permit();
  input.status_arrival_time = time;
  return input;
}

/// The same with a command that arrived at `arrival`.
BridgeInput cycle_with_command(double time, common::DriveCommand command, double arrival) {
  BridgeInput input = cycle(time);
  input.command_received = true;
  input.command = command;
  input.command_arrival_time = arrival;
  return input;
}

constexpr common::DriveCommand kCommand{2.5, -1.0, 0.1};  // [V], [V], [m/s]

void expect_safe(const BridgeCore& core, const BridgeOutput& out, SafeStateReason reason) {
  EXPECT_EQ(out.safe_state_reason, reason) << reason_name(out.safe_state_reason);
  EXPECT_EQ(out.board, core.safe_outputs());
  EXPECT_TRUE(out.brakes_engaged);
  EXPECT_EQ(out.applied_trolley_voltage, 0.0);
  EXPECT_EQ(out.applied_slew_voltage, 0.0);
  EXPECT_EQ(out.applied_hoist_speed, 0.0);
}

TEST(BridgeCore, SafeOutputsAreZeroVoltsAndEverythingOff) {
  const BridgeCore core(BridgeParams{}, plant_ranges());
  for (const std::uint32_t code : core.safe_outputs().dac_codes) EXPECT_EQ(code, kZeroVoltCode);
  EXPECT_EQ(core.safe_outputs().digital_outputs, 0U);
  // On a 12-bit [-10, 10] V comedi range the nearest code to 0 V is 2048 (2047.5 rounds up).
  const AnalogRange twelve{-10.0, 10.0, 4095U};
  const BridgeCore other(BridgeParams{}, {twelve, twelve, twelve, twelve});
  for (const std::uint32_t code : other.safe_outputs().dac_codes) EXPECT_EQ(code, 2048U);
}

TEST(BridgeCore, SafeBeforeTheFirstCommand) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  for (int k = 0; k < 5; ++k) {
    EXPECT_EQ(core.step(cycle(k * kPeriod), out), CommandStatus::none_received);
    expect_safe(core, out, SafeStateReason::no_command_yet);
  }
  EXPECT_EQ(out.counters.safe_cycles, 5U);
  EXPECT_EQ(out.counters.cycles, 5U);
}

TEST(BridgeCore, AppliesAValidCommand) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  EXPECT_EQ(core.step(cycle_with_command(1.0, kCommand, 1.0), out), CommandStatus::accepted);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  EXPECT_FALSE(out.brakes_engaged);
  EXPECT_FALSE(out.clamped);
  EXPECT_EQ(out.board.digital_outputs, all_outputs_energized(kTowerCraneAxes));
  // Trolley 2.5 V = 1024 steps exactly: code 4096 + 1024.
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::trolley_drive)], 5120U);
  EXPECT_EQ(out.applied_trolley_voltage, 2.5);
  // Slew -1 V = -409.6 steps -> -410: code 3686, -1.0009765625 V.
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::slew_drive)], 3686U);
  EXPECT_EQ(out.applied_slew_voltage, -410.0 * kStep);
  // Hoist 0.1 m/s / 0.05 m/s/V = 2 V = 819.2 steps -> 819: code 4915; back to 819 * step * 0.05 m/s.
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::hoist_speed)], 4915U);
  EXPECT_DOUBLE_EQ(out.applied_hoist_speed, 819.0 * kStep * 0.05);
  EXPECT_EQ(out.counters.accepted_commands, 1U);
}

// An overhead crane (kOverheadCraneAxes): the gated bridge voltage goes to its own DAC output like
// the trolley's, its brake line is released with the others, and it is clamped to the supervisor's
// bridge limit and to the output's DAC range; it has no slew, whose output and brake line stay off.
TEST(BridgeCore, OverheadCraneDrivesTheBridgeOutput) {
  BridgeParams params;
  params.axes = kOverheadCraneAxes;
  BridgeCore core(params, plant_ranges());
  EXPECT_EQ(core.safe_outputs().dac_codes[index(AnalogOutput::bridge_drive)], kZeroVoltCode);
  BridgeOutput out;
  BridgeInput input = cycle_with_command(1.0, {2.5, -1.0, 0.0, -3.0}, 1.0);
  input.status.bridge_voltage_limit = 10.0;
  EXPECT_EQ(core.step(input, out), CommandStatus::accepted);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  EXPECT_FALSE(out.clamped);
  EXPECT_EQ(out.board.digital_outputs, all_outputs_energized(kOverheadCraneAxes));
  EXPECT_NE(out.board.digital_outputs & bit(DigitalOutput::brake_release_bridge), 0U);
  EXPECT_EQ(out.board.digital_outputs & bit(DigitalOutput::brake_release_slew), 0U);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::slew_drive)], kZeroVoltCode);
  EXPECT_EQ(out.applied_slew_voltage, 0.0);
  // -3 V = -1228.8 steps -> -1229: code 2867, -1229 steps.
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::bridge_drive)], 2867U);
  EXPECT_EQ(out.applied_bridge_voltage, -1229.0 * kStep);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::trolley_drive)], 5120U);  // the trolley as before

  // The supervisor's bridge limit: 1 V.
  input = cycle_with_command(1.01, {0.0, 0.0, 0.0, -3.0}, 1.01);
  input.status.bridge_voltage_limit = 1.0;
  EXPECT_EQ(core.step(input, out), CommandStatus::accepted);
  EXPECT_TRUE(out.clamped);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::bridge_drive)], kZeroVoltCode - 410U);  // -409.6 steps
  EXPECT_EQ(out.applied_bridge_voltage, -410.0 * kStep);

  // A bridge amplifier input of [-5, 5] V: 7 V ends at its top code, counted as clamped.
  auto ranges = plant_ranges();
  ranges[index(AnalogOutput::bridge_drive)] = AnalogRange{-5.0, 5.0, 4095U};
  BridgeCore narrow(params, ranges);
  input = cycle_with_command(2.0, {0.0, 0.0, 0.0, 7.0}, 2.0);
  input.status.bridge_voltage_limit = 10.0;
  EXPECT_EQ(narrow.step(input, out), CommandStatus::accepted);
  EXPECT_TRUE(out.clamped);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::bridge_drive)], 4095U);
  EXPECT_EQ(out.applied_bridge_voltage, 5.0);
  EXPECT_EQ(out.counters.clamped_cycles, 1U);

  // Safe state: 0 V and the bridge's brake engaged too.
  input.emergency_stop_pressed = true;
  (void)core.step(input, out);
  expect_safe(core, out, SafeStateReason::emergency_stop);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::bridge_drive)], kZeroVoltCode);
  EXPECT_EQ(out.board.digital_outputs & bit(DigitalOutput::brake_release_bridge), 0U);
  EXPECT_EQ(out.applied_bridge_voltage, 0.0);
}

// A tower crane (kTowerCraneAxes) never drives the bridge's output or brake line, whatever the
// command's bridge voltage and the supervisor's bridge limit say; that output's range is not used.
TEST(BridgeCore, TowerCraneLeavesTheBridgeOutputAtZero) {
  auto ranges = plant_ranges();
  ranges[index(AnalogOutput::bridge_drive)] = AnalogRange{1.0, 5.0, 4095U};  // would be refused on an overhead crane
  BridgeCore core(BridgeParams{}, ranges);
  BridgeOutput out;
  BridgeInput input = cycle_with_command(1.0, {2.5, -1.0, 0.1, 3.0}, 1.0);
  input.status.bridge_voltage_limit = 10.0;
  EXPECT_EQ(core.step(input, out), CommandStatus::accepted);
  EXPECT_FALSE(out.clamped);
  EXPECT_EQ(out.board.digital_outputs, all_outputs_energized(kTowerCraneAxes));
  EXPECT_EQ(out.board.digital_outputs & bit(DigitalOutput::brake_release_bridge), 0U);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::bridge_drive)], core.safe_outputs().dac_codes[3]);
  EXPECT_EQ(out.applied_bridge_voltage, 0.0);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::trolley_drive)], 5120U);
}

// A gantry crane (kGantryCraneAxes) has neither a slew nor a bridge: their outputs stay at 0 V and
// their brake lines at 0 whatever the command says, and their ranges are not used; the trolley,
// the hoist and the drive enable work as on the tower crane.
TEST(BridgeCore, GantryCraneLeavesTheSlewAndBridgeOutputsAtZero) {
  auto ranges = plant_ranges();
  ranges[index(AnalogOutput::slew_drive)] = AnalogRange{1.0, 5.0, 4095U};  // would be refused on a tower crane
  ranges[index(AnalogOutput::bridge_drive)] = AnalogRange{1.0, 5.0, 4095U};
  BridgeParams params;
  params.axes = kGantryCraneAxes;
  BridgeCore core(params, ranges);
  BridgeOutput out;
  BridgeInput input = cycle_with_command(1.0, {2.5, -1.0, 0.1, 3.0}, 1.0);
  input.status.bridge_voltage_limit = 10.0;
  EXPECT_EQ(core.step(input, out), CommandStatus::accepted);
  EXPECT_EQ(out.board.digital_outputs, bit(DigitalOutput::brake_release_trolley) |
                                           bit(DigitalOutput::brake_release_hoist) | bit(DigitalOutput::drive_enable));
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::slew_drive)], core.safe_outputs().dac_codes[1]);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::bridge_drive)], core.safe_outputs().dac_codes[3]);
  EXPECT_EQ(out.applied_slew_voltage, 0.0);
  EXPECT_EQ(out.applied_bridge_voltage, 0.0);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::trolley_drive)], 5120U);
  EXPECT_EQ(out.board.dac_codes[index(AnalogOutput::hoist_speed)], 4915U);
}

// Watchdog at 100 Hz, W = 30 ms, cycle instants t_k = k * 10 ms. The outputs written at t stay until
// t + 10 ms, so the command arriving at a may be written at t only if (t - a) + 10 ms <= 30 ms:
//   a = t_100 exactly:         written at t_100, t_101, t_102; safe at t_103 = a + 30 ms;
//   a = t_100 - 2 ms:          (t_102 - a) + 10 = 32 ms > 30: safe at t_102 = a + 22 ms;
//   a = t_100 - 9.9 ms:        (t_101 - a) + 10 = 29.9 ms ok; safe at t_102 = a + 29.9 ms.
TEST(BridgeCore, WatchdogTimingAtOneHundredHertz) {
  struct Case {
    double arrival_before_cycle;  // [s] a = t_100 - this
    int last_applied_cycle;       // k of the last cycle still applying the command
  };
  for (const Case c : {Case{0.0, 102}, Case{0.002, 101}, Case{0.0099, 101}}) {
    BridgeCore core(BridgeParams{}, plant_ranges());
    BridgeOutput out;
    const double arrival = 100 * kPeriod - c.arrival_before_cycle;
    (void)core.step(cycle_with_command(100 * kPeriod, kCommand, arrival), out);
    for (int k = 100; k < 110; ++k) {
      if (k > 100) (void)core.step(cycle(k * kPeriod), out);
      if (k <= c.last_applied_cycle) {
        ASSERT_EQ(out.safe_state_reason, SafeStateReason::none) << "k " << k;
        ASSERT_EQ(out.board.dac_codes[0], 5120U);
      } else {
        expect_safe(core, out, SafeStateReason::watchdog);
        if (k == c.last_applied_cycle + 1) {
          ASSERT_LE(k * kPeriod, arrival + kWatchdog + 1e-9) << "safe state too late";
        }
      }
    }
    EXPECT_EQ(out.counters.watchdog_trips, 1U);
  }
}

// Random arrival times and cycle phases (seeded): the safe state is written at the first cycle
// instant t_s with t_s <= a + W (never later), and holding the command there would have kept it on
// the outputs past a + W (never earlier than needed). Every earlier cycle applied the command.
TEST(BridgeCore, WatchdogNeverLateNeverEarlyRandomized) {
  std::mt19937 rng(41);
  std::uniform_real_distribution<double> phase(0.0, kPeriod);
  std::uniform_real_distribution<double> lead(0.0, kPeriod);
  for (int trial = 0; trial < kRandomTrials; ++trial) {
    BridgeCore core(BridgeParams{}, plant_ranges());
    BridgeOutput out;
    const double t0 = 5.0 + phase(rng);         // first cycle instant
    const double arrival = t0 - lead(rng);      // arrived since the previous cycle
    (void)core.step(cycle_with_command(t0, kCommand, arrival), out);
    ASSERT_EQ(out.safe_state_reason, SafeStateReason::none);
    double safe_at = -1.0;
    for (int k = 1; k < 10; ++k) {
      const double t = t0 + k * kPeriod;
      (void)core.step(cycle(t), out);
      if (out.safe_state_reason != SafeStateReason::none) {
        ASSERT_EQ(out.safe_state_reason, SafeStateReason::watchdog);
        safe_at = t;
        break;
      }
    }
    ASSERT_GT(safe_at, 0.0);
    ASSERT_LE(safe_at, arrival + kWatchdog + 1e-9) << "trial " << trial;
    ASSERT_GT(safe_at + kPeriod, arrival + kWatchdog - 1e-9) << "trial " << trial << ": tripped a cycle early";
  }
}

// Commands every 3rd cycle arriving at the cycle instant are at most 20 ms old when written, 30 ms at
// the end of their hold: never safe. Every 4th cycle: 30 ms old at the 4th, so every 4th cycle is safe.
TEST(BridgeCore, FreshCommandsKeepTheWatchdogQuiet) {
  for (const int every : {1, 2, 3, 4}) {
    BridgeCore core(BridgeParams{}, plant_ranges());
    BridgeOutput out;
    int safe_cycles = 0;
    for (int k = 0; k < 400; ++k) {
      const double t = 1.0 + k * kPeriod;
      if (k % every == 0) {
        (void)core.step(cycle_with_command(t, kCommand, t), out);
      } else {
        (void)core.step(cycle(t), out);
      }
      if (out.safe_state_reason != SafeStateReason::none) {
        ++safe_cycles;
        EXPECT_EQ(out.safe_state_reason, SafeStateReason::watchdog);
        EXPECT_EQ(k % every, 3) << "only the 4th cycle after a command is too late";
      }
    }
    EXPECT_EQ(safe_cycles, every == 4 ? 100 : 0) << "every " << every;
    EXPECT_EQ(out.counters.watchdog_trips, static_cast<std::uint64_t>(every == 4 ? 100 : 0));
  }
}

TEST(BridgeCore, RejectedCommandsAreCountedAndDoNotFeedTheWatchdog) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(core.step(cycle_with_command(1.00, kCommand, 1.00), out), CommandStatus::accepted);
  // t = 1.01: NaN trolley voltage; the previous command stays applied.
  EXPECT_EQ(core.step(cycle_with_command(1.01, {kNan, 0.0, 0.0}, 1.01), out), CommandStatus::rejected_non_finite);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  EXPECT_EQ(out.board.dac_codes[0], 5120U);
  // t = 1.02: Inf slew voltage.
  EXPECT_EQ(core.step(cycle_with_command(1.02, {0.0, -kInf, 0.0}, 1.02), out), CommandStatus::rejected_non_finite);
  // t = 1.03: a NaN arrival time is as bad; the command of t = 1.00 is now too old.
  EXPECT_EQ(core.step(cycle_with_command(1.03, {0.0, 0.0, 0.0}, kNan), out), CommandStatus::rejected_non_finite);
  expect_safe(core, out, SafeStateReason::watchdog);
  EXPECT_EQ(out.counters.rejected_commands.non_finite, 3U);
  // Out of the hard ranges: 10 V and 0.5 m/s by default.
  EXPECT_EQ(core.step(cycle_with_command(1.04, {10.5, 0.0, 0.0}, 1.04), out), CommandStatus::rejected_out_of_range);
  EXPECT_EQ(core.step(cycle_with_command(1.05, {0.0, -10.01, 0.0}, 1.05), out), CommandStatus::rejected_out_of_range);
  EXPECT_EQ(core.step(cycle_with_command(1.06, {0.0, 0.0, 0.6}, 1.06), out), CommandStatus::rejected_out_of_range);
  expect_safe(core, out, SafeStateReason::watchdog);
  EXPECT_EQ(out.counters.rejected_commands.out_of_range, 3U);
  EXPECT_EQ(out.counters.accepted_commands, 1U);
  // Exactly at the hard range is valid; the DAC's top code is 10 V - 1 step, so it is clamped.
  EXPECT_EQ(core.step(cycle_with_command(1.07, {10.0, -10.0, 0.5}, 1.07), out), CommandStatus::accepted);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  EXPECT_EQ(out.board.dac_codes[0], 8191U);
  EXPECT_EQ(out.board.dac_codes[1], 0U);
  EXPECT_EQ(out.board.dac_codes[2], 8191U);  // 0.5 m/s = 10 V
  EXPECT_TRUE(out.clamped);
}

TEST(BridgeCore, ClampsToTheSupervisorsCurrentLimits) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  BridgeInput input = cycle_with_command(1.0, {5.0, -4.0, 0.0}, 1.0);
  input.status = permit(3.0, 1.5);
  (void)core.step(input, out);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  EXPECT_TRUE(out.clamped);
  // 3 V = 1228.8 steps -> 1229; -1.5 V = -614.4 steps -> -614.
  EXPECT_EQ(out.board.dac_codes[0], 4096U + 1229U);
  EXPECT_EQ(out.board.dac_codes[1], 4096U - 614U);
  EXPECT_NEAR(out.applied_trolley_voltage, 3.0, 0.5 * kStep);
  EXPECT_NEAR(out.applied_slew_voltage, -1.5, 0.5 * kStep);
  EXPECT_EQ(out.counters.clamped_cycles, 1U);
  // A lower limit takes effect on the held command at the next cycle.
  input = cycle(1.01);
  input.status = permit(1.0, 1.5);
  (void)core.step(input, out);
  EXPECT_NEAR(out.applied_trolley_voltage, 1.0, 0.5 * kStep);
  // Within the limits: not clamped.
  input = cycle_with_command(1.02, {0.5, 0.5, 0.0}, 1.02);
  input.status = permit(1.0, 1.0);
  (void)core.step(input, out);
  EXPECT_FALSE(out.clamped);
  EXPECT_EQ(out.counters.clamped_cycles, 2U);
}

// Status age: at t with arrival s, usable if (t - s) + 10 ms <= 30 ms, i.e. up to 20 ms old.
TEST(BridgeCore, SupervisorStatusRules) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  (void)core.step(cycle_with_command(1.0, kCommand, 1.0), out);
  ASSERT_EQ(out.safe_state_reason, SafeStateReason::none);

  BridgeInput input = cycle_with_command(1.01, kCommand, 1.01);
  input.status_received = false;
  (void)core.step(input, out);
  expect_safe(core, out, SafeStateReason::supervisor_status_stale);

  input = cycle_with_command(1.02, kCommand, 1.02);
  input.status_arrival_time = 1.02 - 0.020;
  (void)core.step(input, out);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  input = cycle_with_command(1.03, kCommand, 1.03);
  input.status_arrival_time = 1.03 - 0.021;
  (void)core.step(input, out);
  expect_safe(core, out, SafeStateReason::supervisor_status_stale);

  for (const double bad_limit : {std::nan(""), -1.0, std::numeric_limits<double>::infinity()}) {
    input = cycle_with_command(1.04, kCommand, 1.04);
    input.status.slew_voltage_limit = bad_limit;
    (void)core.step(input, out);
    expect_safe(core, out, SafeStateReason::supervisor_status_stale);
  }

  input = cycle_with_command(1.05, kCommand, 1.05);
  input.status.motion_enabled = false;
  (void)core.step(input, out);
  expect_safe(core, out, SafeStateReason::motion_disabled);
  input.status.motion_enabled = true;
  input.status.brakes_released = false;
  (void)core.step(input, out);
  expect_safe(core, out, SafeStateReason::motion_disabled);

  // A zero limit is valid: brakes released, 0 V.
  input = cycle_with_command(1.06, kCommand, 1.06);
  input.status = permit(0.0, 0.0);
  (void)core.step(input, out);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  EXPECT_EQ(out.applied_trolley_voltage, 0.0);
  EXPECT_FALSE(out.brakes_engaged);
}

TEST(BridgeCore, EmergencyStopIsImmediateAndLatchedUntilALaterPermit) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  (void)core.step(cycle_with_command(1.00, kCommand, 1.00), out);
  ASSERT_EQ(out.safe_state_reason, SafeStateReason::none);
  // Pressed at t = 1.01, with a fresh command and a permitting status: safe this very cycle.
  BridgeInput input = cycle_with_command(1.01, kCommand, 1.01);
  input.emergency_stop_pressed = true;
  EXPECT_EQ(core.step(input, out), CommandStatus::accepted);
  expect_safe(core, out, SafeStateReason::emergency_stop);
  // Released at t = 1.02; the status that arrived at 1.015 may predate the supervisor seeing the
  // stop (not more than one period after the last pressed cycle): still stopped.
  input = cycle_with_command(1.02, kCommand, 1.02);
  input.status_arrival_time = 1.015;
  (void)core.step(input, out);
  expect_safe(core, out, SafeStateReason::emergency_stop);
  // A permit that arrived at 1.0201 (> 1.01 + 10 ms) releases it.
  input = cycle_with_command(1.03, kCommand, 1.03);
  input.status_arrival_time = 1.0201;
  (void)core.step(input, out);
  EXPECT_EQ(out.safe_state_reason, SafeStateReason::none);
  EXPECT_EQ(out.counters.emergency_stop_cycles, 2U);
  // The stop outranks every other reason.
  input = cycle(1.04);
  input.status_received = false;
  input.emergency_stop_pressed = true;
  (void)core.step(input, out);
  expect_safe(core, out, SafeStateReason::emergency_stop);
}

TEST(BridgeCore, ResetForgetsTheCommand) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  (void)core.step(cycle_with_command(1.0, kCommand, 1.0), out);
  core.reset();
  (void)core.step(cycle(1.01), out);
  expect_safe(core, out, SafeStateReason::no_command_yet);
  EXPECT_EQ(out.counters.cycles, 2U);  // counters are kept
}

TEST(BridgeCore, StepNeverAllocatesNorThrows) {
  BridgeCore core(BridgeParams{}, plant_ranges());
  BridgeOutput out;
  BridgeInput input = cycle_with_command(1.0, kCommand, 1.0);
  static_assert(noexcept(core.step(input, out)));
  const long before = g_allocations.load();
  for (int k = 0; k < 1000; ++k) {
    input = (k % 5 == 0) ? cycle_with_command(1.0 + k * kPeriod, {std::nan(""), 1.0, 0.0}, 1.0 + k * kPeriod)
                         : cycle_with_command(1.0 + k * kPeriod, kCommand, 1.0 + k * kPeriod);
    input.emergency_stop_pressed = (k % 7 == 0);
    (void)core.step(input, out);
  }
  EXPECT_EQ(g_allocations.load(), before);
}

TEST(BridgeCore, ParametersAndRangesAreValidated) {
  const auto error_of = [](const BridgeParams& params, const std::array<AnalogRange, kAnalogOutputCount>& ranges) {
    try {
      const BridgeCore core(params, ranges);
    } catch (const common::ConfigError& error) {
      return std::string(error.what());
    }
    return std::string();
  };
  EXPECT_EQ(error_of(BridgeParams{}, plant_ranges()), "");
  BridgeParams p;
  p.gate.watchdog_timeout = 0.0;
  EXPECT_TRUE(contains(error_of(p, plant_ranges()), "actuation.watchdog_timeout = 0 is out of range: must be in "
                                                    "[0.01, 1]"))
      << error_of(p, plant_ranges());
  p.gate.watchdog_timeout = 1.5;
  EXPECT_TRUE(contains(error_of(p, plant_ranges()), "actuation.watchdog_timeout = 1.5")) << error_of(p, plant_ranges());
  p = BridgeParams{};
  p.gate.status_timeout = 0.005;  // shorter than one period: the bridge could never drive
  EXPECT_TRUE(contains(error_of(p, plant_ranges()), "actuation.status_timeout = 0.005")) << error_of(p, plant_ranges());
  p = BridgeParams{};
  p.gate.sample_period = 0.0;
  EXPECT_TRUE(contains(error_of(p, plant_ranges()), "actuation.sample_period = 0")) << error_of(p, plant_ranges());
  p = BridgeParams{};
  p.hoist_speed_per_volt = -0.1;
  EXPECT_TRUE(contains(error_of(p, plant_ranges()), "hardware_bridge.hoist_speed_per_volt = -0.1"));
  p = BridgeParams{};
  p.gate.max_drive_voltage = std::nan("");
  EXPECT_TRUE(contains(error_of(p, plant_ranges()), "actuation.max_drive_voltage = nan"))
      << error_of(p, plant_ranges());

  auto ranges = plant_ranges();
  ranges[index(AnalogOutput::slew_drive)] = AnalogRange{1.0, 5.0, 4095U};  // 0 V is not on this output
  EXPECT_TRUE(contains(error_of(BridgeParams{}, ranges), "analog_range.slew_drive.min_volts = 1"))
      << error_of(BridgeParams{}, ranges);
  ranges = plant_ranges();
  ranges[index(AnalogOutput::hoist_speed)].maxdata = 0;
  EXPECT_TRUE(contains(error_of(BridgeParams{}, ranges), "analog_range.hoist_speed")) << error_of(BridgeParams{}, ranges);
  // The bridge's output range matters on an overhead crane only.
  ranges = plant_ranges();
  ranges[index(AnalogOutput::bridge_drive)] = AnalogRange{0.5, 10.0, 8191U};
  EXPECT_EQ(error_of(BridgeParams{}, ranges), "");
  p = BridgeParams{};
  p.axes = kOverheadCraneAxes;
  EXPECT_TRUE(contains(error_of(p, ranges), "analog_range.bridge_drive.min_volts = 0.5")) << error_of(p, ranges);
}

}  // namespace
}  // namespace crane::hardware_bridge
