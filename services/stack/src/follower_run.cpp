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

namespace crane::stack {
namespace {

// The follower's hold (FollowerHold::sliding_friction_scale): the friction compensation's part on a
// drive that slides (outside its zero-velocity band, on the velocity the compensation uses) scaled
// by `scale`, the stiction part on a drive at rest left whole; the drive voltage is then (3.5) again.
void scale_sliding_friction(const friction_compensation::FrictionCompensationParams& params,
                            const protocol::CraneState& estimate, const protocol::LinearCommand& linear, double scale,
                            double voltage_limit, protocol::ActuatorCommand& actuators) {
  const auto slides = [](const friction_compensation::AxisCompensationParams& axis, double raw, double filtered) {
    const double v = axis.velocity_source == friction_compensation::VelocitySource::raw ? raw : filtered;
    return friction_compensation::friction_direction(v, axis.zero_velocity_band) != 0;
  };
  if (slides(params.trolley, estimate.trolley_velocity_raw, estimate.trolley_velocity)) {
    actuators.trolley_friction_voltage *= scale;
    actuators.trolley_voltage =
        std::clamp(linear.trolley_voltage + actuators.trolley_friction_voltage, -voltage_limit, voltage_limit);
  }
  if (slides(params.slew, estimate.slew_rate_raw, estimate.slew_rate)) {
    actuators.slew_friction_voltage *= scale;
    actuators.slew_voltage =
        std::clamp(linear.slew_voltage + actuators.slew_friction_voltage, -voltage_limit, voltage_limit);
  }
  // The overhead crane's bridge has its own parameters (friction_compensation.bridge).
  if (params.bridge && slides(*params.bridge, estimate.bridge_velocity_raw, estimate.bridge_velocity)) {
    actuators.bridge_friction_voltage *= scale;
    actuators.bridge_voltage =
        std::clamp(linear.bridge_voltage + actuators.bridge_friction_voltage, -voltage_limit, voltage_limit);
  }
}

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
    // The follower: the trajectory's first sample (rest at the start) until the move starts.
    const std::size_t i = k < kMoveStartCycle ? 0 : static_cast<std::size_t>(k - kMoveStartCycle);
    plant::ModelState measured;
    measured.position << estimate.trolley_position, estimate.swing_in_plane,
        bridge ? estimate.bridge_position : slews ? estimate.slew_angle : 0.0, estimate.swing_out_of_plane;
    measured.velocity << estimate.trolley_velocity, estimate.swing_in_plane_rate,
        bridge ? estimate.bridge_velocity : slews ? estimate.slew_rate : 0.0, estimate.swing_out_of_plane_rate;
    optimal_control::FollowerCommand command;
    (void)follower.step(i, measured, command);  // 0 V on a refusal, as a stage would
    if (k < kMoveStartCycle) command.trolley_voltage = command.second_voltage = command.hoist_speed = 0.0;
    linear = protocol::LinearCommand{};
    linear.trolley_voltage = command.trolley_voltage;
    linear.slew_voltage = slews ? command.second_voltage : 0.0;
    linear.bridge_voltage = bridge ? command.second_voltage : 0.0;
    linear.hoist_speed = command.hoist_speed;
    common::same_cycle(estimate.header, linear.header);
    reference = protocol::Reference{};
    reference.request_id = 1;
    reference.phase = k < kMoveStartCycle              ? protocol::Reference::PHASE_HOLDING
                      : i < follower.samples()         ? protocol::Reference::PHASE_MOVING
                                                       : protocol::Reference::PHASE_ARRIVED;
    reference.trolley_position = command.trolley.position;
    reference.trolley_velocity = command.trolley.velocity;
    reference.trolley_acceleration = command.trolley.acceleration;
    if (bridge) {
      reference.bridge_position = command.second.position;
      reference.bridge_velocity = command.second.velocity;
      reference.bridge_acceleration = command.second.acceleration;
    } else {
      reference.slew_angle = command.second.position;
      reference.slew_rate = command.second.velocity;
      reference.slew_acceleration = command.second.acceleration;
    }
    reference.cable_length = command.cable.position;
    reference.cable_length_rate = command.cable.velocity;
    reference.cable_length_acceleration = command.cable.acceleration;
    reference.time_in_move = k < kMoveStartCycle ? 0.0 : static_cast<double>(i) * dt;
    reference.move_duration = result.bound.duration;
    common::same_cycle(estimate.header, reference.header);
    (void)compensation.step(estimate, linear, actuators);
    if (command.sliding_friction_scale != 1.0) {
      scale_sliding_friction(compensation_params, estimate, linear, command.sliding_friction_scale,
                             cfg.facts.voltage_limit, actuators);
    }
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
