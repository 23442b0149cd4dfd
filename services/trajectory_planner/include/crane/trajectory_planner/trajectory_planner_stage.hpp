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
//    start and every kProgressCycles), arrived, or aborted (replaced by a newer request).

#include <array>
#include <cstdint>
#include <optional>
#include <span>

#include "crane/common/stack_facts.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::config {
class YamlSection;
}

namespace crane::trajectory_planner {

/// Reads the `trajectory_planner:` block: trolley_min_position, trolley_max_position [m] in
/// [-100, 100], slew_min_angle, slew_max_angle [rad] in [-20 pi, 20 pi] (each max >= its min); the
/// cable range and gravity come from facts.crane. Throws common::ConfigError naming the field.
[[nodiscard]] TrajectoryPlannerParams read_params(config::YamlSection& block, const common::StackFacts& facts);

/// Human-readable GoalStatus ("rejected: trolley target outside the travel limits").
[[nodiscard]] const char* goal_status_name(GoalStatus status) noexcept;

/// The planner's goal for `request` from `current` (axes, waypoints and 0-limits resolved; an
/// unknown profile code gives a profile start_move() rejects).
[[nodiscard]] MoveGoal to_goal(const protocol::MoveRequest& request, const common::CraneStateEstimate& current) noexcept;

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

class TrajectoryPlannerStage {
 public:
  static constexpr std::size_t kMaxGoalsPerCycle = 8;  // outcomes kept per step; more are counted
  static constexpr std::uint64_t kProgressCycles = 10; // a moving request's progress every 10 cycles

  /// Throws common::ConfigError for invalid params (TrajectoryPlanner's constructor) or a
  /// sample_period that is not positive and finite.
  TrajectoryPlannerStage(const TrajectoryPlannerParams& params, double sample_period);

  /// One new cycle. not_ready: the first estimate could not be held (non-finite), nothing written.
  /// rejected_nonfinite: the estimate is not finite; nothing written, nothing taken. Otherwise ok and
  /// `reference` holds the reference of the estimate's cycle. Never throws, never allocates.
  [[nodiscard]] common::StepStatus step(const protocol::CraneState& estimate, std::span<const protocol::MoveRequest> goals,
                                        protocol::Reference& reference) noexcept;

  /// The goals handled by the last step (at most kMaxGoalsPerCycle).
  [[nodiscard]] std::span<const GoalOutcome> goal_outcomes() const noexcept { return {outcomes_.data(), outcome_count_}; }
  /// The feedback of the last step, for the MoveStatus topic (at most 2 kMaxGoalsPerCycle + 2).
  [[nodiscard]] std::span<const protocol::MoveStatus> move_statuses() const noexcept {
    return {statuses_.data(), status_count_};
  }
  /// Goals refused for a NaN/Inf field since construction.
  [[nodiscard]] std::uint64_t nonfinite_goals() const noexcept { return nonfinite_goals_; }

 private:
  void record(const GoalOutcome& outcome) noexcept;
  void report(std::uint32_t request_id, std::uint8_t result, std::uint8_t reason = 0) noexcept;

  TrajectoryPlanner planner_;
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
  std::uint64_t cycles_since_progress_{0};
  const protocol::CraneState* cycle_estimate_{nullptr};  // the step's estimate (header of the feedback)
};

}  // namespace crane::trajectory_planner
