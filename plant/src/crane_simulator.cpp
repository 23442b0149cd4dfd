#include "crane/plant/crane_simulator.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "crane/common/validation.hpp"
#include "crane/plant/gantry_crane_model.hpp"
#include "crane/plant/overhead_crane_model.hpp"
#include "crane/plant/tower_crane_model.hpp"

namespace crane::plant {

namespace {

ExtendedState to_extended_state(const PlantState& s, PlantKind kind, bool rope) {
  ExtendedState e;
  if (kind == PlantKind::overhead) {
    e.position.head<kNumCoordinates>() << s.trolley_position, s.swing_in_plane, s.bridge_position, s.swing_out_of_plane;
    e.velocity.head<kNumCoordinates>() << s.trolley_velocity, s.swing_in_plane_rate, s.bridge_velocity,
        s.swing_out_of_plane_rate;
  } else {
    e.position.head<kNumCoordinates>() << s.trolley_position, s.swing_in_plane, s.slew_angle, s.swing_out_of_plane;
    e.velocity.head<kNumCoordinates>() << s.trolley_velocity, s.swing_in_plane_rate, s.slew_rate,
        s.swing_out_of_plane_rate;
  }
  e.position[kRiggingInPlaneIndex] = s.rigging_in_plane;
  e.position[kRiggingOutOfPlaneIndex] = s.rigging_out_of_plane;
  e.velocity[kRiggingInPlaneIndex] = s.rigging_in_plane_rate;
  e.velocity[kRiggingOutOfPlaneIndex] = s.rigging_out_of_plane_rate;
  if (rope) {  // slot 4 is the stretch (a rope never comes with a hook)
    e.position[kRopeStretchIndex] = s.rope_stretch;
    e.velocity[kRopeStretchIndex] = s.rope_stretch_rate;
  }
  return e;
}

ModelState to_model_state(const PlantState& s, PlantKind kind) {
  ModelState m;
  if (kind == PlantKind::overhead) {
    m.position << s.trolley_position, s.swing_in_plane, s.bridge_position, s.swing_out_of_plane;
    m.velocity << s.trolley_velocity, s.swing_in_plane_rate, s.bridge_velocity, s.swing_out_of_plane_rate;
  } else {
    m.position << s.trolley_position, s.swing_in_plane, s.slew_angle, s.swing_out_of_plane;
    m.velocity << s.trolley_velocity, s.swing_in_plane_rate, s.slew_rate, s.swing_out_of_plane_rate;
  }
  return m;
}

// Friction and brake of the second drive axis: the slew's (tower), the bridge's (overhead); a gantry
// has none, its held slot gets a 1 N static friction that nothing ever loads (so it stays stuck).
AxisFrictionModel second_axis_friction(const SimulatorParameters& p, const CraneDynamics& model) {
  const double force_per_volt = model.drive_force_per_volt(DriveAxis::second);
  switch (p.kind) {
    case PlantKind::tower:
      return AxisFrictionModel(p.crane.slew_friction, force_per_volt,
                               p.brake_holding_factor * force_per_volt * p.crane.dac_range,
                               "simulator.crane.slew_friction");
    case PlantKind::overhead:
      return AxisFrictionModel(p.bridge.friction, force_per_volt,
                               p.brake_holding_factor * force_per_volt * p.crane.dac_range,
                               "simulator.bridge.friction");
    case PlantKind::gantry:
      break;
  }
  return AxisFrictionModel(common::AxisFriction{0.0, 0.0, 0.0, 0.0, 1.0, 1.0}, 1.0, 0.0, "simulator.held_axis");
}

}  // namespace

std::unique_ptr<CraneDynamics> make_crane_dynamics(PlantKind kind, const common::CraneParameters& crane,
                                                   const common::BridgeParameters& bridge, const HookParameters& hook,
                                                   const RopeParameters& rope) {
  switch (kind) {
    case PlantKind::gantry: return std::make_unique<GantryCraneModel>(crane);
    case PlantKind::overhead: return std::make_unique<OverheadCraneModel>(crane, bridge);
    case PlantKind::tower: break;
  }
  return std::make_unique<TowerCraneModel>(crane, hook, rope);
}

const SimulatorParameters& CraneSimulator::validated(const SimulatorParameters& p) {
  common::validate(p.crane, "simulator.crane");  // the cable range (the hoist's) included
  if (p.kind == PlantKind::overhead) common::validate(p.bridge, "simulator.bridge");
  common::require_in_range("simulator.sample_period", p.sample_period, 1e-6, 1.0);
  common::require_greater("simulator.integrator.relative_tolerance", p.integrator.relative_tolerance, 0.0);
  common::require_in_range("simulator.integrator.relative_tolerance", p.integrator.relative_tolerance, 0.0, 1e-2);
  common::require_greater("simulator.integrator.absolute_tolerance", p.integrator.absolute_tolerance, 0.0);
  common::require_in_range("simulator.integrator.absolute_tolerance", p.integrator.absolute_tolerance, 0.0, 1e-2);
  common::require_in_range("simulator.brake_holding_factor", p.brake_holding_factor, 0.0, 1e6);
  common::require_greater("simulator.hoist_max_acceleration", p.hoist_max_acceleration, 0.0);
  validate(p.hook, "plant.hook.");
  validate(p.wind, "plant.wind.");
  validate(p.rope, "plant.rope.");
  if (p.kind != PlantKind::tower && p.rope.enabled) {
    throw common::ConfigError(std::string("plant.rope.enabled = true needs crane.kind = tower (is ") +
                              to_string(p.kind) + ")");
  }
  if (p.kind != PlantKind::tower) {
    if (p.hook.enabled) {
      throw common::ConfigError(std::string("plant.hook.enabled = true needs crane.kind = tower (is ") +
                                to_string(p.kind) + ")");
    }
    if (p.wind.enabled) {
      throw common::ConfigError(std::string("plant.wind.enabled = true needs crane.kind = tower (is ") +
                                to_string(p.kind) + ")");
    }
  }
  if (p.wind.enabled) common::require_greater("plant.wind: crane.load_mass", p.crane.load_mass, 0.0);
  return p;
}

CraneSimulator::CraneSimulator(const SimulatorParameters& parameters)
    : parameters_(validated(parameters)),
      model_(make_crane_dynamics(parameters_.kind, parameters_.crane, parameters_.bridge, parameters_.hook,
                                 parameters_.rope)),
      sensors_(parameters_.crane),
      integrator_(*model_,
                  AxisFrictionModel(parameters_.crane.trolley_friction,
                                    model_->drive_force_per_volt(DriveAxis::trolley),
                                    parameters_.brake_holding_factor *
                                        model_->drive_force_per_volt(DriveAxis::trolley) * parameters_.crane.dac_range,
                                    "simulator.crane.trolley_friction"),
                  second_axis_friction(parameters_, *model_), parameters_.integrator),
      wind_(parameters_.wind, parameters_.sample_period) {
  reset(parameters_.initial_state);
}

CraneSimulator::FrictionModels CraneSimulator::friction_models(const common::AxisFriction& trolley_friction,
                                                               const common::AxisFriction& slew_friction) const {
  SimulatorParameters p = parameters_;
  p.crane.trolley_friction = trolley_friction;
  p.crane.slew_friction = slew_friction;
  const double force_per_volt = model_->drive_force_per_volt(DriveAxis::trolley);
  return FrictionModels{AxisFrictionModel(trolley_friction, force_per_volt,
                                          p.brake_holding_factor * force_per_volt * p.crane.dac_range,
                                          "simulator.crane.trolley_friction"),
                        second_axis_friction(p, *model_)};
}

void CraneSimulator::validate_state(const PlantState& s) const {
  const std::string p = "simulator.initial_state.";
  const double limit = 1e6;
  common::require_in_range(p + "trolley_position", s.trolley_position, -limit, limit);
  common::require_in_range(p + "trolley_velocity", s.trolley_velocity, -limit, limit);
  common::require_in_range(p + "slew_angle", s.slew_angle, -limit, limit);
  common::require_in_range(p + "slew_rate", s.slew_rate, -limit, limit);
  const double swing_limit = 0.5 * std::numbers::pi - 1e-3;
  common::require_in_range(p + "swing_in_plane", s.swing_in_plane, -swing_limit, swing_limit);
  common::require_in_range(p + "swing_in_plane_rate", s.swing_in_plane_rate, -limit, limit);
  common::require_in_range(p + "swing_out_of_plane", s.swing_out_of_plane, -swing_limit, swing_limit);
  common::require_in_range(p + "swing_out_of_plane_rate", s.swing_out_of_plane_rate, -limit, limit);
  common::require_in_range(p + "cable_length", s.cable_length, parameters_.crane.min_cable_length,
                           parameters_.crane.max_cable_length);
  common::require_in_range(p + "cable_length_rate", s.cable_length_rate, -limit, limit);
  common::require_in_range(p + "bridge_position", s.bridge_position, -limit, limit);
  common::require_in_range(p + "bridge_velocity", s.bridge_velocity, -limit, limit);
  // Coordinates the crane kind does not have must be 0 (they would be held at their value).
  const auto require_zero = [&](const char* field, double value) {
    common::require_in_range(p + field + " (" + to_string(parameters_.kind) + " crane)", value, 0.0, 0.0);
  };
  if (parameters_.kind != PlantKind::tower) {
    require_zero("slew_angle", s.slew_angle);
    require_zero("slew_rate", s.slew_rate);
  }
  if (parameters_.kind != PlantKind::overhead) {
    require_zero("bridge_position", s.bridge_position);
    require_zero("bridge_velocity", s.bridge_velocity);
  }
  if (parameters_.kind == PlantKind::gantry) {
    require_zero("swing_out_of_plane", s.swing_out_of_plane);
    require_zero("swing_out_of_plane_rate", s.swing_out_of_plane_rate);
  }
  if (parameters_.hook.enabled) {
    common::require_in_range(p + "rigging_in_plane", s.rigging_in_plane, -swing_limit, swing_limit);
    common::require_in_range(p + "rigging_in_plane_rate", s.rigging_in_plane_rate, -limit, limit);
    common::require_in_range(p + "rigging_out_of_plane", s.rigging_out_of_plane, -swing_limit, swing_limit);
    common::require_in_range(p + "rigging_out_of_plane_rate", s.rigging_out_of_plane_rate, -limit, limit);
  } else {
    const auto require_zero_without_hook = [&](const char* field, double value) {
      common::require_in_range(p + field + " (no plant.hook)", value, 0.0, 0.0);
    };
    require_zero_without_hook("rigging_in_plane", s.rigging_in_plane);
    require_zero_without_hook("rigging_in_plane_rate", s.rigging_in_plane_rate);
    require_zero_without_hook("rigging_out_of_plane", s.rigging_out_of_plane);
    require_zero_without_hook("rigging_out_of_plane_rate", s.rigging_out_of_plane_rate);
  }
  if (parameters_.rope.enabled) {
    common::require_in_range(p + "rope_stretch", s.rope_stretch, -0.5 * s.cable_length, s.cable_length);
    common::require_in_range(p + "rope_stretch_rate", s.rope_stretch_rate, -limit, limit);
  } else {
    common::require_in_range(p + "rope_stretch (no plant.rope)", s.rope_stretch, 0.0, 0.0);
    common::require_in_range(p + "rope_stretch_rate (no plant.rope)", s.rope_stretch_rate, 0.0, 0.0);
  }
}

void CraneSimulator::reset(const PlantState& state) {
  validate_state(state);
  sample_index_ = 0;
  if (parameters_.hook.enabled || parameters_.rope.enabled) {
    integrator_.reset(0.0, to_extended_state(state, parameters_.kind, parameters_.rope.enabled), state.cable_length,
                      state.cable_length_rate);
  } else {
    integrator_.reset(0.0, to_model_state(state, parameters_.kind), state.cable_length, state.cable_length_rate);
  }
  wind_.reset();
  refresh_state();
}

double CraneSimulator::time() const noexcept {
  return static_cast<double>(sample_index_) * parameters_.sample_period;
}

void CraneSimulator::refresh_state() noexcept {
  const ModelState m = integrator_.state();
  state_.trolley_position = m.position[kTrolleyIndex];
  state_.swing_in_plane = m.position[kInPlaneSwingIndex];
  state_.swing_out_of_plane = m.position[kOutOfPlaneSwingIndex];
  state_.trolley_velocity = m.velocity[kTrolleyIndex];
  state_.swing_in_plane_rate = m.velocity[kInPlaneSwingIndex];
  if (parameters_.kind == PlantKind::overhead) {
    state_.bridge_position = m.position[kBridgeIndex];
    state_.bridge_velocity = m.velocity[kBridgeIndex];
  } else {
    state_.slew_angle = m.position[kSlewIndex];
    state_.slew_rate = m.velocity[kSlewIndex];
  }
  state_.swing_out_of_plane_rate = m.velocity[kOutOfPlaneSwingIndex];
  state_.cable_length = integrator_.cable_length();
  state_.cable_length_rate = integrator_.cable_length_rate();
  if (parameters_.rope.enabled) {
    const ExtendedState e = integrator_.extended_state();
    state_.rope_stretch = e.position[kRopeStretchIndex];
    state_.rope_stretch_rate = e.velocity[kRopeStretchIndex];
  }
  if (parameters_.hook.enabled) {
    const ExtendedState e = integrator_.extended_state();
    state_.rigging_in_plane = e.position[kRiggingInPlaneIndex];
    state_.rigging_out_of_plane = e.position[kRiggingOutOfPlaneIndex];
    state_.rigging_in_plane_rate = e.velocity[kRiggingInPlaneIndex];
    state_.rigging_out_of_plane_rate = e.velocity[kRiggingOutOfPlaneIndex];
  }
}

common::StepStatus CraneSimulator::step(const DriveInput& input) noexcept {
  common::StepStatus status = common::StepStatus::ok;
  DriveInput safe = input;
  if (!std::isfinite(input.trolley_voltage) || !std::isfinite(input.slew_voltage) ||
      !std::isfinite(input.bridge_voltage) || !std::isfinite(input.hoist_speed)) {
    status = common::StepStatus::rejected_nonfinite;
    safe = DriveInput{};  // 0 V, brakes engaged
  }
  applied_trolley_voltage_ = sensors_.applied_voltage(safe.trolley_voltage);
  // The second drive: the slew (tower), the bridge (overhead), nothing (gantry: the slot is held).
  const bool overhead = parameters_.kind == PlantKind::overhead;
  applied_slew_voltage_ = overhead ? 0.0 : sensors_.applied_voltage(safe.slew_voltage);
  applied_bridge_voltage_ = overhead ? sensors_.applied_voltage(safe.bridge_voltage) : 0.0;
  brakes_engaged_ = safe.brakes_engaged;

  // Hoist: limit the speed v_next reached at the end of this sample so that the hoist can still stop
  // inside the length range: distance this sample (v + v_next) T_s / 2 plus braking distance
  // v_next^2 / (2 a_max) must not exceed the distance d to the limit:
  //   v_next^2 + a_max T_s v_next + 2 a_max (v T_s / 2 - d) <= 0.
  // Then rate-limit to a_max over this sample.
  const double T_s = parameters_.sample_period;
  const double a_max = parameters_.hoist_max_acceleration;
  const double L = integrator_.cable_length();
  const double L_dot = integrator_.cable_length_rate();
  const auto max_speed_toward_limit = [&](double distance, double speed_toward) {
    const double c = speed_toward * T_s / 2.0 - distance;
    const double discriminant = a_max * a_max * T_s * T_s - 8.0 * a_max * c;
    if (discriminant <= 0.0) return 0.0;
    return std::max(0.0, (-a_max * T_s + std::sqrt(discriminant)) / 2.0);
  };
  const double lowering_limit = max_speed_toward_limit(parameters_.crane.max_cable_length - L, L_dot);
  const double raising_limit = -max_speed_toward_limit(L - parameters_.crane.min_cable_length, -L_dot);
  const double target_rate = std::clamp(safe.hoist_speed, raising_limit, lowering_limit);
  const double L_ddot = std::clamp((target_rate - L_dot) / T_s, -a_max, a_max);

  SampleInput sample;
  sample.trolley_drive_force = applied_trolley_voltage_ * model_->drive_force_per_volt(DriveAxis::trolley);  // (2.26)
  sample.slew_drive_torque = (overhead ? applied_bridge_voltage_ : applied_slew_voltage_) *
                             model_->drive_force_per_volt(DriveAxis::second);  // (2.27); the bridge's F_y = M_y K_my V_y
  sample.cable_length_acceleration = L_ddot;
  sample.load_force_x = wind_.force_x();
  sample.load_force_y = wind_.force_y();
  sample.brakes_engaged = safe.brakes_engaged;

  const double end_time = static_cast<double>(sample_index_ + 1) * T_s;
  const IntegrationStatus result = integrator_.advance_to(end_time, sample);
  ++sample_index_;
  wind_.advance();
  refresh_state();
  applied_hoist_speed_ = state_.cable_length_rate;
  if (result != IntegrationStatus::ok && status == common::StepStatus::ok) status = common::StepStatus::not_ready;
  return status;
}

SimulatorOutput CraneSimulator::output() const noexcept {
  SimulatorOutput out;
  out.measurement = sensors_.measure(state_.trolley_position, state_.slew_angle, state_.swing_in_plane,
                                     state_.swing_out_of_plane, state_.cable_length);
  out.applied_trolley_voltage = applied_trolley_voltage_;
  out.applied_slew_voltage = applied_slew_voltage_;
  out.applied_bridge_voltage = applied_bridge_voltage_;
  if (parameters_.kind == PlantKind::overhead) out.measurement.bridge_position = sensors_.measure_bridge(state_.bridge_position);
  out.applied_hoist_speed = applied_hoist_speed_;
  out.brakes_engaged = brakes_engaged_;
  return out;
}

double CraneSimulator::total_energy() const noexcept {
  if (parameters_.hook.enabled || parameters_.rope.enabled) {
    return model_->extended_total_energy(to_extended_state(state_, parameters_.kind, parameters_.rope.enabled),
                                         HoistMotion{state_.cable_length, state_.cable_length_rate, 0.0});
  }
  const ModelState m = to_model_state(state_, parameters_.kind);
  return model_->total_energy(m, HoistMotion{state_.cable_length, state_.cable_length_rate, 0.0});
}

}  // namespace crane::plant
