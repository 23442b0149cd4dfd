#pragma once
// A crane's side of the site protocol (issue 34, items 2-4; docs/site.md, "Each crane's site
// link"): what turns the crane's queue of pick-and-place jobs into requests to the site service,
// the service's instructions into goals for the crane's planner, and the crane's state into its
// reports. A core with no clock, no DDS and no threads: the site_link process (one per crane, on
// the crane's host) and the tests drive it the same way; the other side of the protocol is
// site_service.hpp.
//
// A job is two legs (to the pick, to the place), and a leg is: hoist up to the travel height,
// travel (slew and trolley), lower to the work height, hold `dwell` (hooking or unhooking), hoist
// up. The crane asks for the whole leg (its report's request, from where it rests; its travel with
// waypoints on its way, evenly spaced on the line of joint space, at most the site file's
// travel_step apart, as many as MAX_WAYPOINTS holds) and starts it only when the service's go for
// that request arrives; a yield it obeys at once (hook up, through the waypoints it is given; it
// asks again afterwards). A go names the stops (airspace.hpp's stops_of) of the leg or of its
// first waypoints only (the service's part of a leg, site_arbiter.hpp; it may end on the travel's
// way): the crane moves to the last of them, and there, at rest (after the dwell, if that is the
// work height), asks for the rest of the leg from that waypoint; a crane that halts or yields
// before asks for the whole leg again. It moves stop by stop: the goal to the next waypoint (COMMAND_MOVE, every axis
// named, the trapezoid profile) once the reference of the goal before has arrived and the crane
// has settled (trolley and slew under 0.01 m/s and rad/s, hoist under 0.01 m/s, swing amplitude
// under 0.5 deg) or `settle_timeout` after the reference arrived. A goal the planner has not
// answered (move_status(): its MoveStatus_) is sent again every kGoalResendPeriod.
//
// A move its planner ends short (MoveStatus_ RESULT_ABORTED: the supervisor's soft stop for swing,
// a speed or zone limit approached, its site guard; or RESULT_REJECTED) leaves the crane inside its
// grant, short of its waypoint. Once the crane is at rest and settled (or settle_timeout after it
// came to rest), and no sooner than kGoalResendPeriod after the abort, the move to that waypoint is
// sent again as a new goal; after kMoveAttempts ended short at one waypoint the link gives up: the
// crane rests where it stopped (phase aborted), reports its rest pose (the service frees the rest
// of its path) and asks for nothing more, an operator's matter (aborted_moves() counts them); it
// still obeys a yield, and rests again where that ends. A move ended because the drives were
// braked under way (REASON_BRAKED: a stalled command chain, not a refusal of the move) is sent
// again the same way but is not an attempt: the link never gives up on a crane that only stalls.
//
// Its report (report()) is its whole state: at rest at its pose, or moving with the rest of its
// path from the last waypoint it reached, or, every kProgressStep of an axis's travel, from the
// point of the segment it has passed on each axis (grant_guard.hpp; its guard holds the same);
// the last instruction it carried out (the epoch and seq of the go or yield it started); the leg
// it asks for while it waits at rest. A crane braked by its supervisor (a latched fault) stops
// reporting and asking, for good: the service then holds its whole reach, as for a crane that went
// silent.
//
// The link: the crane hears the service (heard(): its heartbeat, any instruction) and keeps its
// own GrantGuard (grant_guard.hpp) on what it was granted. When nothing was heard for the site's
// link_deadline, the service holds this crane's whole reach; on its own, the crane then
//   - moving on a path in shared airspace (the guard's rule 4): stops. A soft stop (the planner's
//     COMMAND_STOP) of every axis; or, when that would run out of the grant (a fast trolley near
//     its goal: the shaped stop runs past it), of the axes whose stop stays inside, the others
//     going on to the move's waypoint (COMMAND_STOP naming the axes it stops,
//     GrantGuard::soft_stop_axes, which takes an axis whose reference rests as ending there:
//     reference_rest_of); or, when no such choice stays inside, the move under way ends at its
//     waypoint. No further move starts; then it waits at rest;
//   - moving on a path outside shared airspace: finishes it, then waits at rest;
//   - at rest: waits.
// When the service is heard again, a crane waiting at rest reports where it rests and asks again
// for the leg it was on. Before it first hears the service, a crane waits at rest: it asks for
// nothing (that is no loss: reactions() counts none).
//
// Errors: the constructor throws std::out_of_range for a crane index not on the site and
// std::invalid_argument for a job outside the site file's ranges of the crane (slew, trolley, cable
// length from its hook range) or non-positive dwell, settle timeout, slew acceleration, gravity or
// travel cable length, or a rated speed or acceleration (params.rated) that is not > 0.
// instruction() ignores an instruction to another crane, one of an epoch and
// seq already taken, one of fewer than 2 waypoints, and a go that names no part's stops of the
// request it answers (returns false); step() never throws.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/grant_guard.hpp"
#include "crane/anti_collision/site_layout.hpp"
#include "crane/anti_collision/site_service.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/trajectory_planner/speed_reference.hpp"

namespace crane::anti_collision {

/// A place a crane lifts from or sets down at, in its own coordinates.
struct WorkPoint {
  double slew{0.0};          // [rad]
  double trolley{0.5};       // [m]
  double cable_length{1.5};  // [m] at the work height
};

struct SiteJob {
  WorkPoint pick;
  WorkPoint place;
};

struct CraneLinkParams {
  double travel_cable_length{0.2};  // [m] the cable's length while travelling, hook up (the planner's shortest)
  double dwell{1.0};                // [s] at the pick and at the place
  double settle_timeout{8.0};       // [s] after the reference arrived
  double slew_acceleration{1.0};    // [rad/s^2] of every move (MoveRequest::slew_max_acceleration)
  double slew_speed{0.0};           // [rad/s] of every move (MoveRequest::slew_max_velocity); 0: the crane's rated
  double gravity{9.81};             // [m/s^2] (the swing amplitude of the settle test)
  /// The speeds and accelerations its planner moves the trolley and the hoist at (a goal names none
  /// of theirs: the crane config's trajectory_planner.manual), and the slew's rated speed (for
  /// slew_speed 0): its work-left estimate (moves_time). Each > 0.
  trajectory_planner::ManualParams rated{};
};

/// [s] A move's settling, in the work-left estimate (moves_time): a round figure, for an estimate
/// that ranks cranes (site_arbiter.hpp's rule 0), not one that schedules them.
inline constexpr double kSettleAllowance = 1.0;

/// [s] The time a crane takes, alone, through `poses` (the first where it stands), by the estimate
/// of docs/site.md ("The crane with the most work left first"): it stops where stops_of says; each
/// move lasts the longest of its axes' trapezoid profiles ((3.43) of Omar 2003: the trolley and the
/// hoist at `params.rated`, the slew at params.slew_speed, or rated, and params.slew_acceleration),
/// a travel (the slew or the trolley moves) one swing period 2 pi sqrt(L / g) longer (its shaping
/// and damping, at L = params.travel_cable_length), and kSettleAllowance more. 0 for fewer than two
/// poses. No dwell: the caller adds it. std::invalid_argument for a non-finite pose or a rate, a
/// cable length or gravity that is not > 0.
[[nodiscard]] double moves_time(std::span<const Pose> poses, const CraneLinkParams& params);

/// [s] a goal the planner has not taken is sent again after this long.
inline constexpr double kGoalResendPeriod = 1.0;
/// Moves to one waypoint its planner may end short (aborted, rejected) before the link gives up.
inline constexpr int kMoveAttempts = 3;

/// True when the crane, as its supervisor's `status` says, may start working on the site: every
/// stage alive, the brakes released, no latched fault, mode ready or operating, and its
/// supervisor's guard hears the site service (no WARNING_SITE_UNHEARD). The last: the guard hears
/// the service's instructions on a participant of its own; a link that started before that
/// participant had found the service could take a grant the guard never heard, and the guard then
/// brakes the crane's first move as a move without a grant (session 35, a host round's start:
/// docs/site.md, "Each crane's site link"). The site_link process reports nothing before (the
/// service holds the crane's whole reach).
[[nodiscard]] bool ready_for_site(const protocol::SupervisorStatus& status) noexcept;

class CraneSiteLink {
 public:
  enum class Phase : std::uint8_t {
    resting,   // at rest, about to ask (or to finish: no legs left)
    asking,    // at rest, its request reported, waiting for the go
    moving,    // on a granted path or a yield
    dwelling,  // at the work height, hooking or unhooking
    halting,   // stopping, the link lost (its path in shared airspace)
    halted,    // at rest, waiting for the link
    done,      // every job done, at rest (it may still be told to yield)
    braked,    // its supervisor latched a fault: silent for good
    aborted,   // its planner ended kMoveAttempts moves to one waypoint short: at rest, asks for nothing more
  };

  /// What the crane is doing, as the site's waits are counted by it (docs/site.md, "Where the
  /// waits go"): at rest (resting, asking, halted, done, aborted, braked); on a leg, travelling (the
  /// segment under way moves the slew or the trolley), lowering or raising (the hoist alone), each
  /// until the crane has settled at the segment's end; dwelling at the work height; yielding (a
  /// yield, or a move it was told to make without asking); stopping (halting, the link lost).
  enum class Activity : std::uint8_t { at_rest, travelling, lowering, dwelling, raising, yielding, stopping };
  static constexpr std::size_t kActivityCount = 7;

  /// Crane `crane` of `layout` (copied) with its `jobs`, in order. Its goals to the planner get
  /// request ids from `first_goal_id` up (the planner takes only ids above the last it took).
  /// Throws as the header says.
  CraneSiteLink(const SiteLayout& layout, std::size_t crane, const CraneLinkParams& params, std::vector<SiteJob> jobs,
                std::uint32_t first_goal_id);

  /// Any message from the site service heard at `time` [s] (its status heartbeat, an instruction
  /// to any crane): the link is alive.
  void heard(double time) noexcept;
  /// An instruction of the service of `epoch` heard at `time` [s]. Taken (true) when it is to this
  /// crane, newer than the last taken (another epoch, or a higher seq), and the crane can carry it
  /// out: a go for the request it waits with, or a yield while it waits at rest, is done or gave up. Else
  /// ignored (false; an instruction sent again, one to another crane, a go for an old request).
  bool instruction(const SiteOrder& order, std::uint32_t epoch, double time);
  /// The planner's feedback on a goal (rt/crane/planner/move_status): any answer to the last goal
  /// means it is not sent again; RESULT_ABORTED or RESULT_REJECTED of the move under way means it
  /// ended short (see the header). Feedback on any other goal is ignored.
  void move_status(const protocol::MoveStatus& status, double time) noexcept;

  /// One cycle at `time` [s]: the crane's estimate, its planner's reference, and whether its
  /// supervisor has a latched fault. Returns the goal to send the planner now, if any (a move to
  /// the next waypoint, a soft stop, or a goal sent again).
  [[nodiscard]] std::optional<protocol::MoveRequest> step(double time, const protocol::CraneState& estimate,
                                                          const protocol::Reference& reference, bool braked);

  /// The report to send now; none once braked (see the header) or before the first step.
  [[nodiscard]] std::optional<CraneReport> report() const;
  /// [s] Its estimate of the time its jobs left take it alone (its reports carry it: the site
  /// service's rule 0 ranks the crane with the most first): moves_time of the rest of the leg it is
  /// on (from where it stands, or from its yield's end: a crane halted or yielding asks for the whole
  /// leg again) and of each leg after, plus the dwell of each work point still ahead. 0 when done,
  /// braked or given up. As of the last step() that changed what the crane does (its phase, request,
  /// waypoint, the point it has passed, its leg); a rest of the leg with a non-finite pose (a NaN
  /// estimate) keeps the estimate before. noexcept: read every cycle.
  [[nodiscard]] double work_left() const noexcept { return work_left_; }
  /// True when the report changed since the last call (send it now, not only at the period).
  [[nodiscard]] bool report_changed() noexcept;

  [[nodiscard]] Phase phase() const noexcept { return phase_; }
  /// What it is doing now (Activity). noexcept.
  [[nodiscard]] Activity activity() const noexcept;
  [[nodiscard]] std::size_t crane() const noexcept { return crane_; }
  [[nodiscard]] int jobs_done() const noexcept { return jobs_done_; }
  [[nodiscard]] std::size_t jobs() const noexcept { return legs_.size() / 2; }
  [[nodiscard]] double finish_time() const noexcept { return finish_time_; }    // [s] its last job done
  [[nodiscard]] double waiting_time() const noexcept { return waiting_time_; }  // [s] asking, summed
  [[nodiscard]] int yields() const noexcept { return yields_; }
  [[nodiscard]] int unsettled_moves() const noexcept { return unsettled_moves_; }
  [[nodiscard]] int halts() const noexcept { return halts_; }
  [[nodiscard]] int halts_at_waypoint() const noexcept { return halts_at_waypoint_; }
  /// Of halts(), the stops of some axes only, the others going on to the move's waypoint.
  [[nodiscard]] int halts_per_axis() const noexcept { return halts_per_axis_; }
  /// Moves its planner ended short (aborted or rejected), each sent again or, the last, given up.
  [[nodiscard]] int aborted_moves() const noexcept { return aborted_moves_; }
  /// [s] from each link loss that lasted link_deadline to the crane safe: at rest after its stop,
  /// or still on a path outside shared airspace, or at rest already.
  [[nodiscard]] const std::vector<double>& reactions() const noexcept { return reactions_; }
  /// How the crane was safe after a link loss.
  enum class ReactionEnd : std::uint8_t {
    outside_shared,   // still on a path outside shared airspace
    at_rest_already,  // it was not moving
    soft_stop,        // at rest after its soft stop
    at_waypoint,      // at rest at the waypoint its move went on to (a soft stop would have left the grant)
    per_axis,         // at rest after a stop of some axes, the others gone on to the waypoint (soft_stop_axes)
  };
  struct Reaction {
    double lost_at{0.0};  // [s] the link's last message (the loss counted link_deadline later)
    double seconds{0.0};  // [s] from then to the crane safe
    ReactionEnd end{ReactionEnd::at_rest_already};
  };
  /// The longest of reactions() and how it ended (none: no loss yet).
  [[nodiscard]] const std::optional<Reaction>& longest_reaction() const noexcept { return longest_reaction_; }
  [[nodiscard]] const GrantGuard& guard() const noexcept { return guard_; }
  /// The path it moves on (its first waypoint where it started) and the waypoint it moves to.
  [[nodiscard]] const std::vector<Pose>& path() const noexcept { return path_; }
  [[nodiscard]] std::size_t waypoint() const noexcept { return waypoint_; }
  [[nodiscard]] bool yielding() const noexcept { return yielding_; }

  /// The crane is told to move to `to` without asking (a test of its guard: a crane that
  /// disobeys). Returns the goal.
  [[nodiscard]] protocol::MoveRequest disobey(const Pose& to, const Pose& here);

 private:
  struct Leg {
    WorkPoint at;
    bool place{false};  // the job's second leg: the job is done when it ends
  };
  std::optional<protocol::MoveRequest> advance(double time, const protocol::CraneState& estimate,
                                               const protocol::Reference& reference, bool braked);
  protocol::MoveRequest move_to(const Pose& to);
  /// Leg `leg` from `here`: hoist up to the travel height (unless there), travel with waypoints on
  /// its way (the site file's travel_step), lower to the work point, hoist up. What it asks for.
  [[nodiscard]] std::vector<Pose> leg_path(const Pose& here, std::size_t leg) const;
  /// work_left_ from the crane's state now, when that changed since the last (step()).
  void refresh_work_left();
  /// What it holds of its path: from the last waypoint it reached, or from the point of the segment
  /// under way it has reported passing (passed_, when it is not the segment's start), to the end.
  [[nodiscard]] std::vector<Pose> rest_of_path() const;
  void rest_at(const Pose& here, double time);
  /// At the end of the part of its leg it was granted: it asks for the
  /// rest of the leg from that waypoint (not its measured pose, a hair off it).
  void ask_rest_of_leg(double time);

  SiteLayout layout_;
  std::size_t crane_;
  CraneLinkParams params_;
  GrantGuard guard_;
  std::vector<Leg> legs_;
  std::vector<double> legs_after_;   // [s] legs_after_[k]: moves_time and dwells of the legs after leg k
  double work_left_{0.0};            // [s] work_left()
  static constexpr std::size_t kWorkStateSize = 11;
  std::array<double, kWorkStateSize> work_state_{};  // what work_left_ was computed from (refresh_work_left):
                                                     // NaN until the first step (NaN equals nothing)
  std::size_t next_leg_{0};
  Phase phase_{Phase::resting};
  std::uint32_t goal_id_;            // the last goal's request id
  double goal_sent_{0.0};            // [s] when it was last sent
  bool goal_taken_{true};            // the planner answered it
  std::optional<protocol::MoveRequest> goal_;  // the last goal
  bool link_lost_{true};             // nothing heard yet counts as lost (no loss to react to)
  double lost_from_{0.0};            // [s] the last message heard before the loss
  std::vector<Pose> path_;           // the granted path or yield, path_[0] where it started
  std::size_t waypoint_{0};          // the waypoint being moved to
  Pose passed_{};                    // the point of the segment to waypoint_ reported passed (passed_point)
  bool yielding_{false};
  bool gave_up_{false};              // phase aborted, or a yield from it
  bool start_next_{false};           // the move to waypoint_ + 1 starts at the next step
  std::optional<double> arrived_at_; // [s] the reference arrived
  std::optional<double> ended_short_at_;  // [s] the planner ended the move under way short
  bool ended_braked_{false};              // ... because the drives were braked (not an attempt)
  std::optional<double> stopped_at_;      // [s] the crane came to rest after that
  int attempts_{0};                  // moves to waypoint_ ended short
  double dwell_until_{0.0};
  double asked_at_{0.0};
  std::uint32_t request_id_{0};      // the leg asked for (0: none)
  std::uint32_t requests_{0};        // requests made
  bool stepped_{false};
  CraneMotion motion_{};  // measured, at its last step (its reports carry it)
  std::vector<Pose> request_;
  std::vector<Pose> rest_of_leg_;    // granted a part of its leg: the rest, from
                                     // path_.back(); empty: the whole leg was granted
  Pose pose_{};                      // the measured pose (the last step's)
  std::uint32_t carried_epoch_{0};
  std::uint64_t carried_seq_{0};
  bool changed_{true};
  int jobs_done_{0};
  double finish_time_{0.0};
  double waiting_time_{0.0};
  int yields_{0};
  int unsettled_moves_{0};
  int halts_{0};
  int halts_at_waypoint_{0};
  int halts_per_axis_{0};
  int aborted_moves_{0};
  std::vector<double> reactions_;
  std::optional<Reaction> longest_reaction_;
  double halt_from_{0.0};
  bool halt_at_waypoint_{false};  // the halt under way ends the move at its waypoint
  bool halt_per_axis_{false};     // the halt under way stops some axes, the others go on to the waypoint

  void record_reaction(double lost_at, double time, ReactionEnd end);
};

/// [-] "resting", "asking", ...
[[nodiscard]] const char* to_string(CraneSiteLink::Phase phase) noexcept;
/// [-] "still on a path outside shared airspace", ...
[[nodiscard]] const char* to_string(CraneSiteLink::ReactionEnd end) noexcept;

/// The estimator's state as the site's geometry takes it.
[[nodiscard]] CraneMotion motion_of(const protocol::CraneState& estimate) noexcept;
/// Where the planner's reference rests on each axis (GrantGuard::soft_stop_stays_in_grant):
/// the reference's slew, trolley and cable length, each set when its speed and acceleration are
/// within kReferenceAtRest of zero.
[[nodiscard]] ReferenceRest reference_rest_of(const protocol::Reference& reference) noexcept;

/// Where crane `crane` of `layout` waits when a site starts: its jib turned away from the site's
/// centre (the mean of the bases; slew 0 for a site of one crane) within its slew range and
/// [slew_min + 0.1, slew_max - 0.1] of the planner's (`planner_slew_min`, `planner_slew_max`
/// [rad]), its trolley at `trolley` [m]. std::out_of_range for a crane index not on the site.
[[nodiscard]] Pose site_start_pose(const SiteLayout& layout, std::size_t crane, double planner_slew_min,
                                   double planner_slew_max, double trolley);

/// "at rest", "travelling", "lowering", "dwelling", "raising", "yielding", "stopping".
[[nodiscard]] const char* to_string(CraneSiteLink::Activity activity) noexcept;

}  // namespace crane::anti_collision
