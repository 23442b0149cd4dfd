#pragma once
// The operator's stick for manual mode (deploy/crane jog, crane_jog): what the terminal keys, a
// Linux joystick/gamepad (evdev) or a scripted input file say, as speeds in [-1, 1] of the rated
// speeds per axis. Pure logic, no device, no DDS: crane_jog reads the device and publishes the
// result on rt/crane/operator/speed; the planner shapes it (speed_reference.hpp).
//
// Axis signs: trolley + outward along the jib, slew + counterclockwise, hoist + lowers the load.

#include <cstdint>
#include <string>
#include <vector>

namespace crane::launch {

struct Stick {
  double trolley{0.0};  // [-] in [-1, 1]
  double slew{0.0};     // [-]
  double hoist{0.0};    // [-]
  bool micro{false};    // fine positioning (the micro-speed fraction)
};

/// A terminal has no key-release events: a key held down repeats (after ~0.5 s, then ~30 per s).
/// A press sets its axis to full speed (either sign) for `hold` [s] after the last press, so a held
/// key keeps the axis moving and a released one stops it within `hold`. Inching mode: each press
/// is one short step (the axis moves for `inch` [s]) whether the key is held or not.
///   arrows up/down: trolley out/in; left/right: slew counterclockwise/clockwise; w/s: hoist up/down
///   (up shortens the cable); space: release every axis; m: micro-speed on/off; i: inching on/off.
class KeyboardStick {
 public:
  enum class Key : std::uint8_t { up, down, left, right, hoist_up, hoist_down, release, micro, inching, quit, other };
  /// Decodes the bytes a terminal in raw mode sends for one key (escape sequences of the arrows).
  /// Returns the key and the number of bytes it used (0: an incomplete escape sequence, wait).
  [[nodiscard]] static std::pair<Key, std::size_t> decode(const std::string& bytes);

  explicit KeyboardStick(double hold = 0.6, double inch = 0.15) : hold_(hold), inch_(inch) {}
  /// A key pressed at `time` [s].
  void press(Key key, double time);
  /// The stick at `time` [s].
  [[nodiscard]] Stick at(double time) const;
  [[nodiscard]] bool micro() const { return micro_; }
  [[nodiscard]] bool inching() const { return inching_; }

 private:
  double hold_, inch_;
  double until_[3] = {-1.0, -1.0, -1.0};  // [s] each axis moves until then
  double sign_[3] = {0.0, 0.0, 0.0};
  double started_[3] = {-1.0, -1.0, -1.0};  // inching: the press that started the step
  bool micro_{false};
  bool inching_{false};
};

/// A joystick axis value from evdev (its absinfo minimum and maximum) to [-1, 1], with a dead zone
/// around the centre (a fraction of the half-range, in [0, 0.5)): 0 inside it, then linear to +-1.
/// `invert` flips the sign (a stick pushed forward reads negative on most gamepads). Throws
/// std::invalid_argument unless minimum < maximum and the dead zone is in [0, 0.5).
[[nodiscard]] double joystick_axis(int value, int minimum, int maximum, double dead_zone, bool invert = false);

/// A scripted stick (tests): CSV lines "t, trolley, slew, hoist[, micro]" ([s], [-1, 1] each,
/// micro 0 or 1), a header line allowed, '#' comments; times strictly increasing from >= 0. The
/// stick holds each line's values until the next line's time; after the last line the script is
/// over. Throws std::invalid_argument naming the line, the column, the value and the bound.
class ScriptedStick {
 public:
  struct Row {
    double t{0.0};
    Stick stick;
  };
  [[nodiscard]] static ScriptedStick parse(const std::string& text, const std::string& source_name);
  [[nodiscard]] static ScriptedStick load(const std::string& path);
  /// The stick at `time` [s] (all 0 before the first line).
  [[nodiscard]] Stick at(double time) const;
  /// [s] the last line's time: the script is over after it.
  [[nodiscard]] double end() const { return rows_.empty() ? 0.0 : rows_.back().t; }
  [[nodiscard]] const std::vector<Row>& rows() const { return rows_; }

 private:
  std::vector<Row> rows_;
};

}  // namespace crane::launch
