#include "crane/launch/stack.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <sstream>
#include <stdexcept>

#include "crane/transport/iceoryx_rule.hpp"

namespace crane::launch {

namespace {
std::string number(double value) {
  char buffer[64];
  std::snprintf(buffer, sizeof(buffer), "%.17g", value);
  return buffer;
}

bool is_shm(const std::string& hardware) { return hardware.rfind("shm:", 0) == 0 && hardware.size() > 4; }
bool is_comedi(const std::string& hardware) { return hardware.rfind("comedi:", 0) == 0 && hardware.size() > 7; }

constexpr std::array<const char*, 5> kStages{"friction_compensation", "tracking", "anti_swing", "trajectory_planner",
                                             "state_estimator"};  // the run_stage processes, in start order

bool is_stage(const std::string& name) {
  return std::find(kStages.begin(), kStages.end(), name) != kStages.end();
}
}  // namespace

std::vector<std::string> stack_process_names(const StackOptions& o) {
  std::vector<std::string> names;
  if (o.iceoryx && o.start_roudi) names.push_back(kRoudiProcess);
  names.push_back("supervisor");
  if (o.operator_relay) names.push_back("operator_relay");
  names.insert(names.end(), kStages.begin(), kStages.end());
  if (o.hardware.empty()) {
    names.push_back("plant");
  } else if (is_shm(o.hardware)) {
    names.push_back("plant");  // behind the emulated board: it must exist before the bridge opens it
    names.push_back("hardware_bridge");
  } else if (is_comedi(o.hardware)) {
    names.push_back("hardware_bridge");
  } else {
    throw std::invalid_argument("hardware '" + o.hardware +
                                "' is not a board: use shm:NAME (emulated board, plant behind it) or "
                                "comedi:/dev/comediN (a DAQ board)");
  }
  if (!o.site_jobs.empty()) {
    if (o.site_file.empty() || o.site_crane.empty()) {
      throw std::invalid_argument("a site link (site jobs '" + o.site_jobs + "') needs the site file and the crane's name");
    }
    names.push_back("site_link");
  }
  return names;
}

std::map<std::string, std::string> parse_dds_mix(const std::string& text, const std::vector<std::string>& known) {
  std::map<std::string, std::string> mix;
  std::stringstream entries(text);
  std::string entry;
  while (std::getline(entries, entry, ',')) {
    if (entry.empty()) continue;
    const auto eq = entry.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == entry.size()) {
      throw std::invalid_argument("--dds-mix entry '" + entry + "' is not NAME=VENDOR (e.g. plant=cyclone)");
    }
    const std::string name = entry.substr(0, eq);
    const std::string vendor = entry.substr(eq + 1);
    if (std::find(known.begin(), known.end(), name) == known.end()) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      throw std::invalid_argument("--dds-mix entry '" + entry + "': process '" + name + "' is not one of " + list);
    }
    if (vendor != "fast" && vendor != "cyclone") {  // the --dds values of every process
      throw std::invalid_argument("--dds-mix entry '" + entry + "': vendor '" + vendor + "' must be fast or cyclone");
    }
    if (!mix.emplace(name, vendor).second) {
      throw std::invalid_argument("--dds-mix names process '" + name + "' twice");
    }
  }
  return mix;
}

std::string vendor_of(const StackOptions& o, const std::string& name) {
  const auto found = o.dds_per_process.find(name);
  return found != o.dds_per_process.end() ? found->second : o.dds;
}

std::vector<ProcessSpec> stack_processes(const StackOptions& o) {
  std::vector<ProcessSpec> specs;
  const bool bridge = !o.hardware.empty();
  for (const auto& name : stack_process_names(o)) {
    ProcessSpec spec;
    spec.name = name;
    if (!o.log_directory.empty()) spec.log_path = o.log_directory + "/" + name + ".log";
    if (name == kRoudiProcess) {
      specs.push_back(roudi_process(spec.log_path));
      continue;
    }
    spec.executable = o.binary_directory + "/" + name;
    const auto vendor = vendor_of(o, name);
    if (o.iceoryx) {
      const std::string refusal = transport::iceoryx_refusal(vendor == "cyclone", vendor, o.lan, o.dds_profile,
                                                             o.security_directory);
      if (!refusal.empty()) throw std::invalid_argument("--iceoryx: " + name + ": " + refusal);
    }
    spec.arguments = {"--dds", vendor, "--domain", std::to_string(o.domain_id), "--log-level", o.log_level};
    if (o.iceoryx) spec.arguments.push_back("--iceoryx");
    // The site link reads the crane's config from the site file; it works at normal priority.
    if (name != "site_link") spec.arguments.insert(spec.arguments.begin(), {"--config", o.config_path});
    if (o.lan) spec.arguments.push_back("--lan");
    if (o.site_lan && (name == "supervisor" || name == "site_link")) spec.arguments.push_back("--site-lan");
    if (o.realtime_priority > 0 && name != "site_link") {
      const int offset = name == "plant" || name == "hardware_bridge" ? 10 : name == "supervisor" ? 5 : 0;
      spec.arguments.insert(spec.arguments.end(),
                            {"--realtime-priority", std::to_string(std::min(o.realtime_priority + offset, 99))});
    }
    if (!o.dds_profile.empty()) spec.arguments.insert(spec.arguments.end(), {"--dds-profile", o.dds_profile});
    if (!o.security_directory.empty()) {
      spec.arguments.insert(spec.arguments.end(), {"--security", o.security_directory});
    }
    if (o.insecure_lan) spec.arguments.push_back("--insecure-lan");
    if (name == "plant") {
      spec.arguments.push_back(o.lockstep ? "--lockstep" : "--realtime");
      spec.arguments.insert(spec.arguments.end(), {"--initial-trolley", number(o.initial_trolley_position),
                                                   "--initial-slew", number(o.initial_slew_angle),
                                                   "--initial-bridge", number(o.initial_bridge_position)});
      if (!bridge && !o.plant_stats_path.empty()) {
        spec.arguments.insert(spec.arguments.end(), {"--stats-out", o.plant_stats_path});
      }
      if (o.plant_cable_length_factor != 1.0 || o.plant_load_mass_factor != 1.0 || o.plant_friction_factor != 1.0) {
        spec.arguments.insert(spec.arguments.end(), {"--cable-length-factor", number(o.plant_cable_length_factor),
                                                     "--load-mass-factor", number(o.plant_load_mass_factor),
                                                     "--friction-factor", number(o.plant_friction_factor)});
      }
      if (bridge) spec.arguments.insert(spec.arguments.end(), {"--board", o.hardware});
    }
    if (name == "hardware_bridge") {
      spec.arguments.insert(spec.arguments.end(), {"--board", o.hardware});
      // Behind the emulated board in lockstep, the board's sample clock paces the bridge.
      spec.arguments.insert(spec.arguments.end(), {"--clock", is_shm(o.hardware) && o.lockstep ? "board" : "timer"});
      if (!o.plant_stats_path.empty()) spec.arguments.insert(spec.arguments.end(), {"--stats-out", o.plant_stats_path});
    }
    if (name == "trajectory_planner" && o.lockstep) spec.arguments.push_back("--lockstep");
    if (!o.wake.empty() && (is_stage(name) || name == "plant")) {
      spec.arguments.insert(spec.arguments.end(), {"--wake", o.wake});
    }
    if (name == "friction_compensation" && !o.friction_compensation) spec.arguments.push_back("--disable");
    if (name == "supervisor") {
      if (o.lockstep) spec.arguments.push_back("--lockstep");
      spec.arguments.insert(spec.arguments.end(), {"--sensor-source", bridge ? "bridge" : "plant"});
      if (!o.fault_log_path.empty()) spec.arguments.insert(spec.arguments.end(), {"--fault-log", o.fault_log_path});
      if (!o.site_file.empty()) {
        spec.arguments.insert(spec.arguments.end(), {"--site", o.site_file, "--site-crane", o.site_crane});
      }
    }
    if (name == "site_link") {
      spec.arguments.insert(spec.arguments.end(),
                            {"--site", o.site_file, "--site-crane", o.site_crane, "--jobs", o.site_jobs});
      if (!o.site_summary.empty()) spec.arguments.insert(spec.arguments.end(), {"--summary", o.site_summary});
      if (o.site_slew_speed > 0.0) spec.arguments.insert(spec.arguments.end(), {"--slew-speed", number(o.site_slew_speed)});
    }
    if (name == "anti_swing" && !o.anti_swing_controller.empty()) {
      spec.arguments.insert(spec.arguments.end(), {"--controller", o.anti_swing_controller});
    }
    if (name == "state_estimator" && o.estimator_follower_filter) spec.arguments.push_back("--follower-filter");
    if (name == "tracking" && !o.tracking_controller.empty()) {
      spec.arguments.insert(spec.arguments.end(), {"--controller", o.tracking_controller});
    }
    if (name == "tracking" && o.tracking_acceleration_feedforward) spec.arguments.push_back("--acceleration-feedforward");
    specs.push_back(std::move(spec));
  }
  return specs;
}

}  // namespace crane::launch
