#include "crane/config/simulator_parameters.hpp"

namespace crane::config {

plant::SimulatorParameters simulator_parameters(const StackConfig& config, plant::PlantState initial) {
  plant::SimulatorParameters p;
  p.crane = config.crane;
  p.sample_period = config.plant.sample_period;
  p.relative_tolerance = config.plant.relative_tolerance;
  p.absolute_tolerance = config.plant.absolute_tolerance;
  p.brake_holding_factor = config.plant.brake_holding_factor;
  p.hoist_max_acceleration = config.plant.hoist_max_acceleration;
  p.min_cable_length = config.plant.min_cable_length;
  p.max_cable_length = config.plant.max_cable_length;
  initial.cable_length = config.crane.cable_length;
  p.initial_state = initial;
  return p;
}

}  // namespace crane::config
