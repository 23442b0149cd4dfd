// libFuzzer harness: the operator's input parsers of crane_jog (jog_input.hpp): the scripted stick
// (ScriptedStick::parse: CSV lines, throws std::invalid_argument) and the terminal's key decoder
// (KeyboardStick::decode, then press()/at()). Every stick value must stay in [-1, 1] (what the
// planner is promised), whatever the input.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "crane/launch/jog_input.hpp"

namespace {

void check(const crane::launch::Stick& s) {
  for (const double v : {s.trolley, s.slew, s.hoist}) {
    if (!(std::isfinite(v) && v >= -1.0 && v <= 1.0)) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto script = crane::launch::ScriptedStick::parse(text, "fuzz.csv");
    for (const auto& row : script.rows()) {
      check(row.stick);
      check(script.at(row.t));
      check(script.at(row.t + 0.005));
    }
    check(script.at(-1.0));
    check(script.at(script.end() + 1.0));
  } catch (const std::invalid_argument&) {
  }
  // The same bytes as a terminal's key presses, one every 10 ms.
  crane::launch::KeyboardStick keyboard;
  std::string pending = text;
  double time = 0.0;
  while (!pending.empty()) {
    const auto [key, used] = crane::launch::KeyboardStick::decode(pending);
    if (used == 0) break;  // an incomplete escape sequence: wait for more bytes
    if (used > pending.size()) std::abort();
    pending.erase(0, used);
    keyboard.press(key, time);
    check(keyboard.at(time));
    time += 0.01;
  }
  check(keyboard.at(time + 10.0));
  return 0;
}
