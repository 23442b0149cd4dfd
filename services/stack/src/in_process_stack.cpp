#include "crane/stack/in_process_stack.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/common/validation.hpp"
#include "crane/friction_compensation/friction_compensation_stage.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"
#include "crane/supervisor/actuation_gate.hpp"
#include "crane/supervisor/supervisor_stage.hpp"
#include "crane/tracking/tracking_stage.hpp"

namespace crane::stack {
namespace {

double checked_probability(double p) {
  common::require_in_range("InProcessOptions.lost_command_probability", p, 0.0, 1.0);
  return p;
}

anti_swing::AntiSwingStageParams anti_swing_params(const StackConfig& cfg, const InProcessOptions& o) {
  auto p = cfg.anti_swing;
  p.law = o.controller.anti_swing;
  return p;
}
state_estimator::StateEstimatorStageParams estimator_params(const StackConfig& cfg, const InProcessOptions& o) {
  return o.controller.follower_filter() ? state_estimator::for_follower(cfg.state_estimator) : cfg.state_estimator;
}
tracking::TrackingStageParams tracking_params(const StackConfig& cfg, const InProcessOptions& o) {
  auto p = cfg.tracking;
  p.law = o.controller.tracking;
  p.tracking.acceleration_feedforward = o.controller.acceleration_feedforward;
  return p;
}
friction_compensation::FrictionCompensationParams compensation_params(const StackConfig& cfg,
                                                                      const InProcessOptions& o) {
  auto p = cfg.friction_compensation;
  if (!o.friction_compensation) p.enabled = false;
  return p;
}
supervisor::SupervisorParams supervisor_params(const StackConfig& cfg) {
  auto p = cfg.supervisor;
  p.expected_sensor_source = protocol::SensorSample::SOURCE_PLANT;
  return p;
}

}  // namespace

plant::PlantStageParams plant_stage_params(const StackConfig& cfg, const InProcessOptions& o) {
  plant::PlantStageParams p;
  p.simulator = cfg.plant;
  p.simulator.initial_state.trolley_position = o.initial_trolley_position;
  p.simulator.initial_state.slew_angle = o.initial_slew_angle;
  p.simulator.initial_state.bridge_position = o.initial_bridge_position;
  p.gate = cfg.actuation;
  p.mismatch = o.mismatch;
  return p;
}

struct InProcessStack::Stages {
  Stages(const StackConfig& cfg, const InProcessOptions& o)
      : dt(cfg.facts.sample_period),
        plan_move(o.plan_move),
        lost_from(o.lost_commands_from),
        lost_until(o.lost_commands_from + o.lost_commands),
        lost_probability(checked_probability(o.lost_command_probability)),
        lost_random(o.lost_command_seed),
        plant(plant_stage_params(cfg, o)),
        estimator(estimator_params(cfg, o)),
        planner(cfg.trajectory_planner, dt),
        anti_swing(anti_swing_params(cfg, o)),
        tracking(tracking_params(cfg, o)),
        compensation(compensation_params(cfg, o)),
        supervisor(supervisor_params(cfg)) {
    // Every stage fresh and present, one writer on each topic: what the lockstep supervisor sees
    // of a complete cycle over DDS.
    for (auto& stage : observed.stages) stage = supervisor::StageObservation{true, true, 0.0, false};
    plant.sample(next_sensors);
  }
  double dt;
  MovePlanner plan_move;
  std::uint64_t lost_from, lost_until;  // cycles [lost_from, lost_until) lose their command
  double lost_probability;               // and each other cycle with this probability
  std::mt19937_64 lost_random;
  std::uint64_t planned_sequence{0};  // the last plan request answered (PlanRequest::sequence)
  plant::PlantStage plant;
  state_estimator::StateEstimatorStage estimator;
  trajectory_planner::TrajectoryPlannerStage planner;
  anti_swing::AntiSwingStage anti_swing;
  tracking::TrackingStage tracking;
  const friction_compensation::FrictionCompensationStage compensation;
  supervisor::SupervisorStage supervisor;
  supervisor::SupervisorCycle observed;
  protocol::SensorSample sensors, next_sensors;
  protocol::CraneState estimate;
  protocol::Reference reference;
  protocol::AntiSwingCommand action;
  protocol::LinearCommand linear;
  protocol::ActuatorCommand actuators;
  protocol::SupervisorStatus status, gating;
  std::uint64_t k{0};
  std::uint64_t plant_step_failures{0};
};

MovePlanner planner_node_way(const StackConfig& cfg, const optimal_control::MovePlanning& planning) {
  return [facts = cfg.facts, params = cfg.trajectory_planner, planning](const trajectory_planner::PlanRequest& request)
             -> std::shared_ptr<const trajectory_planner::PlannedPath> {
    try {
      return optimal_control::plan_minimum_time_move(request, facts, params, planning);
    } catch (const common::ConfigError&) {
      return nullptr;  // a request the bound cannot take: the time-optimal profile runs
    }
  };
}

namespace {
InProcessOptions with_planner(const StackConfig& cfg, InProcessOptions o) {
  if (!o.plan_move) o.plan_move = planner_node_way(cfg);
  return o;
}
}  // namespace

InProcessStack::InProcessStack(const StackConfig& config, const InProcessOptions& options)
    : stages_(std::make_unique<Stages>(config, with_planner(config, options))) {}
InProcessStack::~InProcessStack() = default;

void InProcessStack::step(std::span<const protocol::MoveRequest> goals, std::span<const protocol::OperatorSpeed> speeds,
                          const protocol::SupervisorCommand* command) {
  Stages& s = *stages_;
  const std::uint64_t k = s.k;
  s.sensors = s.next_sensors;
  if (s.estimator.step(s.sensors, s.estimate) != common::StepStatus::ok) {
    throw std::runtime_error("in-process run: the estimator refused the sensor sample of cycle " + std::to_string(k));
  }
  // The planner and the anti-swing law see the supervisor's status of the previous cycle (none
  // before cycle 1): the operating mode.
  const protocol::SupervisorStatus* previous = k == 0 ? nullptr : &s.gating;
  const trajectory_planner::PlannerCycle cycle{&s.estimate, goals, speeds, previous};
  if (s.planner.step(cycle, s.reference) != common::StepStatus::ok) {
    throw std::runtime_error("in-process run: the planner did not answer cycle " + std::to_string(k));
  }
  if (const auto& request = s.planner.plan_request(); request && request->sequence != s.planned_sequence) {
    // A minimum-time goal: solved here, in the cycle it arrived (the DDS planner node solves in
    // lockstep the same way, and on a worker thread in real time); its move starts next cycle.
    s.planned_sequence = request->sequence;
    s.planner.provide_plan(request->sequence, s.plan_move(*request));
  }
  if (s.anti_swing.step(s.estimate, previous, s.action) == common::StepStatus::rejected_nonfinite) {
    throw std::runtime_error("in-process run: the anti-swing law refused the estimate of cycle " + std::to_string(k));
  }
  (void)s.tracking.step(s.estimate, s.reference, s.action, s.linear);  // 0 V on a refusal, as the node
  (void)s.compensation.step(s.estimate, s.linear, s.actuators);
  s.observed.sensors = &s.sensors;
  s.observed.actuators = &s.actuators;
  s.observed.reference = &s.reference;
  s.observed.command = command;
  s.supervisor.step(s.observed, s.status);
  if (k == 0) s.gating = s.status;  // cycle 0 is gated by the status of cycle 0, cycle k by that of k - 1
  const bool lost = (k >= s.lost_from && k < s.lost_until) ||
                    (s.lost_probability > 0.0 && std::uniform_real_distribution<double>(0.0, 1.0)(s.lost_random) < s.lost_probability);
  if (s.plant.step(supervisor::lockstep_gate_input(k, s.dt, lost ? nullptr : &s.actuators, s.gating)) !=
      common::StepStatus::ok) {
    ++s.plant_step_failures;
  }
  s.gating = s.status;
  s.plant.sample(s.next_sensors);
  ++s.k;
}

std::uint64_t InProcessStack::cycle() const noexcept { return stages_->k; }
const protocol::SensorSample& InProcessStack::sensors() const noexcept { return stages_->sensors; }
const protocol::SensorSample& InProcessStack::next_sensors() const noexcept { return stages_->next_sensors; }
const protocol::CraneState& InProcessStack::estimate() const noexcept { return stages_->estimate; }
const protocol::Reference& InProcessStack::reference() const noexcept { return stages_->reference; }
const protocol::AntiSwingCommand& InProcessStack::anti_swing() const noexcept { return stages_->action; }
const protocol::LinearCommand& InProcessStack::linear() const noexcept { return stages_->linear; }
const protocol::ActuatorCommand& InProcessStack::actuators() const noexcept { return stages_->actuators; }
const protocol::SupervisorStatus& InProcessStack::status() const noexcept { return stages_->status; }
const trajectory_planner::TrajectoryPlannerStage& InProcessStack::planner() const noexcept { return stages_->planner; }
const plant::PlantStage& InProcessStack::plant() const noexcept { return stages_->plant; }
std::uint64_t InProcessStack::plant_step_failures() const noexcept { return stages_->plant_step_failures; }

InProcessResult run_in_process(const StackConfig& cfg, const InProcessRun& run) {
  const ManeuverConfig& m = run.maneuver;
  const double dt = cfg.facts.sample_period;
  if (run.start_cycle == 0) throw std::invalid_argument("run_in_process: start_cycle must be > 0");
  InProcessOptions options;
  options.friction_compensation = run.friction_compensation;
  options.controller = run.controller;
  options.mismatch = run.mismatch;
  options.plan_move = run.plan_move;
  const ManeuverConfig& from = run.first_move ? *run.first_move : m;  // where the crane starts
  options.initial_trolley_position = from.initial_trolley_position;
  options.initial_slew_angle = from.initial_slew_angle;
  options.initial_bridge_position = from.initial_bridge_position;
  InProcessStack stack(cfg, options);
  InProcessResult result;
  const auto trace = [&] {
    if (!run.record_plant) return;
    result.plant_inputs.push_back(stack.plant().drive_input());
    result.plant_states.push_back(stack.plant().simulator().state());
  };
  const auto cycles_needed = static_cast<std::uint64_t>(std::llround(m.duration / dt));

  std::uint64_t k = 0;  // cycles stepped
  std::uint64_t start_cycle = run.start_cycle;
  if (run.first_move) {
    const ManeuverConfig& f = *run.first_move;
    if (f.trolley_target != m.initial_trolley_position || f.slew_target != m.initial_slew_angle ||
        f.bridge_target != m.initial_bridge_position) {
      throw std::invalid_argument("run_in_process: the first move " + f.name + " does not end where " + m.name + " starts");
    }
    if (f.cable_length_target != cfg.facts.crane.cable_length) {
      throw std::invalid_argument("run_in_process: a first move with hoisting (" + f.name + ")");
    }
    const protocol::MoveRequest first = move_request(f, cfg.facts, run.request_id, run.first_move_profile, start_cycle);
    const auto first_cycles = static_cast<std::uint64_t>(std::llround(f.duration / dt));
    for (; k <= start_cycle + first_cycles; ++k) {
      stack.step(k == 0 ? std::span(&first, 1) : std::span<const protocol::MoveRequest>());
      trace();
      for (const auto& outcome : stack.planner().goal_outcomes()) {
        if (outcome.status != trajectory_planner::GoalStatus::accepted) {
          throw std::runtime_error("in-process run: the first move was refused: " +
                                   std::string(trajectory_planner::goal_status_name(outcome.status)));
        }
      }
    }
    if (stack.status().latched_faults != 0) {
      throw std::runtime_error("in-process run: the supervisor latched faults (FAULT_* bits) " + std::to_string(stack.status().latched_faults) +
                               " in the first move " + f.name);
    }
    start_cycle += k;
  }
  // The measured move's request arrives at this cycle: after the first move, or at cycle 1, when the
  // planner has heard the supervisor (its status of cycle 0: the sway limit a minimum-time plan
  // needs), as over DDS, where it arrives a few cycles after the stack is ready.
  const std::uint64_t goal_cycle = std::max<std::uint64_t>(k, 1);
  const std::uint32_t request_id = run.first_move ? run.request_id + 1 : run.request_id;  // the planner takes newer ids
  const protocol::MoveRequest goal = move_request(m, cfg.facts, request_id, run.profile, start_cycle);

  result.swing_period = swing_period(m, cfg.facts);
  result.records.reserve(static_cast<std::size_t>(cycles_needed + 1));
  bool started = false;
  std::uint64_t start_seq = 0;
  double minimum_time = 0.0;
  for (;; ++k) {
    // The goal arrives while the crane rests (over DDS: a few cycles after the stack is ready) and
    // waits in the planner for its start cycle.
    stack.step(k == goal_cycle ? std::span(&goal, 1) : std::span<const protocol::MoveRequest>());
    trace();
    for (const auto& outcome : stack.planner().goal_outcomes()) {
      if (outcome.status != trajectory_planner::GoalStatus::accepted) {
        throw std::runtime_error("in-process run: move request refused at cycle " + std::to_string(k) + ": " +
                                 trajectory_planner::goal_status_name(outcome.status));
      }
    }
    const auto& reference = stack.reference();
    if (!started && reference.request_id == goal.request_id && reference.phase != protocol::Reference::PHASE_HOLDING) {
      started = true;
      start_seq = k;
      minimum_time = minimum_time_of(reference);
    }
    if (started) {
      result.records.push_back(record_of(static_cast<double>(k - start_seq) * dt, stack.sensors(), stack.next_sensors(),
                                         &reference, &stack.linear(), &stack.actuators()));
      if (stack.next_sensors().brakes_engaged) ++result.braked_cycles;
      if (k == start_seq + cycles_needed) break;
    } else if (k > start_cycle + 10) {
      throw std::runtime_error("in-process run: the move did not start by cycle " + std::to_string(k));
    }
  }
  result.cycles = stack.plant().cycle();
  result.plant_step_failures = stack.plant_step_failures();
  result.friction_events = stack.plant().simulator().friction_event_count();
  result.latched_faults = stack.status().latched_faults;
  result.unsolved_plans = stack.planner().unsolved_plans();
  result.integrator_work = stack.plant().simulator().integrator_work();
  if (run.record_plant) result.plant_parameters = stack.plant().simulator().parameters();
  result.metrics = evaluate(result.records, m);
  result.metrics.minimum_time = minimum_time;
  return result;
}

}  // namespace crane::stack
