#include "crane/stack/convergence_study.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace crane::stack {

StateDifference max_state_difference(const std::vector<plant::PlantState>& a, const std::vector<plant::PlantState>& b) {
  if (a.size() != b.size()) {
    throw std::invalid_argument("max_state_difference: " + std::to_string(a.size()) + " states against " +
                                std::to_string(b.size()));
  }
  StateDifference d;
  const auto widen = [](double& into, double x, double y) { into = std::max(into, std::abs(x - y)); };
  for (std::size_t i = 0; i < a.size(); ++i) {
    const plant::PlantState& p = a[i];
    const plant::PlantState& q = b[i];
    widen(d.position, p.trolley_position, q.trolley_position);
    widen(d.position, p.bridge_position, q.bridge_position);
    widen(d.position, p.cable_length, q.cable_length);
    widen(d.angle, p.slew_angle, q.slew_angle);
    widen(d.angle, p.swing_in_plane, q.swing_in_plane);
    widen(d.angle, p.swing_out_of_plane, q.swing_out_of_plane);
    widen(d.velocity, p.trolley_velocity, q.trolley_velocity);
    widen(d.velocity, p.bridge_velocity, q.bridge_velocity);
    widen(d.velocity, p.cable_length_rate, q.cable_length_rate);
    widen(d.angular_rate, p.slew_rate, q.slew_rate);
    widen(d.angular_rate, p.swing_in_plane_rate, q.swing_in_plane_rate);
    widen(d.angular_rate, p.swing_out_of_plane_rate, q.swing_out_of_plane_rate);
  }
  return d;
}

std::vector<plant::PlantState> replay_plant(const plant::SimulatorParameters& parameters,
                                            const std::vector<plant::DriveInput>& inputs) {
  plant::CraneSimulator simulator(parameters);
  std::vector<plant::PlantState> states;
  states.reserve(inputs.size());
  for (std::size_t k = 0; k < inputs.size(); ++k) {
    if (simulator.step(inputs[k]) != common::StepStatus::ok) {
      throw std::runtime_error("replay_plant: the plant's step failed at cycle " + std::to_string(k));
    }
    states.push_back(simulator.state());
  }
  return states;
}

bool FigureComparison::agrees() const noexcept {
  if (!std::isfinite(at_settings) || !std::isfinite(at_reference)) {
    return std::isfinite(at_settings) == std::isfinite(at_reference);
  }
  // Half a unit of the last decimal, with room for the binary representation of that half.
  const double half_unit = 0.5 * std::pow(10.0, -decimals) * (1.0 + 1e-9);
  return std::abs(at_settings - at_reference) <= half_unit;
}

bool ConvergenceCase::agrees() const noexcept {
  return std::all_of(figures.begin(), figures.end(), [](const FigureComparison& f) { return f.agrees(); });
}

plant::IntegratorSettings reference_integrator_settings() noexcept {
  plant::IntegratorSettings s;
  s.method = plant::IntegrationMethod::bdf;
  s.relative_tolerance = 1e-12;
  s.absolute_tolerance = 1e-14;
  return s;
}

std::vector<ConvergenceCase> run_convergence_study(const StackConfig& config, const std::vector<InProcessRun>& runs,
                                                   const plant::IntegratorSettings& reference) {
  StackConfig reference_config = config;
  reference_config.plant.integrator = reference;
  const bool bridge = config.facts.crane_kind == common::CraneKind::overhead;
  std::vector<ConvergenceCase> cases;
  for (InProcessRun run : runs) {
    if (run.mismatch.friction_change_factor != 1.0) {
      throw std::invalid_argument("run_convergence_study: " + run.maneuver.name +
                                  " changes its friction during the run, which the replay does not carry");
    }
    run.record_plant = true;
    const InProcessResult at_settings = run_in_process(config, run);
    const InProcessResult at_reference = run_in_process(reference_config, run);
    plant::SimulatorParameters replay_parameters = at_settings.plant_parameters;
    replay_parameters.integrator = reference;
    const auto replayed = replay_plant(replay_parameters, at_settings.plant_inputs);

    ConvergenceCase c;
    c.maneuver = run.maneuver.name;
    c.friction_compensation = run.friction_compensation;
    const auto figures = printed_figures(at_settings.metrics, at_settings.swing_period, bridge);
    const auto reference_figures = printed_figures(at_reference.metrics, at_reference.swing_period, bridge);
    for (std::size_t i = 0; i < figures.size(); ++i) {
      c.figures.push_back({figures[i].name, figures[i].decimals, figures[i].value, reference_figures[i].value});
    }
    c.integration_error = max_state_difference(at_settings.plant_states, replayed);
    c.closed_loop_difference = max_state_difference(at_settings.plant_states, at_reference.plant_states);
    c.work = at_settings.integrator_work;
    c.reference_work = at_reference.integrator_work;
    c.friction_events = at_settings.friction_events;
    c.reference_friction_events = at_reference.friction_events;
    cases.push_back(std::move(c));
  }
  return cases;
}

}  // namespace crane::stack
