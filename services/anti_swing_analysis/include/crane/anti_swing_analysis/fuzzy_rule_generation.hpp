#pragma once
// Generation of the fuzzy anti-swing rules by mapping the first delayed-feedback controller's
// responses (section 3.3.2, Table 3.6, (3.52), Tables 3.7-3.8 of H. M. Omar, "Control of Gantry
// and Tower Cranes", Virginia Tech 2003).
//
// Procedure: simulate the normalized linear loop (normalized_loop.hpp) with the tracking PD and the
// delay law from each initial swing and transfer distance; normalize each sample with (3.51):
// x1 = phi/phi_max, x2 = phi'/1.5, y = V_xs/K_v (inputs and output clamped to [-1, 1]). Each
// sample yields up to four rules "if x1 is A_i and x2 is B_j then y is C", one per pair of input
// sets with nonzero degree, C being the output set of largest degree, with degree
// D = mu_Ai(x1) mu_Bj(x2) mu_C(y) (3.52). Conflicts (same if-part) keep the rule of largest degree.
// Allocates; offline use only.

#include <array>
#include <vector>

#include "crane/anti_swing_analysis/fuzzy_anti_swing.hpp"
#include "crane/anti_swing_analysis/normalized_loop.hpp"

namespace crane::anti_swing_analysis {

struct RuleGenerationSpec {
  TrackingLoop loop{};
  double delay_gain{-90.0};               // [-] K_del of the mapped controller (our sign)
  double normalized_delay{0.1};           // [swing periods] tau_del
  double max_swing_angle{0.174};          // [rad] phi_max (3.51)
  double max_normalized_swing_rate{1.5};  // [rad/period] 1/K_phidot (3.51)
  double output_scale{-90.0 * 0.174};     // [-] K_v (3.51)
  std::vector<double> initial_swings{};   // [rad]; empty = {0, +-5, +-10, +-15, +-20 deg}
  // [-] Z/L; empty = {0, +-0.75}: the first maneuver of section 3.3.3 (0.25 m -> 1.0 m, L = 1 m),
  // both directions. Swings up to 2 phi_max are needed to reach the corner cells (x1, x2 both
  // near +-1). The agreement with Table 3.7 depends on this data set: 33..40 of 49 cells over the
  // sets tried (swings to 10/20/30 deg x distances {0}, {0, +-0.75}, to +-1, to +-2).
  std::vector<double> transfer_distances{};
  double run_duration{4.0};               // [swing periods] per run
  double time_step{1e-3};                 // [swing periods]
};

struct GeneratedRules {
  FuzzyRuleTable rules{};                                           // conflict-resolved table
  std::array<std::array<double, kFuzzySetCount>, kFuzzySetCount> degree{};  // 0 = no rule found
  int runs{0};
  long samples{0};
  long candidate_rules{0};  // rules generated before conflict resolution
  [[nodiscard]] bool fully_populated() const noexcept;
};

/// Runs every (initial swing, transfer distance) pair and builds the table. Throws
/// std::invalid_argument for non-positive scales or steps.
[[nodiscard]] GeneratedRules generate_fuzzy_rules(const RuleGenerationSpec& spec);

/// Number of cells where the two tables give the same set.
[[nodiscard]] int count_agreements(const FuzzyRuleTable& lhs, const FuzzyRuleTable& rhs) noexcept;

}  // namespace crane::anti_swing_analysis
