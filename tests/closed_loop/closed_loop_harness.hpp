#pragma once
// Closed-loop simulation of the crane stack without DDS: the pure cores wired in-process, one
// sample period per cycle, mirroring the data flow of the nodes exactly:
//
//   cycle k:  plant.output()            quantized sensors of seq k          (plant_node.cpp)
//          -> estimator.step()          estimate k                          (state_estimator_node.cpp)
//          -> planner.step(dt)          reference k; hold() on the first
//                                       estimate, start_move() at k = 0     (trajectory_planner_node.cpp)
//          -> anti_swing.step()         action k (zero while the delay
//                                       line fills: not_ready)               (anti_swing_node.cpp)
//          -> tracking.step()           linear command k                    (tracking_node.cpp)
//          -> friction_compensation     u = V + F_f/K_m with estimate k     (friction_compensation_node.cpp)
//          -> plant.step(u, brakes released)  ZOH over [k, k+1], DAC-quantized inside the plant
//
// The recording mirrors crane_demo (deploy/launcher/src/demo_main.cpp): cycles k = 0 .. duration/dt,
// t = k dt, the sensors of seq k and the applied (DAC-quantized) voltages of the command of cycle
// k, which the plant reports with seq k + 1. The figures of merit are those of the demo
// (crane::launch::evaluate_maneuver).

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include "crane/anti_swing/anti_swing.hpp"
#include "crane/config/simulator_parameters.hpp"
#include "crane/config/stack_config.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"
#include "crane/launch/maneuver_metrics.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/state_estimator/state_estimator.hpp"
#include "crane/tracking/tracking_controller.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::closed_loop {

/// One cycle of a closed-loop run.
struct TraceSample {
  double time{0.0};                 // [s] since the move started (k dt)
  double trolley_position{0.0};     // [m] measured x
  double slew_angle{0.0};           // [rad] measured gamma
  double swing_in_plane{0.0};       // [rad] measured phi
  double swing_out_of_plane{0.0};   // [rad] measured theta
  double trolley_reference{0.0};    // [m]
  double slew_reference{0.0};       // [rad]
  double trolley_linear_voltage{0.0};  // [V] tracking output V_x (before compensation)
  double slew_linear_voltage{0.0};     // [V]
  double trolley_friction_voltage{0.0};  // [V] F_f/K_m added by the compensator
  double slew_friction_voltage{0.0};     // [V]
  double trolley_voltage{0.0};      // [V] applied by the plant (after the DAC)
  double slew_voltage{0.0};         // [V] applied by the plant (after the DAC)
  double trolley_velocity_true{0.0};  // [m/s] true plant state after the cycle (diagnostics)
};

struct Trace {
  std::string maneuver;
  bool friction_compensation{true};
  double trolley_target{0.0};   // [m]
  double slew_target{0.0};      // [rad]
  double swing_period{0.0};     // [s] T = 2 pi sqrt(L/g)
  std::vector<TraceSample> samples;
  launch::ManeuverMetrics metrics;
  long plant_step_failures{0};  // plant steps that did not return ok
  long friction_events{0};
};

/// Non-asserted diagnostics of the end of a run (limit cycles / chatter).
struct TailStatistics {
  int trolley_voltage_sign_changes{0};  // sign changes of the applied trolley voltage (|V| > 1 DAC step)
  int slew_voltage_sign_changes{0};
  double trolley_voltage_peak{0.0};     // [V] max |applied trolley voltage|
  double slew_voltage_peak{0.0};        // [V]
  double trolley_span{0.0};             // [m] max x - min x
  double slew_span{0.0};                // [rad]
  double trolley_voltage_max_jump{0.0}; // [V] max |u(k) - u(k-1)| of the applied trolley voltage
  double slew_voltage_max_jump{0.0};    // [V]
};

/// Statistics over the samples with time >= end_time - window.
inline TailStatistics tail_statistics(const Trace& trace, double window) {
  TailStatistics s;
  if (trace.samples.empty()) return s;
  const double start = trace.samples.back().time - window;
  constexpr double kDeadband = 2.5e-3;  // [V] about one DAC code: ignore +-0 flicker
  double last_x_sign = 0.0;
  double last_g_sign = 0.0;
  double x_min = 1e300, x_max = -1e300, g_min = 1e300, g_max = -1e300;
  const TraceSample* previous = nullptr;
  for (const auto& c : trace.samples) {
    if (c.time < start) continue;
    if (previous != nullptr) {
      s.trolley_voltage_max_jump =
          std::max(s.trolley_voltage_max_jump, std::fabs(c.trolley_voltage - previous->trolley_voltage));
      s.slew_voltage_max_jump = std::max(s.slew_voltage_max_jump, std::fabs(c.slew_voltage - previous->slew_voltage));
    }
    previous = &c;
    s.trolley_voltage_peak = std::max(s.trolley_voltage_peak, std::fabs(c.trolley_voltage));
    s.slew_voltage_peak = std::max(s.slew_voltage_peak, std::fabs(c.slew_voltage));
    x_min = std::min(x_min, c.trolley_position);
    x_max = std::max(x_max, c.trolley_position);
    g_min = std::min(g_min, c.slew_angle);
    g_max = std::max(g_max, c.slew_angle);
    if (std::fabs(c.trolley_voltage) > kDeadband) {
      const double sign = c.trolley_voltage > 0.0 ? 1.0 : -1.0;
      if (last_x_sign != 0.0 && sign != last_x_sign) ++s.trolley_voltage_sign_changes;
      last_x_sign = sign;
    }
    if (std::fabs(c.slew_voltage) > kDeadband) {
      const double sign = c.slew_voltage > 0.0 ? 1.0 : -1.0;
      if (last_g_sign != 0.0 && sign != last_g_sign) ++s.slew_voltage_sign_changes;
      last_g_sign = sign;
    }
  }
  s.trolley_span = x_max - x_min;
  s.slew_span = g_max - g_min;
  return s;
}

/// Plant parameters as the plant process builds them, starting at the maneuver's position.
inline plant::SimulatorParameters simulator_parameters(const config::StackConfig& cfg,
                                                       const config::ManeuverConfig& maneuver) {
  plant::PlantState initial;
  initial.trolley_position = maneuver.initial_trolley_position;
  initial.slew_angle = maneuver.initial_slew_angle;
  return config::simulator_parameters(cfg, initial);
}

/// Runs `maneuver` through the whole stack configured by `cfg`; `friction_compensation` = false is
/// the friction_compensation node's --disable (u = V, still clamped). `plant_override`, when given,
/// replaces the plant parameters (e.g. a frictionless plant); it must start where the maneuver does.
inline Trace run_closed_loop(const config::StackConfig& cfg, const config::ManeuverConfig& maneuver,
                             bool friction_compensation,
                             const plant::SimulatorParameters* plant_override = nullptr) {
  const plant::SimulatorParameters sim_params =
      plant_override != nullptr ? *plant_override : simulator_parameters(cfg, maneuver);
  plant::CraneSimulator simulator(sim_params);
  state_estimator::StateEstimator estimator(cfg.state_estimator);
  trajectory_planner::TrajectoryPlanner planner(cfg.trajectory_planner);
  anti_swing::AntiSwing anti_swing(cfg.anti_swing);
  const tracking::TrackingController tracking(cfg.tracking);
  auto compensation_params = cfg.friction_compensation;
  if (!friction_compensation) compensation_params.enabled = false;
  const friction_compensation::FrictionCompensation compensator(compensation_params);

  const double dt = cfg.plant.sample_period;
  const auto cycles = static_cast<std::int64_t>(std::llround(maneuver.duration / dt));

  Trace trace;
  trace.maneuver = maneuver.name;
  trace.friction_compensation = friction_compensation;
  trace.trolley_target = maneuver.trolley_target;
  trace.slew_target = maneuver.slew_target;
  trace.swing_period = 2.0 * 3.14159265358979323846 * std::sqrt(cfg.crane.cable_length / cfg.crane.gravity);
  trace.samples.reserve(static_cast<std::size_t>(cycles + 1));

  common::CraneStateEstimate estimate;
  trajectory_planner::PlannerOutput reference;
  anti_swing::AntiSwingOutput action;
  tracking::TrackingOutput linear;
  friction_compensation::FrictionCompensationOutput compensated;

  for (std::int64_t k = 0; k <= cycles; ++k) {
    const plant::SimulatorOutput sensors = simulator.output();
    if (estimator.step(sensors.measurement, estimate) != common::StepStatus::ok) {
      throw std::runtime_error("closed loop: the estimator rejected the measurement of cycle " + std::to_string(k));
    }
    if (k == 0) {
      // trajectory_planner_node: hold the first estimate, then the move request (axes 0x3: the
      // cable keeps its current length), trapezoid profile (crane_demo sends profile 1).
      if (planner.hold(estimate) != trajectory_planner::GoalStatus::accepted) {
        throw std::runtime_error("closed loop: planner.hold refused the first estimate");
      }
      trajectory_planner::MoveGoal goal;
      goal.request_id = 1;
      goal.profile = trajectory_planner::ProfileKind::trapezoid;
      goal.trolley_target = maneuver.trolley_target;
      goal.slew_target = maneuver.slew_target;
      goal.cable_target = estimate.cable_length;
      goal.trolley_limits.max_velocity = maneuver.trolley_max_velocity;
      goal.trolley_limits.max_acceleration = maneuver.trolley_max_acceleration;
      goal.slew_limits.max_velocity = maneuver.slew_max_velocity;
      goal.slew_limits.max_acceleration = maneuver.slew_max_acceleration;
      if (planner.start_move(goal, estimate) != trajectory_planner::GoalStatus::accepted) {
        throw std::runtime_error("closed loop: planner.start_move refused the maneuver " + maneuver.name);
      }
    }
    if (planner.step(dt, reference) != common::StepStatus::ok) {
      throw std::runtime_error("closed loop: planner.step failed at cycle " + std::to_string(k));
    }
    // not_ready (delay line filling) leaves zero actions, which the node publishes as such.
    if (anti_swing.step(estimate, action) == common::StepStatus::rejected_nonfinite) {
      throw std::runtime_error("closed loop: anti-swing rejected the estimate of cycle " + std::to_string(k));
    }
    tracking::TrackingInput tracking_in;
    tracking_in.estimate = estimate;
    tracking_in.reference = reference.reference;
    tracking_in.trolley_anti_swing_action = action.trolley_action;
    tracking_in.slew_anti_swing_action = action.slew_action;
    if (tracking.step(tracking_in, linear) != common::StepStatus::ok) {
      throw std::runtime_error("closed loop: tracking failed at cycle " + std::to_string(k));
    }
    friction_compensation::FrictionCompensationInput compensation_in;
    compensation_in.estimate = estimate;
    compensation_in.command = linear.command;
    if (compensator.step(compensation_in, compensated) != common::StepStatus::ok) {
      throw std::runtime_error("closed loop: friction compensation failed at cycle " + std::to_string(k));
    }
    plant::DriveInput input;
    input.trolley_voltage = compensated.command.trolley_voltage;
    input.slew_voltage = compensated.command.slew_voltage;
    input.hoist_speed = compensated.command.hoist_speed;
    input.brakes_engaged = false;
    if (simulator.step(input) != common::StepStatus::ok) ++trace.plant_step_failures;
    const plant::SimulatorOutput applied = simulator.output();

    TraceSample s;
    s.time = static_cast<double>(k) * dt;
    s.trolley_position = sensors.measurement.trolley_position;
    s.slew_angle = sensors.measurement.slew_angle;
    s.swing_in_plane = sensors.measurement.swing_in_plane;
    s.swing_out_of_plane = sensors.measurement.swing_out_of_plane;
    s.trolley_reference = reference.reference.trolley.position;
    s.slew_reference = reference.reference.slew.position;
    s.trolley_linear_voltage = linear.command.trolley_voltage;
    s.slew_linear_voltage = linear.command.slew_voltage;
    s.trolley_friction_voltage = compensated.trolley_friction;
    s.slew_friction_voltage = compensated.slew_friction;
    s.trolley_voltage = applied.applied_trolley_voltage;
    s.slew_voltage = applied.applied_slew_voltage;
    s.trolley_velocity_true = simulator.state().trolley_velocity;
    trace.samples.push_back(s);
  }
  trace.friction_events = simulator.friction_event_count();

  std::vector<launch::RecordedCycle> recorded;
  recorded.reserve(trace.samples.size());
  for (const auto& s : trace.samples) {
    launch::RecordedCycle c;
    c.time = s.time;
    c.trolley_position = s.trolley_position;
    c.slew_angle = s.slew_angle;
    c.swing_in_plane = s.swing_in_plane;
    c.swing_out_of_plane = s.swing_out_of_plane;
    c.trolley_voltage = s.trolley_voltage;
    c.slew_voltage = s.slew_voltage;
    recorded.push_back(c);
  }
  trace.metrics = launch::evaluate_maneuver(recorded, maneuver.trolley_target, maneuver.slew_target);
  return trace;
}

}  // namespace crane::closed_loop
