#pragma once
// The simulated crane stack as a set of processes: which executables, with which arguments.

#include <map>
#include <string>
#include <vector>

#include "crane/launch/process_group.hpp"

namespace crane::launch {

struct StackOptions {
  std::string config_path;            // YAML configuration, passed to every process
  std::string binary_directory;       // where the stage executables are
  std::string log_directory;          // one <stage>.log per process
  std::string dds{"fast"};            // vendor for every process unless overridden below
  std::map<std::string, std::string> dds_per_process;  // stage name -> vendor
  unsigned domain_id{0};
  bool lockstep{true};                // plant clock: lockstep (default) or realtime
  double initial_trolley_position{0.25};  // [m]
  double initial_slew_angle{0.0};         // [rad]
  bool friction_compensation{true};
  std::string plant_stats_path;       // plant writes its loop statistics here on exit (optional)
  double plant_cable_length_factor{1.0};  // simulated L = factor * configured L (robustness)
  double plant_load_mass_factor{1.0};     // simulated m = factor * configured m (robustness)
  std::string log_level{"info"};
  std::string anti_swing_controller;  // anti_swing --controller (none|pd|delay1|delay2|fuzzy); empty: its default
  std::string tracking_controller;    // tracking --controller (tracking|gain_scheduling_partial|gain_scheduling_full);
                                      // empty: its default
};

/// The seven stage processes of the simulated stack (the plant replaces the hardware bridge), in
/// start order: supervisor first, the sensor writer last.
std::vector<ProcessSpec> simulated_stack(const StackOptions& options);

/// Names of the stages, in the order simulated_stack() returns them.
const std::vector<std::string>& simulated_stage_names();

}  // namespace crane::launch
