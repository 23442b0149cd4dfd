#include "crane/stack/in_process_stack.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/friction_compensation/friction_compensation_stage.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"
#include "crane/supervisor/actuation_gate.hpp"
#include "crane/supervisor/supervisor_stage.hpp"
#include "crane/tracking/tracking_stage.hpp"
#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

namespace crane::stack {

InProcessResult run_in_process(const StackConfig& cfg, const InProcessRun& run) {
  const ManeuverConfig& m = run.maneuver;
  const double dt = cfg.facts.sample_period;
  if (run.start_cycle == 0) throw std::invalid_argument("run_in_process: start_cycle must be > 0");

  plant::PlantStageParams plant_params;
  plant_params.simulator = cfg.plant;
  plant_params.simulator.initial_state.trolley_position = m.initial_trolley_position;
  plant_params.simulator.initial_state.slew_angle = m.initial_slew_angle;
  plant_params.gate = cfg.actuation;
  plant_params.mismatch = run.mismatch;
  plant::PlantStage plant(plant_params);

  state_estimator::StateEstimatorStage estimator(cfg.state_estimator);
  trajectory_planner::TrajectoryPlannerStage planner(cfg.trajectory_planner, dt);
  auto anti_swing_params = cfg.anti_swing;
  anti_swing_params.law = run.controller.anti_swing;
  anti_swing::AntiSwingStage anti_swing(anti_swing_params);
  auto tracking_params = cfg.tracking;
  tracking_params.law = run.controller.tracking;
  tracking_params.tracking.acceleration_feedforward = run.controller.acceleration_feedforward;
  tracking::TrackingStage tracking(tracking_params);
  auto compensation_params = cfg.friction_compensation;
  if (!run.friction_compensation) compensation_params.enabled = false;
  const friction_compensation::FrictionCompensationStage compensation(compensation_params);
  auto supervisor_params = cfg.supervisor;
  supervisor_params.expected_sensor_source = protocol::SensorSample::SOURCE_PLANT;
  supervisor::SupervisorStage supervisor(supervisor_params);

  const protocol::MoveRequest goal =
      move_request(m, cfg.facts, run.request_id, run.profile, run.start_cycle);
  const auto cycles_needed = static_cast<std::uint64_t>(std::llround(m.duration / dt));

  InProcessResult result;
  result.swing_period = swing_period(m, cfg.facts);
  result.records.reserve(static_cast<std::size_t>(cycles_needed + 1));

  // Every stage fresh and present, one writer on each topic: what the lockstep supervisor sees of
  // a complete cycle over DDS.
  supervisor::SupervisorCycle observed;
  for (auto& stage : observed.stages) stage = supervisor::StageObservation{true, true, 0.0, false};

  protocol::SensorSample sensors, next_sensors;
  protocol::CraneState estimate;
  protocol::Reference reference;
  protocol::AntiSwingCommand action;
  protocol::LinearCommand linear;
  protocol::ActuatorCommand actuators;
  protocol::SupervisorStatus status, gating;
  bool started = false;
  std::uint64_t start_seq = 0;
  plant.sample(sensors);
  for (std::uint64_t k = 0;; ++k) {
    if (estimator.step(sensors, estimate) != common::StepStatus::ok) {
      throw std::runtime_error("in-process run: the estimator refused the sensor sample of cycle " + std::to_string(k));
    }
    // The goal arrives while the crane rests (over DDS: a few cycles after the stack is ready) and
    // waits in the planner for its start cycle.
    const std::span<const protocol::MoveRequest> goals = k == 0 ? std::span(&goal, 1) : std::span<const protocol::MoveRequest>();
    if (planner.step(estimate, goals, reference) != common::StepStatus::ok) {
      throw std::runtime_error("in-process run: the planner did not answer cycle " + std::to_string(k));
    }
    for (const auto& outcome : planner.goal_outcomes()) {
      if (outcome.status != trajectory_planner::GoalStatus::accepted) {
        throw std::runtime_error("in-process run: move request refused at cycle " + std::to_string(k) + ": " +
                                 trajectory_planner::goal_status_name(outcome.status));
      }
    }
    if (anti_swing.step(estimate, action) == common::StepStatus::rejected_nonfinite) {
      throw std::runtime_error("in-process run: the anti-swing law refused the estimate of cycle " + std::to_string(k));
    }
    (void)tracking.step(estimate, reference, action, linear);            // 0 V on a refusal, as the node
    (void)compensation.step(estimate, linear, actuators);
    observed.sensors = &sensors;
    observed.actuators = &actuators;
    observed.reference = &reference;
    supervisor.step(observed, status);
    if (k == 0) gating = status;  // cycle 0 is gated by the status of cycle 0, cycle k by that of k - 1
    if (plant.step(supervisor::lockstep_gate_input(k, dt, &actuators, gating)) != common::StepStatus::ok) {
      ++result.plant_step_failures;
    }
    gating = status;
    plant.sample(next_sensors);
    if (!started && reference.request_id == goal.request_id && reference.phase != protocol::Reference::PHASE_HOLDING) {
      started = true;
      start_seq = k;
    }
    if (started) {
      result.records.push_back(record_of(static_cast<double>(k - start_seq) * dt, sensors, next_sensors, &reference,
                                         &linear, &actuators));
      if (next_sensors.brakes_engaged) ++result.braked_cycles;
      if (k == start_seq + cycles_needed) break;
    } else if (k > run.start_cycle + 10) {
      throw std::runtime_error("in-process run: the move did not start by cycle " + std::to_string(k));
    }
    sensors = next_sensors;
  }
  result.cycles = plant.cycle();
  result.friction_events = plant.simulator().friction_event_count();
  result.latched_faults = status.latched_faults;
  result.metrics = evaluate(result.records, m);
  return result;
}

}  // namespace crane::stack
