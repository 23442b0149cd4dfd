// plant process: the simulated crane. The only clock of the stack: at cycle k it samples and
// publishes rt/crane/hw/sensors{seq = k}, applies the actuator command of cycle k (zero-order hold
// over one sample period) and integrates the nonlinear model to k+1.
//
//   --lockstep  advance as soon as the command of cycle k arrives (or after lockstep_timeout, then
//               the cycle counts as an overrun and is integrated with 0 V and brakes on);
//   --realtime  absolute deadlines every sample_period on the monotonic clock; a command that has
//               not arrived by the deadline is an overrun, treated the same way.
// Brakes are released and the command applied only while the supervisor's latest status, no older
// than safety_status_timeout, says so. Non-finite commands are rejected and counted.
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
#include <fstream>
#include <thread>
#include <vector>

#include "crane/config/simulator_parameters.hpp"
#include "crane/hardware_bridge/shm_board.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/plant/drives_and_sensors.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {
using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;

// `cable_length_reading_factor` scales the reported cable length: 1 normally; 1/f when the plant's
// cable is f times the configured one but the crane (like the lab crane, which has no hoist
// encoder) reports the configured length, so every controller keeps assuming it.
void fill_sensors(tp::msgs::SensorSample_& s, const plant::SimulatorOutput& o, std::uint64_t seq,
                  const builtin_interfaces::msg::dds_::Time_& origin, double cable_length_reading_factor = 1.0) {
  runtime::stamp_header(s.header(), seq, origin);
  s.source(1);
  s.writer_pid(static_cast<std::uint32_t>(getpid()));
  s.trolley_position(o.measurement.trolley_position);
  s.slew_angle(o.measurement.slew_angle);
  s.swing_in_plane(o.measurement.swing_in_plane);
  s.swing_out_of_plane(o.measurement.swing_out_of_plane);
  s.cable_length(o.measurement.cable_length * cable_length_reading_factor);
  s.applied_trolley_voltage(o.applied_trolley_voltage);
  s.applied_slew_voltage(o.applied_slew_voltage);
  s.applied_hoist_speed(o.applied_hoist_speed);
  s.brakes_engaged(o.brakes_engaged);
  s.emergency_stop_input(false);
  s.limit_switches(0);
}
// The plant behind the emulated board (--board shm:NAME).
int run_behind_board(const std::string& board_name, const config::StackConfig& cfg, const config::StackConfig& truth,
                     plant::CraneSimulator& simulator, bool realtime, const runtime::NodeOptions& options,
                     const std::string& stats_path) {
  namespace hb = hardware_bridge;
  const plant::DrivesAndSensors sensors_model(truth.crane);
  const auto encoder_counts = [&] {
    const auto& m = simulator.output().measurement;
    return std::array<std::int64_t, hb::kCounterCount>{
        plant::position_to_encoder_counts(m.trolley_position, sensors_model.trolley_resolution()),
        plant::position_to_encoder_counts(m.slew_angle, sensors_model.slew_resolution()),
        plant::position_to_encoder_counts(m.swing_in_plane, sensors_model.swing_resolution()),
        plant::position_to_encoder_counts(m.swing_out_of_plane, sensors_model.swing_resolution())};
  };
  // The initial state is on the counters before the board exists for the bridge (a bridge that
  // read zeros here saw the trolley at 0 m, outside its travel, then jumping to 0.25 m).
  auto board = hb::ShmBoardEmulator::create(board_name, cfg.crane, cfg.hardware_bridge.board.counter_bits,
                                            encoder_counts());
  auto participant = runtime::make_participant(options, "plant");
  transport::Wakeup wakeup;
  runtime::install_stop_handlers(&wakeup);
  runtime::DiagnosticsPublisher diagnostics(*participant, runtime::ProcessId::plant);
  runtime::LoopCounters counters;
  const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg.plant.sample_period));
  const auto lockstep_timeout =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg.plant.lockstep_timeout));
  auto publish = [&] { return board.publish_sample(encoder_counts()); };
  const auto bit = [](hb::DigitalOutput line) { return 1U << static_cast<unsigned>(line); };
  spdlog::info("behind the emulated board {} ({} clock): counters {} bits, DAC [{}, {}] V", board.segment_path(),
               realtime ? "realtime" : "board-paced lockstep", board.counter_bits(),
               board.analog_range(hb::AnalogOutput::trolley_drive).min_volts,
               board.analog_range(hb::AnalogOutput::trolley_drive).max_volts);
  std::uint64_t tick = publish();
  bool answered_once = false;
  auto next_deadline = Clock::now() + period;
  while (!runtime::stop_requested()) {
    if (realtime) {
      std::this_thread::sleep_until(next_deadline);
      next_deadline += period;
      if (Clock::now() > next_deadline) ++counters.overruns;  // the plant itself fell behind
    } else {
      // Board-paced lockstep: wait for the bridge's outputs of this sample. Before the first answer
      // the bridge (or the chain behind it) is still starting: wait without stepping.
      const auto deadline = Clock::now() + (answered_once ? lockstep_timeout : std::chrono::milliseconds(100));
      if (!board.wait_for_outputs(tick, deadline)) {
        if (!answered_once) continue;
        ++counters.overruns;
        spdlog::warn("no board outputs for sample {} within {} s: the outputs as they are are applied",
                     tick, cfg.plant.lockstep_timeout);
      } else {
        answered_once = true;
      }
    }
    const auto outputs = board.read_outputs();
    const std::uint32_t digital = outputs.outputs.digital_outputs;
    const bool drives_enabled = (digital & bit(hb::DigitalOutput::drive_enable)) != 0;
    plant::DriveInput input;
    input.brakes_engaged = (digital & bit(hb::DigitalOutput::brake_release_trolley)) == 0 ||
                           (digital & bit(hb::DigitalOutput::brake_release_slew)) == 0;
    if (drives_enabled) {
      input.trolley_voltage = board.output_volts(outputs, hb::AnalogOutput::trolley_drive);
      input.slew_voltage = board.output_volts(outputs, hb::AnalogOutput::slew_drive);
      if ((digital & bit(hb::DigitalOutput::brake_release_hoist)) != 0) {
        input.hoist_speed = board.output_volts(outputs, hb::AnalogOutput::hoist_speed) *
                            cfg.hardware_bridge.bridge.hoist_speed_per_volt;
      }
    }
    if (simulator.step(input) != common::StepStatus::ok) {
      spdlog::error("plant step at sample {} failed", tick);
    }
    ++counters.cycles;
    counters.last_seq = counters.cycles;
    tick = publish();
    diagnostics.maybe_publish(counters, nullptr);
  }
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
  bool realtime = false;
  double initial_trolley = 0.25;
  double initial_slew = 0.0;
  double initial_swing = 0.0;
  std::string stats_path;
  bool lockstep = false;
  auto* lockstep_flag = app.add_flag("--lockstep", lockstep, "advance as soon as each command arrives (default)");
  app.add_flag("--realtime", realtime, "absolute 10 ms deadlines on the wall clock")->excludes(lockstep_flag);
  app.add_option("--initial-trolley", initial_trolley, "[m] initial trolley position");
  app.add_option("--initial-slew", initial_slew, "[rad] initial slew angle");
  app.add_option("--initial-swing", initial_swing, "[rad] initial in-plane swing");
  app.add_option("--stats-out", stats_path, "write loop statistics (JSON) here on exit");
  double cable_length_factor = 1.0;
  double load_mass_factor = 1.0;
  app.add_option("--cable-length-factor", cable_length_factor,
                 "the simulated crane's cable length is this times the configured one, while the sensors still "
                 "report the configured length (robustness studies)")
      ->check(CLI::Range(0.1, 10.0));
  app.add_option("--load-mass-factor", load_mass_factor,
                 "the simulated load mass is this times the configured one (controllers unaware)")
      ->check(CLI::Range(0.0, 10.0));
  std::string board_uri;
  app.add_option("--board", board_uri,
                 "shm:NAME: sit behind the emulated interface board (the hardware bridge reads and writes it) "
                 "instead of publishing sensors and reading actuators on DDS");
  CLI11_PARSE(app, argc, argv);

  try {
    runtime::configure_logging(options.log_level, "plant");
    const config::StackConfig cfg = config::load_stack_config(options.config_path);
    plant::PlantState initial;
    initial.trolley_position = initial_trolley;
    initial.slew_angle = initial_slew;
    initial.swing_in_plane = initial_swing;
    config::StackConfig truth = cfg;  // what the plant simulates; the controllers read cfg itself
    truth.crane.cable_length *= cable_length_factor;
    truth.crane.load_mass *= load_mass_factor;
    const auto sim_params = config::simulator_parameters(truth, initial);
    if (cable_length_factor != 1.0 || load_mass_factor != 1.0) {
      spdlog::warn("plant differs from the configuration: L = {} m, m = {} kg (configured {} m, {} kg)",
                   truth.crane.cable_length, truth.crane.load_mass, cfg.crane.cable_length, cfg.crane.load_mass);
    }
    plant::CraneSimulator simulator(sim_params);
    if (!board_uri.empty()) {
      if (board_uri.rfind("shm:", 0) != 0) {
        throw std::invalid_argument("--board " + board_uri + ": the plant can only sit behind an emulated board, shm:NAME");
      }
      return run_behind_board(board_uri.substr(4), cfg, truth, simulator, realtime, options, stats_path);
    }

    auto participant = runtime::make_participant(options, "plant");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto sensors = participant->make_writer<tp::Sensors>();
    auto actuators = participant->make_reader<tp::Actuators>(&wakeup);
    auto safety = participant->make_reader<tp::SafetyStatus>(&wakeup);
    runtime::DiagnosticsPublisher diagnostics(*participant, runtime::ProcessId::plant);
    runtime::LatencyStatistics latency;
    runtime::LoopCounters counters;
    std::vector<double> latency_log;
    latency_log.reserve(1 << 16);

    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg.plant.sample_period));
    const auto lockstep_timeout = std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(cfg.plant.lockstep_timeout));
    // In lockstep the supervisor's status may lag simulated time by up to lockstep_timeout.
    const auto status_timeout = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
        realtime ? cfg.plant.safety_status_timeout : std::max(cfg.plant.safety_status_timeout, cfg.plant.lockstep_timeout)));
    const auto republish = std::chrono::milliseconds(10);

    tp::msgs::SensorSample_ sample;
    tp::msgs::ActuatorCommand_ command;
    tp::msgs::ActuatorCommand_ incoming;
    tp::msgs::SupervisorStatus_ status;
    tp::msgs::SupervisorStatus_ incoming_status;
    Clock::time_point status_received{};
    bool have_status = false;
    bool have_command = false;
    std::uint64_t reoffered = 0;  // lockstep cycles offered again after a lost sample
    auto next_brake_report = Clock::now() + std::chrono::seconds(2);
    std::uint64_t last_command_seq = 0;
    bool started = false;      // the chain has answered once
    bool chain_ready = false;  // and the supervisor has seen every stage alive: overruns count from here
    std::uint64_t seq = 0;
    builtin_interfaces::msg::dds_::Time_ origin = runtime::now_stamp();
    std::int64_t origin_ns = runtime::to_nanoseconds(origin);
    fill_sensors(sample, simulator.output(), seq, origin, 1.0 / cable_length_factor);
    sensors->write(sample);
    auto cycle_start = Clock::now();
    auto next_deadline = cycle_start + period;
    spdlog::info("simulating at {} Hz, {} clock, x0 = {} m, gamma0 = {} rad", 1.0 / cfg.plant.sample_period,
                 realtime ? "realtime" : "lockstep", initial_trolley, initial_slew);

    while (!runtime::stop_requested()) {
      // Wait for the command of cycle `seq`.
      bool got = false;
      std::int64_t arrival_ns = 0;
      const auto deadline = realtime ? next_deadline : cycle_start + lockstep_timeout;
      auto next_republish = Clock::now() + republish;
      while (!runtime::stop_requested()) {
        while (actuators->take_next(incoming)) {
          if (!runtime::all_finite(incoming)) {
            ++counters.nonfinite_rejected;
            continue;
          }
          if (incoming.header().seq() == seq) {
            command = incoming;
            got = true;
            arrival_ns = runtime::now_nanoseconds();
          }
        }
        while (safety->take_next(incoming_status)) {
          if (!runtime::all_finite(incoming_status)) {
            ++counters.nonfinite_rejected;
            continue;
          }
          status = incoming_status;
          status_received = Clock::now();
          have_status = true;
          chain_ready = chain_ready || status.stages_alive() == 0x3FU;
        }
        if (got && !realtime) break;
        const auto now = Clock::now();
        if (now >= deadline) break;
        if (!realtime && now >= next_republish) {
          // Lockstep: offer this cycle again until the chain answers. At start-up the stages are
          // still discovering each other; later a best-effort sample was lost on the way. Stages
          // answer a repeated cycle without stepping their cores twice, so the run stays
          // deterministic. Not an overrun unless lockstep_timeout passes.
          if (started) {
            ++reoffered;
          } else {  // start-up: a fresh sample time, so latency counts from when the chain is up
            origin = runtime::now_stamp();
            origin_ns = runtime::to_nanoseconds(origin);
          }
          fill_sensors(sample, simulator.output(), seq, origin, 1.0 / cable_length_factor);
          sensors->write(sample);
          next_republish = now + republish;
        }
        wakeup.wait_until(std::min(deadline, next_republish));
      }
      if (runtime::stop_requested()) break;
      if (!got && !started && !realtime) {  // lockstep start-up: offer the same cycle again
        cycle_start = Clock::now();
        continue;
      }
      // Until the whole chain is matched and alive, a missing command is start-up (the stages still
      // discover each other), not an overrun; brakes are on then anyway.
      const bool count_overrun = !got && started && chain_ready;
      if (got) started = true;

      // A late command is replaced by the last valid one while that is younger than
      // plant.command_timeout (the drive amplifier holds its input); after that: 0 V and brakes.
      if (got) {
        last_command_seq = seq;
        have_command = true;
        latency.record(static_cast<double>(arrival_ns - origin_ns) / 1000.0);
        if (latency_log.size() < latency_log.capacity()) {
          latency_log.push_back(static_cast<double>(arrival_ns - origin_ns) / 1000.0);
        }
      }
      const bool command_valid =
          have_command && static_cast<double>(seq - last_command_seq) * cfg.plant.sample_period <=
                              cfg.plant.command_timeout + 1e-9;
      const bool status_fresh = have_status && Clock::now() - status_received <= status_timeout;
      plant::DriveInput input;  // default: 0 V, brakes engaged
      if (command_valid && status_fresh && status.brakes_released() && status.motion_enabled()) {
        // The supervisor's current limits (lowered near a travel limit: approach margins).
        input.trolley_voltage = std::clamp(command.trolley_voltage(), -status.trolley_voltage_limit(),
                                           status.trolley_voltage_limit());
        input.slew_voltage = std::clamp(command.slew_voltage(), -status.slew_voltage_limit(), status.slew_voltage_limit());
        input.hoist_speed = command.hoist_speed();
        input.brakes_engaged = false;
      }
      if (input.brakes_engaged && Clock::now() >= next_brake_report) {
        // Off the hot path: at most once every 2 s while the brakes stay on.
        next_brake_report = Clock::now() + std::chrono::seconds(2);
        const auto health = safety->health();
        spdlog::info("brakes on at cycle {}: supervisor status {} (matched writers {}, alive {}, samples {}), "
                     "motion {}, command {}",
                     seq, have_status ? (status_fresh ? "fresh" : "stale") : "never received", health.matched_writers,
                     health.alive_writers, health.samples,
                     have_status && status.motion_enabled() ? "enabled" : "disabled",
                     command_valid ? "valid" : "missing");
      }
      if (count_overrun) {
        ++counters.overruns;
        spdlog::warn("overrun: no command for cycle {} within {} ms; {}", seq,
                     realtime ? cfg.plant.sample_period * 1e3 : cfg.plant.lockstep_timeout * 1e3,
                     command_valid ? "the last command is held" : "0 V and brakes for this cycle");
      }
      const auto step_status = simulator.step(input);
      if (step_status != common::StepStatus::ok) {
        spdlog::error("plant step at cycle {} returned status {}", seq, static_cast<int>(step_status));
      }
      ++counters.cycles;
      ++seq;
      counters.last_seq = seq;

      if (realtime) {
        std::this_thread::sleep_until(next_deadline);
        next_deadline += period;
      }
      cycle_start = Clock::now();
      origin = runtime::now_stamp();
      origin_ns = runtime::to_nanoseconds(origin);
      fill_sensors(sample, simulator.output(), seq, origin, 1.0 / cable_length_factor);
      sensors->write(sample);
      diagnostics.maybe_publish(counters, &latency);
    }

    diagnostics.publish_final(counters, &latency);
    spdlog::info("stopping at t = {:.2f} s: {} cycles, {} overruns, {} cycles offered again, {} non-finite commands "
                 "rejected, latency p50 {:.0f} us p99 {:.0f} us max {:.0f} us, {} friction events",
                 simulator.time(), counters.cycles, counters.overruns, reoffered, counters.nonfinite_rejected,
                 latency.percentile(50), latency.percentile(99), latency.maximum(), simulator.friction_event_count());
    if (!stats_path.empty()) {
      std::ofstream out(stats_path);
      out << "{\"cycles\": " << counters.cycles << ", \"overruns\": " << counters.overruns
          << ", \"reoffered\": " << reoffered
          << ", \"nonfinite_rejected\": " << counters.nonfinite_rejected << ", \"latency_us\": [";
      for (std::size_t i = 0; i < latency_log.size(); ++i) out << (i ? "," : "") << latency_log[i];
      out << "]}\n";
    }
  } catch (const std::exception& error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
  return 0;
}
