#pragma once
// The friction compensation stage: what the friction_compensation process computes each cycle,
// without DDS, clock or thread. The linear command and the estimate of cycle k -> u = V + F_f/K_m
// (3.5) with the friction model (3.1)-(3.3) of the configured crane -> ActuatorCommand of cycle k
// (same seq and origin). Disabled (params.enabled false): u = V, still clamped (the dissertation's
// runs without compensation, figures 4.19-4.22). An axis whose ADAPTATION_*_FRICTION_ADAPTED bit
// is set in the estimate is compensated with the estimate's *_friction_* coefficients (the online
// re-estimate, crane::adaptation), otherwise with the configured crane's.

#include "crane/common/stack_facts.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"
#include "crane/protocol/messages.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::friction_compensation {

/// Reads the `friction_compensation:` block: enabled, and per axis (trolley:, slew:, and bridge: on an
/// overhead crane only, with the bridge's friction)
/// zero_velocity_band [m/s or rad/s] in [0, 10], stiction_slope [1/V] in [1e-3, 1e4],
/// velocity_source (raw | filtered); the friction model is the crane's (4.12)-(4.16), the voltage
/// limit the stack's. Throws common::ConfigError naming the field, value and bound.
[[nodiscard]] FrictionCompensationParams read_params(config::YamlSection& block, const common::StackFacts& facts);

class FrictionCompensationStage {
 public:
  /// Throws common::ConfigError for invalid params (FrictionCompensation's constructor).
  explicit FrictionCompensationStage(const FrictionCompensationParams& params);

  /// One cycle; `estimate` and `linear` belong to the same cycle (the caller joins them). `command`
  /// is always written (its header from `linear`): ok, or rejected_nonfinite when a used input is
  /// NaN/Inf (0 V then). Never throws, never allocates.
  [[nodiscard]] common::StepStatus step(const protocol::CraneState& estimate, const protocol::LinearCommand& linear,
                                        protocol::ActuatorCommand& command) const noexcept;

 private:
  FrictionCompensation compensation_;
  std::optional<FrictionCompensation> bridge_;  // the overhead crane's bridge as a trolley
};

}  // namespace crane::friction_compensation
