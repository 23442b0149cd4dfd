#include "crane/stack/maneuver_run.hpp"

#include "crane/common/validation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <ostream>
#include <stdexcept>

namespace crane::stack {

ControllerChoice choose_controller(std::string_view controller, const ManeuverConfig& m, bool acceleration_feedforward) {
  ControllerChoice c;
  c.acceleration_feedforward = acceleration_feedforward;
  if (controller == "auto") {
    // The best measured for the time-optimal profile (docs/architecture.md): a trolley move is
    // swing-free by itself and tracked by PD with acceleration feedforward, no anti-swing law to
    // disturb it; a slew leaves swing the linear design does not foresee (centripetal coupling),
    // which the second delayed-feedback law (3.50) damps without exceeding the speed limits.
    const bool slews = std::fabs(m.slew_target - m.initial_slew_angle) > 1e-9;
    c.anti_swing = slews ? anti_swing::AntiSwingLaw::delay2 : anti_swing::AntiSwingLaw::none;
    c.acceleration_feedforward = true;
  } else if (controller.rfind("gain_scheduling", 0) == 0) {
    c.tracking = tracking::law_from_name(controller, "controller");
    c.anti_swing = anti_swing::AntiSwingLaw::none;
  } else {
    try {
      c.anti_swing = anti_swing::law_from_name(controller, "controller");
    } catch (const common::ConfigError& error) {
      throw std::invalid_argument(error.what());
    }
  }
  c.label = std::string(c.tracking == tracking::TrackingLaw::tracking ? anti_swing::law_name(c.anti_swing)
                                                                      : tracking::law_name(c.tracking));
  if (c.acceleration_feedforward) c.label += "+feedforward";
  return c;
}

std::uint8_t profile_code(std::string_view profile) {
  for (const auto& code : protocol::MoveRequest::kCodes) {
    if (code.group == "PROFILE" && code.name == profile) return static_cast<std::uint8_t>(code.value);
  }
  throw std::invalid_argument("unknown profile '" + std::string(profile) + "'");
}

protocol::MoveRequest move_request(const ManeuverConfig& m, const common::StackFacts& facts, std::uint32_t request_id,
                                   std::uint8_t profile, std::uint64_t start_cycle) {
  using Request = protocol::MoveRequest;
  Request goal;
  goal.header.seq = start_cycle;
  goal.request_id = request_id;
  goal.profile = profile;
  const bool hoists = m.cable_length_target != facts.crane.cable_length;
  goal.axes = Request::AXIS_TROLLEY | Request::AXIS_SLEW | (hoists ? Request::AXIS_HOIST : 0U);
  goal.trolley_target = m.trolley_target;
  goal.slew_target = m.slew_target;
  goal.cable_length_target = m.cable_length_target;
  goal.trolley_max_velocity = m.trolley_max_velocity;
  goal.trolley_max_acceleration = m.trolley_max_acceleration;
  goal.slew_max_velocity = m.slew_max_velocity;
  goal.slew_max_acceleration = m.slew_max_acceleration;
  if (facts.crane_kind == common::CraneKind::overhead) {
    goal.axes |= Request::AXIS_BRIDGE;
    goal.bridge_target = m.bridge_target;
    goal.bridge_max_velocity = m.bridge_max_velocity;
    goal.bridge_max_acceleration = m.bridge_max_acceleration;
  }
  return goal;
}

double swing_period(const ManeuverConfig& m, const common::StackFacts& facts) {
  return 2.0 * std::numbers::pi * std::sqrt(m.cable_length_target / facts.crane.gravity);
}

CycleRecord record_of(double t, const protocol::SensorSample& s, const protocol::SensorSample& next,
                      const protocol::Reference* r, const protocol::LinearCommand* l,
                      const protocol::ActuatorCommand* a) noexcept {
  const double nan = std::nan("");
  CycleRecord c;
  c.t = t;
  c.u_x = next.applied_trolley_voltage;
  c.u_gamma = next.applied_slew_voltage;
  c.x = s.trolley_position;
  c.gamma = s.slew_angle;
  c.phi = s.swing_in_plane;
  c.theta = s.swing_out_of_plane;
  c.L = s.cable_length;
  c.x_ref = r != nullptr ? r->trolley_position : nan;
  c.gamma_ref = r != nullptr ? r->slew_angle : nan;
  c.V_x = l != nullptr ? l->trolley_voltage : nan;
  c.V_gamma = l != nullptr ? l->slew_voltage : nan;
  c.friction_x = a != nullptr ? a->trolley_friction_voltage : nan;
  c.friction_gamma = a != nullptr ? a->slew_friction_voltage : nan;
  c.u_x_cmd = a != nullptr ? a->trolley_voltage : nan;
  c.u_gamma_cmd = a != nullptr ? a->slew_voltage : nan;
  c.brakes = next.brakes_engaged;
  c.y = s.bridge_position;
  c.u_y = next.applied_bridge_voltage;
  c.y_ref = r != nullptr ? r->bridge_position : nan;
  c.V_y = l != nullptr ? l->bridge_voltage : nan;
  c.friction_y = a != nullptr ? a->bridge_friction_voltage : nan;
  c.u_y_cmd = a != nullptr ? a->bridge_voltage : nan;
  return c;
}

void write_csv(std::ostream& out, const std::vector<CycleRecord>& records, bool bridge) {
  out << "t,u_x,u_gamma,x,gamma,phi,theta,L,x_ref,gamma_ref,V_x,V_gamma,friction_x,friction_gamma,"
         "u_x_cmd,u_gamma_cmd,brakes"
      << (bridge ? ",y,u_y,y_ref,V_y,friction_y,u_y_cmd\n" : "\n");
  out.precision(9);
  for (const auto& c : records) {
    out << c.t << ',' << c.u_x << ',' << c.u_gamma << ',' << c.x << ',' << c.gamma << ',' << c.phi << ',' << c.theta
        << ',' << c.L << ',' << c.x_ref << ',' << c.gamma_ref << ',' << c.V_x << ',' << c.V_gamma << ','
        << c.friction_x << ',' << c.friction_gamma << ',' << c.u_x_cmd << ',' << c.u_gamma_cmd << ','
        << (c.brakes ? 1 : 0);
    if (bridge) {
      out << ',' << c.y << ',' << c.u_y << ',' << c.y_ref << ',' << c.V_y << ',' << c.friction_y << ',' << c.u_y_cmd;
    }
    out << '\n';
  }
}

ManeuverMetrics evaluate(const std::vector<CycleRecord>& records, const ManeuverConfig& m) {
  std::vector<RecordedCycle> cycles;
  cycles.reserve(records.size());
  for (const auto& r : records) cycles.push_back({r.t, r.x, r.gamma, r.phi, r.theta, r.u_x, r.u_gamma, r.y, r.u_y});
  return evaluate_maneuver(cycles, m.trolley_target, m.slew_target, SettleCriteria{}, m.bridge_target);
}

std::string format_number(double v, int precision) {
  if (!std::isfinite(v)) return "-";
  char b[64];
  std::snprintf(b, sizeof(b), "%.*f", precision, v);
  return b;
}

std::string table_header(bool bridge) {
  char b[256];
  std::snprintf(b, sizeof(b), "%-13s %-9s %9s %7s %10s %11s %10s %12s %8s", "maneuver", "friction", "settle_s",
                "settle_T", "pos_err_mm", "slew_err_mrad", "max_swing_deg", "resid_swing_deg", "max_V");
  return bridge ? std::string(b) + " bridge_err_mm" : std::string(b);
}

std::vector<PrintedFigure> printed_figures(const ManeuverMetrics& m, double period, bool bridge) {
  constexpr double kDegrees = 180.0 / std::numbers::pi;
  std::vector<PrintedFigure> f{
      {"settle_s", m.settle_time, 2},
      {"settle_T", m.settle_time / period, 2},
      {"pos_err_mm", m.final_position_error * 1e3, 2},
      {"slew_err_mrad", m.final_slew_error * 1e3, 2},
      {"max_swing_deg", m.max_swing * kDegrees, 2},
      {"resid_swing_deg", m.residual_swing * kDegrees, 3},
      {"max_V", m.max_voltage, 2},
  };
  if (bridge) f.push_back({"bridge_err_mm", m.final_bridge_error * 1e3, 2});
  return f;
}

std::string table_row(const std::string& maneuver, bool friction_compensation, const ManeuverMetrics& m,
                      double period, bool bridge) {
  const auto f = printed_figures(m, period, bridge);
  const auto text = [&](std::size_t i) { return format_number(f[i].value, f[i].decimals); };
  char b[256];
  std::snprintf(b, sizeof(b), "%-13s %-9s %9s %7s %10s %11s %10s %12s %8s", maneuver.c_str(),
                friction_compensation ? "comp_on" : "comp_off", text(0).c_str(), text(1).c_str(), text(2).c_str(),
                text(3).c_str(), text(4).c_str(), text(5).c_str(), text(6).c_str());
  if (bridge) return std::string(b) + " " + std::string(13 - std::min<std::size_t>(13, text(7).size()), ' ') + text(7);
  return b;
}

}  // namespace crane::stack
