// trajectory_planner process: rt/crane/planner/goal (MoveRequest), rt/crane/operator/speed
// (OperatorSpeed), rt/crane/safety/status (the operating mode, zones, faults) and rt/crane/state/estimate ->
// TrajectoryPlannerStage (step, the trapezoid of (3.43), input-shaped ZV/ZVD/EI, or the
// time-optimal swing-free profile) -> rt/crane/planner/reference, once per cycle, same seq and
// origin. Goals are taken only with a new cycle (the stage's rules: trajectory_planner_stage.hpp);
// their feedback (waiting, rejected with the bound, moving, arrived, aborted) goes to
// rt/crane/planner/move_status.
#include <spdlog/spdlog.h>

#include <optional>
#include <vector>

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
}  // namespace

int main(int argc, char** argv) {
  return runtime::run_stage(
      argc, argv, runtime::ProcessId::trajectory_planner,
      "trajectory_planner: move requests to reference trajectories (step, trapezoid (3.43), ZV/ZVD/EI input shaping, "
      "time-optimal swing-free)", {},
      [](runtime::StageContext& ctx) -> std::function<void()> {
        auto stage = std::make_shared<trajectory_planner::TrajectoryPlannerStage>(
            ctx.config.read("trajectory_planner", trajectory_planner::read_params), ctx.config.facts().sample_period);
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
          while (runtime::take_plain(*states, state, ctx.counters)) {
            const auto seq = state.header.seq;
            switch (watch->classify(seq, ctx.counters)) {
              case runtime::CycleKind::stale: continue;
              case runtime::CycleKind::repeat: break;  // answered again from *out; goals wait for a new cycle
              case runtime::CycleKind::new_cycle: {
                // Goals are taken only with a new cycle, so a cycle's reference is computed once. The
                // stage refuses (and counts) a goal with a NaN/Inf field itself, with its request id.
                arrived->clear();
                tp::msgs::MoveRequest_ request;
                while (goals->take_next(request)) {
                  protocol::from_dds(request, arrived->emplace_back());
                }
                operator_speeds->clear();
                tp::msgs::OperatorSpeed_ speed;
                while (speeds->take_next(speed) && operator_speeds->size() < operator_speeds->capacity()) {
                  protocol::from_dds(speed, operator_speeds->emplace_back());
                }
                // The latest supervisor status: the operating mode, the zones, a fault or a zone approach.
                protocol::SupervisorStatus latest;
                while (runtime::take_plain(*safety, latest, ctx.counters)) *status = latest;
                const auto refused_before = stage->nonfinite_goals() + stage->rejected_speeds();
                const trajectory_planner::PlannerCycle cycle{&state, *arrived, *operator_speeds,
                                                             status->has_value() ? &**status : nullptr};
                const auto step_status = stage->step(cycle, *out);
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
