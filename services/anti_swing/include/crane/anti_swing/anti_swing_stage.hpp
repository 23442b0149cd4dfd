#pragma once
// The anti-swing stage: what the anti_swing process computes each cycle, without DDS, clock or
// thread. The estimate of cycle k -> the anti-swing law of section 3.3.2 -> AntiSwingCommand of
// cycle k (same seq and origin). The law registry lives here, one place:
//   none    action 0                                           (AntiSwingCommand::CONTROLLER_NONE)
//   pd      (3.45) V_xs = K_ps phi + K_ds T phi_dot            (CONTROLLER_PD)
//   delay1  (3.47) V_xs = K_del phi(tau - tau_del)             (CONTROLLER_DELAY1)
//   delay2  (3.50) Masoud's configuration: the delayed swing corrects the reference the tracking
//           PD follows; actions 0, the reference-correction fields set (CONTROLLER_DELAY2)
//   fuzzy   figures 3.20-3.21, tables 3.7-3.8, (3.51)          (CONTROLLER_FUZZY)
// pd, delay1 and fuzzy use the gains and delay of the `anti_swing:` block, every law the gravity
// and cable range of the crane (fuzzy and delay2 keep their own dissertation defaults for their
// gains). A new law: an enumerator here, its case in anti_swing_stage.cpp, its code in the IDL.
//
// The operating mode (OPC 40020, from the supervisor's SupervisorStatus.operating_mode): MAINTENANCE
// is "reduced speeds, no anti-swing", so there the law's output (actions and reference corrections)
// is 0 and the tracking PD drives alone; in every other mode it is the law's. The law keeps running
// on the estimate in MAINTENANCE (its delay line stays current), and its share of the command
// (engagement(): 1 engaged, 0 off) moves between the two linearly over fade_periods swing periods at
// the measured cable length: no step in the drive voltage when the mode enters or leaves MAINTENANCE
// with the load swinging. Faded over n swing periods, the command changes per cycle by the law's own
// change times the share plus at most |action| T_s / (n T): with n = 1 (the configurations') a sixth
// of what a swing of that amplitude changes the action by itself in a cycle (|action| 2 pi T_s / T).

#include <cstdint>
#include <optional>
#include <string_view>
#include <variant>

#include "crane/anti_swing/anti_swing.hpp"
#include "crane/anti_swing_analysis/delayed_trajectory_anti_swing.hpp"
#include "crane/anti_swing_analysis/fuzzy_anti_swing.hpp"
#include "crane/common/stack_facts.hpp"
#include "crane/protocol/messages.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::anti_swing {

enum class AntiSwingLaw : std::uint8_t {
  none = protocol::AntiSwingCommand::CONTROLLER_NONE,
  pd = protocol::AntiSwingCommand::CONTROLLER_PD,
  delay1 = protocol::AntiSwingCommand::CONTROLLER_DELAY1,
  delay2 = protocol::AntiSwingCommand::CONTROLLER_DELAY2,
  fuzzy = protocol::AntiSwingCommand::CONTROLLER_FUZZY,
};
/// "none" | "pd" | "delay1" | "delay2" | "fuzzy" (the IDL's code names).
[[nodiscard]] std::string_view law_name(AntiSwingLaw law) noexcept;
/// The law named `name`; throws common::ConfigError naming `field`, the value and the choices.
[[nodiscard]] AntiSwingLaw law_from_name(std::string_view name, std::string_view field = "anti_swing.controller");

/// The range of anti_swing.fade_periods [swing periods] (read_params and the stage's constructor).
inline constexpr double kMinFadePeriods = 0.1;
inline constexpr double kMaxFadePeriods = 10.0;

struct AntiSwingStageParams {
  AntiSwingLaw law{AntiSwingLaw::delay1};
  AntiSwingParams anti_swing{};  // gains, delay, sample period, gravity, cable range (kind follows law)
  bool bridge{false};            // an overhead crane (facts.crane_kind): the same law on the bridge, on its
                                 // gantry view (common::bridge_view), into bridge_action / bridge_reference_*
  double fade_periods{1.0};      // [swing periods] in [0.1, 10]: the law's output fades out over this many swing
                                 // periods (2 pi sqrt(L/g), L the measured cable length) when the operating mode
                                 // enters MAINTENANCE and back in when it leaves it
};

/// Reads the `anti_swing:` block: controller (a law name), pd_proportional_gain, pd_derivative_gain,
/// delay_gain [-] in [-1000, 1000], normalized_delay [swing periods] in [1e-3, 5], slew_enabled,
/// short_cable {enabled, short_length and full_gain_length [m] in [1e-3, 100], delay_gain [-] in
/// [-1000, 1000]} (anti_swing.hpp, ShortCableGain),
/// fade_periods [swing periods] in [0.1, 10]; sample period, gravity and cable range from facts.
/// Throws common::ConfigError naming the field.
[[nodiscard]] AntiSwingStageParams read_params(config::YamlSection& block, const common::StackFacts& facts);

/// The rule of the operating modes for the feedback: true (the law's output in the command) in every
/// mode but MAINTENANCE (OPC 40020: "no anti-swing"); an unknown code changes nothing (the caller
/// keeps the mode it had).
[[nodiscard]] bool feedback_in_mode(std::uint8_t operating_mode) noexcept;

class AntiSwingStage {
 public:
  /// Throws common::ConfigError for invalid params (the law's own constructor, fade_periods out of
  /// [0.1, 10]).
  explicit AntiSwingStage(const AntiSwingStageParams& params);

  /// One cycle. `status`: the supervisor's latest status, for its operating_mode (nullptr: none yet,
  /// or none new: the mode stays as it was, FULLAUTOMATIC at start; an OPERATION_* code outside
  /// MANUAL..MAINTENANCE is ignored). ok, or not_ready (a delay line still filling: every action and
  /// correction 0, the safe value): `command` holds the cycle's output, the law's scaled by
  /// engagement(). rejected_nonfinite: nothing written, the law's history, the mode and the
  /// engagement untouched. Never throws, never allocates.
  [[nodiscard]] common::StepStatus step(const protocol::CraneState& estimate, const protocol::SupervisorStatus* status,
                                        protocol::AntiSwingCommand& command) noexcept;
  /// The same without a supervisor status: the operating mode stays as it was.
  [[nodiscard]] common::StepStatus step(const protocol::CraneState& estimate, protocol::AntiSwingCommand& command) noexcept {
    return step(estimate, nullptr, command);
  }

  [[nodiscard]] AntiSwingLaw law() const noexcept { return law_; }
  /// [-] in [0, 1]: the share of the law's output in the last command (1 engaged, 0 off in MAINTENANCE).
  [[nodiscard]] double engagement() const noexcept { return engagement_; }
  /// The OPERATION_* code the last step applied.
  [[nodiscard]] std::uint8_t operating_mode() const noexcept { return operating_mode_; }

 private:
  using Core = std::variant<AntiSwing, anti_swing_analysis::FuzzyAntiSwing, anti_swing_analysis::DelayedTrajectoryAntiSwing>;
  struct Result {
    common::StepStatus status{common::StepStatus::ok};
    AntiSwingOutput action{};
    anti_swing_analysis::TrajectoryCorrection correction{};
  };
  /// One cycle of `core` on `estimate` (finite); not_ready gives every field 0.
  [[nodiscard]] static Result run(Core& core, const protocol::CraneState& estimate) noexcept;

  AntiSwingLaw law_;
  Core core_;
  std::optional<Core> bridge_core_;
  AntiSwingParams swing_;  // sample period, gravity, cable range: the fade's swing period
  double fade_periods_;    // [swing periods]
  std::uint8_t operating_mode_{protocol::SupervisorStatus::OPERATION_FULLAUTOMATIC};
  double engagement_{1.0};  // [-]
};

}  // namespace crane::anti_swing
