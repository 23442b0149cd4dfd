#pragma once
// A crane calibrated the way docs/calibration.md does it by hand, in one call (issue 32; docs/
// optimal_control.md, "Calibrated on the crane"): a closed-loop record of the config's first demo
// maneuver on the plant as it is (a mismatch included), the swing model fitted to that record
// (swing_calibration::fit_swing, the whole record with the measured drive accelerations as input),
// and the fitted equivalent pendulum a L + c written into the config's trajectory_planner.manual
// block, where the manual shaper and the minimum-time plans read it
// (trajectory_planner::equivalent_swing_length). The record is the minimum-time follower's, on the
// uncalibrated config: what an engineer records after rigging a load.
//
// Errors: std::invalid_argument for a config with no demo maneuver or an overhead crane (its
// bridge's acceleration drives the out-of-plane swing, which the swing record has no column for);
// what run_follower throws (the bound not solved); swing_calibration::CalibrationError when the
// record has no swing to fit; common::ConfigError when the fitted length is outside the manual
// block's ranges (trajectory_planner.manual.swing_length_*).

#include <string>

#include "crane/optimal_control/trajectory_follower.hpp"
#include "crane/plant/plant_stage.hpp"
#include "crane/stack/stack_config.hpp"
#include "crane/swing_calibration/swing_calibration.hpp"

namespace crane::stack {

struct CalibratedStack {
  StackConfig config;                 // the given config, its manual.swing_length_scale and _offset the fit's,
                                      // its robust_length_range 0 (the pendulum is known)
  swing_calibration::SwingFit fit;    // a, c, the damping ratio and the residual
  std::string maneuver;               // the recorded maneuver's name
};

/// Calibrates `config` on the plant of `mismatch` (see the header): the follower with `follower`'s
/// weights and a bound of `intervals` collocation intervals.
[[nodiscard]] CalibratedStack calibrate_swing_on(const StackConfig& config, const plant::PlantMismatch& mismatch,
                                                 const optimal_control::FollowerParams& follower = {},
                                                 int intervals = 200);

}  // namespace crane::stack
