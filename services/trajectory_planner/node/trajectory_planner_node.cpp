// trajectory_planner process: rt/crane/planner/goal (MoveRequest) and rt/crane/state/estimate ->
// reference trajectory (step, the trapezoid of (3.43), input-shaped ZV/ZVD/EI, or the time-optimal
// swing-free profile) -> rt/crane/planner/reference, once per
// cycle, same seq and origin. Holds the first measured position until a goal arrives.
#include <algorithm>
#include <optional>
#include <spdlog/spdlog.h>

#include "crane/runtime/stage_node.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace {
using namespace crane;
namespace tp = transport::topics;

trajectory_planner::MoveGoal to_goal(const tp::msgs::MoveRequest_& r, const common::CraneStateEstimate& current) {
  trajectory_planner::MoveGoal g;
  g.request_id = r.request_id();
  using trajectory_planner::ProfileKind;
  switch (r.profile()) {
    case 0: g.profile = ProfileKind::step; break;
    case 1: g.profile = ProfileKind::trapezoid; break;
    case 2: g.profile = ProfileKind::zv; break;
    case 3: g.profile = ProfileKind::zvd; break;
    case 4: g.profile = ProfileKind::ei; break;
    case 5: g.profile = ProfileKind::time_optimal; break;
    default:
      // Not a ProfileKind: start_move() answers rejected_unknown_profile and keeps the running move.
      spdlog::warn("move request {} rejected: unknown profile code {}", r.request_id(), r.profile());
      g.profile = static_cast<ProfileKind>(-1);
      break;
  }
  // An axis not named in `axes` keeps its current position.
  g.trolley_target = (r.axes() & 0x1) != 0 ? r.trolley_target() : current.trolley_position;
  g.slew_target = (r.axes() & 0x2) != 0 ? r.slew_target() : current.slew_angle;
  g.cable_target = (r.axes() & 0x4) != 0 ? r.cable_length_target() : current.cable_length;
  if (r.trolley_max_velocity() > 0.0) g.trolley_limits.max_velocity = r.trolley_max_velocity();
  if (r.trolley_max_acceleration() > 0.0) g.trolley_limits.max_acceleration = r.trolley_max_acceleration();
  if (r.slew_max_velocity() > 0.0) g.slew_limits.max_velocity = r.slew_max_velocity();
  if (r.slew_max_acceleration() > 0.0) g.slew_limits.max_acceleration = r.slew_max_acceleration();
  // Waypoints: an axis not named in `axes` stays where it is at every waypoint. More than
  // kMaxWaypoints is passed on as such, and start_move() rejects it.
  g.waypoint_count = r.waypoint_count();
  for (std::size_t i = 0; i < std::min<std::size_t>(g.waypoint_count, trajectory_planner::kMaxWaypoints); ++i) {
    g.waypoints[i].trolley = (r.axes() & 0x1) != 0 ? r.waypoint_trolley()[i] : current.trolley_position;
    g.waypoints[i].slew = (r.axes() & 0x2) != 0 ? r.waypoint_slew()[i] : current.slew_angle;
    g.waypoints[i].cable = (r.axes() & 0x4) != 0 ? r.waypoint_cable_length()[i] : current.cable_length;
  }
  return g;
}

const char* goal_status_name(trajectory_planner::GoalStatus s) {
  using trajectory_planner::GoalStatus;
  switch (s) {
    case GoalStatus::accepted: return "accepted";
    case GoalStatus::rejected_nonfinite: return "rejected: non-finite field";
    case GoalStatus::rejected_trolley_out_of_range: return "rejected: trolley target outside the travel limits";
    case GoalStatus::rejected_slew_out_of_range: return "rejected: slew target outside the slew range";
    case GoalStatus::rejected_cable_out_of_range: return "rejected: cable length target outside its range";
    case GoalStatus::rejected_invalid_limits: return "rejected: velocity or acceleration limit <= 0, or no profile";
    case GoalStatus::rejected_unknown_profile: return "rejected: unknown profile code";
    case GoalStatus::rejected_waypoint: return "rejected: more than 8 waypoints, or a waypoint non-finite or out of range";
  }
  return "unknown";
}
}  // namespace

int main(int argc, char** argv) {
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::trajectory_planner,
      "trajectory_planner: move requests to reference trajectories (step, trapezoid (3.43), ZV/ZVD/EI input shaping, "
      "time-optimal swing-free)", {},
      [](runtime::StageContext& ctx) -> std::function<void()> {
        auto planner = std::make_shared<trajectory_planner::TrajectoryPlanner>(ctx.config.trajectory_planner);
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(&ctx.wakeup));
        auto goals = std::shared_ptr(ctx.participant.make_reader<tp::Goal>(&ctx.wakeup));
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::Reference>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto out = std::make_shared<tp::msgs::Reference_>();
        auto output = std::make_shared<trajectory_planner::PlannerOutput>();
        auto holding = std::make_shared<bool>(false);
        auto last_request = std::make_shared<std::uint32_t>(0);
        auto pending = std::make_shared<std::optional<tp::msgs::MoveRequest_>>();  // waits for its start cycle
        const double dt = ctx.config.plant.sample_period;
        return [=, &ctx] {
          tp::msgs::CraneState_ state;
          while (runtime::take_finite(*states, state, ctx.counters)) {
            const auto seq = state.header().seq();
            switch (watch->classify(seq, ctx.counters)) {
              case runtime::CycleKind::stale: continue;
              case runtime::CycleKind::repeat: break;  // answered again from *out; goals wait for a new cycle
              case runtime::CycleKind::new_cycle: {
                const auto current = runtime::to_estimate(state);
                if (!*holding) {
                  *holding = planner->hold(current) == trajectory_planner::GoalStatus::accepted;
                  if (!*holding) continue;
                }
                // Goals are taken only at a new cycle, so a cycle's reference is computed once. A goal
                // whose header names a later cycle (header.seq) waits for it: a start at a cycle, not at
                // a wall-clock moment (the lockstep demo's runs are then identical to the last bit).
                tp::msgs::MoveRequest_ request;
                while (goals->take_next(request)) {
                  if (!runtime::all_finite(request)) {
                    ++ctx.counters.nonfinite_rejected;
                    spdlog::warn("move request {} rejected: non-finite field", request.request_id());
                    continue;
                  }
                  // Operators re-send a request until they see it executed: ids only increase.
                  if (request.request_id() <= *last_request) continue;
                  *last_request = request.request_id();
                  if (request.header().seq() > seq) {
                    *pending = request;
                    continue;
                  }
                  if (request.header().seq() != 0 && request.header().seq() < seq) {
                    spdlog::warn("move request {} asked to start at cycle {}, arrived at cycle {}: starts now",
                                 request.request_id(), request.header().seq(), seq);
                  }
                  pending->reset();
                  const auto status = planner->start_move(to_goal(request, current), current);
                  spdlog::info("move request {} to x = {} m, gamma = {} rad at cycle {}: {}", request.request_id(),
                               request.trolley_target(), request.slew_target(), seq, goal_status_name(status));
                }
                if (pending->has_value() && (*pending)->header().seq() <= seq) {
                  const auto status = planner->start_move(to_goal(**pending, current), current);
                  spdlog::info("move request {} to x = {} m, gamma = {} rad at cycle {}, as asked: {}",
                               (*pending)->request_id(), (*pending)->trolley_target(), (*pending)->slew_target(), seq,
                               goal_status_name(status));
                  pending->reset();
                }
                if (planner->step(dt, *output) != common::StepStatus::ok) continue;
                ++ctx.counters.cycles;
                runtime::from_reference(output->reference, *out);
                out->request_id(static_cast<std::uint32_t>(output->request_id));
                out->phase(static_cast<std::uint8_t>(output->phase));
                out->time_in_move(output->time_in_move);
                out->move_duration(output->move_duration);
                watch->answered(seq);
                break;
              }
            }
            runtime::stamp_header(out->header(), seq, state.header().origin());
            writer->write(*out);
            runtime::record_latency(ctx.latency, out->header());
          }
        };
      });
}
