#include "crane/supervisor/supervisor.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
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

// The trolley's point at (trolley [m], slew [rad]), horizontal, world frame.
common::Point2 trolley_point(double trolley, double slew) noexcept {
  return {trolley * std::cos(slew), trolley * std::sin(slew)};
}

}  // namespace

ZoneVerdict zone_guard(const SupervisorParams& p, std::uint32_t enabled, const ZoneState& s) noexcept {
  ZoneVerdict v;
  const common::Site& site = p.site;
  if (enabled == 0 || site.zones.empty()) return v;
  const double length = std::max(s.cable_length, 1e-3);
  const double w = std::sqrt(p.gravity / length);
  const auto load = common::load_position(site, s.trolley, s.slew, s.swing_in_plane, s.swing_out_of_plane, length);
  const common::Point2 load_xy{load[0], load[1]};
  v.inside = common::intruded_zone(site, enabled, load_xy, load[2], 0.0);

  // The load's swing about the trolley's point: offset u, rate du/dt (the load's velocity minus the
  // point's), amplitude |u(t)| <= sqrt(|u|^2 + |du/dt|^2 / w^2) (Cauchy-Schwarz on the ellipse).
  const common::Point2 now = trolley_point(s.trolley, s.slew);
  const common::Point2 offset{load_xy[0] - now[0], load_xy[1] - now[1]};
  const double c = std::cos(s.slew), sn = std::sin(s.slew);
  const common::Point2 point_velocity{s.trolley_velocity * c - s.trolley * s.slew_rate * sn,
                                      s.trolley_velocity * sn + s.trolley * s.slew_rate * c};
  const double rate_x = s.load_velocity[0] - point_velocity[0], rate_y = s.load_velocity[1] - point_velocity[1];
  const double amplitude = std::sqrt(offset[0] * offset[0] + offset[1] * offset[1] + (rate_x * rate_x + rate_y * rate_y) / (w * w));

  // Soft stop: ramp after the shaper's delay; the load about the trolley's rest point within the
  // swing's amplitude, plus what an unshaped stop excites (the point's speed / w).
  const double delay = s.stop == SoftStop::shaped ? p.zone_stop_delay_periods * 2.0 * std::numbers::pi / w : 0.0;
  const auto ramp = [](double speed, double deceleration) { return speed * std::fabs(speed) / (2.0 * deceleration); };
  const double x_soft = s.trolley + ramp(s.trolley_velocity, p.trolley_braking_deceleration) + s.trolley_velocity * delay;
  const double g_soft = s.slew + ramp(s.slew_rate, p.slew_braking_deceleration) + s.slew_rate * delay;
  const common::Point2 soft = trolley_point(x_soft, g_soft);
  const double excited = s.stop == SoftStop::unshaped ? std::hypot(point_velocity[0], point_velocity[1]) / w : 0.0;
  if (s.stop == SoftStop::planned) {
    // The load's offset carried to the rest point, no margin (the planner's paths keep their own).
    v.limit = common::intruded_zone(site, enabled, {soft[0] + offset[0], soft[1] + offset[1]}, load[2], 0.0);
    v.approach = v.limit;
  } else {
    v.limit = common::intruded_zone(site, enabled, soft, load[2], amplitude + excited);
    v.approach = common::intruded_zone(site, enabled, soft, load[2], amplitude + excited + p.zone_approach_margin);
  }
  v.limit_trolley = v.limit >= 0 && s.trolley_velocity * s.trolley_acceleration > 0.0;
  v.limit_slew = v.limit >= 0 && s.slew_rate * s.slew_acceleration > 0.0;

  // Brake envelope, while the crane moves (as the travel limiter's "moving toward": a tenth of
  // the approach speeds; a load at rest beside a zone may stay there).
  const bool moving = std::fabs(s.trolley_velocity) > 0.1 * std::max(p.trolley_approach_speed, 1e-6) ||
                      std::fabs(s.slew_rate) > 0.1 * std::max(p.slew_approach_rate, 1e-6);
  if (moving) {
    const common::Point2 stop = trolley_point(s.trolley + ramp(s.trolley_velocity, p.trolley_braking_deceleration),
                                              s.slew + ramp(s.slew_rate, p.slew_braking_deceleration));
    constexpr int kPhases = 24;
    for (const common::Point2& centre : {now, stop}) {
      for (int i = 0; i < kPhases && v.brake < 0; ++i) {
        const double phase = 2.0 * std::numbers::pi * i / kPhases;
        const double cp = std::cos(phase), sp = std::sin(phase) / w;
        const common::Point2 q{centre[0] + offset[0] * cp + s.load_velocity[0] * sp,
                               centre[1] + offset[1] * cp + s.load_velocity[1] * sp};
        v.brake = common::intruded_zone(site, enabled, q, load[2], p.zone_brake_margin);
      }
    }
    // Only toward the zone (the trolley's point closer to it at the soft stop's rest than now): a
    // crane moving away or along it is not stopped (braking would not keep a swinging load out);
    // in FULLAUTOMATIC only with the ramp-only prediction in the zone (a planned path passing it).
    if (v.brake >= 0) {
      const common::Zone& zone = site.zones[static_cast<std::size_t>(v.brake)];
      const bool toward = common::signed_distance(zone, soft) < common::signed_distance(zone, now);
      if (!toward || (s.stop == SoftStop::planned && v.approach < 0)) v.brake = -1;
    }
  }
  return v;
}

ZoneRefusal zone_command_refusal(const common::Site& site, Command command, std::uint8_t zone) noexcept {
  if (zone >= site.zones.size() || zone >= common::Site::kMaxZones) return ZoneRefusal::no_such_zone;
  if (command == Command::disable_zone && site.zones[zone].fixed) return ZoneRefusal::fixed;
  return ZoneRefusal::none;
}

std::string describe(ZoneRefusal refusal, const common::Site& site, std::uint8_t zone) {
  switch (refusal) {
    case ZoneRefusal::none: return "";
    case ZoneRefusal::no_such_zone:
      return "no zone " + std::to_string(zone) + ": site.zones has " + std::to_string(site.zones.size());
    case ZoneRefusal::fixed:
      return "site.zones[" + std::to_string(zone) + "] (" + site.zones[zone].name +
             ") is fixed: it stays enforced (switching it off is refused)";
  }
  return "";
}

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
  require_in_range("supervisor.zone_stop_delay_periods", p.zone_stop_delay_periods, 0.0, 3.0);
  require_in_range("supervisor.zone_approach_margin", p.zone_approach_margin, 0.0, 10.0);
  require_in_range("supervisor.zone_brake_margin", p.zone_brake_margin, 0.0, 1.0);
  require_in_range("supervisor.gravity", p.gravity, 0.1, 100.0);
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
  const bool load_valid = std::isfinite(in.cable_length) && std::isfinite(in.swing_in_plane) &&
                          std::isfinite(in.swing_out_of_plane);
  const auto load = common::load_position(params_.site, in.trolley_position, in.slew_angle, in.swing_in_plane,
                                          in.swing_out_of_plane, in.cable_length);
  if (in.sensors_valid && finite_sensors) {
    if (have_previous_sample_ && in.sensor_seq > previous_sensor_seq_) {
      const double nominal_dt = static_cast<double>(in.sensor_seq - previous_sensor_seq_) * params_.sample_period;
      const double measured_dt = in.sensor_time - previous_sensor_time_;  // NaN without measurement times
      const double dt = measured_dt >= kMinMeasuredInterval * nominal_dt && measured_dt <= kMaxMeasuredInterval * nominal_dt
                            ? measured_dt
                            : nominal_dt;
      const double trolley_velocity = (in.trolley_position - previous_trolley_) / dt;
      const double slew_rate = (in.slew_angle - previous_slew_) / dt;
      trolley_acceleration_ = (trolley_velocity - trolley_velocity_) / dt;
      slew_acceleration_ = (slew_rate - slew_rate_) / dt;
      trolley_velocity_ = trolley_velocity;
      slew_rate_ = slew_rate;
      // Consecutive samples over the speed limit (kOverspeedSamples in the header).
      trolley_overspeed_samples_ = std::fabs(trolley_velocity_) > params_.trolley().max_speed ? trolley_overspeed_samples_ + 1 : 0;
      slew_overspeed_samples_ = std::fabs(slew_rate_) > params_.slew().max_speed ? slew_overspeed_samples_ + 1 : 0;
      bridge_velocity_ = (in.bridge_position - previous_bridge_) / dt;
      if (load_valid) {
        load_velocity_ = {(load[0] - previous_load_[0]) / dt, (load[1] - previous_load_[1]) / dt};
      }
      bridge_overspeed_samples_ = std::fabs(bridge_velocity_) > params_.bridge().max_speed ? bridge_overspeed_samples_ + 1 : 0;
      cable_rate_ = std::isfinite(in.cable_length) && std::isfinite(previous_cable_)
                        ? (in.cable_length - previous_cable_) / dt
                        : 0.0;
    } else if (!have_previous_sample_ || in.sensor_seq < previous_sensor_seq_) {
      trolley_velocity_ = 0.0;  // first sample, or the sensor writer restarted
      slew_rate_ = 0.0;
      trolley_acceleration_ = 0.0;
      slew_acceleration_ = 0.0;
      trolley_overspeed_samples_ = 0;
      slew_overspeed_samples_ = 0;
      bridge_velocity_ = 0.0;
      bridge_overspeed_samples_ = 0;
      cable_rate_ = 0.0;
      load_velocity_ = {};
    }
    if (load_valid) previous_load_ = {load[0], load[1]};
    have_previous_sample_ = true;
    previous_sensor_seq_ = in.sensor_seq;
    previous_sensor_time_ = in.sensor_time;
    previous_trolley_ = in.trolley_position;
    previous_slew_ = in.slew_angle;
    previous_bridge_ = in.bridge_position;
    previous_cable_ = in.cable_length;  // NaN when not measured: no rate from it
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
    // The site grant, checked by the crane's own guard on this motion (docs/site.md).
    if (in.site == SiteVerdict::emergency_stop) active |= kFaultSiteGrant;
    if (in.site == SiteVerdict::soft_stop) warnings |= kWarningSite;
    if (in.site != SiteVerdict::off && in.site_unheard) warnings |= kWarningSiteUnheard;
    if (zones_enabled_ != 0 && load_valid) {
      ZoneState state;
      state.trolley = in.trolley_position;
      state.trolley_velocity = trolley_velocity_;
      state.slew = in.slew_angle;
      state.slew_rate = slew_rate_;
      state.swing_in_plane = in.swing_in_plane;
      state.swing_out_of_plane = in.swing_out_of_plane;
      state.cable_length = in.cable_length;
      state.load_velocity = load_velocity_;
      state.stop = operating_mode_ == StatusCodes::OPERATION_MAINTENANCE     ? SoftStop::unshaped
                   : operating_mode_ == StatusCodes::OPERATION_FULLAUTOMATIC ? SoftStop::planned
                                                                             : SoftStop::shaped;
      state.trolley_acceleration = trolley_acceleration_;
      state.slew_acceleration = slew_acceleration_;
      const ZoneVerdict zone = zone_guard(params_, zones_enabled_, state);
      if (zone.inside >= 0 || zone.brake >= 0) {
        active |= kFaultZone;
        out.zone = zone.inside >= 0 ? zone.inside : zone.brake;
      } else if (zone.approach >= 0) {
        out.zone = zone.approach;
      }
      if (zone.approach >= 0) warnings |= kWarningZoneApproach;
      if (zone.limit_trolley) trolley_limit = std::min(trolley_limit, params_.approach_voltage_limit);
      if (zone.limit_slew) slew_limit = std::min(slew_limit, params_.approach_voltage_limit);
      if (zone.limit_trolley || zone.limit_slew) warnings |= kWarningSpeedLimited;
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
  out.zone_refusal = ZoneRefusal::none;
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
      out.zone_refusal = zone_command_refusal(params_.site, in.command, in.command_zone);
      refused = out.zone_refusal != ZoneRefusal::none;
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

  const bool may_operate = mode_ == Mode::ready || mode_ == Mode::operating;
  const bool enabled = chain_healthy && may_operate;
  // The drives braked under way (kWarningDrivesBraked): after they ran in this spell of
  // ready/operating, the latest sample reports the brakes on.
  if (!may_operate) {
    drives_ran_ = false;
  } else if (in.sensors_valid) {
    if (in.brakes_engaged && drives_ran_) warnings |= kWarningDrivesBraked;
    if (!in.brakes_engaged) drives_ran_ = true;
  }
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
  out.cable_rate = cable_rate_;
  out.operating_mode = operating_mode_;
  out.zones_enabled = zones_enabled_;
  out.command_refused = refused;
}

}  // namespace crane::supervisor
