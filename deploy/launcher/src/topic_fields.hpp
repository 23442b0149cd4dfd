#pragma once
// Field tables of every message type, for crane_topic echo (JSON). Generated from
// idl/crane_msgs.idl with the parser of tests/ros2/check_msgs.py; tests/ros2 checks this file
// against the IDL (ctest ros2.TopicFieldTablesMirrorTheIdl).
#include <nlohmann/json.hpp>

#include "crane/runtime/node_runtime.hpp"

namespace crane::launch::topic_fields {

namespace msgs = transport::topics::msgs;
using nlohmann::json;

inline json to_json(const builtin_interfaces::msg::dds_::Time_& t) { return json{{"sec", t.sec()}, {"nanosec", t.nanosec()}}; }
inline json to_json(const msgs::CycleHeader_& h) {
  return json{{"stamp", to_json(h.stamp())}, {"seq", h.seq()}, {"origin", to_json(h.origin())}};
}

inline json to_json(const msgs::SensorSample_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["source"] = m.source();
  j["writer_pid"] = m.writer_pid();
  j["trolley_position"] = m.trolley_position();
  j["slew_angle"] = m.slew_angle();
  j["swing_in_plane"] = m.swing_in_plane();
  j["swing_out_of_plane"] = m.swing_out_of_plane();
  j["cable_length"] = m.cable_length();
  j["applied_trolley_voltage"] = m.applied_trolley_voltage();
  j["applied_slew_voltage"] = m.applied_slew_voltage();
  j["applied_hoist_speed"] = m.applied_hoist_speed();
  j["brakes_engaged"] = m.brakes_engaged();
  j["emergency_stop_input"] = m.emergency_stop_input();
  j["limit_switches"] = m.limit_switches();
  return j;
}
inline json to_json(const msgs::ActuatorCommand_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["trolley_voltage"] = m.trolley_voltage();
  j["slew_voltage"] = m.slew_voltage();
  j["hoist_speed"] = m.hoist_speed();
  j["trolley_friction_voltage"] = m.trolley_friction_voltage();
  j["slew_friction_voltage"] = m.slew_friction_voltage();
  return j;
}
inline json to_json(const msgs::CraneState_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["trolley_position"] = m.trolley_position();
  j["trolley_velocity"] = m.trolley_velocity();
  j["slew_angle"] = m.slew_angle();
  j["slew_rate"] = m.slew_rate();
  j["swing_in_plane"] = m.swing_in_plane();
  j["swing_in_plane_rate"] = m.swing_in_plane_rate();
  j["swing_out_of_plane"] = m.swing_out_of_plane();
  j["swing_out_of_plane_rate"] = m.swing_out_of_plane_rate();
  j["cable_length"] = m.cable_length();
  j["cable_length_rate"] = m.cable_length_rate();
  j["trolley_velocity_raw"] = m.trolley_velocity_raw();
  j["slew_rate_raw"] = m.slew_rate_raw();
  return j;
}
inline json to_json(const msgs::MoveRequest_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["request_id"] = m.request_id();
  j["profile"] = m.profile();
  j["axes"] = m.axes();
  j["trolley_target"] = m.trolley_target();
  j["slew_target"] = m.slew_target();
  j["cable_length_target"] = m.cable_length_target();
  j["trolley_max_velocity"] = m.trolley_max_velocity();
  j["trolley_max_acceleration"] = m.trolley_max_acceleration();
  j["slew_max_velocity"] = m.slew_max_velocity();
  j["slew_max_acceleration"] = m.slew_max_acceleration();
  j["waypoint_count"] = m.waypoint_count();
  j["waypoint_trolley"] = m.waypoint_trolley();
  j["waypoint_slew"] = m.waypoint_slew();
  j["waypoint_cable_length"] = m.waypoint_cable_length();
  return j;
}
inline json to_json(const msgs::Reference_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["request_id"] = m.request_id();
  j["phase"] = m.phase();
  j["trolley_position"] = m.trolley_position();
  j["trolley_velocity"] = m.trolley_velocity();
  j["trolley_acceleration"] = m.trolley_acceleration();
  j["slew_angle"] = m.slew_angle();
  j["slew_rate"] = m.slew_rate();
  j["slew_acceleration"] = m.slew_acceleration();
  j["cable_length"] = m.cable_length();
  j["cable_length_rate"] = m.cable_length_rate();
  j["cable_length_acceleration"] = m.cable_length_acceleration();
  j["time_in_move"] = m.time_in_move();
  j["move_duration"] = m.move_duration();
  return j;
}
inline json to_json(const msgs::AntiSwingCommand_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["controller"] = m.controller();
  j["trolley_action"] = m.trolley_action();
  j["slew_action"] = m.slew_action();
  j["trolley_reference_correction"] = m.trolley_reference_correction();
  j["trolley_reference_rate_correction"] = m.trolley_reference_rate_correction();
  j["slew_reference_correction"] = m.slew_reference_correction();
  j["slew_reference_rate_correction"] = m.slew_reference_rate_correction();
  return j;
}
inline json to_json(const msgs::LinearCommand_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["trolley_voltage"] = m.trolley_voltage();
  j["slew_voltage"] = m.slew_voltage();
  j["hoist_speed"] = m.hoist_speed();
  j["trolley_tracking_action"] = m.trolley_tracking_action();
  j["slew_tracking_action"] = m.slew_tracking_action();
  return j;
}
inline json to_json(const msgs::SupervisorStatus_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["mode"] = m.mode();
  j["motion_enabled"] = m.motion_enabled();
  j["brakes_released"] = m.brakes_released();
  j["active_faults"] = m.active_faults();
  j["latched_faults"] = m.latched_faults();
  j["fault_count"] = m.fault_count();
  j["stages_alive"] = m.stages_alive();
  j["nonfinite_rejected"] = m.nonfinite_rejected();
  j["trolley_voltage_limit"] = m.trolley_voltage_limit();
  j["slew_voltage_limit"] = m.slew_voltage_limit();
  j["warnings"] = m.warnings();
  j["last_fault"] = m.last_fault();
  j["last_fault_seq"] = m.last_fault_seq();
  j["trolley_velocity"] = m.trolley_velocity();
  j["slew_rate"] = m.slew_rate();
  j["last_request_id"] = m.last_request_id();
  j["last_request_result"] = m.last_request_result();
  return j;
}
inline json to_json(const msgs::SupervisorCommand_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["request_id"] = m.request_id();
  j["command"] = m.command();
  return j;
}
inline json to_json(const msgs::LoopDiagnostics_& m) {
  json j;
  j["header"] = to_json(m.header());
  j["process"] = m.process();
  j["dds_vendor"] = m.dds_vendor();
  j["pid"] = m.pid();
  j["cycles"] = m.cycles();
  j["overruns"] = m.overruns();
  j["nonfinite_rejected"] = m.nonfinite_rejected();
  j["latency_p50_us"] = m.latency_p50_us();
  j["latency_p99_us"] = m.latency_p99_us();
  j["latency_max_us"] = m.latency_max_us();
  return j;
}

}  // namespace crane::launch::topic_fields
