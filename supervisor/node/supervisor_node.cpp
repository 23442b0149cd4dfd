// supervisor process: watches every stage of the chain and owns brakes and motion enable.
//
// Realtime: runs on its own 100 Hz wall-clock timer (absolute deadlines), independent of the data
// it watches; a stage's silence is measured in wall time since its last sample.
// Lockstep (--lockstep): runs once per cycle of the sensor clock, when every stage's output of
// cycle k has arrived (or a stage's writer is gone), and publishes the status of cycle k stamped
// seq = k, which gates cycle k+1 at the plant (computed while the chain computes cycle k+1). A
// stage's silence is counted in cycles, so a slow machine slows the simulation and never faults it;
// a cycle that waits longer than plant.lockstep_hang_timeout is reported as a hung chain, naming the
// stages it waits for. A sensor sample offered again means the plant still waits: the last status
// is sent again.
//
// Every fault raised or cleared, and every operator command, goes to the log and (with --fault-log)
// to a JSON-lines fault log, flushed line by line; the status topic carries the fault bits, the
// count, the last fault and the answer to the last command.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <optional>
#include <span>
#include <string>
#include <thread>

#include "crane/anti_collision/grant_guard.hpp"
#include "crane/anti_collision/site_file.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/config/config_document.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/supervisor/supervisor_stage.hpp"

namespace {

using namespace crane;
using transport::topics::msgs::CycleHeader_;
using Clock = std::chrono::steady_clock;

// This crane's link to its site (--site, --site-crane; docs/site.md, "The crane's own guard"): a
// participant on the site's domain that hears the site service's instructions to this crane and its
// heartbeat, and the crane's guard (anti_collision::GrantGuard) that checks the measured motion
// against the last grant every cycle; the crane's own reports (its site link's) narrow the grant
// to the rest of the path as it reaches each waypoint. Translation and wiring only: the rules are
// the guard's.
class SiteLink {
 public:
  SiteLink(const std::string& site_path, const std::string& crane_name, const runtime::NodeOptions& options,
           bool site_lan)
      : layout_(anti_collision::load_site_layout(site_path)),
        crane_(anti_collision::find_crane(layout_, crane_name)),
        guard_(layout_, crane_ < 0 ? 0 : static_cast<std::size_t>(crane_)) {
    if (crane_ < 0) {
      throw std::runtime_error("--site-crane " + crane_name + ": no crane of that name in " + site_path);
    }
    participant_ = runtime::make_participant(
        runtime::site_domain_options(options, static_cast<std::uint32_t>(layout_.domain_id), site_lan), "supervisor");
    instructions_ = participant_->make_recording_reader<transport::topics::SiteInstruction>(nullptr, 64);
    status_ = participant_->make_reader<transport::topics::SiteStatus>(nullptr);
    reports_ = participant_->make_recording_reader<transport::topics::SiteReport>(nullptr, 64);
    spdlog::info("on site '{}' as {} (crane {} of {}), the site's domain {}: nothing moves before a grant",
                 layout_.name, crane_name, crane_, layout_.cranes.size(), layout_.domain_id);
  }

  /// The guard's answer for the motion measured now (`time` [s], monotonic).
  supervisor::SiteVerdict check(const anti_collision::CraneMotion& motion, double time) {
    transport::topics::msgs::SiteInstruction_ dds_instruction;
    while (instructions_->take_next(dds_instruction)) {
      protocol::SiteInstruction message;
      protocol::from_dds(dds_instruction, message);
      guard_.heard(time);
      if (message.crane != crane_) continue;
      anti_collision::SiteOrder order;
      const std::string why = anti_collision::from_message(message, order);
      if (!why.empty()) {
        spdlog::warn("site instruction ignored: {}", why);
        continue;
      }
      if (message.epoch == epoch_ && order.seq <= seq_) continue;  // sent again
      epoch_ = message.epoch;
      seq_ = order.seq;
      guard_.grant(anti_collision::path_airspace(order.waypoints, layout_.paths), time);
      granted_ = order.waypoints;
      held_count_ = 0;  // the whole grant
      spdlog::info("site grant {} (epoch {}): {} through {} waypoints", order.seq, message.epoch,
                   order.kind == anti_collision::Instruction::Kind::go ? "go" : "yield", order.waypoints.size());
    }
    transport::topics::msgs::SiteStatus_ dds_status;
    while (status_->take_next(dds_status)) guard_.heard(time);
    // The crane's own progress (its site link's reports): moving on this grant, the rest of the
    // path from the last waypoint it reached or from the point of the segment under way it has
    // passed. Taken only when it narrows what the guard holds (anti_collision::narrows: the rest
    // of the granted path, from further along it).
    transport::topics::msgs::SiteReport_ dds_report;
    while (reports_->take_next(dds_report)) {
      if (dds_report.crane() != crane_ || dds_report.state() != protocol::SiteReport::STATE_MOVING ||
          dds_report.instruction_epoch() != epoch_ || dds_report.instruction_seq() != seq_) {
        continue;
      }
      // Read from the message into a fixed array (no allocation in the cycle).
      const std::size_t n = dds_report.waypoint_count();
      if (n == 0 || n > reported_.size() || n > dds_report.waypoint_slew().size() ||
          n > dds_report.waypoint_trolley().size() || n > dds_report.waypoint_cable_length().size()) {
        continue;
      }
      for (std::size_t k = 0; k < n; ++k) {
        reported_[k] = {dds_report.waypoint_slew()[k], dds_report.waypoint_trolley()[k],
                        dds_report.waypoint_cable_length()[k]};
      }
      const std::span<const anti_collision::Pose> reported(reported_.data(), n);
      if (!anti_collision::narrows(granted_, std::span<const anti_collision::Pose>(held_.data(), held_count_), reported)) {
        continue;
      }
      guard_.progress(anti_collision::path_airspace(reported, layout_.paths));
      std::copy(reported.begin(), reported.end(), held_.begin());
      held_count_ = n;
    }
    const anti_collision::GrantCheck c = guard_.check(motion, time);
    // finish_path: the move under way ends at its waypoint inside the grant, sooner than a soft
    // stop would (the planner is left to it).
    const supervisor::SiteVerdict verdict = c.action == anti_collision::GrantAction::emergency_stop
                                                ? supervisor::SiteVerdict::emergency_stop
                                            : c.action == anti_collision::GrantAction::soft_stop
                                                ? supervisor::SiteVerdict::soft_stop
                                                : supervisor::SiteVerdict::proceed;
    if (verdict != last_) {
      // With the motion it judged, so that a stop on a host can be traced afterwards.
      spdlog::info("site guard: {} ({}): slew {:.4f} rad at {:.4f} rad/s, trolley {:.4f} m at {:.4f} m/s, cable {:.4f} m "
                   "at {:.4f} m/s, swing {:.4f} {:.4f} rad; holding {} of {} granted waypoints",
                   anti_collision::to_string(c.action), c.reason, motion.slew, motion.slew_rate, motion.trolley,
                   motion.trolley_velocity, motion.cable_length, motion.cable_rate, motion.swing_in_plane,
                   motion.swing_out_of_plane, held_count_ == 0 ? granted_.size() : held_count_, granted_.size());
      last_ = verdict;
    }
    return verdict;
  }
  /// True when the guard has heard nothing from the site service for the link deadline at `time`
  /// [s], or never: the status says so (WARNING_SITE_UNHEARD), and the crane's site link does not
  /// start before it clears, so that no grant reaches the link that this guard has not heard.
  [[nodiscard]] bool unheard(double time) const noexcept { return guard_.link_lost(time); }

 private:
  anti_collision::SiteLayout layout_;
  int crane_;
  anti_collision::GrantGuard guard_;
  std::unique_ptr<transport::Participant> participant_;
  std::unique_ptr<transport::Reader<transport::topics::SiteInstruction>> instructions_;
  std::unique_ptr<transport::Reader<transport::topics::SiteStatus>> status_;
  std::unique_ptr<transport::Reader<transport::topics::SiteReport>> reports_;
  std::vector<anti_collision::Pose> granted_;  // the last grant's waypoints
  // What the guard holds of it: the rest of the path from a waypoint, or from a point of a segment
  // (held_count_ 0: the whole grant), and the last report read (fixed arrays: no allocation).
  std::array<anti_collision::Pose, anti_collision::Airspace::kMaxBoxes + 1> held_{};
  std::size_t held_count_{0};
  std::array<anti_collision::Pose, anti_collision::Airspace::kMaxBoxes + 1> reported_{};
  std::uint32_t epoch_{0};
  std::uint64_t seq_{0};
  supervisor::SiteVerdict last_{supervisor::SiteVerdict::proceed};
};

struct Watched {
  Clock::time_point last_sample{};
  bool seen{false};
  std::uint64_t last_seq{0};  // cycle of the newest valid sample
  std::uint64_t deadline_missed{0};
  // DDS liveliness and deadline events combined with our own receive time (header of supervisor.hpp).
  // Lockstep: silence in cycles of the sensor clock (`sensor_seq`), liveliness by matching alone.
  supervisor::StageObservation observe(Clock::time_point now, const transport::ReaderHealth& health, bool lockstep,
                                       std::uint64_t sensor_seq, double sample_period) {
    supervisor::StageObservation o;
    o.present = health.matched_writers > 0;
    o.alive = lockstep ? o.present : health.alive_writers > 0;
    if (!seen) {
      o.seconds_since_sample = 1e9;
    } else if (lockstep) {
      o.seconds_since_sample = sensor_seq > last_seq ? static_cast<double>(sensor_seq - last_seq) * sample_period : 0.0;
    } else {
      o.seconds_since_sample = std::chrono::duration<double>(now - last_sample).count();
    }
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

// Lockstep keeps the last few samples of a topic by cycle: the supervisor steps every cycle in
// order, and the plant may already be a cycle ahead.
template <class Message>
using ByCycle = std::array<std::optional<Message>, 8>;

struct Drained {
  bool any{false};     // a valid sample was taken
  bool repeat{false};  // one of them repeated a cycle already held (a lockstep re-offer)
};

template <class ReaderT, class Message>
Drained drain(ReaderT& reader, Message& latest, Watched& watched, Clock::time_point now, runtime::LoopCounters& counters,
              bool& nonfinite, ByCycle<Message>* by_cycle = nullptr) {
  Message sample;
  Drained d;
  while (reader.take_next(sample)) {
    if (runtime::injected_loss()) continue;  // tests only (CRANE_INJECT_LOSS)
    if (!runtime::all_finite(sample)) {
      ++counters.nonfinite_rejected;
      nonfinite = true;
      continue;
    }
    const auto seq = sample.header().seq();
    if (by_cycle != nullptr) {
      auto& slot = (*by_cycle)[seq % by_cycle->size()];
      d.repeat = d.repeat || (slot.has_value() && slot->header().seq() == seq);
      slot = sample;
    }
    d.any = true;
    // Lockstep re-offers repeat a cycle: the newest cycle stays the latest.
    if (watched.seen && seq < watched.last_seq) continue;
    latest = sample;
    watched.last_sample = now;
    watched.last_seq = seq;
    watched.seen = true;
  }
  return d;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"supervisor: modes, brakes, limits and watchdogs of the crane stack"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  bool lockstep = false;
  app.add_flag("--lockstep", lockstep,
               "the plant runs in lockstep: step once per sensor cycle when every stage's output of it has "
               "arrived, count silence in cycles, and require matching instead of DDS liveliness (a wall-clock lease)");
  std::string fault_log_path;
  app.add_option("--fault-log", fault_log_path, "append every fault raised or cleared and every command here "
                                                "(JSON lines, flushed at once)");
  std::string sensor_source = "any";
  app.add_option("--sensor-source", sensor_source,
                 "which sensor writer the launch mode expects: any | plant | bridge (another one is a fault)")
      ->check(CLI::IsMember({"any", "plant", "bridge"}));
  std::string site_path, site_crane;
  auto* site_option = app.add_option("--site", site_path,
                                     "this crane is on a site (docs/site.md): the site file; its guard checks the site "
                                     "service's grant every cycle")
                          ->check(CLI::ExistingFile);
  app.add_option("--site-crane", site_crane, "this crane's name in the site file")->needs(site_option);
  site_option->needs(app.get_option("--site-crane"));
  bool site_lan = false;
  runtime::add_site_network_option(app, site_lan);
  CLI11_PARSE(app, argc, argv);
  try {
    runtime::configure_logging(options.log_level, "supervisor");
    const auto cfg = config::ConfigDocument::load(options.config_path);
    supervisor::SupervisorParams params = cfg.read("supervisor", supervisor::read_params);
    params.expected_sensor_source = sensor_source == "plant"    ? protocol::SensorSample::SOURCE_PLANT
                                    : sensor_source == "bridge" ? protocol::SensorSample::SOURCE_HARDWARE_BRIDGE
                                                                : protocol::SensorSample::SOURCE_UNKNOWN;
    std::ofstream fault_log;
    if (!fault_log_path.empty()) {
      fault_log.open(fault_log_path, std::ios::app);
      if (!fault_log) throw std::runtime_error("cannot open the fault log " + fault_log_path);
    }
    supervisor::SupervisorStage stage(params);
    std::optional<SiteLink> site;
    if (!site_path.empty()) site.emplace(site_path, site_crane, options, site_lan);
    const auto started = Clock::now();

    auto participant = runtime::make_participant(options, "supervisor");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    namespace tp = transport::topics;
    // Lockstep waits on data: woken by the sensor sample (a new cycle, or one offered again) and by
    // the actuator command, the chain's last output of a cycle; the other outputs of the cycle are
    // there by then, or taken at the next poll. Realtime polls on its own timer.
    transport::Wakeup* data_wakeup = lockstep ? &wakeup : nullptr;
    // Lockstep: a few cycles deep, so that no cycle is overwritten before it is supervised (the plant
    // may publish cycle k+1 before every output of cycle k has arrived here).
    const auto reader = [&](auto tag, transport::Wakeup* wake) {
      using Topic = decltype(tag);
      return lockstep ? participant->make_recording_reader<Topic>(wake, 16) : participant->make_reader<Topic>(wake);
    };
    auto sensors = reader(tp::Sensors{}, data_wakeup);
    auto estimate = reader(tp::StateEstimate{}, nullptr);
    auto reference = reader(tp::Reference{}, nullptr);
    auto anti_swing = reader(tp::AntiSwing{}, nullptr);
    auto linear = reader(tp::LinearCommand{}, nullptr);
    auto actuators = reader(tp::Actuators{}, data_wakeup);
    auto commands = participant->make_reader<tp::SafetyCommand>(data_wakeup);
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
    supervisor::Mode logged_mode = supervisor::Mode::starting;
    tp::msgs::SupervisorCommand_ command;
    bool pending_command = false;
    tp::msgs::SupervisorStatus_ status;
    const double dt = cfg.facts().sample_period;
    using supervisor::Stage;

    // Takes every sample that arrived (lockstep: kept by cycle too); says whether a sensor sample
    // did, and whether it repeated a cycle.
    bool nonfinite = false;
    ByCycle<tp::msgs::SensorSample_> sensors_by_cycle;
    ByCycle<tp::msgs::Reference_> references_by_cycle;
    ByCycle<tp::msgs::ActuatorCommand_> actuators_by_cycle;
    const auto drain_all = [&](Clock::time_point now) {
      const auto sensed = drain(*sensors, last_sensors, watched[static_cast<int>(Stage::sensors)], now, counters,
                                nonfinite, lockstep ? &sensors_by_cycle : nullptr);
      drain(*estimate, last_estimate, watched[static_cast<int>(Stage::state_estimator)], now, counters, nonfinite);
      drain(*reference, last_reference, watched[static_cast<int>(Stage::trajectory_planner)], now, counters, nonfinite,
            lockstep ? &references_by_cycle : nullptr);
      drain(*anti_swing, last_anti_swing, watched[static_cast<int>(Stage::anti_swing)], now, counters, nonfinite);
      drain(*linear, last_linear, watched[static_cast<int>(Stage::tracking)], now, counters, nonfinite);
      drain(*actuators, last_actuators, watched[static_cast<int>(Stage::friction_compensation)], now, counters,
            nonfinite, lockstep ? &actuators_by_cycle : nullptr);
      return sensed;
    };
    const auto healths = [&] {
      return std::array<transport::ReaderHealth, supervisor::kStageCount>{
          sensors->health(), estimate->health(), reference->health(), anti_swing->health(), linear->health(),
          actuators->health()};
    };

    // One supervision step on what was observed (the stage object), then the status (stamped with
    // the sensor cycle).
    protocol::SensorSample sensors_plain;
    protocol::ActuatorCommand actuators_plain;
    protocol::Reference reference_plain;
    protocol::SupervisorCommand command_plain;
    protocol::SupervisorStatus status_plain;
    const auto supervise = [&](Clock::time_point now, const std::array<transport::ReaderHealth, supervisor::kStageCount>& h) {
      supervisor::SupervisorCycle cycle;
      cycle.realtime = !lockstep;
      for (std::size_t i = 0; i < supervisor::kStageCount; ++i) {
        cycle.stages[i] = watched[i].observe(now, h[i], lockstep, last_sensors.header().seq(), dt);
      }
      if (watched[static_cast<int>(Stage::sensors)].seen) {
        protocol::from_dds(last_sensors, sensors_plain);
        cycle.sensors = &sensors_plain;
      }
      if (watched[static_cast<int>(Stage::friction_compensation)].seen) {
        protocol::from_dds(last_actuators, actuators_plain);
        cycle.actuators = &actuators_plain;
      }
      if (watched[static_cast<int>(Stage::trajectory_planner)].seen) {
        protocol::from_dds(last_reference, reference_plain);
        cycle.reference = &reference_plain;
      }
      cycle.sensor_writers = h[0].matched_writers;
      cycle.actuator_writers = h[5].matched_writers;
      cycle.nonfinite_seen = nonfinite;
      nonfinite = false;
      cycle.nonfinite_rejected = static_cast<std::uint32_t>(counters.nonfinite_rejected);
      if (site && cycle.sensors != nullptr) {
        // Positions and swing as measured; the speeds the supervisor differentiates (the hoist's
        // too: the estimator's filtered rate lags, and the supervisor does not trust the control
        // processes); the swing rates the estimator gives (0 before its first estimate).
        const bool estimated = watched[static_cast<int>(Stage::state_estimator)].seen;
        anti_collision::CraneMotion motion;
        motion.slew = sensors_plain.slew_angle;
        motion.slew_rate = stage.output().slew_rate;
        motion.trolley = sensors_plain.trolley_position;
        motion.trolley_velocity = stage.output().trolley_velocity;
        motion.cable_length = sensors_plain.cable_length;
        motion.cable_rate = stage.output().cable_rate;
        motion.swing_in_plane = sensors_plain.swing_in_plane;
        motion.swing_out_of_plane = sensors_plain.swing_out_of_plane;
        motion.swing_in_plane_rate = estimated ? last_estimate.swing_in_plane_rate() : 0.0;
        motion.swing_out_of_plane_rate = estimated ? last_estimate.swing_out_of_plane_rate() : 0.0;
        const double site_time = std::chrono::duration<double>(now - started).count();
        cycle.site = site->check(motion, site_time);
        cycle.site_unheard = site->unheard(site_time);
      }
      // One operator command per cycle; a second one waits for the next cycle (nothing is dropped).
      if (!pending_command && commands->take_next(command)) pending_command = true;
      if (pending_command) {
        protocol::from_dds(command, command_plain);
        cycle.command = &command_plain;
      }
      stage.step(cycle, status_plain);
      const supervisor::SupervisorInput& in = stage.input();
      const supervisor::SupervisorOutput& out = stage.output();
      if (pending_command) {
        pending_command = false;
        const auto code = command_plain.command;
        const std::string name(protocol::code_name(protocol::SupervisorCommand::kCodes, "COMMAND", code));
        if (out.command_refused && out.zone_refusal != supervisor::ZoneRefusal::none) {
          spdlog::warn("command {} (request {}) refused: {}", name, status_plain.last_request_id,
                       supervisor::describe(out.zone_refusal, stage.core().params().site, in.command_zone));
        } else if (out.command_refused) {
          spdlog::warn("command {} (request {}) refused: mode {}, latched faults 0x{:x}, active 0x{:x}, stages "
                       "alive 0x{:x}", name, status_plain.last_request_id, supervisor::mode_name(out.mode),
                       out.latched_faults, out.active_faults, out.stages_alive);
        } else {
          spdlog::info("command {} (request {}) accepted: mode {}", name, status_plain.last_request_id,
                       supervisor::mode_name(out.mode));
        }
        if (fault_log.is_open()) {
          fault_log << "{\"time_ns\": " << runtime::now_nanoseconds() << ", \"event\": \"command\", \"command\": \""
                    << name << "\", \"request_id\": " << status_plain.last_request_id << ", \"result\": \""
                    << (out.command_refused ? "refused" : "accepted") << "\", \"mode\": \""
                    << supervisor::mode_name(out.mode) << "\"}" << std::endl;
        }
      }
      protocol::to_dds(status_plain, status);
      status.header().stamp(runtime::now_stamp());
      status_writer->write(status);
      ++counters.cycles;
      counters.last_seq = last_sensors.header().seq();

      for (int bit = 0; bit < supervisor::kFaultBits; ++bit) {
        const std::uint32_t fault = 1U << bit;
        const bool raised = (stage.core().newly_raised() & fault) != 0;
        const bool cleared = (stage.core().newly_cleared() & fault) != 0;
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
      return in;
    };
    const auto log_stages = [&](const supervisor::SupervisorInput& in, const char* why) {
      for (std::size_t i = 0; i < supervisor::kStageCount; ++i) {
        spdlog::info("  stage {}: {}, last sample {} {:.3f} s ago{}", supervisor::stage_name(static_cast<Stage>(i)),
                     in.stages[i].alive ? "alive" : "lost", watched[i].seen ? "of cycle" : "never",
                     in.stages[i].seconds_since_sample, why);
      }
    };

    spdlog::info("supervising 6 stages at {} Hz, {} clock", 1.0 / dt, lockstep ? "lockstep (cycle-driven)" : "realtime");
    auto next_health_log = Clock::now();
    if (lockstep) {
      // Every cycle in order, exactly once: cycle k is supervised when the sensor sample of k and
      // every stage's output of k have arrived (or a stage's writer is gone).
      const auto hang_timeout = std::chrono::duration<double>(cfg.facts().lockstep_hang_timeout);
      std::array<bool, supervisor::kStageCount> was_matched{};
      bool stepped_any = false;
      std::uint64_t stepped_seq = 0;
      tp::msgs::SupervisorStatus_ previous_status;  // of the cycle before the last stepped (the plant may need it)
      bool have_previous_status = false;
      auto waiting_since = Clock::now();
      bool hang_reported = false;
      bool incomplete = false;  // a cycle waits for an output that does not wake us: poll it soon
      while (!runtime::stop_requested()) {
        wakeup.wait_until(Clock::now() + std::chrono::milliseconds(incomplete ? 1 : 20));
        incomplete = false;
        const auto now = Clock::now();
        const auto sensed = drain_all(now);
        if (sensed.repeat && stepped_any) {
          // A re-offered cycle: the plant still waits; answer again with the stored statuses (each of
          // its own cycle, stamped anew).
          if (have_previous_status) {
            runtime::stamp_header(previous_status.header(), previous_status.header().seq(),
                                  previous_status.header().origin());
            status_writer->write(previous_status);
          }
          runtime::stamp_header(status.header(), stepped_seq, status.header().origin());
          status_writer->write(status);
        }
        while (!runtime::stop_requested()) {
          // The next cycle: after the last one supervised, or the oldest one held at start.
          std::optional<std::uint64_t> next;
          if (stepped_any) {
            next = stepped_seq + 1;
          } else {
            for (const auto& s : sensors_by_cycle) {
              if (s && (!next || s->header().seq() < *next)) next = s->header().seq();
            }
          }
          if (!next) break;
          const auto& sensor_slot = sensors_by_cycle[*next % sensors_by_cycle.size()];
          if (!sensor_slot || sensor_slot->header().seq() != *next) break;
          const std::uint64_t k = *next;
          const auto h = healths();
          bool complete = true;
          bool gone = false;
          for (std::size_t i = 1; i < supervisor::kStageCount; ++i) {
            const bool answered = watched[i].seen && watched[i].last_seq >= k;
            complete = complete && answered;
            was_matched[i] = was_matched[i] || h[i].matched_writers > 0;
            gone = gone || (was_matched[i] && h[i].matched_writers == 0 && !answered);
          }
          if (!complete && !gone) {
            // The actuator command of k is there but another output of k is not: it comes without
            // waking us, so look again soon.
            const auto& last = watched[static_cast<int>(Stage::friction_compensation)];
            incomplete = last.seen && last.last_seq >= k;
            if (!hang_reported && now - waiting_since >= hang_timeout) {
              hang_reported = true;
              std::string missing;
              for (std::size_t i = 1; i < supervisor::kStageCount; ++i) {
                if (watched[i].seen && watched[i].last_seq >= k) continue;
                missing += std::string(missing.empty() ? "" : ", ") + supervisor::stage_name(static_cast<Stage>(i));
              }
              spdlog::error("lockstep: cycle {} has waited {:.1f} s for the output of {}: the chain is hung (not a "
                            "crane fault; the cycle keeps waiting)",
                            k, std::chrono::duration<double>(now - waiting_since).count(), missing);
            }
            break;
          }
          // The values of cycle k itself (the plant may already have published k+1).
          last_sensors = *sensor_slot;
          const auto& a = actuators_by_cycle[k % actuators_by_cycle.size()];
          if (a && a->header().seq() == k) last_actuators = *a;
          const auto& r = references_by_cycle[k % references_by_cycle.size()];
          if (r && r->header().seq() == k) last_reference = *r;
          previous_status = status;
          have_previous_status = stepped_any;
          const auto in = supervise(now, h);
          if (gone && now >= next_health_log) {
            next_health_log = now + std::chrono::seconds(2);
            log_stages(in, " (a writer is gone)");
          }
          stepped_any = true;
          stepped_seq = k;
          waiting_since = now;
          hang_reported = false;
        }
        diagnostics.maybe_publish(counters, nullptr);
      }
    } else {
      const auto period = std::chrono::microseconds(static_cast<long>(dt * 1e6));
      auto next = Clock::now();
      while (!runtime::stop_requested()) {
        next += period;
        std::this_thread::sleep_until(next);
        const auto now = Clock::now();
        if (now - next > period) {
          ++counters.overruns;
          next = now;
        }
        drain_all(now);
        const auto in = supervise(now, healths());
        if (stage.output().stages_alive != protocol::SupervisorStatus::STAGES_ALL && now >= next_health_log) {
          next_health_log = now + std::chrono::seconds(2);
          log_stages(in, "");
        }
        diagnostics.maybe_publish(counters, nullptr);
      }
    }
    runtime::leave_realtime();
    diagnostics.publish_final(counters, nullptr);
    spdlog::info("stopping: {} cycles, {} overruns, {} non-finite samples rejected", counters.cycles,
                 counters.overruns, counters.nonfinite_rejected);
  } catch (const std::exception& error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
  return 0;
}
