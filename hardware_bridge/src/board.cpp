#include "crane/hardware_bridge/board.hpp"

#include <cctype>

#include "crane/common/validation.hpp"
#include "crane/hardware_bridge/comedi_board.hpp"
#include "crane/hardware_bridge/shm_board.hpp"

namespace crane::hardware_bridge {

const char* channel_name(CounterChannel channel) noexcept {
  switch (channel) {
    case CounterChannel::trolley_motor: return "trolley_motor";
    case CounterChannel::slew_motor: return "slew_motor";
    case CounterChannel::swing_in_plane: return "swing_in_plane";
    case CounterChannel::swing_out_of_plane: return "swing_out_of_plane";
    case CounterChannel::bridge_motor: return "bridge_motor";
  }
  return "unknown";
}

const char* channel_name(AnalogOutput channel) noexcept {
  switch (channel) {
    case AnalogOutput::trolley_drive: return "trolley_drive";
    case AnalogOutput::slew_drive: return "slew_drive";
    case AnalogOutput::hoist_speed: return "hoist_speed";
    case AnalogOutput::bridge_drive: return "bridge_drive";
  }
  return "unknown";
}

const char* line_name(DigitalOutput line) noexcept {
  switch (line) {
    case DigitalOutput::brake_release_trolley: return "brake_release_trolley";
    case DigitalOutput::brake_release_slew: return "brake_release_slew";
    case DigitalOutput::brake_release_hoist: return "brake_release_hoist";
    case DigitalOutput::drive_enable: return "drive_enable";
    case DigitalOutput::brake_release_bridge: return "brake_release_bridge";
  }
  return "unknown";
}

const char* line_name(DigitalInput line) noexcept {
  switch (line) {
    case DigitalInput::trolley_min_limit: return "trolley_min_limit";
    case DigitalInput::trolley_max_limit: return "trolley_max_limit";
    case DigitalInput::slew_min_limit: return "slew_min_limit";
    case DigitalInput::slew_max_limit: return "slew_max_limit";
    case DigitalInput::emergency_stop: return "emergency_stop";
    case DigitalInput::bridge_min_limit: return "bridge_min_limit";
    case DigitalInput::bridge_max_limit: return "bridge_max_limit";
  }
  return "unknown";
}

std::array<AnalogRange, kAnalogOutputCount> Board::analog_ranges() const noexcept {
  std::array<AnalogRange, kAnalogOutputCount> ranges{};
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) ranges[i] = analog_range(static_cast<AnalogOutput>(i));
  return ranges;
}

BoardOutputs safe_board_outputs(const std::array<AnalogRange, kAnalogOutputCount>& ranges) noexcept {
  BoardOutputs outputs;
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) outputs.dac_codes[i] = volts_to_code(0.0, ranges[i]);
  outputs.digital_outputs = 0;
  return outputs;
}

namespace {

constexpr const char* kAcceptedUris =
    "accepted forms: comedi:/dev/comediN (N = 0, 1, ...) or shm:NAME (NAME of 1..200 letters, digits, '_' or '-')";

[[noreturn]] void bad_uri(const std::string& uri) {
  throw common::ConfigError("board URI '" + uri + "' is not accepted: " + kAcceptedUris);
}

bool starts_with(const std::string& text, const char* prefix) { return text.rfind(prefix, 0) == 0; }

}  // namespace

std::unique_ptr<Board> open_board(const std::string& uri, const BoardConfig& config) {
  validate(config);
  if (starts_with(uri, "comedi:")) {
    const std::string path = uri.substr(7);
    constexpr const char* kDevicePrefix = "/dev/comedi";
    if (!starts_with(path, kDevicePrefix)) bad_uri(uri);
    const std::string number = path.substr(std::char_traits<char>::length(kDevicePrefix));
    if (number.empty() || number.size() > 3) bad_uri(uri);
    for (const char c : number) {
      if (std::isdigit(static_cast<unsigned char>(c)) == 0) bad_uri(uri);
    }
    return std::make_unique<ComediBoard>(path, config, make_comedilib_api());
  }
  if (starts_with(uri, "shm:")) {
    const std::string name = uri.substr(4);
    try {
      (void)shm_segment_path(name);
    } catch (const common::ConfigError&) {
      bad_uri(uri);
    }
    return std::make_unique<ShmBoard>(name, config);
  }
  bad_uri(uri);
}

}  // namespace crane::hardware_bridge
