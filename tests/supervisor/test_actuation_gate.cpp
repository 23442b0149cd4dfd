// The actuation gate (supervisor/actuation_gate.hpp) through the fault sequences of the
// fault-injection tests (tests/fault_injection: a chain stage killed, the supervisor killed, rogue
// commands, the travel limit, a second sensor writer, the emergency stop; the lockstep dead stage),
// without DDS. Each sequence runs through three consumers of the one gate: the gate itself, the
// simulated plant (plant::PlantStage) and the hardware bridge's output logic
// (hardware_bridge::BridgeCore); they must decide the same every cycle (same reason, same brakes)
// and drive the same voltages (the bridge's within one DAC code: it writes codes).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/hardware_bridge/bridge_core.hpp"
#include "crane/hardware_bridge/conversions.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/supervisor/actuation_gate.hpp"

namespace {

using namespace crane;
using supervisor::GateInput;
using supervisor::SafeStateReason;

constexpr double kPeriod = 0.01;    // [s] T
constexpr double kWatchdog = 0.03;  // [s] actuation.watchdog_timeout of the lab configuration
constexpr double kStatus = 0.03;    // [s] actuation.status_timeout

supervisor::ActuationGateParams gate_params() {
  supervisor::ActuationGateParams p;
  p.sample_period = kPeriod;
  p.watchdog_timeout = kWatchdog;
  p.status_timeout = kStatus;
  p.max_drive_voltage = 10.0;
  p.hoist_speed_limit = 0.5;
  return p;
}

supervisor::SupervisorPermit permit(double trolley_limit = 10.0, double slew_limit = 10.0) {
  return {true, true, trolley_limit, slew_limit};
}

// One cycle's decision by each of the three.
struct Decision {
  SafeStateReason reason;
  bool brakes;
  double trolley_voltage;  // [V] what the drive gets (the bridge: the volts of the code it writes)
  double slew_voltage;     // [V]
};

// The three consumers of the gate, fed the same inputs.
class ThreeGates {
 public:
  ThreeGates()
      : gate_(gate_params()),
        plant_([] {
          plant::PlantStageParams p;
          p.simulator.initial_state.trolley_position = 0.6;
          p.gate = gate_params();
          return p;
        }()),
        bridge_(
            [] {
              hardware_bridge::BridgeParams p;
              p.gate = gate_params();
              return p;
            }(),
            [] {
              const auto range = hardware_bridge::plant_dac_range(common::CraneParameters{});
              return std::array<hardware_bridge::AnalogRange, hardware_bridge::kAnalogOutputCount>{range, range, range, range};
            }()),
        dac_step_(hardware_bridge::code_step_volts(hardware_bridge::plant_dac_range(common::CraneParameters{}))) {}

  /// Steps all three; checks they agree; returns the gate's decision.
  Decision step(const GateInput& in, const std::string& where) {
    supervisor::GateOutput g;
    gate_.step(in, g);
    EXPECT_EQ(plant_.step(in), common::StepStatus::ok) << where;
    hardware_bridge::BridgeOutput b;
    (void)bridge_.step(in, b);
    const auto& p = plant_.gate_output();
    EXPECT_EQ(p.reason, g.reason) << where;
    EXPECT_EQ(b.safe_state_reason, g.reason) << where << ": " << supervisor::reason_name(b.safe_state_reason);
    EXPECT_EQ(p.brakes_engaged, g.brakes_engaged) << where;
    EXPECT_EQ(b.brakes_engaged, g.brakes_engaged) << where;
    EXPECT_EQ(p.drive.trolley_voltage, g.drive.trolley_voltage) << where;
    EXPECT_EQ(p.drive.slew_voltage, g.drive.slew_voltage) << where;
    EXPECT_NEAR(b.applied_trolley_voltage, g.drive.trolley_voltage, dac_step_) << where;
    EXPECT_NEAR(b.applied_slew_voltage, g.drive.slew_voltage, dac_step_) << where;
    // The plant reports what it applied over the cycle (after its own DAC): the same code.
    protocol::SensorSample s;
    plant_.sample(s);
    EXPECT_NEAR(s.applied_trolley_voltage, b.applied_trolley_voltage, 1e-12) << where;
    EXPECT_EQ(s.brakes_engaged, b.brakes_engaged) << where;
    return {g.reason, g.brakes_engaged, g.drive.trolley_voltage, g.drive.slew_voltage};
  }

  const supervisor::GateCounters& counters() const { return gate_.counters(); }
  const supervisor::GateCounters& bridge_counters() const { return bridge_.counters(); }

 private:
  supervisor::ActuationGate gate_;
  plant::PlantStage plant_;
  hardware_bridge::BridgeCore bridge_;
  double dac_step_;
};

/// A healthy realtime cycle k: the command of cycle k arrived `delay` [s] after the cycle's sample,
/// the status at the cycle instant, both before the outputs are written at t = k T + delay.
GateInput healthy(int k, double delay, common::DriveCommand command = {1.5, -0.8, 0.0}) {
  GateInput in;
  in.time = k * kPeriod + delay;
  in.command_received = true;
  in.command = command;
  in.command_arrival_time = in.time;
  in.status_received = true;
  in.status = permit();
  in.status_arrival_time = k * kPeriod;
  return in;
}

// kill -9 of a chain stage in mid-move: the commands stop. Both consumers brake at the first cycle
// instant t > a + watchdog_timeout - T, a the last command's arrival (the fault-injection figure:
// brakes and 0 V 28-29 ms after the last good command), with random arrival jitter.
TEST(ActuationGate, StageKilledMidMoveBrakesBothAtTheWatchdog) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> jitter(0.0002, 0.004);
  for (int trial = 0; trial < 20; ++trial) {
    ThreeGates gates;
    GateInput in;
    for (int k = 0; k < 40; ++k) {
      in = healthy(k, jitter(rng));
      ASSERT_EQ(gates.step(in, "healthy " + std::to_string(k)).reason, SafeStateReason::none);
    }
    const double last_arrival = in.command_arrival_time;
    bool braked = false;
    for (int k = 40; k < 50; ++k) {
      GateInput silent = in;
      silent.time = k * kPeriod + 0.001;
      silent.command_received = false;
      silent.status_arrival_time = k * kPeriod;  // the supervisor still speaks
      const auto d = gates.step(silent, "silent " + std::to_string(k));
      const bool due = silent.time > last_arrival + kWatchdog - kPeriod + 1e-9;
      EXPECT_EQ(d.brakes, due) << "cycle " << k << ", " << (silent.time - last_arrival) * 1e3 << " ms after the last command";
      if (due) {
        EXPECT_EQ(d.reason, SafeStateReason::watchdog);
        EXPECT_EQ(d.trolley_voltage, 0.0);
        if (!braked) {
          EXPECT_LE(silent.time - last_arrival, kWatchdog + 1e-9);  // the first: never after the timeout
        }
        braked = true;
      }
    }
    EXPECT_TRUE(braked);
    EXPECT_EQ(gates.counters().watchdog_trips, 1U);
  }
}

// kill -9 of the supervisor in mid-move: its status stops (figure: outputs safe 17.5 ms after the
// kill, within status timeout + one cycle).
TEST(ActuationGate, SupervisorKilledMidMoveBrakesBothWhenItsStatusIsStale) {
  ThreeGates gates;
  for (int k = 0; k < 30; ++k) ASSERT_EQ(gates.step(healthy(k, 0.001), "healthy").reason, SafeStateReason::none);
  const double last_status = 29 * kPeriod;
  for (int k = 30; k < 36; ++k) {
    GateInput in = healthy(k, 0.001);
    in.status_arrival_time = last_status;  // the last status it ever sent
    const auto d = gates.step(in, "no status " + std::to_string(k));
    const bool due = in.time > last_status + kStatus - kPeriod + 1e-9;
    EXPECT_EQ(d.brakes, due) << "cycle " << k;
    if (due) {
      EXPECT_EQ(d.reason, SafeStateReason::supervisor_status_stale);
    }
  }
}

// 50 non-finite and 50 out-of-range rogue commands: each is rejected where it enters and changes
// nothing (the last valid command stays in force until the watchdog).
TEST(ActuationGate, RogueCommandsAreRejectedAndChangeNothing) {
  ThreeGates gates;
  ASSERT_EQ(gates.step(healthy(0, 0.001, {2.0, 1.0, 0.1}), "good").reason, SafeStateReason::none);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const common::DriveCommand rogues[] = {{nan, 0.0, 0.0}, {0.0, INFINITY, 0.0}, {10.5, 0.0, 0.0}, {0.0, -10.01, 0.0},
                                         {0.0, 0.0, 0.6}};
  int k = 1;
  for (const auto& rogue : rogues) {
    const auto d = gates.step(healthy(k, 0.0, rogue), "rogue " + std::to_string(k));
    ++k;
    if (d.brakes) {
      EXPECT_EQ(d.reason, SafeStateReason::watchdog);  // the good command aged out meanwhile
    } else {
      EXPECT_EQ(d.trolley_voltage, 2.0);  // still the last valid command
      EXPECT_EQ(d.slew_voltage, 1.0);
    }
  }
  EXPECT_EQ(gates.counters().rejected_commands.non_finite, 2U);
  EXPECT_EQ(gates.counters().rejected_commands.out_of_range, 3U);
  EXPECT_EQ(gates.bridge_counters().rejected_commands.non_finite, 2U);
  EXPECT_EQ(gates.counters().accepted_commands, 1U);
}

// The travel limit: in the approach zone the supervisor lowers the trolley's limit to
// approach_voltage_limit (both consumers clamp to it), then stops the crane (motion disabled).
TEST(ActuationGate, TravelLimitClampsThenStopsBoth) {
  ThreeGates gates;
  GateInput in = healthy(0, 0.001, {4.0, -3.0, 0.0});
  in.status = permit(0.5, 10.0);
  auto d = gates.step(in, "approach");
  EXPECT_EQ(d.reason, SafeStateReason::none);
  EXPECT_EQ(d.trolley_voltage, 0.5);
  EXPECT_EQ(d.slew_voltage, -3.0);
  EXPECT_EQ(gates.counters().clamped_cycles, 1U);
  in = healthy(1, 0.001, {4.0, -3.0, 0.0});
  in.status.motion_enabled = false;  // protective stop (fault trolley_travel)
  in.status.brakes_released = false;
  d = gates.step(in, "stop");
  EXPECT_EQ(d.reason, SafeStateReason::motion_disabled);
  EXPECT_TRUE(d.brakes);
}

// A second writer on the sensors topic: the supervisor faults and disables motion; a status with a
// non-finite limit is as good as none.
TEST(ActuationGate, SupervisorFaultOrCorruptStatusBrakesBoth) {
  ThreeGates gates;
  GateInput in = healthy(0, 0.001);
  in.status.motion_enabled = false;
  EXPECT_EQ(gates.step(in, "fault").reason, SafeStateReason::motion_disabled);
  in = healthy(1, 0.001);
  in.status.trolley_voltage_limit = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(gates.step(in, "corrupt").reason, SafeStateReason::supervisor_status_stale);
  in = healthy(2, 0.001);
  in.status_received = false;
  EXPECT_EQ(gates.step(in, "none yet").reason, SafeStateReason::supervisor_status_stale);
}

// The emergency stop input: safe in the cycle it is seen, latched until a permitting status that
// was computed after the supervisor saw the stop (arrived more than one period later).
TEST(ActuationGate, EmergencyStopIsImmediateAndLatchedUntilALaterPermit) {
  ThreeGates gates;
  ASSERT_EQ(gates.step(healthy(0, 0.001), "before").reason, SafeStateReason::none);
  GateInput in = healthy(1, 0.001);
  in.emergency_stop_pressed = true;
  EXPECT_EQ(gates.step(in, "pressed").reason, SafeStateReason::emergency_stop);
  in = healthy(2, 0.001);  // released; the status of cycle 2 arrived at 0.02, not after 0.011 + T
  in.status_arrival_time = 0.0205;
  EXPECT_EQ(gates.step(in, "released, old permit").reason, SafeStateReason::emergency_stop);
  in = healthy(3, 0.001);
  in.status_arrival_time = 0.0305;  // computed after the stop was seen
  EXPECT_EQ(gates.step(in, "new permit").reason, SafeStateReason::none);
  EXPECT_EQ(gates.counters().emergency_stop_cycles, 2U);
}

// Lockstep: a cycle runs with its own command gated by the status of the cycle before; a dead stage
// (stage_silent latched) lets it run without a command, braked; any other missing command waits.
TEST(ActuationGate, LockstepRulesAreOnePlace) {
  EXPECT_EQ(supervisor::gating_cycle(0), 0U);
  EXPECT_EQ(supervisor::gating_cycle(7), 6U);
  protocol::SupervisorStatus status;
  status.motion_enabled = true;
  status.brakes_released = true;
  status.trolley_voltage_limit = status.slew_voltage_limit = 10.0;
  EXPECT_TRUE(supervisor::lockstep_may_run(true, status));
  EXPECT_FALSE(supervisor::lockstep_may_run(false, status));  // waits for its command: nothing is guessed
  ThreeGates gates;
  protocol::ActuatorCommand command;
  command.trolley_voltage = 1.25;
  for (std::uint64_t k = 0; k < 5; ++k) {
    const auto d = gates.step(supervisor::lockstep_gate_input(k, kPeriod, &command, status), "lockstep");
    EXPECT_EQ(d.reason, SafeStateReason::none);
    EXPECT_EQ(d.trolley_voltage, 1.25);
  }
  status.latched_faults = protocol::SupervisorStatus::FAULT_STAGE_SILENT;
  status.motion_enabled = false;
  status.brakes_released = false;
  ASSERT_TRUE(supervisor::lockstep_may_run(false, status));
  const auto d = gates.step(supervisor::lockstep_gate_input(5, kPeriod, nullptr, status), "dead stage");
  EXPECT_EQ(d.reason, SafeStateReason::motion_disabled);
  EXPECT_TRUE(d.brakes);
}

TEST(ActuationGate, ParametersAreValidatedByName) {
  auto p = gate_params();
  p.watchdog_timeout = 0.005;  // shorter than a period: the drives could never be driven
  try {
    supervisor::ActuationGate gate(p);
    ADD_FAILURE() << "no ConfigError";
  } catch (const common::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("actuation.watchdog_timeout = 0.005"), std::string::npos) << error.what();
  }
}

}  // namespace
