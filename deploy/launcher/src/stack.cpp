#include "crane/launch/stack.hpp"

#include <cstdio>

namespace crane::launch {

const std::vector<std::string>& simulated_stage_names() {
  static const std::vector<std::string> names{"supervisor", "friction_compensation", "tracking", "anti_swing",
                                              "trajectory_planner", "state_estimator", "plant"};
  return names;
}

namespace {
std::string number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}
}  // namespace

std::vector<ProcessSpec> simulated_stack(const StackOptions& o) {
  std::vector<ProcessSpec> specs;
  for (const auto& name : simulated_stage_names()) {
    ProcessSpec spec;
    spec.name = name;
    spec.executable = o.binary_directory + "/" + name;
    const auto vendor = o.dds_per_process.count(name) != 0 ? o.dds_per_process.at(name) : o.dds;
    spec.arguments = {"--config", o.config_path, "--dds", vendor, "--domain", std::to_string(o.domain_id),
                      "--log-level", o.log_level};
    if (name == "plant") {
      spec.arguments.push_back(o.lockstep ? "--lockstep" : "--realtime");
      spec.arguments.insert(spec.arguments.end(), {"--initial-trolley", number(o.initial_trolley_position),
                                                   "--initial-slew", number(o.initial_slew_angle)});
      if (!o.plant_stats_path.empty()) spec.arguments.insert(spec.arguments.end(), {"--stats-out", o.plant_stats_path});
      if (o.plant_cable_length_factor != 1.0 || o.plant_load_mass_factor != 1.0) {
        spec.arguments.insert(spec.arguments.end(), {"--cable-length-factor", number(o.plant_cable_length_factor),
                                                     "--load-mass-factor", number(o.plant_load_mass_factor)});
      }
    }
    if (name == "friction_compensation" && !o.friction_compensation) spec.arguments.push_back("--disable");
    if (name == "supervisor" && o.lockstep) spec.arguments.push_back("--lockstep");
    if (name == "anti_swing" && !o.anti_swing_controller.empty()) {
      spec.arguments.insert(spec.arguments.end(), {"--controller", o.anti_swing_controller});
    }
    if (name == "tracking" && !o.tracking_controller.empty()) {
      spec.arguments.insert(spec.arguments.end(), {"--controller", o.tracking_controller});
    }
    if (!o.log_directory.empty()) spec.log_path = o.log_directory + "/" + name + ".log";
    specs.push_back(std::move(spec));
  }
  return specs;
}

}  // namespace crane::launch
