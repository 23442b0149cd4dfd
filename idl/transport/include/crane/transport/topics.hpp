#pragma once
// The topic table of the control bus: one struct per topic with its ROS 2 wire name, message type
// and QoS profile. Message types are the C++ classes fastddsgen generates from idl/crane_msgs.idl;
// they are the canonical in-process representation for every vendor adapter.

#include "crane/transport/qos.hpp"
#include "crane_msgs.h"
#include "crane_msgsPubSubTypes.h"

namespace crane::transport::topics {

namespace msgs = crane_msgs::msg::dds_;

#define CRANE_TOPIC(Tag, Type, wire_name, kind)                     \
  struct Tag {                                                      \
    using Message = msgs::Type;                                     \
    using FastDdsType = msgs::Type##PubSubType;                     \
    static constexpr const char* name = wire_name;                  \
    static constexpr const char* type_name = "crane_msgs::msg::dds_::" #Type; \
    static constexpr QosKind qos = kind;                            \
  }

CRANE_TOPIC(Sensors, SensorSample_, "rt/crane/hw/sensors", QosKind::stream);
CRANE_TOPIC(Actuators, ActuatorCommand_, "rt/crane/hw/actuators", QosKind::stream);
CRANE_TOPIC(StateEstimate, CraneState_, "rt/crane/state/estimate", QosKind::stream);
CRANE_TOPIC(Goal, MoveRequest_, "rt/crane/planner/goal", QosKind::command);
CRANE_TOPIC(Reference, Reference_, "rt/crane/planner/reference", QosKind::stream);
CRANE_TOPIC(MoveStatus, MoveStatus_, "rt/crane/planner/move_status", QosKind::command);
CRANE_TOPIC(AntiSwing, AntiSwingCommand_, "rt/crane/control/anti_swing", QosKind::stream);
CRANE_TOPIC(LinearCommand, LinearCommand_, "rt/crane/control/linear", QosKind::stream);
CRANE_TOPIC(SafetyStatus, SupervisorStatus_, "rt/crane/safety/status", QosKind::safety);
CRANE_TOPIC(SafetyCommand, SupervisorCommand_, "rt/crane/safety/command", QosKind::command);
CRANE_TOPIC(LoopDiagnostics, LoopDiagnostics_, "rt/crane/diag/loop", QosKind::diagnostics);
CRANE_TOPIC(OperatorSpeed, OperatorSpeed_, "rt/crane/operator/speed", QosKind::command);
// The site of several cranes (issue 34), on the site's own domain (site file: domain_id), not a
// crane's: each crane's state and requests, the site service's instructions and its heartbeat.
// Reliable and volatile; each is sent again (reports and status at 10 Hz) so that a reader that
// joins late, or a restarted service, learns the state from the next sample.
CRANE_TOPIC(SiteReport, SiteReport_, "rt/site/report", QosKind::command);
CRANE_TOPIC(SiteInstruction, SiteInstruction_, "rt/site/instruction", QosKind::command);
CRANE_TOPIC(SiteStatus, SiteStatus_, "rt/site/status", QosKind::command);
// The site operator's word to the site service (crane_site_status --out-of-service).
CRANE_TOPIC(SiteCommand, SiteCommand_, "rt/site/command", QosKind::command);

#undef CRANE_TOPIC

/// Calls f.template operator()<Topic>() for every topic of the bus, in the order above: the one
/// list tools iterate (crane_topic list/echo/record).
template <class F>
void for_each_topic(F&& f) {
  f.template operator()<Sensors>();
  f.template operator()<Actuators>();
  f.template operator()<StateEstimate>();
  f.template operator()<Goal>();
  f.template operator()<Reference>();
  f.template operator()<MoveStatus>();
  f.template operator()<AntiSwing>();
  f.template operator()<LinearCommand>();
  f.template operator()<SafetyStatus>();
  f.template operator()<SafetyCommand>();
  f.template operator()<LoopDiagnostics>();
  f.template operator()<OperatorSpeed>();
}

/// The site's topics (on the site's domain; for_each_topic lists a crane's).
template <class F>
void for_each_site_topic(F&& f) {
  f.template operator()<SiteReport>();
  f.template operator()<SiteInstruction>();
  f.template operator()<SiteStatus>();
  f.template operator()<SiteCommand>();
}

}  // namespace crane::transport::topics
