// trajectory_planner process: rt/crane/planner/goal (MoveRequest), rt/crane/operator/speed
// (OperatorSpeed), rt/crane/safety/status (the operating mode, zones, faults) and rt/crane/state/estimate ->
// TrajectoryPlannerStage (step, the trapezoid of (3.43), input-shaped ZV/ZVD/EI, or the
// time-optimal swing-free profile) -> rt/crane/planner/reference, once per cycle, same seq and
// origin. Goals are taken only with a new cycle, once the supervisor has been heard (the stage's
// rules: trajectory_planner_stage.hpp); their feedback (waiting, rejected with the bound, moving,
// arrived, aborted) goes to rt/crane/planner/move_status. A goal with the minimum-time profile is
// planned here (Planning below: the bound solved by IPOPT and its follower's law,
// optimal_control/planned_move.hpp) and handed to the stage, whose reference then carries the law
// of each cycle.
#include <spdlog/spdlog.h>

#include <chrono>
#include <future>
#include <optional>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/optimal_control/planned_move.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/runtime/stage_node.hpp"
#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

namespace {
using namespace crane;
namespace tp = transport::topics;

void log_outcome(const trajectory_planner::GoalOutcome& o) {
  using When = trajectory_planner::GoalOutcome::When;
  switch (o.when) {
    case When::ignored: return;  // a re-sent request
    case When::waiting:
      spdlog::info("move request {} waits for its start cycle {} (now {})", o.request_id, o.asked_cycle, o.cycle);
      return;
    case When::late:
      spdlog::warn("move request {} asked to start at cycle {}, arrived at cycle {}: starts now", o.request_id,
                   o.asked_cycle, o.cycle);
      break;
    case When::now:
    case When::as_asked: break;
  }
  if (o.status == trajectory_planner::GoalStatus::rejected_nonfinite) {
    spdlog::warn("move request {} rejected: non-finite field", o.request_id);
    return;
  }
  spdlog::info("move request {} to x = {} m, gamma = {} rad at cycle {}{}: {}", o.request_id, o.trolley_target,
               o.slew_target, o.cycle, o.when == When::as_asked ? ", as asked" : "",
               trajectory_planner::goal_status_name(o.status));
}
// The minimum-time plan of a goal (PROFILE_MINIMUM_TIME): null when the bound is not solved or the
// request is one the bound cannot take (the stage then runs the time-optimal profile).
std::shared_ptr<const trajectory_planner::PlannedPath> plan(const trajectory_planner::PlanRequest& request,
                                                           const common::StackFacts& facts,
                                                           const trajectory_planner::TrajectoryPlannerParams& params) {
  optimal_control::MinimumTimeResult bound;
  try {
    auto path = optimal_control::plan_minimum_time_move(request, facts, params, optimal_control::MovePlanning{}, &bound);
    if (path && bound.fallback) {
      spdlog::warn("move request {}: the minimum-time bound was not solved; its fixed-duration fallback runs, "
                   "{:.4f} s ({} IPOPT iterations, {} restart(s), {:.2f} s)",
                   request.request_id, bound.trajectory_duration, bound.iterations, bound.restarts, bound.solve_seconds);
    } else if (path) {
      spdlog::info("move request {}: minimum-time plan, T* = {:.4f} s, trajectory {:.4f} s ({}), {} + {} IPOPT "
                   "iterations in {:.2f} s ({} restart(s)); the pendulum {:.4f} L + {:.4f} m",
                   request.request_id, bound.duration, bound.trajectory_duration,
                   bound.robust         ? "least effort, robust to the pendulum's length"
                   : bound.least_effort ? "least effort"
                                        : "the minimum-time solve's",
                   bound.iterations,
                   bound.effort_iterations, bound.solve_seconds, bound.restarts, request.swing.scale,
                   request.swing.offset);
    } else {
      spdlog::warn("move request {}: the minimum-time bound was not solved ({}): the time-optimal profile runs",
                   request.request_id, bound.status);
    }
    return path;
  } catch (const std::exception& error) {
    spdlog::warn("move request {}: no minimum-time plan ({}): the time-optimal profile runs", request.request_id,
                 error.what());
    return nullptr;
  }
}

// Solves the stage's plan requests on a worker thread at normal priority (never on the DDS listener
// thread the stage runs on), handed over before the first cycle after it ends. In real time the
// crane holds meanwhile. In lockstep the solve holds the next cycle: the stage takes no new cycle
// until the plan is handed over, so every run starts the move at the same cycle, as when the solve
// ran in the cycle (the chain waits for this stage, as for any).
class Planning {
 public:
  Planning(bool lockstep, common::StackFacts facts, trajectory_planner::TrajectoryPlannerParams params)
      : lockstep_(lockstep), facts_(std::move(facts)), params_(std::move(params)) {}

  /// In lockstep, while a solve runs: take no new cycle.
  [[nodiscard]] bool holds_cycle() const {
    return lockstep_ && worker_.valid() && worker_.wait_for(std::chrono::seconds(0)) != std::future_status::ready;
  }
  /// Hands a finished plan to the stage (before its step: that cycle uses it).
  void collect(trajectory_planner::TrajectoryPlannerStage& stage) {
    if (worker_.valid() && worker_.wait_for(std::chrono::seconds(0)) == std::future_status::ready) {
      stage.provide_plan(worker_sequence_, worker_.get());  // ignored if the request was dropped meanwhile
    }
  }
  /// Starts the solve of a new plan request of the stage (after its step).
  void start(trajectory_planner::TrajectoryPlannerStage& stage) {
    const auto& request = stage.plan_request();
    if (!request || request->sequence == started_sequence_ || worker_.valid()) return;
    started_sequence_ = request->sequence;
    worker_sequence_ = started_sequence_;
    worker_ = std::async(std::launch::async, [request = *request, facts = facts_, params = params_] {
      runtime::leave_realtime_this_thread();
      return plan(request, facts, params);
    });
  }

 private:
  bool lockstep_;
  common::StackFacts facts_;
  trajectory_planner::TrajectoryPlannerParams params_;
  std::uint64_t started_sequence_{0};
  std::uint64_t worker_sequence_{0};
  std::future<std::shared_ptr<const trajectory_planner::PlannedPath>> worker_;
};
}  // namespace

int main(int argc, char** argv) {
  bool lockstep = false;
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::trajectory_planner,
      "trajectory_planner: move requests to reference trajectories (step, trapezoid (3.43), ZV/ZVD/EI input shaping, "
      "time-optimal swing-free, the minimum-time bound with its follower's law)",
      [&lockstep](CLI::App& app) {
        app.add_flag("--lockstep", lockstep,
                     "a minimum-time plan holds the next cycle until it is solved (the chain waits: every run the "
                     "same); default: the crane holds while it is solved");
      },
      [&lockstep](runtime::StageContext& ctx) -> std::function<void()> {
        const auto params = ctx.config.read("trajectory_planner", trajectory_planner::read_params);
        auto stage = std::make_shared<trajectory_planner::TrajectoryPlannerStage>(params, ctx.config.facts().sample_period);
        auto planning = std::make_shared<Planning>(lockstep, ctx.config.facts(), params);
        auto states = std::shared_ptr(ctx.participant.make_reader<tp::StateEstimate>(&ctx.wakeup));
        auto goals = std::shared_ptr(ctx.participant.make_reader<tp::Goal>(&ctx.wakeup));
        auto speeds = std::shared_ptr(ctx.participant.make_reader<tp::OperatorSpeed>(nullptr));
        auto safety = std::shared_ptr(ctx.participant.make_reader<tp::SafetyStatus>(nullptr));
        auto status = std::make_shared<std::optional<protocol::SupervisorStatus>>();
        auto operator_speeds = std::make_shared<std::vector<protocol::OperatorSpeed>>();
        operator_speeds->reserve(64);
        auto writer = std::shared_ptr(ctx.participant.make_writer<tp::Reference>());
        auto feedback = std::shared_ptr(ctx.participant.make_writer<tp::MoveStatus>());
        auto watch = std::make_shared<runtime::SequenceWatch>();
        auto out = std::make_shared<protocol::Reference>();
        auto arrived = std::make_shared<std::vector<protocol::MoveRequest>>();
        arrived->reserve(trajectory_planner::TrajectoryPlannerStage::kMaxGoalsPerCycle);
        return [=, &ctx] {
          protocol::CraneState state;
          // While a lockstep solve runs, the next cycle's state waits in its reader.
          while (!planning->holds_cycle() && runtime::take_plain(*states, state, ctx.counters)) {
            const auto seq = state.header.seq;
            switch (watch->classify(seq, ctx.counters)) {
              case runtime::CycleKind::stale: continue;
              case runtime::CycleKind::repeat: break;  // answered again from *out; goals wait for a new cycle
              case runtime::CycleKind::new_cycle: {
                // The latest supervisor status: the operating mode, the zones, a fault or a zone approach.
                protocol::SupervisorStatus latest;
                while (runtime::take_plain(*safety, latest, ctx.counters)) *status = latest;
                // Goals are taken only with a new cycle, so a cycle's reference is computed once, and
                // only once the supervisor has been heard: before, the operating mode and the sway
                // limit a minimum-time plan needs are unknown, and a goal waits in the reader (its
                // history: 8). Over DDS the two can match hundreds of cycles apart (a Cyclone planner
                // and a Fast DDS supervisor in lockstep); a minimum-time goal then started unplanned
                // (CI of stop 42). The stage refuses (and counts) a goal with a NaN/Inf field itself.
                arrived->clear();
                tp::msgs::MoveRequest_ request;
                while (status->has_value() && goals->take_next(request)) {
                  protocol::from_dds(request, arrived->emplace_back());
                }
                operator_speeds->clear();
                tp::msgs::OperatorSpeed_ speed;
                while (speeds->take_next(speed) && operator_speeds->size() < operator_speeds->capacity()) {
                  protocol::from_dds(speed, operator_speeds->emplace_back());
                }
                const auto refused_before = stage->nonfinite_goals() + stage->rejected_speeds();
                const trajectory_planner::PlannerCycle cycle{&state, *arrived, *operator_speeds,
                                                             status->has_value() ? &**status : nullptr};
                const auto unsolved_before = stage->unsolved_plans();
                planning->collect(*stage);
                const auto step_status = stage->step(cycle, *out);
                planning->start(*stage);
                if (stage->unsolved_plans() != unsolved_before) {
                  spdlog::warn("a minimum-time goal started without its plan ({} so far): the time-optimal profile runs",
                               stage->unsolved_plans());
                }
                for (const auto& outcome : stage->goal_outcomes()) log_outcome(outcome);
                for (const auto& move_status : stage->move_statuses()) runtime::write_plain(*feedback, move_status);
                ctx.counters.nonfinite_rejected += stage->nonfinite_goals() + stage->rejected_speeds() - refused_before;
                if (step_status != common::StepStatus::ok) continue;
                ++ctx.counters.cycles;
                watch->answered(seq);
                break;
              }
            }
            out->header.origin = state.header.origin;  // a re-offer may carry a newer origin
            runtime::write_plain(*writer, *out);
            runtime::record_latency(ctx.latency, out->header);
          }
        };
      });
}
