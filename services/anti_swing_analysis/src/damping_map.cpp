#include "crane/anti_swing_analysis/damping_map.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace crane::anti_swing_analysis {

DampingMapSpec default_damping_map_spec(AntiSwingLaw law, int resolution) {
  if (resolution < 2) throw std::invalid_argument("resolution must be >= 2");
  DampingMapSpec spec;
  spec.law = law;
  spec.resolution = resolution;
  switch (law) {
    case AntiSwingLaw::pd:
      spec.first_min = -80.0;
      spec.first_max = 20.0;
      spec.second_min = -5.0;
      spec.second_max = 20.0;
      break;
    case AntiSwingLaw::delayed_feedback:
      spec.first_min = -150.0;
      spec.first_max = 0.0;
      spec.second_min = 0.0;
      spec.second_max = 0.5;
      break;
    case AntiSwingLaw::delayed_trajectory_correction:
      spec.first_min = -1.0;
      spec.first_max = 0.0;
      spec.second_min = 0.0;
      spec.second_max = 0.6;
      break;
  }
  return spec;
}

namespace {

double grid_value(double low, double high, int index, int count) {
  return low + (high - low) * static_cast<double>(index) / static_cast<double>(count - 1);
}

bool usable(const DominantPair& pair) { return pair.stable && pair.found && std::isfinite(pair.damping); }

}  // namespace

DampingMap compute_damping_map(const DampingMapSpec& spec) {
  if (spec.resolution < 2) throw std::invalid_argument("resolution must be >= 2");
  if (!(spec.first_max > spec.first_min) || !(spec.second_max > spec.second_min))
    throw std::invalid_argument("parameter ranges must have max > min");
  if (spec.law != AntiSwingLaw::pd && spec.second_min < 0.0)
    throw std::invalid_argument("tau_del range must be >= 0");
  const int n = spec.resolution;
  DampingMap map;
  map.spec = spec;
  for (int i = 0; i < n; ++i) {
    map.first_values.push_back(grid_value(spec.first_min, spec.first_max, i, n));
    map.second_values.push_back(grid_value(spec.second_min, spec.second_max, i, n));
  }
  const auto cells = static_cast<std::size_t>(n * n);
  map.damping.assign(cells, std::numeric_limits<double>::quiet_NaN());
  map.direct_damping.assign(cells, std::numeric_limits<double>::quiet_NaN());
  map.stable.assign(cells, 0);
  map.grid_max_damping = -std::numeric_limits<double>::infinity();
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const LawPoint point{spec.law, map.first_values[static_cast<std::size_t>(i)],
                           map.second_values[static_cast<std::size_t>(j)]};
      const DampingEvaluation evaluation = evaluate_damping(point, spec.loop, spec.pade_order);
      const auto cell = static_cast<std::size_t>(i * n + j);
      map.damping[cell] = evaluation.pade.damping;
      map.direct_damping[cell] = evaluation.direct.damping;
      map.stable[cell] = evaluation.pade.stable ? 1 : 0;
      if (usable(evaluation.pade) && evaluation.pade.damping > map.grid_max_damping) {
        map.grid_max_damping = evaluation.pade.damping;
        map.grid_max_first = point.first;
        map.grid_max_second = point.second;
      }
      if (usable(evaluation.pade) && evaluation.direct_independent.found &&
          std::abs(evaluation.direct_independent.pole - evaluation.direct.pole) >
              1e-6 * std::abs(evaluation.direct.pole)) {
        ++map.dominant_selection_flips;
        map.max_selection_flip_difference =
            std::max(map.max_selection_flip_difference,
                     std::abs(evaluation.pade.damping - evaluation.direct_independent.damping));
      }
      if (usable(evaluation.pade) && evaluation.direct.found) {
        const double difference = std::isfinite(evaluation.direct.damping)
                                      ? std::abs(evaluation.pade.damping - evaluation.direct.damping)
                                      : std::numeric_limits<double>::infinity();
        if (difference > map.max_method_difference) {
          map.max_method_difference = difference;
          map.max_method_difference_first = point.first;
          map.max_method_difference_second = point.second;
        }
      }
    }
  }
  // Zoom: 11x11 grids over +-1 cell around the best point, 4 times (each 5x finer).
  map.max_damping = map.grid_max_damping;
  map.max_first = map.grid_max_first;
  map.max_second = map.grid_max_second;
  double half_first = (spec.first_max - spec.first_min) / (n - 1);
  double half_second = (spec.second_max - spec.second_min) / (n - 1);
  for (int level = 0; level < 4 && std::isfinite(map.max_damping); ++level) {
    const double center_first = map.max_first;
    const double center_second = map.max_second;
    for (int i = 0; i < 11; ++i) {
      for (int j = 0; j < 11; ++j) {
        const LawPoint point{spec.law, center_first + half_first * (i - 5) / 5.0,
                             center_second + half_second * (j - 5) / 5.0};
        if (point.law != AntiSwingLaw::pd && point.second < 0.0) continue;
        const DominantPair pair = dominant_pair(pade_roots(point, spec.loop, spec.pade_order));
        if (usable(pair) && pair.damping > map.max_damping) {
          map.max_damping = pair.damping;
          map.max_first = point.first;
          map.max_second = point.second;
        }
      }
    }
    half_first /= 5.0;
    half_second /= 5.0;
  }
  const DampingEvaluation at_max =
      evaluate_damping({spec.law, map.max_first, map.max_second}, spec.loop, spec.pade_order);
  map.direct_damping_at_max = at_max.direct.damping;
  map.direct_independent_damping_at_max = at_max.direct_independent.damping;
  return map;
}

}  // namespace crane::anti_swing_analysis
