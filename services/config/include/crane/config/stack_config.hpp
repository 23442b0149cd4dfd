#pragma once
// The whole stack's configuration, read from one YAML file (deploy/config/*.yaml).
//
// load_stack_config() reads every section strictly (all fields required, no unknown fields) and
// range-checks each; then each core's own validation runs. Any problem throws
// crane::common::ConfigError whose message starts with the file name and names the field, the
// value and the bound, e.g.
//   "lab.yaml: crane.load_mass = -2 is out of range: must be in [0, 100000]"
//   "lab.yaml: missing field tracking.proportional_gain"

#include <string>
#include <vector>

#include "crane/anti_swing/anti_swing.hpp"
#include "crane/common/crane_parameters.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"
#include "crane/hardware_bridge/board_config.hpp"
#include "crane/hardware_bridge/bridge_core.hpp"
#include "crane/state_estimator/state_estimator.hpp"
#include "crane/supervisor/supervisor.hpp"
#include "crane/tracking/tracking_controller.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::config {

/// Simulated plant settings (plant process).
struct PlantConfig {
  double sample_period{0.01};           // [s]
  double relative_tolerance{1e-8};      // CVODE
  double absolute_tolerance{1e-10};     // CVODE
  double brake_holding_factor{20.0};    // [-] brake holding force / maximum drive force
  double hoist_max_acceleration{0.5};   // [m/s^2]
  double min_cable_length{0.2};         // [m]
  double max_cable_length{2.0};         // [m]
  double lockstep_hang_timeout{5.0};    // [s] lockstep: wall time a cycle may wait for its command and its
                                        // supervisor status before the chain is reported hung (nothing is
                                        // guessed: the cycle keeps waiting)
  double command_timeout{0.03};         // [s] a missing command is replaced by the last one this long
  double safety_status_timeout{0.1};    // [s] brakes on when the supervisor status is older
};

/// Hardware bridge settings: its watchdog and the interface board's channel map.
struct HardwareBridgeConfig {
  hardware_bridge::BridgeParams bridge;   // watchdog and status timeouts, hoist scaling
  hardware_bridge::BoardConfig board;     // counter width, comedi subdevices/channels/bits
};

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
};

struct StackConfig {
  common::CraneParameters crane;
  PlantConfig plant;
  supervisor::SupervisorParams supervisor;
  state_estimator::StateEstimatorParams state_estimator;
  trajectory_planner::TrajectoryPlannerParams trajectory_planner;
  anti_swing::AntiSwingParams anti_swing;
  tracking::TrackingParams tracking;
  friction_compensation::FrictionCompensationParams friction_compensation;
  HardwareBridgeConfig hardware_bridge;
  std::vector<ManeuverConfig> maneuvers;
};

/// Reads and validates `path`. Throws common::ConfigError (see above) on any bad field, and if the
/// file cannot be read or parsed (message names the file, and the line for a YAML syntax error).
StackConfig load_stack_config(const std::string& path);

/// Same, from YAML text (tests); `source_name` prefixes the messages.
StackConfig parse_stack_config(const std::string& yaml_text, const std::string& source_name);

}  // namespace crane::config
