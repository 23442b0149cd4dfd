#include "crane/hardware_bridge/comedi_board.hpp"

#include <algorithm>
#include <sstream>
#include <stdexcept>

#include "crane/common/validation.hpp"

namespace crane::hardware_bridge {

namespace {

bool is_counter(int type) { return type == static_cast<int>(ComediSubdeviceType::counter); }
bool is_analog_output(int type) { return type == static_cast<int>(ComediSubdeviceType::analog_output); }
bool is_digital_io(int type) { return type == static_cast<int>(ComediSubdeviceType::digital_io); }
bool is_digital_output(int type) {
  return type == static_cast<int>(ComediSubdeviceType::digital_output) || is_digital_io(type);
}
bool is_digital_input(int type) {
  return type == static_cast<int>(ComediSubdeviceType::digital_input) || is_digital_io(type);
}

std::string where(int subdevice, int channel) {
  return "(subdevice " + std::to_string(subdevice) + ", channel " + std::to_string(channel) + ")";
}

unsigned as_unsigned(int value) noexcept { return static_cast<unsigned>(value); }

}  // namespace

const char* subdevice_type_name(int comedi_subdevice_type) noexcept {
  switch (comedi_subdevice_type) {
    case 0: return "unused";
    case 1: return "analog input";
    case 2: return "analog output";
    case 3: return "digital input";
    case 4: return "digital output";
    case 5: return "digital input/output";
    case 6: return "counter";
    case 7: return "timer";
    case 8: return "memory";
    case 9: return "calibration";
    case 10: return "processor";
    case 11: return "serial";
    case 12: return "pwm";
    default: return "unknown";
  }
}

ComediBoard::ComediBoard(const std::string& device_path, const BoardConfig& config, std::unique_ptr<ComediApi> api)
    : device_path_(device_path), config_(config), api_(std::move(api)) {
  if (!api_) throw std::invalid_argument("ComediBoard: the ComediApi must not be null");
  validate(config_);
  counter_mask_ = static_cast<std::uint32_t>((std::uint64_t{1} << config_.counter_bits) - 1U);
  device_ = api_->open(device_path_);
  if (device_ == nullptr) fail("comedi_open failed");
  try {
    // Counters: those of the crane (the slew's on a tower crane only, the bridge's on an overhead
    // crane only: BoardConfig::axes).
    const BoardAxes axes = config_.axes;
    for (std::size_t i = 0; i < kCounterCount; ++i) {
      if (!uses(axes, static_cast<CounterChannel>(i))) continue;
      const ComediChannel& counter = config_.counters[i];
      const std::string role = std::string("counter ") + channel_name(static_cast<CounterChannel>(i));
      int n_channels = 0;
      check_subdevice(counter.subdevice, role.c_str(), is_counter, n_channels);
      if (counter.channel >= n_channels) {
        throw BoardError("comedi:" + device_path_ + ": " + role + " " + where(counter.subdevice, counter.channel) +
                         ": the subdevice has only " + std::to_string(n_channels) + " channels");
      }
      const std::uint32_t maxdata =
          api_->get_maxdata(device_, as_unsigned(counter.subdevice), as_unsigned(counter.channel));
      if (maxdata == 0) fail(role + " " + where(counter.subdevice, counter.channel) + ": comedi_get_maxdata failed");
      if (maxdata != counter_mask_) {
        throw BoardError("comedi:" + device_path_ + ": " + role + " " + where(counter.subdevice, counter.channel) +
                         ": maxdata " + std::to_string(maxdata) + " is not 2^counter_bits - 1 = " +
                         std::to_string(counter_mask_) + " (board.counter_bits = " +
                         std::to_string(config_.counter_bits) + ")");
      }
    }
    // Analog outputs: ranges and maxdata, read once.
    int n_channels = 0;
    check_subdevice(config_.analog_output_subdevice, "analog output", is_analog_output, n_channels);
    for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
      if (!uses(axes, static_cast<AnalogOutput>(i))) continue;
      const int channel = config_.analog_output_channels[i];
      const std::string role = std::string("analog output ") + channel_name(static_cast<AnalogOutput>(i)) + " " +
                               where(config_.analog_output_subdevice, channel);
      if (channel >= n_channels) {
        throw BoardError("comedi:" + device_path_ + ": " + role + ": the subdevice has only " +
                         std::to_string(n_channels) + " channels");
      }
      ComediRange range;
      if (!api_->get_range(device_, as_unsigned(config_.analog_output_subdevice), as_unsigned(channel),
                           as_unsigned(config_.analog_output_range), range)) {
        fail(role + ": range " + std::to_string(config_.analog_output_range) + " (board.analog_output_range) " +
             "is not available: comedi_get_range failed");
      }
      const std::uint32_t maxdata =
          api_->get_maxdata(device_, as_unsigned(config_.analog_output_subdevice), as_unsigned(channel));
      if (maxdata == 0) fail(role + ": comedi_get_maxdata failed");
      const AnalogRange analog{range.min, range.max, maxdata};
      if (range.unit != kComediUnitVolt || !is_valid(analog)) {
        throw BoardError("comedi:" + device_path_ + ": " + role + ": range " +
                         std::to_string(config_.analog_output_range) + " = [" + common::format_value(range.min) +
                         ", " + common::format_value(range.max) + "] (unit " + std::to_string(range.unit) +
                         "), maxdata " + std::to_string(maxdata) + " is not a usable voltage range");
      }
      ranges_[i] = analog;
    }
    // Digital outputs and inputs; the lines of a DIO subdevice get their direction.
    check_subdevice(config_.digital_output_subdevice, "digital output", is_digital_output, n_channels);
    const int output_type = api_->get_subdevice_type(device_, as_unsigned(config_.digital_output_subdevice));
    for (std::size_t i = 0; i < kDigitalOutputCount; ++i) {
      if (!uses(axes, static_cast<DigitalOutput>(i))) continue;
      const int line = config_.digital_output_bits[i];
      const std::string role = std::string("digital output ") + line_name(static_cast<DigitalOutput>(i)) + " " +
                               where(config_.digital_output_subdevice, line);
      if (line >= n_channels) {
        throw BoardError("comedi:" + device_path_ + ": " + role + ": the subdevice has only " +
                         std::to_string(n_channels) + " channels");
      }
      if (is_digital_io(output_type) &&
          api_->dio_config(device_, as_unsigned(config_.digital_output_subdevice), as_unsigned(line),
                           kComediDioOutput) < 0) {
        fail(role + ": comedi_dio_config(output) failed");
      }
      digital_output_mask_ |= 1U << as_unsigned(line);
    }
    check_subdevice(config_.digital_input_subdevice, "digital input", is_digital_input, n_channels);
    const int input_type = api_->get_subdevice_type(device_, as_unsigned(config_.digital_input_subdevice));
    for (std::size_t i = 0; i < kDigitalInputCount; ++i) {
      if (!uses(axes, static_cast<DigitalInput>(i))) continue;
      const int line = config_.digital_input_bits[i];
      const std::string role = std::string("digital input ") + line_name(static_cast<DigitalInput>(i)) + " " +
                               where(config_.digital_input_subdevice, line);
      if (line >= n_channels) {
        throw BoardError("comedi:" + device_path_ + ": " + role + ": the subdevice has only " +
                         std::to_string(n_channels) + " channels");
      }
      if (is_digital_io(input_type) &&
          api_->dio_config(device_, as_unsigned(config_.digital_input_subdevice), as_unsigned(line),
                           kComediDioInput) < 0) {
        fail(role + ": comedi_dio_config(input) failed");
      }
    }
  } catch (...) {
    close_device();
    throw;
  }
}

ComediBoard::~ComediBoard() { close_device(); }

void ComediBoard::close_device() noexcept {
  if (device_ != nullptr) {
    (void)api_->close(device_);
    device_ = nullptr;
  }
}

void ComediBoard::fail(const std::string& what) const {
  const int error = api_->error_number();
  throw BoardError("comedi:" + device_path_ + ": " + what + ": " + api_->error_string(error) + " (comedi errno " +
                   std::to_string(error) + ")");
}

void ComediBoard::check_subdevice(int subdevice, const char* role, bool (*type_ok)(int), int& n_channels) const {
  const int type = api_->get_subdevice_type(device_, as_unsigned(subdevice));
  if (type < 0) {
    fail(std::string(role) + " subdevice " + std::to_string(subdevice) +
         " does not exist: comedi_get_subdevice_type failed");
  }
  if (!type_ok(type)) {
    throw BoardError("comedi:" + device_path_ + ": " + role + " subdevice " + std::to_string(subdevice) + " is a " +
                     subdevice_type_name(type) + " subdevice");
  }
  n_channels = api_->get_n_channels(device_, as_unsigned(subdevice));
  if (n_channels < 0) fail(std::string(role) + " subdevice " + std::to_string(subdevice) + ": comedi_get_n_channels failed");
}

void ComediBoard::read_counters(std::array<std::uint32_t, kCounterCount>& raw_counts) {
  raw_counts.fill(0);  // a counter the crane does not have (the bridge's on a tower crane) reads 0
  for (std::size_t i = 0; i < kCounterCount; ++i) {
    if (!uses(config_.axes, static_cast<CounterChannel>(i))) continue;
    const ComediChannel& counter = config_.counters[i];
    std::uint32_t value = 0;
    if (api_->data_read(device_, as_unsigned(counter.subdevice), as_unsigned(counter.channel), 0,
                        kComediAnalogRefGround, value) < 0) {
      fail(std::string("comedi_data_read of counter ") + channel_name(static_cast<CounterChannel>(i)) + " " +
           where(counter.subdevice, counter.channel) + " failed");
    }
    raw_counts[i] = value & counter_mask_;
  }
}

void ComediBoard::write_analog_outputs(const BoardOutputs& outputs) {
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    if (!uses(config_.axes, static_cast<AnalogOutput>(i))) continue;
    const int channel = config_.analog_output_channels[i];
    const std::uint32_t code = std::min(outputs.dac_codes[i], ranges_[i].maxdata);
    if (api_->data_write(device_, as_unsigned(config_.analog_output_subdevice), as_unsigned(channel),
                         as_unsigned(config_.analog_output_range), kComediAnalogRefGround, code) < 0) {
      fail(std::string("comedi_data_write of analog output ") + channel_name(static_cast<AnalogOutput>(i)) + " " +
           where(config_.analog_output_subdevice, channel) + " failed");
    }
  }
}

void ComediBoard::write_digital_outputs(std::uint32_t logical_outputs) {
  unsigned bits = 0;
  for (std::size_t i = 0; i < kDigitalOutputCount; ++i) {
    if (!uses(config_.axes, static_cast<DigitalOutput>(i))) continue;
    if ((logical_outputs & (1U << i)) != 0U) bits |= 1U << as_unsigned(config_.digital_output_bits[i]);
  }
  last_digital_outputs_ = all_outputs_energized(config_.axes);  // unknown until the write succeeds
  if (api_->dio_bitfield2(device_, as_unsigned(config_.digital_output_subdevice), digital_output_mask_, bits, 0) < 0) {
    fail("comedi_dio_bitfield2 of the digital outputs (subdevice " + std::to_string(config_.digital_output_subdevice) +
         ") failed");
  }
  last_digital_outputs_ = logical_outputs;
}

void ComediBoard::write_outputs(const BoardOutputs& outputs) {
  const std::uint32_t logical = outputs.digital_outputs & all_outputs_energized(config_.axes);
  const bool de_energizes = (last_digital_outputs_ & ~logical) != 0U;
  if (de_energizes) {
    write_digital_outputs(logical);  // brakes engage and drives disable before the voltages change
    write_analog_outputs(outputs);
  } else {
    write_analog_outputs(outputs);
    write_digital_outputs(logical);
  }
}

std::uint32_t ComediBoard::read_digital_inputs() {
  unsigned bits = 0;
  if (api_->dio_bitfield2(device_, as_unsigned(config_.digital_input_subdevice), 0, bits, 0) < 0) {
    fail("comedi_dio_bitfield2 of the digital inputs (subdevice " + std::to_string(config_.digital_input_subdevice) +
         ") failed");
  }
  std::uint32_t logical = 0;
  for (std::size_t i = 0; i < kDigitalInputCount; ++i) {
    if (!uses(config_.axes, static_cast<DigitalInput>(i))) continue;
    const bool level = ((bits >> as_unsigned(config_.digital_input_bits[i])) & 1U) != 0U;
    if (level != config_.digital_inputs_active_low) logical |= 1U << i;
  }
  return logical;
}

AnalogRange ComediBoard::analog_range(AnalogOutput channel) const noexcept { return ranges_[index(channel)]; }

std::string ComediBoard::describe() const {
  std::ostringstream text;
  const BoardAxes axes = config_.axes;
  text << "comedi:" << device_path_ << " (" << config_.counter_bits << "-bit counters at";
  for (std::size_t i = 0; i < kCounterCount; ++i) {
    if (!uses(axes, static_cast<CounterChannel>(i))) continue;
    text << " " << config_.counters[i].subdevice << "/" << config_.counters[i].channel;
  }
  text << "; analog outputs on subdevice " << config_.analog_output_subdevice << " range "
       << config_.analog_output_range << ":";
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    if (!uses(axes, static_cast<AnalogOutput>(i))) continue;
    text << " " << channel_name(static_cast<AnalogOutput>(i)) << " ch " << config_.analog_output_channels[i] << " ["
         << common::format_value(ranges_[i].min_volts) << ", " << common::format_value(ranges_[i].max_volts)
         << "] V maxdata " << ranges_[i].maxdata;
  }
  text << "; digital outputs on subdevice " << config_.digital_output_subdevice << " bits";
  for (std::size_t i = 0; i < kDigitalOutputCount; ++i) {
    if (uses(axes, static_cast<DigitalOutput>(i))) text << " " << config_.digital_output_bits[i];
  }
  text << "; digital inputs on subdevice " << config_.digital_input_subdevice << " bits";
  for (std::size_t i = 0; i < kDigitalInputCount; ++i) {
    if (uses(axes, static_cast<DigitalInput>(i))) text << " " << config_.digital_input_bits[i];
  }
  text << (config_.digital_inputs_active_low ? " active-low)" : " active-high)");
  return text.str();
}

}  // namespace crane::hardware_bridge
