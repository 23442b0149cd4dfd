#include "crane/hardware_bridge/bridge_config.hpp"

#include "crane/config/yaml_section.hpp"

namespace crane::hardware_bridge {

HardwareBridgeConfig read_params(config::YamlSection& s, const common::StackFacts& facts,
                                 const supervisor::ActuationGateParams& gate) {
  HardwareBridgeConfig c;
  // The slew's channels exist on a tower crane, the bridge's on an overhead crane: required there,
  // unknown fields elsewhere.
  const BoardAxes axes = board_axes(facts.crane_kind);
  c.bridge.gate = gate;
  c.bridge.axes = axes;
  c.board.axes = axes;
  c.bridge.hoist_speed_per_volt = s.number("hoist_speed_per_volt", 1e-4, 100.0);
  auto& b = c.board;
  b.counter_bits = s.integer("counter_bits", 2, 32);
  auto comedi = s.child("comedi");
  auto counters = comedi.child("counters");
  for (std::size_t i = 0; i < kCounterCount; ++i) {
    if (!uses(axes, static_cast<CounterChannel>(i))) continue;
    auto channel = counters.child(channel_name(static_cast<CounterChannel>(i)));
    b.counters[i].subdevice = channel.integer("subdevice", 0, 255);
    b.counters[i].channel = channel.integer("channel", 0, 255);
    channel.finish();
  }
  counters.finish();
  auto analog = comedi.child("analog_outputs");
  b.analog_output_subdevice = analog.integer("subdevice", 0, 255);
  b.analog_output_range = analog.integer("range", 0, 255);
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    if (!uses(axes, static_cast<AnalogOutput>(i))) continue;
    b.analog_output_channels[i] = analog.integer(channel_name(static_cast<AnalogOutput>(i)), 0, 255);
  }
  analog.finish();
  auto outputs = comedi.child("digital_outputs");
  b.digital_output_subdevice = outputs.integer("subdevice", 0, 255);
  for (std::size_t i = 0; i < kDigitalOutputCount; ++i) {
    if (!uses(axes, static_cast<DigitalOutput>(i))) continue;
    b.digital_output_bits[i] = outputs.integer(line_name(static_cast<DigitalOutput>(i)), 0, 31);
  }
  outputs.finish();
  auto inputs = comedi.child("digital_inputs");
  b.digital_input_subdevice = inputs.integer("subdevice", 0, 255);
  b.digital_inputs_active_low = inputs.flag("active_low");
  for (std::size_t i = 0; i < kDigitalInputCount; ++i) {
    if (!uses(axes, static_cast<DigitalInput>(i))) continue;
    b.digital_input_bits[i] = inputs.integer(line_name(static_cast<DigitalInput>(i)), 0, 31);
  }
  inputs.finish();
  comedi.finish();
  s.finish();
  validate(c.bridge, "hardware_bridge");
  validate(c.board, "hardware_bridge.comedi");
  return c;
}

}  // namespace crane::hardware_bridge
