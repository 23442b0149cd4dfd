#pragma once
// The core signal structs (crane_signals.hpp) of the protocol's messages (crane/protocol/
// messages.hpp, generated from the IDL), field for field, SI: what every stage object reads from
// and writes to its messages. Header-only (target crane::common_protocol).

#include "crane/common/crane_parameters.hpp"
#include "crane/common/crane_signals.hpp"
#include "crane/protocol/messages.hpp"

namespace crane::common {

[[nodiscard]] inline CraneMeasurement to_measurement(const protocol::SensorSample& s) noexcept {
  CraneMeasurement m;
  m.trolley_position = s.trolley_position;
  m.slew_angle = s.slew_angle;
  m.swing_in_plane = s.swing_in_plane;
  m.swing_out_of_plane = s.swing_out_of_plane;
  m.cable_length = s.cable_length;
  m.bridge_position = s.bridge_position;
  return m;
}

[[nodiscard]] inline CraneStateEstimate to_estimate(const protocol::CraneState& s) noexcept {
  CraneStateEstimate e;
  e.trolley_position = s.trolley_position;
  e.trolley_velocity = s.trolley_velocity;
  e.slew_angle = s.slew_angle;
  e.slew_rate = s.slew_rate;
  e.swing_in_plane = s.swing_in_plane;
  e.swing_in_plane_rate = s.swing_in_plane_rate;
  e.swing_out_of_plane = s.swing_out_of_plane;
  e.swing_out_of_plane_rate = s.swing_out_of_plane_rate;
  e.cable_length = s.cable_length;
  e.cable_length_rate = s.cable_length_rate;
  e.trolley_velocity_raw = s.trolley_velocity_raw;
  e.slew_rate_raw = s.slew_rate_raw;
  return e;
}

inline void from_estimate(const CraneStateEstimate& e, protocol::CraneState& s) noexcept {
  s.trolley_position = e.trolley_position;
  s.trolley_velocity = e.trolley_velocity;
  s.slew_angle = e.slew_angle;
  s.slew_rate = e.slew_rate;
  s.swing_in_plane = e.swing_in_plane;
  s.swing_in_plane_rate = e.swing_in_plane_rate;
  s.swing_out_of_plane = e.swing_out_of_plane;
  s.swing_out_of_plane_rate = e.swing_out_of_plane_rate;
  s.cable_length = e.cable_length;
  s.cable_length_rate = e.cable_length_rate;
  s.trolley_velocity_raw = e.trolley_velocity_raw;
  s.slew_rate_raw = e.slew_rate_raw;
}

/// The trolley's friction in use that the estimate carries (CraneState_'s trolley_friction_*), volts.
[[nodiscard]] inline AxisFriction trolley_friction_in_use(const protocol::CraneState& s) noexcept {
  return {s.trolley_friction_viscous_positive, s.trolley_friction_viscous_negative,
          s.trolley_friction_coulomb_positive, s.trolley_friction_coulomb_negative,
          s.trolley_friction_static_positive,  s.trolley_friction_static_negative};
}

/// The slew's (CraneState_'s slew_friction_*).
[[nodiscard]] inline AxisFriction slew_friction_in_use(const protocol::CraneState& s) noexcept {
  return {s.slew_friction_viscous_positive, s.slew_friction_viscous_negative, s.slew_friction_coulomb_positive,
          s.slew_friction_coulomb_negative, s.slew_friction_static_positive,  s.slew_friction_static_negative};
}

inline void set_friction_in_use(const AxisFriction& trolley, const AxisFriction& slew, protocol::CraneState& s) noexcept {
  s.trolley_friction_viscous_positive = trolley.viscous_positive;
  s.trolley_friction_viscous_negative = trolley.viscous_negative;
  s.trolley_friction_coulomb_positive = trolley.coulomb_positive;
  s.trolley_friction_coulomb_negative = trolley.coulomb_negative;
  s.trolley_friction_static_positive = trolley.static_positive;
  s.trolley_friction_static_negative = trolley.static_negative;
  s.slew_friction_viscous_positive = slew.viscous_positive;
  s.slew_friction_viscous_negative = slew.viscous_negative;
  s.slew_friction_coulomb_positive = slew.coulomb_positive;
  s.slew_friction_coulomb_negative = slew.coulomb_negative;
  s.slew_friction_static_positive = slew.static_positive;
  s.slew_friction_static_negative = slew.static_negative;
}

[[nodiscard]] inline MotionReference to_reference(const protocol::Reference& r) noexcept {
  MotionReference m;
  m.trolley = {r.trolley_position, r.trolley_velocity, r.trolley_acceleration};
  m.slew = {r.slew_angle, r.slew_rate, r.slew_acceleration};
  m.cable_length = {r.cable_length, r.cable_length_rate, r.cable_length_acceleration};
  return m;
}

inline void from_reference(const MotionReference& m, protocol::Reference& r) noexcept {
  r.trolley_position = m.trolley.position;
  r.trolley_velocity = m.trolley.velocity;
  r.trolley_acceleration = m.trolley.acceleration;
  r.slew_angle = m.slew.position;
  r.slew_rate = m.slew.velocity;
  r.slew_acceleration = m.slew.acceleration;
  r.cable_length = m.cable_length.position;
  r.cable_length_rate = m.cable_length.velocity;
  r.cable_length_acceleration = m.cable_length.acceleration;
}

// The feedback law a reference carries (Reference.feedback_law; common::TrajectoryFeedback): the
// second axis of z is the bridge on an overhead crane (`bridge`), the slew elsewhere; z_ref's drive
// axes are the reference's own positions and velocities.
[[nodiscard]] inline TrajectoryFeedback to_trajectory_feedback(const protocol::Reference& r, bool bridge) noexcept {
  TrajectoryFeedback f;
  f.position = {r.trolley_position, r.swing_in_plane, bridge ? r.bridge_position : r.slew_angle, r.swing_out_of_plane};
  f.velocity = {r.trolley_velocity, r.swing_in_plane_rate, bridge ? r.bridge_velocity : r.slew_rate,
                r.swing_out_of_plane_rate};
  f.feedforward = {r.trolley_feedforward_voltage, r.second_feedforward_voltage};
  for (std::size_t i = 0; i < f.gain.size(); ++i) f.gain[i] = r.feedback_gain[i];
  f.sliding_friction_reduction = r.sliding_friction_reduction;
  return f;
}

/// Sets `r`'s feedback law (feedback_law TRUE) and its drive axes' positions and velocities from `f`.
inline void set_trajectory_feedback(const TrajectoryFeedback& f, bool bridge, protocol::Reference& r) noexcept {
  r.feedback_law = true;
  r.trolley_position = f.position[0];
  r.trolley_velocity = f.velocity[0];
  r.swing_in_plane = f.position[1];
  r.swing_in_plane_rate = f.velocity[1];
  (bridge ? r.bridge_position : r.slew_angle) = f.position[2];
  (bridge ? r.bridge_velocity : r.slew_rate) = f.velocity[2];
  r.swing_out_of_plane = f.position[3];
  r.swing_out_of_plane_rate = f.velocity[3];
  r.trolley_feedforward_voltage = f.feedforward[0];
  r.second_feedforward_voltage = f.feedforward[1];
  for (std::size_t i = 0; i < f.gain.size(); ++i) r.feedback_gain[i] = f.gain[i];
  r.sliding_friction_reduction = f.sliding_friction_reduction;
}

// The overhead crane's bridge, seen as the trolley of a gantry crane: how every controller stage
// runs the bridge axis with its trolley law and the bridge's parameters (common::bridge_as_trolley,
// which gives the reason). trolley_* := bridge_*, swing_in_plane := -swing_out_of_plane (theta moves
// the load toward +y where phi moves it toward -x, overhead_crane_model.hpp), the slew and the
// out-of-plane swing 0; the rest (cable, payload, header) is kept. The bridge's friction in use is the
// configured one (the online friction estimation covers the trolley and the slew only).

[[nodiscard]] inline protocol::CraneState bridge_view(const protocol::CraneState& s) noexcept {
  protocol::CraneState v = s;
  v.trolley_position = s.bridge_position;
  v.trolley_velocity = s.bridge_velocity;
  v.trolley_velocity_raw = s.bridge_velocity_raw;
  v.swing_in_plane = -s.swing_out_of_plane;
  v.swing_in_plane_rate = -s.swing_out_of_plane_rate;
  v.slew_angle = v.slew_rate = v.slew_rate_raw = 0.0;
  v.swing_out_of_plane = v.swing_out_of_plane_rate = 0.0;
  v.adaptation = 0;
  return v;
}

[[nodiscard]] inline protocol::Reference bridge_view(const protocol::Reference& r) noexcept {
  protocol::Reference v = r;
  v.trolley_position = r.bridge_position;
  v.trolley_velocity = r.bridge_velocity;
  v.trolley_acceleration = r.bridge_acceleration;
  v.slew_angle = v.slew_rate = v.slew_acceleration = 0.0;
  return v;
}

[[nodiscard]] inline protocol::AntiSwingCommand bridge_view(const protocol::AntiSwingCommand& a) noexcept {
  protocol::AntiSwingCommand v = a;
  v.trolley_action = a.bridge_action;
  v.trolley_reference_correction = a.bridge_reference_correction;
  v.trolley_reference_rate_correction = a.bridge_reference_rate_correction;
  v.slew_action = v.slew_reference_correction = v.slew_reference_rate_correction = 0.0;
  return v;
}

[[nodiscard]] inline protocol::LinearCommand bridge_view(const protocol::LinearCommand& c) noexcept {
  protocol::LinearCommand v = c;
  v.trolley_voltage = c.bridge_voltage;
  v.trolley_tracking_action = c.bridge_tracking_action;
  v.slew_voltage = v.slew_tracking_action = 0.0;
  return v;
}

/// The output's header belongs to the input's cycle: same seq and origin (the node stamps `stamp`
/// when it writes).
inline void same_cycle(const protocol::CycleHeader& input, protocol::CycleHeader& output) noexcept {
  output.seq = input.seq;
  output.origin = input.origin;
}

}  // namespace crane::common
