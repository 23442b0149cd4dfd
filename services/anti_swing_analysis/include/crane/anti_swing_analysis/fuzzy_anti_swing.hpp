#pragma once
// Fuzzy anti-swing controller, section 3.3.2 (figures 3.20-3.21, (3.51), tables 3.7-3.8) of
// H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003.
//
// Reading of figure 3.20 (the figure itself is not in the extracted text; this reading reproduces
// every membership degree quoted in the text: x = 0.2 -> ZO 0.4, PS 0.6; x = -0.6 -> NM 0.8,
// NS 0.2; y = 0.9 -> PM 0.3, PB 0.7): seven triangular sets NB, NM, NS, ZO, PS, PM, PB on the
// normalized universe [-1, 1] with centres -1, -b, -a, 0, a, b, 1 (a = 1/3, b = 2/3), each
// falling to zero at its neighbours' centres; NB and PB are shoulders (degree 1 beyond -1 and 1),
// and inputs are clamped to [-1, 1]. The sets form a partition of unity.
//
// Inference and defuzzification: product of the two input degrees as the rule firing strength;
// the crisp output is the weighted average of the output sets' centres (equivalently the centroid
// of singleton consequents): y = sum_ij mu_i(x1) mu_j(x2) c(rule_ij) / sum_ij mu_i(x1) mu_j(x2).
//
// Scaling (3.51): x1 = K_phi phi, x2 = K_phidot phi' (phi' = d phi/d tau = T phi_dot), and the
// action V_xs = K_v y, with K_phi = 1/phi_max, K_phidot = 1/1.5, K_v = K_del phi_max
// (phi_max = 0.174 rad). In our sign convention K_del = -90, so K_v = -90 phi_max, which is
// (3.51) as printed; y = V_xs/K_v is then phi(tau - tau_del)/phi_max, the same normalized rule
// surface as in the dissertation.
//
// Real-time: step() is noexcept, allocates nothing, takes no locks.

#include <array>
#include <cstdint>
#include <string_view>

#include "crane/anti_swing/anti_swing.hpp"
#include "crane/common/crane_signals.hpp"

namespace crane::anti_swing_analysis {

/// The seven linguistic sets of figure 3.20, in order of their centres.
enum class FuzzySet : std::uint8_t { nb, nm, ns, zo, ps, pm, pb };
inline constexpr int kFuzzySetCount = 7;

/// "NB", "NM", ..., "PB".
[[nodiscard]] std::string_view fuzzy_set_name(FuzzySet set) noexcept;
/// Centre of a set on [-1, 1]: -1, -2/3, -1/3, 0, 1/3, 2/3, 1.
[[nodiscard]] double fuzzy_set_center(FuzzySet set) noexcept;
/// Degrees of membership of x in the seven sets (x clamped to [-1, 1]; NaN gives all zeros).
[[nodiscard]] std::array<double, kFuzzySetCount> fuzzy_membership(double x) noexcept;

/// rules[i][j]: output set for swing set i (x1) and swing-rate set j (x2), indices as FuzzySet.
using FuzzyRuleTable = std::array<std::array<FuzzySet, kFuzzySetCount>, kFuzzySetCount>;

/// Table 3.7 as printed (rows phi NB..PB, columns phi_dot NB..PB).
[[nodiscard]] FuzzyRuleTable dissertation_rule_table() noexcept;

/// Crisp normalized output y in [-1, 1] of the rule base for normalized inputs x1, x2.
[[nodiscard]] double fuzzy_inference(const FuzzyRuleTable& rules, double x1, double x2) noexcept;

struct FuzzyAntiSwingParams {
  FuzzyRuleTable rules{dissertation_rule_table()};
  double max_swing_angle{0.174};          // [rad] phi_max = 1/K_phi (3.51), > 0
  double max_normalized_swing_rate{1.5};  // [rad/period] 1/K_phidot (3.51), phi' = T phi_dot, > 0
  double output_scale{-90.0 * 0.174};     // [-] K_v (3.51) = K_del phi_max, our sign; finite, != 0
  double gravity{9.8};                    // [m/s^2] g in T = 2 pi sqrt(L/g), > 0
  double min_cable_length{0.1};           // [m] measured L is clamped to [min, max] for T, > 0
  double max_cable_length{5.0};           // [m] > min_cable_length
  bool slew_enabled{true};                // apply the same law on theta for the slew axis
};

class FuzzyAntiSwing {
 public:
  /// Throws common::ConfigError naming the field, value and bound for: a rule entry that is not a
  /// FuzzySet, max_swing_angle <= 0, max_normalized_swing_rate <= 0, output_scale non-finite or
  /// 0, gravity <= 0, min_cable_length <= 0, max_cable_length <= min_cable_length.
  explicit FuzzyAntiSwing(const FuzzyAntiSwingParams& params);

  /// Uses swing_in_plane [rad], swing_in_plane_rate [rad/s], swing_out_of_plane [rad],
  /// swing_out_of_plane_rate [rad/s] and cable_length [m] from `estimate`. Writes the normalized
  /// actions V_xs, V_ys (add to V_xp, V_yp before (3.37)/(3.38)) and swing_period [s];
  /// delay_samples = 0.
  /// - rejected_nonfinite: a used input is NaN/Inf; output set to zero actions.
  /// - ok otherwise.
  [[nodiscard]] common::StepStatus step(const common::CraneStateEstimate& estimate,
                                        anti_swing::AntiSwingOutput& output) noexcept;

  /// Stateless; present for the common core interface.
  void reset() noexcept {}

  [[nodiscard]] const FuzzyAntiSwingParams& params() const noexcept { return params_; }

 private:
  FuzzyAntiSwingParams params_;
};

}  // namespace crane::anti_swing_analysis
