// ComediBoard against a fake comedilib (no hardware): opening, range read-back, channel validation,
// where codes and bits go, polarity of the inputs, write order, error messages.
#include <gtest/gtest.h>

#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/hardware_bridge/comedi_board.hpp"

namespace crane::hardware_bridge {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

constexpr int kFakeErrno = 5;
constexpr const char* kFakeMessage = "fake driver says no";

struct FakeSubdevice {
  ComediSubdeviceType type{ComediSubdeviceType::unused};
  int n_channels{0};
  std::uint32_t maxdata{1};
  std::vector<ComediRange> ranges;  // by range index
};

/// One recorded call.
struct Call {
  std::string function;
  unsigned subdevice{0};
  unsigned channel{0};  // or base channel
  unsigned range{0};    // or direction
  unsigned aref{0};
  std::uint32_t data{0};  // or bits
  unsigned write_mask{0};
};

/// What the fake device holds; the test keeps it while the board owns the fake.
struct FakeState {
  std::map<unsigned, FakeSubdevice> subdevices;
  std::map<std::pair<unsigned, unsigned>, std::uint32_t> counter_values;  // (subdevice, channel)
  std::map<unsigned, unsigned> digital_lines;                             // subdevice -> line levels
  std::vector<Call> calls;
  std::string fail_function;  // a call of this function fails, after fail_skip successful ones
  int fail_skip{0};
  int opens{0};
  int closes{0};
  int last_error{0};

  [[nodiscard]] std::vector<Call> calls_of(const std::string& function) const {
    std::vector<Call> found;
    for (const Call& call : calls) {
      if (call.function == function) found.push_back(call);
    }
    return found;
  }
};

/// The lab board of these tests: counters on 0 (4 x 24 bit), analog outputs on 1 (4 x 12 bit,
/// ranges [-10, 10] and [-5, 5] V), digital outputs on 2 (8 lines), digital inputs on 3 (8 lines),
/// one DIO subdevice 4 (16 lines) and four single-counter subdevices 5..8 (as an NI 660x).
std::shared_ptr<FakeState> lab_board() {
  auto state = std::make_shared<FakeState>();
  state->subdevices[0] = {ComediSubdeviceType::counter, 4, 0xFFFFFFU, {}};
  state->subdevices[1] = {ComediSubdeviceType::analog_output, 4, 4095U,
                          {ComediRange{-10.0, 10.0, kComediUnitVolt}, ComediRange{-5.0, 5.0, kComediUnitVolt},
                           ComediRange{0.0, 20.0, 1U /* mA */}}};
  state->subdevices[2] = {ComediSubdeviceType::digital_output, 8, 1U, {}};
  state->subdevices[3] = {ComediSubdeviceType::digital_input, 8, 1U, {}};
  state->subdevices[4] = {ComediSubdeviceType::digital_io, 16, 1U, {}};
  for (unsigned s = 5; s <= 8; ++s) state->subdevices[s] = {ComediSubdeviceType::counter, 1, 0xFFFFFFU, {}};
  return state;
}

class FakeComedi final : public ComediApi {
 public:
  explicit FakeComedi(std::shared_ptr<FakeState> state) : state_(std::move(state)) {}

  ComediDevice* open(const std::string& device_path) override {
    state_->calls.push_back({"open", 0, 0, 0, 0, 0, 0});
    if (device_path != "/dev/comedi0" || failing("open")) return fail_pointer();
    ++state_->opens;
    return reinterpret_cast<ComediDevice*>(&device_tag_);
  }
  int close(ComediDevice* device) override {
    check(device);
    ++state_->closes;
    return 0;
  }
  int get_subdevice_type(ComediDevice* device, unsigned subdevice) override {
    check(device);
    const FakeSubdevice* sub = find(subdevice);
    return sub == nullptr ? fail_int() : static_cast<int>(sub->type);
  }
  int get_n_channels(ComediDevice* device, unsigned subdevice) override {
    check(device);
    const FakeSubdevice* sub = find(subdevice);
    return sub == nullptr ? fail_int() : sub->n_channels;
  }
  std::uint32_t get_maxdata(ComediDevice* device, unsigned subdevice, unsigned channel) override {
    check(device);
    const FakeSubdevice* sub = find(subdevice);
    if (sub == nullptr || static_cast<int>(channel) >= sub->n_channels || failing("get_maxdata")) {
      (void)fail_int();
      return 0;
    }
    return sub->maxdata;
  }
  bool get_range(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index,
                 ComediRange& range) override {
    check(device);
    const FakeSubdevice* sub = find(subdevice);
    if (sub == nullptr || static_cast<int>(channel) >= sub->n_channels || range_index >= sub->ranges.size()) {
      (void)fail_int();
      return false;
    }
    range = sub->ranges[range_index];
    return true;
  }
  int data_read(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index, unsigned aref,
                std::uint32_t& data) override {
    check(device);
    state_->calls.push_back({"data_read", subdevice, channel, range_index, aref, 0, 0});
    if (failing("data_read")) return fail_int();
    data = state_->counter_values[{subdevice, channel}];
    return 1;
  }
  int data_write(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned range_index, unsigned aref,
                 std::uint32_t data) override {
    check(device);
    state_->calls.push_back({"data_write", subdevice, channel, range_index, aref, data, 0});
    return failing("data_write") ? fail_int() : 1;
  }
  int dio_config(ComediDevice* device, unsigned subdevice, unsigned channel, unsigned direction) override {
    check(device);
    state_->calls.push_back({"dio_config", subdevice, channel, direction, 0, 0, 0});
    return failing("dio_config") ? fail_int() : 1;
  }
  int dio_bitfield2(ComediDevice* device, unsigned subdevice, unsigned write_mask, unsigned& bits,
                    unsigned base_channel) override {
    check(device);
    state_->calls.push_back({"dio_bitfield2", subdevice, base_channel, 0, 0, bits, write_mask});
    if (failing("dio_bitfield2")) return fail_int();
    unsigned& lines = state_->digital_lines[subdevice];
    lines = (lines & ~write_mask) | (bits & write_mask);
    bits = lines;
    return 0;
  }
  int error_number() override { return state_->last_error; }
  std::string error_string(int error_number) override {
    return error_number == kFakeErrno ? kFakeMessage : "no error";
  }

 private:
  void check(ComediDevice* device) const {
    if (device != reinterpret_cast<const ComediDevice*>(&device_tag_)) ADD_FAILURE() << "wrong device handle";
  }
  const FakeSubdevice* find(unsigned subdevice) const {
    const auto it = state_->subdevices.find(subdevice);
    return it == state_->subdevices.end() ? nullptr : &it->second;
  }
  bool failing(const char* function) {
    if (state_->fail_function != function) return false;
    if (state_->fail_skip > 0) {
      --state_->fail_skip;
      return false;
    }
    state_->fail_function.clear();
    return true;
  }
  int fail_int() {
    state_->last_error = kFakeErrno;
    return -1;
  }
  ComediDevice* fail_pointer() {
    state_->last_error = kFakeErrno;
    return nullptr;
  }

  std::shared_ptr<FakeState> state_;
  int device_tag_{0};
};

std::unique_ptr<ComediBoard> open_fake(const std::shared_ptr<FakeState>& state, const BoardConfig& config = {},
                                       const std::string& path = "/dev/comedi0") {
  return std::make_unique<ComediBoard>(path, config, std::make_unique<FakeComedi>(state));
}

std::string open_error(const std::shared_ptr<FakeState>& state, const BoardConfig& config,
                       const std::string& path = "/dev/comedi0") {
  try {
    (void)open_fake(state, config, path);
  } catch (const BoardError& error) {
    return error.what();
  }
  return "";
}

TEST(ComediBoard, OpensAndReadsRangesFromTheDriver) {
  const auto state = lab_board();
  {
    const auto board = open_fake(state);
    EXPECT_EQ(state->opens, 1);
    EXPECT_EQ(board->counter_bits(), 24);
    for (std::size_t i = 0; i < 3; ++i) {  // a tower crane's three outputs: trolley, slew, hoist
      const AnalogRange range = board->analog_ranges()[i];
      EXPECT_EQ(range.min_volts, -10.0);
      EXPECT_EQ(range.max_volts, 10.0);
      EXPECT_EQ(range.maxdata, 4095U);
    }
    // The bridge's output is not read from the driver on a tower crane: the default range.
    const AnalogRange unused = board->analog_range(AnalogOutput::bridge_drive);
    EXPECT_EQ(unused.maxdata, AnalogRange{}.maxdata);
    EXPECT_TRUE(contains(board->describe(), "comedi:/dev/comedi0")) << board->describe();
    EXPECT_TRUE(state->calls_of("data_write").empty()) << "opening must not write the outputs";
    EXPECT_TRUE(state->calls_of("dio_config").empty()) << "separate DO/DI subdevices need no direction";
  }
  EXPECT_EQ(state->closes, 1);

  BoardConfig five_volts;
  five_volts.analog_output_range = 1;
  const auto board = open_fake(state, five_volts);
  EXPECT_EQ(board->analog_range(AnalogOutput::slew_drive).min_volts, -5.0);
  EXPECT_EQ(board->analog_range(AnalogOutput::slew_drive).max_volts, 5.0);
}

TEST(ComediBoard, OpenFailureNamesTheDeviceAndTheDriversMessage) {
  const auto state = lab_board();
  const std::string message = open_error(state, BoardConfig{}, "/dev/comedi7");
  EXPECT_TRUE(contains(message, "comedi:/dev/comedi7: comedi_open failed: fake driver says no (comedi errno 5)"))
      << message;
  EXPECT_EQ(state->closes, 0);
}

TEST(ComediBoard, ConfiguredSubdevicesAndChannelsAreChecked) {
  const auto state = lab_board();
  BoardConfig c;
  c.counters[1].subdevice = 9;
  std::string message = open_error(state, c);
  EXPECT_TRUE(contains(message, "counter slew_motor subdevice 9 does not exist")) << message;
  EXPECT_TRUE(contains(message, kFakeMessage)) << message;

  c = BoardConfig{};
  c.analog_output_subdevice = 0;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "analog output subdevice 0 is a counter subdevice")) << message;

  c = BoardConfig{};
  c.analog_output_channels = {0, 1, 4};
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "analog output hoist_speed (subdevice 1, channel 4): the subdevice has only 4 channels"))
      << message;

  c = BoardConfig{};
  c.counters[3].channel = 4;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "counter swing_out_of_plane (subdevice 0, channel 4)")) << message;

  c = BoardConfig{};
  c.digital_output_bits[3] = 8;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "digital output drive_enable (subdevice 2, channel 8)")) << message;

  c = BoardConfig{};
  c.digital_input_subdevice = 2;  // a DO subdevice cannot read inputs
  c.digital_input_bits = {4, 5, 6, 7, 8};
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "digital input subdevice 2 is a digital output subdevice")) << message;

  c = BoardConfig{};
  c.counter_bits = 16;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "maxdata 16777215 is not 2^counter_bits - 1 = 65535")) << message;

  c = BoardConfig{};
  c.analog_output_range = 5;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "analog output trolley_drive (subdevice 1, channel 0): range 5")) << message;

  c = BoardConfig{};
  c.analog_output_range = 2;  // a current range
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "is not a usable voltage range")) << message;

  // Every failed open closed the device it had opened.
  EXPECT_EQ(state->opens, 9);
  EXPECT_EQ(state->closes, 9);

  c = BoardConfig{};
  c.counter_bits = 99;  // configuration errors come before any driver call
  EXPECT_THROW((void)open_fake(state, c), common::ConfigError);
  EXPECT_EQ(state->opens, 9);
}

TEST(ComediBoard, ReadsCountersFromTheConfiguredChannelsMasked) {
  const auto state = lab_board();
  state->counter_values[{0, 0}] = 5U;
  state->counter_values[{0, 1}] = 0xFFFFFFU;
  state->counter_values[{0, 2}] = 0x1234567U;  // bits above 24 are dropped
  state->counter_values[{0, 3}] = 42U;
  const auto board = open_fake(state);
  std::array<std::uint32_t, kCounterCount> raw{};
  board->read_counters(raw);
  EXPECT_EQ(raw, (std::array<std::uint32_t, kCounterCount>{5U, 0xFFFFFFU, 0x234567U, 42U}));
  const std::vector<Call> reads = state->calls_of("data_read");
  ASSERT_EQ(reads.size(), 4U);
  for (unsigned i = 0; i < 4; ++i) {
    EXPECT_EQ(reads[i].subdevice, 0U);
    EXPECT_EQ(reads[i].channel, i);
    EXPECT_EQ(reads[i].aref, kComediAnalogRefGround);
  }
}

TEST(ComediBoard, OneSubdevicePerCounter) {
  const auto state = lab_board();
  BoardConfig c;
  c.counters = {{{7, 0}, {5, 0}, {8, 0}, {6, 0}}};
  for (unsigned s = 5; s <= 8; ++s) state->counter_values[{s, 0}] = 100U + s;
  const auto board = open_fake(state, c);
  std::array<std::uint32_t, kCounterCount> raw{};
  board->read_counters(raw);
  EXPECT_EQ(raw, (std::array<std::uint32_t, kCounterCount>{107U, 105U, 108U, 106U}));
}

TEST(ComediBoard, WritesCodesAndTheDigitalWordWhereConfigured) {
  const auto state = lab_board();
  BoardConfig c;
  c.analog_output_channels = {2, 0, 3};
  c.analog_output_range = 1;
  c.digital_output_bits = {5, 1, 7, 0};
  const auto board = open_fake(state, c);
  state->calls.clear();
  BoardOutputs outputs;
  outputs.dac_codes = {100U, 5000U /* > maxdata 4095 */, 2048U};
  outputs.digital_outputs = bit(DigitalOutput::brake_release_trolley) | bit(DigitalOutput::drive_enable);
  board->write_outputs(outputs);
  const std::vector<Call> writes = state->calls_of("data_write");
  ASSERT_EQ(writes.size(), 3U);
  const std::array<unsigned, 3> channels{2U, 0U, 3U};
  const std::array<std::uint32_t, 3> codes{100U, 4095U, 2048U};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(writes[i].subdevice, 1U);
    EXPECT_EQ(writes[i].channel, channels[i]);
    EXPECT_EQ(writes[i].range, 1U);
    EXPECT_EQ(writes[i].aref, kComediAnalogRefGround);
    EXPECT_EQ(writes[i].data, codes[i]);
  }
  const std::vector<Call> bitfields = state->calls_of("dio_bitfield2");
  ASSERT_EQ(bitfields.size(), 1U);
  EXPECT_EQ(bitfields[0].subdevice, 2U);
  EXPECT_EQ(bitfields[0].channel, 0U);                                          // base channel
  EXPECT_EQ(bitfields[0].write_mask, (1U << 5) | (1U << 1) | (1U << 7) | 1U);  // only the output lines
  EXPECT_EQ(bitfields[0].data, (1U << 5) | (1U << 0));                         // trolley brake, drive enable
  EXPECT_EQ(state->digital_lines[2], (1U << 5) | 1U);
}

// De-energizing lines go first (brakes engage before the voltages change); energizing lines last.
TEST(ComediBoard, WriteOrderIsFailSafe) {
  const auto state = lab_board();
  const auto board = open_fake(state);
  const auto order = [&]() {
    std::string sequence;
    for (const Call& call : state->calls) {
      if (call.function == "data_write") sequence += "A";
      if (call.function == "dio_bitfield2") sequence += "D";
    }
    state->calls.clear();
    return sequence;
  };
  BoardOutputs safe = safe_board_outputs(board->analog_ranges());
  BoardOutputs running = safe;
  running.digital_outputs = all_outputs_energized(kTowerCraneAxes);
  running.dac_codes[0] = 3000U;
  state->calls.clear();
  board->write_outputs(safe);  // the state of the lines after open is unknown: digital first
  EXPECT_EQ(order(), "DAAA");
  board->write_outputs(running);  // energizing: voltages first
  EXPECT_EQ(order(), "AAAD");
  board->write_outputs(running);
  EXPECT_EQ(order(), "AAAD");
  board->write_outputs(safe);  // de-energizing: lines first
  EXPECT_EQ(order(), "DAAA");
}

TEST(ComediBoard, DigitalInputsWithBitMapAndPolarity) {
  const auto state = lab_board();
  BoardConfig c;
  c.digital_input_bits = {6, 2, 0, 3, 7};  // trolley min/max, slew min/max, emergency stop
  {
    const auto board = open_fake(state, c);  // active-low (default)
    state->digital_lines[3] = 0xFFU;         // every contact closed: nothing active
    EXPECT_EQ(board->read_digital_inputs(), 0U);
    state->digital_lines[3] = 0xFFU & ~(1U << 7);  // emergency-stop contact open
    EXPECT_EQ(board->read_digital_inputs(), bit(DigitalInput::emergency_stop));
    state->digital_lines[3] = 0x00U;  // all open (a cut cable): every input active
    EXPECT_EQ(board->read_digital_inputs(), 0x1FU);  // a tower crane's five
    const std::vector<Call> reads = state->calls_of("dio_bitfield2");
    ASSERT_FALSE(reads.empty());
    EXPECT_EQ(reads.back().subdevice, 3U);
    EXPECT_EQ(reads.back().write_mask, 0U);
  }
  c.digital_inputs_active_low = false;
  const auto board = open_fake(state, c);
  state->digital_lines[3] = (1U << 2) | (1U << 3);  // trolley max and slew max
  EXPECT_EQ(board->read_digital_inputs(), bit(DigitalInput::trolley_max_limit) | bit(DigitalInput::slew_max_limit));
}

TEST(ComediBoard, DioSubdeviceGetsLineDirections) {
  const auto state = lab_board();
  BoardConfig c;
  c.digital_output_subdevice = 4;
  c.digital_input_subdevice = 4;
  c.digital_output_bits = {0, 1, 2, 3};
  c.digital_input_bits = {8, 9, 10, 11, 12};
  const auto board = open_fake(state, c);
  const std::vector<Call> configs = state->calls_of("dio_config");
  ASSERT_EQ(configs.size(), 9U);
  for (std::size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(configs[i].subdevice, 4U);
    EXPECT_EQ(configs[i].channel, i);
    EXPECT_EQ(configs[i].range, kComediDioOutput);
  }
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_EQ(configs[4 + i].channel, 8U + i);
    EXPECT_EQ(configs[4 + i].range, kComediDioInput);
  }
  // Writing the outputs leaves the input lines alone.
  state->digital_lines[4] = 0xFF00U;
  BoardOutputs outputs = safe_board_outputs(board->analog_ranges());
  outputs.digital_outputs = all_outputs_energized(kTowerCraneAxes);
  board->write_outputs(outputs);
  EXPECT_EQ(state->digital_lines[4], 0xFF0FU);

  state->fail_function = "dio_config";
  const std::string message = open_error(state, c);
  EXPECT_TRUE(contains(message, "digital output brake_release_trolley (subdevice 4, channel 0): comedi_dio_config"))
      << message;
}

// An overhead crane's board (kOverheadCraneAxes): the bridge's counter (here its own counter
// subdevice, as on an NI 660x), its analog output, brake line and runway limit switches are checked
// at open, read and written where configured; the slew's, which it has not, never. The same fake
// opened for a tower crane never touches the bridge's.
BoardConfig overhead_board_config() {
  BoardConfig c;
  c.axes = kOverheadCraneAxes;
  c.counters[index(CounterChannel::bridge_motor)] = {5, 0};
  c.analog_output_channels = {0, 1, 2, 3};
  c.digital_output_bits = {0, 1, 2, 3, 6};
  c.digital_input_bits = {0, 1, 2, 3, 4, 6, 5};  // the runway switches wired to lines 6 and 5
  return c;
}

TEST(ComediBoard, OverheadCraneMapsTheBridgeChannels) {
  const auto state = lab_board();
  const BoardConfig c = overhead_board_config();
  const auto board = open_fake(state, c);
  EXPECT_TRUE(contains(board->describe(), "bridge_drive ch 3")) << board->describe();

  state->counter_values[{0, 0}] = 11U;
  state->counter_values[{5, 0}] = 0x1ABCDEFU;  // bits above 24 are dropped
  std::array<std::uint32_t, kCounterCount> raw{};
  board->read_counters(raw);
  EXPECT_EQ(raw[index(CounterChannel::trolley_motor)], 11U);
  EXPECT_EQ(raw[index(CounterChannel::bridge_motor)], 0xABCDEFU);
  const std::vector<Call> reads = state->calls_of("data_read");
  ASSERT_EQ(reads.size(), 4U);  // trolley, the two swings, the bridge: no slew counter
  EXPECT_EQ(reads[1].channel, 2U);
  EXPECT_EQ(reads[3].subdevice, 5U);
  EXPECT_EQ(reads[3].channel, 0U);
  EXPECT_EQ(raw[index(CounterChannel::slew_motor)], 0U);

  state->calls.clear();
  BoardOutputs outputs;
  outputs.dac_codes = {100U, 200U, 300U, 4000U};
  outputs.digital_outputs = (1U << kDigitalOutputCount) - 1U;  // a stray slew brake bit is not written
  board->write_outputs(outputs);
  const std::vector<Call> writes = state->calls_of("data_write");
  ASSERT_EQ(writes.size(), 3U);  // trolley, hoist, bridge
  EXPECT_EQ(writes[1].channel, 2U);
  EXPECT_EQ(writes[2].channel, 3U);
  EXPECT_EQ(writes[2].data, 4000U);
  const std::vector<Call> bitfields = state->calls_of("dio_bitfield2");
  ASSERT_EQ(bitfields.size(), 1U);
  const unsigned lines = (1U << 0) | (1U << 2) | (1U << 3) | (1U << 6);  // trolley and hoist brakes, enable, bridge brake
  EXPECT_EQ(bitfields[0].write_mask, lines);
  EXPECT_EQ(state->digital_lines[2], lines);
  // Only the bridge's brake engaged: its line alone goes to 0, written before the voltages.
  state->calls.clear();
  outputs.digital_outputs = all_outputs_energized(kOverheadCraneAxes) & ~bit(DigitalOutput::brake_release_bridge);
  board->write_outputs(outputs);
  EXPECT_EQ(state->calls.front().function, "dio_bitfield2");
  EXPECT_EQ(state->digital_lines[2], lines & ~(1U << 6));

  state->digital_lines[3] = 0xFFU & ~(1U << 6);  // active-low: the runway's min switch open
  EXPECT_EQ(board->read_digital_inputs(), bit(DigitalInput::bridge_min_limit));
  state->digital_lines[3] = 0xFFU & ~(1U << 5);
  EXPECT_EQ(board->read_digital_inputs(), bit(DigitalInput::bridge_max_limit));
  EXPECT_EQ(bit(DigitalInput::bridge_max_limit), 64U);  // SWITCH_BRIDGE_MAX of SensorSample_.limit_switches
  state->digital_lines[3] = 0x00U;  // every contact open: no slew switch among them
  EXPECT_EQ(board->read_digital_inputs(), limit_switch_mask(kOverheadCraneAxes) | bit(DigitalInput::emergency_stop));
  EXPECT_FALSE(contains(board->describe(), "slew_drive")) << board->describe();

  // The same board for a tower crane: four counters read, three outputs written, five lines.
  BoardConfig tower = c;
  tower.axes = kTowerCraneAxes;
  const auto tower_board = open_fake(state, tower);
  state->calls.clear();
  state->counter_values[{5, 0}] = 77U;
  tower_board->read_counters(raw);
  EXPECT_EQ(state->calls_of("data_read").size(), 4U);
  EXPECT_EQ(raw[index(CounterChannel::bridge_motor)], 0U);
  outputs.digital_outputs = (1U << kDigitalOutputCount) - 1U;  // a stray bridge bit is not written
  tower_board->write_outputs(outputs);
  EXPECT_EQ(state->calls_of("data_write").size(), 3U);
  EXPECT_EQ(state->calls_of("dio_bitfield2").back().write_mask, 0x0FU);
  state->digital_lines[3] = 0x00U;  // every contact open
  EXPECT_EQ(tower_board->read_digital_inputs(), 0x1FU);
  EXPECT_FALSE(contains(tower_board->describe(), "bridge_drive")) << tower_board->describe();
}

TEST(ComediBoard, OverheadCraneBridgeChannelsAreCheckedAtOpen) {
  const auto state = lab_board();
  BoardConfig c = overhead_board_config();
  c.counters[index(CounterChannel::bridge_motor)] = {0, 4};  // the 4-counter subdevice has no fifth
  std::string message = open_error(state, c);
  EXPECT_TRUE(contains(message, "counter bridge_motor (subdevice 0, channel 4): the subdevice has only 4 channels"))
      << message;
  c = overhead_board_config();
  c.analog_output_channels[index(AnalogOutput::bridge_drive)] = 4;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "analog output bridge_drive (subdevice 1, channel 4): the subdevice has only 4 channels"))
      << message;
  c = overhead_board_config();
  c.digital_output_bits[index(DigitalOutput::brake_release_bridge)] = 8;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "digital output brake_release_bridge (subdevice 2, channel 8)")) << message;
  c = overhead_board_config();
  c.digital_input_bits[index(DigitalInput::bridge_max_limit)] = 9;
  message = open_error(state, c);
  EXPECT_TRUE(contains(message, "digital input bridge_max_limit (subdevice 3, channel 9)")) << message;
  // The same out-of-range bridge entries are never looked at on a tower crane.
  c.axes = kTowerCraneAxes;
  c.counters[index(CounterChannel::bridge_motor)] = {0, 4};
  EXPECT_EQ(open_error(state, c), "");
}

TEST(ComediBoard, DriverErrorsNameDeviceChannelAndMessage) {
  const auto state = lab_board();
  const auto board = open_fake(state);
  std::array<std::uint32_t, kCounterCount> raw{};
  state->fail_function = "data_read";
  state->fail_skip = 2;  // the third read, swing_in_plane, fails
  try {
    board->read_counters(raw);
    FAIL() << "no error";
  } catch (const BoardError& error) {
    EXPECT_TRUE(contains(error.what(), "comedi:/dev/comedi0: comedi_data_read of counter swing_in_plane "
                                       "(subdevice 0, channel 2) failed: fake driver says no (comedi errno 5)"))
        << error.what();
  }
  state->fail_function = "data_write";
  try {
    board->write_outputs(safe_board_outputs(board->analog_ranges()));
    FAIL() << "no error";
  } catch (const BoardError& error) {
    EXPECT_TRUE(contains(error.what(), "comedi_data_write of analog output trolley_drive (subdevice 1, channel 0)"))
        << error.what();
    EXPECT_TRUE(contains(error.what(), kFakeMessage)) << error.what();
  }
  state->fail_function = "dio_bitfield2";
  EXPECT_THROW((void)board->read_digital_inputs(), BoardError);
}

}  // namespace
}  // namespace crane::hardware_bridge
