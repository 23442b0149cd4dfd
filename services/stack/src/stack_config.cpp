#include "crane/stack/stack_config.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "crane/common/validation.hpp"
#include "crane/config/config_document.hpp"
#include "crane/trajectory_planner/speed_reference.hpp"

namespace crane::stack {

namespace {

using common::ConfigError;

constexpr double kDelayPeriodsTolerance = 1e-3;  // [swing periods] a config's rounding of the shaper's mean delay

ManeuverConfig read_maneuver(config::YamlSection& s, bool bridge) {
  constexpr double kDeg = std::numbers::pi / 180.0;
  ManeuverConfig m;
  m.name = s.text("name");
  if (m.name.empty()) throw ConfigError(s.field("name") + " must not be empty");
  m.initial_trolley_position = s.number("initial_trolley_position", -100.0, 100.0);
  m.initial_slew_angle = s.number("initial_slew_angle_deg", -3600.0, 3600.0) * kDeg;
  m.trolley_target = s.number("trolley_target", -100.0, 100.0);
  m.slew_target = s.number("slew_target_deg", -3600.0, 3600.0) * kDeg;
  m.trolley_max_velocity = s.number("trolley_max_velocity", 1e-4, 100.0);
  m.trolley_max_acceleration = s.number("trolley_max_acceleration", 1e-4, 100.0);
  m.slew_max_velocity = s.number("slew_max_velocity", 1e-4, 100.0);
  m.cable_length_target = s.number("cable_length_target", 0.05, 200.0);
  m.slew_max_acceleration = s.number("slew_max_acceleration", 1e-4, 100.0);
  m.duration = s.number("duration", 0.5, 3600.0);
  if (bridge) {
    m.initial_bridge_position = s.number("initial_bridge_position", -1000.0, 1000.0);
    m.bridge_target = s.number("bridge_target", -1000.0, 1000.0);
    m.bridge_max_velocity = s.number("bridge_max_velocity", 1e-4, 100.0);
    m.bridge_max_acceleration = s.number("bridge_max_acceleration", 1e-4, 100.0);
  }
  s.finish();
  return m;
}

StackConfig read(const config::ConfigDocument& doc) {
  doc.check_blocks({"stack", "crane", "site", "plant", "actuation", "supervisor", "state_estimator", "trajectory_planner",
                    "anti_swing", "tracking", "friction_compensation", "hardware_bridge", "maneuvers"});
  StackConfig c;
  c.facts = doc.facts();
  c.plant = doc.read("plant", plant::read_params);
  c.actuation = doc.read("actuation", supervisor::read_actuation_params);
  c.supervisor = doc.read("supervisor", supervisor::read_params);
  c.state_estimator = doc.read("state_estimator", state_estimator::read_params);
  c.trajectory_planner = doc.read("trajectory_planner", trajectory_planner::read_params);
  c.anti_swing = doc.read("anti_swing", anti_swing::read_params);
  c.tracking = doc.read("tracking", tracking::read_params);
  c.tracking.estimator = c.state_estimator.estimator;  // the PD law's momentum balance lags as its rates
  c.friction_compensation = doc.read("friction_compensation", friction_compensation::read_params);
  c.hardware_bridge = doc.read("hardware_bridge", [&](config::YamlSection& block, const common::StackFacts& facts) {
    return hardware_bridge::read_params(block, facts, c.actuation);
  });
  // One description of the soft stop: the supervisor's zone guard (and through it the site's
  // stopping model, anti_collision::StoppingData) predicts a shaped stop's extra travel from
  // zone_stop_delay_periods; the planner shapes the stop with manual.shaping. They must agree.
  const auto& manual = c.trajectory_planner.manual;
  const double shaper_delay = trajectory_planner::shaper_delay_periods(manual.shaping, manual.swing_damping_ratio);
  if (!(std::abs(c.supervisor.zone_stop_delay_periods - shaper_delay) <= kDelayPeriodsTolerance)) {
    throw ConfigError(doc.source_name() + ": supervisor.zone_stop_delay_periods = " +
                      common::format_value(c.supervisor.zone_stop_delay_periods) +
                      " does not describe the planner's soft stop: trajectory_planner.manual.shaping = " +
                      trajectory_planner::to_string(manual.shaping) + " delays it by " +
                      common::format_value(shaper_delay) + " swing periods (its mean, sum A_i t_i)");
  }
  c.maneuvers = doc.read_root([](config::YamlSection& root, const common::StackFacts& facts) {
    std::vector<ManeuverConfig> maneuvers;
    const bool bridge = facts.crane_kind == common::CraneKind::overhead;
    for (auto& item : root.list("maneuvers")) maneuvers.push_back(read_maneuver(item, bridge));
    return maneuvers;
  });
  return c;
}

}  // namespace

StackConfig parse_stack_config(const std::string& yaml_text, const std::string& source_name) {
  return read(config::ConfigDocument::parse(yaml_text, source_name));
}

StackConfig load_stack_config(const std::string& path) { return read(config::ConfigDocument::load(path)); }

const ManeuverConfig& find_maneuver(const StackConfig& cfg, const std::string& name) {
  for (const auto& m : cfg.maneuvers) {
    if (m.name == name) return m;
  }
  throw std::out_of_range("no demo maneuver '" + name + "' in the config");
}

}  // namespace crane::stack
