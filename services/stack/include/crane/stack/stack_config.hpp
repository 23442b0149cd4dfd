#pragma once
// The whole stack's configuration, read from one YAML file (deploy/config/*.yaml): every block by
// its own component's reader (state_estimator::read_params, ...), the shared facts once
// (config::ConfigDocument), the demo maneuvers, and no unknown block. For the launchers, the
// in-process runner and the tests; a single process reads only its own blocks.
//
// Errors: common::ConfigError whose message starts with the file name and names the field, the
// value and the bound, e.g.
//   "lab.yaml: crane.load_mass = -2 is out of range: must be in [0, 100000]"
//   "lab.yaml: missing field tracking.proportional_gain"
// One rule across blocks: supervisor.zone_stop_delay_periods must be the mean delay of the shaper
// of trajectory_planner.manual.shaping (trajectory_planner::shaper_delay_periods, within 1e-3),
// since both describe the one soft stop.

#include <string>
#include <vector>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/common/stack_facts.hpp"
#include "crane/friction_compensation/friction_compensation_stage.hpp"
#include "crane/hardware_bridge/bridge_config.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"
#include "crane/supervisor/supervisor_stage.hpp"
#include "crane/tracking/tracking_stage.hpp"
#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

namespace crane::stack {

/// One demo maneuver (section 3.3.3).
struct ManeuverConfig {
  std::string name;
  double initial_trolley_position{0.25};  // [m]
  double initial_slew_angle{0.0};         // [rad]
  double trolley_target{1.0};             // [m]
  double slew_target{0.0};                // [rad]
  double trolley_max_velocity{0.4982};    // [m/s]
  double trolley_max_acceleration{0.9929};  // [m/s^2]
  double slew_max_velocity{1.0435};       // [rad/s]
  double slew_max_acceleration{2.0796};   // [rad/s^2]
  double cable_length_target{1.0};        // [m] hoisting during the move when it differs from crane.cable_length
  double duration{15.0};                  // [s] recorded after the move starts
  // Overhead crane only (crane.kind = overhead; unknown fields elsewhere):
  double initial_bridge_position{0.0};    // [m]
  double bridge_target{0.0};              // [m]
  double bridge_max_velocity{0.5};        // [m/s]
  double bridge_max_acceleration{0.5};    // [m/s^2]
};

struct StackConfig {
  common::StackFacts facts;                       // stack: and crane:
  plant::SimulatorParameters plant;               // plant: (the configured crane, at rest)
  supervisor::ActuationGateParams actuation;      // actuation: (plant and hardware bridge)
  supervisor::SupervisorParams supervisor;
  state_estimator::StateEstimatorStageParams state_estimator;
  trajectory_planner::TrajectoryPlannerParams trajectory_planner;
  anti_swing::AntiSwingStageParams anti_swing;
  tracking::TrackingStageParams tracking;
  friction_compensation::FrictionCompensationParams friction_compensation;
  hardware_bridge::HardwareBridgeConfig hardware_bridge;
  std::vector<ManeuverConfig> maneuvers;
};

/// Reads and validates `path`. Throws common::ConfigError (see above).
[[nodiscard]] StackConfig load_stack_config(const std::string& path);

/// Same, from YAML text (tests); `source_name` prefixes the messages.
[[nodiscard]] StackConfig parse_stack_config(const std::string& yaml_text, const std::string& source_name);

/// The demo maneuver called `name` of `cfg`. Throws std::out_of_range naming it when there is none.
[[nodiscard]] const ManeuverConfig& find_maneuver(const StackConfig& cfg, const std::string& name);

}  // namespace crane::stack
