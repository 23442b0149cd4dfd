#include "crane/hardware_bridge/board_config.hpp"

#include <string>

#include "crane/common/validation.hpp"

namespace crane::hardware_bridge {

namespace {

std::string field(const char* prefix, const char* name) { return std::string(prefix) + "." + name; }

std::string element(const char* prefix, const char* array, std::size_t i, const char* member = nullptr) {
  std::string text = field(prefix, array) + "[" + std::to_string(i) + "]";
  if (member != nullptr) text += std::string(".") + member;
  return text;
}

[[noreturn]] void duplicate(const std::string& name, int value, const std::string& other) {
  throw common::ConfigError(name + " = " + std::to_string(value) + " is out of range: must differ from " + other);
}

template <typename Line, std::size_t N>
void require_distinct_bits(const char* prefix, const char* array, const std::array<int, N>& bits, BoardAxes axes) {
  for (std::size_t i = 0; i < N; ++i) {
    if (!uses(axes, static_cast<Line>(i))) continue;
    common::require_in_range(element(prefix, array, i), static_cast<double>(bits[i]), 0.0, 31.0);
    for (std::size_t j = 0; j < i; ++j) {
      if (uses(axes, static_cast<Line>(j)) && bits[i] == bits[j]) {
        duplicate(element(prefix, array, i), bits[i], element(prefix, array, j));
      }
    }
  }
}

}  // namespace

void validate(const BoardConfig& config, const char* prefix) {
  common::require_in_range(field(prefix, "counter_bits"), static_cast<double>(config.counter_bits), 2.0, 32.0);
  const BoardAxes axes = config.axes;
  for (std::size_t i = 0; i < kCounterCount; ++i) {
    if (!uses(axes, static_cast<CounterChannel>(i))) continue;
    const ComediChannel& counter = config.counters[i];
    common::require_at_least(element(prefix, "counters", i, "subdevice"), static_cast<double>(counter.subdevice), 0.0);
    common::require_at_least(element(prefix, "counters", i, "channel"), static_cast<double>(counter.channel), 0.0);
    for (std::size_t j = 0; j < i; ++j) {
      if (uses(axes, static_cast<CounterChannel>(j)) && counter.subdevice == config.counters[j].subdevice &&
          counter.channel == config.counters[j].channel) {
        duplicate(element(prefix, "counters", i, "channel"), counter.channel,
                  element(prefix, "counters", j, "channel") + " on the same subdevice");
      }
    }
  }
  common::require_at_least(field(prefix, "analog_output_subdevice"), static_cast<double>(config.analog_output_subdevice),
                           0.0);
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    if (!uses(axes, static_cast<AnalogOutput>(i))) continue;
    const int channel = config.analog_output_channels[i];
    common::require_at_least(element(prefix, "analog_output_channels", i), static_cast<double>(channel), 0.0);
    for (std::size_t j = 0; j < i; ++j) {
      if (uses(axes, static_cast<AnalogOutput>(j)) && channel == config.analog_output_channels[j]) {
        duplicate(element(prefix, "analog_output_channels", i), channel, element(prefix, "analog_output_channels", j));
      }
    }
  }
  common::require_at_least(field(prefix, "analog_output_range"), static_cast<double>(config.analog_output_range), 0.0);
  common::require_at_least(field(prefix, "digital_output_subdevice"),
                           static_cast<double>(config.digital_output_subdevice), 0.0);
  common::require_at_least(field(prefix, "digital_input_subdevice"), static_cast<double>(config.digital_input_subdevice),
                           0.0);
  require_distinct_bits<DigitalOutput>(prefix, "digital_output_bits", config.digital_output_bits, axes);
  require_distinct_bits<DigitalInput>(prefix, "digital_input_bits", config.digital_input_bits, axes);
  if (config.digital_input_subdevice == config.digital_output_subdevice) {
    // One DIO subdevice: a line is either an input or an output.
    for (std::size_t i = 0; i < kDigitalInputCount; ++i) {
      if (!uses(axes, static_cast<DigitalInput>(i))) continue;
      for (std::size_t j = 0; j < kDigitalOutputCount; ++j) {
        if (uses(axes, static_cast<DigitalOutput>(j)) && config.digital_input_bits[i] == config.digital_output_bits[j]) {
          duplicate(element(prefix, "digital_input_bits", i), config.digital_input_bits[i],
                    element(prefix, "digital_output_bits", j) + " (same subdevice)");
        }
      }
    }
  }
}

}  // namespace crane::hardware_bridge
