// crane_jog: the operator's speed commands for manual mode (deploy/crane jog), on
// rt/crane/operator/speed at --rate Hz, from one of
//   the keyboard of this terminal (default): arrows trolley/slew, w/s hoist, space release,
//     m micro-speed, i inching, q quit (jog_input.hpp);
//   a Linux joystick or gamepad (--device /dev/input/eventN, read through libevdev): the left stick
//     moves the trolley (up: out) and the slew (left: counterclockwise), the right stick's vertical
//     axis the hoist (down: lowers), the left shoulder button held: micro-speed;
//   a scripted input file (--script F.csv: t, trolley, slew, hoist[, micro]), for tests.
// The planner takes operator speeds only in MANUAL, SEMIAUTOMATIC and MAINTENANCE (deploy/crane mode),
// shapes them against the swing and releases every axis when nothing arrives for its dead-man
// timeout (200 ms): a device unplugged or this process killed stops the load softly.
//
// Exit codes: 0 done (script over, q pressed, Ctrl-C), 1 no planner listens within --timeout or
// the device cannot be opened, 2 bad usage or a bad script (the message names the line, column,
// value and bound), 3 the device went away while jogging.
#include <fcntl.h>
#include <libevdev/libevdev.h>
#include <termios.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <thread>

#include "crane/launch/jog_input.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
using Speed = protocol::OperatorSpeed;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

// The terminal in raw mode while jogging, restored on every exit path.
class RawTerminal {
 public:
  RawTerminal() {
    if (tcgetattr(STDIN_FILENO, &saved_) != 0) throw std::runtime_error("stdin is not a terminal: give --script or --device");
    termios raw = saved_;
    raw.c_lflag &= ~static_cast<tcflag_t>(ICANON | ECHO);
    raw.c_cc[VMIN] = 0;
    raw.c_cc[VTIME] = 0;
    tcsetattr(STDIN_FILENO, TCSANOW, &raw);
  }
  ~RawTerminal() { tcsetattr(STDIN_FILENO, TCSANOW, &saved_); }
  RawTerminal(const RawTerminal&) = delete;
  RawTerminal& operator=(const RawTerminal&) = delete;

 private:
  termios saved_{};
};

// A joystick through libevdev: the latest stick, or the device gone.
class Joystick {
 public:
  Joystick(const std::string& path, double dead_zone) : dead_zone_(dead_zone) {
    fd_ = open(path.c_str(), O_RDONLY | O_NONBLOCK);
    if (fd_ < 0) throw std::runtime_error(path + ": " + std::strerror(errno));
    if (libevdev_new_from_fd(fd_, &device_) < 0) throw std::runtime_error(path + ": not an input device");
    for (const int code : {ABS_X, ABS_Y}) {
      if (!libevdev_has_event_code(device_, EV_ABS, static_cast<unsigned>(code))) {
        throw std::runtime_error(path + " (" + libevdev_get_name(device_) + "): no " +
                                 libevdev_event_code_get_name(EV_ABS, static_cast<unsigned>(code)) + " axis");
      }
    }
    std::printf("joystick: %s\n", libevdev_get_name(device_));
  }
  ~Joystick() {
    if (device_ != nullptr) libevdev_free(device_);
    if (fd_ >= 0) close(fd_);
  }
  Joystick(const Joystick&) = delete;
  Joystick& operator=(const Joystick&) = delete;

  /// Reads the pending events; false when the device went away (unplugged).
  bool poll() {
    input_event event{};
    for (;;) {
      const int rc = libevdev_next_event(device_, LIBEVDEV_READ_FLAG_NORMAL, &event);
      if (rc == -EAGAIN) return true;
      if (rc == LIBEVDEV_READ_STATUS_SYNC) {
        while (libevdev_next_event(device_, LIBEVDEV_READ_FLAG_SYNC, &event) == LIBEVDEV_READ_STATUS_SYNC) {}
        continue;
      }
      if (rc < 0) return false;  // -ENODEV: unplugged
    }
  }
  [[nodiscard]] launch::Stick stick() const {
    launch::Stick s;
    s.trolley = axis(ABS_Y, true);
    s.slew = axis(ABS_X, true);
    s.hoist = libevdev_has_event_code(device_, EV_ABS, ABS_RY) ? axis(ABS_RY, false) : 0.0;
    s.micro = libevdev_get_event_value(device_, EV_KEY, BTN_TL) != 0;
    return s;
  }

 private:
  [[nodiscard]] double axis(unsigned code, bool invert) const {
    const input_absinfo* info = libevdev_get_abs_info(device_, code);
    if (info == nullptr) return 0.0;
    return launch::joystick_axis(libevdev_get_event_value(device_, EV_ABS, code), info->minimum, info->maximum,
                                 dead_zone_, invert);
  }
  int fd_{-1};
  libevdev* device_{nullptr};
  double dead_zone_;
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_jog: the operator's speed commands for manual mode (keyboard, joystick or script)"};
  runtime::NodeOptions node;
  std::string script_path, device_path;
  double rate = 50.0, timeout = 10.0, dead_zone = 0.08;
  app.add_option("--script", script_path, "scripted stick: CSV t, trolley, slew, hoist[, micro] (tests)");
  app.add_option("--device", device_path, "joystick or gamepad: /dev/input/eventN (libevdev)");
  app.add_option("--rate", rate, "[Hz] samples per second (the planner's dead man wants one per 200 ms)")
      ->check(CLI::Range(10.0, 1000.0));
  app.add_option("--dead-zone", dead_zone, "joystick dead zone, fraction of the half range")->check(CLI::Range(0.0, 0.49));
  app.add_option("--timeout", timeout, "[s] wait for the planner to listen")->check(CLI::PositiveNumber);
  app.add_option("--dds", node.dds, "DDS vendor: fast | cyclone (default: $CRANE_DDS, else fast)");
  app.add_option("--domain", node.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  runtime::add_security_options(app, node);  // identity: the participant's, "operator"
  CLI11_PARSE(app, argc, argv);
  if (!script_path.empty() && !device_path.empty()) {
    std::fprintf(stderr, "crane_jog: give --script or --device, not both\n");
    return 2;
  }
  std::optional<launch::ScriptedStick> script;
  try {
    if (!script_path.empty()) script = launch::ScriptedStick::load(script_path);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_jog: %s\n", error.what());
    return 2;
  }
  try {
    runtime::configure_logging("warn", "jog");
    std::setvbuf(stdout, nullptr, _IOLBF, 0);
    std::optional<Joystick> joystick;
    if (!device_path.empty()) joystick.emplace(device_path, dead_zone);
    std::optional<RawTerminal> terminal;
    launch::KeyboardStick keyboard;
    if (!script && !joystick) terminal.emplace();

    auto participant = runtime::make_participant(node, "operator");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto writer = participant->make_writer<tp::OperatorSpeed>();
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
    while (writer->health().matched_readers == 0 && Clock::now() < deadline && !runtime::stop_requested()) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (writer->health().matched_readers == 0) {
      std::fprintf(stderr, "crane_jog: no planner listens on rt/crane/operator/speed (domain %u) within %.0f s\n",
                   node.domain_id, timeout);
      return 1;
    }
    if (terminal) {
      std::printf("jog: arrows trolley (up: out) and slew (left: counterclockwise), w/s hoist up/down, space release,"
                  " m micro-speed, i inching, q quit\n");
    }
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate));
    const auto start = Clock::now();
    auto next = start;
    std::uint64_t seq = 0;
    std::string pending;
    launch::Stick last_shown;
    for (;;) {
      if (runtime::stop_requested()) break;
      const double t = seconds_since(start);
      launch::Stick stick;
      std::uint8_t device = Speed::DEVICE_KEYBOARD;
      if (script) {
        device = Speed::DEVICE_SCRIPT;
        if (t > script->end() + 0.5) break;  // neutral for half a second after the last line, then done
        stick = t > script->end() ? launch::Stick{} : script->at(t);
      } else if (joystick) {
        device = Speed::DEVICE_JOYSTICK;
        if (!joystick->poll()) {
          std::fprintf(stderr, "crane_jog: %s went away: no more samples, the planner's dead man releases every "
                               "axis (a soft stop)\n", device_path.c_str());
          return 3;
        }
        stick = joystick->stick();
      } else {
        char bytes[64];
        const ssize_t n = read(STDIN_FILENO, bytes, sizeof(bytes));
        if (n > 0) pending.append(bytes, static_cast<std::size_t>(n));
        bool quit = false;
        for (;;) {
          const auto [key, used] = launch::KeyboardStick::decode(pending);
          if (used == 0) break;
          pending.erase(0, used);
          if (key == launch::KeyboardStick::Key::quit) quit = true;
          keyboard.press(key, t);
        }
        if (quit) break;
        stick = keyboard.at(t);
      }
      tp::msgs::OperatorSpeed_ message;
      Speed plain;
      plain.header.seq = ++seq;
      plain.device = device;
      plain.range = stick.micro ? Speed::RANGE_MICRO : Speed::RANGE_NORMAL;
      plain.trolley = stick.trolley;
      plain.slew = stick.slew;
      plain.hoist = stick.hoist;
      protocol::to_dds(plain, message);
      message.header().stamp(runtime::now_stamp());
      writer->write(message);
      if (terminal && (stick.trolley != last_shown.trolley || stick.slew != last_shown.slew ||
                       stick.hoist != last_shown.hoist || stick.micro != last_shown.micro)) {
        std::printf("\rtrolley %+.0f  slew %+.0f  hoist %+.0f  %s%s      ", stick.trolley, stick.slew, stick.hoist,
                    stick.micro ? "micro" : "normal", keyboard.inching() ? " inching" : "");
        std::fflush(stdout);
        last_shown = stick;
      }
      next += period;
      std::this_thread::sleep_until(next);
    }
    // Neutral before leaving (the dead man would release the axes anyway, 200 ms later).
    tp::msgs::OperatorSpeed_ neutral;
    Speed plain;
    plain.header.seq = ++seq;
    protocol::to_dds(plain, neutral);
    neutral.header().stamp(runtime::now_stamp());
    writer->write(neutral);
    if (terminal) std::printf("\n");
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_jog: %s\n", error.what());
    return 1;
  }
}
