#pragma once
// The state estimator stage: what the state_estimator process computes each cycle, without DDS,
// clock or thread. Sensor sample of cycle k -> section 4.3 filter and differentiator -> the
// estimate of cycle k (same seq and origin), with the online payload mass and friction estimate
// (crane::adaptation, online_adaptation.hpp) in its payload_* and *_friction_* fields: the
// configured values while adaptation is off or has not identified them; and the load's equivalent
// pendulum learnt from the swing (adaptation/swing_length_estimator.hpp) in its swing_length_* fields:
// 1 L + 0, not confident, while that is off or has learnt nothing.

#include <optional>

#include "crane/adaptation/online_adaptation.hpp"
#include "crane/adaptation/swing_length_estimator.hpp"
#include "crane/common/stack_facts.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/state_estimator/state_estimator.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::state_estimator {

struct StateEstimatorStageParams {
  StateEstimatorParams estimator{};
  adaptation::OnlineAdaptationParams adaptation{};  // the crane and sample period are the stack's facts
  adaptation::SwingLengthParams swing_length{};     // its sample period, crane kind, crane and bridge too
  bool bridge{false};  // an overhead crane (facts.crane_kind): the bridge position is filtered and
                       // differentiated like the trolley's, into bridge_velocity(_raw)
  /// [Hz] the Butterworth's cutoff while the minimum-time follower controls the crane (tracking law
  /// `follower`; for_follower()): its time-varying LQR feeds back every filtered position and rate,
  /// and its loop near 3-4 Hz does not survive the 66 deg lag of the dissertation's 5 Hz filter
  /// there with a shorter cable or less friction than assumed (docs/optimal_control.md, "The
  /// estimator's lag"). The dissertation's laws keep estimator.cutoff_frequency (section 4.3).
  double follower_cutoff_frequency{5.0};
};

/// `params` with follower_cutoff_frequency as the Butterworth's cutoff: the estimator of a stack
/// whose tracking law is the follower. The in-process stack and the state_estimator process
/// (--follower-filter, which crane_demo passes with `--controller follower`) both call it.
[[nodiscard]] StateEstimatorStageParams for_follower(StateEstimatorStageParams params);

/// Reads the `state_estimator:` block: cutoff_frequency [Hz] and follower_cutoff_frequency [Hz],
/// each in [1e-3, 0.499 fs], differentiator
/// (backward (4.8) | al_alaoui_first_order (4.9) | al_alaoui_second_order (4.10)); fs is
/// 1 / facts.sample_period; its `adaptation:` block (every field of OnlineAdaptationParams,
/// limit_cycle: included; ranges in read_adaptation's body and OnlineAdaptation's validate); and its
/// `swing_length:` block (SwingLengthParams but the facts': enabled, filter_cutoff, forgetting_factor,
/// min_swing, min_information, max_condition, solve_period, length_bound, scale_bound). Throws
/// common::ConfigError naming the field, value and bound.
[[nodiscard]] StateEstimatorStageParams read_params(config::YamlSection& block, const common::StackFacts& facts);

class StateEstimatorStage {
 public:
  /// Throws common::ConfigError for invalid params (StateEstimator's constructor).
  explicit StateEstimatorStage(const StateEstimatorStageParams& params);

  /// One cycle. ok: `estimate` holds the estimate of `sensors`' cycle. rejected_nonfinite (a NaN or
  /// Inf field): `estimate` and the filters are untouched. Never throws, never allocates.
  [[nodiscard]] common::StepStatus step(const protocol::SensorSample& sensors, protocol::CraneState& estimate) noexcept;

 private:
  StateEstimator estimator_;
  std::optional<StateEstimator> bridge_estimator_;  // the bridge through the trolley's filter (overhead crane)
  common::CraneStateEstimate bridge_scratch_{};
  adaptation::OnlineAdaptation adaptation_;
  common::CraneStateEstimate scratch_{};
  adaptation::AdaptationEstimate adapted_{};
  adaptation::SwingLengthEstimator swing_length_;
  adaptation::SwingLengthEstimate pendulum_{};
};

}  // namespace crane::state_estimator
