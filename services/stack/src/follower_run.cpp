#include "crane/stack/follower_run.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "crane/common/protocol_signals.hpp"
#include "crane/friction_compensation/friction_compensation_stage.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/stack/in_process_stack.hpp"
#include "crane/stack/maneuver_bound.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"
#include "crane/supervisor/actuation_gate.hpp"
#include "crane/supervisor/supervisor_stage.hpp"
#include "crane/tracking/tracking_stage.hpp"

namespace crane::stack {
namespace {

}  // namespace

optimal_control::MinimumTimeProblem follower_problem(const StackConfig& cfg, const ManeuverConfig& m, int intervals) {
  // The bound on the controllers' model: the configured crane, rigid.
  optimal_control::MinimumTimeProblem problem = bound_problem(cfg, m, intervals);
  problem.model = plant::make_crane_dynamics(cfg.plant.kind, cfg.facts.crane, cfg.facts.bridge);
  return problem;
}

FollowerResult run_follower(const StackConfig& cfg, const FollowerRun& run) {
  const ManeuverConfig& m = run.maneuver;
  const double dt = cfg.facts.sample_period;
  const bool bridge = cfg.facts.crane_kind == common::CraneKind::overhead;
  const bool slews = cfg.facts.crane_kind == common::CraneKind::tower;

  const optimal_control::MinimumTimeProblem problem = follower_problem(cfg, m, run.intervals);
  FollowerResult result;
  result.bound = run.bound ? *run.bound : optimal_control::solve_minimum_time(problem);
  if (!result.bound.solved) {
    throw std::runtime_error("follower run " + m.name + ": the bound was not solved (" + result.bound.status + ")");
  }
  optimal_control::FollowerParams follower_params = run.follower;
  follower_params.sample_period = dt;
  follower_params.voltage_limit = cfg.facts.voltage_limit;
  const auto setup_start = std::chrono::steady_clock::now();
  const optimal_control::TrajectoryFollower follower(problem, result.bound, follower_params);
  result.follower_setup_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - setup_start).count();

  InProcessOptions plant_options;
  plant_options.mismatch = run.mismatch;
  plant_options.initial_trolley_position = m.initial_trolley_position;
  plant_options.initial_slew_angle = m.initial_slew_angle;
  plant_options.initial_bridge_position = m.initial_bridge_position;
  plant::PlantStage plant(plant_stage_params(cfg, plant_options));
  state_estimator::StateEstimatorStage estimator(cfg.state_estimator);
  auto tracking_params = cfg.tracking;
  tracking_params.law = tracking::TrackingLaw::follower;
  tracking::TrackingStage tracking(tracking_params);
  const protocol::AntiSwingCommand no_anti_swing{};
  auto compensation_params = cfg.friction_compensation;
  if (!run.friction_compensation) compensation_params.enabled = false;
  const friction_compensation::FrictionCompensationStage compensation(compensation_params);
  auto supervisor_params = cfg.supervisor;
  supervisor_params.expected_sensor_source = protocol::SensorSample::SOURCE_PLANT;
  supervisor::SupervisorStage supervisor(supervisor_params);
  supervisor::SupervisorCycle observed;
  for (auto& stage : observed.stages) stage = supervisor::StageObservation{true, true, 0.0, false};

  protocol::SensorSample sensors, next_sensors;
  protocol::CraneState estimate;
  protocol::Reference reference;
  protocol::LinearCommand linear;
  protocol::ActuatorCommand actuators;
  protocol::SupervisorStatus status, gating;
  plant.sample(next_sensors);
  const auto move_cycles = static_cast<std::uint64_t>(std::llround(m.duration / dt));
  result.swing_period = swing_period(m, cfg.facts);
  result.records.reserve(static_cast<std::size_t>(move_cycles + 1));
  for (std::uint64_t k = 0; k <= kMoveStartCycle + move_cycles; ++k) {
    sensors = next_sensors;
    if (estimator.step(sensors, estimate) != common::StepStatus::ok) {
      throw std::runtime_error("follower run: the estimator refused the sensor sample of cycle " + std::to_string(k));
    }
    // The follower's law, carried by the reference from the trajectory's first sample (rest at the
    // start) on, and applied by the tracking stage's `follower` law; 0 V until the move starts.
    const std::size_t i = k < kMoveStartCycle ? 0 : static_cast<std::size_t>(k - kMoveStartCycle);
    const optimal_control::TrajectoryNode& node = follower.node(i);
    const bool moving = follower.moving(i);
    reference = protocol::Reference{};
    reference.request_id = 1;
    reference.phase = k < kMoveStartCycle ? protocol::Reference::PHASE_HOLDING
                      : moving            ? protocol::Reference::PHASE_MOVING
                                          : protocol::Reference::PHASE_ARRIVED;
    common::set_trajectory_feedback(follower.law(i), bridge, reference);
    reference.trolley_acceleration = moving ? node.trolley_acceleration : 0.0;
    (bridge ? reference.bridge_acceleration : reference.slew_acceleration) = moving ? node.second_acceleration : 0.0;
    reference.cable_length = node.cable_length;
    reference.cable_length_rate = node.cable_length_rate;
    reference.cable_length_acceleration = moving ? node.hoist_acceleration : 0.0;
    reference.time_in_move = k < kMoveStartCycle ? 0.0 : static_cast<double>(i) * dt;
    reference.move_duration = result.bound.duration;
    common::same_cycle(estimate.header, reference.header);
    (void)tracking.step(estimate, reference, no_anti_swing, linear);  // 0 V on a refusal
    if (k < kMoveStartCycle) {
      linear.trolley_voltage = linear.slew_voltage = linear.bridge_voltage = linear.hoist_speed = 0.0;
    }
    (void)compensation.step(estimate, linear, actuators);
    observed.sensors = &sensors;
    observed.actuators = &actuators;
    observed.reference = &reference;
    observed.command = nullptr;
    supervisor.step(observed, status);
    if (k == 0) gating = status;
    (void)plant.step(supervisor::lockstep_gate_input(k, dt, &actuators, gating));
    gating = status;
    plant.sample(next_sensors);
    if (k >= kMoveStartCycle) {
      result.records.push_back(
          record_of(static_cast<double>(i) * dt, sensors, next_sensors, &reference, &linear, &actuators));
      if (next_sensors.brakes_engaged) ++result.braked_cycles;
    }
  }
  result.latched_faults = status.latched_faults;
  result.metrics = evaluate(result.records, m);
  return result;
}

}  // namespace crane::stack
