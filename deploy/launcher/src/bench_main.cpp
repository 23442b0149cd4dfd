// crane_bench latency: end-to-end and per-hop latency of the running stack, the jitter of the
// sensor stream, and a raw DDS ping-pong of the same message size as the floor, measured in the
// same run.
//
//   crane_bench latency --config FILE [--rate HZ] [--duration S] [--json]
//
// The stack (plant on DDS, realtime) is started at `--rate` (the config's sample period replaced by
// 1/rate), every stage its own process. Per hop: the `stamp` each stage writes into its output
// header minus the stamp of its input, for the same cycle (all on this machine, one clock).
// End-to-end: the plant's own measurement, sensor sample time to command arrival. Floor: this
// process and a child (crane_bench pong) bounce an ActuatorCommand_ (the chain's message size) over
// the same transport and QoS; one-way = round trip / 2. Between two processes, as between two
// stages: within one process Cyclone DDS delivers locally, without the network. Vendors: --dds
// for every process, --dds-mix per process; the floor's ping side uses the plant's vendor and its
// echo side the other vendor when the stack mixes them, so a mixed stack is measured against a
// cross-vendor floor. Run it inside a private network namespace (deploy/crane bench does).
#include <spdlog/spdlog.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>
#include <type_traits>
#include <vector>

#include "crane/launch/iceoryx.hpp"
#include "crane/launch/process_group.hpp"
#include "crane/launch/stack.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {

using namespace crane;
namespace fs = std::filesystem;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
using Status = protocol::SupervisorStatus;  // its codes: MODE_*, STAGES_ALL, WARNING_*
using nlohmann::json;

double ns(const builtin_interfaces::msg::dds_::Time_& t) { return static_cast<double>(runtime::to_nanoseconds(t)); }

json summary(std::vector<double> us) {
  if (us.empty()) return json{{"samples", 0}};
  std::sort(us.begin(), us.end());
  auto at = [&](double p) { return us[static_cast<std::size_t>(std::lround(p / 100.0 * static_cast<double>(us.size() - 1)))]; };
  return json{{"samples", us.size()}, {"p50_us", at(50)}, {"p99_us", at(99)}, {"max_us", us.back()}};
}

/// The echo side of the floor (crane_bench pong, a process of its own like every stage): answers
/// each ActuatorCommand_ with a LinearCommand_ carrying its header, until SIGINT/SIGTERM.
int pong(std::uint32_t domain, transport::Vendor vendor) {
  transport::ParticipantOptions options;
  options.name = "bench_pong";
  options.domain_id = domain;
  options.vendor = vendor;
  transport::Participant participant(options);
  transport::Wakeup wake;
  runtime::install_stop_handlers(&wake);
  auto reader = participant.make_reader<tp::Actuators>(&wake);
  auto writer = participant.make_writer<tp::LinearCommand>();
  tp::msgs::ActuatorCommand_ in;
  tp::msgs::LinearCommand_ out;
  while (!runtime::stop_requested()) {
    while (reader->take_next(in)) {
      out.header(in.header());
      writer->write(out);
    }
    wake.wait_until(Clock::now() + std::chrono::milliseconds(50));
  }
  return 0;
}

/// One-way latency [us] of a raw DDS ping-pong on the actuator topic's QoS between this process
/// (ping, `ping_vendor`) and a child process (crane_bench pong, `echo_vendor`), as between two
/// stages; `count` round trips, in a domain of their own. Ping on the actuator topic, pong on the
/// linear-command topic (same stream QoS, 8 bytes less).
std::vector<double> ping_pong(std::uint32_t domain, int count, const std::string& ping_vendor,
                              const std::string& echo_vendor, const std::string& log_path) {
  launch::ProcessGroup echo_process;
  echo_process.start({"bench_pong", launch::executable_directory() + "/crane_bench",
                      {"pong", "--domain", std::to_string(domain), "--dds", echo_vendor}, log_path});
  transport::ParticipantOptions options;
  options.name = "bench_ping";
  options.domain_id = domain;
  options.vendor = transport::parse_vendor(ping_vendor);
  transport::Participant participant(options);
  transport::Wakeup wake;
  auto writer = participant.make_writer<tp::Actuators>();
  auto reader = participant.make_reader<tp::LinearCommand>(&wake);
  const auto matched = Clock::now() + std::chrono::seconds(10);
  while ((writer->health().matched_readers == 0 || reader->health().matched_writers == 0) && Clock::now() < matched) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  std::vector<double> one_way;
  tp::msgs::ActuatorCommand_ ping;
  tp::msgs::LinearCommand_ answer;
  for (int i = 0; i < count && !runtime::stop_requested(); ++i) {
    runtime::stamp_header(ping.header(), static_cast<std::uint64_t>(i), runtime::now_stamp());
    const auto sent = Clock::now();
    writer->write(ping);
    const auto deadline = sent + std::chrono::milliseconds(100);
    bool got = false;
    while (!got && Clock::now() < deadline) {
      while (reader->take_next(answer)) got = got || answer.header().seq() == static_cast<std::uint64_t>(i);
      if (!got) wake.wait_until(deadline);
    }
    if (got) one_way.push_back(std::chrono::duration<double, std::micro>(Clock::now() - sent).count() / 2.0);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  return one_way;  // echo_process stops its child (SIGTERM, then SIGKILL) when it goes
}


/// Resident set size [kB] of process `pid` (VmRSS of /proc/PID/status); -1 when it is gone.
long resident_kb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmRSS:", 0) == 0) return std::stol(line.substr(6));
  }
  return -1;
}

/// Resident memory of one process over a soak [kB]: at readiness, after the first minute (the
/// reference: DDS discovery, history buffers and the allocator's pools have settled by then), the
/// largest seen after that minute, and at the end.
struct MemoryTrace {
  long at_start{-1};
  long after_first_minute{-1};
  long max_after_first_minute{-1};
  long at_end{-1};
};

// crane_bench soak: the live stack (realtime clock, real-time priority where the system allows it,
// as crane_launch) at rest for `rest_s`, then moves between two positions (`moves` of them, or until
// `duration_s` has passed since readiness when it is > 0), optionally with stress-ng loading both
// cores at normal priority (below the stages' SCHED_FIFO). Prints faults, moments the stack was not
// ready, late-stage warnings, every process's overruns (its rt/crane/diag/loop counters), the
// end-to-end latency, and every process's resident memory at start, after the first minute and at the
// end. Exit 0 when no fault, no overrun, every move arrived and (runs of 2 minutes or more) no
// process grew by more than `memory_bound_kb` after the first minute.
int soak(const std::string& config_path, unsigned domain, double rest_s, int moves, double duration_s, bool stress,
         int priority, const std::string& dds, long memory_bound_kb) {
  const fs::path dir = fs::temp_directory_path() / ("crane_soak_" + std::to_string(getpid()));
  fs::create_directories(dir);
  launch::StackOptions stack;
  stack.config_path = fs::absolute(config_path).string();
  stack.binary_directory = launch::executable_directory();
  stack.log_directory = dir.string();
  stack.domain_id = domain;
  stack.lockstep = false;
  stack.dds = dds;
  stack.plant_stats_path = (dir / "plant_stats.json").string();
  stack.fault_log_path = (dir / "faults.jsonl").string();
  const std::string rt_failure = priority > 0 ? launch::probe_realtime(priority + 10) : "not asked";
  if (rt_failure.empty()) stack.realtime_priority = priority;
  const std::string move_plan =
      duration_s > 0.0 ? "moves until " + std::to_string(static_cast<long>(duration_s)) + " s" : std::to_string(moves) + " moves";
  std::printf("soak: realtime clock, %s, rest %.0f s, %s, %s\n",
              rt_failure.empty() ? ("SCHED_FIFO " + std::to_string(priority) + "+").c_str()
                                 : ("normal priority (" + rt_failure + ")").c_str(),
              rest_s, move_plan.c_str(), stress ? "stress-ng --cpu 2 at normal priority" : "no load");
  launch::ProcessGroup group;
  std::map<std::string, pid_t> pids;
  for (const auto& spec : launch::stack_processes(stack)) pids[spec.name] = group.start(spec);
  launch::ProcessGroup load;
  runtime::NodeOptions node;
  node.dds = dds;
  node.domain_id = domain;
  auto participant = runtime::make_participant(node, "bench");
  transport::Wakeup wakeup;
  runtime::install_stop_handlers(&wakeup);
  auto status_reader = participant->make_reader<tp::SafetyStatus>(&wakeup);
  auto references = participant->make_reader<tp::Reference>(&wakeup);
  auto goal_writer = participant->make_writer<tp::Goal>();
  auto diagnostics = participant->make_recording_reader<tp::LoopDiagnostics>(&wakeup, 64);
  std::map<std::uint32_t, tp::msgs::LoopDiagnostics_> last_diagnostics;  // by writer pid
  tp::msgs::SupervisorStatus_ status;
  tp::msgs::Reference_ reference;
  const auto ready_deadline = Clock::now() + std::chrono::seconds(60);
  while (!(status.stages_alive() == Status::STAGES_ALL && status.mode() == Status::MODE_READY &&
           goal_writer->health().matched_readers > 0)) {
    if (Clock::now() > ready_deadline || runtime::stop_requested()) {
      std::fprintf(stderr, "crane_bench soak: the stack did not become ready; see %s\n", dir.string().c_str());
      return 1;
    }
    if (auto exit = group.poll()) {
      std::fprintf(stderr, "crane_bench soak: %s; see %s\n", exit->describe().c_str(), dir.string().c_str());
      return 1;
    }
    status_reader->take_latest(status);
    wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
  }
  if (stress) load.start({"stress-ng", "/usr/bin/stress-ng", {"--cpu", "2", "--quiet"}, (dir / "stress.log").string()});
  const auto started = Clock::now();
  std::map<std::string, MemoryTrace> memory;
  for (const auto& [name, pid] : pids) memory[name].at_start = resident_kb(pid);
  auto next_memory_sample = started + std::chrono::seconds(60);
  bool first_minute_taken = false;
  auto sample_memory = [&] {
    if (Clock::now() < next_memory_sample) return;
    for (const auto& [name, pid] : pids) {
      auto& m = memory[name];
      const long kb = resident_kb(pid);
      if (!first_minute_taken) m.after_first_minute = kb;
      m.max_after_first_minute = std::max(m.max_after_first_minute, kb);
    }
    first_minute_taken = true;
    next_memory_sample += std::chrono::seconds(10);
  };
  std::uint64_t statuses = 0, not_ready = 0, late = 0;
  std::uint32_t faults = 0;
  std::string died;
  auto watch = [&](double seconds, const std::function<bool()>& done) {
    const auto end = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(seconds));
    while (Clock::now() < end && !runtime::stop_requested() && died.empty()) {
      tp::msgs::LoopDiagnostics_ d;
      while (diagnostics->take_next(d)) last_diagnostics[d.pid()] = d;
      sample_memory();
      while (status_reader->take_next(status)) {
        ++statuses;
        if (status.mode() != Status::MODE_READY && status.mode() != Status::MODE_OPERATING) ++not_ready;
        if (status.warnings() & Status::WARNING_STAGE_LATE) ++late;
        faults = status.fault_count();
      }
      while (references->take_next(reference)) {
      }
      if (auto exit = group.poll()) died = exit->describe();
      if (done && done()) return true;
      wakeup.wait_until(std::min(end, Clock::now() + std::chrono::milliseconds(20)));
    }
    return false;
  };
  watch(rest_s, nullptr);
  int arrived = 0;
  int sent = 0;
  const auto soak_end = started + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(duration_s));
  auto more_moves = [&](int i) { return duration_s > 0.0 ? Clock::now() < soak_end : i < moves; };
  for (int i = 0; more_moves(i) && died.empty() && !runtime::stop_requested(); ++i) {
    ++sent;
    tp::msgs::MoveRequest_ goal;
    runtime::stamp_header(goal.header(), 0, runtime::now_stamp());
    const auto id = static_cast<std::uint32_t>(i + 1);
    goal.request_id(id);
    goal.profile(protocol::MoveRequest::PROFILE_TRAPEZOID);
    goal.axes(protocol::MoveRequest::AXIS_TROLLEY | protocol::MoveRequest::AXIS_SLEW);
    goal.trolley_target(i % 2 == 0 ? 0.9 : 0.4);
    goal.slew_target(i % 2 == 0 ? 0.5 : 0.0);
    goal.cable_length_target(1.0);
    bool seen = false;
    // Sent until the planner executes it (the goal topic is volatile), then until it reports arrival.
    const bool ok = watch(30.0, [&] {
      if (!seen) goal_writer->write(goal);
      seen = seen || reference.request_id() == id;
      return seen && reference.request_id() == id && reference.phase() == protocol::Reference::PHASE_ARRIVED;
    });
    if (ok) ++arrived;
    watch(5.0, nullptr);  // let the load settle before the next move
  }
  for (const auto& [name, pid] : pids) memory[name].at_end = resident_kb(pid);
  const double soaked_s = std::chrono::duration<double>(Clock::now() - started).count();
  load.stop_all();
  group.stop_all();
  json plant = json::parse(std::ifstream(stack.plant_stats_path), nullptr, false);
  const auto e2e = summary(plant.is_object() ? plant.value("latency_us", std::vector<double>{}) : std::vector<double>{});
  const int overruns = plant.is_object() ? plant.value("overruns", -1) : -1;
  std::printf("statuses %llu, not ready %llu, late-stage warnings %llu, faults raised %u, moves arrived %d of %d%s%s\n",
              static_cast<unsigned long long>(statuses), static_cast<unsigned long long>(not_ready),
              static_cast<unsigned long long>(late), faults, arrived, sent, died.empty() ? "" : ", died: ",
              died.c_str());
  // Every process's own counters (its last rt/crane/diag/loop sample), by pid.
  std::printf("%-22s %10s %9s %13s %13s %13s %13s %13s\n", "process", "cycles", "overruns", "latency_p99_us",
              "rss_start_kB", "rss_1min_kB", "rss_max_kB", "rss_end_kB");
  bool memory_flat = true;
  for (const auto& [name, pid] : pids) {
    const auto d = last_diagnostics.find(static_cast<std::uint32_t>(pid));
    const auto& m = memory[name];
    const bool have = d != last_diagnostics.end();
    std::printf("%-22s %10llu %9llu %13.0f %13ld %13ld %13ld %13ld\n", name.c_str(),
                have ? static_cast<unsigned long long>(d->second.cycles()) : 0ULL,
                have ? static_cast<unsigned long long>(d->second.overruns()) : 0ULL,
                have ? d->second.latency_p99_us() : 0.0, m.at_start, m.after_first_minute, m.max_after_first_minute,
                m.at_end);
    if (m.after_first_minute >= 0 && m.max_after_first_minute - m.after_first_minute > memory_bound_kb) {
      memory_flat = false;
    }
  }
  const bool judged = soaked_s >= 120.0;
  std::printf("memory after the first minute: %s (bound %ld kB, %.0f s soaked)\n",
              !judged ? "not judged (under 2 minutes)" : memory_flat ? "flat" : "GREW", memory_bound_kb, soaked_s);
  std::printf("plant: %d overruns, end to end p50 %.0f us, p99 %.0f us, max %.0f us (%d cycles); logs in %s\n", overruns,
              e2e.value("p50_us", 0.0), e2e.value("p99_us", 0.0), e2e.value("max_us", 0.0),
              e2e["samples"].get<int>(), dir.string().c_str());
  return faults == 0 && overruns == 0 && died.empty() && arrived == sent && (!judged || memory_flat) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_bench: latency of the stack and of raw DDS on this machine"};
  app.require_subcommand(1);
  auto* latency_cmd = app.add_subcommand("latency", "end-to-end and per-hop latency, sensor jitter, DDS floor");
  std::string config_path;
  double rate = 100.0;
  double duration = 10.0;
  bool as_json = false;
  unsigned domain = 30;
  latency_cmd->add_option("--config", config_path, "crane configuration (YAML)")->required()->check(CLI::ExistingFile);
  latency_cmd->add_option("--rate", rate, "[Hz] sample rate of the stack")->check(CLI::Range(10.0, 2000.0));
  latency_cmd->add_option("--duration", duration, "[s] measuring time")->check(CLI::Range(1.0, 3600.0));
  int latency_priority = 0;
  latency_cmd->add_option("--realtime-priority", latency_priority,
                          "the stages at SCHED_FIFO from this priority, as crane_launch (0: normal priority, the default)")
      ->check(CLI::Range(0, 89));
  latency_cmd->add_option("--domain", domain, "DDS domain (the floor uses domain + 1)")->check(CLI::Range(0, 231));
  latency_cmd->add_flag("--json", as_json, "one JSON object");
  bool lockstep = false;
  latency_cmd->add_flag("--lockstep", lockstep,
                        "plant in lockstep (as the demo): where a cycle's time goes when nothing waits on a clock, "
                        "and the speed in multiples of real time");
  bool sensors_only = false;
  latency_cmd->add_flag("--sensors-only", sensors_only,
                        "the bench reads the sensor clock alone (no per-hop readers, no hop or chain figures): the "
                        "stack's speed without the bench's readers on its chain");
  std::string wake;
  latency_cmd->add_option("--wake", wake,
                          "the chain's --wake (stages and plant): listener (their default: one thread wake-up per "
                          "hop) | thread (two)")
      ->check(CLI::IsMember({"listener", "thread"}));
  std::string dds = "fast";
  std::string dds_mix;
  latency_cmd->add_option("--dds", dds, "DDS vendor of every process: fast | cyclone")
      ->check(CLI::IsMember({"fast", "cyclone"}));
  bool iceoryx = false;
  latency_cmd->add_flag("--iceoryx", iceoryx,
                        "the stack's samples through iceoryx shared memory (Cyclone DDS, RouDi started first), the "
                        "bench's own readers too; the floor stays on UDP");
  latency_cmd->add_option("--dds-mix", dds_mix, "vendor per process, overriding --dds, e.g. "
                                                "plant=cyclone,state_estimator=cyclone (names: the stages, bench)");
  bool lan = false;
  std::string dds_profile;
  latency_cmd->add_flag("--lan", lan, "every process on all interfaces (monitors on other machines may join)");
  latency_cmd->add_option("--dds-profile", dds_profile, "network profile of every process (deploy/dds/*.xml)")
      ->check(CLI::ExistingFile);
  runtime::NodeOptions security;  // --security, --identity (of bench: default operator), --insecure-lan
  runtime::add_security_options(*latency_cmd, security);
  auto* soak_cmd = app.add_subcommand("soak", "the live stack (realtime) at rest, then moves, optionally under load: "
                                              "faults, readiness, overruns, end-to-end latency");
  double soak_rest = 600.0;
  int soak_moves = 20;
  bool soak_stress = false;
  int soak_priority = 70;
  soak_cmd->add_option("--config", config_path, "crane configuration (YAML)")->required()->check(CLI::ExistingFile);
  soak_cmd->add_option("--rest", soak_rest, "[s] at rest first")->check(CLI::Range(0.0, 86400.0));
  soak_cmd->add_option("--moves", soak_moves, "moves between two positions after the rest")->check(CLI::Range(0, 10000));
  double soak_duration = 0.0;
  soak_cmd->add_option("--duration", soak_duration,
                       "[s] the whole soak from readiness: after the rest, moves until then (overrides --moves)")
      ->check(CLI::Range(0.0, 7.0 * 86400.0));
  long soak_memory_bound_kb = 1024;
  soak_cmd->add_option("--memory-bound", soak_memory_bound_kb,
                       "[kB] largest growth of any process's resident memory after the first minute")
      ->check(CLI::Range(0L, 1L << 30));
  soak_cmd->add_flag("--stress", soak_stress, "stress-ng loads both cores at normal priority meanwhile");
  soak_cmd->add_option("--realtime-priority", soak_priority, "as crane_launch (0: normal priority)")
      ->check(CLI::Range(0, 89));
  soak_cmd->add_option("--domain", domain, "DDS domain")->check(CLI::Range(0, 232));
  soak_cmd->add_option("--dds", dds, "DDS vendor of every process")->check(CLI::IsMember({"fast", "cyclone"}));
  auto* pong_cmd = app.add_subcommand("pong", "(internal) the echo process of the DDS floor");
  pong_cmd->group("");  // not listed in --help
  std::string pong_dds = "fast";
  unsigned pong_domain = 31;
  pong_cmd->add_option("--dds", pong_dds, "DDS vendor")->check(CLI::IsMember({"fast", "cyclone"}));
  pong_cmd->add_option("--domain", pong_domain, "DDS domain")->check(CLI::Range(0, 232));
  CLI11_PARSE(app, argc, argv);
  if (pong_cmd->parsed()) {
    try {
      return pong(pong_domain, transport::parse_vendor(pong_dds));
    } catch (const std::exception& error) {
      std::fprintf(stderr, "crane_bench pong: %s\n", error.what());
      return 1;
    }
  }
  if (soak_cmd->parsed()) {
    try {
      runtime::configure_logging("warn", "bench");
      if (soak_duration > 0.0 && soak_duration <= soak_rest) {
        throw std::invalid_argument("--duration " + std::to_string(soak_duration) + " s must exceed --rest " +
                                    std::to_string(soak_rest) + " s");
      }
      return soak(config_path, domain, soak_rest, soak_moves, soak_duration, soak_stress, soak_priority, dds,
                  soak_memory_bound_kb);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "crane_bench soak: %s\n", error.what());
      return 1;
    }
  }
  // The run's folder (logs, the configuration at the rate), named before RouDi's fork (--iceoryx).
  const fs::path dir = fs::temp_directory_path() / ("crane_bench_" + std::to_string(getpid()));
  const auto latency_run = [&]() -> int {
    try {
      runtime::configure_logging("warn", "bench");
      // The configuration at the requested rate.
      std::ifstream in(config_path);
      std::stringstream text;
      text << in.rdbuf();
      std::string yaml = text.str();
      const std::string key = "sample_period:";
      const auto at = yaml.find(key);
      if (at == std::string::npos) throw std::invalid_argument(config_path + ": no plant.sample_period");
      const auto end = yaml.find_first_of("#\n", at);
      char period[64];
      std::snprintf(period, sizeof(period), " %.9g ", 1.0 / rate);
      yaml.replace(at + key.size(), end - at - key.size(), period);
      fs::create_directories(dir);
      const fs::path config = dir / "bench.yaml";
      std::ofstream(config) << yaml;

      launch::StackOptions stack;
      stack.config_path = config.string();
      stack.binary_directory = launch::executable_directory();
      stack.log_directory = dir.string();
      stack.domain_id = domain;
      stack.lockstep = lockstep;
    // In lockstep the stack as the demo runs it: no operator relay, whose readers of the status and
    // the estimate (woken every cycle) compete with the chain for the cores.
    stack.operator_relay = !lockstep;
      stack.wake = wake;
      stack.plant_stats_path = (dir / "plant_stats.json").string();
      if (latency_priority > 0) {
        const std::string rt_failure = launch::probe_realtime(latency_priority + 10);
        if (rt_failure.empty()) {
          stack.realtime_priority = latency_priority;
        } else {
          std::fprintf(stderr, "crane_bench latency: --realtime-priority %d: %s (the stack runs at normal priority)\n",
                       latency_priority, rt_failure.c_str());
        }
      }
      stack.lan = lan;
      stack.dds = dds;
      stack.iceoryx = iceoryx;
      stack.start_roudi = false;  // run_beside_roudi() below
      {
        auto known = launch::stack_process_names(stack);
        known.push_back("bench");
        stack.dds_per_process = launch::parse_dds_mix(dds_mix, known);
      }
      if (!dds_profile.empty()) stack.dds_profile = fs::absolute(dds_profile).string();
      if (!security.security_directory.empty()) {
        stack.security_directory = fs::absolute(security.security_directory).string();
      }
      stack.insecure_lan = security.insecure_lan;
      runtime::check_network_security(!lan, stack.dds_profile, stack.security_directory, stack.insecure_lan);
      launch::ProcessGroup group;
      for (const auto& spec : launch::stack_processes(stack)) group.start(spec);

      runtime::NodeOptions node;
      node.dds = launch::vendor_of(stack, "bench");
      node.domain_id = domain;
      node.loopback_only = !lan;
      node.dds_profile = stack.dds_profile;
      node.security_directory = stack.security_directory;
      node.identity = security.identity.empty() ? "operator" : security.identity;  // it writes the goals
      node.insecure_lan = stack.insecure_lan;
      node.iceoryx = iceoryx;  // every reader of the chain on shared memory, or each writer also sends UDP
      auto participant = runtime::make_participant(node, "bench");
      transport::Wakeup wakeup;
      runtime::install_stop_handlers(&wakeup);
      // Woken by every sample and drained at once. Polled every 20 ms instead (as crane_demo's
      // recorder), the bench's bursts of work held the chain: 2026-11-28, deploy/bench_shm.sh, on
      // iceoryx 36.1x with chain p99 823 us polled, 43.0x and 318 us woken, minutes apart.
      auto status_reader = participant->make_reader<tp::SafetyStatus>(&wakeup);
      auto sensors = participant->make_recording_reader<tp::Sensors>(&wakeup, 8192);
      // With --sensors-only the chain's topics have one reader fewer each: no delivery to the bench
      // on the chain's path (on iceoryx, each reader is one more wake-up per sample).
      const auto hop_reader = [&]<typename T>(std::type_identity<T>) {
        return sensors_only ? nullptr : participant->make_recording_reader<T>(&wakeup, 8192);
      };
      auto estimate = hop_reader(std::type_identity<tp::StateEstimate>{});
      auto reference = hop_reader(std::type_identity<tp::Reference>{});
      auto anti_swing = hop_reader(std::type_identity<tp::AntiSwing>{});
      auto linear = hop_reader(std::type_identity<tp::LinearCommand>{});
      auto actuators = hop_reader(std::type_identity<tp::Actuators>{});
      // seq -> write stamps [ns] per stage. Taken as they come, also before the recording: a reader on
      // iceoryx may hold only so many samples (TOO_MANY_CHUNKS_HELD_IN_PARALLEL).
      std::map<std::uint64_t, std::array<double, 6>> stamps;
      auto drain = [&] {
        auto take = [&](auto& reader, std::size_t index) {
          if (!reader) return;
          typename std::remove_reference_t<decltype(*reader)>::Message m;
          while (reader->take_next(m)) {
            auto& row = stamps.try_emplace(m.header().seq(), std::array<double, 6>{NAN, NAN, NAN, NAN, NAN, NAN}).first->second;
            if (std::isnan(row[index])) row[index] = ns(m.header().stamp());
          }
        };
        take(sensors, 0);
        take(estimate, 1);
        take(reference, 2);
        take(anti_swing, 3);
        take(linear, 4);
        take(actuators, 5);
      };
      tp::msgs::SupervisorStatus_ status;
      const auto ready_deadline = Clock::now() + std::chrono::seconds(30);
      while (status.stages_alive() != Status::STAGES_ALL && Clock::now() < ready_deadline) {
        status_reader->take_latest(status);
        drain();
        wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
      }
      if (status.stages_alive() != Status::STAGES_ALL) throw std::runtime_error("the stack did not become ready; see " + dir.string());
      for (const auto settled = Clock::now() + std::chrono::seconds(1); Clock::now() < settled;) {
        drain();
        wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
      }
      // Forget what came before; record `duration` seconds.
      drain();
      stamps.clear();
      const auto end_time = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(duration));
      while (Clock::now() < end_time && !runtime::stop_requested()) {
        drain();
        wakeup.wait_until(std::min(end_time, Clock::now() + std::chrono::milliseconds(20)));
      }
      drain();
      for (const auto& exit : group.stop_all()) {
        if (!(WIFEXITED(exit.status) && WEXITSTATUS(exit.status) == 0)) spdlog::warn("{}", exit.describe());
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));

      // Hops: sensors -> estimator -> planner (needs the estimate) -> anti-swing (estimate) ->
      // tracking (joins all three) -> friction compensation; the chain's own end.
      const char* hop_names[] = {"sensors->state_estimator", "state_estimator->trajectory_planner",
                                 "state_estimator->anti_swing", "inputs->tracking", "tracking->friction_compensation"};
      std::vector<double> hops[5], chain, sensor_stamps;
      for (const auto& [seq, r] : stamps) {
        if (std::isnan(r[0])) continue;
        sensor_stamps.push_back(r[0]);
        if (!std::isnan(r[1])) hops[0].push_back((r[1] - r[0]) / 1e3);
        if (!std::isnan(r[2]) && !std::isnan(r[1])) hops[1].push_back((r[2] - r[1]) / 1e3);
        if (!std::isnan(r[3]) && !std::isnan(r[1])) hops[2].push_back((r[3] - r[1]) / 1e3);
        if (!std::isnan(r[4]) && !std::isnan(r[1]) && !std::isnan(r[2]) && !std::isnan(r[3])) {
          hops[3].push_back((r[4] - std::max({r[1], r[2], r[3]})) / 1e3);
        }
        if (!std::isnan(r[5]) && !std::isnan(r[4])) hops[4].push_back((r[5] - r[4]) / 1e3);
        if (!std::isnan(r[5])) chain.push_back((r[5] - r[0]) / 1e3);
      }
      std::vector<double> periods;
      for (std::size_t i = 1; i < sensor_stamps.size(); ++i) periods.push_back((sensor_stamps[i] - sensor_stamps[i - 1]) / 1e3);
      std::vector<double> jitter;
      for (const double p : periods) jitter.push_back(std::fabs(p - 1e6 / rate));
      std::vector<double> end_to_end;
      json plant;
      {
        std::ifstream stats(stack.plant_stats_path);
        if (stats) plant = json::parse(stats, nullptr, false);
        if (plant.is_object()) end_to_end = plant.value("latency_us", std::vector<double>{});
      }
      // Floor between two processes: the plant's vendor pings; the echo takes the other vendor when
      // the stack mixes them (the cross-vendor hop is the floor of a mixed stack), else the same.
      const auto ping_vendor = launch::vendor_of(stack, "plant");
      auto echo_vendor = ping_vendor;
      for (const auto& name : launch::stack_process_names(stack)) {
        if (launch::vendor_of(stack, name) != ping_vendor) echo_vendor = launch::vendor_of(stack, name);
      }
      const auto floor = ping_pong(domain + 1, 1000, ping_vendor, echo_vendor, (dir / "bench_pong.log").string());

      json j;
      j["rate_hz"] = rate;
      j["duration_s"] = duration;
      j["dds"] = dds;
      j["dds_mix"] = stack.dds_per_process;
      j["iceoryx"] = iceoryx;
      j["floor_vendors"] = ping_vendor + "->" + echo_vendor;
      j["end_to_end"] = summary(end_to_end);  // plant: sensor sample -> command arrival (all cycles of the run)
      j["chain_sensors_to_actuators"] = summary(chain);
      for (int h = 0; h < 5; ++h) j["hops"][hop_names[h]] = summary(hops[h]);
      j["sensor_jitter"] = summary(jitter);
      j["floor_one_way"] = summary(floor);
      j["overruns"] = plant.is_object() ? plant.value("overruns", -1) : -1;
      j["clock"] = lockstep ? "lockstep" : "realtime";
      j["sensors_only"] = sensors_only;
      j["wake"] = wake.empty() ? "listener" : wake;
      if (plant.is_object() && plant.contains("step_us")) j["plant_step"] = plant["step_us"];
      if (lockstep && sensor_stamps.size() > 1) {
        // Cycles stepped per second of wall time while recording.
        const double wall = (sensor_stamps.back() - sensor_stamps.front()) / 1e9;
        j["real_time_factor"] = static_cast<double>(sensor_stamps.size() - 1) / rate / wall;
      }
      if (!floor.empty() && !end_to_end.empty()) {
        j["p99_ratio_to_floor"] = j["end_to_end"]["p99_us"].get<double>() / j["floor_one_way"]["p99_us"].get<double>();
      }
      if (as_json) {
        std::printf("%s\n", j.dump(2).c_str());
      } else {
        auto line = [](const char* name, const json& s) {
          if (s["samples"].get<int>() == 0) {
            std::printf("%-38s no samples\n", name);
            return;
          }
          std::printf("%-38s p50 %8.1f us  p99 %8.1f us  max %9.1f us  (%d)\n", name, s["p50_us"].get<double>(),
                      s["p99_us"].get<double>(), s["max_us"].get<double>(), s["samples"].get<int>());
        };
        std::string vendors = dds + (iceoryx ? " on iceoryx" : "");
        for (const auto& [name, vendor] : stack.dds_per_process) vendors += ", " + name + "=" + vendor;
        std::printf("dds %s, %.0f Hz, %.0f s, %d overruns%s\n", vendors.c_str(), rate, duration, j["overruns"].get<int>(),
                    sensors_only ? " (the bench reads the sensors alone)" : "");
        line("end to end (sample -> command at plant)", j["end_to_end"]);
        line("chain (sensor stamp -> actuator stamp)", j["chain_sensors_to_actuators"]);
        for (int h = 0; h < 5; ++h) line(hop_names[h], j["hops"][hop_names[h]]);
        line("sensor period jitter", j["sensor_jitter"]);
        line("floor: DDS one-way (ping-pong / 2)", j["floor_one_way"]);
        if (j.contains("p99_ratio_to_floor")) std::printf("end-to-end p99 / floor p99 = %.2f\n", j["p99_ratio_to_floor"].get<double>());
        if (j.contains("plant_step")) {
          std::printf("%-38s p50 %8.1f us  p99 %8.1f us  max %9.1f us\n", "plant step (integrator, one cycle)",
                      j["plant_step"]["p50"].get<double>(), j["plant_step"]["p99"].get<double>(),
                      j["plant_step"]["max"].get<double>());
        }
        if (j.contains("real_time_factor")) {
          std::printf("lockstep speed: %.1f x real time\n", j["real_time_factor"].get<double>());
        }
      }
      fs::remove_all(dir);
      return 0;
    } catch (const std::exception& error) {
      std::fprintf(stderr, "crane_bench: %s\n", error.what());
      return 1;
    }
  };
  if (!iceoryx) return latency_run();
  try {
    fs::create_directories(dir);
    return launch::run_beside_roudi((dir / "iox_roudi.log").string(), latency_run);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_bench: %s\n", error.what());
    return 1;
  }
}
