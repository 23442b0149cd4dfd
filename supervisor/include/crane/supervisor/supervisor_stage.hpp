#pragma once
// The supervisor stage: what the supervisor process computes each cycle, without DDS, clock or
// thread. What the node observed of the chain (every stage's freshness, the latest sensor sample,
// reference and actuator command, writer counts, at most one operator command) -> the Supervisor
// core (supervisor.hpp) -> the SupervisorStatus of the sensor sample's cycle (same seq and origin).
// The node keeps the transport's part: which cycle to supervise when (realtime timer or lockstep
// cycles), the observations' clock, the fault log file.

#include <cstdint>

#include "crane/common/stack_facts.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/supervisor/supervisor.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::supervisor {

/// Reads the `supervisor:` block (every field of SupervisorParams but sample_period, voltage_limit,
/// gravity, site and expected_sensor_source: the first four from facts, the last from the launch;
/// the slew_* fields (limits, approach, rate and braking deceleration) on a tower crane only, the
/// bridge_* fields on an overhead crane only, unknown fields elsewhere; slew_enabled and
/// bridge_enabled from facts.crane_kind). Throws
/// common::ConfigError naming the field, value and bound.
[[nodiscard]] SupervisorParams read_params(config::YamlSection& block, const common::StackFacts& facts);

/// What the node observed since the last cycle.
struct SupervisorCycle {
  std::array<StageObservation, kStageCount> stages{};
  const protocol::SensorSample* sensors{nullptr};       // the cycle's sample (nullptr: none received yet)
  const protocol::ActuatorCommand* actuators{nullptr};  // the latest command (nullptr: none yet)
  const protocol::Reference* reference{nullptr};        // the latest reference (nullptr: none yet)
  int sensor_writers{1};                                // writers matched on the sensors topic
  int actuator_writers{1};                              // writers matched on the actuators topic
  bool nonfinite_seen{false};                           // a watched sample was rejected since the last cycle
  std::uint32_t nonfinite_rejected{0};                  // samples rejected since start (carried in the status)
  const protocol::SupervisorCommand* command{nullptr};  // at most one operator command per cycle
  bool realtime{false};  // wall-clock cycles: a hardware bridge's sample stamp is when it read the encoders
  SiteVerdict site{SiteVerdict::off};  // the site guard's answer on this cycle's motion (off: not on a site)
  bool site_unheard{false};            // the site guard has not heard the site service within its link deadline
};

class SupervisorStage {
 public:
  /// Throws common::ConfigError for invalid params.
  explicit SupervisorStage(const SupervisorParams& params);

  /// One supervision cycle; `status` is written completely (header seq and origin of the sensor
  /// sample). A command with an unknown code is handled as Command::none (nothing happens) and its
  /// request id answered. Never throws, never allocates.
  void step(const SupervisorCycle& cycle, protocol::SupervisorStatus& status) noexcept;

  /// The core's input and output of the last step (the fault log's record).
  [[nodiscard]] const SupervisorInput& input() const noexcept { return input_; }
  [[nodiscard]] const SupervisorOutput& output() const noexcept { return output_; }
  [[nodiscard]] const Supervisor& core() const noexcept { return core_; }
  /// The last step handled an operator command (its request id and result are in the status).
  [[nodiscard]] bool command_handled() const noexcept { return command_handled_; }

 private:
  Supervisor core_;
  SupervisorInput input_{};
  SupervisorOutput output_{};
  std::uint32_t last_request_id_{0};
  std::uint8_t last_request_result_{protocol::SupervisorStatus::RESULT_NONE};
  bool command_handled_{false};
};

}  // namespace crane::supervisor
