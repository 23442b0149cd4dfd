#pragma once
// Safety supervisor core: modes, brakes, travel and voltage limits, stage watchdogs.
//
// Pure logic (no DDS, no clock): the node feeds it what it observed of every stage of the chain and
// the latest sensor and actuator values; it answers whether drives may be energized and brakes
// opened. Modes follow the OPC UA for Cranes and Hoists vocabulary where it fits (standby, ready,
// operating, fault, emergency stop).
//
// Rules (docs/architecture.md, "Safety"):
//  - brakes released and motion enabled only in ready/operating, and only while every stage of the
//    chain is alive (liveliness asserted and a sample received within stage_timeout);
//  - the moment a stage goes silent, a limit is exceeded or a non-finite value arrives: fault, brakes
//    engaged, drives at zero; the fault stays latched until an explicit reset with a healthy chain;
//  - an emergency stop engages the brakes at once and needs a reset.

#include <array>
#include <cstdint>

namespace crane::supervisor {

/// Stages of the chain the supervisor watches, in data-flow order.
enum class Stage : std::uint8_t {
  sensors = 0,          // plant or hardware bridge
  state_estimator = 1,
  trajectory_planner = 2,
  anti_swing = 3,
  tracking = 4,
  friction_compensation = 5,  // the actuator command
};
inline constexpr std::size_t kStageCount = 6;
[[nodiscard]] const char* stage_name(Stage stage) noexcept;

enum class Mode : std::uint8_t { starting = 0, standby = 1, ready = 2, operating = 3, fault = 4, emergency_stop = 5 };
[[nodiscard]] const char* mode_name(Mode mode) noexcept;

/// Fault codes: one bit each in SupervisorStatus_.active_faults / latched_faults.
enum Fault : std::uint32_t {
  kFaultStageSilent = 1U << 0,          // a stage of the chain stopped publishing or lost liveliness
  kFaultTrolleyTravel = 1U << 1,        // trolley position outside [trolley_min, trolley_max]
  kFaultVoltage = 1U << 2,              // an actuator command beyond the voltage limit
  kFaultNonFinite = 1U << 3,            // NaN or Inf arrived on a watched topic
  kFaultEmergencyStop = 1U << 4,        // emergency stop commanded or input pressed
  kFaultMultipleSensorWriters = 1U << 5,  // more than one writer on rt/crane/hw/sensors
  kFaultSwing = 1U << 6,                // swing angle beyond max_swing
};

struct SupervisorParams {
  double trolley_min{0.05};          // [m] hard travel limit
  double trolley_max{1.30};          // [m] hard travel limit
  double voltage_limit{10.0};        // [V] magnitude limit on both drive commands
  double max_swing{0.35};            // [rad] swing angle beyond which the crane stops
  double stage_timeout{0.05};        // [s] a stage silent for longer is dead (5 cycles at 100 Hz)
  double lockstep_stage_timeout{1.0};  // [s] the same when the plant runs in lockstep: simulated time
                                       // waits for a slow stage, so only a long silence is a death
  bool arm_on_start{true};           // arm by itself once the chain is healthy (simulation); a
                                     // real crane sets false and waits for an explicit arm command
};
/// Throws crane::common::ConfigError naming the field, value and bound.
void validate(const SupervisorParams& params);

/// What the node observed of one stage since the last step.
struct StageObservation {
  bool alive{false};                  // DDS liveliness asserted and matched
  double seconds_since_sample{1e9};   // [s] since the last valid sample was received
};

enum class Command : std::uint8_t { none = 0, arm = 1, disarm = 2, emergency_stop = 3, reset = 4 };

struct SupervisorInput {
  std::array<StageObservation, kStageCount> stages{};
  bool sensors_valid{false};          // a sensor sample has been received (limits are checked only then)
  double trolley_position{0.0};       // [m] from the latest sensor sample
  double swing_in_plane{0.0};         // [rad]
  double swing_out_of_plane{0.0};     // [rad]
  double trolley_voltage{0.0};        // [V] latest actuator command
  double slew_voltage{0.0};           // [V]
  bool emergency_stop_input{false};   // hardware input
  int sensor_writers{1};              // writers matched on the sensors topic
  bool nonfinite_seen{false};         // a watched sample was rejected for NaN/Inf since last step
  bool move_in_progress{false};       // the planner reports a move (ready -> operating)
  Command command{Command::none};
};

struct SupervisorOutput {
  Mode mode{Mode::starting};
  bool motion_enabled{false};
  bool brakes_released{false};
  std::uint32_t active_faults{0};
  std::uint32_t latched_faults{0};
  std::uint32_t fault_count{0};
  std::uint32_t stages_alive{0};      // bit i set: Stage(i) alive
};

class Supervisor {
 public:
  explicit Supervisor(const SupervisorParams& params);
  /// One supervision cycle. Never throws, never allocates.
  void step(const SupervisorInput& input, SupervisorOutput& output) noexcept;
  [[nodiscard]] Mode mode() const noexcept { return mode_; }
  /// Faults raised in the last step that were not active before (for the fault log).
  [[nodiscard]] std::uint32_t newly_raised() const noexcept { return newly_raised_; }

 private:
  SupervisorParams params_;
  Mode mode_{Mode::starting};
  std::uint32_t latched_{0};
  std::uint32_t previous_active_{0};
  std::uint32_t fault_count_{0};
  std::uint32_t newly_raised_{0};
  bool armed_{false};
};

}  // namespace crane::supervisor
