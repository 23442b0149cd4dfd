#include "crane/supervisor/supervisor.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <string>
#include <string_view>

#include "crane/common/validation.hpp"

namespace crane::supervisor {

const char* stage_name(Stage stage) noexcept {
  return protocol::code_name(StatusCodes::kCodes, "STAGE", 1U << static_cast<unsigned>(stage)).data();
}

const char* mode_name(Mode mode) noexcept {
  return protocol::code_name(StatusCodes::kCodes, "MODE", static_cast<std::uint64_t>(mode)).data();
}

const char* fault_name(std::uint32_t fault_bit) noexcept {
  return protocol::code_name(StatusCodes::kCodes, "FAULT", fault_bit).data();
}

const char* operating_mode_name(std::uint8_t code) noexcept {
  return protocol::code_name(StatusCodes::kCodes, "OPERATION", code).data();
}

namespace {

void validate_axis(const char* prefix, const char* speed_name, const AxisLimits& a) {
  using common::require_in_range;
  const std::string p = std::string("supervisor.") + prefix;
  const double span = a.max - a.min;
  require_in_range(p + "_approach_margin", a.approach_margin, 0.0, 0.5 * span);
  require_in_range(p + "_stop_margin", a.stop_margin, 0.0, a.approach_margin);
  require_in_range(p + "_" + speed_name, a.max_speed, 1e-3, 1e3);
  require_in_range(p + "_approach_" + (speed_name == std::string("max_speed") ? "speed" : "rate"), a.approach_speed,
                   0.0, a.max_speed);
}

struct AxisVerdict {
  bool range_fault{false};     // outside the hard limits, or inside the stop margin moving toward one
  bool overspeed{false};
  bool approaching{false};     // inside the approach margin, moving toward the limit
  bool speed_limited{false};   // and faster than the approach speed allows there
};

// Travel/slew limiter with approach margins (header: "approach margins").
AxisVerdict check_axis(const AxisLimits& a, double position, double velocity) noexcept {
  AxisVerdict v;
  if (position < a.min || position > a.max) v.range_fault = true;
  if (std::fabs(velocity) > a.max_speed) v.overspeed = true;
  // "Moving toward": faster than a tenth of the approach speed (encoder quantization and the
  // friction compensator's dither at rest stay below it).
  const double moving = 0.1 * std::max(a.approach_speed, 1e-6);
  double distance = 1e300;
  if (velocity > moving) distance = a.max - position;
  if (velocity < -moving) distance = position - a.min;
  if (distance < a.stop_margin) v.range_fault = true;
  if (distance < a.approach_margin) {
    v.approaching = true;
    const double width = a.approach_margin - a.stop_margin;
    const double fraction = width > 0.0 ? std::clamp((distance - a.stop_margin) / width, 0.0, 1.0) : 0.0;
    const double allowed = a.approach_speed + (a.max_speed - a.approach_speed) * fraction;
    if (std::fabs(velocity) > allowed) v.speed_limited = true;
  }
  return v;
}

}  // namespace

void validate(const SupervisorParams& p) {
  using common::require_in_range;
  require_in_range("supervisor.trolley_min", p.trolley_min, -100.0, 100.0);
  require_in_range("supervisor.trolley_max", p.trolley_max, p.trolley_min + 1e-3, 100.0);
  validate_axis("trolley", "max_speed", p.trolley());
  if (p.slew_enabled) {
    require_in_range("supervisor.slew_min", p.slew_min, -100.0, 100.0);
    require_in_range("supervisor.slew_max", p.slew_max, p.slew_min + 1e-3, 100.0);
    validate_axis("slew", "max_rate", p.slew());
    require_in_range("supervisor.slew_braking_deceleration", p.slew_braking_deceleration, 1e-3, 1e3);
  }
  if (p.bridge_enabled) {
    require_in_range("supervisor.bridge_min", p.bridge_min, -1000.0, 1000.0);
    require_in_range("supervisor.bridge_max", p.bridge_max, p.bridge_min + 1e-3, 1000.0);
    validate_axis("bridge", "max_speed", p.bridge());
  }
  require_in_range("supervisor.voltage_limit", p.voltage_limit, 0.1, 100.0);
  require_in_range("supervisor.approach_voltage_limit", p.approach_voltage_limit, 0.0, p.voltage_limit);
  require_in_range("supervisor.max_voltage_rate", p.max_voltage_rate, 1.0, 1e6);
  require_in_range("supervisor.max_swing", p.max_swing, 0.01, 1.5);
  require_in_range("supervisor.stage_timeout", p.stage_timeout, 0.005, 5.0);
  require_in_range("supervisor.stage_dead_timeout", p.stage_dead_timeout, p.stage_timeout, 60.0);
  require_in_range("supervisor.sample_period", p.sample_period, 1e-4, 1.0);
  require_in_range("supervisor.expected_sensor_source", p.expected_sensor_source, 0.0, 2.0);
  require_in_range("supervisor.trolley_braking_deceleration", p.trolley_braking_deceleration, 1e-3, 1e3);
  common::validate(p.site, "site");
}

Supervisor::Supervisor(const SupervisorParams& params) : params_(params) {
  validate(params_);
  zones_enabled_ = params_.site.enabled_at_start();
}

void Supervisor::step(const SupervisorInput& in, SupervisorOutput& out) noexcept {
  std::uint32_t alive_mask = 0;
  std::uint32_t dead_mask = 0;
  std::uint32_t warnings = 0;
  out.zone = -1;
  for (std::size_t i = 0; i < kStageCount; ++i) {
    const auto& s = in.stages[i];
    const bool fresh = s.alive && s.present && s.seconds_since_sample <= params_.stage_timeout;
    const bool dead = !s.present || !(s.seconds_since_sample <= params_.stage_dead_timeout);
    if (fresh) alive_mask |= 1U << i;
    if (dead) dead_mask |= 1U << i;
    if (s.deadline_missed || (!fresh && !dead)) warnings |= kWarningStageLate;
  }
  const std::uint32_t all_alive = (1U << kStageCount) - 1U;
  const bool chain_healthy = alive_mask == all_alive;

  // Velocities from the sensor stream itself (seq differences), not from the state estimator.
  const bool finite_sensors =
      std::isfinite(in.trolley_position) && std::isfinite(in.slew_angle) && std::isfinite(in.bridge_position);
  if (in.sensors_valid && finite_sensors) {
    if (have_previous_sample_ && in.sensor_seq > previous_sensor_seq_) {
      const double dt = static_cast<double>(in.sensor_seq - previous_sensor_seq_) * params_.sample_period;
      trolley_velocity_ = (in.trolley_position - previous_trolley_) / dt;
      slew_rate_ = (in.slew_angle - previous_slew_) / dt;
      // Consecutive samples over the speed limit (kOverspeedSamples in the header).
      trolley_overspeed_samples_ = std::fabs(trolley_velocity_) > params_.trolley().max_speed ? trolley_overspeed_samples_ + 1 : 0;
      slew_overspeed_samples_ = std::fabs(slew_rate_) > params_.slew().max_speed ? slew_overspeed_samples_ + 1 : 0;
      bridge_velocity_ = (in.bridge_position - previous_bridge_) / dt;
      bridge_overspeed_samples_ = std::fabs(bridge_velocity_) > params_.bridge().max_speed ? bridge_overspeed_samples_ + 1 : 0;
    } else if (!have_previous_sample_ || in.sensor_seq < previous_sensor_seq_) {
      trolley_velocity_ = 0.0;  // first sample, or the sensor writer restarted
      slew_rate_ = 0.0;
      trolley_overspeed_samples_ = 0;
      slew_overspeed_samples_ = 0;
      bridge_velocity_ = 0.0;
      bridge_overspeed_samples_ = 0;
    }
    have_previous_sample_ = true;
    previous_sensor_seq_ = in.sensor_seq;
    previous_trolley_ = in.trolley_position;
    previous_slew_ = in.slew_angle;
    previous_bridge_ = in.bridge_position;
  }

  std::uint32_t active = 0;
  // A stage that dies after the chain was up is a fault; during start-up it only keeps us waiting.
  // A late stage only inhibits motion while it is late (below).
  if (dead_mask != 0 && chain_was_up_) active |= kFaultStageSilent;
  chain_was_up_ = chain_was_up_ || chain_healthy;
  double trolley_limit = params_.voltage_limit;
  double slew_limit = params_.slew_enabled ? params_.voltage_limit : 0.0;
  double bridge_limit = params_.bridge_enabled ? params_.voltage_limit : 0.0;
  if (in.sensors_valid && finite_sensors) {
    if (params_.bridge_enabled) {
      const AxisVerdict bridge = check_axis(params_.bridge(), in.bridge_position, bridge_velocity_);
      if (bridge.range_fault) active |= kFaultBridgeTravel;
      if (bridge.overspeed && bridge_overspeed_samples_ >= kOverspeedSamples) active |= kFaultBridgeOverspeed;
      if (bridge.approaching) warnings |= kWarningBridgeApproach;
      if (bridge.speed_limited) {
        bridge_limit = params_.approach_voltage_limit;
        warnings |= kWarningSpeedLimited;
      }
    }
    const AxisVerdict trolley = check_axis(params_.trolley(), in.trolley_position, trolley_velocity_);
    if (trolley.range_fault) active |= kFaultTrolleyTravel;
    if (trolley.overspeed && trolley_overspeed_samples_ >= kOverspeedSamples) active |= kFaultTrolleyOverspeed;
    if (trolley.approaching) warnings |= kWarningTrolleyApproach;
    if (trolley.speed_limited) {
      trolley_limit = params_.approach_voltage_limit;
      warnings |= kWarningSpeedLimited;
    }
    if (params_.slew_enabled) {
      const AxisVerdict slew = check_axis(params_.slew(), in.slew_angle, slew_rate_);
      if (slew.range_fault) active |= kFaultSlewRange;
      if (slew.overspeed && slew_overspeed_samples_ >= kOverspeedSamples) active |= kFaultSlewOverspeed;
      if (slew.approaching) warnings |= kWarningSlewApproach;
      if (slew.speed_limited) {
        slew_limit = params_.approach_voltage_limit;
        warnings |= kWarningSpeedLimited;
      }
    }
    if (std::fabs(in.swing_in_plane) > params_.max_swing || std::fabs(in.swing_out_of_plane) > params_.max_swing) {
      active |= kFaultSwing;
    }
    if (in.limit_switches != 0) active |= kFaultLimitSwitch;
    if (zones_enabled_ != 0 && std::isfinite(in.cable_length) && std::isfinite(in.swing_in_plane) &&
        std::isfinite(in.swing_out_of_plane)) {
      // The load itself, then where it stops if both drives brake now.
      const common::Site& site = params_.site;
      const auto load = common::load_position(site, in.trolley_position, in.slew_angle, in.swing_in_plane,
                                              in.swing_out_of_plane, in.cable_length);
      const int inside = common::intruded_zone(site, zones_enabled_, {load[0], load[1]}, load[2], 0.0);
      const double x_stop = in.trolley_position +
                            trolley_velocity_ * std::fabs(trolley_velocity_) / (2.0 * params_.trolley_braking_deceleration);
      const double slew_stop =
          in.slew_angle + slew_rate_ * std::fabs(slew_rate_) / (2.0 * params_.slew_braking_deceleration);
      const auto stop = common::load_position(site, x_stop, slew_stop, in.swing_in_plane, in.swing_out_of_plane,
                                              in.cable_length);
      const int ahead = common::intruded_zone(site, zones_enabled_, {stop[0], stop[1]}, stop[2], 0.0);
      if (inside >= 0) {
        active |= kFaultZone;
        out.zone = inside;
      } else if (ahead >= 0) {
        warnings |= kWarningZoneApproach;
        out.zone = ahead;
      }
    }
    if (params_.expected_sensor_source != 0 && in.sensor_source != params_.expected_sensor_source) {
      active |= kFaultSensorSource;
    }
  }
  if (in.actuators_valid) {
    if (std::fabs(in.trolley_voltage) > params_.voltage_limit + 1e-9 ||
        std::fabs(in.slew_voltage) > params_.voltage_limit + 1e-9 ||
        std::fabs(in.bridge_voltage) > params_.voltage_limit + 1e-9) {
      active |= kFaultVoltage;
    }
    if (have_previous_command_ && in.actuator_seq > previous_actuator_seq_) {
      const double dt = static_cast<double>(in.actuator_seq - previous_actuator_seq_) * params_.sample_period;
      const double rate = std::max({std::fabs(in.trolley_voltage - previous_trolley_voltage_),
                                    std::fabs(in.slew_voltage - previous_slew_voltage_),
                                    std::fabs(in.bridge_voltage - previous_bridge_voltage_)}) / dt;
      if (rate > params_.max_voltage_rate) active |= kFaultVoltageRate;
    }
    if (std::isfinite(in.trolley_voltage) && std::isfinite(in.slew_voltage) && std::isfinite(in.bridge_voltage)) {
      have_previous_command_ = true;
      previous_actuator_seq_ = in.actuator_seq;
      previous_trolley_voltage_ = in.trolley_voltage;
      previous_slew_voltage_ = in.slew_voltage;
      previous_bridge_voltage_ = in.bridge_voltage;
    }
  }
  if (in.nonfinite_seen) active |= kFaultNonFinite;
  if (in.emergency_stop_input || in.command == Command::emergency_stop) active |= kFaultEmergencyStop;
  if (in.sensor_writers > 1) active |= kFaultMultipleSensorWriters;
  if (in.actuator_writers > 1) active |= kFaultMultipleActuatorWriters;

  newly_raised_ = active & ~previous_active_;
  newly_cleared_ = previous_active_ & ~active;
  fault_count_ += static_cast<std::uint32_t>(std::popcount(newly_raised_));
  if (newly_raised_ != 0) {
    last_fault_ = std::bit_floor(newly_raised_);  // the highest-numbered new bit when several at once
    last_fault_seq_ = in.sensor_seq;
  }
  previous_active_ = active;
  latched_ |= active;

  bool refused = false;
  switch (in.command) {
    case Command::arm:
      // Arming needs a healthy chain and nothing latched (a reset comes first).
      refused = !chain_healthy || latched_ != 0;
      if (!refused) armed_ = true;
      break;
    case Command::disarm: armed_ = false; break;
    case Command::reset:
      // A reset clears latched faults only when nothing is active and the chain is healthy.
      refused = active != 0 || !chain_healthy;
      if (!refused) latched_ = 0;
      break;
    case Command::set_operating_mode:
      refused = std::string_view(operating_mode_name(in.command_operating_mode)) == "unknown";
      if (!refused) operating_mode_ = in.command_operating_mode;
      break;
    case Command::enable_zone:
    case Command::disable_zone:
      refused = in.command_zone >= params_.site.zones.size();
      if (!refused) {
        const std::uint32_t bit = 1U << in.command_zone;
        zones_enabled_ = in.command == Command::enable_zone ? (zones_enabled_ | bit) : (zones_enabled_ & ~bit);
      }
      break;
    case Command::emergency_stop:
    case Command::none: break;
  }

  if (latched_ & kFaultEmergencyStop) {
    mode_ = Mode::emergency_stop;
  } else if (latched_ != 0) {
    mode_ = Mode::fault;
  } else if (!chain_healthy) {
    // Start-up, or a late stage: the mode stays, motion is inhibited below until it is fresh again.
    if (!chain_was_up_ || mode_ == Mode::fault || mode_ == Mode::emergency_stop) mode_ = Mode::starting;
  } else if (armed_ || params_.arm_on_start) {
    if (mode_ == Mode::starting && params_.arm_on_start) armed_ = true;
    mode_ = armed_ ? (in.move_in_progress ? Mode::operating : Mode::ready) : Mode::standby;
  } else {
    mode_ = Mode::standby;
  }

  const bool enabled = chain_healthy && (mode_ == Mode::ready || mode_ == Mode::operating);
  out.mode = mode_;
  out.motion_enabled = enabled;
  // The brakes open one cycle after the drives were enabled, with the chain still alive.
  out.brakes_released = enabled && drives_enabled_previous_;
  drives_enabled_previous_ = enabled;
  out.active_faults = active;
  out.latched_faults = latched_;
  out.fault_count = fault_count_;
  out.stages_alive = alive_mask;
  out.stages_dead = dead_mask;
  out.warnings = warnings;
  out.last_fault = last_fault_;
  out.last_fault_seq = last_fault_seq_;
  out.trolley_voltage_limit = enabled ? trolley_limit : 0.0;
  out.slew_voltage_limit = enabled ? slew_limit : 0.0;
  out.trolley_velocity = trolley_velocity_;
  out.slew_rate = slew_rate_;
  out.bridge_voltage_limit = enabled ? bridge_limit : 0.0;
  out.bridge_velocity = bridge_velocity_;
  out.operating_mode = operating_mode_;
  out.zones_enabled = zones_enabled_;
  out.command_refused = refused;
}

}  // namespace crane::supervisor
