// crane_demo: the main job. For each maneuver of section 3.3.3 (and each friction-compensation
// setting) it launches the whole simulated stack as separate processes, waits until every stage is
// matched and the supervisor is ready, sends the move over DDS, records every cycle, stops the
// stack, and reports the figures of merit (table, summary.json, CSV, plots).
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <thread>

#include "crane/launch/iceoryx.hpp"
#include "crane/launch/process_group.hpp"
#include "crane/launch/stack.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/stack/controller_comparison.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

constexpr double kPi = 3.14159265358979323846;
// The start cycle of the readiness probe (crane_demo's first request of a run): never reached.
constexpr std::uint64_t kNeverCycle = std::numeric_limits<std::uint64_t>::max();

struct DemoOptions {
  std::string config_path;
  std::string out_dir{"demo-out"};
  std::string dds{"fast"};
  std::string dds_mix;                                 // --dds-mix text
  std::map<std::string, std::string> dds_per_process;  // parsed from dds_mix (stages and "operator")
  std::vector<std::string> maneuvers;
  int moves{0};             // --moves: seeded random moves besides the demo maneuvers (crane_sim compare's)
  std::uint64_t seed{1};    // --seed
  std::string compensation{"both"};
  bool realtime{false};
  bool acceleration_feedforward{false};  // tracking --acceleration-feedforward
  std::string hardware;  // empty: plant on DDS; "shm": hardware_bridge + emulated board + plant behind it
  unsigned domain_id{0};
  std::string plot_script;
  std::string python{"/usr/bin/python3"};
  double ready_timeout{60.0};
  std::string profile{"trapezoid"};
  std::uint8_t profile_code{protocol::MoveRequest::PROFILE_TRAPEZOID};
  std::string controller;             // --controller, see main(); "auto" picks per maneuver (time_optimal)
  double plant_cable_length_factor{1.0};
  double plant_load_mass_factor{1.0};
  double plant_friction_factor{1.0};
  std::string security_directory;  // --security: every process and the operator secured (DDS Security)
  bool iceoryx{false};             // --iceoryx: every process and the operator on iceoryx shared memory
};

struct ProcessRecord {
  std::string name;
  pid_t pid;
  std::string dds;
  std::string run;
};

struct RunResult {
  std::string maneuver;
  std::string controller;        // anti-swing or gain-scheduling law of this run
  bool friction_compensation{true};
  stack::ManeuverMetrics metrics;
  double swing_period{0.0};      // [s] T = 2 pi sqrt(L/g)
  std::size_t samples{0};        // cycles recorded and evaluated
  std::size_t missing{0};        // cycles of the move missing from the recording
  std::size_t braked_cycles{0};  // cycles of the move during which the plant had its brakes on
  std::string csv;
  std::uint64_t cycles{0};
  std::uint64_t overruns{0};             // cycles of the 100 Hz chain (plant and data-driven stages)
  std::uint64_t supervisor_timer_overruns{0};  // the supervisor's own 100 Hz timer woke a period late
  std::uint64_t nonfinite_rejected{0};
  std::vector<double> latencies_us;
  std::vector<ProcessRecord> processes;
  bool diagnostics_complete{false};
  std::vector<std::string> diagnostics_missing;  // stages whose final loop diagnostics never arrived
  unsigned domain_id{0};         // this run's DDS domain (a fresh one per run)
  std::uint64_t move_start_cycle{0};  // lockstep: the cycle the move was asked to start at (0: realtime)
  double startup_s{0.0};         // [s] wall time from the first process started to the stack ready
  double wall_time_s{0.0};       // [s] wall time of the stepping loop: from ready to the last recorded cycle
  double simulated_time_s{0.0};  // [s] simulated time over the same cycles
  std::vector<std::string> failures;  // stages that died (or did not stop cleanly), and why: the run failed
};

// Everything the operator records in one run, keyed by cycle.
struct Recording {
  std::map<std::uint64_t, tp::msgs::SensorSample_> sensors;
  std::map<std::uint64_t, tp::msgs::Reference_> references;
  std::map<std::uint64_t, tp::msgs::LinearCommand_> linear;
  std::map<std::uint64_t, tp::msgs::ActuatorCommand_> actuators;
};

class Operator {
 public:
  explicit Operator(transport::Participant& participant)
      : participant_(participant), goal_(participant.make_writer<tp::Goal>()) {
    make_readers();
  }

  transport::Wakeup& wakeup() { return wakeup_; }

  /// On iceoryx (Cyclone DDS 0.10.2), a reader keeps each sample that reaches it before its
  /// participant has discovered the sample's writer: the chunk is never released
  /// (cyclonedds#1409, fixed upstream after 0.10.2), and after 256 such samples the reader takes
  /// nothing more ("TOO_MANY_CHUNKS_HELD_IN_PARALLEL"). In lockstep the stack runs thousands of
  /// cycles a second before a move, so a writer this process discovers late leaves its reader
  /// deaf for the run (seen once, in a full test run on a loaded VM: the actuators, "actuators 0").
  /// Once every reader has matched a writer, the readers are made again: the new ones start with
  /// those writers known (the diagnostics' several writers may still be discovered later; each
  /// writes once a second of wall time). Returns whether that happened (once per run; before the
  /// move, whose samples are the recording).
  bool renew_readers_once_matched() {
    if (renewed_) return false;
    const std::int32_t matched[] = {status_->health().matched_writers,     sensors_->health().matched_writers,
                                    references_->health().matched_writers, linear_->health().matched_writers,
                                    actuators_->health().matched_writers,  diagnostics_->health().matched_writers,
                                    move_status_->health().matched_writers};
    if (std::any_of(std::begin(matched), std::end(matched), [](std::int32_t n) { return n < 1; })) return false;
    make_readers();
    renewed_ = true;
    return true;
  }

  void drain_all() {
    tp::msgs::SupervisorStatus_ s;
    status_->take_latest(s);
    tp::msgs::SensorSample_ a;
    sensors_->take_latest(a);
    tp::msgs::Reference_ b;
    references_->take_latest(b);
    tp::msgs::LinearCommand_ c;
    linear_->take_latest(c);
    tp::msgs::ActuatorCommand_ d;
    actuators_->take_latest(d);
    tp::msgs::LoopDiagnostics_ e;
    diagnostics_->take_latest(e);
    tp::msgs::MoveStatus_ f;
    while (move_status_->take_next(f)) {
    }
  }

  std::optional<tp::msgs::SupervisorStatus_> latest_status() {
    tp::msgs::SupervisorStatus_ s;
    if (status_->take_latest(s)) last_status_ = s;
    return last_status_;
  }
  void forget_status() { last_status_.reset(); }

  void record(Recording& r) {
    tp::msgs::SensorSample_ a;
    while (sensors_->take_next(a)) r.sensors[a.header().seq()] = a;
    tp::msgs::Reference_ b;
    while (references_->take_next(b)) r.references[b.header().seq()] = b;
    tp::msgs::LinearCommand_ c;
    while (linear_->take_next(c)) r.linear[c.header().seq()] = c;
    tp::msgs::ActuatorCommand_ d;
    while (actuators_->take_next(d)) r.actuators[d.header().seq()] = d;
  }

  void collect_diagnostics(std::map<std::uint32_t, tp::msgs::LoopDiagnostics_>& by_pid) {
    tp::msgs::LoopDiagnostics_ d;
    while (diagnostics_->take_next(d)) by_pid[d.pid()] = d;
  }

  int goal_matches() const { return goal_->health().matched_readers; }
  /// Whether the planner has reported request `request_id` waiting for its start cycle (its reader
  /// has matched this process's goal writer: discovery is not symmetric, and between vendors the
  /// reader's side was seen to lag the writer's by more than a second).
  bool planner_waits_for(std::uint32_t request_id) {
    tp::msgs::MoveStatus_ f;
    while (move_status_->take_next(f)) {
      if (f.request_id() == request_id && f.result() == protocol::MoveStatus::RESULT_WAITING) probe_seen_ = request_id;
    }
    return probe_seen_ == request_id;
  }
  bool send_goal(const tp::msgs::MoveRequest_& goal) { return goal_->write(goal); }

 private:
  transport::Wakeup wakeup_;
  // The recorders do not wake this process on every sample (four wake-ups a cycle would take
  // the cores from the chain in lockstep): it polls them every 20 ms, 8192 samples deep.
  void make_readers() {
    status_.reset();
    status_ = participant_.make_reader<tp::SafetyStatus>(&wakeup_);
    sensors_ = participant_.make_recording_reader<tp::Sensors>(nullptr, 8192);
    references_ = participant_.make_recording_reader<tp::Reference>(nullptr, 8192);
    linear_ = participant_.make_recording_reader<tp::LinearCommand>(nullptr, 8192);
    actuators_ = participant_.make_recording_reader<tp::Actuators>(nullptr, 8192);
    diagnostics_ = participant_.make_recording_reader<tp::LoopDiagnostics>(nullptr, 256);
    move_status_ = participant_.make_recording_reader<tp::MoveStatus>(nullptr, 64);
  }

  transport::Participant& participant_;
  bool renewed_{false};
  std::unique_ptr<transport::Reader<tp::SafetyStatus>> status_;
  std::unique_ptr<transport::Reader<tp::Sensors>> sensors_;
  std::unique_ptr<transport::Reader<tp::Reference>> references_;
  std::unique_ptr<transport::Reader<tp::LinearCommand>> linear_;
  std::unique_ptr<transport::Reader<tp::Actuators>> actuators_;
  std::unique_ptr<transport::Reader<tp::LoopDiagnostics>> diagnostics_;
  std::unique_ptr<transport::Reader<tp::MoveStatus>> move_status_;
  std::unique_ptr<transport::Writer<tp::Goal>> goal_;
  std::optional<tp::msgs::SupervisorStatus_> last_status_;
  std::uint32_t probe_seen_{0};
};

class RunFailure : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

void check_children(launch::ProcessGroup& group) {
  if (auto exit = group.poll()) throw RunFailure("stage died: " + exit->describe());
  if (runtime::stop_requested()) throw RunFailure("interrupted");
}

using stack::format_number;


RunResult run_maneuver(const DemoOptions& options, const stack::StackConfig& cfg, const stack::ManeuverConfig& m,
                       bool compensation, Operator& op, std::uint32_t request_id, unsigned domain_id) {
  const std::string run_name = m.name + (compensation ? "_fc_on" : "_fc_off");
  const fs::path out(options.out_dir);
  const fs::path log_dir = out / "logs" / run_name;
  fs::create_directories(log_dir);

  launch::StackOptions stack;
  stack.config_path = fs::absolute(options.config_path).string();
  stack.binary_directory = launch::executable_directory();
  stack.log_directory = log_dir.string();
  stack.dds = options.dds;
  stack.dds_per_process = options.dds_per_process;
  stack.security_directory = options.security_directory;
  stack.iceoryx = options.iceoryx;
  stack.start_roudi = false;  // run_beside_roudi() in main()
  stack.domain_id = domain_id;
  stack.lockstep = !options.realtime;
  stack.initial_trolley_position = m.initial_trolley_position;
  stack.initial_slew_angle = m.initial_slew_angle;
  stack.initial_bridge_position = m.initial_bridge_position;
  stack.friction_compensation = compensation;
  stack.plant_stats_path = (log_dir / "plant_stats.json").string();
  stack.plant_cable_length_factor = options.plant_cable_length_factor;
  stack.plant_load_mass_factor = options.plant_load_mass_factor;
  stack.plant_friction_factor = options.plant_friction_factor;
  // What the controller name stands for (one place for crane_demo and crane_sim).
  const auto choice = stack::choose_controller(options.controller, m, options.acceleration_feedforward);
  stack.anti_swing_controller = std::string(anti_swing::law_name(choice.anti_swing));
  stack.tracking_controller = std::string(tracking::law_name(choice.tracking));
  stack.estimator_follower_filter = choice.follower_filter();
  stack.tracking_acceleration_feedforward = choice.acceleration_feedforward;
  stack.fault_log_path = (log_dir / "faults.jsonl").string();
  // The demo is its own operator (op), in a private network namespace no shell reaches: no relay.
  stack.operator_relay = false;
  // Realtime runs as crane_launch does: the stages on SCHED_FIFO where the system allows it.
  if (options.realtime && launch::probe_realtime(80).empty()) stack.realtime_priority = 70;
  // One emulated board per run, named after this process so parallel demos do not share one.
  if (options.hardware == "shm") stack.hardware = "shm:demo_" + std::to_string(getpid());

  RunResult result;
  result.maneuver = m.name;
  result.controller = choice.label;
  result.friction_compensation = compensation;
  result.domain_id = domain_id;
  result.swing_period = stack::swing_period(m, cfg.facts);

  launch::ProcessGroup group;
  op.drain_all();
  op.forget_status();
  const auto run_start = Clock::now();
  for (const auto& spec : launch::stack_processes(stack)) {
    const pid_t pid = group.start(spec);
    result.processes.push_back(ProcessRecord{spec.name, pid, launch::vendor_of(stack, spec.name), run_name});
  }

  // 1. Wait until every stage is matched and alive, the supervisor is ready, this operator itself
  //    receives every stream it records from this run's processes (its own discovery of a fresh
  //    stack can lag the stages' discovery of each other by up to an announcement period, which in
  //    lockstep is hundreds of cycles), and the planner has this operator's goals: a probe request
  //    whose start cycle never comes is reported waiting. Our writer matching the planner's reader
  //    does not prove it: with the planner on Cyclone and this process on Fast DDS the reader's
  //    side was seen to lag by 570 and 720 cycles, and the move then started late (issue: CI of
  //    stop 22). The move request replaces the probe before anything moves.
  const std::uint32_t probe_id = request_id;
  const std::uint32_t move_id = request_id + 1;
  tp::msgs::MoveRequest_ probe;
  // A trapezoid whatever the run's profile: a minimum-time probe would have the planner solve a bound
  // for a move that never starts.
  protocol::to_dds(stack::move_request(m, cfg.facts, probe_id, protocol::MoveRequest::PROFILE_TRAPEZOID, kNeverCycle),
                   probe);
  auto next_probe = Clock::now();
  const auto plant_pid = result.processes.back().pid;  // the sensor writer (plant or bridge) starts last
  Recording rec;
  const auto ready_deadline = Clock::now() + std::chrono::duration<double>(options.ready_timeout);
  while (true) {
    check_children(group);
    if (options.iceoryx) {
      op.record(rec);  // what the old readers hold, before they go
      if (op.renew_readers_once_matched()) spdlog::info("{}: readers made again, every writer known", run_name);
    }
    const auto status = op.latest_status();
    op.record(rec);
    // The plant itself reports brakes released: the supervisor's "ready" has reached it.
    const bool recording = !rec.sensors.empty() &&
                           rec.sensors.rbegin()->second.writer_pid() == static_cast<std::uint32_t>(plant_pid) &&
                           !rec.sensors.rbegin()->second.brakes_engaged() && !rec.references.empty() &&
                           !rec.linear.empty() && !rec.actuators.empty();
    const bool stack_ready = status && status->stages_alive() == protocol::SupervisorStatus::STAGES_ALL &&
                             status->mode() == protocol::SupervisorStatus::MODE_READY && op.goal_matches() > 0 &&
                             recording;
    if (stack_ready && op.planner_waits_for(probe_id)) break;
    if (stack_ready && Clock::now() >= next_probe) {
      probe.header().stamp(runtime::now_stamp());
      op.send_goal(probe);
      next_probe = Clock::now() + std::chrono::milliseconds(100);
    }

    if (Clock::now() > ready_deadline) {
      throw RunFailure(
          run_name + ": the stack did not become ready within " + format_number(options.ready_timeout, 0) +
          " s (stages alive " + (status ? std::to_string(status->stages_alive()) : "none") + " of 63, supervisor mode " +
          (status ? std::to_string(status->mode()) : "none") + ", planner matched to our goal writer " +
          std::to_string(op.goal_matches()) + ", recorded sensors " + std::to_string(rec.sensors.size()) +
          (rec.sensors.empty() ? std::string()
                               : std::string(" (last from pid ") + std::to_string(rec.sensors.rbegin()->second.writer_pid()) +
                                     ", brakes " + (rec.sensors.rbegin()->second.brakes_engaged() ? "on" : "off") + ")") +
          ", references " + std::to_string(rec.references.size()) + ", linear " + std::to_string(rec.linear.size()) +
          ", actuators " + std::to_string(rec.actuators.size()) + ", planner reported our probe request waiting " +
          (op.planner_waits_for(probe_id) ? "yes" : "no") + "; see " + log_dir.string() + ")");
    }
    op.wakeup().wait_until(Clock::now() + std::chrono::milliseconds(20));
  }

  const auto ready_time = Clock::now();
  const std::uint64_t ready_seq = std::max(rec.sensors.rbegin()->first, op.latest_status()->header().seq());
  result.startup_s = std::chrono::duration<double>(ready_time - run_start).count();

  // 2. Send the move. In lockstep it starts at a fixed cycle, not at the wall-clock moment the goal
  //    arrives: the crane rests before it, but the estimator's filters and the integrator's step size at
  //    rest differ in the last bits from one cycle to the next, so only the same start cycle gives
  //    the same run to the last bit. The stack is ready after a few cycles; should it be later, the
  //    start moves (and the run is repeatable only with runs that moved it alike). A goal that
  //    arrives after its start cycle starts at once: the run is then failed. The recording so far
  //    is kept: the first cycle of the move may be in it.
  constexpr std::uint64_t kStartAhead = 100;  // [cycles] at least, for the goal's delivery
  const std::uint64_t start_at = options.realtime ? 0 : std::max(stack::kMoveStartCycle, ready_seq + kStartAhead);
  result.move_start_cycle = start_at;
  tp::msgs::MoveRequest_ goal;
  protocol::to_dds(stack::move_request(m, cfg.facts, move_id, options.profile_code, start_at), goal);
  goal.header().stamp(runtime::now_stamp());
  if (!op.send_goal(goal)) throw RunFailure(run_name + ": the move request could not be written");
  spdlog::info("{}: stack ready, move {} sent", run_name, move_id);
  auto next_resend = Clock::now() + std::chrono::milliseconds(100);

  // 3. Record until `duration` seconds of cycles after the move started.
  const double dt = cfg.facts.sample_period;
  const auto cycles_needed = static_cast<std::uint64_t>(std::llround(m.duration / dt));
  std::optional<std::uint64_t> start_seq;
  std::optional<Clock::time_point> tail_deadline;
  const double wall_budget = options.realtime ? m.duration * 1.5 + 20.0 : m.duration * 20.0 + 60.0;
  const auto record_deadline = Clock::now() + std::chrono::duration<double>(wall_budget);
  while (true) {
    check_children(group);
    op.record(rec);
    if (!start_seq && Clock::now() > next_resend) {
      // Discovery is not symmetric: the planner may not have matched us when the request went out.
      op.send_goal(goal);
      next_resend = Clock::now() + std::chrono::milliseconds(100);
    }
    if (!start_seq) {
      for (const auto& [seq, r] : rec.references) {
        if (r.request_id() == move_id && r.phase() != protocol::Reference::PHASE_HOLDING) {
          start_seq = seq;
          break;
        }
      }
    }
    if (start_seq && !rec.sensors.empty() && rec.sensors.rbegin()->first >= *start_seq + cycles_needed + 1) {
      // Every topic's last cycle too: they reach this process by other paths than the sensors (seen:
      // the linear command of the last cycle arrived after its successor's sensor sample, 1 run in 46).
      const std::uint64_t last = *start_seq + cycles_needed;
      const bool complete =
          rec.references.count(last) != 0 && rec.linear.count(last) != 0 && rec.actuators.count(last) != 0;
      if (complete) break;
      if (!tail_deadline) tail_deadline = Clock::now() + std::chrono::seconds(2);
      if (Clock::now() > *tail_deadline) break;  // what is missing is counted below
    }
    if (Clock::now() > record_deadline) {
      throw RunFailure(run_name + ": recording did not complete within " + format_number(wall_budget, 0) + " s");
    }
    op.wakeup().wait_until(Clock::now() + std::chrono::milliseconds(20));
  }

  if (start_at != 0 && *start_seq != start_at) {
    result.failures.push_back("the move started at cycle " + std::to_string(*start_seq) + " instead of " +
                              std::to_string(start_at) + " (the goal arrived late): not repeatable to the bit");
    spdlog::error("{}: {}", run_name, result.failures.back());
  }
  result.wall_time_s = std::chrono::duration<double>(Clock::now() - ready_time).count();
  result.simulated_time_s = static_cast<double>(rec.sensors.rbegin()->first - ready_seq) * cfg.facts.sample_period;

  // 4. Stop the stack; every stage publishes its final loop diagnostics on the way out. A stage that
  //    does not stop cleanly (it aborted, or had to be killed) fails the run.
  for (const auto& exit : group.stop_all()) {
    const bool clean = WIFEXITED(exit.status) && WEXITSTATUS(exit.status) == 0;
    if (!clean) {
      spdlog::error("{}: {}", run_name, exit.describe());
      result.failures.push_back(exit.describe());
    }
  }
  std::map<std::uint32_t, tp::msgs::LoopDiagnostics_> diagnostics;
  const auto diag_deadline = Clock::now() + std::chrono::milliseconds(500);
  while (Clock::now() < diag_deadline) {
    op.collect_diagnostics(diagnostics);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  std::size_t reported = 0;
  for (const auto& p : result.processes) {
    const auto found = diagnostics.find(static_cast<std::uint32_t>(p.pid));
    if (found == diagnostics.end()) {
      result.diagnostics_missing.push_back(p.name);
      continue;
    }
    ++reported;
    // The supervisor runs on its own wall-clock timer, outside the data-driven chain.
    (p.name == "supervisor" ? result.supervisor_timer_overruns : result.overruns) += found->second.overruns();
    result.nonfinite_rejected += found->second.nonfinite_rejected();
    if (p.name == (stack.hardware.empty() ? "plant" : "hardware_bridge")) result.cycles = found->second.cycles();
  }
  result.diagnostics_complete = reported == result.processes.size();
  {
    std::ifstream stats(stack.plant_stats_path);
    if (stats) {
      const json j = json::parse(stats, nullptr, false);
      if (!j.is_discarded()) {
        result.cycles = j.value("cycles", result.cycles);
        result.latencies_us = j.value("latency_us", std::vector<double>{});
      }
    }
  }

  // 5. Assemble the cycles of the move and evaluate them (the CSV and the figures: stack::record_of,
  //    one place with crane_sim).
  std::vector<stack::CycleRecord> records;
  const fs::path csv_path = out / (run_name + ".csv");
  for (std::uint64_t seq = *start_seq; seq <= *start_seq + cycles_needed; ++seq) {
    const auto s = rec.sensors.find(seq);
    const auto next = rec.sensors.find(seq + 1);
    if (s == rec.sensors.end() || next == rec.sensors.end()) {
      ++result.missing;
      continue;
    }
    protocol::SensorSample sensors, next_sensors;
    protocol::from_dds(s->second, sensors);
    protocol::from_dds(next->second, next_sensors);
    protocol::Reference reference;
    protocol::LinearCommand linear;
    protocol::ActuatorCommand actuators;
    const auto r = rec.references.find(seq);
    const auto l = rec.linear.find(seq);
    const auto a = rec.actuators.find(seq);
    if (r != rec.references.end()) protocol::from_dds(r->second, reference);
    if (l != rec.linear.end()) protocol::from_dds(l->second, linear);
    if (a != rec.actuators.end()) protocol::from_dds(a->second, actuators);
    // A cycle whose reference, linear or actuator command was not recorded counts as missing too.
    if (r == rec.references.end() || l == rec.linear.end() || a == rec.actuators.end()) ++result.missing;
    records.push_back(stack::record_of(static_cast<double>(seq - *start_seq) * dt, sensors, next_sensors,
                                       r != rec.references.end() ? &reference : nullptr,
                                       l != rec.linear.end() ? &linear : nullptr,
                                       a != rec.actuators.end() ? &actuators : nullptr));
    if (next_sensors.brakes_engaged) ++result.braked_cycles;
  }
  {
    std::ofstream csv(csv_path);
    stack::write_csv(csv, records, cfg.facts.crane_kind == common::CraneKind::overhead);
  }
  if (result.missing > 0) {
    spdlog::warn("{}: {} of {} cycles missing from the recording (move started at cycle {}, {} sensor samples from "
                 "cycle {} to {})",
                 run_name, result.missing, cycles_needed + 1, *start_seq, rec.sensors.size(),
                 rec.sensors.empty() ? 0 : rec.sensors.begin()->first,
                 rec.sensors.empty() ? 0 : rec.sensors.rbegin()->first);
  }
  if (records.empty()) {
    throw RunFailure(run_name + ": no cycle was recorded (move started at cycle " + std::to_string(*start_seq) +
                     ", " + std::to_string(rec.sensors.size()) + " sensor samples from cycle " +
                     (rec.sensors.empty() ? std::string("-") : std::to_string(rec.sensors.begin()->first)) + " to " +
                     (rec.sensors.empty() ? std::string("-") : std::to_string(rec.sensors.rbegin()->first)) + ")");
  }
  result.samples = records.size();
  result.csv = csv_path.filename().string();
  result.metrics = stack::evaluate(records, m);
  if (const auto first = rec.references.find(*start_seq); first != rec.references.end()) {
    protocol::Reference reference;
    protocol::from_dds(first->second, reference);
    result.metrics.minimum_time = stack::minimum_time_of(reference);
  }
  return result;
}

double percentile(std::vector<double> values, double p) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const double rank = p / 100.0 * static_cast<double>(values.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(rank));
  const auto hi = std::min(lo + 1, values.size() - 1);
  return values[lo] + (rank - static_cast<double>(lo)) * (values[hi] - values[lo]);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_demo: the full simulated crane stack over DDS doing the maneuvers of section 3.3.3"};
  DemoOptions options;
  app.add_option("--config", options.config_path, "crane configuration (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--out", options.out_dir, "output directory (summary.json, CSV, plots, logs)");
  app.add_option("--dds", options.dds, "DDS vendor of every process: fast | cyclone")
      ->check(CLI::IsMember({"fast", "cyclone"}));
  app.add_option("--dds-mix", options.dds_mix,
                 "vendor per process, overriding --dds, e.g. plant=cyclone,state_estimator=cyclone "
                 "(names: the stages, plant, hardware_bridge, operator)");
  app.add_option("--maneuver", options.maneuvers,
                 "maneuver names to run (default: all in the config, and the random moves of --moves)");
  app.add_option("--moves", options.moves,
                 "seeded random moves besides the demo maneuvers, random_0 .. (crane_sim compare's and demo's)")
      ->check(CLI::Range(0, 1000));
  app.add_option("--seed", options.seed, "the random moves' seed");
  app.add_option("--friction-compensation", options.compensation, "on | off | both")
      ->check(CLI::IsMember({"on", "off", "both"}));
  app.add_flag("--realtime", options.realtime, "plant on absolute 10 ms deadlines instead of lockstep");
  app.add_flag("--acceleration-feedforward", options.acceleration_feedforward,
               "tracking adds the reference acceleration to its PD action (beyond the dissertation)");
  app.add_option("--hardware", options.hardware,
                 "shm: run through the real hardware_bridge process against the emulated board, with the plant "
                 "behind it (hardware-in-the-loop), instead of the plant on DDS")
      ->check(CLI::IsMember({"shm"}));
  app.add_option("--domain", options.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_option("--security", options.security_directory,
                 "DDS Security material (deploy/crane security init): every process with its own identity")
      ->check(CLI::ExistingDirectory);
  app.add_flag("--iceoryx", options.iceoryx,
               "every process and this one's operator on iceoryx shared memory (Cyclone DDS; RouDi started "
               "beside the runs and stopped after them)");
  app.add_option("--plot-script", options.plot_script, "matplotlib script that draws the PNG plots");
  app.add_option("--python", options.python, "python interpreter with matplotlib");
  app.add_option("--ready-timeout", options.ready_timeout, "[s] longest wait for the stack to become ready");
  app.add_option("--plant-cable-length-factor", options.plant_cable_length_factor,
                 "robustness: the simulated cable is this times the configured length, which every controller "
                 "still assumes")
      ->check(CLI::Range(0.1, 10.0));
  app.add_option("--plant-load-mass-factor", options.plant_load_mass_factor,
                 "robustness: the simulated load mass (so m_t, m_r) is this times the configured one")
      ->check(CLI::Range(0.0, 10.0));
  app.add_option("--plant-friction-factor", options.plant_friction_factor,
                 "robustness: every friction coefficient of both simulated drives is this times the configured "
                 "one (crane_sim's --mismatch L m f is these three factors)")
      ->check(CLI::Range(0.0, 10.0));
  auto* profile_option =
      app.add_option("--profile", options.profile,
                     "reference profile of every move: step | trapezoid (3.43) | zv | zvd | ei | time_optimal | minimum_time "
                     "(default trapezoid; step with a gain_scheduling controller, minimum_time with the follower)")
          ->check(CLI::IsMember({"step", "trapezoid", "zv", "zvd", "ei", "time_optimal", "minimum_time"}));
  app.add_option("--controller", options.controller,
                 "controller of the stack: gain_scheduling_partial (3.19) | gain_scheduling_full (3.26) (no "
                 "anti-swing) | none (PD tracking alone) | pd (3.45) | delay1 (3.47) | delay2 (3.50) | fuzzy (anti-swing with PD "
                 "tracking) | auto (per maneuver the best measured with the time-optimal profile: none for a trolley "
                 "move, delay2 when the jib slews, both with acceleration feedforward; the default with "
                 "--profile time_optimal) | follower (the minimum-time bound followed in closed loop, profile "
                 "minimum_time; the default, delay1 with another --profile)")
      ->check(CLI::IsMember({"gain_scheduling_partial", "gain_scheduling_full", "none", "pd", "delay1", "delay2", "fuzzy",
                             "auto", "follower"}));
  CLI11_PARSE(app, argc, argv);
  if (options.controller.empty()) {
    options.controller = stack::default_controller(profile_option->count() > 0 ? options.profile : std::string());
  }
  if (const auto implied = stack::implied_profile(options.controller); implied && profile_option->count() == 0) {
    options.profile = std::string(*implied);
  }
  options.profile_code = stack::profile_code(options.profile);

  const auto demo = [&]() -> int {
    try {
      runtime::configure_logging("info", "demo");
      const stack::StackConfig cfg = stack::load_stack_config(options.config_path);
      const auto selected = stack::select_moves(cfg, options.maneuvers, options.moves, options.seed);
      std::vector<bool> settings;
      if (options.compensation != "off") settings.push_back(true);
      if (options.compensation != "on") settings.push_back(false);
      fs::create_directories(options.out_dir);

      {
        launch::StackOptions all;
        all.hardware = options.hardware == "shm" ? "shm:x" : "";
        auto known = launch::stack_process_names(all);
        known.push_back("operator");
        options.dds_per_process = launch::parse_dds_mix(options.dds_mix, known);
      }
      runtime::NodeOptions node;
      node.dds = options.dds_per_process.count("operator") != 0 ? options.dds_per_process.at("operator") : options.dds;
      if (!options.security_directory.empty()) {
        options.security_directory = fs::absolute(options.security_directory).string();
      }
      node.security_directory = options.security_directory;
      node.iceoryx = options.iceoryx;

      // Each run gets a fresh DDS domain and a fresh operator participant: nothing of one run's
      // discovery (participants still being removed while the next stack starts) reaches the next.
      // Fast DDS 2.9 can abort in PDP::check_remote_participant_liveliness when a remote participant
      // is removed while its lease timer fires (docs/architecture.md, "Transport").
      std::vector<RunResult> results;
      std::uint32_t request_id = 1;
      unsigned run_index = 0;
      const auto demo_start = Clock::now();
      for (const auto& m : selected) {
        for (const bool compensation : settings) {
          node.domain_id = (options.domain_id + run_index++) % 233U;
          std::unique_ptr<transport::Participant> participant = runtime::make_participant(node, "operator");
          auto op = std::make_unique<Operator>(*participant);
          runtime::install_stop_handlers(&op->wakeup());
          try {
            results.push_back(run_maneuver(options, cfg, m, compensation, *op, request_id, node.domain_id));
            request_id += 2;  // the probe's and the move's
          } catch (...) {
            runtime::install_stop_handlers(nullptr);
            throw;
          }
          runtime::install_stop_handlers(nullptr);
          op.reset();
          participant.reset();
          const auto& r = results.back();
          spdlog::info("{} (friction compensation {}): settle {} s, position error {} mm, residual swing {} deg",
                       r.maneuver, r.friction_compensation ? "on" : "off", format_number(r.metrics.settle_time, 2),
                       format_number(r.metrics.final_position_error * 1e3, 2), format_number(r.metrics.residual_swing * 180 / kPi, 3));
        }
      }

      // summary.json
      json summary;
      summary["config"] = fs::absolute(options.config_path).string();
      summary["clock"] = options.realtime ? "realtime" : "lockstep";
      summary["sensor_writer"] = options.hardware.empty() ? "plant" : "hardware_bridge (emulated board, plant behind it)";
      summary["dds"] = options.dds;
      summary["dds_mix"] = options.dds_per_process;
      summary["profile"] = options.profile;
      summary["plant_cable_length_factor"] = options.plant_cable_length_factor;
      summary["plant_load_mass_factor"] = options.plant_load_mass_factor;
      summary["plant_friction_factor"] = options.plant_friction_factor;
      summary["controller"] = options.controller;
      json maneuvers = json::array();
      std::vector<double> all_latencies;
      double wall_time = 0.0, simulated_time = 0.0, startup_time = 0.0;
      std::vector<std::string> failures;
      std::uint64_t cycles = 0, overruns = 0, supervisor_overruns = 0, nonfinite = 0;
      json processes = json::array();
      bool diagnostics_complete = true;
      for (const auto& r : results) {
        json j;
        j["name"] = r.maneuver;
        j["controller"] = r.controller;
        j["friction_compensation"] = r.friction_compensation;
        j["settle_time_s"] = std::isfinite(r.metrics.settle_time) ? json(r.metrics.settle_time) : json(nullptr);
        j["settle_time_periods"] =
            std::isfinite(r.metrics.settle_time) ? json(r.metrics.settle_time / r.swing_period) : json(nullptr);
        j["minimum_time_s"] = std::isfinite(r.metrics.minimum_time) ? json(r.metrics.minimum_time) : json(nullptr);
        j["final_position_error_m"] = r.metrics.final_position_error;
        j["final_slew_error_rad"] = r.metrics.final_slew_error;
        if (cfg.facts.crane_kind == common::CraneKind::overhead) j["final_bridge_error_m"] = r.metrics.final_bridge_error;
        j["max_swing_rad"] = r.metrics.max_swing;
        j["residual_swing_rad"] = r.metrics.residual_swing;
        j["max_voltage_V"] = r.metrics.max_voltage;
        j["samples"] = r.samples;
        j["missing_samples"] = r.missing;
        j["braked_cycles"] = r.braked_cycles;
        j["csv"] = r.csv;
        j["plant_cycles"] = r.cycles;
        j["overruns"] = r.overruns;
        j["supervisor_timer_overruns"] = r.supervisor_timer_overruns;
        j["diagnostics_missing"] = r.diagnostics_missing;
        j["domain_id"] = r.domain_id;
        j["move_start_cycle"] = r.move_start_cycle;
        j["startup_s"] = r.startup_s;
        j["wall_time_s"] = r.wall_time_s;
        j["simulated_time_s"] = r.simulated_time_s;
        j["failures"] = r.failures;
        j["failed"] = !r.failures.empty();
        maneuvers.push_back(j);
        wall_time += r.wall_time_s;
        simulated_time += r.simulated_time_s;
        startup_time += r.startup_s;
        for (const auto& f : r.failures) failures.push_back(r.maneuver + (r.friction_compensation ? "_fc_on: " : "_fc_off: ") + f);
        all_latencies.insert(all_latencies.end(), r.latencies_us.begin(), r.latencies_us.end());
        cycles += r.cycles;
        overruns += r.overruns;
        supervisor_overruns += r.supervisor_timer_overruns;
        nonfinite += r.nonfinite_rejected;
        diagnostics_complete = diagnostics_complete && r.diagnostics_complete;
        for (const auto& p : r.processes) {
          processes.push_back({{"name", p.name}, {"pid", p.pid}, {"dds", p.dds}, {"run", p.run}});
        }
      }
      processes.push_back({{"name", "operator"}, {"pid", getpid()}, {"dds", node.dds}, {"run", "all"}});
      summary["maneuvers"] = maneuvers;
      summary["loop"] = {{"cycles", cycles},
                         {"overruns", overruns},
                         {"supervisor_timer_overruns", supervisor_overruns},
                         {"nonfinite_rejected", nonfinite},
                         {"diagnostics_complete", diagnostics_complete},
                         {"wall_time_s", wall_time},
                         {"simulated_time_s", simulated_time},
                         {"real_time_factor", wall_time > 0.0 ? simulated_time / wall_time : 0.0},
                         {"startup_s", startup_time},
                         {"demo_wall_time_s", std::chrono::duration<double>(Clock::now() - demo_start).count()},
                         {"failures", failures},
                         {"latency_us",
                          {{"p50", percentile(all_latencies, 50)},
                           {"p99", percentile(all_latencies, 99)},
                           {"max", all_latencies.empty() ? 0.0 : *std::max_element(all_latencies.begin(), all_latencies.end())},
                           {"samples", all_latencies.size()}}},
                         {"processes", processes}};
      const fs::path summary_path = fs::path(options.out_dir) / "summary.json";
      std::ofstream(summary_path) << summary.dump(2) << '\n';

      // Table (stack::table_row: one place with crane_sim).
      const bool bridge = cfg.facts.crane_kind == common::CraneKind::overhead;
      std::printf("\n%s\n", stack::table_header(bridge).c_str());
      for (const auto& r : results) {
        std::printf("%s\n", stack::table_row(r.maneuver, r.friction_compensation, r.metrics, r.swing_period, bridge).c_str());
      }
      std::printf("\nloop: %llu cycles, %llu overruns, latency sensor->command p50 %.0f us, p99 %.0f us, max %.0f us (%s)\n",
                  static_cast<unsigned long long>(cycles), static_cast<unsigned long long>(overruns),
                  percentile(all_latencies, 50), percentile(all_latencies, 99),
                  all_latencies.empty() ? 0.0 : *std::max_element(all_latencies.begin(), all_latencies.end()),
                  options.realtime ? "realtime" : "lockstep");
      std::printf("speed: %.1f s simulated in %.2f s of stepping (%.0fx real time); stack start-up %.1f s over %zu runs\n",
                  simulated_time, wall_time, wall_time > 0.0 ? simulated_time / wall_time : 0.0, startup_time,
                  results.size());
      std::printf("summary: %s\n", summary_path.string().c_str());
      for (const auto& f : failures) std::printf("FAILED: %s\n", f.c_str());

      if (!options.plot_script.empty()) {
        const std::string command = "'" + options.python + "' '" + options.plot_script + "' --out '" + options.out_dir + "'";
        const int rc = std::system(command.c_str());
        if (rc != 0) throw std::runtime_error("plot script failed: " + command);
      }
      if (!failures.empty()) return 1;
    } catch (const std::exception& error) {
      spdlog::critical("{}", error.what());
      return 1;
    }
    return 0;
  };
  if (!options.iceoryx) return demo();
  try {
    fs::create_directories(fs::path(options.out_dir) / "logs");
    return launch::run_beside_roudi((fs::path(options.out_dir) / "logs" / "iox_roudi.log").string(), demo);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_demo: %s\n", error.what());
    return 1;
  }
}
