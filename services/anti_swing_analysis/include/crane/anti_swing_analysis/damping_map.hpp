#pragma once
// Damping maps of the anti-swing laws over their parameter planes (figures 3.16, 3.17 and 3.19 of
// H. M. Omar, "Control of Gantry and Tower Cranes", Virginia Tech 2003), in this project's sign
// convention (see characteristic_equation.hpp). Damping = damping ratio of the dominant (slowest)
// complex pole pair, Pade (3.49) with l = 20; each point is cross-checked by Newton on the exact
// delay equation. Allocates; offline use only.

#include <vector>

#include "crane/anti_swing_analysis/characteristic_equation.hpp"

namespace crane::anti_swing_analysis {

/// Grid and loop of one map. Points are first_min + i (first_max - first_min)/(resolution - 1),
/// likewise for second.
struct DampingMapSpec {
  AntiSwingLaw law{AntiSwingLaw::delayed_feedback};
  double first_min{0.0};   // K_ps or K_del [-]
  double first_max{0.0};
  double second_min{0.0};  // K_ds [-] or tau_del [swing periods], >= 0 for the delay laws
  double second_max{0.0};
  int resolution{81};      // points per axis, >= 2
  int pade_order{20};      // l in (3.49)
  TrackingLoop loop{};
};

/// The grids used by crane_damping_map: they cover the dissertation's maxima in our convention
/// (pd: K_ps -80..20, K_ds -5..20; delay1: K_del -150..0, tau_del 0..0.5; delay2: K_del -1..0,
/// tau_del 0..0.6). Throws std::invalid_argument if resolution < 2.
[[nodiscard]] DampingMapSpec default_damping_map_spec(AntiSwingLaw law, int resolution = 81);

struct DampingMap {
  DampingMapSpec spec;
  std::vector<double> first_values;   // [resolution]
  std::vector<double> second_values;  // [resolution]
  // Row-major [i_first * resolution + i_second]:
  std::vector<double> damping;         // Pade dominant-pair damping (NaN: no complex pair)
  std::vector<double> direct_damping;  // same pair refined by Newton on the exact equation
  std::vector<char> stable;            // 1 if all Pade roots have Re s <= 1e-9
  // Maximum over the stable grid points, then refined by successive 11x11 zooms around it.
  double max_damping{0.0};
  double max_first{0.0};
  double max_second{0.0};
  double grid_max_damping{0.0};  // before refinement
  double grid_max_first{0.0};
  double grid_max_second{0.0};
  double direct_damping_at_max{0.0};              // DampingEvaluation::direct at the max
  double direct_independent_damping_at_max{0.0};  // DampingEvaluation::direct_independent there
  // Points where the independently chosen exact dominant pair is not the Pade one (pair flips
  // at near-ties of the real parts) and their largest damping jump.
  int dominant_selection_flips{0};
  double max_selection_flip_difference{0.0};
  // max |damping - direct_damping| over stable points where both found a pair:
  double max_method_difference{0.0};
  double max_method_difference_first{0.0};
  double max_method_difference_second{0.0};
};

/// Computes the map. Throws std::invalid_argument for resolution < 2, inverted ranges or a
/// negative tau_del range.
[[nodiscard]] DampingMap compute_damping_map(const DampingMapSpec& spec);

}  // namespace crane::anti_swing_analysis
