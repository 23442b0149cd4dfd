// The operator's stick for manual mode (jog_input.hpp): the terminal's key codes and hold rule,
// inching, the joystick axis mapping with its dead zone, and the scripted input file with its
// errors naming the line, the column, the value and the bound.
#include <gtest/gtest.h>

#include <string>

#include "crane/launch/jog_input.hpp"

namespace {
using crane::launch::joystick_axis;
using crane::launch::KeyboardStick;
using crane::launch::ScriptedStick;
using Key = KeyboardStick::Key;

TEST(JogKeyboard, DecodesArrowsAndKeys) {
  EXPECT_EQ(KeyboardStick::decode("\x1b[A"), std::make_pair(Key::up, std::size_t{3}));
  EXPECT_EQ(KeyboardStick::decode("\x1b[D"), std::make_pair(Key::left, std::size_t{3}));
  EXPECT_EQ(KeyboardStick::decode("\x1bOB"), std::make_pair(Key::down, std::size_t{3}));  // application mode
  EXPECT_EQ(KeyboardStick::decode("\x1b["), std::make_pair(Key::other, std::size_t{0}));  // incomplete: wait
  EXPECT_EQ(KeyboardStick::decode("w"), std::make_pair(Key::hoist_up, std::size_t{1}));
  EXPECT_EQ(KeyboardStick::decode(" "), std::make_pair(Key::release, std::size_t{1}));
  EXPECT_EQ(KeyboardStick::decode("\x03"), std::make_pair(Key::quit, std::size_t{1}));
}

TEST(JogKeyboard, AHeldKeyMovesAReleasedOneStopsWithinTheHold) {
  KeyboardStick k(0.6, 0.15);
  k.press(Key::up, 0.0);
  EXPECT_EQ(k.at(0.3).trolley, 1.0);
  k.press(Key::up, 0.5);  // autorepeat
  EXPECT_EQ(k.at(1.0).trolley, 1.0);
  EXPECT_EQ(k.at(1.11).trolley, 0.0);  // 0.6 s after the last press
  k.press(Key::right, 2.0);
  EXPECT_EQ(k.at(2.1).slew, -1.0);  // right: clockwise
  k.press(Key::hoist_up, 2.0);
  EXPECT_EQ(k.at(2.1).hoist, -1.0);  // up shortens the cable
  k.press(Key::release, 2.2);
  EXPECT_EQ(k.at(2.3).slew, 0.0);
  EXPECT_EQ(k.at(2.3).hoist, 0.0);
  k.press(Key::micro, 3.0);
  EXPECT_TRUE(k.at(3.0).micro);
}

TEST(JogKeyboard, InchingIsOneShortStepPerPress) {
  KeyboardStick k(0.6, 0.15);
  k.press(Key::inching, 0.0);
  k.press(Key::up, 1.0);
  EXPECT_EQ(k.at(1.1).trolley, 1.0);
  EXPECT_TRUE(k.at(1.1).micro);  // inching moves at the micro-speed
  k.press(Key::up, 1.12);          // a repeat while the step runs does not extend it
  EXPECT_EQ(k.at(1.16).trolley, 0.0);
  k.press(Key::up, 1.2);           // a new press: a new step
  EXPECT_EQ(k.at(1.3).trolley, 1.0);
}

TEST(JogJoystick, AxisWithDeadZoneAndInversion) {
  EXPECT_EQ(joystick_axis(128, 0, 255, 0.1), 0.0);  // about the centre
  EXPECT_NEAR(joystick_axis(255, 0, 255, 0.1), 1.0, 1e-12);
  EXPECT_NEAR(joystick_axis(0, 0, 255, 0.1), -1.0, 1e-12);
  EXPECT_NEAR(joystick_axis(0, 0, 255, 0.1, true), 1.0, 1e-12);
  // Half-way between the dead zone's edge and the end: 0.5.
  EXPECT_NEAR(joystick_axis(18022, -32768, 32767, 0.1), 0.5, 1e-4);  // u = 0.55: (0.55 - 0.1) / 0.9
  EXPECT_EQ(joystick_axis(40000, -32768, 32767, 0.0), 1.0);  // clamped
  EXPECT_THROW((void)joystick_axis(0, 5, 5, 0.1), std::invalid_argument);
  EXPECT_THROW((void)joystick_axis(0, 0, 255, 0.5), std::invalid_argument);
}

TEST(JogScript, HoldsEachLineUntilTheNext) {
  const auto s = ScriptedStick::parse("t,trolley,slew,hoist,micro\n0, 1, 0, 0\n3, 0, -0.5, 0.25, 1\n# done\n4,0,0,0\n",
                                      "stick.csv");
  ASSERT_EQ(s.rows().size(), 3U);
  EXPECT_EQ(s.at(-1.0).trolley, 0.0);
  EXPECT_EQ(s.at(2.99).trolley, 1.0);
  EXPECT_EQ(s.at(3.0).slew, -0.5);
  EXPECT_TRUE(s.at(3.5).micro);
  EXPECT_EQ(s.end(), 4.0);
}

TEST(JogScript, BadLinesAreRefusedNamingLineColumnValueAndBound) {
  const auto refused = [](const std::string& text, const std::string& expected) {
    try {
      (void)ScriptedStick::parse(text, "stick.csv");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  };
  refused("0,1.5,0,0\n", "stick.csv:1: trolley = 1.5 is out of range: must be in [-1, 1]");
  refused("0,0,0,0\n0,0,0,0\n", "stick.csv:2: t = 0 is not after the previous line's");
  refused("0,0,nan,0\n", "stick.csv:1: slew = 'nan' is not finite");
  refused("0,0,x,0\n", "stick.csv:1: slew = 'x' is not a number");
  refused("0,0,0\n", "stick.csv:1: 3 columns: expected t, trolley, slew, hoist[, micro]");
  refused("0,0,0,0,2\n", "stick.csv:1: micro = 2 must be 0 or 1");
  refused("-1,0,0,0\n", "stick.csv:1: t = -1 is out of range: must be >= 0");
  refused("# nothing\n", "stick.csv: no line");
}

}  // namespace
