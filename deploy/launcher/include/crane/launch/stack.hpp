#pragma once
// The crane stack as a set of processes: which executables, with which arguments. Three modes:
//   simulated (hardware empty): the plant is the sensor writer on the DDS bus;
//   shm:NAME: the hardware bridge is the sensor writer, against the emulated board, with the
//             simulated plant behind the board (hardware-in-the-loop; lockstep uses the board's
//             sample clock);
//   comedi:/dev/comediN: the hardware bridge against a real DAQ board, no plant.

#include <map>
#include <string>
#include <vector>

#include "crane/launch/iceoryx.hpp"
#include "crane/launch/process_group.hpp"

namespace crane::launch {

struct StackOptions {
  std::string config_path;            // YAML configuration, passed to every process
  std::string binary_directory;       // where the stage executables are
  std::string log_directory;          // one <stage>.log per process
  std::string dds{"fast"};            // vendor for every process unless overridden below
  std::map<std::string, std::string> dds_per_process;  // stage name -> vendor
  unsigned domain_id{0};
  bool lan{false};                    // every process with --lan (all interfaces) instead of loopback only
  std::string dds_profile;            // every process with --dds-profile (deploy/dds/*.xml); empty: none
  std::string security_directory;     // every process with --security DIR (its own identity in it); empty: none
  bool insecure_lan{false};           // every process with --insecure-lan (--lan or a profile without security)
  bool lockstep{true};                // plant clock: lockstep (default) or realtime
  double initial_trolley_position{0.25};  // [m]
  double initial_slew_angle{0.0};         // [rad]
  double initial_bridge_position{0.0};    // [m] overhead crane
  bool friction_compensation{true};
  std::string plant_stats_path;       // the sensor writer (plant or hardware_bridge) writes its loop statistics
                                      // (cycles, overruns, latency log) here on exit (optional)
  double plant_cable_length_factor{1.0};  // simulated L = factor * configured L (robustness)
  double plant_load_mass_factor{1.0};     // simulated m = factor * configured m (robustness)
  double plant_friction_factor{1.0};      // every friction coefficient of both simulated drives x factor (robustness)
  std::string log_level{"info"};
  std::string anti_swing_controller;  // anti_swing --controller (none|pd|delay1|delay2|fuzzy); empty: its default
  std::string tracking_controller;    // tracking --controller (tracking|gain_scheduling_partial|gain_scheduling_full);
                                      // empty: its default
  bool tracking_acceleration_feedforward{false};  // tracking --acceleration-feedforward
  bool estimator_follower_filter{false};  // state_estimator --follower-filter (stack::ControllerChoice::follower_filter)
  std::string hardware;               // empty: simulated plant on DDS; shm:NAME or comedi:/dev/comediN: the
                                      // hardware bridge on that board (see the file comment)
  std::string fault_log_path;         // supervisor --fault-log (optional)
  std::string site_file;              // supervisor --site: the crane is on this site (docs/site.md); empty: none
  std::string site_crane;             // supervisor --site-crane: its name in the site file
  std::string site_jobs;              // the crane's job file (crane_site jobs): a site_link process works through it
                                      // under the site service's grants (site_file and site_crane required);
                                      // empty: no site link
  std::string site_summary;           // site_link --summary: its figures as JSON (optional)
  double site_slew_speed{0.0};        // site_link --slew-speed [rad/s]: 0, the crane's rated slew rate
  bool site_lan{false};               // supervisor and site_link --site-lan: the site's domain on every interface,
                                      // the crane's own as `lan` says (a crane on a host of its own)
  bool operator_relay{true};          // the operator relay (supervisor/node/operator_relay_node.cpp): the operator's
                                      // commands (deploy/crane estop, ...) over a local socket to a participant
                                      // already matched with the supervisor; off: they make a participant each
  std::string wake;                   // the chain's --wake (the stages and the plant): listener | thread; empty:
                                      // their default, listener (runtime::ListenerDispatch)
  bool iceoryx{false};                // every process --iceoryx (Cyclone DDS for all; docs/architecture.md,
                                      // "Shared memory")
  bool start_roudi{true};             // with iceoryx: RouDi is the stack's first process (false: it runs
                                      // already, run_beside_roudi())
  int realtime_priority{0};           // > 0: every process --realtime-priority: the sensor writer (plant or
                                      // bridge) this + 10, the supervisor + 5, the chain this (as the
                                      // systemd units); 0: normal priority
};

/// The processes of the stack in start order: with options.iceoryx and start_roudi, RouDi first
/// (iox_roudi; launch/iceoryx.hpp); the
/// supervisor (then the operator relay, when options.operator_relay), the sensor writer (plant or
/// hardware_bridge) last of the chain; with shm:NAME the plant behind the board comes just before
/// the bridge; the site link after all (options.site_jobs). RouDi needs no stop order: stopped with
/// the others, it waits for its clients to exit (it sends them SIGTERM itself).
/// Throws std::invalid_argument for a `hardware` that is neither empty, shm:NAME nor comedi:PATH, for
/// site_jobs without site_file and site_crane, and with options.iceoryx for lan, a dds_profile, a
/// security_directory, a process on another vendor than Cyclone DDS or iox-roudi not on PATH.
std::vector<ProcessSpec> stack_processes(const StackOptions& options);

/// Names of the processes, in the order stack_processes() returns them.
std::vector<std::string> stack_process_names(const StackOptions& options);


/// Parses a vendor mix "plant=cyclone,state_estimator=cyclone" (--dds-mix) into process name ->
/// vendor ("fast" or "cyclone"). `known` lists the names a mix may use. Empty text: empty map.
/// Throws std::invalid_argument naming the entry: not NAME=VENDOR, a name not in `known` (lists
/// them), a vendor not known, a name given twice.
std::map<std::string, std::string> parse_dds_mix(const std::string& text, const std::vector<std::string>& known);

/// The vendor of process `name`: its entry in options.dds_per_process, else options.dds.
std::string vendor_of(const StackOptions& options, const std::string& name);

}  // namespace crane::launch
