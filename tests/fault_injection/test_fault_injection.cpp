// Fault injection against the hardware-in-the-loop stack: the real hardware_bridge process on the
// emulated interface board, the simulated plant behind the board, every stage its own process, all
// on the wall clock (--realtime: the bridge's watchdog is a wall-clock matter). Each test prints its
// figure. Run inside a private network namespace (deploy/crane test does); otherwise every
// participant is bound to loopback.
//
// What is measured and how:
//  - the board's outputs: a thread in this process maps the emulated board (ShmBoardEmulator::attach)
//    and records every write of the bridge with its CLOCK_MONOTONIC time (written by the bridge);
//  - "the last good command": this process also subscribes to rt/crane/hw/actuators and stamps the
//    arrival of each command on the same clock; the last one before a fault is the last good one;
//  - the load's travel after a fault: from the sensor samples the bridge keeps publishing.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <nlohmann/json.hpp>
#include <map>
#include <optional>
#include <regex>
#include <sstream>
#include <thread>

#include "crane/config/config_document.hpp"
#include "crane/hardware_bridge/shm_board.hpp"
#include "crane/launch/process_group.hpp"
#include "crane/launch/stack.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/supervisor/actuation_gate.hpp"
#include "crane/testing/scratch_directory.hpp"
#include "crane/supervisor/operator_socket.hpp"

namespace {
// With CRANE_SECURITY set (ctest fault_injection_secured.*: the material of tests/security), every
// process of the stack runs secured (each reads $CRANE_SECURITY) and this test's participant is the
// operator identity. Empty: no security, as before.
std::string security_directory() {
  const char* dir = std::getenv("CRANE_SECURITY");
  return dir == nullptr ? std::string() : std::string(dir);
}

namespace fs = std::filesystem;
namespace tp = crane::transport::topics;
namespace hb = crane::hardware_bridge;
using Status = crane::protocol::SupervisorStatus;  // its codes: MODE_*, FAULT_*, WARNING_*, STAGES_ALL
using crane::launch::ProcessGroup;
using Clock = std::chrono::steady_clock;

const std::string kBin = CRANE_BIN_DIR;
const std::string kConfig = std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml";
/// kConfig's actuation gate (watchdog_timeout, sample_period [s]), as the bridge reads it.
const crane::supervisor::ActuationGateParams& gate_params() {
  static const auto params =
      crane::config::ConfigDocument::load(kConfig).read("actuation", crane::supervisor::read_actuation_params);
  return params;
}

// crane_fault_<name>_<pid>, removed at the end of a test that passes (scratch_directory.hpp).
fs::path fresh_directory(const std::string& name) { return crane::testing::scratch_directory("fault_" + name); }

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

/// Records every write of the bridge to the emulated board.
class BoardMonitor {
 public:
  struct Write {
    std::int64_t ns;          // CLOCK_MONOTONIC time of the write
    std::uint32_t digital;    // logical digital output word
    double trolley_volts;
    double slew_volts;
  };

  explicit BoardMonitor(const std::string& name) : board_(attach(name)) {
    thread_ = std::thread([this] { run(); });
  }
  BoardMonitor(const BoardMonitor&) = delete;
  BoardMonitor& operator=(const BoardMonitor&) = delete;
  ~BoardMonitor() {
    stop_ = true;
    thread_.join();
  }
  std::vector<Write> writes() const {
    std::lock_guard lock(mutex_);
    return writes_;
  }
  void set_emergency_stop(bool pressed) { board_.set_digital_input(hb::DigitalInput::emergency_stop, pressed); }

 private:
  static hb::ShmBoardEmulator attach(const std::string& name) {
    const auto deadline = Clock::now() + std::chrono::seconds(20);
    for (;;) {
      try {
        return hb::ShmBoardEmulator::attach(name);
      } catch (const hb::BoardError&) {
        if (Clock::now() > deadline) throw;
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
    }
  }
  void run() {
    std::uint64_t seen = 0;
    while (!stop_) {
      try {
        const auto o = board_.read_outputs();
        if (o.write_count != seen) {
          seen = o.write_count;
          std::lock_guard lock(mutex_);
          writes_.push_back({o.last_write_ns, o.outputs.digital_outputs,
                             board_.output_volts(o, hb::AnalogOutput::trolley_drive),
                             board_.output_volts(o, hb::AnalogOutput::slew_drive)});
        }
      } catch (const hb::BoardError&) {
        // the bridge died in the middle of a write: keep watching
      }
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
  }
  hb::ShmBoardEmulator board_;
  mutable std::mutex mutex_;
  std::vector<Write> writes_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

bool safe(const BoardMonitor::Write& w) { return w.digital == 0 && w.trolley_volts == 0.0 && w.slew_volts == 0.0; }
bool energized(const BoardMonitor::Write& w) { return w.digital == hb::all_outputs_energized(hb::kTowerCraneAxes); }

/// The hardware-in-the-loop stack plus this process's participant (observer, operator, rogue).
class HilStack {
 public:
  /// `iceoryx`: the stack on Cyclone DDS and iceoryx, RouDi its first process; this process's
  /// participant stays on UDP with the same QoS (RouDi would end it when it stops).
  HilStack(const std::string& name, std::uint32_t domain, const std::string& config = kConfig,
           double initial_trolley = 0.25, const std::map<std::string, std::string>& dds_per_process = {},
           bool iceoryx = false)
      : dir_(fresh_directory(name)), board_name_("fi_" + name + "_" + std::to_string(getpid())), domain_(domain),
        iceoryx_(iceoryx) {
    crane::launch::StackOptions options;
    options.dds_per_process = dds_per_process;
    if (iceoryx) {
      options.dds = "cyclone";
      options.iceoryx = true;
    }
    options.config_path = config;
    options.binary_directory = kBin;
    options.log_directory = dir_.string();
    options.domain_id = domain;
    options.lockstep = false;
    options.hardware = "shm:" + board_name_;
    options.initial_trolley_position = initial_trolley;
    options.plant_stats_path = (dir_ / "bridge_stats.json").string();
    options.fault_log_path = (dir_ / "faults.jsonl").string();
    for (const auto& spec : crane::launch::stack_processes(options)) pids_[spec.name] = group_.start(spec);

    crane::transport::ParticipantOptions p;
    p.name = "fault_injection";
    p.domain_id = domain;
    p.security_directory = security_directory();
    p.identity = "operator";
    if (iceoryx) p.liveliness = crane::transport::Liveliness::watchdogs;
    participant_ = std::make_unique<crane::transport::Participant>(p);
    status_reader_ = participant_->make_recording_reader<tp::SafetyStatus>(&wakeup_, 4096);
    sensors_reader_ = participant_->make_recording_reader<tp::Sensors>(&wakeup_, 4096);
    actuators_reader_ = participant_->make_recording_reader<tp::Actuators>(&wakeup_, 4096);
    goal_writer_ = participant_->make_writer<tp::Goal>();
    command_writer_ = participant_->make_writer<tp::SafetyCommand>();
    monitor_ = std::make_unique<BoardMonitor>(board_name_);
  }
  HilStack(const HilStack&) = delete;
  HilStack& operator=(const HilStack&) = delete;
  ~HilStack() {
    // Readers before writers of the same topic (transport note), then the processes.
    monitor_.reset();
    group_.stop_all();
    // A process killed -9 leaves its iceoryx runtime's socket and lock in /tmp
    // (iceoryx_rt_<pid>_<time>, Cyclone DDS's name for it); one that exits removes its own.
    if (iceoryx_) {
      for (const auto& [name, pid] : pids_) {
        const std::string prefix = "iceoryx_rt_" + std::to_string(pid) + "_";
        std::error_code error;
        for (const auto& entry : fs::directory_iterator("/tmp", error)) {
          if (entry.path().filename().string().rfind(prefix, 0) == 0) fs::remove(entry.path(), error);
        }
      }
    }
  }

  const fs::path& dir() const { return dir_; }
  BoardMonitor& monitor() { return *monitor_; }
  std::uint32_t domain() const { return domain_; }
  pid_t pid(const std::string& name) const { return pids_.at(name); }
  crane::transport::Participant& participant() { return *participant_; }

  /// Deletes this process's readers: before a rogue writer of the same topic is deleted (transport
  /// note: readers before writers of one topic within a process).
  void stop_observing() {
    status_reader_.reset();
    sensors_reader_.reset();
    actuators_reader_.reset();
  }
  /// Takes everything that arrived, stamping actuator commands with their arrival time.
  void pump() {
    if (!status_reader_) return;
    tp::msgs::SupervisorStatus_ s;
    while (status_reader_->take_next(s)) {
      status_ = s;
      status_log_.push_back(s);
    }
    tp::msgs::SensorSample_ sample;
    while (sensors_reader_->take_next(sample)) sensors_.push_back(sample);
    tp::msgs::ActuatorCommand_ a;
    while (actuators_reader_->take_next(a)) command_arrivals_.push_back(hb::monotonic_time_ns());
  }
  /// Pumps for `seconds`, failing the test if a process dies unexpectedly (except `expected_dead`).
  void run_for(double seconds) {
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    while (Clock::now() < until) {
      pump();
      wakeup_.wait_until(std::min(until, Clock::now() + std::chrono::milliseconds(5)));
    }
  }
  /// Waits until the chain is alive, the supervisor ready, the bridge applying commands and this
  /// process's observer receiving them (its own discovery of a writer on the other vendor can lag
  /// the stack's by a second; the figures are timed from the commands it sees).
  ::testing::AssertionResult wait_ready(double timeout = 40.0) {
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
    while (Clock::now() < deadline) {
      if (auto exit = group_.poll()) return ::testing::AssertionFailure() << exit->describe() << "; see " << dir_;
      run_for(0.02);
      const auto w = monitor_->writes();
      if (status_ && status_->stages_alive() == Status::STAGES_ALL &&
          (status_->mode() == Status::MODE_READY || status_->mode() == Status::MODE_OPERATING) &&
          status_->brakes_released() && !w.empty() && energized(w.back()) && !command_arrivals_.empty()) {
        return ::testing::AssertionSuccess();
      }
    }
    return ::testing::AssertionFailure() << "stack not ready within " << timeout << " s (stages alive "
                                         << (status_ ? status_->stages_alive() : 0) << ", mode "
                                         << (status_ ? static_cast<int>(status_->mode()) : -1) << "); see " << dir_;
  }
  /// Sends the trolley move of (3.54) to `target` [m] and waits until the trolley moves faster than
  /// `speed` [m/s] (the supervisor's own velocity).
  ::testing::AssertionResult start_move(double target, double speed = 0.3, double timeout = 10.0) {
    tp::msgs::MoveRequest_ goal;
    crane::runtime::stamp_header(goal.header(), 0, crane::runtime::now_stamp());
    goal.request_id(next_goal_id_++);  // a new goal each call (7 first)
    goal.profile(crane::protocol::MoveRequest::PROFILE_TRAPEZOID);  // (3.43)
    goal.axes(crane::protocol::MoveRequest::AXIS_TROLLEY | crane::protocol::MoveRequest::AXIS_SLEW);
    goal.trolley_target(target);
    goal.slew_target(0.0);
    goal.cable_length_target(1.0);
    goal.trolley_max_velocity(0.4982);
    goal.trolley_max_acceleration(0.9929);
    goal.slew_max_velocity(1.0435);
    goal.slew_max_acceleration(2.0796);
    const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
    while (Clock::now() < deadline) {
      if (!status_ || status_->mode() != Status::MODE_OPERATING) goal_writer_->write(goal);  // until the move is under way
      run_for(0.05);
      if (status_ && std::fabs(status_->trolley_velocity()) > speed) return ::testing::AssertionSuccess();
    }
    return ::testing::AssertionFailure() << "the trolley did not reach " << speed << " m/s; see " << dir_;
  }
  void send_command(std::uint8_t code, std::uint32_t request_id) {
    tp::msgs::SupervisorCommand_ c;
    crane::runtime::stamp_header(c.header(), 0, crane::runtime::now_stamp());
    c.request_id(request_id);
    c.command(code);
    command_writer_->write(c);
  }

  const std::optional<tp::msgs::SupervisorStatus_>& status() const { return status_; }
  const std::vector<tp::msgs::SupervisorStatus_>& status_log() const { return status_log_; }
  const std::vector<tp::msgs::SensorSample_>& sensors() const { return sensors_; }
  /// Arrival time [ns, CLOCK_MONOTONIC] of the last actuator command received before `ns`.
  std::optional<std::int64_t> last_command_before(std::int64_t ns) const {
    std::optional<std::int64_t> last;
    for (const auto t : command_arrivals_) {
      if (t < ns) last = t;
    }
    return last;
  }
  std::string fault_log() const { return read_file(dir_ / "faults.jsonl"); }
  nlohmann::json bridge_stats() {
    group_.stop_all();  // the bridge writes its statistics on exit
    std::ifstream in(dir_ / "bridge_stats.json");
    return in ? nlohmann::json::parse(in, nullptr, false) : nlohmann::json();
  }

 private:
  fs::path dir_;
  std::string board_name_;
  std::uint32_t domain_;
  bool iceoryx_;
  std::uint32_t next_goal_id_{7};
  ProcessGroup group_;
  std::map<std::string, pid_t> pids_;
  std::unique_ptr<crane::transport::Participant> participant_;
  crane::transport::Wakeup wakeup_;
  std::unique_ptr<crane::transport::Reader<tp::SafetyStatus>> status_reader_;
  std::unique_ptr<crane::transport::Reader<tp::Sensors>> sensors_reader_;
  std::unique_ptr<crane::transport::Reader<tp::Actuators>> actuators_reader_;
  std::unique_ptr<crane::transport::Writer<tp::Goal>> goal_writer_;
  std::unique_ptr<crane::transport::Writer<tp::SafetyCommand>> command_writer_;
  std::unique_ptr<BoardMonitor> monitor_;
  std::optional<tp::msgs::SupervisorStatus_> status_;
  std::vector<tp::msgs::SupervisorStatus_> status_log_;
  std::vector<tp::msgs::SensorSample_> sensors_;
  std::vector<std::int64_t> command_arrivals_;
};

/// The first safe write at or after `ns`, and the last energized write before it.
struct FailSafe {
  std::optional<BoardMonitor::Write> last_energized;
  std::optional<BoardMonitor::Write> first_safe;
};
FailSafe fail_safe_after(const std::vector<BoardMonitor::Write>& writes, std::int64_t ns) {
  FailSafe f;
  for (const auto& w : writes) {
    if (w.ns < ns) {
      if (energized(w)) f.last_energized = w;
      continue;
    }
    if (safe(w)) {
      f.first_safe = w;
      break;
    }
    if (energized(w)) f.last_energized = w;
  }
  return f;
}

/// The bridge's log line for its watchdog trip: the age [ms] of the command it tripped on, at the
/// step, and how late [ms] that step ran after its scheduled cycle instant.
/// The bridge's first safe-state transition after the last cycle it applied commands in, as it
/// logs it: the reason (the gate's name), the age of the last valid command and the cycle's
/// lateness [ms]. The fault's transition is usually the watchdog; a status that came stale or
/// disabling first makes the outputs safe earlier under another reason.
struct SafeTransition {
  std::string reason;
  double age_ms;
  double late_ms;
};
std::optional<SafeTransition> fault_transition(const fs::path& bridge_log) {
  std::ifstream in(bridge_log);
  const std::regex safe(R"(outputs safe \(([a-z_]+)\): last valid command ([0-9.eE+-]+) ms old, this cycle ([0-9.eE+-]+) ms late)");
  std::optional<SafeTransition> first;
  std::string text;
  std::smatch m;
  while (std::getline(in, text)) {
    if (text.find("commands applied, brakes released") != std::string::npos) {
      first.reset();
    } else if (!first && std::regex_search(text, m, safe)) {
      first = SafeTransition{m[1], std::stod(m[2]), std::stod(m[3])};
    }
  }
  return first;
}

/// Trolley travel [m] from the sample nearest `ns` to the last sample.
double travel_after(const std::vector<tp::msgs::SensorSample_>& sensors, std::int64_t wall_ns_at_fault) {
  std::optional<double> at_fault;
  for (const auto& s : sensors) {
    if (crane::runtime::to_nanoseconds(s.header().origin()) >= wall_ns_at_fault) {
      at_fault = s.trolley_position();
      break;
    }
  }
  if (!at_fault || sensors.empty()) return std::nan("");
  return sensors.back().trolley_position() - *at_fault;
}

// ---- kill -9 of each stage of the chain in mid-move ----

// kill -9 of `stage` in mid-move; `dds_per_process` puts some processes on another vendor; `iceoryx`
// the whole stack on Cyclone DDS and iceoryx shared memory.
void kill_stage_in_mid_move(const std::string& stage, std::uint32_t domain,
                            const std::map<std::string, std::string>& dds_per_process, bool iceoryx = false) {
  std::string vendors;
  for (const auto& [name, vendor] : dds_per_process) vendors += " " + name + "=" + vendor;
  if (iceoryx) vendors = " iceoryx";
  if (!dds_per_process.empty() && !security_directory().empty()) {
    GTEST_SKIP() << "mixed vendors do not handshake secured with the Debian packages (docs/deployment.md, \"Security\")";
  }
  if (iceoryx && !security_directory().empty()) {
    GTEST_SKIP() << "iceoryx carries no DDS Security: a secured participant refuses it (transport/participant.hpp)";
  }
  HilStack stack("kill_" + stage + (dds_per_process.empty() ? "" : "_mixed") + (iceoryx ? "_iceoryx" : ""), domain,
                 kConfig, 0.25, dds_per_process, iceoryx);
  ASSERT_TRUE(stack.wait_ready());
  ASSERT_TRUE(stack.start_move(1.0));

  const std::int64_t kill_ns = hb::monotonic_time_ns();
  const std::int64_t kill_wall_ns = crane::runtime::now_nanoseconds();
  ASSERT_EQ(::kill(stack.pid(stage), SIGKILL), 0);
  stack.run_for(2.0);

  const auto f = fail_safe_after(stack.monitor().writes(), kill_ns);
  ASSERT_TRUE(f.first_safe.has_value()) << "the outputs never became safe; see " << stack.dir();
  const auto last_command = stack.last_command_before(f.first_safe->ns);
  ASSERT_TRUE(last_command.has_value());
  const double after_command_ms = static_cast<double>(f.first_safe->ns - *last_command) / 1e6;
  const double after_kill_ms = static_cast<double>(f.first_safe->ns - kill_ns) / 1e6;
  const double travel_mm = travel_after(stack.sensors(), kill_wall_ns) * 1e3;
  const auto trip = fault_transition(stack.dir() / "hardware_bridge.log");
  ASSERT_TRUE(trip.has_value()) << "the bridge logged no safe-state transition after its last commands; see "
                                << stack.dir();
  std::printf("[ figure   ] kill -9 %s in mid-move%s%s: brakes engaged and 0 V %.1f ms after the last good command "
              "(%.1f ms after the kill); the bridge went safe (%s) on a command %.2f ms old in a cycle %.2f ms "
              "late; trolley travel after the fault %.1f mm\n",
              stage.c_str(), vendors.empty() ? "" : ", on", vendors.c_str(), after_command_ms, after_kill_ms,
              trip->reason.c_str(), trip->age_ms, trip->late_ms, travel_mm);
  // The gate's rule (actuation_gate.hpp, rule H) on the bridge's own clock: it trips on a command
  // older than watchdog_timeout - T when it steps (it held the command for every cycle it could),
  // and at the cycle's scheduled instant that command was at most watchdog_timeout old. The wall-clock figure above adds the
  // OS's wake-up lateness of that cycle and this process's reception skew; it is printed, not bounded.
  const double timeout_ms = gate_params().watchdog_timeout * 1e3;
  const double period_ms = gate_params().sample_period * 1e3;
  // Whatever the reason, the drives never rest on a command older than the watchdog timeout.
  EXPECT_LE(trip->age_ms - trip->late_ms, timeout_ms + 1e-6) << "the outputs must be safe within 3 cycles (" << trip->reason << ")";
  if (trip->reason == "watchdog") {
    EXPECT_GT(trip->age_ms, timeout_ms - period_ms) << "the watchdog tripped on a command it could still hold";
  }
  EXPECT_GE(after_command_ms, 0.0);
  // Nothing energized after the safe write: the outputs stay safe.
  for (const auto& w : stack.monitor().writes()) {
    if (w.ns > f.first_safe->ns) {
      EXPECT_FALSE(energized(w)) << "outputs re-energized after the fault";
    }
  }
  // The supervisor saw it too: the stage silent, on the status topic and in the fault log.
  ASSERT_TRUE(stack.status().has_value());
  EXPECT_TRUE(stack.status()->latched_faults() & Status::FAULT_STAGE_SILENT);
  EXPECT_EQ(stack.status()->mode(), Status::MODE_FAULT);
  const auto log = stack.fault_log();
  EXPECT_NE(log.find("\"fault\": \"stage_silent\""), std::string::npos) << log;
  EXPECT_NE(log.find("\"" + stage + "\""), std::string::npos) << "the fault log must name the silent stage: " << log;
}

class KillStage : public ::testing::TestWithParam<const char*> {};

TEST_P(KillStage, BrakesAndZeroVoltsWithinTheWatchdogTimeout) {
  static std::uint32_t domain = 40;
  kill_stage_in_mid_move(GetParam(), domain++, {});
}

// The same with the killed stage on Cyclone DDS and the supervisor, the bridge and the plant on
// Fast DDS: liveliness, deadlines and the bridge's watchdog work across the two vendors.
class KillCycloneStage : public ::testing::TestWithParam<const char*> {};

TEST_P(KillCycloneStage, BrakesAndZeroVoltsWithinTheWatchdogTimeout) {
  static std::uint32_t domain = 70;
  kill_stage_in_mid_move(GetParam(), domain++, {{GetParam(), "cyclone"}});
}

// The same with the stack on iceoryx shared memory (docs/architecture.md, "Shared memory"): no DDS
// liveliness or deadline on the chain there; the supervisor's receive-time watchdog and the bridge's
// command-age watchdog must give the same bound by themselves.
class KillStageOnIceoryx : public ::testing::TestWithParam<const char*> {};

TEST_P(KillStageOnIceoryx, BrakesAndZeroVoltsWithinTheWatchdogTimeout) {
  static std::uint32_t domain = 100;
  kill_stage_in_mid_move(GetParam(), domain++, {}, true);
}

INSTANTIATE_TEST_SUITE_P(Chain, KillStage,
                         ::testing::Values("state_estimator", "trajectory_planner", "anti_swing", "tracking",
                                           "friction_compensation"));
INSTANTIATE_TEST_SUITE_P(MixedVendors, KillCycloneStage,
                         ::testing::Values("state_estimator", "trajectory_planner", "anti_swing", "tracking",
                                           "friction_compensation"));
INSTANTIATE_TEST_SUITE_P(Iceoryx, KillStageOnIceoryx,
                         ::testing::Values("state_estimator", "trajectory_planner", "anti_swing", "tracking",
                                           "friction_compensation"));

TEST(FaultInjection, SupervisorKilledTheBridgeFailsSafeByItself) {
  HilStack stack("kill_supervisor", 50);
  ASSERT_TRUE(stack.wait_ready());
  ASSERT_TRUE(stack.start_move(1.0));
  const std::int64_t kill_ns = hb::monotonic_time_ns();
  const std::int64_t kill_wall_ns = crane::runtime::now_nanoseconds();
  ASSERT_EQ(::kill(stack.pid("supervisor"), SIGKILL), 0);
  stack.run_for(2.0);
  const auto f = fail_safe_after(stack.monitor().writes(), kill_ns);
  ASSERT_TRUE(f.first_safe.has_value()) << "the outputs never became safe; see " << stack.dir();
  // The last status the bridge could rest on arrived before the kill.
  const double after_kill_ms = static_cast<double>(f.first_safe->ns - kill_ns) / 1e6;
  std::printf("[ figure   ] kill -9 supervisor in mid-move: outputs safe %.1f ms after the kill (status timeout "
              "%.0f ms + up to one cycle), trolley travel after the fault %.1f mm\n",
              after_kill_ms, gate_params().status_timeout * 1e3, travel_after(stack.sensors(), kill_wall_ns) * 1e3);
  EXPECT_LE(after_kill_ms, (gate_params().status_timeout + gate_params().sample_period) * 1e3);
  // The chain is still alive and keeps commanding: only the bridge's own rule holds the brakes.
  stack.run_for(0.3);
  const auto w = stack.monitor().writes();
  ASSERT_FALSE(w.empty());
  EXPECT_TRUE(safe(w.back()));
  EXPECT_TRUE(stack.last_command_before(hb::monotonic_time_ns()).value_or(0) > f.first_safe->ns)
      << "the chain stopped commanding: this test would not show the bridge acting alone";
}

TEST(FaultInjection, BridgeStartsSafeAndLeavesSafeOnSigterm) {
  HilStack stack("bridge_sigterm", 55);
  ASSERT_TRUE(stack.wait_ready());
  auto writes = stack.monitor().writes();
  ASSERT_FALSE(writes.empty());
  EXPECT_TRUE(safe(writes.front())) << "the bridge's first write must be the safe state";
  ASSERT_TRUE(stack.start_move(1.0));
  const std::int64_t term_ns = hb::monotonic_time_ns();
  ASSERT_EQ(::kill(stack.pid("hardware_bridge"), SIGTERM), 0);
  stack.run_for(1.0);
  writes = stack.monitor().writes();
  ASSERT_FALSE(writes.empty());
  EXPECT_GT(writes.back().ns, term_ns) << "the bridge wrote nothing after SIGTERM";
  EXPECT_TRUE(safe(writes.back())) << "the bridge exited with its outputs energized";
  const auto f = fail_safe_after(writes, term_ns);
  ASSERT_TRUE(f.first_safe.has_value());
  const double term_ms = static_cast<double>(f.first_safe->ns - term_ns) / 1e6;
  std::printf("[ figure   ] SIGTERM to the bridge in mid-move: outputs safe %.1f ms later\n", term_ms);
  EXPECT_LE(term_ms, 30.0) << "the bridge must make its outputs safe before its DDS teardown";
}

// ---- bad commands: NaN, Inf, out of range ----

TEST(FaultInjection, NonFiniteAndOutOfRangeCommandsAreRejectedAndCounted) {
  HilStack stack("bad_commands", 51);
  ASSERT_TRUE(stack.wait_ready());
  if (!security_directory().empty()) {
    // Secured, the operator may not write actuator commands at all: the writer is refused.
    EXPECT_THROW((void)stack.participant().make_writer<tp::Actuators>(), std::runtime_error);
    GTEST_SKIP() << "secured: a rogue actuator writer cannot be created (checked above)";
  }
  auto rogue = stack.participant().make_writer<tp::Actuators>();
  stack.run_for(0.5);  // discovery of the rogue writer
  const std::int64_t start_ns = hb::monotonic_time_ns();
  // Half non-finite (NaN or Inf on either drive), half out of range (50 V or -37 V).
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 100; ++i) {
    stack.pump();
    tp::msgs::ActuatorCommand_ a;
    const auto& s = stack.sensors();
    a.header().seq(s.empty() ? 0 : s.back().header().seq());  // the current cycle, as far as we know
    if (i % 2 == 0) {
      (i % 4 == 0 ? a.trolley_voltage(nan) : a.slew_voltage(inf));
    } else {
      (i % 4 == 1 ? a.trolley_voltage(50.0) : a.slew_voltage(-37.0));
    }
    rogue->write(a);
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  stack.run_for(0.3);
  for (const auto& w : stack.monitor().writes()) {
    if (w.ns < start_ns) continue;
    ASSERT_TRUE(std::isfinite(w.trolley_volts) && std::isfinite(w.slew_volts));
    EXPECT_LT(std::fabs(w.trolley_volts), 9.0) << "a rogue voltage reached the board";
    EXPECT_LT(std::fabs(w.slew_volts), 9.0) << "a rogue voltage reached the board";
  }
  const auto writes = stack.monitor().writes();
  ASSERT_FALSE(writes.empty());
  EXPECT_TRUE(safe(writes.back())) << "a second actuator writer must stop motion";
  ASSERT_TRUE(stack.status().has_value());
  EXPECT_TRUE(stack.status()->latched_faults() & Status::FAULT_MULTIPLE_ACTUATOR_WRITERS);
  const auto log = stack.fault_log();
  EXPECT_NE(log.find("multiple_actuator_writers"), std::string::npos) << log;
  const auto stats = stack.bridge_stats();
  ASSERT_FALSE(stats.is_null()) << "no bridge statistics in " << stack.dir();
  std::printf("[ figure   ] 50 non-finite and 50 out-of-range rogue commands written: the bridge rejected %d "
              "non-finite and %d out of range (the rest overwritten on the keep-last-1 stream); supervisor fault "
              "multiple_actuator_writers\n",
              stats["rejected_non_finite"].get<int>(), stats["rejected_out_of_range"].get<int>());
  // 50 of each were written on a keep-last-1 best-effort stream shared with the real commands, so
  // some are overwritten before the bridge takes them; every one it takes is checked, whatever
  // cycle it claims.
  EXPECT_GT(stats["rejected_non_finite"].get<int>(), 0);
  EXPECT_GT(stats["rejected_out_of_range"].get<int>(), 0);
  EXPECT_LE(stats["rejected_non_finite"].get<int>(), 50);
  EXPECT_LE(stats["rejected_out_of_range"].get<int>(), 50);
  stack.stop_observing();
}

// ---- a move toward a travel limit ----

TEST(FaultInjection, MoveTowardATravelLimitStopsBeforeIt) {
  // The supervisor's hard limit at 0.9 m, the move to 1.0 m (the planner's own range allows it).
  const fs::path dir = fresh_directory("limit_config");
  std::string text = read_file(kConfig);
  const std::string from = "trolley_max: 1.30";
  ASSERT_NE(text.find(from), std::string::npos);
  text.replace(text.find(from), from.size(), "trolley_max: 0.90");
  const fs::path config = dir / "limit.yaml";
  std::ofstream(config) << text;

  HilStack stack("travel_limit", 52, config.string());
  ASSERT_TRUE(stack.wait_ready());
  ASSERT_TRUE(stack.start_move(1.0));
  // Until the trolley rests past 0.8 m (the approach zone), or 12 s: 4 s suffice on a quiet
  // machine, but each watchdog brake of a stalled chain pauses the goal until the load settles
  // (3 of 4 runs on 2026-11-26 had not reached the zone after 4 s, with 6-8 such brakes).
  for (int i = 0; i < 120; ++i) {
    stack.run_for(0.1);
    if (i >= 40 && stack.status() && std::fabs(stack.status()->trolley_velocity()) < 0.01 &&
        !stack.sensors().empty() && stack.sensors().back().trolley_position() > 0.8) {
      break;
    }
  }
  double furthest = 0.0;
  for (const auto& s : stack.sensors()) furthest = std::max(furthest, s.trolley_position());
  bool limited = false;
  for (const auto& s : stack.status_log()) limited = limited || (s.warnings() & Status::WARNING_SPEED_LIMITED);
  const auto& last = *stack.status();
  std::printf("[ figure   ] move to 1.0 m with the travel limit at 0.90 m: the trolley stopped at %.4f m, %.1f mm "
              "before the limit (speed limited in the approach zone: %s; latched faults 0x%x)\n",
              stack.sensors().back().trolley_position(), (0.90 - furthest) * 1e3, limited ? "yes" : "no",
              last.latched_faults());
  EXPECT_LT(furthest, 0.90) << "the trolley reached the hard limit";
  EXPECT_TRUE(limited) << "the approach margin should have slowed the trolley";
  EXPECT_LT(std::fabs(last.trolley_velocity()), 0.01) << "the trolley must have stopped";
}

// ---- a second sensor writer ----

TEST(FaultInjection, SecondSensorWriterRefusesMotion) {
  HilStack stack("second_sensor_writer", 53);
  ASSERT_TRUE(stack.wait_ready());
  if (!security_directory().empty()) {
    // Secured, the operator may not write sensor samples at all: the writer is refused.
    EXPECT_THROW((void)stack.participant().make_writer<tp::Sensors>(), std::runtime_error);
    GTEST_SKIP() << "secured: a second sensor writer cannot be created (checked above)";
  }
  auto rogue = stack.participant().make_writer<tp::Sensors>();
  for (int i = 0; i < 50; ++i) {
    stack.pump();
    tp::msgs::SensorSample_ s;
    if (!stack.sensors().empty()) s = stack.sensors().back();
    s.writer_pid(static_cast<std::uint32_t>(getpid()));
    rogue->write(s);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  stack.run_for(0.3);
  ASSERT_TRUE(stack.status().has_value());
  EXPECT_TRUE(stack.status()->latched_faults() & Status::FAULT_MULTIPLE_SENSOR_WRITERS);
  EXPECT_FALSE(stack.status()->motion_enabled());
  const auto writes = stack.monitor().writes();
  ASSERT_FALSE(writes.empty());
  EXPECT_TRUE(safe(writes.back()));
  // A move is refused while the fault is latched.
  EXPECT_FALSE(stack.start_move(1.0, 0.05, 3.0)) << "the trolley moved with two sensor writers";
  EXPECT_NE(stack.fault_log().find("multiple_sensor_writers"), std::string::npos);
  std::printf("[ figure   ] second writer on rt/crane/hw/sensors: supervisor mode %s, motion refused\n",
              std::string(crane::protocol::code_name(Status::kCodes, "MODE", stack.status()->mode())).c_str());
  stack.stop_observing();
}

// ---- emergency stop: by command and by the board's input ----

TEST(FaultInjection, EmergencyStopInputAndCommandBrakeAtOnce) {
  HilStack stack("estop", 54);
  ASSERT_TRUE(stack.wait_ready());
  const std::string safety = kBin + "/crane_safety";
  // A fresh participant: secured, its handshakes with every stage take seconds on a loaded machine.
  const std::string domain = " --domain " + std::to_string(stack.domain()) + " --timeout 15";
  auto run = [](const std::string& command) { return WEXITSTATUS(std::system((command + " > /dev/null").c_str())); };

  // The board's emergency-stop input (crane ready, brakes released): the bridge engages the brakes
  // itself at its next cycle.
  const std::int64_t pressed_ns = hb::monotonic_time_ns();
  stack.monitor().set_emergency_stop(true);
  stack.run_for(0.5);
  auto f = fail_safe_after(stack.monitor().writes(), pressed_ns);
  ASSERT_TRUE(f.first_safe.has_value());
  const double input_ms = static_cast<double>(f.first_safe->ns - pressed_ns) / 1e6;
  ASSERT_TRUE(stack.status().has_value());
  EXPECT_EQ(stack.status()->mode(), Status::MODE_EMERGENCY_STOP);
  // The operator's CLI: reset refused while the button is pressed (exit code 3), accepted once released.
  EXPECT_EQ(run(safety + " status" + domain), 0);
  EXPECT_EQ(run(safety + " reset" + domain), 3);
  stack.monitor().set_emergency_stop(false);
  stack.run_for(0.1);
  EXPECT_EQ(run(safety + " reset" + domain), 0);
  ASSERT_TRUE(stack.wait_ready(10.0));

  // The operator's emergency stop in mid-move: supervisor, then the bridge.
  ASSERT_TRUE(stack.start_move(1.0));
  const std::int64_t command_ns = hb::monotonic_time_ns();
  stack.send_command(crane::protocol::SupervisorCommand::COMMAND_EMERGENCY_STOP, 101);
  stack.run_for(0.5);
  f = fail_safe_after(stack.monitor().writes(), command_ns);
  ASSERT_TRUE(f.first_safe.has_value());
  const double command_ms = static_cast<double>(f.first_safe->ns - command_ns) / 1e6;
  EXPECT_EQ(stack.status()->mode(), Status::MODE_EMERGENCY_STOP);
  EXPECT_EQ(stack.status()->last_request_id(), 101U);
  std::printf("[ figure   ] emergency stop: brakes engaged %.1f ms after the board's input was pressed, %.1f ms "
              "after the operator's command\n",
              input_ms, command_ms);
  EXPECT_LE(input_ms, 20.0) << "the bridge reads the input every cycle";
  EXPECT_LE(command_ms, 30.0) << "supervisor cycle + bridge cycle";
  const auto log = stack.fault_log();
  EXPECT_NE(log.find("\"fault\": \"emergency_stop\""), std::string::npos) << log;
  EXPECT_NE(log.find("\"command\": \"reset\""), std::string::npos) << log;
}

// An operator's stop typed at `ns`: whether the outputs were energized then (the crane was
// driving: an energized write within the 3 cycles before), and the first safe write after which
// none is energized again (-1: none). A late status or command makes the bridge's gate hold a single
// cycle safe on a loaded machine; that is neither a crane at rest nor the stop.
struct StopSeen {
  bool driving{false};
  std::int64_t held_ns{-1};
};
StopSeen stopped_for_good(const std::vector<BoardMonitor::Write>& writes, std::int64_t ns) {
  constexpr std::int64_t kDrivingWindow = 30'000'000;  // [ns] 3 cycles
  StopSeen seen;
  for (const auto& w : writes) {
    if (w.ns < ns) {
      if (w.ns >= ns - kDrivingWindow && energized(w)) seen.driving = true;
      continue;
    }
    if (energized(w)) seen.held_ns = -1;
    else if (seen.held_ns < 0) seen.held_ns = w.ns;
  }
  return seen;
}

// Whether the crane drives now, as stopped_for_good counts it: the board had energized outputs
// within the last 3 cycles. A stall of the command chain on a loaded machine makes the bridge hold
// its outputs safe and brake the drives under way (WARNING_DRIVES_BRAKED): seen in a local CI run,
// 2026-11-30, safe writes from 36 ms before an estop was typed to the command. A stop typed then
// finds no crane driving.
bool driving_now(HilStack& stack) {
  return stopped_for_good(stack.monitor().writes(), hb::monotonic_time_ns()).driving;
}

// What the board and the supervisor showed in the second before `ns` (a failure's diagnostic): each
// safe write, and each status whose mode, warnings or faults differ from the one before.
std::string recent_history(HilStack& stack, std::int64_t ns) {
  std::ostringstream out;
  const std::int64_t from = ns - 1'000'000'000;
  std::size_t energized_writes = 0;
  for (const auto& w : stack.monitor().writes()) {
    if (w.ns < from || w.ns >= ns) continue;
    if (energized(w)) ++energized_writes;
    else out << "  safe write at " << static_cast<double>(w.ns - ns) / 1e6 << " ms\n";
  }
  out << "  " << energized_writes << " energized writes in the second before\n";
  // The samples around each step of more than 8 mm (0.8 m/s over 10 ms).
  const auto& samples = stack.sensors();
  for (std::size_t i = 1; i < samples.size(); ++i) {
    if (std::fabs(samples[i].trolley_position() - samples[i - 1].trolley_position()) <= 0.008) continue;
    for (std::size_t j = i >= 3 ? i - 3 : 0; j < std::min(samples.size(), i + 3); ++j) {
      const auto& m = samples[j];
      out << "    sample seq " << m.header().seq() << " stamp " << m.header().stamp().sec() << "."
          << m.header().stamp().nanosec() << ": trolley " << m.trolley_position() << " m, applied "
          << m.applied_trolley_voltage() << " V, brakes " << m.brakes_engaged() << "\n";
    }
    out << "    --\n";
  }
  std::optional<tp::msgs::SupervisorStatus_> last;
  for (const auto& s : stack.status_log()) {
    if (last && s.mode() == last->mode() && s.warnings() == last->warnings() &&
        s.active_faults() == last->active_faults() && s.stages_alive() == last->stages_alive()) {
      continue;
    }
    out << "  status seq " << s.header().seq() << ": mode " << static_cast<int>(s.mode()) << ", warnings 0x" << std::hex
        << s.warnings() << ", active faults 0x" << s.active_faults() << ", stages alive 0x" << s.stages_alive() << std::dec
        << ", trolley " << s.trolley_velocity() << " m/s\n";
    last = s;
  }
  return out.str();
}

// The operator's own path, as typed in a shell: `deploy/crane estop` in mid-move. The script never
// installs or builds; it runs crane_operator, which hands the command to the stack's operator relay
// over a local socket (a participant matched with the supervisor since the stack started), and, with
// --direct, crane_safety, a participant of its own that must discover the supervisor first. Five
// stops each way, alternating; the figure is from the command's start to the bridge's safe outputs
// on the board (issue 14 asks under 100 ms; a timing target is a figure here, not an assertion).
// Asserted: every stop engages the brakes at once (not after a package check and a build:
// seconds), the supervisor answers it, and the relay served exactly the relayed ones (its log).
// The script finds this build through CRANE_BUILD_DIR.
TEST(FaultInjection, EmergencyStopFromTheOperatorsShellBrakesAtOnce) {
  HilStack stack("estop_shell", 55);
  ASSERT_TRUE(stack.wait_ready());
  const std::string domain = " --domain " + std::to_string(stack.domain());
  const std::string script = "CRANE_BUILD_DIR='" + kBin + "/..' '" + std::string(CRANE_SOURCE_DIR) + "/deploy/crane'";
  std::vector<double> relayed, direct;
  constexpr int kStops = 5;
  int protective_stops = 0;  // moves the supervisor stopped itself before the command was typed
  int paused_moves = 0;      // moves braked when the command would be typed (driving_now)
  // After a protective stop, `deploy/crane reset`: the supervisor refuses it (exit 3) while a fault
  // is still active, as an overspeed is while the braked trolley slows down (seen in a local CI run,
  // 2026-11-27: a reset typed as the fault latched was refused). Asked again each 0.5 s, 5 s at most;
  // any other exit code fails.
  const auto reset_when_the_faults_cleared = [&]() {
    for (int ask = 0; ask < 10; ++ask) {
      stack.run_for(0.5);
      const int rc = WEXITSTATUS(std::system((script + " reset" + domain + " > /dev/null").c_str()));
      if (rc == 0) return true;
      if (rc != 3) {
        ADD_FAILURE() << "deploy/crane reset exited " << rc;
        return false;
      }
      std::printf("[ note     ] deploy/crane reset refused (a fault still active); asked again\n");
    }
    return false;
  };
  for (int i = 0; i < 2 * kStops; ++i) {
    const bool via_relay = i % 2 == 0;
    // To 0.3 or 1.0 m, whichever is farther from where the last stop left the trolley: 10 cm inside
    // the planner's travel [0.2, 1.1] m. The stops leave the load swinging, and the anti-swing law's
    // action on top of the move can take the trolley past the supervisor's trolley_max_speed (a
    // protective stop, fault trolley_overspeed): that move is not driving when the command would be
    // typed; it is reset and moved again (at most 3 times a stop), and the count is printed. A
    // --direct stop can come seconds late, after its move has ended: the swinging load then carries
    // the trolley up to 12 cm past the goal (0.2 m once, 2026-11-25, in CI: to 0.0797 m, inside the
    // supervisor's stop margin, trolley_travel latched, and every reset re-raised it while the load
    // swung toward the limit). Hence the 10 cm, and a crane found faulted before its move is reset
    // and counted the same way.
    for (int attempt = 0;; ++attempt) {
      stack.run_for(0.2);  // a fault re-raised just after the reset is seen here
      const double at = stack.sensors().empty() ? 0.25 : stack.sensors().back().trolley_position();
      if (stack.status() && stack.status()->mode() == Status::MODE_FAULT) {
        ASSERT_LT(attempt, 3) << "the supervisor kept the crane faulted before stop " << i << "\n"
                              << recent_history(stack, hb::monotonic_time_ns());
        ++protective_stops;
        std::printf("[ note     ] stop %d: the crane was faulted before its move (faults 0x%x latched); reset\n", i,
                    stack.status()->latched_faults());
        ASSERT_TRUE(reset_when_the_faults_cleared()) << "before stop " << i << "\n"
                                                     << recent_history(stack, hb::monotonic_time_ns());
        ASSERT_TRUE(stack.wait_ready(10.0)) << "after the protective stop before stop " << i;
        continue;
      }
      ASSERT_TRUE(stack.start_move(at < 0.65 ? 1.0 : 0.3)) << "stop " << i << " from " << at << " m";
      stack.run_for(0.5);
      ASSERT_TRUE(stack.status().has_value());
      if (stack.status()->mode() != Status::MODE_FAULT && driving_now(stack)) break;
      if (stack.status()->mode() != Status::MODE_FAULT) {
        // Braked under way: moved again (at most 3 times a stop), counted.
        ASSERT_LT(attempt, 3) << "no move was driving before stop " << i << "\n"
                              << recent_history(stack, hb::monotonic_time_ns());
        ++paused_moves;
        std::printf("[ note     ] stop %d: no energized output in the last 3 cycles (mode %d, warnings 0x%x); move again\n", i,
                    static_cast<int>(stack.status()->mode()), stack.status()->warnings());
        continue;
      }
      ASSERT_LT(attempt, 3) << "the supervisor stopped every move before stop " << i << "\n"
                            << recent_history(stack, hb::monotonic_time_ns());
      ++protective_stops;
      std::printf("[ note     ] stop %d: the supervisor stopped the move itself (faults 0x%x latched); reset, move again\n",
                  i, stack.status()->latched_faults());
      ASSERT_TRUE(reset_when_the_faults_cleared()) << "before stop " << i << "\n"
                                                   << recent_history(stack, hb::monotonic_time_ns());
      ASSERT_TRUE(stack.wait_ready(10.0)) << "after the protective stop before stop " << i;
    }
    // --direct: a fresh participant; secured, its handshakes take seconds on a loaded machine before
    // it sees the supervisor's answer (the brakes engage sooner: the figure).
    const std::string command = script + " estop" + domain + (via_relay ? "" : " --direct --timeout 15") + " > /dev/null";
    const std::int64_t typed_ns = hb::monotonic_time_ns();
    const int rc = WEXITSTATUS(std::system(command.c_str()));
    const std::int64_t returned_ns = hb::monotonic_time_ns();
    stack.run_for(0.3);
    const auto stop = stopped_for_good(stack.monitor().writes(), typed_ns);
    ASSERT_TRUE(stop.driving) << "the crane was not driving when " << command << " was typed (stop " << i << ")\n"
                              << recent_history(stack, typed_ns);
    ASSERT_GE(stop.held_ns, 0) << "the outputs were not safe for good after " << command;
    const double ms = static_cast<double>(stop.held_ns - typed_ns) / 1e6;
    std::printf("[ figure   ] deploy/crane estop%s: brakes engaged %.1f ms after the command started (it returned after "
                "%.1f ms, having seen the supervisor answer)\n",
                via_relay ? " (operator relay)" : " --direct (a participant of its own)", ms,
                static_cast<double>(returned_ns - typed_ns) / 1e6);
    (via_relay ? relayed : direct).push_back(ms);
    EXPECT_EQ(rc, 0) << command;
    ASSERT_TRUE(stack.status().has_value());
    EXPECT_EQ(stack.status()->mode(), Status::MODE_EMERGENCY_STOP);
    // At once: the script checks no package and builds nothing. The relay path is that bound's
    // check; the direct path runs the same script, and its time is the fresh participant's secured
    // handshakes, which take seconds on a loaded machine (3162 ms once, 2026-11-24, in a CI
    // rehearsal): a figure (printed), and its bound the command's own --timeout (rc 0 above: it saw
    // the supervisor's answer within it).
    if (via_relay) {
      EXPECT_LT(ms, 3000.0) << "at once: no package check, no build";
    }
    ASSERT_EQ(WEXITSTATUS(std::system((script + " reset" + domain + " > /dev/null").c_str())), 0);
    ASSERT_TRUE(stack.wait_ready(10.0)) << "after stop " << i;
  }
  const auto summary = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    char text[96];
    std::snprintf(text, sizeof text, "min %.1f, median %.1f, max %.1f ms", v.front(), v[v.size() / 2], v.back());
    return std::string(text);
  };
  std::printf("[ figure   ] deploy/crane estop to brakes engaged, %d stops each: operator relay %s; a participant of its "
              "own (--direct) %s; moves stopped by the supervisor before the command: %d; moves braked by a stall before it: %d\n",
              kStops, summary(relayed).c_str(), summary(direct).c_str(), protective_stops, paused_moves);
  const auto relay_log = read_file(stack.dir() / "operator_relay.log");
  std::size_t served = 0;
  for (auto at = relay_log.find("operator command 'estop'"); at != std::string::npos;
       at = relay_log.find("operator command 'estop'", at + 1)) {
    ++served;
  }
  EXPECT_EQ(served, static_cast<std::size_t>(kStops)) << relay_log;
}

// The operator relay's socket against hostile local clients: connections that never send, a
// request without its newline beyond the size limit, a malformed one; an emergency stop typed
// meanwhile is served at once, and the malformed requests are answered with exit code 2.
TEST(FaultInjection, TheOperatorRelayServesAnEstopBesideHostileClients) {
  HilStack stack("relay_hostile", 56);
  ASSERT_TRUE(stack.wait_ready());
  namespace sock = crane::supervisor::operator_socket;
  const auto connect_relay = [&]() {
    const int fd = socket(AF_UNIX, SOCK_STREAM, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    const auto name = sock::name(stack.domain());
    std::memcpy(address.sun_path, name.data(), name.size());
    const auto size = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + name.size());
    EXPECT_EQ(connect(fd, reinterpret_cast<sockaddr*>(&address), size), 0) << std::strerror(errno);
    return fd;
  };
  // Everything the relay sent until it closed the connection; "(no end)" when it had not closed
  // it within 10 s.
  const auto reply_of = [](int fd) {
    std::string reply;
    char buffer[512];
    timeval limit{10, 0};
    setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof limit);
    ssize_t n = 0;
    while ((n = read(fd, buffer, sizeof buffer)) > 0) reply.append(buffer, static_cast<std::size_t>(n));
    close(fd);
    return n == 0 ? reply : reply + "(no end)";
  };
  std::vector<int> silent;
  for (int i = 0; i < 4; ++i) silent.push_back(connect_relay());
  const int oversize = connect_relay();
  const std::string flood(sock::kMaxRequestBytes + 100, 'x');
  EXPECT_EQ(write(oversize, flood.data(), flood.size()), static_cast<ssize_t>(flood.size()));
  const int malformed = connect_relay();
  EXPECT_EQ(write(malformed, "estop\n", 6), 6);  // its argument lacks the NUL

  // Driving when the estop is typed (driving_now: a move braked by a stall is moved again).
  for (int attempt = 0; attempt < 3; ++attempt) {
    ASSERT_TRUE(stack.start_move(attempt % 2 == 0 ? 1.0 : 0.3));
    stack.run_for(0.5);
    if (driving_now(stack)) break;
    std::printf("[ note     ] no energized output in the last 3 cycles; move again\n");
  }
  const std::string script = "CRANE_BUILD_DIR='" + kBin + "/..' '" + std::string(CRANE_SOURCE_DIR) + "/deploy/crane' estop --domain " +
                             std::to_string(stack.domain()) + " > /dev/null";
  const std::int64_t typed_ns = hb::monotonic_time_ns();
  EXPECT_EQ(WEXITSTATUS(std::system(script.c_str())), 0);
  stack.run_for(0.3);
  const auto stop = stopped_for_good(stack.monitor().writes(), typed_ns);
  ASSERT_TRUE(stop.driving) << "the crane was not driving when the estop was typed";
  ASSERT_GE(stop.held_ns, 0) << "the outputs were not safe for good after the estop";
  const double ms = static_cast<double>(stop.held_ns - typed_ns) / 1e6;
  const auto oversize_reply = reply_of(oversize);
  const auto malformed_reply = reply_of(malformed);
  std::printf("[ figure   ] estop beside 4 silent connections and 2 bad requests: brakes engaged %.1f ms after the "
              "command started; replies: '%s', '%s'\n",
              ms, oversize_reply.c_str(), malformed_reply.c_str());
  EXPECT_EQ(stack.status()->mode(), Status::MODE_EMERGENCY_STOP);
  EXPECT_EQ(oversize_reply.rfind("2 ", 0), 0U) << oversize_reply;
  EXPECT_NE(oversize_reply.find("request not read"), std::string::npos) << oversize_reply;
  EXPECT_EQ(malformed_reply.rfind("2 ", 0), 0U) << malformed_reply;
  EXPECT_NE(malformed_reply.find("malformed request"), std::string::npos) << malformed_reply;
  // The silent ones are closed after 5 s without a request: read() sees the end, not a timeout.
  for (const int fd : silent) EXPECT_EQ(reply_of(fd), "");
  const auto relay_log = read_file(stack.dir() / "operator_relay.log");
  EXPECT_NE(relay_log.find("operator command 'estop'"), std::string::npos) << relay_log;
}

}  // namespace
