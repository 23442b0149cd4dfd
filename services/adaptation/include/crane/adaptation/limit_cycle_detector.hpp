#pragma once
// Limit-cycle detector on one drive: the stiction hazard of section 3.1 of H. M. Omar, "Control of
// Gantry and Tower Cranes", Virginia Tech 2003 ("to cancel it, we need to reverse the control action
// after it passes zero velocity, which generates limit cycles"). Over-compensated friction makes the
// axis hunt: at rest (its position within `rest_span` over the last `window`), the drive voltage
// changes sign and the axis breaks away, alternately in each direction, again and again.
//
// Counted each sample:
//   - a drive-voltage sign change at rest: |u| >= min_voltage with the opposite sign of the last
//     such voltage (the compensation's dither at rest counts here too: it is reported, not a fault);
//   - a hunting reversal: the axis leaves the zero-velocity band d_s ((3.3), backward difference of
//     the position) at rest, in the direction opposite to its previous breakaway and the same as
//     the drive voltage.
// The detector fires (latched until reset()) when `max_reversals` hunting reversals fall within
// one window. A move is not at rest (it travels further than rest_span) and never counts.
//
// Errors: the constructor throws common::ConfigError naming the field, value and bound; step() is
// noexcept and allocation-free (the window's ring is sized at construction).

#include <cstdint>
#include <vector>

namespace crane::adaptation {

struct LimitCycleParams {
  double window{4.0};        // [s] in [0.1, 60]
  double rest_span{0.01};    // [m] or [rad] position span over the window that counts as at rest, > 0
  double min_voltage{0.2};   // [V] smaller drive voltages have no sign, >= 0
  int max_reversals{6};      // [-] hunting reversals within a window that make a limit cycle, >= 2
};

/// Throws common::ConfigError naming `prefix`.<field>, the value and the bound.
void validate(const LimitCycleParams& params, const char* prefix);

class LimitCycleDetector {
 public:
  /// `sample_period` [s] > 0, `zero_velocity_band` [m/s or rad/s] >= 0. Throws common::ConfigError.
  LimitCycleDetector(const LimitCycleParams& params, double sample_period, double zero_velocity_band,
                     const char* prefix);

  /// One sample: `position` [m or rad], `voltage` [V] applied to the drive. Non-finite: ignored.
  void step(double position, double voltage) noexcept;
  void reset() noexcept;

  [[nodiscard]] bool fired() const noexcept { return fired_; }
  [[nodiscard]] std::uint32_t sign_changes_at_rest() const noexcept { return sign_changes_; }
  [[nodiscard]] std::uint32_t hunting_reversals() const noexcept { return reversals_total_; }

 private:
  LimitCycleParams params_;
  double sample_period_;
  double zero_velocity_band_;
  std::vector<double> positions_;            // ring over the window
  std::vector<std::uint64_t> reversal_at_;   // ring of the last max_reversals reversal samples
  std::uint64_t sample_{0};
  double last_position_{0.0};
  int last_voltage_sign_{0};
  int last_breakaway_{0};
  int moving_{0};
  std::uint32_t sign_changes_{0};
  std::uint32_t reversals_total_{0};
  bool fired_{false};
};

}  // namespace crane::adaptation
