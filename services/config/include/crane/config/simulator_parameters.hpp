#pragma once
// The simulated plant's parameters from the stack configuration (the crane: and plant: sections),
// used by the plant process and by the closed-loop tests alike.

#include "crane/config/stack_config.hpp"
#include "crane/plant/crane_simulator.hpp"

namespace crane::config {

/// Simulator parameters for `config`, starting at `initial` (SI; its cable_length is replaced by
/// crane.cable_length). The simulator's constructor validates the result and throws
/// common::ConfigError naming the field.
[[nodiscard]] plant::SimulatorParameters simulator_parameters(const StackConfig& config, plant::PlantState initial);

}  // namespace crane::config
