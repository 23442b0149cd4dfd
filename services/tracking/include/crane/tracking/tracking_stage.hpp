#pragma once
// The tracking stage: what the tracking process computes each cycle, without DDS, clock or thread.
// The estimate, the reference and the anti-swing command of cycle k -> LinearCommand of cycle k
// (same seq and origin). The law registry lives here, one place:
//   tracking                 PD tracking (3.40)-(3.42) mapped to voltages (3.37)-(3.38), plus the
//                            anti-swing action; the anti-swing command's reference corrections
//                            (Masoud's configuration (3.50)) are added to the trolley and slew
//                            reference position and velocity first
//   gain_scheduling_partial  gain-scheduling state feedback (3.19) on the reference position
//   gain_scheduling_full     gain-scheduling state feedback (3.26) on the reference position
//   follower                 the feedback law the reference carries (Reference.feedback_law: the
//                            minimum-time follower's feedforward and time-varying LQR gains,
//                            trajectory_feedback.hpp; docs/optimal_control.md), the hoist at the
//                            reference's cable rate and the reference's sliding friction reduction
//                            passed on to the friction compensation, with the plant's friction
//                            over the model's, estimated along the move from the law's feedback
//                            (friction_factor_estimate.hpp, LinearCommand_.friction_factor:
//                            along the move following the estimate at friction_factor_rate at
//                            most, 1 until the move has rows enough; at the target the estimate;
//                            0 under the other laws: unset); at
//                            the target (the law's reference at rest) a drive the friction holds
//                            at rest off the target gets the breakaway ramp (breakaway_ramp.hpp); a reference
//                            without a law (holding, a stop, manual motion) is tracked by
//                            `tracking`
// With estimate_friction_factor (the config's tracking.estimate_friction_factor), the `tracking` law
// too estimates the plant's friction over the model's along each move and hands it to the friction
// compensation as the follower does (along the move at friction_factor_rate at most, at the target
// the estimate): the compensation (3.5) then adds f times the model's stiction at rest and min(1, f)
// of its sliding part, so a plant with less friction than the model is not over-compensated into a
// limit cycle at the hold, nor one with more left stuck with its swing undamped. Its rows: the
// balance of the crane's generalized momentum along each drive (friction_momentum_balance.hpp: the
// law's voltage summed over blocks of friction_balance_block through the estimator's lag, against the
// change of TrackingOutput's momenta), over the cycles where the drive's measured speed slides the
// reference's way (the compensation then adds the sliding part the row assumes). The factor is
// handed once known to within tracking_friction_factor's max_standard_error, and carried from one
// move into the next (a hoist alone gives no rows); the follower's starts each move from 1. No
// breakaway ramp under this law (docs/optimal_control.md, "The friction factor under delay1").
// Without the setting, LinearCommand_.friction_factor stays 0 (the configured friction) under that
// law.
// The gain-scheduling laws do not use the anti-swing command; the stage still takes it, so the
// chain (and its timing) is the same for every law. A new law: an enumerator, its name, its case.
// Every law takes the load (m_t, m_r of (3.37)-(3.38) and the gain schedule) from the estimate's
// payload_mass while payload_confident is set (the online estimate, crane::adaptation), and from the
// configured crane otherwise.

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <string_view>

#include "crane/common/stack_facts.hpp"
#include "crane/gain_scheduling/gain_scheduling_controller.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/state_estimator/state_estimator.hpp"
#include "crane/tracking/breakaway_ramp.hpp"
#include "crane/tracking/friction_factor_estimate.hpp"
#include "crane/tracking/friction_momentum_balance.hpp"
#include "crane/tracking/tracking_controller.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::tracking {

enum class TrackingLaw : std::uint8_t { tracking, gain_scheduling_partial, gain_scheduling_full, follower };
/// "tracking" | "gain_scheduling_partial" | "gain_scheduling_full" | "follower".
[[nodiscard]] std::string_view law_name(TrackingLaw law) noexcept;
/// The law named `name`; throws common::ConfigError naming `field`, the value and the choices.
[[nodiscard]] TrackingLaw law_from_name(std::string_view name, std::string_view field = "tracking law");

struct TrackingStageParams {
  TrackingLaw law{TrackingLaw::tracking};
  TrackingParams tracking{};                         // the PD law (model constants from the crane)
  gain_scheduling::GainSchedulingParams gain_scheduling{};  // the gain-scheduling laws (kind follows law)
  double trolley_drive_mass{22.222};  // [kg] M, > 0: m_t = payload_mass / M when the estimate is confident
  double jib_inertia{7.143};          // [kg m^2] J_o, > 0: m_r = payload_mass / J_o
  // The follower's drives' friction model (the crane's, the second axis the slew's or the bridge's),
  // for the friction factor it estimates along a move.
  common::AxisFriction trolley_friction{};
  common::AxisFriction second_friction{};
  // [1/s] > 0: how fast the friction factor the follower hands the compensation along a move may
  // change (its estimate from the move's first rows is noisy; at the target it hands the estimate).
  double friction_factor_rate{1.0};
  // The `tracking` law estimates and hands the friction factor too (see the header); false: the
  // dissertation's (3.5) with the configured friction.
  bool estimate_friction_factor{false};
  // The PD law's estimate: a row per block of the momentum balance, f handed once it has min_rows of
  // them and is known to within max_standard_error (a short slew alone gives too few; then the last
  // move's factor stands), to the nearest resolution; min_reference_speed is the measured speed a
  // row's cycles need. Measured
  // in docs/optimal_control.md, "The friction factor under delay1"; the follower's keeps
  // FrictionFactorParams' defaults.
  FrictionFactorParams tracking_friction_factor{.min_rows = 3, .max_standard_error = 0.05, .resolution = 0.01};
  double friction_balance_block{0.5};  // [s] in [sample_period, 1000]: the balance's blocks (its rows)
  // The estimator whose rates the momenta come from (the state_estimator block's: its low-pass and
  // differentiator; the balance's voltage side runs through the same lag).
  state_estimator::StateEstimatorParams estimator{};
  // The follower's hold at the target: integral action against a drive stuck off it.
  BreakawayRampParams breakaway{};
  double sample_period{0.01};  // [s] > 0, the cycle (facts.sample_period)
  // An overhead crane (facts.crane_kind): the bridge's stage, the same law on the bridge's gantry view
  // (common::bridge_view) with the bridge's drive (common::bridge_as_trolley); null elsewhere.
  std::shared_ptr<const TrackingStageParams> bridge;
};

/// Reads the `tracking:` block: proportional_gain [-] in [0, 1e4], derivative_gain [-] in [0, 1e3],
/// min_radius [m] in [1e-3, 100], slew_enabled, estimate_friction_factor; the crane's model constants, the voltage limit and
/// the cable range from facts. The law is `tracking` (processes choose another with --controller).
/// Throws common::ConfigError naming the field, value and bound.
[[nodiscard]] TrackingStageParams read_params(config::YamlSection& block, const common::StackFacts& facts);

class TrackingStage {
 public:
  /// Throws common::ConfigError for invalid params (the law's own constructor).
  explicit TrackingStage(const TrackingStageParams& params);

  /// One cycle; `estimate`, `reference` and `anti_swing` belong to the same cycle (the caller joins
  /// them). `command` is always written (its header from the estimate); ok, or rejected_nonfinite
  /// when a used input is NaN/Inf (then the law's safe output: 0 V). Never throws, never allocates.
  [[nodiscard]] common::StepStatus step(const protocol::CraneState& estimate, const protocol::Reference& reference,
                                        const protocol::AntiSwingCommand& anti_swing,
                                        protocol::LinearCommand& command) noexcept;

  [[nodiscard]] TrackingLaw law() const noexcept { return law_; }

 private:
  /// The follower law on a reference that carries one.
  [[nodiscard]] common::StepStatus follow(const protocol::CraneState& estimate, const protocol::Reference& reference,
                                          protocol::LinearCommand& command) noexcept;
  /// A new estimate when `reference` names a move other than the last (request_id 0: holding), from
  /// the last move's factor with `carry` (the PD law's), else from the model's (1, the follower's);
  /// true then.
  bool start_friction_estimate(const protocol::Reference& reference, bool carry) noexcept;
  /// The reference at rest on both drives (the trolley and the slew, or the bridge).
  [[nodiscard]] static bool at_target(const protocol::Reference& reference, bool bridge) noexcept;
  /// The follower's rows of this cycle (the drives' voltages [V] less their feedforward, `known` [V];
  /// `reduction` the command's sliding_friction_reduction) and the factor to hand with the command.
  [[nodiscard]] double hand_friction_factor(const protocol::Reference& reference, bool bridge,
                                            const std::array<double, 2>& voltage, const std::array<double, 2>& known,
                                            double reduction) noexcept;
  /// The PD law's: this cycle into each drive's momentum balance, whose closed blocks are rows.
  [[nodiscard]] double hand_balanced_friction_factor(const protocol::CraneState& estimate,
                                                     const protocol::Reference& reference, bool bridge,
                                                     const protocol::LinearCommand& command) noexcept;
  /// The factor to hand along the move (toward the estimate at friction_factor_rate) or at the target.
  [[nodiscard]] double next_handed_friction_factor(const protocol::Reference& reference, bool bridge) noexcept;
  /// kept_sliding_share's excess with the factor handed with the last command (reduction `reduction`).
  [[nodiscard]] double compensated_share(double reduction) const noexcept;

  TrackingLaw law_;
  TrackingController tracking_;
  double voltage_limit_;
  std::optional<gain_scheduling::GainSchedulingController> scheduled_;
  double trolley_drive_mass_;  // [kg]
  double jib_inertia_;         // [kg m^2]
  std::unique_ptr<TrackingStage> bridge_;  // the overhead crane's bridge (its trolley is the bridge)
  FrictionFactorEstimate friction_factor_;  // the follower's, over the move of friction_request_
  std::uint32_t friction_request_{0};
  double friction_factor_step_;     // [-] the most the handed factor changes in a cycle along a move
  double handed_friction_factor_{1.0};  // handed to the compensation with the last command (this move's)
  BreakawayRamp breakaway_;  // the follower's hold, reset when the reference moves or a move starts
  bool estimate_friction_factor_;  // under the `tracking` law too
  double tracking_friction_factor_speed_;  // [m/s or rad/s] the PD law's rows: the measured speed at least this
  // The PD law's momenta of the last cycle (TrackingOutput: the trolley's, dT/dx's voltage, the slew's).
  std::array<double, 3> momentum_{};
  std::array<FrictionMomentumBalance, 2> balance_;  // the PD law's, per drive (trolley; slew or bridge)
  std::array<common::AxisFriction, 2> friction_model_;  // the drives' model friction (the rows' F)
};

}  // namespace crane::tracking
