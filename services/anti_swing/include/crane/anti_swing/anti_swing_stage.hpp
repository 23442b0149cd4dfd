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

struct AntiSwingStageParams {
  AntiSwingLaw law{AntiSwingLaw::delay1};
  AntiSwingParams anti_swing{};  // gains, delay, sample period, gravity, cable range (kind follows law)
  bool bridge{false};            // an overhead crane (facts.crane_kind): the same law on the bridge, on its
                                 // gantry view (common::bridge_view), into bridge_action / bridge_reference_*
};

/// Reads the `anti_swing:` block: controller (a law name), pd_proportional_gain, pd_derivative_gain,
/// delay_gain [-] in [-1000, 1000], normalized_delay [swing periods] in [1e-3, 5], slew_enabled;
/// sample period, gravity and cable range from facts. Throws common::ConfigError naming the field.
[[nodiscard]] AntiSwingStageParams read_params(config::YamlSection& block, const common::StackFacts& facts);

class AntiSwingStage {
 public:
  /// Throws common::ConfigError for invalid params (the law's own constructor).
  explicit AntiSwingStage(const AntiSwingStageParams& params);

  /// One cycle. ok, or not_ready (a delay line still filling: every action and correction 0, the
  /// safe value): `command` holds the cycle's output. rejected_nonfinite: nothing written, the law's
  /// history untouched. Never throws, never allocates.
  [[nodiscard]] common::StepStatus step(const protocol::CraneState& estimate, protocol::AntiSwingCommand& command) noexcept;

  [[nodiscard]] AntiSwingLaw law() const noexcept { return law_; }

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
};

}  // namespace crane::anti_swing
