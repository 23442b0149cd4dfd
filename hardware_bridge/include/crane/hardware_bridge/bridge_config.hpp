#pragma once
// The hardware bridge's configuration: its output logic (the actuation gate and the hoist scaling)
// and the interface board's channel map, read from the `hardware_bridge:` block.

#include "crane/common/stack_facts.hpp"
#include "crane/hardware_bridge/board_config.hpp"
#include "crane/hardware_bridge/bridge_core.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::hardware_bridge {

struct HardwareBridgeConfig {
  BridgeParams bridge;   // the actuation gate and the hoist scaling
  BoardConfig board;     // counter width, comedi subdevices/channels/bits
};

/// The axes whose channels a crane of `kind` has: the slew's on a tower crane, the bridge's on an
/// overhead crane, neither on a gantry crane.
[[nodiscard]] constexpr BoardAxes board_axes(common::CraneKind kind) noexcept {
  return kind == common::CraneKind::tower    ? kTowerCraneAxes
         : kind == common::CraneKind::overhead ? kOverheadCraneAxes
                                               : kGantryCraneAxes;
}

/// Reads the `hardware_bridge:` block (hoist_speed_per_volt [m/s/V] in [1e-4, 100], counter_bits
/// in [2, 32], comedi: counters, analog_outputs, digital_outputs, digital_inputs); the gate's
/// params are `gate` (the `actuation:` block, supervisor::read_actuation_params). The channels are
/// those of the crane (board_axes(facts.crane_kind), set in both results' `axes`): the slew's
/// (comedi.counters.slew_motor, analog_outputs.slew_drive, digital_outputs.brake_release_slew,
/// digital_inputs.slew_min_limit and slew_max_limit) are required on a tower crane, the bridge's
/// (counters.bridge_motor, analog_outputs.bridge_drive, digital_outputs.brake_release_bridge,
/// digital_inputs.bridge_min_limit and bridge_max_limit) on an overhead crane; a crane without
/// that axis has them as unknown fields. Throws common::ConfigError naming the field, value and
/// bound ("missing field ...", "unknown field ...").
[[nodiscard]] HardwareBridgeConfig read_params(config::YamlSection& block, const common::StackFacts& facts,
                                               const supervisor::ActuationGateParams& gate);

}  // namespace crane::hardware_bridge
