#include "crane/state_estimator/state_estimator_stage.hpp"

#include "crane/common/protocol_signals.hpp"
#include "crane/config/yaml_section.hpp"

namespace crane::state_estimator {

StateEstimatorParams read_params(config::YamlSection& s, const common::StackFacts& facts) {
  StateEstimatorParams p;
  p.sample_rate = 1.0 / facts.sample_period;
  p.cutoff_frequency = s.number("cutoff_frequency", 1e-3, 0.499 * p.sample_rate);
  const auto kind = s.text("differentiator", {"backward", "al_alaoui_first_order", "al_alaoui_second_order"});
  p.differentiator = kind == "backward"                ? DifferentiatorKind::backward
                     : kind == "al_alaoui_first_order" ? DifferentiatorKind::al_alaoui_first_order
                                                       : DifferentiatorKind::al_alaoui_second_order;
  s.finish();
  StateEstimator{p};  // its own invariants, same message format
  return p;
}

StateEstimatorStage::StateEstimatorStage(const StateEstimatorParams& params) : estimator_(params) {}

common::StepStatus StateEstimatorStage::step(const protocol::SensorSample& sensors,
                                             protocol::CraneState& estimate) noexcept {
  if (!protocol::all_finite(sensors)) return common::StepStatus::rejected_nonfinite;
  const auto status = estimator_.step(common::to_measurement(sensors), scratch_);
  if (status != common::StepStatus::ok) return status;
  common::from_estimate(scratch_, estimate);
  common::same_cycle(sensors.header, estimate.header);
  return status;
}

}  // namespace crane::state_estimator
