#include "crane/config/stack_config.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "crane/common/validation.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::config {

using common::ConfigError;

namespace {

constexpr double kPi = 3.14159265358979323846;

common::AxisFriction read_friction(YamlSection s) {
  common::AxisFriction f;
  f.viscous_positive = s.number("viscous_positive", 0.0, 100.0);
  f.viscous_negative = s.number("viscous_negative", 0.0, 100.0);
  f.coulomb_positive = s.number("coulomb_positive", 0.0, 10.0);
  f.coulomb_negative = s.number("coulomb_negative", 0.0, 10.0);
  f.static_positive = s.number("static_positive", 0.0, 10.0);
  f.static_negative = s.number("static_negative", 0.0, 10.0);
  s.finish();
  return f;
}

common::CraneParameters read_crane(YamlSection s) {
  common::CraneParameters c;
  c.gravity = s.number("gravity", 9.0, 10.5);
  c.load_mass = s.number("load_mass", 0.0, 1.0e5);
  c.cable_length = s.number("cable_length", 0.05, 200.0);
  c.trolley_drive_mass = s.number("trolley_drive_mass", 1e-3, 1.0e6);
  c.trolley_mass = s.number("trolley_mass", 1e-3, 1.0e6);
  c.jib_inertia = s.number("jib_inertia", 1e-4, 1.0e9);
  c.trolley_drive_gain = s.number("trolley_drive_gain", 1e-3, 1.0e3);
  c.slew_drive_gain = s.number("slew_drive_gain", 1e-3, 1.0e3);
  c.trolley_friction = read_friction(s.child("trolley_friction"));
  c.slew_friction = read_friction(s.child("slew_friction"));
  c.dac_bits = s.integer("dac_bits", 8, 24);
  c.dac_range = s.number("dac_range", 0.1, 100.0);
  c.motor_encoder_lines = s.integer("motor_encoder_lines", 1, 1 << 20);
  c.swing_encoder_lines = s.integer("swing_encoder_lines", 1, 1 << 20);
  c.leadscrew_pitch = s.number("leadscrew_pitch", 1e-6, 1.0);
  c.slew_gear_ratio = s.number("slew_gear_ratio", 1e-3, 1.0e4);
  s.finish();
  common::validate(c, "crane");
  return c;
}

PlantConfig read_plant(YamlSection s) {
  PlantConfig p;
  p.sample_period = s.number("sample_period", 1e-4, 0.1);
  p.relative_tolerance = s.number("relative_tolerance", 1e-14, 1e-3);
  p.absolute_tolerance = s.number("absolute_tolerance", 1e-16, 1e-3);
  p.brake_holding_factor = s.number("brake_holding_factor", 1.0, 1000.0);
  p.hoist_max_acceleration = s.number("hoist_max_acceleration", 1e-3, 100.0);
  p.min_cable_length = s.number("min_cable_length", 0.05, 200.0);
  p.max_cable_length = s.number("max_cable_length", p.min_cable_length, 200.0);
  p.lockstep_hang_timeout = s.number("lockstep_hang_timeout", 0.1, 3600.0);
  p.command_timeout = s.number("command_timeout", 0.0, 1.0);
  p.safety_status_timeout = s.number("safety_status_timeout", 0.01, 10.0);
  s.finish();
  return p;
}

supervisor::SupervisorParams read_supervisor(YamlSection s, double sample_period) {
  supervisor::SupervisorParams p;
  p.sample_period = sample_period;
  p.trolley_min = s.number("trolley_min", -100.0, 100.0);
  p.trolley_max = s.number("trolley_max", -100.0, 100.0);
  p.trolley_approach_margin = s.number("trolley_approach_margin", 0.0, 100.0);
  p.trolley_stop_margin = s.number("trolley_stop_margin", 0.0, 100.0);
  p.trolley_approach_speed = s.number("trolley_approach_speed", 0.0, 100.0);
  p.trolley_max_speed = s.number("trolley_max_speed", 1e-3, 100.0);
  p.slew_min = s.number("slew_min", -100.0, 100.0);
  p.slew_max = s.number("slew_max", -100.0, 100.0);
  p.slew_approach_margin = s.number("slew_approach_margin", 0.0, 100.0);
  p.slew_stop_margin = s.number("slew_stop_margin", 0.0, 100.0);
  p.slew_approach_rate = s.number("slew_approach_rate", 0.0, 100.0);
  p.slew_max_rate = s.number("slew_max_rate", 1e-3, 100.0);
  p.voltage_limit = s.number("voltage_limit", 0.1, 100.0);
  p.approach_voltage_limit = s.number("approach_voltage_limit", 0.0, 100.0);
  p.max_voltage_rate = s.number("max_voltage_rate", 1.0, 1e6);
  p.max_swing = s.number("max_swing", 0.01, 1.5);
  p.stage_timeout = s.number("stage_timeout", 0.005, 5.0);
  p.stage_dead_timeout = s.number("stage_dead_timeout", p.stage_timeout, 60.0);
  p.arm_on_start = s.flag("arm_on_start");
  s.finish();
  supervisor::validate(p);
  return p;
}

state_estimator::StateEstimatorParams read_estimator(YamlSection s, double sample_period) {
  state_estimator::StateEstimatorParams p;
  p.sample_rate = 1.0 / sample_period;
  p.cutoff_frequency = s.number("cutoff_frequency", 1e-3, 0.499 * p.sample_rate);
  const auto kind = s.text("differentiator", {"backward", "al_alaoui_first_order", "al_alaoui_second_order"});
  using state_estimator::DifferentiatorKind;
  p.differentiator = kind == "backward"                ? DifferentiatorKind::backward
                     : kind == "al_alaoui_first_order" ? DifferentiatorKind::al_alaoui_first_order
                                                       : DifferentiatorKind::al_alaoui_second_order;
  s.finish();
  return p;
}

trajectory_planner::TrajectoryPlannerParams read_planner(YamlSection s) {
  trajectory_planner::TrajectoryPlannerParams p;
  p.trolley_min_position = s.number("trolley_min_position", -100.0, 100.0);
  p.trolley_max_position = s.number("trolley_max_position", p.trolley_min_position, 100.0);
  p.slew_min_angle = s.number("slew_min_angle", -20.0 * kPi, 20.0 * kPi);
  p.slew_max_angle = s.number("slew_max_angle", p.slew_min_angle, 20.0 * kPi);
  p.cable_min_length = s.number("cable_min_length", 0.05, 200.0);
  p.cable_max_length = s.number("cable_max_length", p.cable_min_length, 200.0);
  s.finish();
  return p;
}

anti_swing::AntiSwingParams read_anti_swing(YamlSection s, double sample_period, double gravity,
                                            const PlantConfig& plant) {
  anti_swing::AntiSwingParams p;
  const auto kind = s.text("controller", {"none", "pd", "delayed_feedback"});
  using anti_swing::AntiSwingKind;
  p.kind = kind == "none" ? AntiSwingKind::none : kind == "pd" ? AntiSwingKind::pd : AntiSwingKind::delayed_feedback;
  p.pd_proportional_gain = s.number("pd_proportional_gain", -1000.0, 1000.0);
  p.pd_derivative_gain = s.number("pd_derivative_gain", -1000.0, 1000.0);
  p.delay_gain = s.number("delay_gain", -1000.0, 1000.0);
  p.normalized_delay = s.number("normalized_delay", 1e-3, 5.0);
  p.slew_enabled = s.flag("slew_enabled");
  s.finish();
  p.sample_period = sample_period;
  p.gravity = gravity;
  p.min_cable_length = plant.min_cable_length;
  p.max_cable_length = plant.max_cable_length;
  return p;
}

tracking::TrackingParams read_tracking(YamlSection s, const common::CraneParameters& crane, double voltage_limit,
                                       const PlantConfig& plant) {
  // The controller's model is the configured crane (section 3.3: (3.37)-(3.38) need K_m, m_t,
  // m_r, M_r and g).
  tracking::TrackingParams p = tracking::tracking_params_from(crane);
  p.proportional_gain = s.number("proportional_gain", 0.0, 1.0e4);
  p.derivative_gain = s.number("derivative_gain", 0.0, 1.0e3);
  p.min_radius = s.number("min_radius", 1e-3, 100.0);
  p.slew_enabled = s.flag("slew_enabled");
  s.finish();
  p.min_cable_length = plant.min_cable_length;
  p.voltage_limit = voltage_limit;
  return p;
}

friction_compensation::AxisCompensationParams read_compensation_axis(YamlSection s,
                                                                      const common::AxisFriction& friction) {
  friction_compensation::AxisCompensationParams a;
  a.friction = friction;
  a.zero_velocity_band = s.number("zero_velocity_band", 0.0, 10.0);
  a.stiction_slope = s.number("stiction_slope", 1e-3, 1e4);
  const auto source = s.text("velocity_source", {"raw", "filtered"});
  a.velocity_source = source == "raw" ? friction_compensation::VelocitySource::raw
                                      : friction_compensation::VelocitySource::filtered;
  s.finish();
  return a;
}

friction_compensation::FrictionCompensationParams read_compensation(YamlSection s,
                                                                     const common::CraneParameters& crane,
                                                                     double voltage_limit) {
  friction_compensation::FrictionCompensationParams p;
  p.enabled = s.flag("enabled");
  // The compensator's friction model is the configured crane's, (4.12)-(4.16).
  p.trolley = read_compensation_axis(s.child("trolley"), crane.trolley_friction);
  p.slew = read_compensation_axis(s.child("slew"), crane.slew_friction);
  s.finish();
  p.voltage_limit = voltage_limit;
  return p;
}

ManeuverConfig read_maneuver(YamlSection s) {
  ManeuverConfig m;
  m.name = s.text("name");
  if (m.name.empty()) throw ConfigError(s.field("name") + " must not be empty");
  m.initial_trolley_position = s.number("initial_trolley_position", -100.0, 100.0);
  m.initial_slew_angle = s.number("initial_slew_angle_deg", -3600.0, 3600.0) * kPi / 180.0;
  m.trolley_target = s.number("trolley_target", -100.0, 100.0);
  m.slew_target = s.number("slew_target_deg", -3600.0, 3600.0) * kPi / 180.0;
  m.trolley_max_velocity = s.number("trolley_max_velocity", 1e-4, 100.0);
  m.trolley_max_acceleration = s.number("trolley_max_acceleration", 1e-4, 100.0);
  m.slew_max_velocity = s.number("slew_max_velocity", 1e-4, 100.0);
  m.cable_length_target = s.number("cable_length_target", 0.05, 200.0);
  m.slew_max_acceleration = s.number("slew_max_acceleration", 1e-4, 100.0);
  m.duration = s.number("duration", 0.5, 3600.0);
  s.finish();
  return m;
}

HardwareBridgeConfig read_hardware_bridge(YamlSection s, const PlantConfig& plant, double voltage_limit) {
  namespace hb = hardware_bridge;
  HardwareBridgeConfig c;
  c.bridge.sample_period = plant.sample_period;
  c.bridge.max_drive_voltage = voltage_limit;
  c.bridge.watchdog_timeout = s.number("watchdog_timeout", plant.sample_period, 1.0);
  c.bridge.status_timeout = s.number("status_timeout", plant.sample_period, 1.0);
  c.bridge.hoist_speed_limit = s.number("hoist_speed_limit", 1e-3, 100.0);
  c.bridge.hoist_speed_per_volt = s.number("hoist_speed_per_volt", 1e-4, 100.0);
  auto& b = c.board;
  b.counter_bits = s.integer("counter_bits", 2, 32);
  auto comedi = s.child("comedi");
  auto counters = comedi.child("counters");
  for (std::size_t i = 0; i < hb::kCounterCount; ++i) {
    auto channel = counters.child(hb::channel_name(static_cast<hb::CounterChannel>(i)));
    b.counters[i].subdevice = channel.integer("subdevice", 0, 255);
    b.counters[i].channel = channel.integer("channel", 0, 255);
    channel.finish();
  }
  counters.finish();
  auto analog = comedi.child("analog_outputs");
  b.analog_output_subdevice = analog.integer("subdevice", 0, 255);
  b.analog_output_range = analog.integer("range", 0, 255);
  for (std::size_t i = 0; i < hb::kAnalogOutputCount; ++i) {
    b.analog_output_channels[i] = analog.integer(hb::channel_name(static_cast<hb::AnalogOutput>(i)), 0, 255);
  }
  analog.finish();
  auto outputs = comedi.child("digital_outputs");
  b.digital_output_subdevice = outputs.integer("subdevice", 0, 255);
  for (std::size_t i = 0; i < hb::kDigitalOutputCount; ++i) {
    b.digital_output_bits[i] = outputs.integer(hb::line_name(static_cast<hb::DigitalOutput>(i)), 0, 31);
  }
  outputs.finish();
  auto inputs = comedi.child("digital_inputs");
  b.digital_input_subdevice = inputs.integer("subdevice", 0, 255);
  b.digital_inputs_active_low = inputs.flag("active_low");
  for (std::size_t i = 0; i < hb::kDigitalInputCount; ++i) {
    b.digital_input_bits[i] = inputs.integer(hb::line_name(static_cast<hb::DigitalInput>(i)), 0, 31);
  }
  inputs.finish();
  comedi.finish();
  s.finish();
  hb::validate(c.bridge, "hardware_bridge");
  hb::validate(c.board, "hardware_bridge.comedi");
  return c;
}

StackConfig read_stack(YamlSection root) {
  StackConfig c;
  c.crane = read_crane(root.child("crane"));
  c.plant = read_plant(root.child("plant"));
  c.supervisor = read_supervisor(root.child("supervisor"), c.plant.sample_period);
  c.state_estimator = read_estimator(root.child("state_estimator"), c.plant.sample_period);
  c.trajectory_planner = read_planner(root.child("trajectory_planner"));
  c.anti_swing = read_anti_swing(root.child("anti_swing"), c.plant.sample_period, c.crane.gravity, c.plant);
  c.tracking = read_tracking(root.child("tracking"), c.crane, c.supervisor.voltage_limit, c.plant);
  c.friction_compensation =
      read_compensation(root.child("friction_compensation"), c.crane, c.supervisor.voltage_limit);
  c.hardware_bridge =
      read_hardware_bridge(root.child("hardware_bridge"), c.plant, c.supervisor.voltage_limit);
  for (auto& item : root.list("maneuvers")) c.maneuvers.push_back(read_maneuver(item));
  root.finish();
  // Each core validates its own invariants as well (same message format).
  state_estimator::StateEstimator{c.state_estimator};
  anti_swing::AntiSwing{c.anti_swing};
  tracking::TrackingController{c.tracking};
  friction_compensation::FrictionCompensation{c.friction_compensation};
  return c;
}

}  // namespace

StackConfig parse_stack_config(const std::string& yaml_text, const std::string& source_name) {
  try {
    return read_stack(YamlSection(YAML::Load(yaml_text), ""));
  } catch (const YAML::Exception& error) {
    throw ConfigError(source_name + ": YAML syntax error at line " + std::to_string(error.mark.line + 1) + ": " +
                      error.msg);
  } catch (const ConfigError& error) {
    throw ConfigError(source_name + ": " + error.what());
  }
}

StackConfig load_stack_config(const std::string& path) {
  std::ifstream file(path);
  if (!file) throw ConfigError(path + ": cannot be read");
  std::stringstream text;
  text << file.rdbuf();
  return parse_stack_config(text.str(), std::filesystem::path(path).filename().string());
}

}  // namespace crane::config
