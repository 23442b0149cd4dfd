#pragma once
// The site service's rules (issue 34, item 3; docs/site.md, "Grants"): which crane may use which
// airspace next. A core with no clock of its own (request() and decide() are given their time),
// no DDS and no threads: the site service process, the lockstep site simulation and the tests
// drive it the same way.
//
// Each crane holds an airspace at all times: at rest, the box of its pose (rest); moving, the
// path it was granted (airspace.hpp); when it stops reporting, its whole reach (lost), until an
// operator confirms it braked where it stood (out_of_service: what it held then). A crane at
// rest asks for the path of its next leg (request). decide() grants a request when the path keeps
// at least margins.slow_down from every other crane's held airspace, so that a granted crane never
// meets another crane's slow-down margin while it keeps to its path (the site's warning and
// slow-down layer, crane_geometry.hpp's classify, is for cranes that leave their paths).
//
// Who goes first, when requests compete (the rules of real sites, in this order):
//   0. no starving: a request that has waited `max_wait` of the site file (when it is not 0) goes
//      before every other, the oldest first, and it reserves its path: a later-ranked request that
//      could go but meets it waits for it (in waits_for, and so in the rules against deadlock
//      below), unless it waits for a crane that may never move: silent, out of service, or, in
//      turn, at rest with a request that waits for such a crane (the reservation would stop the
//      others for nothing). A starving request gives its jib way to no cable (rule 2).
//      The same for the request of the crane with the most work left (the site file's
//      most_work_left_first; docs/site.md, "The crane with the most work left first"): the crane at
//      rest with a pending request whose reported work left (work_left()) is more than every other
//      crane's that reports (silent and out-of-service cranes are not counted; a tie: none). The
//      crane that finishes last decides when the site is done, so its legs go first. It ranks with
//      the starving requests, by its request's time;
//   1. the higher `priority` of the site file;
//   2. the lower crane yields its jib to the higher crane's cable: when the closest parts of two
//      pending paths are the lower crane's jib or counter-jib and the higher crane's cable or load,
//      the higher crane goes first;
//   3. first come: the earlier request;
//   4. the crane listed first in the site file.
// No deadlock: a crane waits for the cranes whose held airspace its path meets (waits_for). A
// crane at rest that blocks another and has nothing to do, or two or more cranes at rest that wait
// for each other in a cycle, would wait forever; the one of them that ranks last by the rules
// above is told to yield: it goes, hook up, to the nearest pose (its current slew and trolley
// first, then the trolley in and the slew turned by kYieldSlewStep, 2 kYieldSlewStep, ...) whose
// rest airspace keeps clear of the paths that wait for it and whose path there meets nothing held.
// A crane reports each waypoint it reaches (progress) and holds only the rest of its path.
//
// A part of a leg (the site file's part_of_leg; docs/site.md, "A part of a leg"): a request that
// waits only for cranes at rest or moving on a path is granted up to a waypoint where it can wait
// for them: the last, not its first, up to which the part's stops (airspace.hpp's stops_of) and
// its rest box there keep clear of what every other crane holds and, for a crane it waits for
// moving, of the rest box at that crane's path's end (the request's waypoints on its travel's way
// included: docs/site.md, "A wait inside the travel"). It then holds that part only, and asks
// there for the rest of its leg as a new request. It waits whole for a crane yielding, silent or
// out of service. Every go names the stops of what it grants, and the crane holds their airspace.
//
// The serialized mode is the baseline of issue 34's demo: also, at most one crane at a time
// travels in shared airspace (the part of its reach that another crane's whole reach meets within
// margins.slow_down).

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

enum class ArbiterMode : std::uint8_t { coordinated, serialized };

/// True when `airspace` of crane `crane` meets another crane's whole reach within
/// margins.slow_down: shared airspace, which a crane without a live link to the site service must
/// not move in (issue 34, item 4). std::out_of_range for a crane index not on the site.
[[nodiscard]] bool in_shared_airspace(const SiteLayout& layout, std::size_t crane, const Airspace& airspace);

/// What decide() tells a crane.
struct Instruction {
  enum class Kind : std::uint8_t { go, yield };
  std::size_t crane{0};
  Kind kind{Kind::go};
  std::vector<Pose> waypoints;  // go: the path requested; yield: where the crane is, then its yield pose
};

enum class Holding : std::uint8_t { rest, path, yield, whole_reach, out_of_service };
/// "rest", "path", "yield", "whole_reach", "out_of_service".
[[nodiscard]] const char* to_string(Holding holding) noexcept;

/// Why a pending request waits for the cranes of waits_for (the rules of the header): none (it
/// does not wait, or it is not decided yet); held: its path meets what they hold (serialized: or
/// they travel in shared airspace); starving: rule 0, it meets the path a starving request of
/// theirs reserves; higher_cable: rule 2, it gives its jib way to a higher crane's cable;
/// most_work_left: rule 0, it meets the path the request of the crane with the most work left
/// reserves.
enum class WaitReason : std::uint8_t { none, held, starving, higher_cable, most_work_left };
inline constexpr std::size_t kWaitReasonCount = 5;
/// "none", "held", "starving", "higher_cable", "most_work_left".
[[nodiscard]] const char* to_string(WaitReason reason) noexcept;

class SiteArbiter {
 public:
  static constexpr double kYieldSlewStep = 0.5236;  // [rad] (30 deg)

  /// Every crane starts lost (holding its whole reach) until its first rest(). Throws
  /// common::ConfigError when the layout is invalid (validate()).
  SiteArbiter(SiteLayout layout, ArbiterMode mode);

  /// Crane `crane` is at rest at `pose`: it holds the pose's box (ending a path or a yield, or
  /// coming back after being lost). std::out_of_range for a crane index not on the site.
  void rest(std::size_t crane, const Pose& pose);
  /// Crane `crane` asks for the path through `waypoints` (the first where it is) at `time` [s]; a
  /// new request replaces its pending one. std::invalid_argument for no waypoint, more than
  /// Airspace::kMaxBoxes + 1, a non-finite field or a cable length <= 0.
  void request(std::size_t crane, std::vector<Pose> waypoints, double time);
  /// Crane `crane`, moving on its path or yield, has reached a waypoint: it holds the rest of the
  /// path from there (`remaining`, its first waypoint where the crane is), and what it left behind
  /// is free for the others. std::logic_error when the crane holds no path or yield;
  /// std::invalid_argument as request() for bad waypoints.
  void progress(std::size_t crane, const std::vector<Pose>& remaining);
  /// Crane `crane` withdraws its pending request (nothing left to do).
  void withdraw(std::size_t crane);
  /// Crane `crane` reports `seconds` [s] of work left (its jobs' time alone, by its own estimate:
  /// CraneSiteLink::work_left), for rule 0's crane with the most work left. Every crane starts at 0.
  /// std::invalid_argument for a negative or non-finite value; std::out_of_range for a crane index
  /// not on the site.
  void work_left(std::size_t crane, double seconds);
  /// The crane whose request rule 0 ranks first for the most work left (the header), as the cranes
  /// stand now; none when the site file's most_work_left_first is off, no crane reports more work
  /// left than every other, or that crane is not at rest with a request pending.
  [[nodiscard]] std::optional<std::size_t> most_work_left() const;
  /// Crane `crane` stopped reporting (`moved` false), or moved without a grant (`moved` true): it
  /// holds its whole reach until its next rest() (or out_of_service(), when it went silent from a
  /// rest or a path; a crane that moved without a grant, out of service or not, cannot be put out
  /// of service before it rests: where it stood says nothing any more).
  void lost(std::size_t crane, bool moved = false);
  /// An operator confirms that crane `crane`, silent (lost), stands braked where it was when it went
  /// silent (its host stopped, say): until its next rest() it holds what it held then, with the
  /// swing of its load braked from `last`, its last reported motion, up to `report_age` [s] old
  /// (out_of_service_airspace), instead of its whole reach. Its pending request is dropped.
  /// std::logic_error, naming the crane, when it is not lost, or when this arbiter does not know
  /// where it stood (never at rest or on a path here and not recalled: a restarted service with no
  /// memory of it; or it moved without a grant);
  /// std::invalid_argument for a non-finite `last` or a negative `report_age`; std::out_of_range
  /// for a crane index not on the site.
  /// With `last` none, the motion is not known (a crane a restarted service recalls on a path,
  /// recall(): it may have been moving at any speed its grant allows when it stopped): it holds what
  /// it held then as it was held, each box with its own swing allowance.
  void out_of_service(std::size_t crane, const std::optional<CraneMotion>& last, double report_age);

  /// Where crane `crane` stands for this arbiter: what it holds at rest, on a path or a yield, or
  /// what it held when it went silent (lost or out of service); none when it never knew (its whole
  /// reach since the start). `moving`: that place is a path or a yield, not a rest box.
  struct Place {
    Airspace airspace;
    bool moving{false};
  };
  [[nodiscard]] std::optional<Place> place(std::size_t crane) const;
  /// A restarted service's memory (site_memory.hpp): crane `crane`, never heard by this arbiter,
  /// stood in `place` when the service before it last knew (SiteService::recall). It still holds its
  /// whole reach; the place is what out_of_service() then holds. std::logic_error, naming the crane,
  /// when this arbiter already knows where it is (it rested or was lost here); std::invalid_argument
  /// for a place of no box, more than Airspace::kMaxBoxes, or a box with a non-finite field, a low end
  /// above its high end, a cable length <= 0 or a negative swing radius; std::out_of_range for a crane
  /// index not on the site.
  void recall(std::size_t crane, const Place& place);

  /// Grants and yields at `time` [s] (the clock of request()), by the rules of the header; each
  /// crane at most one instruction. The instructed cranes hold the path or the yield from now on.
  /// std::invalid_argument for a non-finite time. A request that starts starving (rule 0) grants
  /// nothing by itself (what could go was granted at the decision before; it only reorders and
  /// holds back): the caller decides again only when what the cranes hold or ask changed.
  [[nodiscard]] std::vector<Instruction> decide(double time);

  [[nodiscard]] std::size_t size() const noexcept { return cranes_.size(); }
  [[nodiscard]] Holding holding(std::size_t crane) const { return cranes_.at(crane).holding; }
  [[nodiscard]] const Airspace& held(std::size_t crane) const { return cranes_.at(crane).held; }
  [[nodiscard]] bool pending(std::size_t crane) const { return cranes_.at(crane).request.has_value(); }
  /// The cranes whose held airspace the pending request meets, or whose starving request it meets
  /// (rule 0), as of the last decide().
  [[nodiscard]] const std::vector<std::size_t>& waits_for(std::size_t crane) const { return cranes_.at(crane).waits_for; }
  /// Why, as of the last decide(): none when waits_for is empty.
  [[nodiscard]] WaitReason wait_reason(std::size_t crane) const { return cranes_.at(crane).wait_reason; }
  /// The time [s] (request()'s clock) of crane `crane`'s pending request; none when none is pending.
  [[nodiscard]] std::optional<double> requested_at(std::size_t crane) const {
    const auto& r = cranes_.at(crane).request;
    return r ? std::optional<double>(r->time) : std::nullopt;
  }
  /// Yields told so far, and the times decide() found a blocked crane no yield could free.
  [[nodiscard]] std::uint64_t yields() const noexcept { return yields_; }
  [[nodiscard]] std::uint64_t unresolved() const noexcept { return unresolved_; }
  [[nodiscard]] const SiteLayout& layout() const noexcept { return layout_; }

  /// True when `a` of crane i and `b` of crane j keep margins.slow_down.
  [[nodiscard]] bool clear(std::size_t i, const Airspace& a, std::size_t j, const Airspace& b) const noexcept;

 private:
  struct Request {
    std::vector<Pose> waypoints;
    Airspace airspace;
    double time{0.0};
    bool shared{false};  // serialized mode: meets another crane's reach
  };
  struct CraneState {
    Holding holding{Holding::whole_reach};
    Airspace held;
    std::optional<Airspace> held_when_lost;  // what it held when it went silent (none: unknown)
    bool lost_moving{false};                 // held_when_lost is a path or a yield
    Pose pose;            // at rest: where; else the last rest pose
    bool held_shared{false};
    std::optional<Request> request;
    std::vector<std::size_t> waits_for;
    WaitReason wait_reason{WaitReason::none};
    std::optional<Pose> path_end;     // holding a path: where it ends (its rest box there)
    double work_left{0.0};            // [s] as it last reported
  };

  [[nodiscard]] bool starving(std::size_t i) const noexcept;  // rule 0, at decided_at_
  [[nodiscard]] bool first(std::size_t i) const noexcept;     // rule 0: starving, or critical_
  [[nodiscard]] bool ranks_before(std::size_t i, std::size_t j) const;  // rules 0, 1, 3, 4
  [[nodiscard]] bool yields_jib_to(std::size_t i, std::size_t j) const;  // rule 2: i's request gives way to j's
  [[nodiscard]] bool shared(std::size_t i, const Airspace& a) const;
  [[nodiscard]] std::optional<std::vector<Pose>> yield_path(std::size_t victim, const std::vector<std::size_t>& waiting) const;
  /// A part of a leg (the header): how many of i's request's waypoints are granted now while it
  /// waits for the cranes `waits` (2 or more), or 0 when it waits whole.
  [[nodiscard]] std::size_t part_of_leg(std::size_t i, const std::vector<std::size_t>& waits) const;

  SiteLayout layout_;
  ArbiterMode mode_;
  std::vector<CraneState> cranes_;
  std::uint64_t yields_{0};
  std::uint64_t unresolved_{0};
  double decided_at_{-std::numeric_limits<double>::infinity()};  // [s] the last decide()'s time
  std::optional<std::size_t> critical_;  // most_work_left() as the last decide() began
};

}  // namespace crane::anti_collision
