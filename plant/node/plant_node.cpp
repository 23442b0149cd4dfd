// plant process: the simulated crane. The only clock of the stack: at cycle k it samples and
// publishes rt/crane/hw/sensors{seq = k}, applies the actuator command of cycle k (zero-order hold
// over one sample period) and integrates the nonlinear model to k+1.
//
//   --lockstep  integrate cycle k as soon as the command of cycle k and the supervisor's status of
//               cycle k-1 have arrived (supervisor::lockstep_may_run), never before and never with
//               another cycle's command; the cycle is offered again while it waits (a lost
//               best-effort sample), and a wait longer than stack.lockstep_hang_timeout is reported
//               as a hung chain;
//   --realtime  absolute deadlines every sample_period on the monotonic clock; a command that has
//               not arrived by the deadline is an overrun: the gate holds the last one while it is
//               within actuation.watchdog_timeout, then 0 V and brakes.
// What reaches the simulated drives is decided by the actuation gate the hardware bridge applies
// too (supervisor/actuation_gate.hpp, inside plant::PlantStage): the command only while the
// supervisor's status (of cycle k-1 in lockstep; the latest, within actuation.status_timeout, in
// realtime) permits it and the command is within actuation.watchdog_timeout; else 0 V and brakes.
// Non-finite commands are rejected and counted.
//
//   --board shm:NAME  the plant sits behind the emulated interface board instead of the DDS bus
//               (hardware-in-the-loop): it creates the shared-memory board, writes the encoder
//               counters from its simulated motion and applies what the hardware bridge writes to
//               the analog and digital outputs (the board holds its outputs, as a real DAC does).
//               Lockstep: the board's sample clock waits for the bridge's outputs of each sample;
//               realtime: absolute 10 ms deadlines, the outputs read as they are.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <array>
#include <fstream>
#include <optional>
#include <thread>
#include <vector>

#include "crane/config/config_document.hpp"
#include "crane/hardware_bridge/bridge_config.hpp"
#include "crane/hardware_bridge/shm_board.hpp"
#include "crane/plant/drives_and_sensors.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/supervisor/actuation_gate.hpp"

namespace {
using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;

// The plant behind the emulated board (--board shm:NAME).
int run_behind_board(const std::string& board_name, const config::ConfigDocument& cfg,
                     const plant::PlantStageParams& params, bool realtime, const runtime::NodeOptions& options,
                     const std::string& stats_path) {
  namespace hb = hardware_bridge;
  // Behind the board the hardware bridge is the gate: the plant applies what the board's outputs say.
  plant::CraneSimulator simulator(plant::simulated_truth(params.simulator, params.mismatch));
  const auto& truth = simulator.parameters();
  const plant::DrivesAndSensors sensors_model(truth.crane);
  const auto gate = cfg.read("actuation", supervisor::read_actuation_params);
  const auto bridge = cfg.read("hardware_bridge", [&](config::YamlSection& block, const common::StackFacts& facts) {
    return hb::read_params(block, facts, gate);
  });
  const hb::BoardAxes axes = bridge.board.axes;  // the crane's drives and brake lines: the slew's or the bridge's
  const std::uint32_t travel_brakes = hb::travel_brake_lines(axes);
  const auto encoder_counts = [&] {
    const auto& m = simulator.output().measurement;
    return std::array<std::int64_t, hb::kCounterCount>{
        plant::position_to_encoder_counts(m.trolley_position, sensors_model.trolley_resolution()),
        plant::position_to_encoder_counts(m.slew_angle, sensors_model.slew_resolution()),
        plant::position_to_encoder_counts(m.swing_in_plane, sensors_model.swing_resolution()),
        plant::position_to_encoder_counts(m.swing_out_of_plane, sensors_model.swing_resolution()),
        plant::position_to_encoder_counts(m.bridge_position, sensors_model.bridge_resolution())};  // 0 m elsewhere
  };
  // The initial state is on the counters before the board exists for the bridge (a bridge that
  // read zeros here saw the trolley at 0 m, outside its travel, then jumping to 0.25 m).
  auto board = hb::ShmBoardEmulator::create(board_name, cfg.facts().crane, bridge.board.counter_bits,
                                            encoder_counts());
  auto participant = runtime::make_participant(options, "plant");
  transport::Wakeup wakeup;
  runtime::install_stop_handlers(&wakeup);
  runtime::DiagnosticsPublisher diagnostics(*participant, runtime::ProcessId::plant);
  runtime::LoopCounters counters;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg.facts().sample_period));
  const auto hang_timeout = std::chrono::duration_cast<Clock::duration>(
      std::chrono::duration<double>(cfg.facts().lockstep_hang_timeout));
  // Realtime: the board's counters move between the plant's samples as an encoder's do (the bridge
  // reads them on a timer of its own); lockstep: the bridge reads each sample once, held.
  auto publish = [&](Clock::time_point due) {
    if (!realtime) return board.publish_sample(encoder_counts());
    const auto due_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(due.time_since_epoch()).count();
    return board.publish_timed_sample(encoder_counts(), due_ns, cfg.facts().sample_period);
  };
  const auto bit = [](hb::DigitalOutput line) { return 1U << static_cast<unsigned>(line); };
  spdlog::info("behind the emulated board {} ({} clock): counters {} bits, DAC [{}, {}] V", board.segment_path(),
               realtime ? "realtime" : "board-paced lockstep", board.counter_bits(),
               board.analog_range(hb::AnalogOutput::trolley_drive).min_volts,
               board.analog_range(hb::AnalogOutput::trolley_drive).max_volts);
  std::uint64_t tick = publish(Clock::now());
  bool answered_once = false;
  auto next_deadline = Clock::now() + period;
  while (!runtime::stop_requested()) {
    const auto due = next_deadline;  // realtime: when this step is due (steady_clock is CLOCK_MONOTONIC)
    if (realtime) {
      std::this_thread::sleep_until(next_deadline);
      next_deadline += period;
      if (Clock::now() > next_deadline) ++counters.overruns;  // the plant itself fell behind
    } else {
      // Board-paced lockstep: sample `tick` is integrated only with the bridge's outputs of that
      // sample, however long they take (nothing is guessed); a wait beyond lockstep_hang_timeout is
      // reported as a hung chain, once per sample.
      const auto wait_start = Clock::now();
      bool hang_reported = false;
      bool answered = false;
      while (!runtime::stop_requested() && !answered) {
        answered = board.wait_for_outputs(tick, Clock::now() + std::chrono::milliseconds(100));
        if (!answered && answered_once && !hang_reported && Clock::now() - wait_start >= hang_timeout) {
          hang_reported = true;
          ++counters.overruns;
          spdlog::error("lockstep: no board outputs for sample {} in {} s: the chain behind the bridge is hung "
                        "(the sample keeps waiting)", tick, cfg.facts().lockstep_hang_timeout);
        }
      }
      if (!answered) break;
      answered_once = true;
    }
    const auto outputs = board.read_outputs();
    const std::uint32_t digital = outputs.outputs.digital_outputs;
    const bool drives_enabled = (digital & bit(hb::DigitalOutput::drive_enable)) != 0;
    plant::DriveInput input;
    input.brakes_engaged = (digital & travel_brakes) != travel_brakes;
    if (drives_enabled) {
      input.trolley_voltage = board.output_volts(outputs, hb::AnalogOutput::trolley_drive);
      if (axes.slew) input.slew_voltage = board.output_volts(outputs, hb::AnalogOutput::slew_drive);
      if (axes.bridge) input.bridge_voltage = board.output_volts(outputs, hb::AnalogOutput::bridge_drive);
      if ((digital & bit(hb::DigitalOutput::brake_release_hoist)) != 0) {
        input.hoist_speed = board.output_volts(outputs, hb::AnalogOutput::hoist_speed) *
                            bridge.bridge.hoist_speed_per_volt;
      }
    }
    if (simulator.step(input) != common::StepStatus::ok) {
      spdlog::error("plant step at sample {} failed", tick);
    }
    ++counters.cycles;
    counters.last_seq = counters.cycles;
    tick = publish(due);
    diagnostics.maybe_publish(counters, nullptr);
  }
  runtime::leave_realtime();
  diagnostics.publish_final(counters, nullptr);
  spdlog::info("stopping at t = {:.2f} s: {} samples, {} overruns, {} friction events", simulator.time(),
               counters.cycles, counters.overruns, simulator.friction_event_count());
  if (!stats_path.empty()) {
    std::ofstream out(stats_path);
    out << "{\"cycles\": " << counters.cycles << ", \"overruns\": " << counters.overruns << "}\n";
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"plant: simulated tower crane (nonlinear model, friction, drives and sensors) on the DDS bus"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  std::string wake = "listener";
  runtime::add_wake_option(app, wake);
  bool realtime = false;
  double initial_trolley = 0.25;
  double initial_slew = 0.0;
  double initial_bridge = 0.0;
  double initial_swing = 0.0;
  std::string stats_path;
  bool lockstep = false;
  auto* lockstep_flag = app.add_flag("--lockstep", lockstep, "advance as soon as each command arrives (default)");
  app.add_flag("--realtime", realtime, "absolute 10 ms deadlines on the wall clock")->excludes(lockstep_flag);
  app.add_option("--initial-trolley", initial_trolley, "[m] initial trolley position");
  app.add_option("--initial-slew", initial_slew, "[rad] initial slew angle");
  app.add_option("--initial-bridge", initial_bridge, "[m] initial bridge position (overhead crane)");
  app.add_option("--initial-swing", initial_swing, "[rad] initial in-plane swing");
  app.add_option("--stats-out", stats_path, "write loop statistics (JSON) here on exit");
  plant::PlantMismatch mismatch;
  app.add_option("--cable-length-factor", mismatch.cable_length_factor,
                 "the simulated crane's cable length is this times the configured one, while the sensors still "
                 "report the configured length (robustness studies)")
      ->check(CLI::Range(0.1, 10.0));
  app.add_option("--load-mass-factor", mismatch.load_mass_factor,
                 "the simulated load mass is this times the configured one (controllers unaware)")
      ->check(CLI::Range(0.0, 10.0));
  app.add_option("--friction-factor", mismatch.friction_factor,
                 "every friction coefficient of the simulated drives is this times the configured one")
      ->check(CLI::Range(0.0, 10.0));
  app.add_option("--sensor-delay", mismatch.sensor_delay_cycles,
                 "[cycles] the sensor sample of cycle k reports the encoders of cycle k - this")
      ->check(CLI::Range(0, plant::PlantStage::kMaxSensorDelay));
  app.add_option("--friction-change-factor", mismatch.friction_change_factor,
                 "from --friction-change-cycle on, every friction coefficient of both drives is this times what it "
                 "was (a plant whose friction changes during a run; 1: off)")
      ->check(CLI::Range(0.1, 10.0));
  app.add_option("--friction-change-cycle", mismatch.friction_change_cycle,
                 "[cycles] the first cycle integrated with the changed friction");
  std::string board_uri;
  app.add_option("--board", board_uri,
                 "shm:NAME: sit behind the emulated interface board (the hardware bridge reads and writes it) "
                 "instead of publishing sensors and reading actuators on DDS");
  CLI11_PARSE(app, argc, argv);

  try {
    runtime::configure_logging(options.log_level, "plant");
    const auto cfg = config::ConfigDocument::load(options.config_path);
    plant::PlantStageParams params;
    params.simulator = cfg.read("plant", plant::read_params);
    params.simulator.initial_state.trolley_position = initial_trolley;
    params.simulator.initial_state.slew_angle = initial_slew;
    params.simulator.initial_state.bridge_position = initial_bridge;
    params.simulator.initial_state.swing_in_plane = initial_swing;
    params.gate = cfg.read("actuation", supervisor::read_actuation_params);
    params.mismatch = mismatch;
    if (mismatch.cable_length_factor != 1.0 || mismatch.load_mass_factor != 1.0 || mismatch.friction_factor != 1.0 ||
        mismatch.sensor_delay_cycles != 0 || mismatch.friction_change_factor != 1.0) {
      spdlog::warn("plant differs from the configuration: L x {}, m x {}, friction x {} (x {} from cycle {}), sensors {} "
                   "cycles late",
                   mismatch.cable_length_factor, mismatch.load_mass_factor, mismatch.friction_factor,
                   mismatch.friction_change_factor, mismatch.friction_change_cycle, mismatch.sensor_delay_cycles);
    }
    if (!board_uri.empty()) {
      if (board_uri.rfind("shm:", 0) != 0) {
        throw std::invalid_argument("--board " + board_uri + ": the plant can only sit behind an emulated board, shm:NAME");
      }
      return run_behind_board(board_uri.substr(4), cfg, params, realtime, options, stats_path);
    }
    plant::PlantStage plant(params);
    const double dt = cfg.facts().sample_period;

    auto participant = runtime::make_participant(options, "plant");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto sensors = participant->make_writer<tp::Sensors>();
    auto actuators = participant->make_reader<tp::Actuators>(&wakeup);
    // A few statuses deep: in lockstep the status of cycle k can follow that of k-1 before this
    // process has taken it, and cycle k needs k-1's.
    auto safety = participant->make_recording_reader<tp::SafetyStatus>(&wakeup, 8);
    runtime::DiagnosticsPublisher diagnostics(*participant, runtime::ProcessId::plant);
    runtime::LatencyStatistics latency;
    runtime::LoopCounters counters;
    // Every sample's end-to-end latency for the run's summary (crane_demo's and crane_bench's
    // percentiles): 2^19 samples, 87 min at 100 Hz, so a 30-minute soak is covered whole (it kept
    // the first 2^16, 11 min, before). Allocated and written at start (4 MiB) so that the resident
    // memory stays flat while it fills, with or without mlockall; samples past it are not logged.
    constexpr std::size_t kLatencyLogCapacity = std::size_t{1} << 19;
    std::vector<double> latency_log(kLatencyLogCapacity, 0.0);
    std::size_t latency_logged = 0;

    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(dt));
    const auto hang_timeout = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(cfg.facts().lockstep_hang_timeout));

    tp::msgs::SensorSample_ sample;
    protocol::SensorSample sample_plain;
    protocol::ActuatorCommand command;
    tp::msgs::ActuatorCommand_ incoming;
    protocol::SupervisorStatus status;
    tp::msgs::SupervisorStatus_ incoming_status;
    std::uint64_t reoffered = 0;  // lockstep: cycles offered again (a best-effort sample lost, or start-up)
    std::uint64_t hangs = 0;      // lockstep: cycles that waited longer than lockstep_hang_timeout
    auto next_brake_report = Clock::now() + std::chrono::seconds(2);
    bool started = false;      // the chain has answered once
    bool chain_ready = false;  // and the supervisor has seen every stage alive: overruns count from here
    builtin_interfaces::msg::dds_::Time_ origin = runtime::now_stamp();
    std::int64_t origin_ns = runtime::to_nanoseconds(origin);
    // The sample's stamp is when its positions were measured: now, or, in realtime, the cycle's
    // scheduled instant (the simulated state is exactly there, however late this process runs), on
    // the wall clock through one offset taken at the start: `measured_ns`. The supervisor
    // differentiates positions over the stamps' interval (supervisor.hpp): with publication stamps,
    // a sample published 8 ms late and the next on time read as a 2.5x faster crane. (The first
    // version read the wall clock and the monotonic clock one after the other at each sample and
    // subtracted the lateness: exact unless the process is descheduled between the two reads,
    // which a VM's stolen time makes possible; one offset leaves nothing to race.)
    const auto publish = [&](std::optional<std::int64_t> measured_ns = std::nullopt) {
      plant.sample(sample_plain);
      protocol::from_dds(origin, sample_plain.header.origin);
      sample_plain.writer_pid = static_cast<std::uint32_t>(getpid());
      protocol::to_dds(sample_plain, sample);
      auto stamp = runtime::now_stamp();
      if (measured_ns) {
        stamp.sec(static_cast<std::int32_t>(*measured_ns / 1000000000LL));
        stamp.nanosec(static_cast<std::uint32_t>(*measured_ns % 1000000000LL));
      }
      sample.header().stamp(stamp);
      sensors->write(sample);
    };
    const auto new_origin = [&] {
      origin = runtime::now_stamp();
      origin_ns = runtime::to_nanoseconds(origin);
    };
    const auto record_arrival = [&](std::int64_t arrival_ns) {
      const double us = static_cast<double>(arrival_ns - origin_ns) / 1000.0;
      latency.record(us);
      if (latency_logged < latency_log.size()) latency_log[latency_logged++] = us;
    };
    runtime::LatencyStatistics step_cost(1 << 16);  // [us] of the plant's step: where a lockstep cycle goes
    const auto step = [&](const supervisor::GateInput& input) {
      const auto step_start = Clock::now();
      const auto step_status = plant.step(input);
      step_cost.record(std::chrono::duration<double, std::micro>(Clock::now() - step_start).count());
      if (step_status != common::StepStatus::ok) {
        spdlog::error("plant step at cycle {} returned status {}", plant.cycle() - 1, static_cast<int>(step_status));
      }
      ++counters.cycles;
      counters.last_seq = plant.cycle();
    };
    publish();
    spdlog::info("simulating at {} Hz, {} clock, x0 = {} m, gamma0 = {} rad", 1.0 / dt, realtime ? "realtime" : "lockstep",
                 initial_trolley, initial_slew);

    if (!realtime) {
      std::array<std::optional<protocol::SupervisorStatus>, 8> recent_statuses;
      tp::msgs::SensorSample_ previous_sample;  // of cycle k-1, offered again with cycle k
      // Lockstep (docs/architecture.md, "The 100 Hz cycle"; the rules in one place:
      // supervisor::lockstep_may_run and lockstep_gate_input): cycle k is integrated only with the
      // command of cycle k, gated by the supervisor's status of cycle k-1 (computed from every
      // stage's output of cycle k-1, while the chain computes cycle k: the supervisor is off the
      // chain's path, and its decision lags the command by one cycle as in realtime). Cycle 0 waits
      // for the status of cycle 0. Nothing is guessed and nothing depends on wall time: a slow
      // machine slows the simulation, never changes it. While it waits, the plant offers cycle k
      // again (after 10 ms, then doubling to 80 ms): a lost best-effort sample is recovered, and
      // every stage and the supervisor answer a repeated cycle from their stored output.
      // The cycle advances on the DDS listener thread that brings its last input
      // (runtime::ListenerDispatch: one thread wake-up for the chain's last hop); this thread keeps
      // the re-offers and the hang report, serialized with it.
      struct CycleWait {
        bool got_command{false};
        bool got_status{false};
        std::int64_t arrival_ns{0};
        Clock::time_point start;
        Clock::duration backoff{std::chrono::milliseconds(10)};
        Clock::time_point next_reoffer;
        bool hang_reported{false};
      };
      CycleWait wait;
      const auto begin_wait = [&wait] {
        wait = CycleWait{};
        wait.start = Clock::now();
        wait.next_reoffer = wait.start + wait.backoff;
      };
      begin_wait();
      // Takes what has arrived; steps and publishes cycle k once its inputs are complete.
      const auto advance = [&] {
        const std::uint64_t seq = plant.cycle();
        while (actuators->take_next(incoming)) {
          if (runtime::injected_loss()) continue;  // tests only (CRANE_INJECT_LOSS)
          if (!runtime::all_finite(incoming)) {
            ++counters.nonfinite_rejected;
            continue;
          }
          if (incoming.header().seq() == seq && !wait.got_command) {
            protocol::from_dds(incoming, command);
            wait.got_command = true;
            wait.arrival_ns = runtime::now_nanoseconds();
          }
        }
        while (safety->take_next(incoming_status)) {
          if (runtime::injected_loss()) continue;  // tests only (CRANE_INJECT_LOSS)
          if (!runtime::all_finite(incoming_status)) {
            ++counters.nonfinite_rejected;
            continue;
          }
          // Kept by cycle: one for a later cycle may arrive before this cycle is done.
          protocol::from_dds(incoming_status, recent_statuses[incoming_status.header().seq() % recent_statuses.size()].emplace());
        }
        if (!wait.got_status) {
          const std::uint64_t gate_seq = supervisor::gating_cycle(seq);
          const auto& gate = recent_statuses[gate_seq % recent_statuses.size()];
          if (gate.has_value() && gate->header.seq == gate_seq) {
            status = *gate;
            wait.got_status = true;
          }
        }
        if (!wait.got_status || !supervisor::lockstep_may_run(wait.got_command, status)) return;
        started = true;
        if (wait.got_command) record_arrival(wait.arrival_ns);
        previous_sample = sample;
        step(supervisor::lockstep_gate_input(seq, dt, wait.got_command ? &command : nullptr, status));
        new_origin();
        publish();
        begin_wait();
      };
      // The node's thread: offers the cycle again while it waits, and reports a hang.
      Clock::time_point next_timer;
      const auto timers = [&] {
        const auto now = Clock::now();
        if (now >= wait.next_reoffer) {
          if (started) {
            ++reoffered;
            // The previous cycle first: the supervisor may still lack it (it gates this cycle).
            previous_sample.header().stamp(runtime::now_stamp());
            sensors->write(previous_sample);
          } else {
            new_origin();  // start-up: latency counts from when the chain is up
          }
          publish();
          wait.backoff = std::min(wait.backoff * 2, Clock::duration(std::chrono::milliseconds(80)));
          wait.next_reoffer = now + wait.backoff;
        }
        if (started && !wait.hang_reported && now - wait.start >= hang_timeout) {
          wait.hang_reported = true;
          ++hangs;
          const auto a = actuators->health();
          const auto h = safety->health();
          spdlog::error("lockstep: cycle {} has waited {:.1f} s for {}{}{}: the chain is hung (not a crane fault; "
                        "the cycle keeps waiting). Actuator writers matched {}, supervisor status writers matched {}",
                        plant.cycle(), std::chrono::duration<double>(now - wait.start).count(),
                        wait.got_command ? "" : "the actuator command", !wait.got_command && !wait.got_status ? " and " : "",
                        wait.got_status ? "" : "the supervisor status", a.matched_writers, h.matched_writers);
        }
        diagnostics.maybe_publish(counters, &latency);
        next_timer = std::min(wait.next_reoffer, Clock::now() + std::chrono::milliseconds(5));
      };
      runtime::ListenerDispatch dispatch(wakeup, advance, wake == "listener");
      while (!runtime::stop_requested()) {
        dispatch.run(timers);
        wakeup.wait_until(next_timer);
      }
    } else {
      // Realtime: absolute deadlines every sample period on the monotonic clock. A command missing at
      // the deadline is an overrun; the gate keeps the last valid one while it is within
      // actuation.watchdog_timeout (a drive amplifier holds its input), then 0 V and brakes.
      const auto epoch = Clock::now();
      const std::int64_t wall_at_epoch_ns = runtime::now_nanoseconds();  // the one offset of the stamps
      const auto seconds = [&](Clock::time_point t) { return std::chrono::duration<double>(t - epoch).count(); };
      supervisor::GateInput in;
      auto next_deadline = Clock::now() + period;
      while (!runtime::stop_requested()) {
        const std::uint64_t seq = plant.cycle();
        bool got = false;
        std::int64_t arrival_ns = 0;
        while (!runtime::stop_requested()) {
          while (actuators->take_next(incoming)) {
            if (!runtime::all_finite(incoming)) {
              ++counters.nonfinite_rejected;
              continue;
            }
            if (incoming.header().seq() == seq) {
              protocol::from_dds(incoming, command);
              got = true;
              arrival_ns = runtime::now_nanoseconds();
              in.command_arrival_time = seconds(Clock::now());
            }
          }
          while (safety->take_next(incoming_status)) {
            if (!runtime::all_finite(incoming_status)) {
              ++counters.nonfinite_rejected;
              continue;
            }
            protocol::from_dds(incoming_status, status);
            in.status_received = true;
            in.status = supervisor::permit_of(status);
            in.status_arrival_time = seconds(Clock::now());
            chain_ready = chain_ready || status.stages_alive == protocol::SupervisorStatus::STAGES_ALL;
          }
          if (Clock::now() >= next_deadline) break;
          wakeup.wait_until(next_deadline);
        }
        if (runtime::stop_requested()) break;
        // Until the whole chain is matched and alive, a missing command is start-up, not an overrun.
        const bool count_overrun = !got && started && chain_ready;
        if (got) {
          started = true;
          record_arrival(arrival_ns);
        }
        in.time = seconds(Clock::now());
        in.command_received = got;
        in.command = supervisor::drive_command_of(command);
        step(in);
        const auto& gate = plant.gate_output();
        if (gate.brakes_engaged && Clock::now() >= next_brake_report) {
          // Off the hot path: at most once every 2 s while the brakes stay on.
          next_brake_report = Clock::now() + std::chrono::seconds(2);
          const auto health = safety->health();
          spdlog::info("brakes on at cycle {}: {} (supervisor status writers matched {}, alive {}, samples {})", seq,
                       supervisor::reason_name(gate.reason), health.matched_writers, health.alive_writers,
                       health.samples);
        }
        if (count_overrun) {
          ++counters.overruns;
          spdlog::warn("overrun: no command for cycle {} within {} ms; {}", seq, dt * 1e3,
                       gate.brakes_engaged ? "0 V and brakes for this cycle" : "the last command is held");
        }
        std::this_thread::sleep_until(next_deadline);
        const auto measured_at = next_deadline;
        next_deadline += period;
        new_origin();
        publish(wall_at_epoch_ns + std::chrono::duration_cast<std::chrono::nanoseconds>(measured_at - epoch).count());
        diagnostics.maybe_publish(counters, &latency);
      }
    }

    const auto& simulator = plant.simulator();
    runtime::leave_realtime();
    diagnostics.publish_final(counters, &latency);
    spdlog::info("stopping at t = {:.2f} s: {} cycles, {} overruns, {} cycles offered again, {} hung, {} non-finite "
                 "commands rejected, latency p50 {:.0f} us p99 {:.0f} us max {:.0f} us, {} friction events, "
                 "plant step p50 {:.0f} us p99 {:.0f} us",
                 simulator.time(), counters.cycles, counters.overruns, reoffered, hangs, counters.nonfinite_rejected,
                 latency.percentile(50), latency.percentile(99), latency.maximum(), simulator.friction_event_count(),
                 step_cost.percentile(50), step_cost.percentile(99));
    if (!stats_path.empty()) {
      std::ofstream out(stats_path);
      out << "{\"cycles\": " << counters.cycles << ", \"overruns\": " << counters.overruns
          << ", \"reoffered\": " << reoffered << ", \"hung\": " << hangs
          << ", \"simulated_time_s\": " << simulator.time() << ", \"step_us\": {\"p50\": " << step_cost.percentile(50)
          << ", \"p99\": " << step_cost.percentile(99) << ", \"max\": " << step_cost.maximum() << "}"
          << ", \"nonfinite_rejected\": " << counters.nonfinite_rejected << ", \"latency_us\": [";
      for (std::size_t i = 0; i < latency_logged; ++i) out << (i ? "," : "") << latency_log[i];
      out << "]}\n";
    }
  } catch (const std::exception& error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
  return 0;
}
