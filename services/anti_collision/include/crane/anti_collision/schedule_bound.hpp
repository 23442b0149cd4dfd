#pragma once
// How fast two cranes could do their jobs on one site at best, under the site's own rules
// (issue 34's throughput figure; docs/site.md, "How far from the best order"): a lower bound of
// any order of grants, against which the site service's order is measured. Below it, the other
// end for every crane of a site at once: the best schedule a search finds (search_site_schedule).
//
// Each crane's work is taken as it ran alone (its Timeline: the intervals of its solo run, each
// with the airspace it used, the box of a path segment or of its rest), and the two are laid out
// on one plane, the first crane's progress along x, the second's along y (Akers' geometric method
// for two jobs: S. B. Akers, "A graphical approach to production scheduling problems", Operations
// Research 4, 1956; P. Brucker, "Scheduling Algorithms", 5th ed., section 6.4.2). A schedule is a
// monotone path from (0, 0) to (T_a, T_b): diagonally both cranes progress, along x only the first
// (the second waits), along y only the second; its length is the site's time. Forbidden is the
// interior of every cell (interval k of a, interval l of b) whose airspaces do not keep
// margins.slow_down (SiteArbiter::clear's rule: such grants are never held together); its edges are
// open (a crane waits at the end of an interval holding nothing). The shortest path is searched
// over the lattice of whole cycles, on which every interval ends (the lockstep's 10 ms): exact for
// the cycle-stepped site, T_a x T_b cells (about 0.3 s for two cranes' 90 s). Akers' shortcut, the
// diagonal until a forbidden cell and then around it, is not exact on these planes, whose forbidden
// cells touch (an edge between two of them is open): on seeded random planes it came out longer
// than the lattice (the first: 15 cycles against 14; session 31), so it is not used.
//
// What it leaves out makes it lower than any real schedule, so it is a bound: a crane that has done
// its jobs stands nowhere (a real one must be told to yield); the third crane of a site is not
// there (the site's bound is the largest of its pairs'); a crane's intervals hold what its own
// reports say while it is in them (the rest of its leg from the point it has passed is held, the
// interval's part of it counted); each interval lasts as long as alone (a run's settling varies
// by a few seconds). Where a crane waits (WaitRule): anywhere, holding only the interval it is in
// and at an interval's end nothing, the bound of any order and any cut of the legs into grants;
// or only at rest between legs, holding its rest box, the bound of the site's protocol, which
// grants a leg whole. It is the bound of the rules' geometry (the grants' boxes, margins and
// allowances), not of the cranes' physics.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/site_layout.hpp"

namespace crane::anti_collision {

/// One interval of a crane's work: from the end of the one before (from cycle 0 for the first) to
/// `end_cycle`, it uses `uses` (a path segment's box, or its rest box).
struct TimelineStep {
  std::int64_t end_cycle{0};  // [cycles] > the step before's
  Airspace uses;
  bool rest{false};  // at rest between legs (WaitRule::at_rest: where it may wait)
};

/// Where a crane may wait for the other.
enum class WaitRule : std::uint8_t {
  anywhere,  // inside any interval, holding it; at an interval's end, holding nothing
  at_rest,   // only in its rest intervals, holding them: the site's protocol, which grants a leg whole
};

/// A crane's work, interval by interval, as it ran alone.
struct Timeline {
  std::vector<TimelineStep> steps;
  [[nodiscard]] std::int64_t cycles() const noexcept { return steps.empty() ? 0 : steps.back().end_cycle; }
};

/// The shortest time [cycles] in which crane `first` doing `a` and crane `second` doing `b` can both
/// be done under the header's rules, each waiting as `rule` says: at least max(a.cycles(),
/// b.cycles()); with WaitRule::anywhere at most their sum (one after the other is a path). -1 when
/// no path exists (WaitRule::at_rest: each stands in the other's way where it may wait, which the
/// site resolves by a yield, not modelled). std::invalid_argument for a crane index not on
/// `layout`, the same crane twice, or a step that does not end after the one before.
[[nodiscard]] std::int64_t two_crane_bound(const SiteLayout& layout, std::size_t first, const Timeline& a,
                                           std::size_t second, const Timeline& b,
                                           WaitRule rule = WaitRule::anywhere);

/// What a crane holds while it moves, in search_site_schedule.
enum class HoldRule : std::uint8_t {
  timed,  // each interval while it is in it: a leg may start while its path still meets another's, as
          // long as the two are never there in the same cycle (the bound's model; a service would need
          // each leg's timing)
  path,   // the site service's rule (SiteArbiter::decide): a crane leaves its rest only when its whole
          // leg and the rest box at its end meet nothing another crane holds then, at rest its box,
          // moving the rest of its leg (each interval not yet over) and the rest box at its end
  behind, // HoldRule::path, and a crane may also leave behind one that left on a clear path and has not
          // arrived: its leg may meet what that one still holds of its leg (not the rest box at that
          // one's end, nor with its first interval or its own rest box at the end), and it enters each
          // interval only when the interval meets nothing held then, waiting before it where it is
          // (a stop in the middle of a leg, taken to cost no time). The service's rule of session 38
          // (it stopped at a waypoint and held the rest of its leg meanwhile), since replaced by its
          // part of a leg (SiteArbiter::part_of_leg), which also goes behind a crane that will rest
          // in its way and holds only the part granted
};

/// An order of every crane's whole legs at once, found by search: the other end of the bound of the
/// site's protocol (WaitRule::at_rest) on a site of more than two cranes, where two_crane_bound sees
/// one pair at a time and the exact search, a lattice of one axis per crane, is too large (three
/// cranes' 90 s: 10^12 points).
///
/// The model is two_crane_bound's at rest, for every crane at once: a crane runs each leg (the
/// intervals between two rest intervals) without a stop, holding each interval while it is in it;
/// it waits only inside a rest interval, holding its box; done, it holds nothing. No two cranes may
/// hold, in the same cycle, intervals whose airspaces do not keep margins.slow_down. A schedule is
/// the cycle each crane leaves each of its rest intervals.
///
/// The search is a serial schedule generation (R. Kolisch, "Serial and parallel resource-constrained
/// project scheduling methods revisited", EJOR 90, 1996): the departures are placed one at a time,
/// each at the earliest cycle at which the leg it starts, and the rest at its end, keep clear of
/// everything placed so far, the other cranes taken to stay at rest where they stand until their
/// own next departure is placed. The order of the departures is searched: earliest leg first,
/// then `tries` random orders (seeded by `seed`) biased towards it, each improved by swapping
/// neighbours. Under HoldRule::path and HoldRule::behind the site is replayed cycle by cycle instead, each crane asking
/// as soon as it has stood its rest interval's time and the requests that may go granted in an
/// order of random keys per leg (the first try: the crane listed first goes first), every other try
/// holding back a request whose leg meets a waiting request's ranked before it.
/// With `tries` 0 it takes only the first order, as a service that knew the legs' timing, or
/// followed its own rule, would grant them: the departures in the order of time, each as soon as
/// it may (timed, the soonest departure first places them in the order of time: placing one never
/// lets another leave sooner); under HoldRule::path and HoldRule::behind the first replay.
/// Every schedule it returns keeps the rule, so the site's best order of whole legs takes at most
/// `cycles`; the search is not exhaustive, so it may take less. It may find none where cranes can
/// only pass each other by leaving together (each leg meeting the other's rest box after it has
/// left): a departure is placed only when it keeps clear of the others standing where they are.
struct SiteSchedule {
  std::int64_t cycles{-1};  // [cycles] when the last crane is done; -1: no order found
  // Per crane, the cycle it leaves each of its rest intervals, in order (empty: it has none).
  std::vector<std::vector<std::int64_t>> departures;
  // Per crane, per interval of its timeline, the cycles [cycles] it waited inside its leg just before
  // entering that interval, in the one before it (HoldRule::behind; 0 under the other rules). With
  // the departures, where every crane is in every cycle.
  std::vector<std::vector<std::int64_t>> waits;
};

/// The best schedule found for crane k doing timelines[k], k = 0 .. layout.cranes.size() - 1.
/// std::invalid_argument when the timelines are not one per crane of `layout`, or a step does not
/// end after the one before.
[[nodiscard]] SiteSchedule search_site_schedule(const SiteLayout& layout, const std::vector<Timeline>& timelines,
                                                std::uint64_t seed, int tries = 200,
                                                HoldRule rule = HoldRule::timed);

namespace internal {
/// search_site_schedule on planes given directly: per crane its intervals' ends (ends[k][0] = 0,
/// rising) and whether each is at rest; forbidden(i, k, j, l) whether interval k of crane i and
/// interval l of crane j may not be held in one cycle (asked for i < j only).
[[nodiscard]] SiteSchedule search_site_schedule(
    const std::vector<std::vector<std::int64_t>>& ends, const std::vector<std::vector<char>>& rest,
    const std::function<bool(std::size_t, std::size_t, std::size_t, std::size_t)>& forbidden, std::uint64_t seed,
    int tries = 200, HoldRule rule = HoldRule::timed);

/// The same search on a plane given directly: the first crane's interval ends x (x[0] = 0, rising),
/// the second's y, and forbidden[k * (y.size() - 1) + l] for the cell of intervals k and l;
/// rest_x, rest_y empty for WaitRule::anywhere, else per interval whether it is a rest interval.
[[nodiscard]] std::int64_t two_crane_bound(const std::vector<std::int64_t>& x, const std::vector<std::int64_t>& y,
                                           const std::vector<char>& forbidden, const std::vector<char>& rest_x = {},
                                           const std::vector<char>& rest_y = {});
}  // namespace internal

}  // namespace crane::anti_collision
