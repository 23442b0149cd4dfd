#include "crane/stack/swing_calibration_run.hpp"

#include <stdexcept>

#include "crane/stack/follower_run.hpp"
#include "crane/trajectory_planner/speed_reference.hpp"

namespace crane::stack {

CalibratedStack calibrate_swing_on(const StackConfig& config, const plant::PlantMismatch& mismatch,
                                   const optimal_control::FollowerParams& follower, int intervals) {
  if (config.maneuvers.empty()) throw std::invalid_argument("swing calibration: the config has no demo maneuver");
  if (config.facts.crane_kind == common::CraneKind::overhead) {
    throw std::invalid_argument("swing calibration: an overhead crane's bridge drives the out-of-plane swing, and the "
                                "swing record has no bridge column (tower and gantry cranes only)");
  }
  FollowerRun run;
  run.maneuver = config.maneuvers.front();
  run.mismatch = mismatch;
  run.intervals = intervals;
  run.follower = follower;
  const FollowerResult recorded = run_follower(config, run);

  swing_calibration::SwingRecord record;
  record.source = "calibration record: " + run.maneuver.name;
  for (const CycleRecord& c : recorded.records) {
    record.time.push_back(c.t);
    record.trolley_position.push_back(c.x);
    record.slew_angle.push_back(c.gamma);
    record.swing_in_plane.push_back(c.phi);
    record.swing_out_of_plane.push_back(c.theta);
    record.cable_length.push_back(c.L);
  }
  swing_calibration::CalibrationOptions options;
  options.gravity = config.facts.crane.gravity;
  options.whole_record = true;

  CalibratedStack out{config, swing_calibration::fit_swing(record, options), run.maneuver.name};
  out.config.trajectory_planner.manual.swing_length_scale = out.fit.length_scale;
  out.config.trajectory_planner.manual.swing_length_offset = out.fit.length_offset;
  out.config.trajectory_planner.robust_length_range = 0.0;  // known now (crane_calibrate prints the same line)
  trajectory_planner::validate(out.config.trajectory_planner.manual);
  return out;
}

}  // namespace crane::stack
