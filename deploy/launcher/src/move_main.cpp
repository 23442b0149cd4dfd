// crane_move: send the crane somewhere and follow it, like a ROS 2 action client (deploy/crane move).
//
//   crane_move [--trolley M] [--slew DEG] [--hoist M] [--bridge M] [--profile NAME] [--trolley-max-velocity V] ...
//              [--waypoint X,SLEW_DEG,L ...] [--wait] [--json] [--domain N] [--timeout S] [--config F]
//   crane_move --stop [--json]    a controlled anti-sway stop (deploy/crane stop): prints the stopping
//                                 position the planner predicts, then where the crane came to rest
//
// Publishes a MoveRequest_ (the axes given; the others keep their position) and follows the
// planner's MoveStatus_ feedback: rejected (the message names the field, the value and the bound),
// waiting, moving (a progress bar on a terminal, a line a second otherwise), arrived or aborted.
// With --wait it also watches the sensors and the supervisor until the load has settled (the
// demo's criteria: trolley within 5 mm, slew within 0.005 rad, swing within 0.5 deg, for 2 s) and
// prints the settle time, the final errors and the residual swing.
//
// With --config (deploy/crane passes its configuration) a goal refused for a no-go zone names it.
//
// Exit codes: 0 accepted (without --wait) or arrived (a stop: at rest), 1 no planner answered
// within --timeout, 2 rejected (the operating mode, a zone, a bound) or bad usage, 3 aborted
// (replaced by another request, stopped, the operating mode changed, a supervisor fault, an
// emergency stop, a zone approach).
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "crane/config/config_document.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/stack/maneuver_metrics.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
using json = nlohmann::json;
using Feedback = protocol::MoveStatus;
constexpr double kDeg = std::numbers::pi / 180.0;

struct MoveOptions {
  std::optional<double> trolley;        // [m]
  std::optional<double> slew_deg;       // [deg]
  std::optional<double> hoist;          // [m] cable length
  std::optional<double> bridge;         // [m] an overhead crane's bridge
  double bridge_max_velocity{0.0};      // [m/s] 0: the configured rated bridge speed
  double bridge_max_acceleration{0.0};  // [m/s^2]
  std::string profile{"trapezoid"};
  double trolley_max_velocity{0.0};     // [m/s] 0: the planner's default
  double trolley_max_acceleration{0.0}; // [m/s^2]
  double slew_max_velocity_deg{0.0};    // [deg/s]
  double slew_max_acceleration_deg{0.0};  // [deg/s^2]
  std::vector<std::string> waypoints;   // "x,slew_deg,L"
  bool wait{false};
  bool json{false};
  double timeout{30.0};                 // [s] for the planner's first answer
  double settle_timeout{60.0};          // [s] after arrival, for the load to settle (--wait)
  double sample_period{0.01};           // [s] of the sensor stream
  bool stop{false};                     // a stop request instead of a move
  std::string config;                   // the stack's configuration (names the zones)
};

std::string reason_name(std::uint8_t reason) {
  return std::string(protocol::code_name(Feedback::kCodes, "REASON", reason));
}

// The zone's name from the configuration ("" without one).
std::string zone_name(const std::string& config, double index) {
  if (config.empty()) return "";
  try {
    const auto site = config::ConfigDocument::load(config).facts().site;
    const auto i = static_cast<std::size_t>(index);
    if (index >= 0.0 && i < site.zones.size()) return site.zones[i].name;
  } catch (const std::exception&) {
  }
  return "";
}

// "trolley target 1.5 m is outside its range [0.1, 1.2] m" and the like.
std::string rejection_message(const Feedback& f, const std::string& config) {
  char b[256];
  switch (f.reason) {
    case Feedback::REASON_ZONE: {
      const std::string name = zone_name(config, f.value);
      std::snprintf(b, sizeof(b), "the target is in no-go zone %g%s%s%s, or no route around the zones keeps out of it",
                    f.value, name.empty() ? "" : " (", name.c_str(), name.empty() ? "" : ")");
      return b;
    }
    case Feedback::REASON_MODE:
      return "goals are not taken in operating mode " +
             std::string(protocol::code_name(protocol::SupervisorStatus::kCodes, "OPERATION",
                                             static_cast<std::uint64_t>(f.value))) +
             " (deploy/crane mode fullautomatic or semiautomatic)";
    case Feedback::REASON_FAULT:
      return "the supervisor has stopped the crane (mode " +
             std::string(protocol::code_name(protocol::SupervisorStatus::kCodes, "MODE",
                                             static_cast<std::uint64_t>(f.value))) +
             "): deploy/crane status, then reset";
    case Feedback::REASON_MANUAL_MOTION: return "operator speed control is moving the crane";
    case Feedback::REASON_TROLLEY_RANGE:
      std::snprintf(b, sizeof(b), "trolley target %g m is outside the travel range [%g, %g] m", f.value, f.bound_min,
                    f.bound_max);
      return b;
    case Feedback::REASON_SLEW_RANGE:
      std::snprintf(b, sizeof(b), "slew target %g deg is outside the slew range [%g, %g] deg", f.value / kDeg,
                    f.bound_min / kDeg, f.bound_max / kDeg);
      return b;
    case Feedback::REASON_BRIDGE_RANGE:
      if (f.bound_min == 0.0 && f.bound_max == 0.0) return "this crane has no bridge (crane.kind is not overhead)";
      std::snprintf(b, sizeof(b), "bridge target %g m is outside the runway travel [%g, %g] m", f.value, f.bound_min,
                    f.bound_max);
      return b;
    case Feedback::REASON_CABLE_RANGE:
      std::snprintf(b, sizeof(b), "hoist target %g m is outside the cable range [%g, %g] m", f.value, f.bound_min,
                    f.bound_max);
      return b;
    case Feedback::REASON_NON_FINITE: return "a target, limit or waypoint is not a finite number";
    case Feedback::REASON_LIMITS: return "a velocity or acceleration limit is <= 0";
    case Feedback::REASON_PROFILE: return "unknown profile";
    case Feedback::REASON_WAYPOINT: return "more than 8 waypoints, or a waypoint non-finite or out of range";
    default: return "rejected (" + reason_name(f.reason) + ")";
  }
}

protocol::MoveRequest build_request(const MoveOptions& o, std::uint32_t id) {
  using Request = protocol::MoveRequest;
  Request r;
  r.request_id = id;
  bool known = false;
  for (const auto& code : Request::kCodes) {
    if (code.group == "PROFILE" && code.name == o.profile) {
      r.profile = static_cast<std::uint8_t>(code.value);
      known = true;
    }
  }
  if (!known) throw CLI::ValidationError("--profile", "unknown profile '" + o.profile + "'");
  r.axes = static_cast<std::uint8_t>((o.trolley ? Request::AXIS_TROLLEY : 0U) | (o.slew_deg ? Request::AXIS_SLEW : 0U) |
                                     (o.hoist ? Request::AXIS_HOIST : 0U) | (o.bridge ? Request::AXIS_BRIDGE : 0U));
  r.trolley_target = o.trolley.value_or(0.0);
  r.slew_target = o.slew_deg.value_or(0.0) * kDeg;
  r.cable_length_target = o.hoist.value_or(0.0);
  r.trolley_max_velocity = o.trolley_max_velocity;
  r.trolley_max_acceleration = o.trolley_max_acceleration;
  r.slew_max_velocity = o.slew_max_velocity_deg * kDeg;
  r.slew_max_acceleration = o.slew_max_acceleration_deg * kDeg;
  r.bridge_target = o.bridge.value_or(0.0);
  r.bridge_max_velocity = o.bridge_max_velocity;
  r.bridge_max_acceleration = o.bridge_max_acceleration;
  if (o.waypoints.size() > r.waypoint_trolley.size()) {
    throw CLI::ValidationError("--waypoint", "at most " + std::to_string(r.waypoint_trolley.size()) + " waypoints");
  }
  r.waypoint_count = static_cast<std::uint8_t>(o.waypoints.size());
  for (std::size_t i = 0; i < o.waypoints.size(); ++i) {
    std::stringstream in(o.waypoints[i]);
    double x = 0.0, slew = 0.0, length = 0.0, y = 0.0;
    char c1 = 0, c2 = 0, c3 = 0;
    if (!(in >> x >> c1 >> slew >> c2 >> length) || c1 != ',' || c2 != ',') {
      throw CLI::ValidationError("--waypoint", "'" + o.waypoints[i] + "' is not X,SLEW_DEG,L[,BRIDGE]");
    }
    const bool has_bridge = static_cast<bool>(in >> c3 >> y) && c3 == ',';
    if (has_bridge != o.bridge.has_value()) {
      throw CLI::ValidationError("--waypoint", "'" + o.waypoints[i] + "': with --bridge each waypoint is X,SLEW_DEG,L,BRIDGE; "
                                 "without it X,SLEW_DEG,L");
    }
    r.waypoint_bridge[i] = y;
    r.waypoint_trolley[i] = x;
    r.waypoint_slew[i] = slew * kDeg;
    r.waypoint_cable_length[i] = length;
  }
  return r;
}

// deploy/crane stop: a stop request; its feedback: the predicted stopping position, then at rest.
int run_stop(const MoveOptions& o, const runtime::NodeOptions& node) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  auto participant = runtime::make_participant(node, "operator");
  transport::Wakeup wakeup;
  runtime::install_stop_handlers(&wakeup);
  auto goals = participant->make_writer<tp::Goal>();
  auto feedback = participant->make_recording_reader<tp::MoveStatus>(&wakeup, 64);
  const std::uint32_t id = runtime::fresh_request_id();
  protocol::MoveRequest request;
  request.request_id = id;
  request.command = protocol::MoveRequest::COMMAND_STOP;
  tp::msgs::MoveRequest_ message;
  protocol::to_dds(request, message);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.timeout));
  auto next_send = Clock::now();
  bool answered = false;
  json out{{"request_id", id}};
  while (!runtime::stop_requested() && Clock::now() < deadline) {
    if (!answered && Clock::now() >= next_send) {
      message.header().stamp(runtime::now_stamp());
      goals->write(message);
      next_send = Clock::now() + std::chrono::milliseconds(100);
    }
    tp::msgs::MoveStatus_ incoming;
    while (feedback->take_next(incoming)) {
      if (incoming.request_id() != id) continue;
      Feedback f;
      protocol::from_dds(incoming, f);
      answered = true;
      if (f.result == Feedback::RESULT_STOPPING) {
        out["predicted_trolley_m"] = f.rest_trolley_position;
        out["predicted_slew_rad"] = f.rest_slew_angle;
        out["predicted_cable_length_m"] = f.rest_cable_length;
        if (!o.json) {
          std::printf("stopping: predicted rest at trolley %.3f m, slew %.1f deg, cable %.3f m\n", f.rest_trolley_position,
                      f.rest_slew_angle / kDeg, f.rest_cable_length);
        }
      }
      if (f.result == Feedback::RESULT_ARRIVED) {
        out["result"] = "at_rest";
        out["rest_trolley_m"] = f.rest_trolley_position;
        out["rest_slew_rad"] = f.rest_slew_angle;
        out["rest_cable_length_m"] = f.rest_cable_length;
        if (o.json) std::printf("%s\n", out.dump().c_str());
        else std::printf("at rest: trolley %.3f m, slew %.1f deg, cable %.3f m (the reference; the load settles)\n",
                         f.rest_trolley_position, f.rest_slew_angle / kDeg, f.rest_cable_length);
        return 0;
      }
    }
    wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
  }
  std::fprintf(stderr, "crane_move: %s\n", answered ? "the stop did not come to rest in time"
                                                     : "no planner answered the stop request (is the stack running?)");
  return 1;
}

int run(const MoveOptions& o, const runtime::NodeOptions& node) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress lines as they come, in order with stderr
  auto participant = runtime::make_participant(node, "operator");
  transport::Wakeup wakeup;
  runtime::install_stop_handlers(&wakeup);
  auto goals = participant->make_writer<tp::Goal>();
  auto feedback = participant->make_recording_reader<tp::MoveStatus>(&wakeup, 64);
  auto sensors = participant->make_recording_reader<tp::Sensors>(nullptr, 4096);
  auto safety = participant->make_reader<tp::SafetyStatus>(nullptr);
  const bool tty = isatty(STDOUT_FILENO) != 0 && !o.json;

  const std::uint32_t id = runtime::fresh_request_id();
  const protocol::MoveRequest request = build_request(o, id);
  tp::msgs::MoveRequest_ message;
  protocol::to_dds(request, message);

  // 1. Send until the planner answers (discovery is not symmetric: re-send; the id makes repeats harmless).
  const auto answer_deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.timeout));
  auto next_send = Clock::now();
  std::optional<Feedback> last;
  std::map<std::uint64_t, protocol::SensorSample> samples;  // by cycle (the move's from start_seq on)
  std::optional<std::uint64_t> start_seq;
  std::optional<std::uint64_t> arrived_seq;
  std::optional<protocol::SensorSample> first_sample;
  auto next_line = Clock::now();
  std::optional<Clock::time_point> settle_deadline;
  const stack::SettleCriteria criteria;
  double trolley_target = request.trolley_target, slew_target = request.slew_target;
  double bridge_target = request.bridge_target;
  std::string abort_reason;
  while (!runtime::stop_requested()) {
    const auto now = Clock::now();
    if (!last && now >= next_send) {
      message.header().stamp(runtime::now_stamp());
      goals->write(message);
      next_send = now + std::chrono::milliseconds(100);
    }
    if (!last && now > answer_deadline) {
      std::fprintf(stderr, "crane_move: no planner answered request %u within %.0f s (is the stack running on domain "
                           "%u?)\n", id, o.timeout, node.domain_id);
      return 1;
    }
    tp::msgs::MoveStatus_ incoming;
    while (feedback->take_next(incoming)) {
      if (incoming.request_id() != id) continue;
      Feedback f;
      protocol::from_dds(incoming, f);
      last = f;
      if (f.result == Feedback::RESULT_REJECTED) {
        const std::string text = rejection_message(f, o.config);
        if (o.json) {
          std::printf("%s\n", json{{"result", "rejected"}, {"request_id", id}, {"reason", reason_name(f.reason)},
                                   {"value", f.value}, {"bound_min", f.bound_min}, {"bound_max", f.bound_max},
                                   {"message", text}}.dump().c_str());
        } else {
          std::fprintf(stderr, "crane_move: request %u rejected: %s\n", id, text.c_str());
        }
        return 2;
      }
      if (f.result == Feedback::RESULT_ABORTED) {
        abort_reason = f.reason == Feedback::REASON_REPLACED ? "replaced by a newer request"
                       : f.reason == Feedback::REASON_STOPPED ? "stopped (deploy/crane stop)"
                       : f.reason == Feedback::REASON_MODE    ? "the operating mode changed (a soft stop first)"
                       : f.reason == Feedback::REASON_FAULT   ? "the supervisor stopped the crane"
                       : f.reason == Feedback::REASON_ZONE    ? "approaching a no-go zone (a soft stop)"
                       : f.reason == Feedback::REASON_LIMIT_APPROACH ? "approaching a travel limit too fast (a soft stop)"
                       : f.reason == Feedback::REASON_MANUAL_MOTION ? "the operator's stick took over"
                       : f.reason == Feedback::REASON_BRAKED ? "the drives were braked under way (a stalled command chain)"
                                                                   : reason_name(f.reason);
        break;
      }
      if (f.result == Feedback::RESULT_MOVING && !start_seq) start_seq = f.header.seq;
      if (f.result == Feedback::RESULT_ARRIVED) {
        arrived_seq = f.header.seq;
        if (!start_seq) start_seq = f.header.seq;
        settle_deadline = now + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.settle_timeout));
      }
      if (!o.wait && (f.result == Feedback::RESULT_MOVING || f.result == Feedback::RESULT_WAITING ||
                      f.result == Feedback::RESULT_ARRIVED)) {
        if (o.json) std::printf("%s\n", json{{"result", "accepted"}, {"request_id", id}}.dump().c_str());
        else std::printf("request %u accepted\n", id);
        return 0;
      }
      if (tty && f.result == Feedback::RESULT_MOVING && f.move_duration > 0.0) {
        const double done = std::clamp(f.time_in_move / f.move_duration, 0.0, 1.0);
        const int bar = static_cast<int>(done * 30.0);
        std::printf("\r[%-30s] %3.0f%%  trolley %+.3f m, slew %+.1f deg, hoist %+.3f m to go, %.1f of %.1f s ",
                    std::string(static_cast<std::size_t>(bar), '#').c_str(), done * 100.0, f.trolley_to_go,
                    f.slew_to_go / kDeg, f.cable_to_go, f.time_in_move, f.move_duration);
        std::fflush(stdout);
      } else if (!o.json && f.result == Feedback::RESULT_MOVING && now >= next_line) {
        next_line = now + std::chrono::seconds(1);
        std::printf("moving: trolley %+.3f m, slew %+.1f deg, hoist %+.3f m to go, %.1f of %.1f s\n", f.trolley_to_go,
                    f.slew_to_go / kDeg, f.cable_to_go, f.time_in_move, f.move_duration);
      }
    }
    if (!abort_reason.empty()) break;
    tp::msgs::SupervisorStatus_ status;
    if (last && safety->take_latest(status) &&
        (status.mode() == protocol::SupervisorStatus::MODE_FAULT ||
         status.mode() == protocol::SupervisorStatus::MODE_EMERGENCY_STOP)) {
      abort_reason = "supervisor " + std::string(protocol::code_name(protocol::SupervisorStatus::kCodes, "MODE", status.mode())) +
                     " (last fault " + std::string(protocol::code_name(protocol::SupervisorStatus::kCodes, "FAULT", status.last_fault())) + ")";
      break;
    }
    tp::msgs::SensorSample_ sample;
    while (sensors->take_next(sample)) {
      if (!runtime::all_finite(sample)) continue;
      protocol::SensorSample s;
      protocol::from_dds(sample, s);
      if (!first_sample) first_sample = s;
      samples[s.header.seq] = s;
    }
    if (arrived_seq && !samples.empty()) {
      samples.erase(samples.begin(), samples.lower_bound(*start_seq));
      // Settled for good: every criterion has held for the residual window since some cycle.
      if (!o.trolley) trolley_target = first_sample->trolley_position;
      if (!o.slew_deg) slew_target = first_sample->slew_angle;
      if (!o.bridge) bridge_target = first_sample->bridge_position;
      std::uint64_t calm = 0;
      for (auto it = samples.rbegin(); it != samples.rend(); ++it) {
        const auto& s = it->second;
        const bool ok = std::fabs(s.trolley_position - trolley_target) < criteria.trolley_tolerance &&
                        std::fabs(s.slew_angle - slew_target) < criteria.slew_tolerance &&
                        std::fabs(s.bridge_position - bridge_target) < criteria.trolley_tolerance &&
                        std::fabs(s.swing_in_plane) < criteria.swing_tolerance &&
                        std::fabs(s.swing_out_of_plane) < criteria.swing_tolerance;
        if (!ok) break;
        ++calm;
      }
      const auto window = static_cast<std::uint64_t>(criteria.residual_window / o.sample_period);
      if ((samples.rbegin()->first >= *arrived_seq && calm > window) || Clock::now() > *settle_deadline) break;
    }
    wakeup.wait_until(Clock::now() + std::chrono::milliseconds(20));
  }
  if (tty) std::printf("\n");
  if (runtime::stop_requested()) abort_reason = "interrupted (the move goes on; deploy/crane stop or estop to stop it)";
  if (!abort_reason.empty()) {
    if (o.json) {
      std::printf("%s\n", json{{"result", "aborted"}, {"request_id", id}, {"reason", abort_reason}}.dump().c_str());
    } else {
      std::fprintf(stderr, "crane_move: request %u aborted: %s\n", id, abort_reason.c_str());
    }
    return 3;
  }
  std::vector<stack::RecordedCycle> cycles;
  if (start_seq) samples.erase(samples.begin(), samples.lower_bound(*start_seq));
  for (const auto& [seq, s] : samples) {
    cycles.push_back({static_cast<double>(seq - *start_seq) * o.sample_period, s.trolley_position, s.slew_angle,
                      s.swing_in_plane, s.swing_out_of_plane, s.applied_trolley_voltage, s.applied_slew_voltage,
                      s.bridge_position, s.applied_bridge_voltage});
  }
  if (cycles.empty()) {
    std::fprintf(stderr, "crane_move: request %u arrived, but no sensor sample of the move was received\n", id);
    return 3;
  }
  const auto m = stack::evaluate_maneuver(cycles, trolley_target, slew_target, criteria, bridge_target);
  json result{{"result", "arrived"},
                    {"request_id", id},
                    {"move_duration_s", last ? last->move_duration : 0.0},
                    {"settle_time_s", std::isfinite(m.settle_time) ? json(m.settle_time) : json(nullptr)},
                    {"final_position_error_m", m.final_position_error},
                    {"final_slew_error_rad", m.final_slew_error},
                    {"max_swing_rad", m.max_swing},
                    {"residual_swing_rad", m.residual_swing},
                    {"final_cable_length_m", cycles.empty() ? 0.0 : samples.rbegin()->second.cable_length}};
  if (o.bridge) result["final_bridge_error_m"] = m.final_bridge_error;
  if (o.json) {
    std::printf("%s\n", result.dump().c_str());
  } else {
    char settle[32] = "- (not settled)";
    if (std::isfinite(m.settle_time)) std::snprintf(settle, sizeof(settle), "%.2f", m.settle_time);
    std::printf("arrived: settle %s s, trolley error %.2f mm, slew error %.2f mrad, residual swing %.3f deg (max %.1f deg)\n",
                settle,
                m.final_position_error * 1e3, m.final_slew_error * 1e3, m.residual_swing / kDeg, m.max_swing / kDeg);
    if (o.bridge) std::printf("         bridge error %.2f mm\n", m.final_bridge_error * 1e3);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_move: send the crane to a position and follow the move (the planner's MoveStatus feedback)"};
  MoveOptions o;
  runtime::NodeOptions node;
  app.add_option("--dds", node.dds, "DDS vendor: fast | cyclone (default: $CRANE_DDS, else fast)");
  app.add_option("--domain", node.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_option("--dds-profile", node.dds_profile, "network profile (deploy/dds/*.xml)")->check(CLI::ExistingFile);
  bool lan = false;
  app.add_flag("--lan", lan, "reach the stack over the network (UDP) instead of loopback only");
  runtime::add_iceoryx_option(app, node);
  runtime::add_security_options(app, node);  // identity: the participant's, "operator"
  app.add_option("--trolley", o.trolley, "[m] trolley target")->check(CLI::Range(-100.0, 100.0));
  app.add_option("--slew", o.slew_deg, "[deg] slew target")->check(CLI::Range(-3600.0, 3600.0));
  app.add_option("--hoist", o.hoist, "[m] cable length target")->check(CLI::Range(0.0, 200.0));
  app.add_option("--bridge", o.bridge, "[m] bridge target (overhead crane)")->check(CLI::Range(-1000.0, 1000.0));
  app.add_option("--bridge-max-velocity", o.bridge_max_velocity, "[m/s] (default: the configured rated bridge speed)")
      ->check(CLI::PositiveNumber);
  app.add_option("--bridge-max-acceleration", o.bridge_max_acceleration, "[m/s^2]")->check(CLI::PositiveNumber);
  app.add_option("--profile", o.profile, "step | trapezoid | zv | zvd | ei | time_optimal (default trapezoid)");
  app.add_option("--trolley-max-velocity", o.trolley_max_velocity, "[m/s] (default: the planner's)")->check(CLI::PositiveNumber);
  app.add_option("--trolley-max-acceleration", o.trolley_max_acceleration, "[m/s^2]")->check(CLI::PositiveNumber);
  app.add_option("--slew-max-velocity", o.slew_max_velocity_deg, "[deg/s]")->check(CLI::PositiveNumber);
  app.add_option("--slew-max-acceleration", o.slew_max_acceleration_deg, "[deg/s^2]")->check(CLI::PositiveNumber);
  app.add_option("--waypoint", o.waypoints, "X,SLEW_DEG,L: an intermediate point (repeat, up to 8)");
  app.add_flag("--wait", o.wait, "follow the move to its end and until the load settles; print the figures");
  app.add_flag("--json", o.json, "one JSON object on stdout");
  app.add_option("--timeout", o.timeout, "[s] for the planner's answer")->check(CLI::PositiveNumber);
  app.add_option("--settle-timeout", o.settle_timeout, "[s] after arrival, for the load to settle")->check(CLI::PositiveNumber);
  app.add_option("--sample-period", o.sample_period, "[s] of the sensor stream")->check(CLI::PositiveNumber);
  app.add_flag("--stop", o.stop, "a controlled anti-sway stop of whatever moves (deploy/crane stop)");
  app.add_option("--config", o.config, "the stack's configuration: names the no-go zones in messages");
  CLI11_PARSE(app, argc, argv);
  node.loopback_only = !lan;
  node.shared_memory = !lan;
  if (o.stop) {
    try {
      runtime::configure_logging("warn", "move");
      return run_stop(o, node);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "crane_move: %s\n", error.what());
      return 1;
    }
  }
  if (!o.trolley && !o.slew_deg && !o.hoist && !o.bridge && o.waypoints.empty()) {
    std::fprintf(stderr, "crane_move: give at least one of --trolley, --slew, --hoist, --bridge\n");
    return 2;
  }
  try {
    runtime::configure_logging("warn", "move");
    return run(o, node);
  } catch (const CLI::ValidationError& error) {
    std::fprintf(stderr, "crane_move: %s\n", error.what());
    return 2;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_move: %s\n", error.what());
    return 1;
  }
}
