// Tests of the launcher library: maneuver figures of merit (hand-built recordings with known
// answers) and the process group (real fork/exec of /bin/sleep, /bin/true, /bin/bash).
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cerrno>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "crane/stack/maneuver_metrics.hpp"
#include "crane/launch/iceoryx.hpp"
#include "crane/launch/process_group.hpp"
#include "crane/launch/stack.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace la = crane::launch;
using namespace std::chrono_literals;

namespace {

constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kTrolleyTarget = 1.0;             // [m]
constexpr double kSlewTarget = std::numbers::pi / 2.0;  // [rad]

/// `count` cycles every `dt` seconds from t = 0, all exactly at the targets, no swing, no voltage.
std::vector<crane::stack::RecordedCycle> settled_run(std::size_t count, double dt) {
  std::vector<crane::stack::RecordedCycle> cycles(count);
  for (std::size_t i = 0; i < count; ++i) {
    cycles[i].time = static_cast<double>(i) * dt;
    cycles[i].trolley_position = kTrolleyTarget;
    cycles[i].slew_angle = kSlewTarget;
  }
  return cycles;
}

// ---------------------------------------------------------------------------------------------
// maneuver_metrics

TEST(ManeuverMetrics, SettledFromTheStart) {
  const auto cycles = settled_run(501, 0.01);  // 0 .. 5 s
  const auto m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_EQ(m.settle_time, 0.0);  // no violation at all: settled at the first cycle, t = 0
  EXPECT_EQ(m.final_position_error, 0.0);
  EXPECT_EQ(m.final_slew_error, 0.0);
  EXPECT_EQ(m.max_swing, 0.0);
  EXPECT_EQ(m.residual_swing, 0.0);
  EXPECT_EQ(m.max_voltage, 0.0);
}

TEST(ManeuverMetrics, SettleTimeIsTheSampleAfterTheLastSwingViolation) {
  // Cycles every 0.1 s over 0 .. 6 s; swing 1 deg (> 0.5 deg tolerance) up to and including
  // t = 3.2 s (cycle 32), 0.2 deg afterwards. Position and slew on target throughout. The last
  // violation is cycle 32, so the run settles for good at cycle 33, t = 3.3 s.
  auto cycles = settled_run(61, 0.1);
  for (std::size_t i = 0; i < cycles.size(); ++i) {
    cycles[i].swing_in_plane = (i <= 32 ? 1.0 : 0.2) * kDeg * (i % 2 == 0 ? 1.0 : -1.0);
  }
  const auto m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_DOUBLE_EQ(m.settle_time, cycles[33].time);
  EXPECT_NEAR(m.settle_time, 3.3, 1e-12);
  EXPECT_NEAR(m.max_swing, 1.0 * kDeg, 1e-15);
  // Last 2 s is t in [4, 6]: only the 0.2 deg tail.
  EXPECT_NEAR(m.residual_swing, 0.2 * kDeg, 1e-15);

  // The same with the violation in the out-of-plane swing.
  for (auto& c : cycles) std::swap(c.swing_in_plane, c.swing_out_of_plane);
  EXPECT_DOUBLE_EQ(crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget).settle_time, cycles[33].time);
}

TEST(ManeuverMetrics, TransientViolationAfterSettlingMovesTheSettleTime) {
  // Settled throughout except a single 6 mm position excursion at cycle 40 (t = 4.0 s): "for good"
  // means the settle time is the next cycle, t = 4.1 s, not the first good cycle.
  auto cycles = settled_run(61, 0.1);
  cycles[40].trolley_position = kTrolleyTarget + 0.006;
  const auto m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_DOUBLE_EQ(m.settle_time, cycles[41].time);
  EXPECT_EQ(m.final_position_error, 0.0);
}

TEST(ManeuverMetrics, SlewToleranceCounts) {
  // Slew 6 mrad (> 5 mrad) off until cycle 10 (t = 1.0 s), then on target: settles at t = 1.1 s.
  auto cycles = settled_run(31, 0.1);
  for (std::size_t i = 0; i <= 10; ++i) cycles[i].slew_angle = kSlewTarget - 0.006;
  const auto m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_DOUBLE_EQ(m.settle_time, cycles[11].time);
}

TEST(ManeuverMetrics, NeverWithinToleranceIsNaN) {
  // 6 mm short of the target the whole run (tolerance 5 mm): never settled.
  auto cycles = settled_run(301, 0.01);
  for (auto& c : cycles) c.trolley_position = kTrolleyTarget - 0.006;
  auto m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_TRUE(std::isnan(m.settle_time));
  EXPECT_NEAR(m.final_position_error, 0.006, 1e-12);

  // Within tolerance everywhere except the very last cycle: still never settled "for good".
  cycles = settled_run(301, 0.01);
  cycles.back().trolley_position = kTrolleyTarget + 0.006;
  m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_TRUE(std::isnan(m.settle_time));
}

TEST(ManeuverMetrics, ResidualSwingOnlyOverTheLastTwoSeconds) {
  // Cycles every 0.25 s (exact in binary) over 0 .. 10 s. The residual window is t >= 8 s.
  // A 0.1 rad swing at t = 7.75 s lies outside it (counts for max_swing only); inside it the
  // largest is |-0.03| out of plane at t = 9.5 s.
  auto cycles = settled_run(41, 0.25);
  cycles[31].swing_in_plane = 0.1;        // t = 7.75
  cycles[34].swing_in_plane = 0.02;       // t = 8.5
  cycles[38].swing_out_of_plane = -0.03;  // t = 9.5
  const auto m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_DOUBLE_EQ(m.max_swing, 0.1);
  EXPECT_DOUBLE_EQ(m.residual_swing, 0.03);

  // A shorter window (1 s: t >= 9) drops the 0.02 too but keeps the 0.03.
  crane::stack::SettleCriteria criteria;
  criteria.residual_window = 1.0;
  EXPECT_DOUBLE_EQ(crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget, criteria).residual_swing, 0.03);
  criteria.residual_window = 0.25;  // t >= 9.75: nothing
  EXPECT_DOUBLE_EQ(crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget, criteria).residual_swing, 0.0);
}

TEST(ManeuverMetrics, MaxVoltageOverBothDrivesAndFinalErrors) {
  auto cycles = settled_run(11, 0.1);
  cycles[2].trolley_voltage = 3.0;
  cycles[3].trolley_voltage = -4.0;
  cycles[5].slew_voltage = -7.5;  // the largest magnitude, on the slew drive
  cycles[6].slew_voltage = 6.0;
  cycles.back().trolley_position = kTrolleyTarget - 0.002;
  cycles.back().slew_angle = kSlewTarget + 0.003;
  const auto m = crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget);
  EXPECT_DOUBLE_EQ(m.max_voltage, 7.5);
  EXPECT_NEAR(m.final_position_error, 0.002, 1e-12);
  EXPECT_NEAR(m.final_slew_error, 0.003, 1e-12);

  // Trolley drive the largest: |-8| > 7.5.
  cycles[3].trolley_voltage = -8.0;
  EXPECT_DOUBLE_EQ(crane::stack::evaluate_maneuver(cycles, kTrolleyTarget, kSlewTarget).max_voltage, 8.0);
}

TEST(ManeuverMetrics, EmptyRecordingThrows) {
  EXPECT_THROW((void)crane::stack::evaluate_maneuver({}, kTrolleyTarget, kSlewTarget), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// process_group

class ProcessGroupTest : public ::testing::Test {
 protected:
  void SetUp() override {
    directory_ = std::filesystem::temp_directory_path() /
                 ("crane_test_launch_" + std::to_string(getpid()) + "_" +
                  ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::remove_all(directory_);
    std::filesystem::create_directories(directory_);
  }
  void TearDown() override { std::filesystem::remove_all(directory_); }

  std::string log(const std::string& name) const { return (directory_ / (name + ".log")).string(); }

  static std::string read_text(const std::string& path) {
    std::ifstream file(path);
    std::stringstream text;
    text << file.rdbuf();
    return text.str();
  }

  /// Polls until one child exits or `timeout` passes.
  static std::optional<la::ChildExit> poll_until_exit(la::ProcessGroup& group,
                                                      std::chrono::milliseconds timeout = 5000ms) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (auto exit = group.poll()) return exit;
      std::this_thread::sleep_for(5ms);
    }
    return std::nullopt;
  }

  /// Waits until the file at `path` contains `text` or `timeout` passes.
  static bool wait_for_text(const std::string& path, const std::string& text,
                            std::chrono::milliseconds timeout = 5000ms) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      if (read_text(path).find(text) != std::string::npos) return true;
      std::this_thread::sleep_for(5ms);
    }
    return false;
  }

  std::filesystem::path directory_;
};

TEST_F(ProcessGroupTest, PollReportsExitAndStopAllTerminatesTheRest) {
  la::ProcessGroup group;
  const pid_t a = group.start({"sleep_a", "/bin/sleep", {"30"}, ""});
  const pid_t b = group.start({"sleep_b", "/bin/sleep", {"30"}, ""});
  const pid_t t = group.start({"true", "/bin/true", {}, ""});
  EXPECT_GT(a, 0);
  EXPECT_GT(b, 0);
  EXPECT_GT(t, 0);
  ASSERT_EQ(group.children().size(), 3U);

  const auto exit = poll_until_exit(group);
  ASSERT_TRUE(exit.has_value()) << "/bin/true did not exit within 5 s";
  EXPECT_EQ(exit->name, "true");
  EXPECT_EQ(exit->pid, t);
  ASSERT_TRUE(WIFEXITED(exit->status));
  EXPECT_EQ(WEXITSTATUS(exit->status), 0);
  EXPECT_NE(exit->describe().find("exited with code 0"), std::string::npos) << exit->describe();
  EXPECT_NE(exit->describe().find("true (pid " + std::to_string(t) + ")"), std::string::npos) << exit->describe();

  // The sleeps are still running.
  EXPECT_FALSE(group.poll().has_value());

  // /bin/sleep dies on SIGTERM at once: well inside a 3 s grace, and no SIGKILL needed.
  const auto grace = 3000ms;
  const auto begin = std::chrono::steady_clock::now();
  const auto exits = group.stop_all(grace);
  const auto elapsed = std::chrono::steady_clock::now() - begin;
  EXPECT_LT(elapsed, grace);
  ASSERT_EQ(exits.size(), 2U);
  for (const auto& e : exits) {
    SCOPED_TRACE(e.describe());
    EXPECT_TRUE(e.pid == a || e.pid == b);
    ASSERT_TRUE(WIFSIGNALED(e.status));
    EXPECT_EQ(WTERMSIG(e.status), SIGTERM);
    EXPECT_NE(e.describe().find("killed by signal 15"), std::string::npos);
  }
  for (const auto& child : group.children()) EXPECT_FALSE(child.running) << child.name;
  // Nothing left to reap and nothing left to stop.
  EXPECT_FALSE(group.poll().has_value());
  EXPECT_TRUE(group.stop_all(100ms).empty());
}

TEST_F(ProcessGroupTest, ChildIgnoringSigtermIsKilledAfterTheGrace) {
  la::ProcessGroup group;
  // bash ignores TERM, says so, then becomes `sleep 30` (exec keeps TERM ignored, and leaves no
  // orphan behind when it is SIGKILLed). Waiting for "ready" makes sure the trap is in place
  // before stop_all sends SIGTERM.
  const std::string log_path = log("stubborn");
  const pid_t pid =
      group.start({"stubborn", "/bin/bash", {"-c", "trap '' TERM; echo ready; exec /bin/sleep 30"}, log_path});
  ASSERT_GT(pid, 0);
  ASSERT_TRUE(wait_for_text(log_path, "ready")) << read_text(log_path);

  const auto grace = 500ms;
  const auto begin = std::chrono::steady_clock::now();
  const auto exits = group.stop_all(grace);
  const auto elapsed = std::chrono::steady_clock::now() - begin;
  // SIGTERM is ignored, so stop_all waits the whole grace, then SIGKILLs: grace <= elapsed, and
  // (generous margin for a loaded machine) elapsed < grace + 2 s.
  EXPECT_GE(elapsed, grace);
  EXPECT_LT(elapsed, grace + 2000ms);
  ASSERT_EQ(exits.size(), 1U);
  EXPECT_EQ(exits[0].pid, pid);
  ASSERT_TRUE(WIFSIGNALED(exits[0].status)) << exits[0].describe();
  EXPECT_EQ(WTERMSIG(exits[0].status), SIGKILL);
  EXPECT_NE(exits[0].describe().find("killed by signal 9"), std::string::npos) << exits[0].describe();
}

TEST_F(ProcessGroupTest, NonexistentExecutableExitsWith127) {
  la::ProcessGroup group;
  const std::string log_path = log("missing");
  // fork succeeds, so start() returns a pid; the exec fails in the child, which exits 127 (the
  // shell convention for "command not found").
  const pid_t pid = group.start({"missing", "/nonexistent/crane_no_such_binary", {"--flag"}, log_path});
  ASSERT_GT(pid, 0);
  const auto exit = poll_until_exit(group);
  ASSERT_TRUE(exit.has_value());
  EXPECT_EQ(exit->pid, pid);
  ASSERT_TRUE(WIFEXITED(exit->status)) << exit->describe();
  EXPECT_EQ(WEXITSTATUS(exit->status), 127);
  EXPECT_NE(exit->describe().find("exited with code 127"), std::string::npos) << exit->describe();
  EXPECT_NE(read_text(log_path).find("exec failed"), std::string::npos) << read_text(log_path);
}

TEST_F(ProcessGroupTest, LogPathCapturesStdoutAndStderrAppending) {
  la::ProcessGroup group;
  const std::string log_path = log("echo");
  group.start({"echo", "/bin/echo", {"hello", "crane"}, log_path});
  auto exit = poll_until_exit(group);
  ASSERT_TRUE(exit.has_value());
  EXPECT_EQ(WEXITSTATUS(exit->status), 0);
  EXPECT_EQ(read_text(log_path), "hello crane\n");

  // stderr goes to the same file, and a second process appends rather than truncates.
  group.start({"both", "/bin/bash", {"-c", "echo out; echo err >&2; exit 3"}, log_path});
  exit = poll_until_exit(group);
  ASSERT_TRUE(exit.has_value());
  ASSERT_TRUE(WIFEXITED(exit->status));
  EXPECT_EQ(WEXITSTATUS(exit->status), 3);
  EXPECT_NE(exit->describe().find("exited with code 3"), std::string::npos) << exit->describe();
  EXPECT_EQ(read_text(log_path), "hello crane\nout\nerr\n");
}

TEST_F(ProcessGroupTest, DestructorStopsRunningChildren) {
  pid_t pid = 0;
  {
    la::ProcessGroup group;
    pid = group.start({"sleep", "/bin/sleep", {"30"}, ""});
    ASSERT_GT(pid, 0);
  }
  // The destructor reaped it: the pid is no longer our child.
  int status = 0;
  EXPECT_EQ(waitpid(pid, &status, WNOHANG), -1);
  EXPECT_EQ(errno, ECHILD);
}

// iceoryx's runtime leaves its socket and lock behind when a signal ends the process: the group
// removes them for a child that a signal ended, and leaves a cleanly exited child's files alone
// (iceoryx removes its own then; a file left on a clean exit is not the group's to judge).
TEST_F(ProcessGroupTest, AChildEndedByASignalLosesItsIceoryxRuntimeFiles) {
  namespace fs = std::filesystem;
  const auto files_of = [](pid_t pid) {
    std::vector<fs::path> files;
    for (const char* suffix : {"_1795851044607436901", "_1795851044607436901.lock"}) {
      files.push_back(fs::path(la::kIceoryxRuntimeDirectory) / ("iceoryx_rt_" + std::to_string(pid) + suffix));
    }
    return files;
  };
  const std::string make = "touch " + std::string(la::kIceoryxRuntimeDirectory) + "/iceoryx_rt_$$_1795851044607436901 " +
                           la::kIceoryxRuntimeDirectory + "/iceoryx_rt_$$_1795851044607436901.lock; ";
  la::ProcessGroup group;
  const pid_t killed = group.start({"killed", "/bin/bash", {"-c", make + "kill -9 $$"}, log("killed")});
  auto exit = poll_until_exit(group);
  ASSERT_TRUE(exit.has_value());
  ASSERT_EQ(exit->pid, killed);
  ASSERT_TRUE(WIFSIGNALED(exit->status)) << exit->describe() << ": " << read_text(log("killed"));
  for (const auto& file : files_of(killed)) EXPECT_FALSE(fs::exists(file)) << file;

  const pid_t clean = group.start({"clean", "/bin/bash", {"-c", make + "exit 0"}, log("clean")});
  exit = poll_until_exit(group);
  ASSERT_TRUE(exit.has_value());
  ASSERT_EQ(exit->pid, clean);
  ASSERT_TRUE(WIFEXITED(exit->status)) << exit->describe();
  for (const auto& file : files_of(clean)) {
    EXPECT_TRUE(fs::exists(file)) << file;
    fs::remove(file);
  }

  // stop_all's SIGKILL after the grace: the same.
  const std::string stubborn_log = log("stubborn");
  const pid_t stubborn =
      group.start({"stubborn", "/bin/bash", {"-c", "trap '' TERM; " + make + "echo ready; exec /bin/sleep 30"}, stubborn_log});
  ASSERT_TRUE(wait_for_text(stubborn_log, "ready")) << read_text(stubborn_log);
  for (const auto& file : files_of(stubborn)) ASSERT_TRUE(fs::exists(file)) << file;
  const auto exits = group.stop_all(200ms);
  ASSERT_EQ(exits.size(), 1U);
  ASSERT_TRUE(WIFSIGNALED(exits[0].status)) << exits[0].describe();
  for (const auto& file : files_of(stubborn)) EXPECT_FALSE(fs::exists(file)) << file;
}

// A child that outlives the others (RouDi: ProcessSpec::outlive_killed) is stopped after them, and
// no sooner than its time after the last child that a signal ended; with no such child, at once.
TEST_F(ProcessGroupTest, AnOutlivingChildStopsLastAndAfterItsTimeSinceAKill) {
  for (const bool kill_one : {true, false}) {
    SCOPED_TRACE(kill_one ? "a child killed first" : "no child killed");
    la::ProcessGroup group;
    la::ProcessSpec outliving{"outliving", "/bin/sleep", {"30"}, ""};
    outliving.outlive_killed = 400ms;
    const pid_t last = group.start(outliving);
    // It exits cleanly on SIGTERM, as the stages do (a sleep ended by SIGTERM would count as killed).
    const std::string other_log = log(kill_one ? "other_after_a_kill" : "other");
    const pid_t other =
        group.start({"other", "/usr/bin/python3",
                     {"-c", "import signal, sys, time\n"
                            "signal.signal(signal.SIGTERM, lambda *_: sys.exit(0))\n"
                            "print('ready', flush=True)\n"
                            "time.sleep(30)"},
                     other_log});
    ASSERT_TRUE(wait_for_text(other_log, "ready")) << read_text(other_log);
    std::chrono::steady_clock::time_point killed_at{};
    if (kill_one) {
      const pid_t killed = group.start({"killed", "/bin/bash", {"-c", "kill -9 $$"}, ""});
      const auto exit = poll_until_exit(group);
      killed_at = std::chrono::steady_clock::now();
      ASSERT_TRUE(exit.has_value());
      ASSERT_EQ(exit->pid, killed);
      ASSERT_TRUE(WIFSIGNALED(exit->status)) << exit->describe();
    }
    const auto begin = std::chrono::steady_clock::now();
    const auto exits = group.stop_all(2000ms);
    const auto done = std::chrono::steady_clock::now();
    ASSERT_EQ(exits.size(), 2U);
    EXPECT_EQ(exits[0].pid, other);
    EXPECT_EQ(exits[1].pid, last);
    if (kill_one) {
      EXPECT_GE(done - killed_at, 400ms);
    } else {
      EXPECT_LT(done - begin, 400ms);
    }
  }
}

}  // namespace

// Only the files of that pid: not another pid that begins with the same digits, not other names.
TEST(Iceoryx, OnlyThatProcesssRuntimeFilesAreRemoved) {
  namespace fs = std::filesystem;
  const fs::path directory = fs::temp_directory_path() / ("crane_test_iceoryx_rt_" + std::to_string(getpid()));
  fs::remove_all(directory);
  fs::create_directories(directory);
  const std::vector<std::string> gone = {"iceoryx_rt_4242_1795851044607436901", "iceoryx_rt_4242_1795851044607436901.lock",
                                         "iceoryx_rt_4242_7"};
  const std::vector<std::string> kept = {"iceoryx_rt_42420_1795851044607436901", "iceoryx_rt_424_1",
                                         "xiceoryx_rt_4242_1", "iceoryx_rt_4242", "roudi.log"};
  for (const auto& name : gone) std::ofstream(directory / name) << "x";
  for (const auto& name : kept) std::ofstream(directory / name) << "x";
  EXPECT_EQ(la::remove_iceoryx_runtime_files(4242, directory.string()), 3);
  for (const auto& name : gone) EXPECT_FALSE(fs::exists(directory / name)) << name;
  for (const auto& name : kept) EXPECT_TRUE(fs::exists(directory / name)) << name;
  EXPECT_EQ(la::remove_iceoryx_runtime_files(4242, directory.string()), 0);
  EXPECT_EQ(la::remove_iceoryx_runtime_files(4242, (directory / "missing").string()), 0);
  fs::remove_all(directory);
}

// --dds-mix: vendor per process; every process not named keeps --dds.
TEST(DdsMix, ParsesAndOverridesPerProcess) {
  crane::launch::StackOptions o;
  o.config_path = "c.yaml";
  o.binary_directory = "/bin";
  o.dds = "fast";
  const auto known = crane::launch::stack_process_names(o);
  o.dds_per_process = crane::launch::parse_dds_mix("plant=cyclone,state_estimator=cyclone", known);
  ASSERT_EQ(o.dds_per_process.size(), 2U);
  for (const auto& spec : crane::launch::stack_processes(o)) {
    const auto at = std::find(spec.arguments.begin(), spec.arguments.end(), "--dds");
    ASSERT_NE(at, spec.arguments.end()) << spec.name;
    const bool cyclone = spec.name == "plant" || spec.name == "state_estimator";
    EXPECT_EQ(*(at + 1), cyclone ? "cyclone" : "fast") << spec.name;
  }
  EXPECT_TRUE(crane::launch::parse_dds_mix("", known).empty());
}

// A stack on iceoryx (docs/architecture.md, "Shared memory"): RouDi first, every other process with
// --iceoryx, none on another vendor than Cyclone DDS, nothing that leaves the machine; start_roudi
// false leaves RouDi to run_beside_roudi().
TEST(Iceoryx, RoudiFirstAndEveryProcessOnItOnCycloneOnly) {
  if (la::find_executable("iox-roudi").empty()) GTEST_SKIP() << "iox-roudi not installed (Debian package iceoryx)";
  la::StackOptions o;
  o.config_path = "c.yaml";
  o.binary_directory = "/bin";
  o.dds = "cyclone";
  o.iceoryx = true;
  o.log_directory = "/logs";
  const auto specs = la::stack_processes(o);
  ASSERT_GT(specs.size(), 3U);
  EXPECT_EQ(specs.front().name, la::kRoudiProcess);
  EXPECT_EQ(specs.front().executable, la::find_executable("iox-roudi"));
  EXPECT_EQ(specs.front().log_path, "/logs/iox_roudi.log");
  for (std::size_t i = 1; i < specs.size(); ++i) {
    const auto& a = specs[i].arguments;
    EXPECT_NE(std::find(a.begin(), a.end(), "--iceoryx"), a.end()) << specs[i].name;
  }
  EXPECT_EQ(la::stack_process_names(o).front(), la::kRoudiProcess);
  o.start_roudi = false;
  EXPECT_EQ(la::stack_processes(o).front().name, "supervisor");
  const auto refused = [](la::StackOptions bad, const std::string& named) {
    try {
      (void)la::stack_processes(bad);
      ADD_FAILURE() << "accepted; expected a refusal naming '" << named << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(named), std::string::npos) << e.what();
    }
  };
  auto mixed = o;
  mixed.dds_per_process = {{"tracking", "fast"}};
  refused(mixed, "--iceoryx: tracking: ");
  refused(mixed, "this participant is on fast");
  auto fast = o;
  fast.dds = "fast";
  refused(fast, "Cyclone DDS");
  auto lan = o;
  lan.lan = true;
  refused(lan, "--lan");
  auto secured = o;
  secured.security_directory = "/security";
  refused(secured, "--security /security");
  auto profiled = o;
  profiled.dds_profile = "/lan.xml";
  refused(profiled, "with the network profile /lan.xml");
  // Every reason named at once, in the transport's words (crane/transport/iceoryx_rule.hpp, the rule
  // transport::Participant applies too).
  auto all = fast;
  all.lan = true;
  all.security_directory = "/security";
  refused(all, "this participant is on fast, with --lan, with --security /security");
}

// --iceoryx on a process: on loopback it joins iceoryx; with --lan or a profile it keeps the stack's
// QoS over UDP (a monitor on another machine); a site's domain is never on iceoryx.
TEST(Iceoryx, AProcessJoinsOnLoopbackAndSpeaksTheStacksQosOverTheNetwork) {
  using crane::transport::Liveliness;
  crane::runtime::NodeOptions node;
  node.dds = "cyclone";
  EXPECT_FALSE(crane::runtime::participant_options(node, "p").iceoryx);
  EXPECT_EQ(crane::runtime::participant_options(node, "p").liveliness, Liveliness::dds);
  node.iceoryx = true;
  const auto local = crane::runtime::participant_options(node, "p");
  EXPECT_TRUE(local.iceoryx);
  EXPECT_EQ(crane::transport::effective_liveliness(local), Liveliness::watchdogs);
  auto lan = node;
  lan.loopback_only = false;
  EXPECT_FALSE(crane::runtime::participant_options(lan, "p").iceoryx);
  EXPECT_EQ(crane::runtime::participant_options(lan, "p").liveliness, Liveliness::watchdogs);
  auto profile = node;
  profile.dds_profile = "cyclone_lan_unicast.xml";
  EXPECT_FALSE(crane::runtime::participant_options(profile, "p").iceoryx);
  const auto site = crane::runtime::participant_options(crane::runtime::site_domain_options(node, 10, false), "p");
  EXPECT_FALSE(site.iceoryx);
  EXPECT_EQ(site.liveliness, Liveliness::dds);
}

// find_executable: as the shell finds a command on PATH.
TEST(FindExecutable, FindsWhatThePathHasAndNothingElse) {
  const std::string sh = la::find_executable("sh");
  ASSERT_FALSE(sh.empty());
  EXPECT_EQ(access(sh.c_str(), X_OK), 0) << sh;
  EXPECT_EQ(std::filesystem::path(sh).filename(), "sh");
  EXPECT_TRUE(la::find_executable("crane_no_such_command_anywhere").empty());
}

// run_beside_roudi: RouDi runs while the body's process does, stops after it, and the body's exit
// code comes back; a second RouDi (one runs already) ends at once and takes its body with it.
// RouDi's shared memory (/dev/shm/iceoryx_mgmt, iceoryx 2.0's name) tells whether it runs.
TEST(Iceoryx, RoudiRunsBesideTheBodyAndStopsAfterIt) {
  if (la::find_executable("iox-roudi").empty()) GTEST_SKIP() << "iox-roudi not installed (Debian package iceoryx)";
  const std::filesystem::path management = "/dev/shm/iceoryx_mgmt";
  ASSERT_FALSE(std::filesystem::exists(management)) << "a RouDi runs already on this machine";
  const std::string log = "/tmp/crane_test_roudi_" + std::to_string(getpid()) + ".log";
  const auto started = std::chrono::steady_clock::now();
  const int code = la::run_beside_roudi(log, [&] {
    for (int i = 0; i < 250 && !std::filesystem::exists(management); ++i) std::this_thread::sleep_for(20ms);
    if (!std::filesystem::exists(management)) return 10;  // RouDi never came up
    // A second one beside it: RouDi refuses to start twice; its body is stopped, the result nonzero.
    const auto nested_start = std::chrono::steady_clock::now();
    const int nested = la::run_beside_roudi(log + ".nested", [] {
      std::this_thread::sleep_for(30s);
      return 0;
    });
    if (nested == 0) return 11;
    if (std::chrono::steady_clock::now() - nested_start > 20s) return 12;
    return std::filesystem::exists(management) ? 3 : 13;  // the first RouDi still runs
  });
  EXPECT_EQ(code, 3) << "see " << log << " (10: RouDi never came up, 11: a second RouDi ran, 12: its body was "
                                         "not stopped, 13: the first RouDi went with it)";
  EXPECT_FALSE(std::filesystem::exists(management)) << "RouDi still runs after its body";
  EXPECT_LT(std::chrono::steady_clock::now() - started, 30s);
  std::ifstream text(log);
  const std::string output((std::istreambuf_iterator<char>(text)), std::istreambuf_iterator<char>());
  EXPECT_NE(output.find("RouDi is ready for clients"), std::string::npos) << output;
  if (!HasFailure()) {
    std::filesystem::remove(log);
    std::filesystem::remove(log + ".nested");
  }
}

// The follower's filter (state_estimator::for_follower): the state_estimator process, and it alone,
// gets --follower-filter when the options ask for it (crane_demo: ControllerChoice::follower_filter).
TEST(FollowerFilter, OnlyTheStateEstimatorGetsTheFlagAndOnlyWhenAsked) {
  crane::launch::StackOptions o;
  o.config_path = "c.yaml";
  o.binary_directory = "/bin";
  const auto with_flag = [&] {
    std::set<std::string> names;
    for (const auto& spec : crane::launch::stack_processes(o)) {
      const auto& a = spec.arguments;
      if (std::find(a.begin(), a.end(), "--follower-filter") != a.end()) names.insert(spec.name);
    }
    return names;
  };
  EXPECT_TRUE(with_flag().empty());
  o.estimator_follower_filter = true;
  EXPECT_EQ(with_flag(), (std::set<std::string>{"state_estimator"}));
}

// Where a cycle runs (runtime::ListenerDispatch): --wake reaches the chain (the five stages and the
// plant) and no other process, and only when the options name it (the nodes' default: listener).
TEST(Wake, TheChainsProcessesAndOnlyTheyGetIt) {
  crane::launch::StackOptions o;
  o.config_path = "c.yaml";
  o.binary_directory = "/bin";
  const auto with_wake = [&](const std::string& value) {
    std::set<std::string> names;
    for (const auto& spec : crane::launch::stack_processes(o)) {
      const auto& a = spec.arguments;
      const auto at = std::find(a.begin(), a.end(), "--wake");
      if (at != a.end() && at + 1 != a.end() && *(at + 1) == value) names.insert(spec.name);
    }
    return names;
  };
  EXPECT_TRUE(with_wake("thread").empty());
  EXPECT_TRUE(with_wake("listener").empty());
  o.wake = "thread";
  const std::set<std::string> chain{"plant", "state_estimator", "trajectory_planner", "anti_swing", "tracking",
                                    "friction_compensation"};
  EXPECT_EQ(with_wake("thread"), chain);
  o.hardware = "shm:test_board";  // the plant behind the board, and the bridge, which has no such option
  EXPECT_EQ(with_wake("thread"), chain);
}

TEST(DdsMix, RefusesBadEntriesNamingThem) {
  const std::vector<std::string> known{"plant", "tracking"};
  const auto message = [&](const std::string& text) {
    try {
      (void)crane::launch::parse_dds_mix(text, known);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("plant").find("'plant' is not NAME=VENDOR"), std::string::npos) << message("plant");
  EXPECT_NE(message("crane=fast").find("process 'crane' is not one of plant, tracking"), std::string::npos)
      << message("crane=fast");
  EXPECT_NE(message("plant=opensplice").find("vendor 'opensplice' must be fast or cyclone"), std::string::npos)
      << message("plant=opensplice");
  EXPECT_NE(message("plant=fast,plant=cyclone").find("twice"), std::string::npos) << message("plant=fast,plant=cyclone");
}

// --site-lan: a crane on a host of its own puts only the site's domain on the network: the
// supervisor (its guard) and the site link get --site-lan, no process gets --lan, and the site's
// participant (runtime::site_domain_options) leaves loopback while the crane's own stays on it.
TEST(SiteLan, OnlyTheSiteDomainLeavesTheHost) {
  crane::launch::StackOptions o;
  o.config_path = "c.yaml";
  o.binary_directory = "/bin";
  o.site_file = "site.yaml";
  o.site_crane = "tc1";
  o.site_jobs = "tc1.csv";
  o.site_lan = true;
  std::set<std::string> with_site_lan;
  for (const auto& spec : crane::launch::stack_processes(o)) {
    const auto& a = spec.arguments;
    EXPECT_EQ(std::find(a.begin(), a.end(), "--lan"), a.end()) << spec.name;
    if (std::find(a.begin(), a.end(), "--site-lan") != a.end()) with_site_lan.insert(spec.name);
  }
  EXPECT_EQ(with_site_lan, (std::set<std::string>{"site_link", "supervisor"}));

  crane::runtime::NodeOptions crane_side;
  crane_side.domain_id = 11;
  const auto site_side = crane::runtime::site_domain_options(crane_side, 10, true);
  EXPECT_EQ(site_side.domain_id, 10U);
  EXPECT_FALSE(site_side.loopback_only);
  EXPECT_TRUE(crane_side.loopback_only);
  EXPECT_TRUE(crane::runtime::site_domain_options(crane_side, 10, false).loopback_only);
  // Leaving loopback is the network rule's business: refused without security or --insecure-lan.
  EXPECT_THROW(crane::runtime::check_network_security(site_side.loopback_only, "", "", false), std::invalid_argument);
}
