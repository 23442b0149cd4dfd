#pragma once
// Point-to-point reference generator for the trolley, slew and hoist axes (section 3.3.1 of
// H. M. Omar, "Control of Gantry and Tower Cranes", 2003). Each axis runs its own profile from
// the position at the start of the move; the move ends when the slowest axis arrives.
//
// Beyond the dissertation:
//  - waypoints: a move may pass through up to kMaxWaypoints intermediate points; it is a chain of
//    rest-to-rest segments (current -> waypoint 1 -> ... -> target), each planned with the goal's
//    profile from the previous segment's targets, each starting when the previous one ends;
//  - hoisting during the move: the cable axis runs a trapezoid alongside; the swing-aware profiles
//    of a segment are tuned to the cable length at its start, and shaped (zv/zvd/ei) profiles
//    reschedule their impulses with the reference cable length as it changes
//    (ShapedProfile::reschedule_for_hoisting). The time-optimal profile keeps the length at the
//    segment's start (its swing-free property holds for constant L only).
//
// Real-time: start_move(), hold() and step() are noexcept and allocate nothing; all profiles are
// held by value.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "crane/common/crane_signals.hpp"
#include "crane/common/site.hpp"
#include "crane/trajectory_planner/planned_path.hpp"
#include "crane/trajectory_planner/shaped_profile.hpp"
#include "crane/trajectory_planner/speed_reference.hpp"
#include "crane/trajectory_planner/step_profile.hpp"
#include "crane/trajectory_planner/time_optimal_profile.hpp"
#include "crane/trajectory_planner/trapezoid_profile.hpp"

namespace crane::trajectory_planner {

/// Profile shapes. The swing-aware kinds (zv, zvd, ei, time_optimal) apply to the trolley and slew
/// axes, tuned to w = sqrt(g/L) with L the cable length at the start of the move (the slew's
/// out-of-plane swing has the same frequency); the hoist (cable) axis uses the trapezoid for every
/// kind other than step.
enum class ProfileKind {
  step,          // target at once
  trapezoid,     // (3.43)
  zv,            // trapezoid convolved with a ZV shaper (ShapedProfile)
  zvd,           // trapezoid convolved with a ZVD shaper
  ei,            // trapezoid convolved with an EI shaper
  time_optimal,  // time-optimal swing-free rest-to-rest (TimeOptimalProfile)
  planned,       // a path planned outside the cycle (PlannedPath; start_planned()); start_move() refuses it
};

/// Travel limits of the crane, checked against every goal.
struct TrajectoryPlannerParams {
  double trolley_min_position{0.1};   // [m] along the jib
  double trolley_max_position{1.2};   // [m]
  double slew_min_angle{-6.283185307179586};  // [rad]
  double slew_max_angle{6.283185307179586};   // [rad]
  double cable_min_length{0.2};       // [m]
  double cable_max_length{5.0};       // [m]
  double gravity{9.8};                // [m/s^2] swing model, w = sqrt(gravity / cable_length)
  double swing_damping_ratio{0.0};    // [-] swing damping used by the zv/zvd/ei shapers, 0..0.3
  double ei_vibration_tolerance{0.05};  // [-] EI residual-vibration tolerance V, (0, 0.2]
  ManualParams manual{};              // operator speed control and stops (speed_reference.hpp)
  /// A minimum-time plan made on the configured pendulum (none learnt yet, or the state
  /// estimator's swing_length off) robust to its length: the plan also brings pendulums
  /// (1 - robust_length_range) and (1 + robust_length_range) times as long to rest, at a duration of
  /// (1 + robust_margin) T* (optimal_control::MinimumTimeProblem::detuned_pendulums;
  /// docs/optimal_control.md, "Robust to the pendulum's length"). Each in [0, 0.5]; a range of 0
  /// plans every move as before. A plan on a learnt pendulum is never made robust.
  double robust_length_range{0.0};    // [-]
  double robust_margin{0.2};          // [-]
  /// [m] >= 0: where > 0, only a plan whose trolley ends within this radius of the slew axis is made
  /// robust (a tower crane). Near the mast the slew is a weak actuator for the out-of-plane swing (a
  /// slew angle moves the trolley sideways by the radius times it), so the hold at the target damps
  /// the swing a longer cable leaves slowly, with the slew outside its settle band meanwhile; further
  /// out the hold does, and a robust plan's margin costs more than it saves (docs/optimal_control.md,
  /// "Robust near the mast"). 0: every plan on the configured pendulum.
  double robust_within_radius{0.0};
  common::Site site{};                // the no-go zones (goals refused inside, paths planned around)
  // An overhead crane's bridge (crane.kind = overhead; false elsewhere): its runway travel (its manual
  // motion is manual.bridge). The planner stage runs it as the trolley of a second planner
  // (bridge_view(); trajectory_planner_stage.hpp); the planner itself has no bridge axis.
  bool bridge_enabled{false};
  double bridge_min_position{0.0};    // [m]
  double bridge_max_position{0.0};    // [m]

  /// The params of the bridge's planner: the trolley's travel and manual motion replaced by the
  /// bridge's, no zones, bridge_enabled false.
  [[nodiscard]] TrajectoryPlannerParams bridge_view() const {
    TrajectoryPlannerParams p = *this;
    p.trolley_min_position = bridge_min_position;
    p.trolley_max_position = bridge_max_position;
    p.manual.trolley = manual.bridge;
    p.site = common::Site{};
    p.bridge_enabled = false;
    return p;
  }

  /// The bounds the speed reference keeps (the travel above).
  [[nodiscard]] SpeedBounds speed_bounds() const noexcept {
    return {{trolley_min_position, slew_min_angle, cable_min_length},
            {trolley_max_position, slew_max_angle, cable_max_length},
            gravity};
  }
};

/// Plans `r` (its trolley_target set) on `pendulum`: robust to its length (params.robust_length_range
/// and robust_margin) where it is the configured one (`learnt` false) and the trolley ends within
/// params.robust_within_radius (where > 0), fast on it otherwise: where the state estimator learnt it,
/// or further out.
inline void plan_on_pendulum(PlanRequest& r, const EquivalentPendulum& pendulum, bool learnt,
                             const TrajectoryPlannerParams& params) noexcept {
  r.swing = pendulum;
  const bool near_the_mast = params.robust_within_radius <= 0.0 || r.trolley_target <= params.robust_within_radius;
  r.robust_length_range = learnt || !near_the_mast ? 0.0 : params.robust_length_range;
  r.robust_margin = params.robust_margin;
}

/// An intermediate point of a move.
struct Waypoint {
  double trolley{0.25};  // [m]
  double slew{0.0};      // [rad]
  double cable{1.0};     // [m]
};
inline constexpr std::size_t kMaxWaypoints = 8;
/// [s] the longest move start_move() plans. A goal whose limits make it longer (e.g. a velocity
/// limit of 1e-9 m/s, or 1e-311: a duration of Inf) is a wrong request, refused as
/// rejected_invalid_limits: its reference would carry move_duration = Inf (which every node's NaN/Inf
/// gate drops, stalling the chain), and the no-go zone check samples the whole move every 20 ms
/// (a 1e9 s move would hold the 100 Hz loop for hours). Found by tests/fuzz (topic_gates).
inline constexpr double kMaxMoveDuration = 600.0;

/// A move request.
struct MoveGoal {
  std::uint64_t request_id{0};
  ProfileKind profile{ProfileKind::trapezoid};
  double trolley_target{0.25};  // [m]
  double slew_target{0.0};      // [rad]
  double cable_target{1.0};     // [m]
  AxisLimits trolley_limits{0.4982, 0.9929};  // [m/s], [m/s^2]   (3.54)
  AxisLimits slew_limits{1.0435, 2.0796};     // [rad/s], [rad/s^2] (3.55)
  AxisLimits cable_limits{0.2, 0.5};          // [m/s], [m/s^2]
  std::array<Waypoint, kMaxWaypoints> waypoints{};  // passed through in order, before the targets
  std::size_t waypoint_count{0};              // valid entries of `waypoints`, <= kMaxWaypoints
};

/// Why a goal was refused (the planner then keeps what it was doing).
enum class [[nodiscard]] GoalStatus {
  accepted,
  rejected_nonfinite,             // a target, limit or start position is NaN/Inf
  rejected_trolley_out_of_range,  // trolley_target outside [trolley_min_position, trolley_max_position]
  rejected_slew_out_of_range,     // slew_target outside [slew_min_angle, slew_max_angle]
  rejected_cable_out_of_range,    // cable_target outside [cable_min_length, cable_max_length]
  rejected_invalid_limits,        // a limit is <= 0, an axis profile could not be planned, or the
                                  // move would last longer than kMaxMoveDuration
  rejected_unknown_profile,       // the goal's profile is not a ProfileKind (e.g. an unknown wire code)
  rejected_waypoint,              // more than kMaxWaypoints, or a waypoint non-finite or out of range
  // Refusals of the planner stage (trajectory_planner_stage.hpp), never of start_move():
  rejected_zone,                  // the target is in a no-go zone, or no route around the zones
  rejected_operating_mode,        // goals are not taken in the operating mode (MANUAL, MAINTENANCE)
  rejected_supervisor_stop,       // the supervisor reports a fault or an emergency stop
  rejected_manual_motion,         // operator speed control is moving the crane
  rejected_bridge_out_of_range,   // the bridge target (or a bridge waypoint) outside its travel, or a
                                  // bridge target for a crane without a bridge
};

enum class MovePhase {
  holding,  // no move yet (or after hold()): the reference holds a position
  moving,
  arrived,  // the last move finished; the reference holds its targets
};

struct PlannerOutput {
  common::MotionReference reference;
  MovePhase phase{MovePhase::holding};
  std::uint64_t request_id{0};  // of the current/last move, 0 if none
  double time_in_move{0.0};     // [s] since the move started
  double move_duration{0.0};    // [s] planned duration of the current/last move
};

class TrajectoryPlanner {
 public:
  /// Throws common::ConfigError naming the field unless every bound is finite and min < max,
  /// cable_min_length > 0, gravity > 0, 0 <= swing_damping_ratio <= 0.3,
  /// 0 < ei_vibration_tolerance <= 0.2, the manual params are valid (validate(ManualParams)) and
  /// the site is (common::validate(Site)).
  explicit TrajectoryPlanner(const TrajectoryPlannerParams& params);

  /// Hold the given position (phase holding). Non-finite positions -> rejected_nonfinite.
  [[nodiscard]] GoalStatus hold(const common::CraneStateEstimate& current) noexcept;

  /// Start a move from `current` (trolley_position [m], slew_angle [rad], cable_length [m]).
  /// Every axis is planned into a temporary first and committed only if all succeed: on rejection
  /// nothing changes (the running move, if any, continues).
  [[nodiscard]] GoalStatus start_move(const MoveGoal& goal,
                                      const common::CraneStateEstimate& current) noexcept;

  /// Start the path `path` (planned_path.hpp) as move `request_id`: one segment, every axis on its
  /// samples (`bridge_axis`: the path's bridge as this planner's trolley, the bridge's planner of an
  /// overhead crane). rejected_nonfinite for a null, invalid or bridge-less (when asked) path;
  /// rejected_invalid_limits for one longer than kMaxMoveDuration. Allocates nothing.
  [[nodiscard]] GoalStatus start_planned(std::uint64_t request_id, const std::shared_ptr<const PlannedPath>& path,
                                         bool bridge_axis = false) noexcept;

  /// Advance time by `dt` [s] (>= 0) and sample the reference at the new time.
  /// not_ready before the first hold()/start_move() (output untouched); rejected_nonfinite if dt is
  /// NaN/Inf or negative (time not advanced, output untouched).
  [[nodiscard]] common::StepStatus step(double dt, PlannerOutput& output) noexcept;

  /// Back to not_ready.
  void reset() noexcept;

  /// The reference of the current time (as the last step() returned it), for a hand-over to the
  /// speed reference. Precondition: a hold()/start_move() happened.
  [[nodiscard]] common::MotionReference sample_now() const noexcept;

  /// The zone (index) the move currently planned enters, sampling its reference every `spacing`
  /// [s] (or every 1/400 of the rest of the move, if that is longer) from the current time, or -1
  /// (zone_guard.hpp): each sample with the margin of the largest
  /// horizontal acceleration of the swing period before it (the swing it excited is still there).
  [[nodiscard]] int intruded_zone(std::uint32_t zones_enabled, double spacing) const noexcept;

  [[nodiscard]] const TrajectoryPlannerParams& params() const noexcept { return params_; }
  /// Planned duration [s] of the current move (0 while holding).
  [[nodiscard]] double move_duration() const noexcept { return move_duration_; }
  /// The segment of the current move the reference is on: 0 .. its waypoint count (the waypoints
  /// before it are passed); 0 while holding.
  [[nodiscard]] std::size_t segment_index() const noexcept;
  /// True while a move runs its last segment (every waypoint passed) with each axis on a profile of
  /// its own (not a planned path, whose axes share one law): an axis may then run on to its target
  /// while the others are stopped (TrajectoryPlannerStage, a stop naming axes).
  [[nodiscard]] bool last_segment_axes_independent() const noexcept;
  /// Where the current move ends (each axis's target, at rest); the held position while holding.
  /// Precondition: a hold()/start_move() happened.
  [[nodiscard]] common::MotionReference sample_end() const noexcept;

 private:
  struct Axis {
    TrapezoidProfile trapezoid;
    StepProfile step;
    ShapedProfile shaped;
    TimeOptimalProfile time_optimal;
    PlannedProfile planned;
    ProfileKind kind{ProfileKind::step};
    // Indexing by kind (not a stored pointer) keeps the planner safely copyable.
    [[nodiscard]] const AxisProfile& active() const noexcept {
      switch (kind) {
        case ProfileKind::trapezoid: return trapezoid;
        case ProfileKind::zv:
        case ProfileKind::zvd:
        case ProfileKind::ei: return shaped;
        case ProfileKind::time_optimal: return time_optimal;
        case ProfileKind::planned: return planned;
        case ProfileKind::step: break;
      }
      return step;
    }
  };
  /// Plans `axis` (a temporary) with `kind`; `swing_frequency` [rad/s] is used by the shaped and
  /// time-optimal kinds. False if the profile rejected its arguments (axis then unspecified).
  [[nodiscard]] bool plan_axis(Axis& axis, ProfileKind kind, double start, double target,
                               const AxisLimits& limits, double swing_frequency) const noexcept;

  /// One rest-to-rest leg of a move (the whole move without waypoints).
  struct Segment {
    Axis trolley;
    Axis slew;
    Axis cable;
    double start_time{0.0};  // [s] since the move started
    double duration{0.0};    // [s] the slowest axis
  };
  using Segments = std::array<Segment, kMaxWaypoints + 1>;
  [[nodiscard]] const Segment& segment_at(double time_in_move) const noexcept;

  TrajectoryPlannerParams params_;
  Segments segments_{};
  std::size_t segment_count_{1};
  bool ready_{false};
  MovePhase phase_{MovePhase::holding};
  std::uint64_t request_id_{0};
  double time_in_move_{0.0};
  double move_duration_{0.0};
};

}  // namespace crane::trajectory_planner
