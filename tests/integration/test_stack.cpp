// Integration tests: the real stage executables as separate processes over Fast DDS.
// Run them inside a private network namespace (deploy/crane test does); otherwise every participant
// is bound to loopback by default.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <iterator>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

#include "crane/launch/process_group.hpp"
#include "crane/launch/stack.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/testing/scratch_directory.hpp"

namespace {

namespace fs = std::filesystem;
namespace tp = crane::transport::topics;
using crane::launch::ProcessGroup;
using Clock = std::chrono::steady_clock;
using Status = crane::protocol::SupervisorStatus;  // its codes: STAGES_ALL, FAULT_*, MODE_*

const std::string kBin = CRANE_BIN_DIR;
const std::string kConfig = std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml";
const std::string kOverheadConfig = std::string(CRANE_SOURCE_DIR) + "/deploy/config/overhead_crane.yaml";
const std::string kGantryConfig = std::string(CRANE_SOURCE_DIR) + "/deploy/config/gantry_crane.yaml";

// crane_test_<name>_<pid>, removed at the end of a test that passes (scratch_directory.hpp).
fs::path fresh_directory(const std::string& name) { return crane::testing::scratch_directory("test_" + name); }

// The main job on one maneuver: every stage its own process, the move sent over DDS, the
// acceptance figures of the issue read back from summary.json.
TEST(Stack, TrolleyManeuverThroughEveryProcess) {
  const fs::path out = fresh_directory("demo");
  ProcessGroup group;
  group.start({"crane_demo", kBin + "/crane_demo",
               {"--config", kConfig, "--out", out.string(), "--maneuver", "trolley", "--friction-compensation",
                "on", "--domain", "11"},
               (out / "demo.log").string()});
  std::optional<crane::launch::ChildExit> exit;
  const auto deadline = Clock::now() + std::chrono::seconds(240);
  while (!(exit = group.poll()) && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  ASSERT_TRUE(exit.has_value()) << "crane_demo did not finish within 240 s; see " << out;
  ASSERT_TRUE(WIFEXITED(exit->status) && WEXITSTATUS(exit->status) == 0) << exit->describe() << "; see " << out;

  std::ifstream file(out / "summary.json");
  ASSERT_TRUE(file) << "no summary.json in " << out;
  const auto summary = nlohmann::json::parse(file);
  ASSERT_EQ(summary["maneuvers"].size(), 1U);
  const auto& m = summary["maneuvers"][0];
  EXPECT_EQ(m["name"], "trolley");
  EXPECT_EQ(m["friction_compensation"], true);
  EXPECT_LT(m["final_position_error_m"].get<double>(), 0.005);
  EXPECT_LT(m["residual_swing_rad"].get<double>(), 0.5 * M_PI / 180.0);
  EXPECT_FALSE(m["settle_time_s"].is_null()) << "the move never settled";
  EXPECT_EQ(m["missing_samples"].get<int>(), 0);
  EXPECT_EQ(m["braked_cycles"].get<int>(), 0) << "the brakes were on during the move";
  // The move is 0.75 m with a_max 0.9929 m/s^2 under +-10 V: the drive must have been used, within range.
  EXPECT_GT(m["max_voltage_V"].get<double>(), 0.5);
  EXPECT_LE(m["max_voltage_V"].get<double>(), 10.0);

  const auto& loop = summary["loop"];
  EXPECT_EQ(loop["overruns"].get<int>(), 0) << "lockstep must not overrun";
  EXPECT_TRUE(loop["diagnostics_complete"].get<bool>());
  EXPECT_GT(loop["latency_us"]["p50"].get<double>(), 0.0);
  EXPECT_GE(loop["latency_us"]["max"].get<double>(), loop["latency_us"]["p99"].get<double>());
  // Seven stage processes plus the operator, each a distinct OS process.
  std::set<std::string> names;
  std::set<int> pids;
  for (const auto& p : loop["processes"]) {
    names.insert(p["name"].get<std::string>());
    pids.insert(p["pid"].get<int>());
  }
  for (const auto* name : {"plant", "state_estimator", "trajectory_planner", "anti_swing", "tracking",
                           "friction_compensation", "supervisor", "operator"}) {
    EXPECT_EQ(names.count(name), 1U) << name << " missing from summary.json";
  }
  EXPECT_EQ(pids.size(), loop["processes"].size()) << "two entries share a pid";
}

// Runs crane_demo (`config`, the lab's by default; its own output directory and DDS domain) with
// `options` and returns its summary.json; an empty json (and a test failure) if it fails or takes
// longer than 240 s.
nlohmann::json run_demo(const std::string& name, unsigned domain, const std::vector<std::string>& options,
                        const std::string& config = kConfig) {
  const fs::path out = fresh_directory(name);
  std::vector<std::string> arguments{"--config", config, "--out", out.string(), "--domain", std::to_string(domain)};
  arguments.insert(arguments.end(), options.begin(), options.end());
  ProcessGroup group;
  group.start({"crane_demo", kBin + "/crane_demo", arguments, (out / "demo.log").string()});
  std::optional<crane::launch::ChildExit> exit;
  const auto deadline = Clock::now() + std::chrono::seconds(240);
  while (!(exit = group.poll()) && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  if (!exit || !WIFEXITED(exit->status) || WEXITSTATUS(exit->status) != 0) {
    ADD_FAILURE() << name << ": crane_demo failed or timed out; see " << out;
    return {};
  }
  std::ifstream file(out / "summary.json");
  return nlohmann::json::parse(file);
}

// Runs crane_sim demo (every stage object in one process, no DDS; `config`, the lab's by default)
// with the demo's `options` into a fresh directory, which it returns (empty path, and a test failure, if it fails).
fs::path run_sim(const std::string& name, const std::vector<std::string>& options, const std::string& config = kConfig) {
  const fs::path out = fresh_directory(name);
  std::vector<std::string> arguments{"demo", "--config", config, "--out", out.string()};
  arguments.insert(arguments.end(), options.begin(), options.end());
  ProcessGroup group;
  group.start({"crane_sim", kBin + "/crane_sim", arguments, (out / "sim.log").string()});
  std::optional<crane::launch::ChildExit> exit;
  const auto deadline = Clock::now() + std::chrono::seconds(120);
  while (!(exit = group.poll()) && Clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  if (!exit || !WIFEXITED(exit->status) || WEXITSTATUS(exit->status) != 0) {
    ADD_FAILURE() << name << ": crane_sim failed or timed out; see " << out;
    return {};
  }
  return out;
}

std::string file_bytes(const fs::path& path) {
  std::ifstream file(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(file), std::istreambuf_iterator<char>()};
}

// Every CSV of a crane_demo run (its summary) equals crane_sim's of the same name, to the last bit.
void expect_sim_equals_demo(const nlohmann::json& summary, const fs::path& demo_out, const fs::path& sim_out) {
  ASSERT_FALSE(sim_out.empty());
  for (const auto& m : summary["maneuvers"]) {
    const std::string csv = m["csv"];
    const std::string demo = file_bytes(demo_out / csv);
    ASSERT_GT(demo.size(), 1000U) << csv;
    EXPECT_TRUE(file_bytes(sim_out / csv) == demo) << csv << ": crane_sim (" << sim_out << ") differs from crane_demo ("
                                                   << demo_out << ")";
  }
}

// Lockstep never guesses (docs/architecture.md, "The 100 Hz cycle"): the same maneuvers run again
// and again give the same CSV files to the last bit and the same figures, with 0 overruns and no
// fault, whatever the machine does meanwhile. Repetition 0 runs clean; every later one drops a
// seeded 1 % of the samples every reader of the chain takes (CRANE_INJECT_LOSS, as a lossy
// best-effort link would), and the odd ones run while stress-ng loads both cores at normal priority.
// CRANE_LOCKSTEP_REPEATS (default 2: clean, then lossy under load) and CRANE_LOCKSTEP_SEED set the
// count and the seed; deploy/bench_lockstep.sh runs the whole demo 10 times, every other run under
// stress-ng.
TEST(Lockstep, RepeatedRunsAreBitIdenticalWithLostSamplesAndUnderLoad) {
  const int repeats = std::getenv("CRANE_LOCKSTEP_REPEATS") ? std::atoi(std::getenv("CRANE_LOCKSTEP_REPEATS")) : 2;
  const unsigned seed = std::getenv("CRANE_LOCKSTEP_SEED") ? static_cast<unsigned>(std::atoi(std::getenv("CRANE_LOCKSTEP_SEED")))
                                                           : 20261122U;
  ASSERT_GE(repeats, 2);
  const std::vector<std::string> options{"--maneuver", "trolley", "--maneuver", "combined",
                                         "--friction-compensation", "both"};
  const std::vector<std::string> compared{"settle_time_s", "final_position_error_m", "final_slew_error_rad",
                                          "max_swing_rad", "residual_swing_rad", "max_voltage_V", "samples"};
  nlohmann::json first;
  std::map<std::string, std::string> first_csv;
  for (int r = 0; r < repeats; ++r) {
    SCOPED_TRACE("repetition " + std::to_string(r));
    const std::string loss = r == 0 ? "" : "0.01:" + std::to_string(seed + static_cast<unsigned>(r));
    ProcessGroup stress;
    if (r % 2 == 1) {
      stress.start({"stress-ng", "/usr/bin/stress-ng", {"--cpu", "2", "--timeout", "600s", "--quiet"}, ""});
    }
    ::setenv("CRANE_INJECT_LOSS", loss.c_str(), 1);
    const std::string name = "lockstep_" + std::to_string(r);
    const auto summary = run_demo(name, 30, options);
    ::unsetenv("CRANE_INJECT_LOSS");
    stress.stop_all();
    ASSERT_FALSE(summary.is_null());
    const fs::path out = fs::temp_directory_path() / ("crane_test_" + name + "_" + std::to_string(getpid()));
    ASSERT_EQ(summary["maneuvers"].size(), 4U);
    EXPECT_EQ(summary["loop"]["overruns"].get<int>(), 0);
    EXPECT_TRUE(summary["loop"]["failures"].empty()) << summary["loop"]["failures"];
    std::printf("[ figure   ] repetition %d (%s%s): %.1f s simulated in %.2f s of stepping (%.0fx real time)\n", r,
                loss.empty() ? "no loss" : ("loss " + loss).c_str(), r % 2 == 1 ? ", stress-ng on 2 cores" : "",
                summary["loop"]["simulated_time_s"].get<double>(), summary["loop"]["wall_time_s"].get<double>(),
                summary["loop"]["real_time_factor"].get<double>());
    for (const auto& m : summary["maneuvers"]) {
      const std::string csv = m["csv"];
      EXPECT_EQ(m["braked_cycles"].get<int>(), 0) << csv;
      EXPECT_EQ(m["missing_samples"].get<int>(), 0) << csv;
      EXPECT_EQ(m["overruns"].get<int>(), 0) << csv;
      // No fault raised in any run: the supervisor's fault log holds commands only.
      const std::string run = csv.substr(0, csv.size() - 4);
      std::ifstream faults(out / "logs" / run / "faults.jsonl");
      EXPECT_TRUE(faults.is_open()) << run << ": no fault log";  // the supervisor opens it at start
      std::string line;
      while (std::getline(faults, line)) EXPECT_EQ(line.find("\"raised\""), std::string::npos) << run << ": " << line;
      std::ifstream file(out / csv, std::ios::binary);
      const std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
      ASSERT_GT(bytes.size(), 1000U) << csv;
      if (r == 0) {
        first_csv[csv] = bytes;
      } else {
        EXPECT_TRUE(bytes == first_csv[csv]) << csv << " differs from repetition 0 (see " << out << ")";
      }
    }
    if (r == 0) {
      first = summary;
      // The in-process runner gives the same files: the same stage objects on the same inputs.
      expect_sim_equals_demo(summary, out, run_sim("lockstep_sim", options));
    } else {
      for (std::size_t i = 0; i < 4; ++i) {
        for (const auto& key : compared) {
          EXPECT_EQ(summary["maneuvers"][i][key], first["maneuvers"][i][key]) << key << " of maneuver " << i;
        }
      }
    }
  }
}

// Packets sent on this network namespace's loopback interface so far (/proc/net/dev, which shows the
// namespace of the reading process; /sys/class/net shows the one sysfs was mounted in).
long loopback_packets_sent() {
  std::ifstream dev("/proc/net/dev");
  std::string line;
  while (std::getline(dev, line)) {
    const auto colon = line.find(':');
    if (colon == std::string::npos || line.substr(0, colon).find("lo") == std::string::npos) continue;
    std::istringstream fields(line.substr(colon + 1));
    long value = 0;
    for (int i = 0; i < 10 && (fields >> value); ++i) {
    }
    return value;  // the 10th field: transmitted packets
  }
  return -1;
}

// The stack on iceoryx shared memory (docs/architecture.md, "Shared memory"): the same maneuvers
// give crane_sim's files to the last bit, as on UDP, and the samples leave the network stack. On
// UDP every cycle sends at least 6 packets for the chain's hops alone (and their copies to the
// supervisor and the recorder); on iceoryx only discovery is left, which goes with the wall time,
// not the cycles (2026-11-28: 2905 packets against 46831 for the trolley move, all of them to
// discovery ports). Both counted here, in this test's private network namespace (the integration
// tests run alone).
TEST(Lockstep, OnIceoryxTheDemoIsCraneSimToTheBitAndOffTheNetwork) {
  const std::vector<std::string> maneuvers{"--maneuver", "trolley", "--maneuver", "combined",
                                           "--friction-compensation", "on"};
  auto options = maneuvers;
  options.insert(options.end(), {"--dds", "cyclone"});
  auto with_iceoryx = options;
  with_iceoryx.push_back("--iceoryx");
  const long before_udp = loopback_packets_sent();
  ASSERT_GE(before_udp, 0) << "no loopback interface in /proc/net/dev";
  const auto udp = run_demo("iceoryx_udp", 36, options);
  const long udp_packets = loopback_packets_sent() - before_udp;
  const auto iceoryx = run_demo("iceoryx", 37, with_iceoryx);
  const long iceoryx_packets = loopback_packets_sent() - before_udp - udp_packets;
  ASSERT_FALSE(udp.is_null());
  ASSERT_FALSE(iceoryx.is_null());
  ASSERT_EQ(iceoryx["maneuvers"].size(), 2U);
  const fs::path out = fs::temp_directory_path() / ("crane_test_iceoryx_" + std::to_string(getpid()));
  expect_sim_equals_demo(iceoryx, out, run_sim("iceoryx_sim", maneuvers));
  double cycles = 0.0;
  for (const auto& m : iceoryx["maneuvers"]) {
    EXPECT_EQ(m["braked_cycles"].get<int>(), 0) << m["csv"];
    EXPECT_EQ(m["missing_samples"].get<int>(), 0) << m["csv"];
    cycles += m["samples"].get<double>();
  }
  EXPECT_EQ(iceoryx["loop"]["overruns"].get<int>(), 0);
  std::printf("[ figure   ] %.0f cycles: %ld packets on loopback over UDP (%.1f a cycle), %ld on iceoryx (%.2f a "
              "cycle); %.0fx vs %.0fx real time\n",
              cycles, udp_packets, static_cast<double>(udp_packets) / cycles, iceoryx_packets,
              static_cast<double>(iceoryx_packets) / cycles, udp["loop"]["real_time_factor"].get<double>(),
              iceoryx["loop"]["real_time_factor"].get<double>());
  EXPECT_GE(static_cast<double>(udp_packets), 6.0 * cycles) << "the UDP run must carry the chain on loopback";
  EXPECT_LT(5 * iceoryx_packets, udp_packets) << "on iceoryx the samples must leave the network stack";
}

// `maneuvers` (crane_demo options) of `config` run twice, lockstep: with the plant on DDS, and through
// the real hardware_bridge process against the emulated board with the plant behind it (the bridge
// on the board's sample clock). The results must agree within 5 mm (trolley, bridge, slew as arc
// length at the jib radius of (3.55)) and 0.5 deg of swing (issue 5), every move settled through
// the bridge, no braked cycle, no lost sample, no overrun.
void expect_bridge_matches_plant_on_dds(const std::string& name, unsigned domain, const std::string& config,
                                        const std::vector<std::string>& maneuvers, std::size_t count) {
  auto with_bridge = maneuvers;
  with_bridge.insert(with_bridge.end(), {"--hardware", "shm"});
  const auto dds = run_demo(name + "_dds", domain, maneuvers, config);
  const auto bridge = run_demo(name + "_bridge", domain + 1, with_bridge, config);
  ASSERT_FALSE(dds.is_null());
  ASSERT_FALSE(bridge.is_null());
  ASSERT_EQ(dds["maneuvers"].size(), count);
  ASSERT_EQ(bridge["maneuvers"].size(), count);
  EXPECT_EQ(bridge["sensor_writer"].get<std::string>().rfind("hardware_bridge", 0), 0U);
  const double deg = M_PI / 180.0;
  for (std::size_t i = 0; i < count; ++i) {
    const auto& a = dds["maneuvers"][i];
    const auto& b = bridge["maneuvers"][i];
    const std::string maneuver = a["name"];
    ASSERT_EQ(b["name"], a["name"]);
    const double radius = 0.9;  // [m] slew errors as arc length at the jib radius of (3.55)
    const double dx = std::fabs(a["final_position_error_m"].get<double>() - b["final_position_error_m"].get<double>());
    const double dslew =
        std::fabs(a["final_slew_error_rad"].get<double>() - b["final_slew_error_rad"].get<double>()) * radius;
    // The overhead crane's summary has the bridge's error; the others have no bridge.
    ASSERT_EQ(a.contains("final_bridge_error_m"), b.contains("final_bridge_error_m")) << maneuver;
    const double dbridge = a.contains("final_bridge_error_m")
                               ? std::fabs(a["final_bridge_error_m"].get<double>() - b["final_bridge_error_m"].get<double>())
                               : 0.0;
    const double dmax = std::fabs(a["max_swing_rad"].get<double>() - b["max_swing_rad"].get<double>());
    const double dres = std::fabs(a["residual_swing_rad"].get<double>() - b["residual_swing_rad"].get<double>());
    std::printf("[ figure   ] %s through the bridge vs on DDS: final position %+.3f mm, slew %+.3f mm at 0.9 m, "
                "bridge %+.3f mm, max swing %+.4f deg, residual swing %+.4f deg; settle %.2f s vs %.2f s\n",
                maneuver.c_str(), dx * 1e3, dslew * 1e3, dbridge * 1e3, dmax / deg, dres / deg,
                b["settle_time_s"].is_null() ? -1.0 : b["settle_time_s"].get<double>(),
                a["settle_time_s"].is_null() ? -1.0 : a["settle_time_s"].get<double>());
    EXPECT_LT(dx, 0.005) << maneuver;
    EXPECT_LT(dslew, 0.005) << maneuver;
    EXPECT_LT(dbridge, 0.005) << maneuver;
    EXPECT_LT(dmax, 0.5 * deg) << maneuver;
    EXPECT_LT(dres, 0.5 * deg) << maneuver;
    EXPECT_FALSE(b["settle_time_s"].is_null()) << maneuver << " never settled through the bridge";
    EXPECT_EQ(b["braked_cycles"].get<int>(), 0) << maneuver;
    EXPECT_EQ(b["missing_samples"].get<int>(), 0) << maneuver;
  }
  EXPECT_EQ(bridge["loop"]["overruns"].get<int>(), 0);
}

// The three maneuvers of section 3.3.3 on the lab tower crane.
TEST(Stack, ThreeManeuversThroughTheHardwareBridgeMatchThePlantOnDds) {
  expect_bridge_matches_plant_on_dds("maneuvers", 13, kConfig,
                                     {"--friction-compensation", "on", "--maneuver", "trolley", "--maneuver", "slew",
                                      "--maneuver", "combined"},
                                     3);
}

// The overhead crane's diagonal move (bridge and trolley together, hoisting): the bridge's counter,
// DAC and brake line through the board. Not to the bit, unlike the tower crane's maneuvers: the
// hardware bridge has no hoist encoder (section 4.1) and reports the configured 4 m while the load
// is lowered to 5 m, where the plant on DDS reports the true length (the same move without hoisting
// gives the plant-on-DDS rows to the bit: docs/architecture.md, "The bridge axis").
TEST(Stack, OverheadDiagonalThroughTheHardwareBridgeMatchesThePlantOnDds) {
  expect_bridge_matches_plant_on_dds("overhead_diagonal", 25, kOverheadConfig,
                                     {"--friction-compensation", "on", "--maneuver", "diagonal"}, 1);
}

// The gantry crane through the hardware bridge with its own channel map (no slew's channels: the
// board is asked for the trolley's, the swings' and the hoist's only): the trolley move of (3.54)
// as on DDS (to the bit in the runs of docs/cranes.md; asserted within the bounds).
TEST(Stack, GantryTrolleyThroughTheHardwareBridgeMatchesThePlantOnDds) {
  expect_bridge_matches_plant_on_dds("gantry_trolley", 27, kGantryConfig,
                                     {"--friction-compensation", "on", "--maneuver", "trolley"}, 1);
}

// Two DDS vendors (issue 6): the three maneuvers of section 3.3.3 on Cyclone DDS alone and on two
// mixed stacks give the results of the Fast DDS stack. Lockstep makes every run deterministic, so
// the figures must agree to well below the printed digits (0.01 mm, 0.001 deg, one cycle of settle
// time).
TEST(Stack, MixedVendorStacksGiveTheSingleVendorResults) {
  const std::vector<std::string> maneuvers{"--friction-compensation", "on", "--maneuver", "trolley",
                                           "--maneuver", "slew", "--maneuver", "combined"};
  auto with = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), maneuvers.begin(), maneuvers.end());
    return extra;
  };
  const auto fast = run_demo("vendors_fast", 17, with({"--dds", "fast"}));
  const std::vector<std::pair<std::string, nlohmann::json>> others{
      {"cyclone only", run_demo("vendors_cyclone", 18, with({"--dds", "cyclone"}))},
      {"plant+estimator on cyclone", run_demo("vendors_mix_a", 19, with({"--dds-mix", "plant=cyclone,state_estimator=cyclone"}))},
      {"chain on cyclone, plant+supervisor+operator on fast",
       run_demo("vendors_mix_b", 20, with({"--dds", "cyclone", "--dds-mix", "plant=fast,supervisor=fast,operator=fast"}))}};
  ASSERT_FALSE(fast.is_null());
  ASSERT_EQ(fast["maneuvers"].size(), 3U);
  const double deg = M_PI / 180.0;
  for (const auto& [label, other] : others) {
    ASSERT_FALSE(other.is_null()) << label;
    ASSERT_EQ(other["maneuvers"].size(), 3U) << label;
    for (std::size_t i = 0; i < 3; ++i) {
      const auto& a = fast["maneuvers"][i];
      const auto& b = other["maneuvers"][i];
      const std::string name = a["name"];
      ASSERT_EQ(b["name"], a["name"]);
      ASSERT_FALSE(a["settle_time_s"].is_null()) << name;
      ASSERT_FALSE(b["settle_time_s"].is_null()) << label << " " << name << " never settled";
      const double dx = std::fabs(a["final_position_error_m"].get<double>() - b["final_position_error_m"].get<double>());
      const double dslew = std::fabs(a["final_slew_error_rad"].get<double>() - b["final_slew_error_rad"].get<double>());
      const double dmax = std::fabs(a["max_swing_rad"].get<double>() - b["max_swing_rad"].get<double>());
      const double dres = std::fabs(a["residual_swing_rad"].get<double>() - b["residual_swing_rad"].get<double>());
      const double dsettle = std::fabs(a["settle_time_s"].get<double>() - b["settle_time_s"].get<double>());
      std::printf("[ figure   ] %-8s %s vs fast: settle %.2f vs %.2f s, |d position| %.4f mm, |d slew| %.4f mrad, "
                  "|d max swing| %.5f deg, |d residual swing| %.5f deg\n",
                  name.c_str(), label.c_str(), b["settle_time_s"].get<double>(), a["settle_time_s"].get<double>(),
                  dx * 1e3, dslew * 1e3, dmax / deg, dres / deg);
      EXPECT_LT(dx, 1e-5) << label << " " << name;
      EXPECT_LT(dslew, 1e-5) << label << " " << name;
      EXPECT_LT(dmax, 1e-3 * deg) << label << " " << name;
      EXPECT_LT(dres, 1e-3 * deg) << label << " " << name;
      EXPECT_LE(dsettle, 0.0101) << label << " " << name;
      EXPECT_EQ(b["braked_cycles"].get<int>(), 0) << label << " " << name;
      EXPECT_EQ(b["missing_samples"].get<int>(), 0) << label << " " << name;
    }
    // The summary records each process's vendor as launched.
    std::map<std::string, std::string> vendors;
    for (const auto& process : other["loop"]["processes"]) vendors[process["name"]] = process["dds"];
    if (label == "cyclone only") {
      for (const auto& [process, vendor] : vendors) EXPECT_EQ(vendor, "cyclone") << process;
    } else if (label == "plant+estimator on cyclone") {
      EXPECT_EQ(vendors["plant"], "cyclone");
      EXPECT_EQ(vendors["state_estimator"], "cyclone");
      EXPECT_EQ(vendors["tracking"], "fast");
    }
  }
}

// Issue 4 on the running stack: a recording of the combined maneuver over DDS (mixed vendors) is
// audited with the crane model against the configuration. The plant as configured gives "none";
// the plant with a load 25 % heavier than the configuration says (2.5 kg against 2.0 kg) gives
// payload_mass_error with the 0.5 kg within 10 %. The whole record (the move, then the crane at
// rest until the end): the audit holds out among the moving windows (hold_out_moving_windows),
// so a record that ends at rest is validated where the crane moves (issue 17 item 5; it used to
// be cut at 7 s, inside the move: docs/model_audit.md).
// Run with delay1, the controller this figure was measured with: the follower's recording (the
// default since issue 32) leaves the audit naming no cause (2026-11-25, docs/model_audit.md).
TEST(Stack, CraneAuditOfAStackRecordingNamesAHeavierPayload) {
  const std::vector<std::string> run{"--maneuver", "combined", "--friction-compensation", "on", "--controller", "delay1",
                                     "--dds-mix", "plant=cyclone,state_estimator=cyclone"};
  auto heavy_run = run;
  heavy_run.insert(heavy_run.end(), {"--plant-load-mass-factor", "1.25"});
  const auto as_configured = run_demo("audit_configured", 23, run);
  const auto heavy = run_demo("audit_heavy", 24, heavy_run);
  ASSERT_FALSE(as_configured.is_null());
  ASSERT_FALSE(heavy.is_null());
  auto audit = [](const std::string& name) {
    const fs::path dir = fs::temp_directory_path() / ("crane_test_" + name + "_" + std::to_string(getpid()));
    const std::string command = kBin + "/crane_audit --model crane --data " + (dir / "combined_fc_on.csv").string() +
                                " --config " + kConfig + " --out " + (dir / "audit").string() + " > " +
                                (dir / "audit.log").string() + " 2>&1";
    EXPECT_EQ(WEXITSTATUS(std::system(command.c_str())), 0) << "see " << dir / "audit.log";
    std::ifstream file(dir / "audit" / "report.json");
    return file ? nlohmann::json::parse(file, nullptr, false) : nlohmann::json();
  };
  const auto configured_report = audit("audit_configured");
  const auto heavy_report = audit("audit_heavy");
  ASSERT_TRUE(configured_report.is_object());
  ASSERT_TRUE(heavy_report.is_object());
  const double error = heavy_report["parameters"].value("load_mass_error", nlohmann::json::object()).value("value", 0.0);
  std::printf("[ figure   ] crane audit of stack recordings: as configured -> %s; load 2.5 kg against 2.0 kg "
              "configured -> %s, load mass error %+.4f kg, held-out gain %.1f %%\n",
              configured_report["cause"].get<std::string>().c_str(), heavy_report["cause"].get<std::string>().c_str(),
              error, heavy_report["gain"].value("percent", 0.0));
  EXPECT_EQ(configured_report["cause"], "none");
  EXPECT_EQ(heavy_report["cause"], "payload_mass_error");
  EXPECT_NEAR(error, 0.5, 0.05);
}

// The time-optimal swing-free profile for the 0.75 m trolley move of (3.54), closed loop on the
// plant with friction: settled within 1.1 times the profile's duration (2.2543 s, checked against a
// linear program in tests/trajectory_profiles) with residual swing below 0.2 deg (issue 3).
// `--profile time_optimal` alone picks the controller (auto: PD tracking with acceleration
// feedforward, no anti-swing law, for a trolley move).
TEST(Stack, TimeOptimalTrolleyMoveSettlesWithinTenPercentOfItsDuration) {
  const auto summary = run_demo("time_optimal", 15, {"--maneuver", "trolley", "--friction-compensation", "on",
                                                      "--profile", "time_optimal"});
  ASSERT_FALSE(summary.is_null());
  const auto& m = summary["maneuvers"][0];
  EXPECT_EQ(summary["controller"], "auto");
  EXPECT_EQ(m["controller"], "none+feedforward");
  ASSERT_FALSE(m["settle_time_s"].is_null()) << "never settled";
  const double duration = 2.2543;  // [s] the profile's duration
  std::printf("[ figure   ] time-optimal trolley move: settled in %.2f s = %.3f x the profile's %.4f s, residual "
              "swing %.3f deg\n",
              m["settle_time_s"].get<double>(), m["settle_time_s"].get<double>() / duration, duration,
              m["residual_swing_rad"].get<double>() * 180.0 / M_PI);
  EXPECT_LE(m["settle_time_s"].get<double>(), 1.1 * duration);
  EXPECT_LT(m["residual_swing_rad"].get<double>(), 0.2 * M_PI / 180.0);
  EXPECT_EQ(m["braked_cycles"].get<int>(), 0);
}

// crane_topic, the monitoring tool, against a running realtime stack: discovery lists every topic
// with its writers and readers, hz measures the 100 Hz sensor stream, echo prints a sample, record
// writes the audit's CSV.
TEST(Stack, CraneTopicListsMeasuresEchoesAndRecords) {
  const fs::path logs = fresh_directory("crane_topic");
  crane::launch::StackOptions options;
  options.config_path = kConfig;
  options.binary_directory = kBin;
  options.log_directory = logs.string();
  options.domain_id = 16;
  options.lockstep = false;
  ProcessGroup group;
  for (const auto& spec : crane::launch::stack_processes(options)) group.start(spec);
  auto run = [&](const std::string& arguments, const fs::path& out) {
    const std::string command = kBin + "/crane_topic " + arguments + " --domain 16 > " + out.string() + " 2>&1";
    return WEXITSTATUS(std::system(command.c_str()));
  };
  std::this_thread::sleep_for(std::chrono::seconds(3));  // the stack discovers itself
  ASSERT_FALSE(group.poll().has_value()) << "a stage died; see " << logs;

  ASSERT_EQ(run("list --json --wait 2", logs / "list.json"), 0) << "see " << logs;
  std::ifstream list_file(logs / "list.json");
  const auto topics = nlohmann::json::parse(list_file);
  for (const auto* name : {"rt/crane/hw/sensors", "rt/crane/hw/actuators", "rt/crane/state/estimate",
                           "rt/crane/planner/reference", "rt/crane/control/anti_swing", "rt/crane/control/linear",
                           "rt/crane/safety/status", "rt/crane/diag/loop"}) {
    ASSERT_TRUE(topics.contains(name)) << name << " not discovered";
    EXPECT_GE(topics[name]["writers"].size(), 1U) << name;
  }
  EXPECT_EQ(topics["rt/crane/hw/sensors"]["type"], "crane_msgs::msg::dds_::SensorSample_");
  EXPECT_EQ(topics["rt/crane/hw/sensors"]["writers"][0]["participant"], "plant");
  EXPECT_EQ(topics["rt/crane/hw/sensors"]["writers"].size(), 1U);

  ASSERT_EQ(run("hz rt/crane/hw/sensors --duration 3 --json", logs / "hz.json"), 0);
  std::ifstream hz_file(logs / "hz.json");
  const auto hz = nlohmann::json::parse(hz_file);
  std::printf("[ figure   ] crane_topic hz rt/crane/hw/sensors: %.2f Hz, period std %.3f ms, jitter p99 %.3f ms\n",
              hz["receive"]["rate_hz"].get<double>(), hz["receive"]["period_std_ms"].get<double>(),
              hz["receive"]["jitter_p99_ms"].get<double>());
  EXPECT_NEAR(hz["receive"]["rate_hz"].get<double>(), 100.0, 5.0);

  // The realtime plant stamps each sample with its cycle's scheduled instant, however late it
  // runs: consecutive stamps 10 ms apart per seq (the supervisor differentiates positions over
  // them; with publish times, a late sample then one on time read as a crane up to 4x faster).
  ASSERT_EQ(run("echo rt/crane/hw/sensors --count 300", logs / "sensors.jsonl"), 0);
  std::ifstream sensors_file(logs / "sensors.jsonl");
  std::optional<std::pair<std::uint64_t, std::int64_t>> previous;
  double worst_us = 0.0;
  int intervals = 0;
  for (std::string line; std::getline(sensors_file, line);) {
    const auto sample = nlohmann::json::parse(line);
    const auto& header = sample["header"];
    const std::uint64_t seq = header["seq"].get<std::uint64_t>();
    const std::int64_t ns = header["stamp"]["sec"].get<std::int64_t>() * 1000000000LL + header["stamp"]["nanosec"].get<std::int64_t>();
    if (previous && seq > previous->first) {
      const double off_us = std::abs(static_cast<double>(ns - previous->second) / 1e3 - 1e4 * static_cast<double>(seq - previous->first));
      worst_us = std::max(worst_us, off_us);
      ++intervals;
    }
    previous = {seq, ns};
  }
  std::printf("[ figure   ] the realtime plant's sensor stamps: %d intervals, worst %.1f us off seq x 10 ms\n", intervals, worst_us);
  EXPECT_GE(intervals, 250);
  EXPECT_LT(worst_us, 5.0) << "stamps jitter: the supervisor's velocities would too";

  ASSERT_EQ(run("echo rt/crane/safety/status --count 1", logs / "echo.json"), 0);
  std::ifstream echo_file(logs / "echo.json");
  const auto status = nlohmann::json::parse(echo_file);
  EXPECT_EQ(status["stages_alive"], Status::STAGES_ALL);

  ASSERT_EQ(run("record --out " + (logs / "run.csv").string() + " --duration 2", logs / "record.log"), 0);
  std::ifstream csv(logs / "run.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("t,u_x,u_gamma,x,gamma,phi,theta,L", 0), 0U);
  int rows = 0;
  for (std::string line; std::getline(csv, line);) ++rows;
  EXPECT_GT(rows, 100);
  EXPECT_EQ(run("echo rt/crane/nothing", logs / "unknown.log"), 2) << "an unknown topic is a usage error";
}

// Each controller of the dissertation, selected at launch, moves the trolley of (3.54) through the
// real processes to within the tolerances (5 mm, 0.5 deg residual swing). The figures
// differ per controller (docs/architecture.md); here only the acceptance criteria are checked.
class StackController : public ::testing::TestWithParam<const char*> {};

TEST_P(StackController, TrolleyManeuverMeetsTheCriteria) {
  const std::string controller = GetParam();
  const auto summary = run_demo("controller_" + controller, 13,
                                {"--maneuver", "trolley", "--friction-compensation", "on", "--controller", controller});
  ASSERT_FALSE(summary.is_null());
  EXPECT_EQ(summary["controller"], controller);
  const auto& m = summary["maneuvers"][0];
  EXPECT_LT(m["final_position_error_m"].get<double>(), 0.005) << controller;
  EXPECT_LT(m["residual_swing_rad"].get<double>(), 0.5 * M_PI / 180.0) << controller;
  EXPECT_FALSE(m["settle_time_s"].is_null()) << controller << " never settled";
  EXPECT_EQ(summary["loop"]["overruns"].get<int>(), 0);
}

INSTANTIATE_TEST_SUITE_P(Controllers, StackController,
                         ::testing::Values("pd", "delay2", "fuzzy", "gain_scheduling_partial"));

// crane_sim (every stage object in one thread, no DDS) gives the DDS lockstep demo's run to the last
// bit for every controller of crane_demo (docs/architecture.md, "The in-process runner"): the
// combined maneuver (trolley and slew), friction compensation on; the Lockstep test above compares
// the default controller on two maneuvers with compensation on and off.
class SimMatchesDemo : public ::testing::TestWithParam<const char*> {};

TEST_P(SimMatchesDemo, CraneSimGivesTheLockstepDemoToTheBit) {
  const std::string controller = GetParam();
  const std::vector<std::string> options{"--maneuver", "combined", "--friction-compensation", "on", "--controller",
                                         controller};
  const auto summary = run_demo("sim_vs_demo_" + controller, 31, options);
  ASSERT_FALSE(summary.is_null());
  ASSERT_EQ(summary["maneuvers"].size(), 1U);  // a comparison of no file would pass
  EXPECT_TRUE(summary["loop"]["failures"].empty()) << summary["loop"]["failures"];
  const fs::path demo_out = fs::temp_directory_path() / ("crane_test_sim_vs_demo_" + controller + "_" + std::to_string(getpid()));
  expect_sim_equals_demo(summary, demo_out, run_sim("sim_" + controller, options));
}

INSTANTIATE_TEST_SUITE_P(Controllers, SimMatchesDemo,
                         ::testing::Values("none", "pd", "delay2", "fuzzy", "gain_scheduling_partial",
                                           "gain_scheduling_full", "auto", "follower"));

// The gantry crane's demo over DDS (`deploy/crane demo --config deploy/config/gantry_crane.yaml`,
// docs/cranes.md) is crane_sim's to the last bit: its four runs (both maneuvers, compensation on
// and off). The overhead crane's diagonal is not compared to the bit here: one DDS run of it (under
// a load average of about 24) left crane_sim's record at t = 12.54 s by 5e-8 m of cable length,
// with no sample lost, and ended 0.26 mm and one encoder count of swing apart (docs/cranes.md); the
// cause is not found. Its DDS run is checked against the hardware bridge's in
// Stack.OverheadDiagonalThroughTheHardwareBridgeMatchesThePlantOnDds.
TEST(SimMatchesDemo, GantryDemoOverDdsIsCraneSimToTheBit) {
  const std::vector<std::string> gantry{"--friction-compensation", "both"};
  const auto g = run_demo("sim_vs_demo_gantry", 32, gantry, kGantryConfig);
  ASSERT_FALSE(g.is_null());
  ASSERT_EQ(g["maneuvers"].size(), 4U);
  EXPECT_TRUE(g["loop"]["failures"].empty()) << g["loop"]["failures"];
  expect_sim_equals_demo(g, fs::temp_directory_path() / ("crane_test_sim_vs_demo_gantry_" + std::to_string(getpid())),
                         run_sim("sim_gantry", gantry, kGantryConfig));
}

// The comparison's random moves run over DDS too (crane_demo --moves, as crane_sim compare's): random
// move 12 of seed 1 on the lab tower crane ends 0.21 m from the slew axis, so it is planned robustly
// to the pendulum's length (trajectory_planner.robust_within_radius) and held with the slew's
// sideways weight; over DDS it gives crane_sim's CSV to the last bit and settles within 1.2 T*.
TEST(SimMatchesDemo, ARandomMoveNearTheMastOverDdsIsCraneSimToTheBit) {
  const std::vector<std::string> options{"--moves", "20", "--seed", "1", "--maneuver", "random_12",
                                         "--friction-compensation", "on", "--controller", "follower"};
  const auto summary = run_demo("sim_vs_demo_random", 38, options);
  ASSERT_FALSE(summary.is_null());
  ASSERT_EQ(summary["maneuvers"].size(), 1U);
  EXPECT_TRUE(summary["loop"]["failures"].empty()) << summary["loop"]["failures"];
  const auto& m = summary["maneuvers"][0];
  EXPECT_EQ(m["name"], "random_12");
  ASSERT_TRUE(m["settle_time_s"].is_number()) << m.dump();
  ASSERT_TRUE(m["minimum_time_s"].is_number()) << m.dump();
  EXPECT_LE(m["settle_time_s"].get<double>(), 1.2 * m["minimum_time_s"].get<double>()) << m.dump();
  EXPECT_EQ(m["braked_cycles"], 0);
  expect_sim_equals_demo(summary, fs::temp_directory_path() / ("crane_test_sim_vs_demo_random_" + std::to_string(getpid())),
                         run_sim("sim_random", options));
}

// A mismatch corner over DDS: the plant process's cable 20 % longer, its load 20 % heavier and its
// friction 30 % higher than every controller assumes (crane_demo --plant-*-factor), random move 17
// of seed 1, the slowest corner of crane_sim compare's sweep (2.32 T*). Over DDS it settles, no
// brake, and gives crane_sim demo --mismatch 1.2 1.2 1.3's CSV to the last bit.
TEST(SimMatchesDemo, AMismatchCornerOverDdsIsCraneSimToTheBit) {
  const std::vector<std::string> options{"--moves", "20", "--seed", "1", "--maneuver", "random_17",
                                         "--friction-compensation", "on", "--controller", "follower"};
  std::vector<std::string> dds = options;
  dds.insert(dds.end(), {"--plant-cable-length-factor", "1.2", "--plant-load-mass-factor", "1.2",
                         "--plant-friction-factor", "1.3"});
  std::vector<std::string> sim = options;
  sim.insert(sim.end(), {"--mismatch", "1.2", "1.2", "1.3"});
  const auto summary = run_demo("sim_vs_demo_corner", 39, dds);
  ASSERT_FALSE(summary.is_null());
  ASSERT_EQ(summary["maneuvers"].size(), 1U);
  EXPECT_TRUE(summary["loop"]["failures"].empty()) << summary["loop"]["failures"];
  EXPECT_EQ(summary["plant_friction_factor"], 1.3);
  const auto& m = summary["maneuvers"][0];
  EXPECT_TRUE(m["settle_time_s"].is_number()) << m.dump();
  EXPECT_EQ(m["braked_cycles"], 0);
  expect_sim_equals_demo(summary, fs::temp_directory_path() / ("crane_test_sim_vs_demo_corner_" + std::to_string(getpid())),
                         run_sim("sim_corner", sim));
}

// Starts crane_launch (`config`, simulated plant, lockstep, DDS domain `domain`, its log in `dir`)
// in `launcher`; true once every stage is matched and alive (within 60 s).
bool launch_stack(ProcessGroup& launcher, const fs::path& dir, const std::string& config, const std::string& domain) {
  launcher.start({"crane_launch", kBin + "/crane_launch",
                  {"--config", config, "--sim", "--lockstep", "--domain", domain, "--log-dir", (dir / "logs").string()},
                  (dir / "launch.log").string()});
  const auto deadline = Clock::now() + std::chrono::seconds(60);
  while (Clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (file_bytes(dir / "launch.log").find("all stages matched and alive") != std::string::npos) return true;
  }
  return false;
}

// Runs an operator tool (crane_move, crane_safety, crane_jog) on DDS domain `domain`: stdout to
// `out`, stderr to `out`.err; its exit code.
int run_operator_tool(const std::string& domain, const std::string& tool, const std::string& arguments,
                      const fs::path& out) {
  const std::string command =
      kBin + "/" + tool + " --domain " + domain + " " + arguments + " > " + out.string() + " 2> " + out.string() + ".err";
  return WEXITSTATUS(std::system(command.c_str()));
}

// Operating the crane (issue 14, goals with feedback): a stack run by crane_launch (lockstep, so the
// move takes a second or two of wall time), and `crane_move ... --wait --json` from another process,
// as an operator's second shell: the move arrives, the load settles within the demo's criteria,
// and a goal beyond the travel range is refused (exit 2) naming the bound; then a no-go zone, the
// operating modes, a scripted stick and a stop, each from its own command, as an operator would.
TEST(Operate, MoveArrivesSettledAndAGoalOutOfRangeIsRefusedNamingTheBound) {
  const fs::path dir = fresh_directory("operate");
  const std::string domain = "33";
  ProcessGroup launcher;
  ASSERT_TRUE(launch_stack(launcher, dir, kConfig, domain)) << "crane_launch not ready; see " << dir;
  const auto run_move = [&](const std::string& arguments, const fs::path& out) {
    return run_operator_tool(domain, "crane_move", arguments, out);
  };
  ASSERT_EQ(run_move("--trolley 0.8 --slew 45 --hoist 1.2 --wait --json", dir / "move.json"), 0)
      << file_bytes(dir / "move.json.err");
  const auto result = nlohmann::json::parse(file_bytes(dir / "move.json"));
  std::printf("[ figure   ] crane_move --trolley 0.8 --slew 45 --hoist 1.2 --wait --json: %s\n", result.dump().c_str());
  EXPECT_EQ(result["result"], "arrived");
  ASSERT_FALSE(result["settle_time_s"].is_null()) << "never settled";
  EXPECT_LT(result["final_position_error_m"].get<double>(), 0.005);
  EXPECT_LT(result["final_slew_error_rad"].get<double>(), 0.005);
  EXPECT_LT(result["residual_swing_rad"].get<double>(), 0.5 * M_PI / 180.0);
  EXPECT_NEAR(result["final_cable_length_m"].get<double>(), 1.2, 0.01);

  EXPECT_EQ(run_move("--trolley 1.5 --json", dir / "refused.json"), 2);
  const auto refused = nlohmann::json::parse(file_bytes(dir / "refused.json"));
  EXPECT_EQ(refused["result"], "rejected");
  EXPECT_EQ(refused["reason"], "trolley_range");
  const std::string message = refused["message"];
  EXPECT_NE(message.find("1.5 m is outside the travel range [0.2, 1.1] m"), std::string::npos) << message;

  // No-go zones over DDS: the lab's "control desk" (zone 0, off in the configuration) switched on;
  // a slew at 0.9 m whose straight path crosses it (at a cable of 1.5 m the load hangs 1.0 m above
  // the ground, below the desk's top of 1.2 m) arrives around it: the supervisor checks the
  // measured load every cycle and would have stopped the crane (fault zone) had it entered.
  const auto run_tool = [&](const std::string& tool, const std::string& arguments, const fs::path& out) {
    return run_operator_tool(domain, tool, arguments, out);
  };
  ASSERT_EQ(run_move("--trolley 0.9 --slew 0 --hoist 1.5 --profile zv --wait --json", dir / "to_start.json"), 0)
      << file_bytes(dir / "to_start.json.err");
  ASSERT_EQ(run_tool("crane_safety", "zone enable 0", dir / "zone.txt"), 0) << file_bytes(dir / "zone.txt.err");
  EXPECT_NE(file_bytes(dir / "zone.txt").find("zones enforced 0"), std::string::npos) << file_bytes(dir / "zone.txt");
  ASSERT_EQ(run_move("--trolley 0.9 --slew 90 --hoist 1.5 --profile zv --wait --json", dir / "around.json"), 0)
      << file_bytes(dir / "around.json.err") << file_bytes(dir / "around.json");
  const auto around = nlohmann::json::parse(file_bytes(dir / "around.json"));
  std::printf("[ figure   ] around the control desk: %s\n", around.dump().c_str());
  EXPECT_EQ(around["result"], "arrived");
  ASSERT_EQ(run_tool("crane_safety", "status --json", dir / "status.json"), 0);
  const auto status = nlohmann::json::parse(file_bytes(dir / "status.json"));
  EXPECT_EQ(status["latched_faults"].size(), 0U) << status.dump();
  // A goal inside the zone: refused, naming it.
  EXPECT_EQ(run_move("--trolley 0.9 --slew 40 --hoist 1.5 --json --config " + kConfig, dir / "in_zone.json"), 2);
  const auto in_zone = nlohmann::json::parse(file_bytes(dir / "in_zone.json"));
  EXPECT_EQ(in_zone["reason"], "zone");
  EXPECT_NE(in_zone["message"].get<std::string>().find("no-go zone 0 (control desk)"), std::string::npos) << in_zone.dump();

  // Manual mode: a goal is refused naming the mode; a scripted stick moves the trolley in; a stop
  // brings it to rest where the planner said it would.
  ASSERT_EQ(run_tool("crane_safety", "mode manual", dir / "mode.txt"), 0) << file_bytes(dir / "mode.txt.err");
  EXPECT_EQ(run_move("--trolley 0.5 --json", dir / "in_manual.json"), 2);
  const auto in_manual = nlohmann::json::parse(file_bytes(dir / "in_manual.json"));
  EXPECT_EQ(in_manual["reason"], "mode");
  EXPECT_NE(in_manual["message"].get<std::string>().find("operating mode manual"), std::string::npos) << in_manual.dump();
  {
    std::ofstream script(dir / "stick.csv");
    script << "t,trolley,slew,hoist\n0,-0.5,0,0\n1.0,0,0,0\n";
  }
  // The desk off again (the stick's way in passes within the margin of its corner), and 500
  // samples a second: the lockstep stack runs about 10x faster than the wall clock, and the
  // planner's dead man counts its own cycles (200 ms of the crane's time).
  ASSERT_EQ(run_tool("crane_safety", "zone disable 0", dir / "zone_off.txt"), 0);
  ASSERT_EQ(run_tool("crane_jog", "--rate 500 --script " + (dir / "stick.csv").string(), dir / "jog.txt"), 0)
      << file_bytes(dir / "jog.txt.err");
  ASSERT_EQ(run_tool("crane_move", "--stop --json", dir / "stop.json"), 0) << file_bytes(dir / "stop.json.err");
  const auto stop = nlohmann::json::parse(file_bytes(dir / "stop.json"));
  std::printf("[ figure   ] after a 1 s stick at half speed inward: %s\n", stop.dump().c_str());
  EXPECT_EQ(stop["result"], "at_rest");
  EXPECT_LT(stop["rest_trolley_m"].get<double>(), 0.85) << "the stick moved the trolley in";
  ASSERT_EQ(run_tool("crane_safety", "mode fullautomatic", dir / "mode2.txt"), 0);
  launcher.stop_all();
}

// A device unplugged mid-jog stops the load softly (issue 14, manual mode), over DDS with real
// processes: a realtime stack (the planner's dead man counts its cycles, 10 ms of the wall clock
// each), MANUAL from crane_safety, `crane_jog --script` (50 Hz) pushing the trolley out at 30 %,
// killed with SIGKILL 3 s into the motion, at the shaped speed's steady value (1 run in 6 here was
// killed mid-ramp, at 0.112 m/s, when the kill came 3 s after the first speed whatever it was; the
// cause was not reproduced: a stall of the jog's stream is one candidate). The planner hears
// nothing for manual.dead_man_timeout (200 ms) and releases the axes: its reference starts to
// decelerate (the shaped ramp) between 200 ms less the jog's 20 ms period and 200 ms plus three
// cycles (the dead man's "longer than": the 21st cycle; the wait for the planner's next cycle;
// DDS) after the kill. The reference comes to rest, the load with it: its swing 2-6 s after rest
// < 0.5 deg (the sensors' encoder), and the supervisor raised no fault.
TEST(Operate, AJogKilledMidMoveStopsTheLoadSoftlyWithinTheDeadManTime) {
  const fs::path dir = fresh_directory("jog_killed");
  fs::create_directories(dir / "logs");
  const unsigned domain = 35;
  crane::launch::StackOptions options;
  options.config_path = kConfig;
  options.binary_directory = kBin;
  options.log_directory = (dir / "logs").string();
  options.domain_id = domain;
  options.lockstep = false;  // the wall clock: the dead man's 200 ms are real time
  ProcessGroup stack;
  for (const auto& spec : crane::launch::stack_processes(options)) stack.start(spec);

  crane::transport::ParticipantOptions p;
  p.name = "jog_test";
  p.domain_id = domain;
  crane::transport::Participant participant(p);
  crane::transport::Wakeup wakeup;
  auto status_reader = participant.make_recording_reader<tp::SafetyStatus>(&wakeup, 4096);
  auto reference_reader = participant.make_recording_reader<tp::Reference>(&wakeup, 4096);
  auto sensors_reader = participant.make_recording_reader<tp::Sensors>(&wakeup, 4096);
  // Ready: every stage alive, the brakes released and nothing latched, for 1 s. A fault latched
  // while the stack starts (stage_silent: a loaded machine started a stage late) is reset, as an
  // operator would, and printed; the faults from the jog on are the test's.
  tp::msgs::SupervisorStatus_ status;
  bool ready = false;
  Clock::time_point ready_since = Clock::now();
  int resets = 0;
  const auto ready_deadline = Clock::now() + std::chrono::seconds(30);
  while (!(ready && Clock::now() > ready_since + std::chrono::seconds(1)) && Clock::now() < ready_deadline) {
    ASSERT_FALSE(stack.poll().has_value()) << "a stage died during start-up; see " << dir;
    wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
    if (!status_reader->take_latest(status)) continue;
    const bool now_ready =
        status.stages_alive() == Status::STAGES_ALL && status.brakes_released() && status.latched_faults() == 0;
    if (now_ready && !ready) ready_since = Clock::now();
    ready = now_ready;
    if (status.latched_faults() != 0 && status.active_faults() == 0 && resets < 3) {
      std::printf("[ note     ] start-up fault (latched bits %u) reset\n", status.latched_faults());
      ++resets;
      EXPECT_EQ(run_operator_tool(std::to_string(domain), "crane_safety", "reset", dir / "reset.txt"), 0);
    }
  }
  ASSERT_TRUE(ready) << "stack not ready (stages, brakes, no fault) within 30 s; see " << dir;
  ASSERT_EQ(run_operator_tool(std::to_string(domain), "crane_safety", "mode manual", dir / "mode.txt"), 0)
      << file_bytes(dir / "mode.txt.err");
  {
    std::ofstream script(dir / "stick.csv");
    script << "t,trolley,slew,hoist\n0,0,0,0\n0.2,0.3,0,0\n30,0,0,0\n";
  }
  tp::msgs::Reference_ reference;
  tp::msgs::SensorSample_ sample;
  reference_reader->take_latest(reference);  // the samples from before the jog
  sensors_reader->take_latest(sample);
  ProcessGroup jog;
  const pid_t jog_pid = jog.start({"crane_jog", kBin + "/crane_jog",
                                   {"--domain", std::to_string(domain), "--script", (dir / "stick.csv").string()},
                                   (dir / "jog.log").string()});

  using crane::runtime::to_nanoseconds;
  std::optional<std::int64_t> moving, killed, released, at_rest;  // [ns] CLOCK_REALTIME, the headers' clock
  double speed_at_kill = 0.0, position_at_kill = 0.0, rest_position = 0.0, residual = 0.0;
  std::uint32_t faults = 0;
  std::uint64_t swing_samples = 0;
  int early_releases = 0;
  bool decelerating = false;
  const auto deadline = Clock::now() + std::chrono::seconds(40);
  while (Clock::now() < deadline) {
    wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
    while (status_reader->take_next(status)) faults |= status.latched_faults() | status.active_faults();
    while (reference_reader->take_next(reference)) {
      const std::int64_t stamp = to_nanoseconds(reference.header().stamp());
      if (!moving && reference.trolley_velocity() > 0.0) moving = stamp;
      // A release before the kill: the jog's stream stalled longer than the dead man's time (a
      // starved machine: the jog runs at normal priority, the stages do not); counted, and the kill
      // waits for the steady speed again, so the release measured is the kill's.
      if (moving && !killed && reference.trolley_acceleration() < 0.0 && !decelerating) ++early_releases;
      decelerating = reference.trolley_acceleration() < 0.0;
      if (moving && !killed && stamp >= *moving + 3'000'000'000LL && reference.trolley_acceleration() == 0.0 &&
          std::abs(reference.trolley_velocity() - 0.3 * 0.4982) < 1e-6) {
        // 3 s into the motion, at the steady speed: the jog "unplugged", its pid (this test started it).
        ASSERT_EQ(::kill(jog_pid, SIGKILL), 0);
        killed = crane::runtime::now_nanoseconds();
        speed_at_kill = reference.trolley_velocity();
        position_at_kill = reference.trolley_position();
      }
      // Released: the reference decelerates (its first shaped step down from the steady speed).
      if (killed && !released && reference.trolley_acceleration() < 0.0) released = stamp;
      if (released && !at_rest && reference.trolley_velocity() == 0.0 &&
          reference.phase() != crane::protocol::Reference::PHASE_MOVING) {
        at_rest = stamp;
        rest_position = reference.trolley_position();
      }
    }
    while (sensors_reader->take_next(sample)) {
      const std::int64_t t = to_nanoseconds(sample.header().origin());
      if (at_rest && t >= *at_rest + 2'000'000'000LL && t < *at_rest + 6'000'000'000LL) {
        residual = std::max({residual, std::abs(sample.swing_in_plane()), std::abs(sample.swing_out_of_plane())});
        ++swing_samples;
      }
    }
    if (at_rest && swing_samples > 0 && crane::runtime::now_nanoseconds() > *at_rest + 6'500'000'000LL) break;
  }
  ASSERT_TRUE(moving.has_value()) << "the jog never moved the trolley; see " << dir;
  // The kill waits for the steady shaped speed (0.3 of the rated 0.4982 m/s): that it came is the check.
  ASSERT_TRUE(killed.has_value()) << "the reference never held the stick's 0.149 m/s 3 s into the motion; see " << dir;
  const auto jog_exit = jog.poll();
  ASSERT_TRUE(jog_exit.has_value());
  EXPECT_TRUE(WIFSIGNALED(jog_exit->status) && WTERMSIG(jog_exit->status) == SIGKILL) << jog_exit->describe();
  ASSERT_TRUE(released.has_value()) << "the planner never released the axes; see " << dir;
  ASSERT_TRUE(at_rest.has_value()) << "the reference never came to rest; see " << dir;
  const double release_ms = static_cast<double>(*released - *killed) * 1e-6;
  const double rest_s = static_cast<double>(*at_rest - *killed) * 1e-9;
  std::printf("[ figure   ] crane_jog killed (SIGKILL) at trolley %.3f m, %.3f m/s: the reference decelerates %.1f ms "
              "after the kill (dead man 200 ms), at rest %.2f s after the kill at %.3f m, residual swing %.3f deg 2-6 s "
              "after rest (%llu samples), supervisor faults %u; releases before the kill (the jog's stream stalled) %d\n",
              position_at_kill, speed_at_kill, release_ms, rest_s, rest_position, residual * 180.0 / M_PI,
              static_cast<unsigned long long>(swing_samples), faults, early_releases);
  EXPECT_GE(release_ms, 200.0 - 20.0) << "released before the dead man's time: by something else";
  EXPECT_LE(release_ms, 200.0 + 3 * 10.0);
  EXPECT_GT(swing_samples, 300U);
  EXPECT_LT(residual * 180.0 / M_PI, 0.5);
  EXPECT_EQ(faults, 0U) << "supervisor fault; see " << dir;
  for (const auto& e : stack.stop_all()) EXPECT_TRUE(WIFEXITED(e.status) && WEXITSTATUS(e.status) == 0) << e.describe();
  status_reader.reset();
  reference_reader.reset();
  sensors_reader.reset();
}

// `deploy/crane launch --config` for the other two cranes (docs/cranes.md): the overhead crane's stack
// live (lockstep), a diagonal goal (bridge and trolley together, hoisting) from `crane_move --wait
// --json` arrives settled within the demo's criteria on both axes and in both swing planes, and a
// bridge goal off the runway is refused (exit 2) naming the planner's bridge range; the gantry's
// stack takes a trolley goal with hoisting and settles it.
TEST(Operate, OverheadAndGantryCranesLaunchedTakeGoalsAndRefuseOnesOffTheRunway) {
  const fs::path dir = fresh_directory("operate_overhead");
  const std::string domain = "34";
  {
    ProcessGroup launcher;
    ASSERT_TRUE(launch_stack(launcher, dir, kOverheadConfig, domain)) << "crane_launch not ready; see " << dir;
    ASSERT_EQ(run_operator_tool(domain, "crane_move", "--bridge 30 --trolley 12 --hoist 5 --wait --json",
                                dir / "diagonal.json"),
              0)
        << file_bytes(dir / "diagonal.json.err") << file_bytes(dir / "diagonal.json");
    const auto moved = nlohmann::json::parse(file_bytes(dir / "diagonal.json"));
    std::printf("[ figure   ] overhead crane_move --bridge 30 --trolley 12 --hoist 5 --wait --json: %s\n",
                moved.dump().c_str());
    EXPECT_EQ(moved["result"], "arrived");
    ASSERT_FALSE(moved["settle_time_s"].is_null()) << "never settled";
    EXPECT_LT(moved["final_position_error_m"].get<double>(), 0.005);
    EXPECT_LT(moved["final_bridge_error_m"].get<double>(), 0.005);
    EXPECT_LT(moved["residual_swing_rad"].get<double>(), 0.5 * M_PI / 180.0);  // both planes
    EXPECT_NEAR(moved["final_cable_length_m"].get<double>(), 5.0, 0.01);

    EXPECT_EQ(run_operator_tool(domain, "crane_move", "--bridge 58 --json", dir / "off_runway.json"), 2)
        << file_bytes(dir / "off_runway.json.err");
    const auto refused = nlohmann::json::parse(file_bytes(dir / "off_runway.json"));
    EXPECT_EQ(refused["result"], "rejected");
    EXPECT_EQ(refused["reason"], "bridge_range");
    const std::string message = refused["message"];
    EXPECT_NE(message.find("bridge target 58 m is outside the runway travel [3, 57] m"), std::string::npos) << message;
    launcher.stop_all();
  }

  const fs::path gantry_dir = fresh_directory("operate_gantry");
  ProcessGroup launcher;
  ASSERT_TRUE(launch_stack(launcher, gantry_dir, kGantryConfig, domain)) << "crane_launch not ready; see " << gantry_dir;
  ASSERT_EQ(run_operator_tool(domain, "crane_move", "--trolley 1.0 --hoist 1.5 --wait --json", gantry_dir / "move.json"),
            0)
      << file_bytes(gantry_dir / "move.json.err") << file_bytes(gantry_dir / "move.json");
  const auto moved = nlohmann::json::parse(file_bytes(gantry_dir / "move.json"));
  std::printf("[ figure   ] gantry crane_move --trolley 1.0 --hoist 1.5 --wait --json: %s\n", moved.dump().c_str());
  EXPECT_EQ(moved["result"], "arrived");
  ASSERT_FALSE(moved["settle_time_s"].is_null()) << "never settled";
  EXPECT_LT(moved["final_position_error_m"].get<double>(), 0.005);
  EXPECT_LT(moved["residual_swing_rad"].get<double>(), 0.5 * M_PI / 180.0);
  EXPECT_NEAR(moved["final_cable_length_m"].get<double>(), 1.5, 0.01);
  EXPECT_EQ(run_operator_tool(domain, "crane_move", "--bridge 1 --json", gantry_dir / "no_bridge.json"), 2);
  const auto no_bridge = nlohmann::json::parse(file_bytes(gantry_dir / "no_bridge.json"));
  EXPECT_NE(no_bridge["message"].get<std::string>().find("this crane has no bridge"), std::string::npos)
      << no_bridge.dump();
  launcher.stop_all();
}

// NaN and Inf injected on the bus by a rogue participant are rejected where they enter, counted,
// and never reach a drive: the voltages the plant applies stay finite and in range.
TEST(Stack, NonFiniteSamplesAreRejectedAndNeverReachADrive) {
  const fs::path logs = fresh_directory("nonfinite");
  crane::launch::StackOptions options;
  options.config_path = kConfig;
  options.binary_directory = kBin;
  options.log_directory = logs.string();
  options.domain_id = 12;
  options.lockstep = false;  // realtime: the rogue samples interleave with the real ones
  ProcessGroup group;
  std::map<int, std::string> stage_of_pid;
  for (const auto& spec : crane::launch::stack_processes(options)) stage_of_pid[group.start(spec)] = spec.name;

  crane::transport::ParticipantOptions p;
  p.name = "rogue";
  p.domain_id = 12;
  crane::transport::Participant participant(p);
  crane::transport::Wakeup wakeup;
  auto status_reader = participant.make_reader<tp::SafetyStatus>(&wakeup);
  auto sensors_reader = participant.make_recording_reader<tp::Sensors>(&wakeup, 4096);
  auto diagnostics_reader = participant.make_recording_reader<tp::LoopDiagnostics>(&wakeup, 256);

  // Wait until the chain is up.
  tp::msgs::SupervisorStatus_ status;
  const auto ready_deadline = Clock::now() + std::chrono::seconds(30);
  while (status.stages_alive() != Status::STAGES_ALL && Clock::now() < ready_deadline) {
    ASSERT_FALSE(group.poll().has_value()) << "a stage died during start-up; see " << logs;
    status_reader->take_latest(status);
    wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
  }
  ASSERT_EQ(status.stages_alive(), Status::STAGES_ALL) << "stack not ready; see " << logs;

  // Rogue writers on every topic a stage reads. (A second sensor writer is also a supervisor fault
  // of its own.)
  auto actuators = participant.make_writer<tp::Actuators>();
  auto linear = participant.make_writer<tp::LinearCommand>();
  auto estimate = participant.make_writer<tp::StateEstimate>();
  auto goal = participant.make_writer<tp::Goal>();
  auto sensors = participant.make_writer<tp::Sensors>();
  auto reference = participant.make_writer<tp::Reference>();
  auto anti_swing = participant.make_writer<tp::AntiSwing>();
  auto safety = participant.make_writer<tp::SafetyStatus>();
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // discovery of the new writers
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int i = 0; i < 50; ++i) {
    tp::msgs::ActuatorCommand_ a;
    a.header().seq(status.header().seq() + static_cast<std::uint64_t>(i));
    a.trolley_voltage(i % 2 ? nan : inf);
    actuators->write(a);
    tp::msgs::LinearCommand_ l;
    l.header().seq(status.header().seq() + static_cast<std::uint64_t>(i));
    l.slew_voltage(nan);
    linear->write(l);
    tp::msgs::CraneState_ e;
    e.header().seq(status.header().seq() + static_cast<std::uint64_t>(i));
    e.swing_in_plane(nan);
    estimate->write(e);
    tp::msgs::MoveRequest_ g;
    g.request_id(1000 + static_cast<std::uint32_t>(i));
    g.trolley_target(nan);
    goal->write(g);
    tp::msgs::SensorSample_ bad_sensor;
    bad_sensor.header().seq(status.header().seq() + static_cast<std::uint64_t>(i));
    bad_sensor.trolley_position(i % 2 ? nan : -inf);
    sensors->write(bad_sensor);
    tp::msgs::Reference_ r;
    r.header().seq(status.header().seq() + static_cast<std::uint64_t>(i));
    r.trolley_velocity(nan);
    reference->write(r);
    tp::msgs::AntiSwingCommand_ as;
    as.header().seq(status.header().seq() + static_cast<std::uint64_t>(i));
    as.trolley_action(inf);
    anti_swing->write(as);
    tp::msgs::SupervisorStatus_ st;
    st.brakes_released(true);
    st.motion_enabled(true);
    st.trolley_voltage_limit(nan);
    safety->write(st);
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // at least one diagnostics period

  // Every applied voltage the plant reported stayed finite and within the DAC range.
  tp::msgs::SensorSample_ s;
  int samples = 0;
  while (sensors_reader->take_next(s)) {
    ++samples;
    ASSERT_TRUE(std::isfinite(s.applied_trolley_voltage()) && std::isfinite(s.applied_slew_voltage()));
    ASSERT_LE(std::fabs(s.applied_trolley_voltage()), 10.0);
    ASSERT_LE(std::fabs(s.applied_slew_voltage()), 10.0);
  }
  EXPECT_GT(samples, 100);

  std::map<std::string, std::uint64_t> rejected;
  tp::msgs::LoopDiagnostics_ d;
  while (diagnostics_reader->take_next(d)) {
    const auto found = stage_of_pid.find(static_cast<int>(d.pid()));
    if (found != stage_of_pid.end()) rejected[found->second] = d.nonfinite_rejected();
  }
  // Where each rogue stream enters: sensors -> estimator (and supervisor); actuators -> plant; safety
  // status -> plant, planner, anti-swing; linear -> friction compensation; estimate -> planner, anti-swing, tracking, friction
  // compensation; goal -> planner; reference, anti-swing action -> tracking; all but the goal and
  // the status -> supervisor.
  for (const auto* stage : {"state_estimator", "plant", "friction_compensation", "trajectory_planner", "anti_swing",
                            "tracking", "supervisor"}) {
    EXPECT_GT(rejected[stage], 0U) << stage << " did not count the non-finite samples it received";
  }
  // The supervisor saw the NaN and latched the fault: brakes stay engaged until a reset.
  status_reader->take_latest(status);
  EXPECT_NE(status.latched_faults() & Status::FAULT_NON_FINITE, 0U);
  EXPECT_FALSE(status.brakes_released());
  for (const auto& e : group.stop_all()) {
    EXPECT_TRUE(WIFEXITED(e.status) && WEXITSTATUS(e.status) == 0) << e.describe();
  }
  // Readers first: Fast DDS 2.9 delivers samples between a writer and a reader of the same process
  // by reference into the writer's payload pool, so a reader that outlives such a writer crashes
  // when it frees its cache (seen here on the safety-status reader).
  status_reader.reset();
  sensors_reader.reset();
  diagnostics_reader.reset();
}

}  // namespace
