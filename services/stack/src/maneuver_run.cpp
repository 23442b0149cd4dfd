#include "crane/stack/maneuver_run.hpp"

#include "crane/common/validation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
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
  } else if (controller == "follower") {
    // The minimum-time follower: its law travels on the reference (PROFILE_MINIMUM_TIME); no
    // anti-swing law beside it (a reference without a law is tracked by the PD alone).
    c.tracking = tracking::TrackingLaw::follower;
    c.anti_swing = anti_swing::AntiSwingLaw::none;
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

double minimum_time_of(const protocol::Reference& first) noexcept {
  return first.feedback_law ? first.move_duration : std::numeric_limits<double>::quiet_NaN();
}

std::string default_controller(std::string_view profile) {
  if (profile.empty() || profile == "minimum_time") return "follower";
  return profile == "time_optimal" ? "auto" : "delay1";
}

std::optional<std::string_view> implied_profile(std::string_view controller) {
  // The dissertation drives the gain-scheduling controllers with step references (section 3.2).
  if (controller.rfind("gain_scheduling", 0) == 0) return "step";
  if (controller == "follower") return "minimum_time";
  return std::nullopt;
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

namespace {
// The columns' widths, in printed_figures' order (the header is the figure's name).
constexpr int kWidths[] = {9, 7, 6, 8, 10, 11, 10, 12, 8, 13};
}  // namespace

std::string table_header(bool bridge) {
  std::string line;
  char b[64];
  std::snprintf(b, sizeof(b), "%-13s %-9s", "maneuver", "friction");
  line = b;
  const auto figures = printed_figures(ManeuverMetrics{}, 1.0, bridge);
  for (std::size_t i = 0; i < figures.size(); ++i) {
    std::snprintf(b, sizeof(b), " %*s", kWidths[i], figures[i].name);
    line += b;
  }
  return line;
}

std::vector<PrintedFigure> printed_figures(const ManeuverMetrics& m, double period, bool bridge) {
  constexpr double kDegrees = 180.0 / std::numbers::pi;
  std::vector<PrintedFigure> f{
      {"settle_s", m.settle_time, 2},
      {"settle_T", m.settle_time / period, 2},
      {"T*_s", m.minimum_time, 2},
      {"settle/T*", m.settle_time / m.minimum_time, 2},
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
  char b[64];
  std::snprintf(b, sizeof(b), "%-13s %-9s", maneuver.c_str(), friction_compensation ? "comp_on" : "comp_off");
  std::string line = b;
  for (std::size_t i = 0; i < f.size(); ++i) {
    std::snprintf(b, sizeof(b), " %*s", kWidths[i], format_number(f[i].value, f[i].decimals).c_str());
    line += b;
  }
  return line;
}

}  // namespace crane::stack
