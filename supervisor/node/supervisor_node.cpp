// supervisor process: watches every stage of the chain and owns brakes and motion enable.
// Runs on its own 100 Hz wall-clock timer (absolute deadlines), independent of the data it watches.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
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
  supervisor::StageObservation observe(Clock::time_point now, const transport::ReaderHealth& health,
                                       bool lockstep) const {
    supervisor::StageObservation o;
    o.alive = lockstep ? health.matched_writers > 0 : health.alive_writers > 0;
    o.seconds_since_sample = seen ? std::chrono::duration<double>(now - last_sample).count() : 1e9;
    return o;
  }
};

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
  CLI11_PARSE(app, argc, argv);
  try {
    runtime::configure_logging(options.log_level, "supervisor");
    const config::StackConfig cfg = config::load_stack_config(options.config_path);
    supervisor::SupervisorParams params = cfg.supervisor;
    if (lockstep) params.stage_timeout = params.lockstep_stage_timeout;
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
      in.stages[0] = watched[0].observe(now, sensors->health(), lockstep);
      in.stages[1] = watched[1].observe(now, estimate->health(), lockstep);
      in.stages[2] = watched[2].observe(now, reference->health(), lockstep);
      in.stages[3] = watched[3].observe(now, anti_swing->health(), lockstep);
      in.stages[4] = watched[4].observe(now, linear->health(), lockstep);
      in.stages[5] = watched[5].observe(now, actuators->health(), lockstep);
      in.sensors_valid = watched[0].seen;
      in.trolley_position = last_sensors.trolley_position();
      in.swing_in_plane = last_sensors.swing_in_plane();
      in.swing_out_of_plane = last_sensors.swing_out_of_plane();
      in.emergency_stop_input = last_sensors.emergency_stop_input();
      in.trolley_voltage = last_actuators.trolley_voltage();
      in.slew_voltage = last_actuators.slew_voltage();
      in.sensor_writers = sensors->health().matched_writers;
      in.nonfinite_seen = nonfinite;
      in.move_in_progress = last_reference.phase() == 1;
      tp::msgs::SupervisorCommand_ command;
      while (commands->take_next(command)) {
        if (command.command() >= 1 && command.command() <= 4) in.command = static_cast<supervisor::Command>(command.command());
      }
      core.step(in, out);
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
      status.trolley_voltage_limit(cfg.supervisor.voltage_limit);
      status.slew_voltage_limit(cfg.supervisor.voltage_limit);
      status_writer->write(status);
      ++counters.cycles;
      counters.last_seq = last_sensors.header().seq();

      if (core.newly_raised() != 0) {
        spdlog::warn("fault raised: active=0x{:x} latched=0x{:x} stages_alive=0x{:x} (seq {})", out.active_faults,
                     out.latched_faults, out.stages_alive, counters.last_seq);
        for (std::size_t i = 0; i < supervisor::kStageCount; ++i) {
          if ((out.stages_alive & (1U << i)) == 0) {
            spdlog::warn("  stage {} is silent", supervisor::stage_name(static_cast<supervisor::Stage>(i)));
          }
        }
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
