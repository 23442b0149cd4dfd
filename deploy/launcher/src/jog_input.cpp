#include "crane/launch/jog_input.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace crane::launch {

std::pair<KeyboardStick::Key, std::size_t> KeyboardStick::decode(const std::string& b) {
  if (b.empty()) return {Key::other, 0};
  if (b[0] == '\x1b') {
    if (b.size() < 3) return {Key::other, 0};
    if (b[1] == '[' || b[1] == 'O') {
      switch (b[2]) {
        case 'A': return {Key::up, 3};
        case 'B': return {Key::down, 3};
        case 'C': return {Key::right, 3};
        case 'D': return {Key::left, 3};
        default: return {Key::other, 3};
      }
    }
    return {Key::other, 1};
  }
  switch (b[0]) {
    case 'w': case 'W': return {Key::hoist_up, 1};
    case 's': case 'S': return {Key::hoist_down, 1};
    case ' ': return {Key::release, 1};
    case 'm': case 'M': return {Key::micro, 1};
    case 'i': case 'I': return {Key::inching, 1};
    case 'q': case 'Q': case '\x03': return {Key::quit, 1};
    default: return {Key::other, 1};
  }
}

void KeyboardStick::press(Key key, double time) {
  int axis = -1;
  double sign = 0.0;
  switch (key) {
    case Key::up: axis = 0; sign = 1.0; break;
    case Key::down: axis = 0; sign = -1.0; break;
    case Key::left: axis = 1; sign = 1.0; break;
    case Key::right: axis = 1; sign = -1.0; break;
    case Key::hoist_up: axis = 2; sign = -1.0; break;
    case Key::hoist_down: axis = 2; sign = 1.0; break;
    case Key::release:
      for (double& u : until_) u = -1.0;
      return;
    case Key::micro: micro_ = !micro_; return;
    case Key::inching: inching_ = !inching_; return;
    case Key::quit:
    case Key::other: return;
  }
  if (inching_) {
    // One step per press: a repeat of the same key while its step runs does not extend it.
    if (time < until_[axis] && sign_[axis] == sign) return;
    started_[axis] = time;
    until_[axis] = time + inch_;
  } else {
    until_[axis] = time + hold_;
  }
  sign_[axis] = sign;
}

Stick KeyboardStick::at(double time) const {
  Stick s;
  double* v[3] = {&s.trolley, &s.slew, &s.hoist};
  for (int i = 0; i < 3; ++i) *v[i] = time < until_[i] ? sign_[i] : 0.0;
  s.micro = micro_ || inching_;  // inching moves at the micro-speed
  return s;
}

double joystick_axis(int value, int minimum, int maximum, double dead_zone, bool invert) {
  if (!(minimum < maximum)) {
    throw std::invalid_argument("joystick axis range [" + std::to_string(minimum) + ", " + std::to_string(maximum) +
                                "] is empty");
  }
  if (!(dead_zone >= 0.0 && dead_zone < 0.5)) {
    throw std::invalid_argument("joystick dead zone " + std::to_string(dead_zone) + " is out of range: must be in [0, 0.5)");
  }
  const double centre = 0.5 * (static_cast<double>(minimum) + static_cast<double>(maximum));
  const double half = 0.5 * (static_cast<double>(maximum) - static_cast<double>(minimum));
  double u = std::clamp((static_cast<double>(value) - centre) / half, -1.0, 1.0);
  if (std::abs(u) <= dead_zone) return 0.0;
  u = std::copysign((std::abs(u) - dead_zone) / (1.0 - dead_zone), u);
  return invert ? -u : u;
}

ScriptedStick ScriptedStick::parse(const std::string& text, const std::string& source) {
  ScriptedStick script;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  static const char* kColumns[] = {"t", "trolley", "slew", "hoist", "micro"};
  while (std::getline(lines, line)) {
    ++number;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.erase(hash);
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::vector<std::string> cells;
    std::stringstream row(line);
    std::string cell;
    while (std::getline(row, cell, ',')) cells.push_back(cell);
    const std::string where = source + ":" + std::to_string(number);
    if (script.rows_.empty() && number == 1 && !cells.empty() && cells[0].find_first_of("0123456789.-+") != 0 &&
        cells[0].find_first_not_of(" \t") != std::string::npos &&
        std::isalpha(static_cast<unsigned char>(cells[0][cells[0].find_first_not_of(" \t")])) != 0) {
      continue;  // a header line
    }
    if (cells.size() < 4 || cells.size() > 5) {
      throw std::invalid_argument(where + ": " + std::to_string(cells.size()) +
                                  " columns: expected t, trolley, slew, hoist[, micro]");
    }
    double values[5] = {0, 0, 0, 0, 0};
    for (std::size_t c = 0; c < cells.size(); ++c) {
      std::size_t used = 0;
      try {
        values[c] = std::stod(cells[c], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used == 0 || cells[c].find_first_not_of(" \t\r", used) != std::string::npos) {
        throw std::invalid_argument(where + ": " + kColumns[c] + " = '" + cells[c] + "' is not a number");
      }
      if (!std::isfinite(values[c])) {
        throw std::invalid_argument(where + ": " + kColumns[c] + " = '" + cells[c] + "' is not finite");
      }
    }
    for (std::size_t c = 1; c < 4; ++c) {
      if (std::abs(values[c]) > 1.0) {
        throw std::invalid_argument(where + ": " + kColumns[c] + " = " + cells[c] + " is out of range: must be in [-1, 1]");
      }
    }
    if (values[4] != 0.0 && values[4] != 1.0) {
      throw std::invalid_argument(where + ": micro = " + cells[4] + " must be 0 or 1");
    }
    if (values[0] < 0.0) throw std::invalid_argument(where + ": t = " + cells[0] + " is out of range: must be >= 0");
    if (!script.rows_.empty() && !(values[0] > script.rows_.back().t)) {
      throw std::invalid_argument(where + ": t = " + cells[0] + " is not after the previous line's " +
                                  std::to_string(script.rows_.back().t));
    }
    script.rows_.push_back({values[0], Stick{values[1], values[2], values[3], values[4] == 1.0}});
  }
  if (script.rows_.empty()) throw std::invalid_argument(source + ": no line of t, trolley, slew, hoist");
  return script;
}

ScriptedStick ScriptedStick::load(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw std::invalid_argument(path + ": cannot be read");
  std::stringstream text;
  text << file.rdbuf();
  return parse(text.str(), path);
}

Stick ScriptedStick::at(double time) const {
  Stick s;
  for (const auto& row : rows_) {
    if (row.t > time) break;
    s = row.stick;
  }
  return s;
}

}  // namespace crane::launch
