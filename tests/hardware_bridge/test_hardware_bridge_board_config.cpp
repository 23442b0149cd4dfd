// BoardConfig validation and the open_board() URI factory.
#include <gtest/gtest.h>
#include <unistd.h>

#include <string>

#include "crane/common/validation.hpp"
#include "crane/hardware_bridge/board.hpp"
#include "crane/hardware_bridge/shm_board.hpp"

namespace crane::hardware_bridge {
namespace {

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The ConfigError message of validate(config), or "" if it passed.
std::string validation_error(const BoardConfig& config, const char* prefix = "board") {
  try {
    validate(config, prefix);
  } catch (const common::ConfigError& error) {
    return error.what();
  }
  return "";
}

std::string unique_name(const char* what) { return std::string("cfg_") + what + "_" + std::to_string(getpid()); }

TEST(BoardConfig, DefaultsAreValid) { EXPECT_EQ(validation_error(BoardConfig{}), ""); }

TEST(BoardConfig, MessagesNameFieldValueAndBound) {
  BoardConfig c;
  c.counter_bits = 1;
  EXPECT_TRUE(contains(validation_error(c), "board.counter_bits = 1 is out of range: must be in [2, 32]"))
      << validation_error(c);
  c = BoardConfig{};
  c.counter_bits = 33;
  EXPECT_TRUE(contains(validation_error(c, "hardware_bridge.board"), "hardware_bridge.board.counter_bits = 33"));

  c = BoardConfig{};
  c.counters[2].channel = -1;
  EXPECT_TRUE(contains(validation_error(c), "board.counters[2].channel = -1 is out of range: must be >= 0"))
      << validation_error(c);
  c = BoardConfig{};
  c.counters[3].subdevice = -2;
  EXPECT_TRUE(contains(validation_error(c), "board.counters[3].subdevice = -2")) << validation_error(c);

  c = BoardConfig{};
  c.analog_output_range = -1;
  EXPECT_TRUE(contains(validation_error(c), "board.analog_output_range = -1")) << validation_error(c);

  c = BoardConfig{};
  c.digital_output_bits[3] = 32;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_output_bits[3] = 32 is out of range: must be in [0, 31]"))
      << validation_error(c);
  c = BoardConfig{};
  c.digital_input_bits[4] = -1;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_input_bits[4] = -1")) << validation_error(c);
}

TEST(BoardConfig, DuplicatesAreRejected) {
  BoardConfig c;
  c.analog_output_channels = {0, 2, 0};
  EXPECT_TRUE(contains(validation_error(c), "board.analog_output_channels[2] = 0 is out of range: must differ from "
                                            "board.analog_output_channels[0]"))
      << validation_error(c);

  c = BoardConfig{};
  c.counters[1] = c.counters[0];
  EXPECT_TRUE(contains(validation_error(c), "board.counters[1].channel")) << validation_error(c);
  // The same channel number on another subdevice is a different counter (one subdevice per counter).
  c = BoardConfig{};
  c.counters = {{{4, 0}, {5, 0}, {6, 0}, {7, 0}}};
  EXPECT_EQ(validation_error(c), "");

  c = BoardConfig{};
  c.digital_output_bits = {0, 1, 1, 3};
  EXPECT_TRUE(contains(validation_error(c), "board.digital_output_bits[2] = 1")) << validation_error(c);

  // Inputs and outputs on one DIO subdevice must use different lines; on separate subdevices they may not.
  c = BoardConfig{};
  c.digital_input_subdevice = c.digital_output_subdevice;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_input_bits[0] = 0")) << validation_error(c);
  c.digital_input_bits = {8, 9, 10, 11, 12};
  EXPECT_EQ(validation_error(c), "");
}

// The bridge's entries (the last of each array) are validated on an overhead crane only.
TEST(BoardConfig, BridgeChannelsAreValidatedOnAnOverheadCraneOnly) {
  BoardConfig c;
  c.counters[index(CounterChannel::bridge_motor)] = c.counters[0];
  c.analog_output_channels[index(AnalogOutput::bridge_drive)] = -1;
  c.digital_output_bits[index(DigitalOutput::brake_release_bridge)] = 40;
  c.digital_input_bits[index(DigitalInput::bridge_min_limit)] = 4;  // the emergency stop's line
  EXPECT_EQ(validation_error(c), "");  // a tower crane has none of them
  c.axes = kOverheadCraneAxes;
  c.counters[index(CounterChannel::slew_motor)] = c.counters[0];  // nor has an overhead crane the slew's
  c.analog_output_channels[index(AnalogOutput::slew_drive)] = -1;
  EXPECT_TRUE(contains(validation_error(c), "board.counters[4].channel = 0 is out of range: must differ from "
                                            "board.counters[0].channel on the same subdevice"))
      << validation_error(c);
  c.counters[index(CounterChannel::bridge_motor)] = {1, 0};
  EXPECT_TRUE(contains(validation_error(c), "board.analog_output_channels[3] = -1")) << validation_error(c);
  c.analog_output_channels[index(AnalogOutput::bridge_drive)] = 3;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_output_bits[4] = 40 is out of range: must be in [0, 31]"))
      << validation_error(c);
  c.digital_output_bits[index(DigitalOutput::brake_release_bridge)] = 4;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_input_bits[5] = 4 is out of range: must differ from "
                                            "board.digital_input_bits[4]"))
      << validation_error(c);
  c.digital_input_bits[index(DigitalInput::bridge_min_limit)] = 5;
  EXPECT_EQ(validation_error(c), "");
  // On one DIO subdevice the bridge's brake line and its switches must differ too.
  c.digital_input_subdevice = c.digital_output_subdevice;
  c.digital_input_bits = {8, 9, 10, 11, 12, 13, 4};
  EXPECT_TRUE(contains(validation_error(c), "board.digital_input_bits[6] = 4")) << validation_error(c);
  EXPECT_TRUE(contains(validation_error(c), "board.digital_output_bits[4] (same subdevice)")) << validation_error(c);
}

// The slew's entries (counter 1, analog output 1, output line 1, input lines 2 and 3) are validated
// on a tower crane only: a gantry or overhead crane has no slew.
TEST(BoardConfig, SlewChannelsAreValidatedOnATowerCraneOnly) {
  BoardConfig c;
  c.counters[index(CounterChannel::slew_motor)] = c.counters[0];
  c.analog_output_channels[index(AnalogOutput::slew_drive)] = -1;
  c.digital_output_bits[index(DigitalOutput::brake_release_slew)] = 40;
  c.digital_input_bits[index(DigitalInput::slew_min_limit)] = 4;  // the emergency stop's line
  c.digital_input_bits[index(DigitalInput::slew_max_limit)] = 0;  // the trolley's min switch
  c.axes = kGantryCraneAxes;
  EXPECT_EQ(validation_error(c), "");
  c.axes = kTowerCraneAxes;
  EXPECT_TRUE(contains(validation_error(c), "board.counters[1].channel = 0 is out of range: must differ from "
                                            "board.counters[0].channel on the same subdevice"))
      << validation_error(c);
  c.counters[index(CounterChannel::slew_motor)] = {0, 1};
  EXPECT_TRUE(contains(validation_error(c), "board.analog_output_channels[1] = -1")) << validation_error(c);
  c.analog_output_channels[index(AnalogOutput::slew_drive)] = 1;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_output_bits[1] = 40 is out of range: must be in [0, 31]"))
      << validation_error(c);
  c.digital_output_bits[index(DigitalOutput::brake_release_slew)] = 1;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_input_bits[3] = 0 is out of range: must differ from "
                                            "board.digital_input_bits[0]"))
      << validation_error(c);
  c.digital_input_bits[index(DigitalInput::slew_max_limit)] = 3;
  EXPECT_TRUE(contains(validation_error(c), "board.digital_input_bits[4] = 4 is out of range: must differ from "
                                            "board.digital_input_bits[2]"))
      << validation_error(c);
  c.digital_input_bits[index(DigitalInput::slew_min_limit)] = 2;
  EXPECT_EQ(validation_error(c), "");
}

TEST(BoardChannels, NamesAndTheLogicalLayout) {
  EXPECT_STREQ(channel_name(CounterChannel::bridge_motor), "bridge_motor");
  EXPECT_STREQ(channel_name(AnalogOutput::bridge_drive), "bridge_drive");
  EXPECT_STREQ(line_name(DigitalOutput::brake_release_bridge), "brake_release_bridge");
  EXPECT_STREQ(line_name(DigitalInput::bridge_min_limit), "bridge_min_limit");
  EXPECT_STREQ(line_name(DigitalInput::bridge_max_limit), "bridge_max_limit");
  EXPECT_STREQ(channel_name(static_cast<CounterChannel>(9)), "unknown");
  // The limit-switch bits are SensorSample_.limit_switches' (idl/crane_msgs.idl): 1, 2, 4, 8, 32, 64.
  EXPECT_EQ(kLimitSwitchMask, 1U + 2U + 4U + 8U + 32U + 64U);
  // Limit switches: trolley and slew on a tower crane, trolley alone on a gantry, trolley and
  // runway on an overhead crane.
  EXPECT_EQ(limit_switch_mask(kTowerCraneAxes), 0x0FU);
  EXPECT_EQ(limit_switch_mask(kGantryCraneAxes), 0x03U);
  EXPECT_EQ(limit_switch_mask(kOverheadCraneAxes), 0x63U);
  EXPECT_EQ(bit(DigitalInput::emergency_stop), 16U);
  // Brake lines and the drive enable: 0 trolley, 1 slew, 2 hoist, 3 enable, 4 bridge.
  EXPECT_EQ(all_outputs_energized(kTowerCraneAxes), 0x0FU);
  EXPECT_EQ(all_outputs_energized(kGantryCraneAxes), 0x0DU);
  EXPECT_EQ(all_outputs_energized(kOverheadCraneAxes), 0x1DU);
  EXPECT_EQ(travel_brake_lines(kTowerCraneAxes), 0x03U);
  EXPECT_EQ(travel_brake_lines(kGantryCraneAxes), 0x01U);
  EXPECT_EQ(travel_brake_lines(kOverheadCraneAxes), 0x11U);
  EXPECT_TRUE(uses(kTowerCraneAxes, CounterChannel::slew_motor));
  EXPECT_FALSE(uses(kTowerCraneAxes, CounterChannel::bridge_motor));
  EXPECT_FALSE(uses(kGantryCraneAxes, AnalogOutput::slew_drive));
  EXPECT_FALSE(uses(kOverheadCraneAxes, DigitalInput::slew_max_limit));
  EXPECT_TRUE(uses(kOverheadCraneAxes, DigitalInput::bridge_min_limit));
  EXPECT_TRUE(uses(kGantryCraneAxes, CounterChannel::swing_out_of_plane));
}

TEST(OpenBoard, MalformedUrisNameTheUriAndTheAcceptedForms) {
  for (const std::string uri : {"", "comedi:", "comedi:/dev/ttyS0", "comedi:/dev/comedi", "comedi:/dev/comedi0x",
                                "comedi:dev/comedi0", "COMEDI:/dev/comedi0", "shm:", "shm:a/b", "shm:has space",
                                "file:/tmp/x", "shm"}) {
    try {
      (void)open_board(uri, BoardConfig{});
      FAIL() << "accepted '" << uri << "'";
    } catch (const common::ConfigError& error) {
      const std::string message = error.what();
      EXPECT_TRUE(contains(message, "'" + uri + "'")) << message;
      EXPECT_TRUE(contains(message, "comedi:/dev/comediN")) << message;
      EXPECT_TRUE(contains(message, "shm:NAME")) << message;
    }
  }
}

TEST(OpenBoard, InvalidConfigIsRejectedBeforeOpening) {
  BoardConfig c;
  c.counter_bits = 0;
  EXPECT_THROW((void)open_board("shm:whatever", c), common::ConfigError);
}

TEST(OpenBoard, MissingDevicesThrowBoardErrorNamingThem) {
  const std::string name = unique_name("missing");
  try {
    (void)open_board("shm:" + name, BoardConfig{});
    FAIL() << "opened a missing segment";
  } catch (const BoardError& error) {
    EXPECT_TRUE(contains(error.what(), "/crane_board_" + name)) << error.what();
  }
  // The real libcomedi on a device number that does not exist (no hardware needed).
  try {
    (void)open_board("comedi:/dev/comedi987", BoardConfig{});
    FAIL() << "opened /dev/comedi987";
  } catch (const BoardError& error) {
    EXPECT_TRUE(contains(error.what(), "comedi:/dev/comedi987")) << error.what();
    EXPECT_TRUE(contains(error.what(), "comedi_open failed")) << error.what();
  }
}

TEST(OpenBoard, OpensTheEmulatedBoard) {
  const std::string name = unique_name("open");
  const ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
  const std::unique_ptr<Board> board = open_board("shm:" + name, BoardConfig{});
  ASSERT_NE(board, nullptr);
  EXPECT_EQ(board->counter_bits(), 24);
  EXPECT_TRUE(contains(board->describe(), "shm:" + name)) << board->describe();
  // The emulated board wants the configured counter width.
  BoardConfig sixteen;
  sixteen.counter_bits = 16;
  EXPECT_THROW((void)open_board("shm:" + name, sixteen), BoardError);
}

}  // namespace
}  // namespace crane::hardware_bridge
