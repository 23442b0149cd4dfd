#pragma once
// The trajectory planner stage: what the trajectory_planner process computes each cycle, without
// DDS, clock or thread. The estimate of cycle k and the move requests that arrived since the last
// cycle -> the reference of cycle k (same seq and origin).
//
// Rules (docs/architecture.md, "The 100 Hz cycle"):
//  - the first estimate is held (phase holding) until a goal arrives;
//  - goals are taken only with a new cycle, so a cycle's reference is computed once;
//  - request ids only increase: a request whose id is not above the last one taken is ignored
//    (operators re-send a request until they see it executed);
//  - MoveRequest.header.seq > 0 names the cycle the move starts at: a goal arriving earlier waits
//    here (the latest waiting one wins); one arriving later starts at once (reported as late);
//  - a goal's axes not named in MoveRequest.axes keep their current position, limits given as 0
//    keep the planner's defaults, unknown profile codes are rejected (the running move continues);
//  - every request gets feedback, as a ROS 2 action does (MoveStatus, move_statuses()): waiting for
//    its start cycle, or rejected (reason, the value and the bound it violated), then moving (at the
//    start and every kProgressCycles), arrived, or aborted (replaced by a newer request, stopped, the
//    operating mode changed, a fault, a zone approach);
//  - a stop request (MoveRequest.command COMMAND_STOP) is a controlled anti-sway stop: the running
//    reference is handed over to the speed reference (speed_reference.hpp) with every speed 0; its
//    feedback (RESULT_STOPPING, with the predicted stopping position) is written in the cycle the
//    deceleration starts, before that cycle's reference; RESULT_ARRIVED when at rest. A stop whose
//    `axes` names some of the trolley, slew and hoist (0 names every one) stops those; the others run
//    on to their targets, when the move runs its last segment with a profile per axis (not a planned
//    minimum-time path, not an overhead crane's bridge; otherwise every axis stops). The site link
//    asks for such a stop when stopping an axis would carry it past its target (docs/site.md). The same stop
//    answers a change of operating mode while moving and the supervisor's warnings zone_approach
//    and speed_limited (a travel or slew limit approached faster than its approach speed);
//  - operating modes (OPC 40020) come from the supervisor's status: goals are refused in MANUAL and
//    MAINTENANCE (REASON_MODE, value the mode), operator speeds in FULLAUTOMATIC (counted); in
//    SEMIAUTOMATIC an operator speed takes over from a running goal (aborted: manual motion);
//  - operator speeds (OperatorSpeed) are checked (finite, in [-1, 1], a known range; else refused
//    and counted), scaled by the rated speeds (the micro-speed fraction, the maintenance fraction)
//    and shaped (none in MAINTENANCE); silence for manual.dead_man_timeout releases every axis (a
//    soft stop); after a stop the stick must come back to neutral before it moves the crane again;
//  - when the supervisor reports a fault or an emergency stop, a running goal is aborted (fault) and
//    goals are refused; when it lets the crane move again, the reference holds the measured
//    position, so a reset resumes nothing;
//  - when it warns that the drives were braked under way (WARNING_DRIVES_BRAKED: a stalled command
//    chain, no fault), the goal pauses: the reference holds the measured position, where the
//    brakes stopped the crane, and when they are open, the swing they caused has settled below
//    kResumeSwing and every axis is slower than kResumeSpeed, the rest of the goal (the waypoints not yet passed, the targets) starts again
//    from there with the goal's id and profile (a minimum-time goal: time-optimal); not settled
//    kResumeTimeoutCycles after they opened, the goal ends there (REASON_BRAKED). So the tracking
//    law never chases a reference that ran on during the stall. Under operator speeds (or a soft
//    stop) the speed reference starts again from rest where the crane is, and the stick still held
//    drives it on from there. A goal the planner cannot start again (an overhead crane's: its
//    bridge), or a stop reason while paused (a stop request, a mode change, a fault, a zone, the
//    site), ends it there (REASON_BRAKED, or that reason);
//  - no-go zones (zone_paths.hpp): a goal inside one is refused (REASON_ZONE, value the zone's
//    index), others are planned around; operator speeds are held back so that the load can always
//    come to rest outside every zone (SpeedReference).

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>

#include "crane/common/stack_facts.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/trajectory_planner/planned_path.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::trajectory_planner {

/// Reads the `trajectory_planner:` block: trolley_min_position, trolley_max_position [m] in
/// [-100, 100], slew_min_angle, slew_max_angle [rad] in [-20 pi, 20 pi] (each max >= its min), the
/// manual: block; on an overhead crane (facts.crane_kind) also bridge_min_position,
/// bridge_max_position [m] in [-1000, 1000] and manual.bridge_speed/acceleration (unknown fields
/// elsewhere), and site zones are refused there. The cable range and gravity come from facts.crane.
/// Throws common::ConfigError naming the field.
[[nodiscard]] TrajectoryPlannerParams read_params(config::YamlSection& block, const common::StackFacts& facts);

/// Human-readable GoalStatus ("rejected: trolley target outside the travel limits").
[[nodiscard]] const char* goal_status_name(GoalStatus status) noexcept;

/// The planner's goal for `request` from `current` (axes, waypoints and 0-limits resolved: a limit of
/// 0 is the configured rated motion of `rated`, the hoist's always (the request has no field for it);
/// an unknown profile code gives a profile start_move() rejects).
[[nodiscard]] MoveGoal to_goal(const protocol::MoveRequest& request, const common::CraneStateEstimate& current,
                               const ManualParams& rated) noexcept;

/// What happened to a goal in a step.
struct GoalOutcome {
  enum class When : std::uint8_t {
    now,      // started at this cycle (header.seq 0, or this cycle)
    as_asked, // waited for its start cycle, started now
    late,     // asked for an earlier cycle than the one it arrived at: started now
    waiting,  // its start cycle is ahead: it waits
    ignored,  // its id is not above the last one taken
  };
  std::uint32_t request_id{0};
  std::uint64_t cycle{0};        // the cycle of this step
  std::uint64_t asked_cycle{0};  // MoveRequest.header.seq
  When when{When::now};
  GoalStatus status{GoalStatus::accepted};  // for now, as_asked and late
  double trolley_target{0.0};    // [m] as requested
  double slew_target{0.0};       // [rad]
};

/// The feedback of a goal outcome that refused it: reason, value and bound (MoveStatus fields).
void describe_rejection(GoalStatus status, const MoveGoal& goal, const TrajectoryPlannerParams& params,
                        protocol::MoveStatus& feedback) noexcept;

/// What the planner's process received for one cycle.
struct PlannerCycle {
  const protocol::CraneState* estimate{nullptr};      // the cycle's estimate (required)
  std::span<const protocol::MoveRequest> goals{};     // move and stop requests since the last cycle
  std::span<const protocol::OperatorSpeed> speeds{};  // operator speed samples since the last cycle
  const protocol::SupervisorStatus* status{nullptr};  // the latest supervisor status (nullptr: none yet:
                                                      // FULLAUTOMATIC, the zones enabled at start)
};

class TrajectoryPlannerStage {
 public:
  static constexpr std::size_t kMaxGoalsPerCycle = 8;  // outcomes kept per step; more are counted
  static constexpr std::uint64_t kProgressCycles = 10; // a moving request's progress every 10 cycles
  /// [rad] a goal paused by the brakes (WARNING_DRIVES_BRAKED) goes on once they are open and the
  /// load's swing amplitude (either plane: sqrt(angle^2 + (rate / w)^2), w = sqrt(g / L)) is below
  /// this: the brakes' jolt swings it, and a move started into that swing (the anti-swing law's
  /// correction on top of the profile) overspeeds the drives.
  static constexpr double kResumeSwing = 0.017;
  /// [m/s], [rad/s] ... and every axis slower than this (trolley, slew, hoist): the rest of the goal is
  /// planned from rest. The brakes hold the trolley and the slew; the hoist ramps down to the held
  /// reference at its own rate (up to 36 mm from 0.2 m/s on the lab crane), and a plan started while it
  /// still moved left it coasting past a work point's box: the site guard's stop on hosts (docs/site.md).
  static constexpr double kResumeSpeed = 0.01;
  /// [cycles] a paused goal whose swing has not settled this long after the brakes opened ends
  /// there (REASON_BRAKED): a client sends it again.
  static constexpr std::uint64_t kResumeTimeoutCycles = 1000;

  /// Throws common::ConfigError for invalid params (TrajectoryPlanner's constructor) or a
  /// sample_period that is not positive and finite.
  TrajectoryPlannerStage(const TrajectoryPlannerParams& params, double sample_period);

  /// One new cycle. not_ready: the first estimate could not be held (non-finite), nothing written.
  /// rejected_nonfinite: the estimate is not finite; nothing written, nothing taken. Otherwise ok and
  /// `reference` holds the reference of the estimate's cycle. Never throws, never allocates.
  [[nodiscard]] common::StepStatus step(const PlannerCycle& cycle, protocol::Reference& reference) noexcept;
  /// The same without operator speeds or supervisor status.
  [[nodiscard]] common::StepStatus step(const protocol::CraneState& estimate, std::span<const protocol::MoveRequest> goals,
                                        protocol::Reference& reference) noexcept {
    return step(PlannerCycle{&estimate, goals, {}, nullptr}, reference);
  }

  /// The goals handled by the last step (at most kMaxGoalsPerCycle).
  [[nodiscard]] std::span<const GoalOutcome> goal_outcomes() const noexcept { return {outcomes_.data(), outcome_count_}; }
  /// The feedback of the last step, for the MoveStatus topic (at most 2 kMaxGoalsPerCycle + 2).
  [[nodiscard]] std::span<const protocol::MoveStatus> move_statuses() const noexcept {
    return {statuses_.data(), status_count_};
  }
  /// Goals refused for a NaN/Inf field since construction.
  [[nodiscard]] std::uint64_t nonfinite_goals() const noexcept { return nonfinite_goals_; }
  /// Operator speed samples refused since construction: NaN/Inf, outside [-1, 1] or an unknown range
  /// code (rejected_speeds), or arriving in FULLAUTOMATIC (speeds_outside_manual).
  [[nodiscard]] std::uint64_t rejected_speeds() const noexcept { return rejected_speeds_; }
  [[nodiscard]] std::uint64_t speeds_outside_manual() const noexcept { return speeds_outside_manual_; }
  /// A goal with the minimum-time profile (PROFILE_MINIMUM_TIME) waiting for its plan, or empty:
  /// the crane holds where the move starts until provide_plan() hands the plan over (see the header).
  /// Its `swing` is the pendulum the state estimator has learnt (the estimate's swing_length_scale
  /// and _offset while swing_length_confident) when it swings over the move's cable span
  /// (swings_down_to the shorter of cable_from and cable_target), else the configured
  /// manual.swing_length_scale and _offset.
  [[nodiscard]] const std::optional<PlanRequest>& plan_request() const noexcept { return plan_request_; }
  /// The plan of request `sequence` (PlanRequest::sequence), taken at the next step: its path starts
  /// then (or at the goal's start cycle), and the reference carries the path's law of each cycle;
  /// null (not solved) or a path start_planned() refuses: the goal runs the time-optimal profile
  /// (unsolved_plans() counts it). Ignored for a request that is no longer asked (replaced, stopped,
  /// cancelled by a fault or a mode change meanwhile). Allocates nothing (the path is shared).
  void provide_plan(std::uint64_t sequence, std::shared_ptr<const PlannedPath> path) noexcept;
  /// Minimum-time goals from rest (no waypoint, no zone) that ran the time-optimal profile for want of
  /// a plan: not solved, or started before the supervisor's sway limit was heard.
  [[nodiscard]] std::uint64_t unsolved_plans() const noexcept { return unsolved_plans_; }
  /// The operating mode the stage applies (an OPERATION_* code).
  [[nodiscard]] std::uint8_t operating_mode() const noexcept { return operating_mode_; }
  /// True while the speed reference (manual motion or a stop) drives the reference.
  [[nodiscard]] bool under_speed_control() const noexcept { return source_ == Source::speed; }
  /// The operator's speed targets of the last step [m/s, rad/s, m/s] (0 when released: dead man,
  /// stop, neutral required, a mode without operator speeds).
  [[nodiscard]] const std::array<double, 3>& speed_targets() const noexcept { return targets_; }
  /// AXIS bits held back by the travel or zone bounds in the last step (manual motion).
  [[nodiscard]] std::uint8_t held_axes() const noexcept { return held_axes_; }

 private:
  enum class Source : std::uint8_t { profile, speed };
  static constexpr std::uint8_t kEveryAxis =
      protocol::MoveRequest::AXIS_TROLLEY | protocol::MoveRequest::AXIS_SLEW | protocol::MoveRequest::AXIS_HOIST;
  void record(const GoalOutcome& outcome) noexcept;
  protocol::MoveStatus* report(std::uint32_t request_id, std::uint8_t result, std::uint8_t reason = 0) noexcept;
  void abort_active(std::uint8_t reason) noexcept;
  /// The plan request of `r` from the reference's `rest` (and the bridge's `bridge_rest` [m]); axes `r`
  /// does not name stay there; the goal's rated limits, the sway limit heard.
  [[nodiscard]] PlanRequest plan_of(const protocol::MoveRequest& r, const common::CraneStateEstimate& current,
                                    const common::MotionReference& rest, double bridge_rest) const noexcept;
  /// A minimum-time goal `r` that waits for its start cycle: its plan asked for now, from where the
  /// reference rests (`current`: the estimate, for the axes `r` does not name).
  void plan_ahead(const protocol::MoveRequest& r, const common::CraneStateEstimate& current) noexcept;
  /// Drops a goal waiting for its plan, reported aborted for `reason`.
  void cancel_plan(std::uint8_t reason) noexcept;
  /// Hands the running reference over to the speed reference with every speed 0; `stop_id` (0:
  /// none) is the stop request answered when at rest. `stopped_axes` (AXIS bits; every axis by
  /// default): the axes the stop decelerates. The others run on to their targets on their profile
  /// when the move runs its last segment with a profile per axis
  /// (TrajectoryPlanner::last_segment_axes_independent); otherwise every axis stops.
  void soft_stop(std::uint32_t stop_id, std::uint8_t stopped_axes = kEveryAxis) noexcept;
  [[nodiscard]] bool moving() const noexcept;
  void take_speeds(std::span<const protocol::OperatorSpeed> speeds, std::uint64_t seq) noexcept;
  /// The operator's speed targets: trolley, slew, hoist, bridge (0 without a bridge).
  [[nodiscard]] std::array<double, 4> targets_of(std::uint64_t seq) const noexcept;
  void report_rest(protocol::MoveStatus& status) const noexcept;

  TrajectoryPlanner planner_;
  TrajectoryPlanner scratch_;        // routes around zones are tried here (same params, no allocation)
  // An overhead crane's bridge: a second planner and speed reference that run it as their trolley
  // (TrajectoryPlannerParams::bridge_view()), started, stopped and held with the crane's; absent elsewhere.
  struct BridgeAxis {
    explicit BridgeAxis(const TrajectoryPlannerParams& p) : params(p), planner(p), trial(p) {}
    TrajectoryPlannerParams params;
    TrajectoryPlanner planner;
    TrajectoryPlanner trial;         // a goal is planned here first: both axes start it, or neither
    SpeedReference speed{};
    PlannerOutput output{};
    double target{0.0};              // [m] of the active goal
    double operator_speed{0.0};      // [-1, 1] the latest accepted operator bridge speed
    double speed_target{0.0};        // [m/s] its target of the last step
    [[nodiscard]] common::AxisReference reference(bool speed_control) const noexcept {
      return speed_control ? speed.reference().trolley : output.reference.trolley;
    }
  };
  std::optional<BridgeAxis> bridge_;
  SpeedReference speed_{};
  Source source_{Source::profile};
  // Under a stop naming axes: the AXIS bits still running on to their targets on planner_'s profile
  // (the speed reference takes each cycle's sample; a bit clears when its axis rests at its target).
  std::uint8_t finishing_axes_{0};
  std::uint8_t operating_mode_{protocol::SupervisorStatus::OPERATION_FULLAUTOMATIC};
  std::uint32_t zones_enabled_{0};
  bool supervisor_stopped_{false};   // the supervisor reports a fault or an emergency stop
  std::uint8_t supervisor_mode_{0};  // its MODE_* code
  bool hold_on_release_{false};      // hold the measured position when the supervisor releases the crane
  std::uint32_t stop_id_{0};         // the stop request being executed (0: none)
  bool require_neutral_{false};      // after a stop: operator speeds ignored until all are 0
  std::array<double, 3> operator_speed_{};  // [-1, 1] the latest accepted operator speeds
  bool operator_micro_{false};
  std::uint64_t operator_seq_{0};    // cycle at which operator_speed_ arrived
  bool have_operator_input_{false};
  bool was_commanding_{false};       // the last cycle had a non-zero operator target
  std::uint64_t cycles_since_manual_report_{0};
  std::uint8_t held_axes_{0};
  std::array<double, 3> targets_{};
  std::uint64_t rejected_speeds_{0};
  std::uint64_t speeds_outside_manual_{0};
  double sample_period_;
  bool holding_{false};
  std::uint32_t last_request_{0};
  std::optional<protocol::MoveRequest> pending_;
  PlannerOutput output_{};
  std::array<GoalOutcome, kMaxGoalsPerCycle> outcomes_{};
  std::size_t outcome_count_{0};
  std::uint64_t nonfinite_goals_{0};
  std::array<protocol::MoveStatus, 2 * kMaxGoalsPerCycle + 2> statuses_{};
  std::size_t status_count_{0};
  MoveGoal active_goal_{};           // the request being executed (targets for the distances to go)
  bool active_{false};               // a move of active_goal_ is under way (not yet arrived or aborted)
  // The drives braked under way (WARNING_DRIVES_BRAKED): the rest of active_goal_ (the waypoints
  // not yet passed, the targets), started again from the measured position when the brakes open.
  std::optional<MoveGoal> paused_;
  std::uint64_t paused_seq_{0};  // the last cycle the brakes held the paused goal
  std::uint64_t cycles_since_progress_{0};
  const protocol::CraneState* cycle_estimate_{nullptr};  // the step's estimate (header of the feedback)
  // The minimum-time profile (planned_path.hpp).
  double max_swing_{0.0};                         // [rad] the supervisor's sway limit (0: not heard yet)
  std::optional<PlanRequest> plan_request_;       // a goal waiting for its plan
  std::uint64_t plan_sequence_{0};                // the last PlanRequest::sequence given
  protocol::MoveRequest plan_fallback_{};         // that goal with the time-optimal profile
  std::shared_ptr<const PlannedPath> plan_answer_;  // handed over by provide_plan
  bool plan_answered_{false};
  std::shared_ptr<const PlannedPath> planned_;    // the path whose law the reference carries
  std::uint64_t planned_id_{0};
  std::uint64_t unsolved_plans_{0};
};

}  // namespace crane::trajectory_planner
