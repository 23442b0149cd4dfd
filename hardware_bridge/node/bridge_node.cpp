// hardware_bridge process: the encoder/DAC/digital-IO board on the DDS bus. The sensor writer (and
// the only clock) of the stack when it runs against a crane: at cycle k it reads the counters and
// digital inputs, publishes rt/crane/hw/sensors{seq = k, source = 2}, and writes the outputs for the
// actuator command of cycle k as soon as it arrives (BridgeCore: the actuation gate the simulated
// plant applies too, supervisor/actuation_gate.hpp, then the board's DAC ranges).
//
//   --clock timer  absolute sample_period deadlines on the monotonic clock (a real board);
//   --clock board  the emulated board's sample clock (shm only): each sample the simulated plant
//                  publishes is answered once, so the plant can run in lockstep behind the board.
//                  Times given to BridgeCore are then simulated (k * sample_period), and sample k is
//                  answered only with the command of cycle k gated by the supervisor's status of
//                  cycle k-1 (or without a command when that status reports a dead stage: the
//                  lockstep rules of supervisor::lockstep_may_run); a wait longer than
//                  stack.lockstep_hang_timeout is reported as a hung chain.
//
// Fail-safe: safe outputs (0 V, brakes engaged, drives disabled) are written right after the board
// opens, whenever BridgeCore says so (no valid command for watchdog_timeout, no fresh supervisor
// status, motion disabled, emergency stop input), on SIGINT/SIGTERM and on every exit path,
// including exceptions.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <thread>
#include <vector>

#include "crane/config/config_document.hpp"
#include "crane/hardware_bridge/board.hpp"
#include "crane/hardware_bridge/bridge_config.hpp"
#include "crane/hardware_bridge/bridge_core.hpp"
#include "crane/hardware_bridge/shm_board.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/supervisor/actuation_gate.hpp"
#include "crane/supervisor/supervisor_stage.hpp"

namespace {

using namespace crane;
namespace hb = hardware_bridge;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point epoch, Clock::time_point t) {
  return std::chrono::duration<double>(t - epoch).count();
}

// Writes the safe outputs when it goes out of scope, whatever the exit path.
class SafeOnExit {
 public:
  SafeOnExit(hb::Board& board, const hb::BoardOutputs& safe) : board_(board), safe_(safe) {}
  SafeOnExit(const SafeOnExit&) = delete;
  SafeOnExit& operator=(const SafeOnExit&) = delete;
  ~SafeOnExit() {
    try {
      board_.write_outputs(safe_);
      spdlog::info("outputs safe: 0 V, brakes engaged, drives disabled");
    } catch (const std::exception& error) {
      spdlog::critical("could not write the safe outputs on exit: {}", error.what());
    }
  }

 private:
  hb::Board& board_;
  hb::BoardOutputs safe_;
};

std::unique_ptr<hb::Board> open_with_retry(const std::string& uri, const hb::BoardConfig& config, double timeout) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout));
  for (;;) {
    try {
      return hb::open_board(uri, config);
    } catch (const hb::BoardError& error) {
      // The emulated board appears when the plant behind it starts; a real device does not.
      if (uri.rfind("shm:", 0) != 0 || Clock::now() >= deadline || runtime::stop_requested()) throw;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"hardware_bridge: the crane's encoder/DAC/digital-IO board on the DDS bus, with its own watchdog"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  std::string board_uri;
  std::string clock = "timer";
  double open_timeout = 10.0;
  std::string stats_path;
  app.add_option("--board", board_uri, "comedi:/dev/comediN (a DAQ board) or shm:NAME (the emulated board)")
      ->required();
  app.add_option("--clock", clock, "timer (sample_period deadlines) | board (the emulated board's sample clock)")
      ->check(CLI::IsMember({"timer", "board"}));
  app.add_option("--open-timeout", open_timeout, "[s] wait this long for an emulated board to appear")
      ->check(CLI::Range(0.0, 600.0));
  app.add_option("--stats-out", stats_path, "write loop statistics (JSON) here on exit");
  CLI11_PARSE(app, argc, argv);

  try {
    runtime::configure_logging(options.log_level, "hardware_bridge");
    const auto cfg = config::ConfigDocument::load(options.config_path);
    const auto gate_params = cfg.read("actuation", supervisor::read_actuation_params);
    const auto bridge_config =
        cfg.read("hardware_bridge", [&](config::YamlSection& block, const common::StackFacts& facts) {
          return hb::read_params(block, facts, gate_params);
        });
    if (clock == "board" && board_uri.rfind("shm:", 0) != 0) {
      throw std::invalid_argument("--clock board needs the emulated board (shm:NAME), not " + board_uri);
    }
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto board = open_with_retry(board_uri, bridge_config.board, open_timeout);
    hb::BridgeCore core(bridge_config.bridge, board->analog_ranges());
    board->write_outputs(core.safe_outputs());
    SafeOnExit safe_on_exit(*board, core.safe_outputs());
    auto* shm_board = dynamic_cast<hb::ShmBoard*>(board.get());
    spdlog::info("board {}: {} clock, watchdog {} ms, status timeout {} ms", board->describe(), clock,
                 gate_params.watchdog_timeout * 1e3, gate_params.status_timeout * 1e3);

    auto participant = runtime::make_participant(options, "hardware_bridge");
    auto sensors = participant->make_writer<tp::Sensors>();
    auto actuators = participant->make_reader<tp::Actuators>(&wakeup);
    // A few statuses deep: on the board clock the status of cycle k can follow that of k-1 before
    // this process has taken it, and sample k needs k-1's.
    auto safety = participant->make_recording_reader<tp::SafetyStatus>(&wakeup, 8);
    runtime::DiagnosticsPublisher diagnostics(*participant, runtime::ProcessId::hardware_bridge);
    runtime::LatencyStatistics latency;
    runtime::LoopCounters counters;
    std::vector<double> latency_log;
    latency_log.reserve(1 << 16);

    const hb::EncoderScaling scaling(cfg.facts().crane);
    std::array<hb::CounterUnwrapper, hb::kCounterCount> unwrap{
        hb::CounterUnwrapper(board->counter_bits()), hb::CounterUnwrapper(board->counter_bits()),
        hb::CounterUnwrapper(board->counter_bits()), hb::CounterUnwrapper(board->counter_bits()),
        hb::CounterUnwrapper(board->counter_bits())};
    const hb::BoardAxes axes = bridge_config.board.axes;  // the crane's switches: the slew's or the bridge's
    const double period_s = cfg.facts().sample_period;
    const auto period = std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(period_s));
    const auto hang_timeout =
        std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(cfg.facts().lockstep_hang_timeout));
    const auto republish = std::chrono::milliseconds(10);
    const bool board_clock = clock == "board";
    const auto epoch = Clock::now();

    tp::msgs::SensorSample_ sample;
    tp::msgs::SensorSample_ previous_sample;  // board clock: cycle k-1, offered again with cycle k
    tp::msgs::ActuatorCommand_ incoming;
    tp::msgs::SupervisorStatus_ incoming_status;
    hb::BridgeInput in;
    hb::BridgeOutput out;
    out.board = core.safe_outputs();
    std::uint64_t status_seq = 0;  // cycle of the supervisor status applied last
    std::array<std::optional<tp::msgs::SupervisorStatus_>, 8> recent_statuses;  // board clock: by cycle
    bool board_command = false;    // board clock: a valid command of the current cycle is held
    protocol::ActuatorCommand board_command_plain;
    std::uint64_t seq = 0;
    std::uint64_t tick = 0;
    std::uint64_t stale_commands = 0;  // valid commands for another cycle than the current one
    std::uint64_t rejected_non_finite = 0;   // NaN/Inf in a command, any cycle
    std::uint64_t rejected_out_of_range = 0;  // beyond the hardware ranges, any cycle
    bool started = false;              // a command has arrived once
    hb::SafeStateReason logged_reason = hb::SafeStateReason::none;
    auto next_deadline = Clock::now();

    auto fill_sample = [&](std::uint64_t k) {
      std::array<std::uint32_t, hb::kCounterCount> raw{};
      board->read_counters(raw);
      std::array<std::int64_t, hb::kCounterCount> counts{};
      for (std::size_t i = 0; i < hb::kCounterCount; ++i) counts[i] = unwrap[i].update(raw[i]);
      const std::uint32_t inputs = board->read_digital_inputs();
      const auto m = scaling.measurement(counts, cfg.facts().crane.cable_length);
      runtime::stamp_header(sample.header(), k, runtime::now_stamp());
      sample.source(protocol::SensorSample::SOURCE_HARDWARE_BRIDGE);
      sample.writer_pid(static_cast<std::uint32_t>(getpid()));
      sample.trolley_position(m.trolley_position);
      sample.slew_angle(m.slew_angle);
      sample.swing_in_plane(m.swing_in_plane);
      sample.swing_out_of_plane(m.swing_out_of_plane);
      sample.cable_length(m.cable_length);
      sample.bridge_position(m.bridge_position);
      sample.applied_trolley_voltage(out.applied_trolley_voltage);
      sample.applied_bridge_voltage(out.applied_bridge_voltage);
      sample.applied_slew_voltage(out.applied_slew_voltage);
      sample.applied_hoist_speed(out.applied_hoist_speed);
      sample.brakes_engaged(out.brakes_engaged);
      const bool estop = (inputs >> static_cast<unsigned>(hb::DigitalInput::emergency_stop)) & 1U;
      sample.emergency_stop_input(estop);
      using Switches = protocol::SensorSample;
      constexpr unsigned kLimitSwitches = Switches::SWITCH_TROLLEY_MIN | Switches::SWITCH_TROLLEY_MAX |
                                          Switches::SWITCH_SLEW_MIN | Switches::SWITCH_SLEW_MAX |
                                          Switches::SWITCH_BRIDGE_MIN | Switches::SWITCH_BRIDGE_MAX;
      static_assert(kLimitSwitches == hb::kLimitSwitchMask &&
                        Switches::SWITCH_BRIDGE_MIN == hb::bit(hb::DigitalInput::bridge_min_limit) &&
                        Switches::SWITCH_BRIDGE_MAX == hb::bit(hb::DigitalInput::bridge_max_limit) &&
                        Switches::SWITCH_SLEW_MAX == hb::bit(hb::DigitalInput::slew_max_limit),
                    "the board's limit-switch inputs are laid out as SensorSample_.limit_switches");
      sample.limit_switches(static_cast<std::uint8_t>(inputs & hb::limit_switch_mask(axes)));
      in.emergency_stop_pressed = estop;
    };
    // Takes what arrived; returns true once a valid command for cycle k went to the board.
    auto drain = [&](std::uint64_t k, double now_s) {
      while (safety->take_next(incoming_status)) {
        if (!runtime::all_finite(incoming_status)) {
          ++counters.nonfinite_rejected;
          continue;
        }
        if (board_clock) {  // kept by cycle: the status of cycle k-1 gates sample k (board_step)
          recent_statuses[incoming_status.header().seq() % recent_statuses.size()] = incoming_status;
          continue;
        }
        in.status_received = true;
        in.status.motion_enabled = incoming_status.motion_enabled();
        in.status.brakes_released = incoming_status.brakes_released();
        in.status.trolley_voltage_limit = incoming_status.trolley_voltage_limit();
        in.status.slew_voltage_limit = incoming_status.slew_voltage_limit();
        in.status.bridge_voltage_limit = incoming_status.bridge_voltage_limit();
        in.status_arrival_time = now_s;
        status_seq = incoming_status.header().seq();
      }
      bool applied = false;
      while (actuators->take_next(incoming)) {
        // Every command is checked where it enters, whatever cycle it claims (BridgeCore checks the
        // one it applies again).
        if (!runtime::all_finite(incoming)) {
          ++rejected_non_finite;
          ++counters.nonfinite_rejected;
          continue;
        }
        const auto& limits = gate_params;
        if (std::fabs(incoming.trolley_voltage()) > limits.max_drive_voltage ||
            std::fabs(incoming.slew_voltage()) > limits.max_drive_voltage ||
            std::fabs(incoming.bridge_voltage()) > limits.max_drive_voltage ||
            std::fabs(incoming.hoist_speed()) > limits.hoist_speed_limit) {
          ++rejected_out_of_range;
          continue;
        }
        if (incoming.header().seq() != k) {
          ++stale_commands;
          continue;
        }
        const std::int64_t arrival_ns = runtime::now_nanoseconds();
        in.time = now_s;
        in.command_received = true;
        in.command = {incoming.trolley_voltage(), incoming.slew_voltage(), incoming.hoist_speed(), incoming.bridge_voltage()};
        in.command_arrival_time = now_s;
        if (board_clock) {  // applied once the status of this cycle is there (board_step below)
          board_command = true;
          protocol::from_dds(incoming, board_command_plain);
          const double us = static_cast<double>(arrival_ns - runtime::to_nanoseconds(sample.header().origin())) / 1000.0;
          latency.record(us);
          if (latency_log.size() < latency_log.capacity()) latency_log.push_back(us);
          continue;
        }
        const auto status = core.step(in, out);
        in.command_received = false;
        if (status != hb::CommandStatus::accepted) {
          ++counters.nonfinite_rejected;  // counted by reason in core.counters()
          continue;                       // a valid command for this cycle may still come
        }
        board->write_outputs(out.board);
        applied = true;
        started = true;
        const double us = static_cast<double>(arrival_ns - runtime::to_nanoseconds(sample.header().origin())) / 1000.0;
        latency.record(us);
        if (latency_log.size() < latency_log.capacity()) latency_log.push_back(us);
      }
      return applied;
    };
    auto step_without_command = [&](double now_s) {
      in.time = now_s;
      in.command_received = false;
      (void)core.step(in, out);
      board->write_outputs(out.board);
    };
    // Board clock (lockstep, as the plant on DDS): sample k is answered with the command of cycle k
    // gated by the supervisor's status of cycle k-1 (sample 0: of cycle 0), or without a command
    // when that status reports a dead stage. That status is fresh in simulated time.
    // The status that gates sample k, when it has arrived (nullptr otherwise).
    auto gating_status = [&](std::uint64_t k) -> const tp::msgs::SupervisorStatus_* {
      const std::uint64_t gate_seq = supervisor::gating_cycle(k);
      const auto& slot = recent_statuses[gate_seq % recent_statuses.size()];
      return slot.has_value() && slot->header().seq() == gate_seq ? &*slot : nullptr;
    };
    auto board_step = [&](std::uint64_t k) {
      const auto* gate = gating_status(k);
      if (gate == nullptr) return false;
      protocol::SupervisorStatus gating;
      protocol::from_dds(*gate, gating);
      status_seq = gating.header.seq;
      // Only a dead stage (stage_silent latched) lets a sample pass without the chain's command.
      if (!supervisor::lockstep_may_run(board_command, gating)) return false;
      in = supervisor::lockstep_gate_input(k, period_s, board_command ? &board_command_plain : nullptr, gating,
                                           in.emergency_stop_pressed);
      const auto status = core.step(in, out);
      in.command_received = false;
      board_command = false;
      if (status != hb::CommandStatus::accepted && status != hb::CommandStatus::none_received) {
        ++counters.nonfinite_rejected;  // counted by reason in core.counters()
      }
      board->write_outputs(out.board);
      started = started || status == hb::CommandStatus::accepted;
      return true;
    };

    while (!runtime::stop_requested()) {
      double now_s = 0.0;
      Clock::time_point cycle_deadline;
      if (board_clock) {
        if (!shm_board->wait_for_sample(tick, Clock::now() + std::chrono::milliseconds(100), tick)) {
          if (shm_board->emulator_closed()) {
            spdlog::warn("the emulated board was closed (the plant stopped)");
            break;
          }
          continue;
        }
        now_s = static_cast<double>(seq) * period_s;
        cycle_deadline = Clock::time_point::max();
      } else {
        next_deadline += period;
        now_s = seconds_since(epoch, Clock::now());
        cycle_deadline = next_deadline;
      }
      fill_sample(seq);
      sensors->write(sample);
      bool applied = false;
      auto next_republish = Clock::now() + republish;
      const auto wait_start = Clock::now();
      bool hang_reported = false;
      while (!runtime::stop_requested()) {
        applied = drain(seq, board_clock ? now_s : seconds_since(epoch, Clock::now()));
        if (board_clock) applied = board_step(seq);
        if (applied) break;
        const auto now = Clock::now();
        if (board_clock && now >= next_republish) {
          // As the plant in lockstep: offer the cycle again until the chain answers (start-up, or a
          // best-effort sample lost); every stage answers a repeated cycle from its stored output.
          if (seq > 0) {  // the previous cycle first: the supervisor may still lack it (it gates this one)
            previous_sample.header().stamp(runtime::now_stamp());
            sensors->write(previous_sample);
          }
          runtime::stamp_header(sample.header(), seq, runtime::now_stamp());
          sensors->write(sample);
          next_republish = now + republish;
          if (started && !hang_reported && now - wait_start >= hang_timeout) {
            hang_reported = true;
            ++counters.overruns;
            spdlog::error("lockstep: cycle {} has waited {} s for {}: the chain is hung (the cycle keeps waiting)", seq,
                          cfg.facts().lockstep_hang_timeout,
                          gating_status(seq) == nullptr ? "the supervisor status" : "the actuator command");
          }
        }
        if (now >= cycle_deadline) break;
        wakeup.wait_until(std::min(cycle_deadline, next_republish));
      }
      if (runtime::stop_requested()) break;
      double late_ms = 0.0;  // [ms] how late this cycle's step ran after its deadline (timer clock)
      if (!applied) {
        if (started) ++counters.overruns;
        const auto step_time = Clock::now();
        if (!board_clock) late_ms = std::chrono::duration<double, std::milli>(step_time - cycle_deadline).count();
        step_without_command(board_clock ? now_s : seconds_since(epoch, step_time));
      }
      if (out.safe_state_reason != logged_reason) {
        if (out.safe_state_reason == hb::SafeStateReason::none) {
          spdlog::info("cycle {}: commands applied, brakes released", seq);
        } else if (started) {
          // The gate's rule on this process's clock: a punctual cycle trips on a command at most
          // watchdog_timeout old; a late wake-up (the OS's) adds its lateness. Another reason (a stale
          // or disabling status) may come first; the age is printed for every reason.
          spdlog::warn("cycle {}: outputs safe ({}): last valid command {:.2f} ms old, this cycle {:.2f} ms late", seq,
                       hb::reason_name(out.safe_state_reason), (in.time - core.last_command_arrival()) * 1e3, late_ms);
        } else {
          spdlog::warn("cycle {}: outputs safe ({})", seq, hb::reason_name(out.safe_state_reason));
        }
        logged_reason = out.safe_state_reason;
      }
      ++counters.cycles;
      counters.last_seq = seq;
      previous_sample = sample;
      ++seq;
      diagnostics.maybe_publish(counters, &latency);
      if (!board_clock) std::this_thread::sleep_until(next_deadline);
    }

    // Stopping (signal, or the emulated board closed): safe outputs first, then the bookkeeping.
    board->write_outputs(core.safe_outputs());
    runtime::leave_realtime();
    spdlog::info("outputs safe: 0 V, brakes engaged, drives disabled");
    diagnostics.publish_final(counters, &latency);
    const auto& c = core.counters();
    spdlog::info("stopping: {} cycles, {} overruns, {} commands accepted, rejected {} non-finite and {} out of range, "
                 "{} stale, {} watchdog trips, {} safe cycles, latency p50 {:.0f} us p99 {:.0f} us max {:.0f} us",
                 counters.cycles, counters.overruns, c.accepted_commands,
                 rejected_non_finite + c.rejected_commands.non_finite,
                 rejected_out_of_range + c.rejected_commands.out_of_range, stale_commands, c.watchdog_trips, c.safe_cycles,
                 latency.percentile(50), latency.percentile(99), latency.maximum());
    if (!stats_path.empty()) {
      std::ofstream stats(stats_path);
      stats << "{\"cycles\": " << counters.cycles << ", \"overruns\": " << counters.overruns
            << ", \"accepted_commands\": " << c.accepted_commands
            << ", \"rejected_non_finite\": " << rejected_non_finite + c.rejected_commands.non_finite
            << ", \"rejected_out_of_range\": " << rejected_out_of_range + c.rejected_commands.out_of_range
            << ", \"stale_commands\": " << stale_commands
            << ", \"watchdog_trips\": " << c.watchdog_trips << ", \"safe_cycles\": " << c.safe_cycles
            << ", \"latency_us\": [";
      for (std::size_t i = 0; i < latency_log.size(); ++i) stats << (i ? "," : "") << latency_log[i];
      stats << "]}\n";
    }
  } catch (const std::exception& error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
  return 0;
}
