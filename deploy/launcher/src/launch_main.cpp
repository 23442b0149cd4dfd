// crane_launch: runs the crane stack until Ctrl-C, on the simulated plant (--sim, the default) or
// on a board through the hardware bridge (--hardware comedi:/dev/comediN, or --hardware shm:NAME
// which also starts the simulated plant behind the emulated board). Starts every stage as its own OS process,
// waits until all are matched and alive (the supervisor reports every stage alive), then watches:
// on Ctrl-C (SIGINT/SIGTERM) or on the death of any stage it stops all of them by pid (SIGTERM,
// then SIGKILL after a grace period) and exits. Goals are sent by any DDS participant on
// rt/crane/planner/goal (for example crane_demo, or a ROS 2 node). The crane starts where the
// configuration's first maneuver starts (inside its travel limits, whichever crane), unless
// --initial-trolley, --initial-slew or --initial-bridge say otherwise.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <thread>

#include "crane/launch/process_group.hpp"
#include "crane/launch/stack.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/stack/maneuver_run.hpp"
#include "crane/stack/stack_config.hpp"

int main(int argc, char** argv) {
  using namespace crane;
  namespace tp = transport::topics;
  using Clock = std::chrono::steady_clock;
  CLI::App app{"crane_launch: run the crane stack (each stage its own process) until Ctrl-C"};
  launch::StackOptions stack;
  bool lockstep = false;
  bool no_compensation = false;
  double ready_timeout = 60.0;
  std::string log_dir = "crane-logs";
  bool simulated = false;
  auto* sim_flag = app.add_flag("--sim", simulated, "simulated plant as the sensor writer on DDS (the default)");
  app.add_option("--hardware", stack.hardware,
                 "the hardware bridge on this board: comedi:/dev/comediN (a DAQ board) or shm:NAME (the emulated "
                 "board, with the simulated plant behind it)")
      ->excludes(sim_flag);
  std::string fault_log;
  app.add_option("--fault-log", fault_log, "the supervisor's fault log (JSON lines; default <log-dir>/faults.jsonl)");
  app.add_option("--config", stack.config_path, "crane configuration (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--dds", stack.dds, "DDS vendor of every process: fast | cyclone")
      ->check(CLI::IsMember({"fast", "cyclone"}));
  std::string dds_mix;
  app.add_option("--dds-mix", dds_mix,
                 "vendor per process, overriding --dds, e.g. plant=cyclone,state_estimator=cyclone "
                 "(names: the stack's processes and launcher)");
  app.add_option("--domain", stack.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_option("--dds-profile", stack.dds_profile, "network profile of every process (deploy/dds/*.xml)")
      ->check(CLI::ExistingFile);
  app.add_flag("--lan", stack.lan, "every process uses all network interfaces (monitoring from another machine) "
                                   "instead of loopback only");
  app.add_option("--security", stack.security_directory,
                 "DDS Security material of every process (deploy/crane security init; default: $CRANE_SECURITY), "
                 "each with its own identity")
      ->check(CLI::ExistingDirectory);
  app.add_flag("--iceoryx", stack.iceoryx,
               "the stack's samples through iceoryx shared memory (Cyclone DDS in every process; RouDi started "
               "first; docs/architecture.md, \"Shared memory\")");
  app.add_flag("--insecure-lan", stack.insecure_lan,
               "allow --lan or --dds-profile without --security: anyone on that network can read and command the crane");
  app.add_flag("--lockstep", lockstep, "plant in lockstep (faster than real time) instead of realtime");
  app.add_option("--wake", stack.wake,
                 "the chain's --wake (stages and plant): listener (their default: a cycle runs on the DDS thread "
                 "that delivers its input) | thread (the node's own thread, woken by it)")
      ->check(CLI::IsMember({"listener", "thread"}));
  std::optional<double> initial_trolley, initial_slew, initial_bridge;
  app.add_option("--initial-trolley", initial_trolley,
                 "[m] initial trolley position (default: where the configuration's first maneuver starts)");
  app.add_option("--initial-slew", initial_slew, "[rad] initial slew angle (default: the same)");
  app.add_option("--initial-bridge", initial_bridge, "[m] initial bridge position (overhead crane; default: the same)");
  app.add_flag("--no-friction-compensation", no_compensation, "friction_compensation passes V through");
  std::string controller;
  app.add_option("--controller", controller,
                 "the stack's controllers, as crane_demo names them: follower (minimum-time goals followed in "
                 "closed loop: send them with `deploy/crane move --profile minimum_time`), delay1, delay2, pd, "
                 "none, fuzzy, gain_scheduling_partial, gain_scheduling_full (default: each stage's own)");
  app.add_option("--plant-load-mass-factor", stack.plant_load_mass_factor,
                 "--sim: the simulated load mass is this times the configured one (the controllers assume the "
                 "configuration; the online estimate, state_estimator.adaptation, finds it)")
      ->check(CLI::Range(0.0, 10.0));
  app.add_option("--plant-cable-length-factor", stack.plant_cable_length_factor,
                 "--sim: the simulated pendulum is this times the cable the hoist reports (the controllers assume "
                 "the configured pendulum; the online estimate, state_estimator.swing_length, finds it)")
      ->check(CLI::Range(0.1, 10.0));
  app.add_option("--plant-friction-factor", stack.plant_friction_factor,
                 "--sim: every friction coefficient of both simulated drives is this times the configured one (the "
                 "friction compensation assumes the configuration; the tracking stage estimates the factor along a "
                 "move)")
      ->check(CLI::Range(0.0, 10.0));
  auto* site_option = app.add_option("--site", stack.site_file,
                                     "the crane is on this site (docs/site.md): its supervisor enforces its grant")
                          ->check(CLI::ExistingFile);
  auto* site_crane_option = app.add_option("--site-crane", stack.site_crane, "the crane's name in the site file");
  site_option->needs(site_crane_option);
  site_crane_option->needs(site_option);
  app.add_option("--site-jobs", stack.site_jobs,
                 "the crane's job file (crane_site jobs): a site_link process works through it under the site "
                 "service's grants")
      ->needs(site_option)
      ->check(CLI::ExistingFile);
  app.add_option("--site-summary", stack.site_summary, "the site link's figures as JSON (site_link --summary)");
  app.add_flag("--site-lan", stack.site_lan,
               "the site's domain (the supervisor's guard, the site link) on every interface, the crane's own on "
               "loopback unless --lan: a crane on a host of its own")
      ->needs(site_option);
  app.add_option("--site-slew-speed", stack.site_slew_speed,
                 "[rad/s] the site link's moves slew at most this fast (0: the crane's rated slew rate)")
      ->check(CLI::Range(0.0, 10.0));
  app.add_option("--log-dir", log_dir, "one <stage>.log per process");
  app.add_option("--ready-timeout", ready_timeout, "[s] longest wait for the stack to become ready");
  int realtime_priority = 70;
  app.add_option("--realtime-priority", realtime_priority,
                 "realtime clock: SCHED_FIFO priority of the chain (the sensor writer +10, the supervisor +5) and "
                 "locked memory, where the system allows it; 0: normal priority (lockstep always runs at normal "
                 "priority)")
      ->check(CLI::Range(0, 89));
  CLI11_PARSE(app, argc, argv);
  stack.lockstep = lockstep;
  stack.friction_compensation = !no_compensation;

  try {
    runtime::configure_logging("info", "launch");
    std::filesystem::create_directories(log_dir);
    stack.config_path = std::filesystem::absolute(stack.config_path).string();
    for (std::string* path : {&stack.site_file, &stack.site_jobs, &stack.site_summary}) {
      if (!path->empty()) *path = std::filesystem::absolute(*path).string();
    }
    // The whole configuration, validated before any stage starts (each stage would refuse it too).
    const crane::stack::StackConfig config = crane::stack::load_stack_config(stack.config_path);
    if (!config.maneuvers.empty()) {
      const crane::stack::ManeuverConfig& first = config.maneuvers.front();
      stack.initial_trolley_position = first.initial_trolley_position;
      stack.initial_slew_angle = first.initial_slew_angle;
      stack.initial_bridge_position = first.initial_bridge_position;
    }
    if (!controller.empty()) {  // the demo's names (crane::stack::choose_controller: one place)
      const auto choice = crane::stack::choose_controller(
          controller, config.maneuvers.empty() ? crane::stack::ManeuverConfig{} : config.maneuvers.front(), false);
      stack.anti_swing_controller = std::string(anti_swing::law_name(choice.anti_swing));
      stack.tracking_controller = std::string(tracking::law_name(choice.tracking));
      stack.estimator_follower_filter = choice.follower_filter();
    }
    stack.initial_trolley_position = initial_trolley.value_or(stack.initial_trolley_position);
    stack.initial_slew_angle = initial_slew.value_or(stack.initial_slew_angle);
    stack.initial_bridge_position = initial_bridge.value_or(stack.initial_bridge_position);
    spdlog::info("{} crane ({}), starting at trolley {} m, slew {} rad, bridge {} m", to_string(config.facts.crane_kind),
                 stack.config_path, stack.initial_trolley_position, stack.initial_slew_angle,
                 stack.initial_bridge_position);
    stack.log_directory = std::filesystem::absolute(log_dir).string();
    stack.fault_log_path =
        std::filesystem::absolute(fault_log.empty() ? std::filesystem::path(log_dir) / "faults.jsonl"
                                                     : std::filesystem::path(fault_log)).string();
    stack.binary_directory = launch::executable_directory();
    auto known = launch::stack_process_names(stack);
    known.push_back("launcher");
    stack.dds_per_process = launch::parse_dds_mix(dds_mix, known);

    runtime::NodeOptions node;
    node.dds = launch::vendor_of(stack, "launcher");
    node.domain_id = stack.domain_id;
    node.loopback_only = !stack.lan;
    if (!stack.dds_profile.empty()) stack.dds_profile = std::filesystem::absolute(stack.dds_profile).string();
    node.dds_profile = stack.dds_profile;
    if (stack.security_directory.empty()) {
      if (const char* env = std::getenv("CRANE_SECURITY"); env != nullptr) stack.security_directory = env;
    }
    if (!stack.security_directory.empty()) {
      stack.security_directory = std::filesystem::absolute(stack.security_directory).string();
    }
    node.security_directory = stack.security_directory;
    node.insecure_lan = stack.insecure_lan;
    // Off iceoryx (RouDi, stopped with the stack, ends every client still registered), with the QoS of
    // a stack on it.
    if (stack.iceoryx) node.liveliness = transport::Liveliness::watchdogs;
    // Refused here, before any stage starts (each stage would refuse it too).
    runtime::check_network_security(node.loopback_only, node.dds_profile, node.security_directory, node.insecure_lan);
    if (!lockstep && realtime_priority > 0) {
      // Ask before starting anything: a forked probe tries what every stage will do.
      const std::string failure = launch::probe_realtime(realtime_priority + 10);
      if (failure.empty()) {
        stack.realtime_priority = realtime_priority;
        spdlog::info("stages run at real-time priority: SCHED_FIFO {} (plant/bridge {}, supervisor {}), memory locked",
                     realtime_priority, realtime_priority + 10, realtime_priority + 5);
      } else {
        spdlog::warn("the stages cannot run at real-time priority here ({}; it needs CAP_SYS_NICE or an RLIMIT_RTPRIO, "
                     "and CAP_IPC_LOCK or an RLIMIT_MEMLOCK, as the systemd units give): they run at normal priority, "
                     "and another busy process can make them late",
                     failure);
      }
    }
    auto participant = runtime::make_participant(node, "launcher");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto status_reader = participant->make_reader<tp::SafetyStatus>(&wakeup);

    launch::ProcessGroup group;
    for (const auto& spec : launch::stack_processes(stack)) {
      const pid_t pid = group.start(spec);
      spdlog::info("started {} (pid {}), log {}", spec.name, pid, spec.log_path);
    }
    using Status = protocol::SupervisorStatus;  // its codes: MODE_*, STAGES_ALL
    tp::msgs::SupervisorStatus_ status;
    bool ready = false;
    int exit_code = 0;
    const auto ready_deadline = Clock::now() + std::chrono::duration<double>(ready_timeout);
    auto next_report = Clock::now();
    while (!runtime::stop_requested()) {
      if (auto exit = group.poll()) {
        spdlog::error("{}: stopping the stack", exit->describe());
        exit_code = 1;
        break;
      }
      status_reader->take_latest(status);
      if (!ready && status.stages_alive() == Status::STAGES_ALL) {
        ready = true;
        spdlog::info("all stages matched and alive, supervisor mode {}; Ctrl-C stops the stack",
                     protocol::code_name(Status::kCodes, "MODE", status.mode()));
      }
      if (!ready && Clock::now() > ready_deadline) {
        spdlog::error("the stack did not become ready within {} s (stages alive 0x{:x}); see {}", ready_timeout,
                      status.stages_alive(), log_dir);
        exit_code = 1;
        break;
      }
      if (ready && Clock::now() >= next_report) {
        next_report = Clock::now() + std::chrono::seconds(5);
        spdlog::info("mode {}, stages alive 0x{:x}, latched faults 0x{:x}, cycle {}",
                     protocol::code_name(Status::kCodes, "MODE", status.mode()), status.stages_alive(),
                     status.latched_faults(), status.header().seq());
      }
      wakeup.wait_until(Clock::now() + std::chrono::milliseconds(50));
    }
    // This participant goes first: the stages' participants then leave no one here to remove them
    // (Fast DDS 2.9 can abort when a remote participant is removed while its lease timer fires:
    // docs/architecture.md, "Transport").
    status_reader.reset();
    participant.reset();
    for (const auto& exit : group.stop_all()) spdlog::info("{}", exit.describe());
    return exit_code;
  } catch (const std::exception& error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
}
