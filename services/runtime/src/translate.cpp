#include "crane/runtime/translate.hpp"

namespace crane::runtime {

common::CraneMeasurement to_measurement(const msgs::SensorSample_& s) noexcept {
  common::CraneMeasurement m;
  m.trolley_position = s.trolley_position();
  m.slew_angle = s.slew_angle();
  m.swing_in_plane = s.swing_in_plane();
  m.swing_out_of_plane = s.swing_out_of_plane();
  m.cable_length = s.cable_length();
  return m;
}

common::CraneStateEstimate to_estimate(const msgs::CraneState_& s) noexcept {
  common::CraneStateEstimate e;
  e.trolley_position = s.trolley_position();
  e.trolley_velocity = s.trolley_velocity();
  e.slew_angle = s.slew_angle();
  e.slew_rate = s.slew_rate();
  e.swing_in_plane = s.swing_in_plane();
  e.swing_in_plane_rate = s.swing_in_plane_rate();
  e.swing_out_of_plane = s.swing_out_of_plane();
  e.swing_out_of_plane_rate = s.swing_out_of_plane_rate();
  e.cable_length = s.cable_length();
  e.cable_length_rate = s.cable_length_rate();
  e.trolley_velocity_raw = s.trolley_velocity_raw();
  e.slew_rate_raw = s.slew_rate_raw();
  return e;
}

void from_estimate(const common::CraneStateEstimate& e, msgs::CraneState_& s) noexcept {
  s.trolley_position(e.trolley_position);
  s.trolley_velocity(e.trolley_velocity);
  s.slew_angle(e.slew_angle);
  s.slew_rate(e.slew_rate);
  s.swing_in_plane(e.swing_in_plane);
  s.swing_in_plane_rate(e.swing_in_plane_rate);
  s.swing_out_of_plane(e.swing_out_of_plane);
  s.swing_out_of_plane_rate(e.swing_out_of_plane_rate);
  s.cable_length(e.cable_length);
  s.cable_length_rate(e.cable_length_rate);
  s.trolley_velocity_raw(e.trolley_velocity_raw);
  s.slew_rate_raw(e.slew_rate_raw);
}

common::MotionReference to_reference(const msgs::Reference_& r) noexcept {
  common::MotionReference m;
  m.trolley = {r.trolley_position(), r.trolley_velocity(), r.trolley_acceleration()};
  m.slew = {r.slew_angle(), r.slew_rate(), r.slew_acceleration()};
  m.cable_length = {r.cable_length(), r.cable_length_rate(), r.cable_length_acceleration()};
  return m;
}

void from_reference(const common::MotionReference& m, msgs::Reference_& r) noexcept {
  r.trolley_position(m.trolley.position);
  r.trolley_velocity(m.trolley.velocity);
  r.trolley_acceleration(m.trolley.acceleration);
  r.slew_angle(m.slew.position);
  r.slew_rate(m.slew.velocity);
  r.slew_acceleration(m.slew.acceleration);
  r.cable_length(m.cable_length.position);
  r.cable_length_rate(m.cable_length.velocity);
  r.cable_length_acceleration(m.cable_length.acceleration);
}

}  // namespace crane::runtime
