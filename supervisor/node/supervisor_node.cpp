// supervisor process: watches every stage of the chain and owns brakes and motion enable.
// Runs on its own 100 Hz wall-clock timer (absolute deadlines), independent of the data it watches.
// Every fault raised or cleared, and every operator command, goes to the log and (with --fault-log)
// to a JSON-lines fault log, flushed line by line; the status topic carries the fault bits, the
// count, the last fault and the answer to the last command.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>

#include "crane/config/stack_config.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/supervisor/supervisor.hpp"

namespace {

using namespace crane;
using transport::topics::msgs::CycleHeader_;
using Clock = std::chrono::steady_clock;

struct Watched {
  Clock::time_point last_sample{};
  bool seen{false};
  std::uint64_t deadline_missed{0};
  // DDS liveliness and deadline events combined with our own receive time (header of supervisor.hpp).
  supervisor::StageObservation observe(Clock::time_point now, const transport::ReaderHealth& health, bool lockstep) {
    supervisor::StageObservation o;
    o.alive = lockstep ? health.matched_writers > 0 : health.alive_writers > 0;
    o.seconds_since_sample = seen ? std::chrono::duration<double>(now - last_sample).count() : 1e9;
    // Deadlines run on the wall clock: meaningless while the plant runs faster than real time.
    o.deadline_missed = !lockstep && seen && health.deadline_missed > deadline_missed;
    deadline_missed = health.deadline_missed;
    return o;
  }
};

// One line of the fault log (JSON): what, when, and the values that explain it.
std::string fault_record(const char* event, std::uint32_t bit, std::uint64_t seq, const supervisor::SupervisorInput& in,
                         const supervisor::SupervisorOutput& out) {
  char buffer[768];
  std::string silent;
  for (std::size_t i = 0; i < supervisor::kStageCount; ++i) {
    if ((out.stages_alive & (1U << i)) == 0) {
      if (!silent.empty()) silent += ",";
      silent += std::string("\"") + supervisor::stage_name(static_cast<supervisor::Stage>(i)) + "\"";
    }
  }
  std::snprintf(buffer, sizeof(buffer),
                "{\"time_ns\": %lld, \"event\": \"%s\", \"fault\": \"%s\", \"bit\": %u, \"seq\": %llu, "
                "\"mode\": \"%s\", \"silent_stages\": [%s], \"trolley_position_m\": %.6g, "
                "\"trolley_velocity_mps\": %.6g, \"slew_angle_rad\": %.6g, \"slew_rate_radps\": %.6g, "
                "\"swing_rad\": [%.6g, %.6g], \"voltage_V\": [%.6g, %.6g], \"sensor_writers\": %d, "
                "\"actuator_writers\": %d, \"sensor_source\": %u, \"limit_switches\": %u, "
                "\"emergency_stop_input\": %s}",
                static_cast<long long>(runtime::now_nanoseconds()), event, supervisor::fault_name(bit), bit,
                static_cast<unsigned long long>(seq), supervisor::mode_name(out.mode), silent.c_str(),
                in.trolley_position, out.trolley_velocity, in.slew_angle, out.slew_rate, in.swing_in_plane,
                in.swing_out_of_plane, in.trolley_voltage, in.slew_voltage, in.sensor_writers, in.actuator_writers,
                static_cast<unsigned>(in.sensor_source), static_cast<unsigned>(in.limit_switches),
                in.emergency_stop_input ? "true" : "false");
  return buffer;
}

template <class ReaderT, class Message>
bool drain(ReaderT& reader, Message& latest, Watched& watched, Clock::time_point now, runtime::LoopCounters& counters,
           bool& nonfinite) {
  Message sample;
  bool any = false;
  while (reader.take_next(sample)) {
    if (!runtime::all_finite(sample)) {
      ++counters.nonfinite_rejected;
      nonfinite = true;
      continue;
    }
    latest = sample;
    watched.last_sample = now;
    watched.seen = true;
    any = true;
  }
  return any;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"supervisor: modes, brakes, limits and watchdogs of the crane stack"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  bool lockstep = false;
  app.add_flag("--lockstep", lockstep,
               "the plant runs in lockstep: a stage is dead after lockstep_stage_timeout of silence, and DDS "
               "liveliness (a wall-clock lease) is not required");
  std::string fault_log_path;
  app.add_option("--fault-log", fault_log_path, "append every fault raised or cleared and every command here "
                                                "(JSON lines, flushed at once)");
  std::string sensor_source = "any";
  app.add_option("--sensor-source", sensor_source,
                 "which sensor writer the launch mode expects: any | plant | bridge (another one is a fault)")
      ->check(CLI::IsMember({"any", "plant", "bridge"}));
  CLI11_PARSE(app, argc, argv);
  try {
    runtime::configure_logging(options.log_level, "supervisor");
    const config::StackConfig cfg = config::load_stack_config(options.config_path);
    supervisor::SupervisorParams params = cfg.supervisor;
    if (lockstep) params.stage_timeout = params.lockstep_stage_timeout;
    params.expected_sensor_source = sensor_source == "plant" ? 1 : sensor_source == "bridge" ? 2 : 0;
    std::ofstream fault_log;
    if (!fault_log_path.empty()) {
      fault_log.open(fault_log_path, std::ios::app);
      if (!fault_log) throw std::runtime_error("cannot open the fault log " + fault_log_path);
    }
    supervisor::Supervisor core(params);

    auto participant = runtime::make_participant(options, "supervisor");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    namespace tp = transport::topics;
    auto sensors = participant->make_reader<tp::Sensors>(nullptr);
    auto estimate = participant->make_reader<tp::StateEstimate>(nullptr);
    auto reference = participant->make_reader<tp::Reference>(nullptr);
    auto anti_swing = participant->make_reader<tp::AntiSwing>(nullptr);
    auto linear = participant->make_reader<tp::LinearCommand>(nullptr);
    auto actuators = participant->make_reader<tp::Actuators>(nullptr);
    auto commands = participant->make_reader<tp::SafetyCommand>(nullptr);
    auto status_writer = participant->make_writer<tp::SafetyStatus>();
    runtime::DiagnosticsPublisher diagnostics(*participant, runtime::ProcessId::supervisor);

    tp::msgs::SensorSample_ last_sensors;
    tp::msgs::CraneState_ last_estimate;
    tp::msgs::Reference_ last_reference;
    tp::msgs::AntiSwingCommand_ last_anti_swing;
    tp::msgs::LinearCommand_ last_linear;
    tp::msgs::ActuatorCommand_ last_actuators;
    std::array<Watched, supervisor::kStageCount> watched{};
    runtime::LoopCounters counters;
    supervisor::SupervisorOutput out;
    supervisor::Mode logged_mode = supervisor::Mode::starting;
    tp::msgs::SupervisorCommand_ command;
    bool pending_command = false;
    std::uint32_t last_request_id = 0;
    std::uint8_t last_request_result = 0;

    const auto period = std::chrono::microseconds(static_cast<long>(cfg.plant.sample_period * 1e6));
    auto next = Clock::now();
    auto next_health_log = next;
    spdlog::info("supervising 6 stages at {} Hz", 1.0 / cfg.plant.sample_period);
    while (!runtime::stop_requested()) {
      next += period;
      std::this_thread::sleep_until(next);
      const auto now = Clock::now();
      if (now - next > period) {
        ++counters.overruns;
        next = now;
      }
      bool nonfinite = false;
      using supervisor::Stage;
      drain(*sensors, last_sensors, watched[static_cast<int>(Stage::sensors)], now, counters, nonfinite);
      drain(*estimate, last_estimate, watched[static_cast<int>(Stage::state_estimator)], now, counters, nonfinite);
      drain(*reference, last_reference, watched[static_cast<int>(Stage::trajectory_planner)], now, counters, nonfinite);
      drain(*anti_swing, last_anti_swing, watched[static_cast<int>(Stage::anti_swing)], now, counters, nonfinite);
      drain(*linear, last_linear, watched[static_cast<int>(Stage::tracking)], now, counters, nonfinite);
      drain(*actuators, last_actuators, watched[static_cast<int>(Stage::friction_compensation)], now, counters,
            nonfinite);

      supervisor::SupervisorInput in;
      const auto sensor_health = sensors->health();
      const auto actuator_health = actuators->health();
      in.stages[0] = watched[0].observe(now, sensor_health, lockstep);
      in.stages[1] = watched[1].observe(now, estimate->health(), lockstep);
      in.stages[2] = watched[2].observe(now, reference->health(), lockstep);
      in.stages[3] = watched[3].observe(now, anti_swing->health(), lockstep);
      in.stages[4] = watched[4].observe(now, linear->health(), lockstep);
      in.stages[5] = watched[5].observe(now, actuator_health, lockstep);
      in.sensors_valid = watched[0].seen;
      in.sensor_seq = last_sensors.header().seq();
      in.sensor_source = last_sensors.source();
      in.trolley_position = last_sensors.trolley_position();
      in.slew_angle = last_sensors.slew_angle();
      in.swing_in_plane = last_sensors.swing_in_plane();
      in.swing_out_of_plane = last_sensors.swing_out_of_plane();
      in.limit_switches = last_sensors.limit_switches();
      in.emergency_stop_input = last_sensors.emergency_stop_input();
      in.actuators_valid = watched[5].seen;
      in.actuator_seq = last_actuators.header().seq();
      in.trolley_voltage = last_actuators.trolley_voltage();
      in.slew_voltage = last_actuators.slew_voltage();
      in.sensor_writers = sensor_health.matched_writers;
      in.actuator_writers = actuator_health.matched_writers;
      in.nonfinite_seen = nonfinite;
      in.move_in_progress = last_reference.phase() == 1;
      // One operator command per cycle; a second one waits for the next cycle (nothing is dropped).
      if (!pending_command && commands->take_next(command)) pending_command = true;
      if (pending_command && command.command() >= 1 && command.command() <= 4) {
        in.command = static_cast<supervisor::Command>(command.command());
      }
      core.step(in, out);
      if (pending_command) {
        pending_command = false;
        last_request_id = command.request_id();
        last_request_result = out.command_refused ? 2 : 1;
        const char* names[] = {"none", "arm", "disarm", "emergency_stop", "reset"};
        const char* name = command.command() <= 4 ? names[command.command()] : "invalid";
        if (out.command_refused) {
          spdlog::warn("command {} (request {}) refused: mode {}, latched faults 0x{:x}, active 0x{:x}, stages "
                       "alive 0x{:x}", name, last_request_id, supervisor::mode_name(out.mode), out.latched_faults,
                       out.active_faults, out.stages_alive);
        } else {
          spdlog::info("command {} (request {}) accepted: mode {}", name, last_request_id,
                       supervisor::mode_name(out.mode));
        }
        if (fault_log.is_open()) {
          fault_log << "{\"time_ns\": " << runtime::now_nanoseconds() << ", \"event\": \"command\", \"command\": \""
                    << name << "\", \"request_id\": " << last_request_id << ", \"result\": \""
                    << (out.command_refused ? "refused" : "accepted") << "\", \"mode\": \""
                    << supervisor::mode_name(out.mode) << "\"}" << std::endl;
        }
      }
      if (out.stages_alive != 0x3FU && now >= next_health_log) {
        next_health_log = now + std::chrono::seconds(2);
        for (std::size_t i = 0; i < supervisor::kStageCount; ++i) {
          spdlog::info("  stage {}: liveliness {}, last sample {:.3f} s ago",
                       supervisor::stage_name(static_cast<supervisor::Stage>(i)), in.stages[i].alive ? "alive" : "lost",
                       in.stages[i].seconds_since_sample);
        }
      }

      tp::msgs::SupervisorStatus_ status;
      runtime::stamp_header(status.header(), last_sensors.header().seq(), last_sensors.header().origin());
      status.mode(static_cast<uint8_t>(out.mode));
      status.motion_enabled(out.motion_enabled);
      status.brakes_released(out.brakes_released);
      status.active_faults(out.active_faults);
      status.latched_faults(out.latched_faults);
      status.fault_count(out.fault_count);
      status.stages_alive(out.stages_alive);
      status.nonfinite_rejected(static_cast<uint32_t>(counters.nonfinite_rejected));
      status.trolley_voltage_limit(out.trolley_voltage_limit);
      status.slew_voltage_limit(out.slew_voltage_limit);
      status.warnings(out.warnings);
      status.last_fault(out.last_fault);
      status.last_fault_seq(out.last_fault_seq);
      status.trolley_velocity(out.trolley_velocity);
      status.slew_rate(out.slew_rate);
      status.last_request_id(last_request_id);
      status.last_request_result(last_request_result);
      status_writer->write(status);
      ++counters.cycles;
      counters.last_seq = last_sensors.header().seq();

      for (int bit = 0; bit < supervisor::kFaultBits; ++bit) {
        const std::uint32_t fault = 1U << bit;
        const bool raised = (core.newly_raised() & fault) != 0;
        const bool cleared = (core.newly_cleared() & fault) != 0;
        if (!raised && !cleared) continue;
        const std::string record = fault_record(raised ? "raised" : "cleared", fault, counters.last_seq, in, out);
        if (raised) {
          spdlog::warn("fault {} raised: {}", supervisor::fault_name(fault), record);
        } else {
          spdlog::info("fault {} cleared (stays latched until reset)", supervisor::fault_name(fault));
        }
        if (fault_log.is_open()) fault_log << record << std::endl;
      }
      if (out.mode != logged_mode) {
        spdlog::info("mode {} -> {}", supervisor::mode_name(logged_mode), supervisor::mode_name(out.mode));
        logged_mode = out.mode;
      }
      diagnostics.maybe_publish(counters, nullptr);
    }
    diagnostics.publish_final(counters, nullptr);
    spdlog::info("stopping: {} cycles, {} overruns, {} non-finite samples rejected", counters.cycles,
                 counters.overruns, counters.nonfinite_rejected);
  } catch (const std::exception& error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
  return 0;
}
