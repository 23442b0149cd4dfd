// The lower bound of any order of grants for two cranes (schedule_bound.hpp, Akers' geometric
// method): cases worked by hand, the search against a lattice search over every cycle on seeded
// random planes, and the site's own geometry deciding which cells are forbidden.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

#include "crane/anti_collision/airspace.hpp"
#include "crane/anti_collision/schedule_bound.hpp"
#include "crane/anti_collision/site_layout.hpp"
#include "two_towers.hpp"

namespace {

using namespace crane::anti_collision;
namespace internal = crane::anti_collision::internal;

// The shortest monotone lattice path, one cycle a move: a diagonal move through a unit square inside
// a forbidden cell, or a move along x (y) through the inside of one, is not allowed; edges are.
std::int64_t lattice(const std::vector<std::int64_t>& x, const std::vector<std::int64_t>& y,
                     const std::vector<char>& forbidden) {
  const std::int64_t X = x.back(), Y = y.back();
  const std::size_t n = y.size() - 1;
  const auto interval = [](const std::vector<std::int64_t>& ends, std::int64_t t) {  // t .. t+1 lies in
    return static_cast<std::size_t>(std::upper_bound(ends.begin(), ends.end(), t) - ends.begin() - 1);
  };
  const auto inside = [](const std::vector<std::int64_t>& ends, std::int64_t t) {  // t strictly inside one
    return !std::binary_search(ends.begin(), ends.end(), t);
  };
  constexpr std::int64_t kFar = std::numeric_limits<std::int64_t>::max() / 2;
  std::vector<std::int64_t> d(static_cast<std::size_t>((X + 1) * (Y + 1)), kFar);
  const auto cost = [&](std::int64_t i, std::int64_t j) -> std::int64_t& {
    return d[static_cast<std::size_t>(i * (Y + 1) + j)];
  };
  const auto blocked = [&](std::int64_t i, std::int64_t j) {
    return forbidden[interval(x, i) * n + interval(y, j)] != 0;
  };
  cost(0, 0) = 0;
  for (std::int64_t i = 0; i <= X; ++i) {
    for (std::int64_t j = 0; j <= Y; ++j) {
      const std::int64_t here = cost(i, j);
      if (here >= kFar) continue;
      if (i < X && j < Y && !blocked(i, j)) cost(i + 1, j + 1) = std::min(cost(i + 1, j + 1), here + 1);
      if (i < X && !(j < Y && inside(y, j) && blocked(i, j))) cost(i + 1, j) = std::min(cost(i + 1, j), here + 1);
      if (j < Y && !(i < X && inside(x, i) && blocked(i, j))) cost(i, j + 1) = std::min(cost(i, j + 1), here + 1);
    }
  }
  return cost(X, Y);
}

TEST(ScheduleBound, HandWorkedPlanes) {
  // Nothing forbidden: both at once, the longer decides.
  EXPECT_EQ(internal::two_crane_bound({0, 100}, {0, 50}, {0}), 100);
  // Their one interval each meets: one after the other.
  EXPECT_EQ(internal::two_crane_bound({0, 100}, {0, 50}, {1}), 150);
  // a: 40 clear, then 60 meeting b's first 50; b: 50, then 30 clear. Best: a waits 10 at its
  // waypoint for b's first interval to end, then both go on: 40 + 10 + 60 = 110 (b done at 80).
  // The other order, b waiting for a's 60 from cycle 40, takes 100 + 40 = 140.
  EXPECT_EQ(internal::two_crane_bound({0, 40, 100}, {0, 50, 80}, {0, 0, 1, 0}), 110);
  // b's second interval meets a's first too: the same, since a's first is over (cycle 40) before
  // b's second begins (cycle 50).
  EXPECT_EQ(internal::two_crane_bound({0, 40, 100}, {0, 50, 80}, {0, 1, 1, 0}), 110);
  // ... unless a's first lasts 55: both do their first together; at 50 b, done with its first,
  // waits at its waypoint the 5 cycles a's first has left; then b's second (30) beside a's second
  // (60): 55 + 60 = 115.
  EXPECT_EQ(internal::two_crane_bound({0, 55, 115}, {0, 50, 80}, {0, 1, 1, 0}), 115);
  // The same with b's waiting not possible in the middle of its first: a's first and b's first meet
  // too, so one waits for the other: b's first (50), then a's first (55) while b waits, then both
  // seconds: 105 + 60 = 165; or a's first, then b's first while a waits at 55: 105, a's second and
  // b's second together: 165.
  EXPECT_EQ(internal::two_crane_bound({0, 55, 115}, {0, 50, 80}, {1, 1, 1, 0}), 165);
}

// Waiting only at rest (WaitRule::at_rest). a: two moves of 30, the second meeting b's move; b: at
// rest 10, then its move of 30. Anywhere, a waits 10 at its waypoint between its moves: 70. At rest
// only, a never waits and b must wait at rest until a's second move is over: 60 + 30 = 90.
TEST(ScheduleBound, WaitingOnlyAtRestBetweenLegs) {
  const std::vector<std::int64_t> x{0, 30, 60}, y{0, 10, 40};
  const std::vector<char> cells{0, 0, 0, 1};  // (a's first, b's rest), (a's first, b's move), ...
  EXPECT_EQ(internal::two_crane_bound(x, y, cells), 70);
  EXPECT_EQ(internal::two_crane_bound(x, y, cells, {0, 0}, {1, 0}), 90);
  // b's rest box meeting a's second move too: b cannot wait through it, a cannot wait at all.
  EXPECT_EQ(internal::two_crane_bound(x, y, {0, 0, 1, 1}, {0, 0}, {1, 0}), -1);
  EXPECT_EQ(internal::two_crane_bound(x, y, {0, 0, 1, 1}), 70);
  // Every interval at rest and nothing forbidden: both at once.
  EXPECT_EQ(internal::two_crane_bound(x, y, {0, 0, 0, 0}, {1, 1}, {1, 1}), 60);
}

// The first time at which both can be done, found forward in time: the set of lattice points
// reachable after t cycles, grown a cycle at a time (the same moves as lattice()).
std::int64_t earliest(const std::vector<std::int64_t>& x, const std::vector<std::int64_t>& y,
                      const std::vector<char>& forbidden) {
  const std::int64_t X = x.back(), Y = y.back();
  const std::size_t n = y.size() - 1;
  const auto column = [&](std::int64_t t) {  // the interval holding t .. t + 1, and t inside it
    std::size_t k = 0;
    while (x[k + 1] <= t) ++k;
    return k;
  };
  const auto row = [&](std::int64_t t) {
    std::size_t l = 0;
    while (y[l + 1] <= t) ++l;
    return l;
  };
  std::vector<char> reach(static_cast<std::size_t>((X + 1) * (Y + 1)), 0);
  const auto idx = [&](std::int64_t i, std::int64_t j) { return static_cast<std::size_t>(i * (Y + 1) + j); };
  reach[idx(0, 0)] = 1;
  for (std::int64_t t = 0; t <= X + Y; ++t) {
    if (reach[idx(X, Y)]) return t;
    std::vector<char> next = reach;  // a point stays reachable (waiting there is a move of its own below)
    std::fill(next.begin(), next.end(), 0);
    for (std::int64_t i = 0; i <= X; ++i) {
      for (std::int64_t j = 0; j <= Y; ++j) {
        if (!reach[idx(i, j)]) continue;
        const bool i_edge = std::binary_search(x.begin(), x.end(), i);
        const bool j_edge = std::binary_search(y.begin(), y.end(), j);
        if (i < X && j < Y && !forbidden[column(i) * n + row(j)]) next[idx(i + 1, j + 1)] = 1;
        if (i < X && (j == Y || j_edge || !forbidden[column(i) * n + row(j)])) next[idx(i + 1, j)] = 1;
        if (j < Y && (i == X || i_edge || !forbidden[column(i) * n + row(j)])) next[idx(i, j + 1)] = 1;
      }
    }
    reach.swap(next);
  }
  return -1;
}

// The row-by-row search of the library against the whole lattice searched two more ways (by
// position, by time), on 500 seeded random planes of 1-6 intervals of 1-7 cycles each, 40 % of the
// cells forbidden.
TEST(ScheduleBound, TheSearchIsTheShortestPathOverEveryCycle) {
  std::mt19937_64 rng(20261129);
  std::uniform_int_distribution<int> count(1, 6), length(1, 7);
  std::bernoulli_distribution forbid(0.4);
  int differed = 0, with_order_at_rest = 0;
  for (int trial = 0; trial < 500; ++trial) {
    std::vector<std::int64_t> x{0}, y{0};
    for (int k = count(rng); k > 0; --k) x.push_back(x.back() + length(rng));
    for (int l = count(rng); l > 0; --l) y.push_back(y.back() + length(rng));
    std::vector<char> cells((x.size() - 1) * (y.size() - 1));
    for (char& c : cells) c = forbid(rng) ? 1 : 0;
    const std::int64_t found = internal::two_crane_bound(x, y, cells);
    const std::int64_t expected = lattice(x, y, cells);
    if (found != expected) ++differed;
    EXPECT_EQ(found, expected) << "trial " << trial;
    EXPECT_EQ(earliest(x, y, cells), expected) << "trial " << trial;
    // Waiting only at rest, in a random half of the intervals: never shorter.
    std::vector<char> rest_x(x.size() - 1), rest_y(y.size() - 1);
    for (char& r : rest_x) r = forbid(rng) ? 1 : 0;
    for (char& r : rest_y) r = forbid(rng) ? 1 : 0;
    const std::int64_t at_rest = internal::two_crane_bound(x, y, cells, rest_x, rest_y);
    if (at_rest >= 0) {
      ++with_order_at_rest;
      EXPECT_GE(at_rest, found) << "trial " << trial;
    }
    EXPECT_GE(found, std::max(x.back(), y.back()));
    EXPECT_LE(found, x.back() + y.back());
  }
  EXPECT_EQ(differed, 0);
  EXPECT_GT(with_order_at_rest, 100) << "the comparison at rest must have planes to compare";
  std::printf("%d of 500 planes had an order waiting at rest\n", with_order_at_rest);
}

// The site's geometry decides the cells: the two towers of the service's tests, b's jib 1 m above
// a's; with both jibs towards each other (trolleys and cables at 1 m), b's cable hangs through a's
// jib; with a's turned away, everything keeps clear (a's counter-jib 0.52 m from b's load).
TEST(ScheduleBound, TheSiteGeometryForbidsTheCellsThatMeet) {
  const SiteLayout s = test_sites::two_towers(3.5);
  const auto at = [&](double slew) { return rest_airspace({slew, 1.0, 1.0}, s.paths); };
  const double pi = std::numbers::pi;
  const Timeline towards{{{100, at(0.0)}}};
  const Timeline away{{{100, at(pi)}}};
  const Timeline towards_b{{{50, at(pi)}}};
  EXPECT_EQ(two_crane_bound(s, 0, towards, 1, towards_b), 150);
  EXPECT_EQ(two_crane_bound(s, 0, away, 1, towards_b), 100);
  EXPECT_EQ(two_crane_bound(s, 1, towards_b, 0, towards), 150);
  EXPECT_THROW((void)two_crane_bound(s, 0, towards, 0, towards), std::invalid_argument);
  EXPECT_THROW((void)two_crane_bound(s, 0, towards, 2, towards), std::invalid_argument);
  const Timeline backwards{{{100, at(0.0)}, {100, at(0.0)}}};
  EXPECT_THROW((void)two_crane_bound(s, 0, backwards, 1, towards_b), std::invalid_argument);
}

// search_site_schedule (every crane at once, whole legs).

using Ends = std::vector<std::vector<std::int64_t>>;
using Rests = std::vector<std::vector<char>>;
using Cells = std::vector<std::vector<std::vector<char>>>;  // [i][j][k * steps_j + l], both ways

// Each crane's interval per cycle of the schedule `departures` and `waits` say (the rest intervals
// held until their departure, the others as long as alone and the wait before the next, nothing once
// done), -1 when done; empty if a departure comes before the crane could leave, or a wait is not
// inside a leg (before an interval that follows a moving one) or is negative.
std::vector<std::vector<int>> held_per_cycle(const Ends& ends, const Rests& rest, const SiteSchedule& s,
                                             std::int64_t horizon) {
  std::vector<std::vector<int>> held;
  if (s.waits.size() != ends.size()) return {};
  for (std::size_t c = 0; c < ends.size(); ++c) {
    if (s.waits[c].size() != rest[c].size()) return {};
    std::vector<int> h(static_cast<std::size_t>(horizon), -1);
    std::int64_t t = 0;
    std::size_t q = 0;
    for (std::size_t k = 0; k < rest[c].size(); ++k) {
      const std::int64_t wait = s.waits[c][k];
      if (wait < 0 || (wait > 0 && (k == 0 || rest[c][k] || rest[c][k - 1]))) return {};
      std::int64_t until = t + ends[c][k + 1] - ends[c][k];
      if (k + 1 < rest[c].size()) until += s.waits[c][k + 1];  // waiting in k before k + 1
      if (rest[c][k]) {
        if (q >= s.departures[c].size() || s.departures[c][q] < until) return {};
        until = s.departures[c][q++];
      }
      for (std::int64_t u = t; u < until && u < horizon; ++u) h[static_cast<std::size_t>(u)] = static_cast<int>(k);
      t = until;
    }
    if (q != s.departures[c].size()) return {};
    held.push_back(h);
  }
  return held;
}

// The schedule keeps the rule in every cycle and ends when it says.
::testing::AssertionResult keeps_the_rule(const Ends& ends, const Rests& rest, const Cells& cells,
                                          const SiteSchedule& s) {
  const std::int64_t horizon = s.cycles + 1;
  const auto held = held_per_cycle(ends, rest, s, horizon);
  if (held.empty()) return ::testing::AssertionFailure() << "a departure before its crane could leave, or a wait outside a leg";
  std::int64_t last = 0;
  for (std::size_t c = 0; c < held.size(); ++c) {
    for (std::int64_t t = 0; t < horizon; ++t) {
      if (held[c][static_cast<std::size_t>(t)] >= 0) last = std::max(last, t + 1);
    }
  }
  if (last != s.cycles) return ::testing::AssertionFailure() << "done at " << last << ", said " << s.cycles;
  for (std::int64_t t = 0; t < horizon; ++t) {
    for (std::size_t i = 0; i < held.size(); ++i) {
      for (std::size_t j = i + 1; j < held.size(); ++j) {
        const int k = held[i][static_cast<std::size_t>(t)], l = held[j][static_cast<std::size_t>(t)];
        if (k >= 0 && l >= 0 && cells[i][j][static_cast<std::size_t>(k) * rest[j].size() + static_cast<std::size_t>(l)]) {
          return ::testing::AssertionFailure() << "cranes " << i << " and " << j << " meet in cycle " << t;
        }
      }
    }
  }
  return ::testing::AssertionSuccess();
}

// The exact best of the same model, by a breadth-first search of the lattice with one axis per
// crane (small planes only): each cycle every crane moves on one cycle, or waits where
// two_crane_bound's rule at rest lets it (inside a rest interval, holding it; on the edge of one or
// two, holding them; done, holding nothing). -1: no order.
std::int64_t exact_at_rest(const Ends& ends, const Rests& rest, const Cells& cells) {
  const std::size_t n = ends.size();
  std::vector<std::int64_t> size(n), stride(n);
  std::int64_t states = 1;
  for (std::size_t c = 0; c < n; ++c) {
    size[c] = ends[c].back() + 1;
    stride[c] = states;
    states *= size[c];
  }
  const auto interval = [&](std::size_t c, std::int64_t p) {  // the one holding p .. p + 1
    return static_cast<int>(std::upper_bound(ends[c].begin(), ends[c].end(), p) - ends[c].begin() - 1);
  };
  // Waiting at p: the intervals held, or {-2} where it may not wait.
  const auto waiting = [&](std::size_t c, std::int64_t p) -> std::vector<int> {
    if (p == ends[c].back()) return {};
    const auto e = std::lower_bound(ends[c].begin(), ends[c].end(), p);
    if (*e != p) {  // inside interval k
      const int k = static_cast<int>(e - ends[c].begin() - 1);
      return rest[c][static_cast<std::size_t>(k)] ? std::vector<int>{k} : std::vector<int>{-2};
    }
    std::vector<int> h;
    const auto k = static_cast<std::size_t>(e - ends[c].begin());
    if (k > 0 && rest[c][k - 1]) h.push_back(static_cast<int>(k - 1));
    if (rest[c][k]) h.push_back(static_cast<int>(k));
    return h.empty() ? std::vector<int>{-2} : h;
  };
  std::vector<std::int64_t> when(static_cast<std::size_t>(states), -1);
  std::vector<std::int64_t> queue{0};
  when[0] = 0;
  const std::int64_t goal = states - 1;
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const std::int64_t here = queue[head];
    if (here == goal) return when[static_cast<std::size_t>(here)];
    std::vector<std::int64_t> p(n);
    for (std::size_t c = 0; c < n; ++c) p[c] = here / stride[c] % size[c];
    for (unsigned moving = 1; moving < (1u << n); ++moving) {
      std::vector<std::vector<int>> held(n);
      bool ok = true;
      std::int64_t to = 0;
      for (std::size_t c = 0; c < n && ok; ++c) {
        if (moving & (1u << c)) {
          if (p[c] == ends[c].back()) ok = false;
          else held[c] = {interval(c, p[c])}, to += (p[c] + 1) * stride[c];
        } else {
          held[c] = waiting(c, p[c]);
          ok = held[c] != std::vector<int>{-2};
          to += p[c] * stride[c];
        }
      }
      for (std::size_t i = 0; i < n && ok; ++i) {
        for (std::size_t j = i + 1; j < n && ok; ++j) {
          for (const int k : held[i]) {
            for (const int l : held[j]) {
              if (cells[i][j][static_cast<std::size_t>(k) * rest[j].size() + static_cast<std::size_t>(l)]) ok = false;
            }
          }
        }
      }
      if (!ok || when[static_cast<std::size_t>(to)] >= 0) continue;
      when[static_cast<std::size_t>(to)] = when[static_cast<std::size_t>(here)] + 1;
      queue.push_back(to);
    }
  }
  return -1;
}

SiteSchedule search(const Ends& ends, const Rests& rest, const Cells& cells, int tries = 200,
                    HoldRule rule = HoldRule::timed) {
  return internal::search_site_schedule(
      ends, rest, [&](std::size_t i, std::size_t k, std::size_t j, std::size_t l) {
        return cells[i][j][k * rest[j].size() + l] != 0;
      }, 7, tries, rule);
}

// The service's rule against the bound's, by hand. a: at rest 1, then a leg of 10 cycles that meets
// b's second interval, and 50 clear; b: at rest 1, then 100 clear and 10 that meet a's first. Timed,
// both leave at 1: a's first is over at 11, b reaches its second at 101: b done at 111. Under the
// service's rule b's path meets what a holds until a's first interval is over: b leaves at 11, done
// at 121 (b first would keep a at rest until 111: 171).
TEST(SiteScheduleSearch, TheServicesRuleWaitsForTheWholePathToClear) {
  const Ends ends{{0, 1, 11, 61}, {0, 1, 101, 111}};
  const Rests rest{{1, 0, 0}, {1, 0, 0}};
  Cells cells(2, std::vector<std::vector<char>>(2));
  cells[0][1] = {0, 0, 0, 0, 0, 1, 0, 0, 0};  // (a's k, b's l) at k * 3 + l: a's first with b's second
  cells[1][0] = {0, 0, 0, 0, 0, 0, 0, 1, 0};  // (b's l, a's k) at l * 3 + k
  const SiteSchedule timed = search(ends, rest, cells);
  EXPECT_EQ(timed.cycles, 111);
  EXPECT_EQ(exact_at_rest(ends, rest, cells), 111);
  const SiteSchedule path = search(ends, rest, cells, 20, HoldRule::path);
  EXPECT_EQ(path.cycles, 121);
  EXPECT_EQ(path.departures[0], std::vector<std::int64_t>{1});
  EXPECT_EQ(path.departures[1], std::vector<std::int64_t>{11});
  EXPECT_TRUE(keeps_the_rule(ends, rest, cells, path));
}

// Leaving behind a moving crane (HoldRule::behind), by hand. a: at rest 1, then 10 cycles that meet
// b's second interval and 1 clear; b: at rest 1, then 5 clear and 10 that meet a's first. Under the
// service's rule b leaves when a's first interval is over, at 11: done at 26 (b first: a leaves at
// 16, done at 27). Behind a, b leaves at 1, stands before its second interval from 6 to 11 and is
// done at 21, the exact best at rest (b leaving at 6). a cannot go behind b: its first interval
// meets what b holds. Nor can b go behind a when a comes to rest where b's second interval passes:
// then one waits for the other, 27 cycles either way.
TEST(SiteScheduleSearch, ALegLeavesBehindAMovingCraneAndWaitsBeforeWhatItHolds) {
  const Ends ends{{0, 1, 11, 12}, {0, 1, 6, 16}};
  const Rests rest{{1, 0, 0}, {1, 0, 0}};
  Cells cells(2, std::vector<std::vector<char>>(2));
  cells[0][1] = {0, 0, 0, 0, 0, 1, 0, 0, 0};  // a's first with b's second
  cells[1][0] = {0, 0, 0, 0, 0, 0, 0, 1, 0};
  EXPECT_EQ(search(ends, rest, cells, 20, HoldRule::path).cycles, 26);
  EXPECT_EQ(exact_at_rest(ends, rest, cells), 21);
  const SiteSchedule behind = search(ends, rest, cells, 20, HoldRule::behind);
  EXPECT_EQ(behind.cycles, 21);
  EXPECT_EQ(behind.departures[0], std::vector<std::int64_t>{1});
  EXPECT_EQ(behind.departures[1], std::vector<std::int64_t>{1});
  EXPECT_EQ(behind.waits[1], (std::vector<std::int64_t>{0, 0, 5}));  // before its second interval, 6 to 11
  EXPECT_EQ(behind.waits[0], (std::vector<std::int64_t>{0, 0, 0}));
  EXPECT_TRUE(keeps_the_rule(ends, rest, cells, behind));
  // Not behind a crane whose rest box at its end meets the leg: a rests after its first interval.
  const Rests rests_after{{1, 0, 1}, {1, 0, 0}};
  cells[0][1] = {0, 0, 0, 0, 0, 1, 0, 0, 1};  // ... and that rest box meets b's second too
  cells[1][0] = {0, 0, 0, 0, 0, 0, 0, 1, 1};
  EXPECT_EQ(search(ends, rests_after, cells, 20, HoldRule::behind).cycles, 27);  // one after the other
  EXPECT_EQ(search(ends, rests_after, cells, 20, HoldRule::path).cycles, 27);
}

// Three cranes, each at rest 1 cycle, then a leg of 100 that meets each other's: one after the
// other, 301 cycles; each pair alone needs 201, so the pairs' bound misses the third crane by 100.
TEST(SiteScheduleSearch, ThreeCranesInEachOthersWayGoOneAfterTheOther) {
  const Ends ends(3, {0, 1, 101});
  const Rests rest(3, {1, 0});
  Cells cells(3, std::vector<std::vector<char>>(3, {0, 0, 0, 1}));
  const SiteSchedule s = search(ends, rest, cells);
  EXPECT_EQ(s.cycles, 301);
  EXPECT_TRUE(keeps_the_rule(ends, rest, cells, s));
  EXPECT_EQ(exact_at_rest(ends, rest, cells), 301);
  EXPECT_EQ(internal::two_crane_bound(ends[0], ends[1], cells[0][1], rest[0], rest[1]), 201);
  // The legs of 0 and 2 clear of each other: 0 and 2 together, then 1: 201.
  cells[0][2] = cells[2][0] = {0, 0, 0, 0};
  EXPECT_EQ(search(ends, rest, cells).cycles, 201);
  EXPECT_EQ(exact_at_rest(ends, rest, cells), 201);
  // Each rest box in the others' legs' way too: the first to go ends where the others' legs pass.
  // Whoever leaves first meets the others standing: no order.
  cells = Cells(3, std::vector<std::vector<char>>(3, {0, 1, 1, 1}));
  EXPECT_EQ(search(ends, rest, cells).cycles, -1);
  EXPECT_EQ(exact_at_rest(ends, rest, cells), -1);
}

// The sites' geometry through the public call: the two towers of the tests, a at rest turned away
// for 10 cycles, then its jib towards b for 100; b at rest towards a for 50, then done: a waits
// until b is done (150), as two_crane_bound at rest says.
TEST(SiteScheduleSearch, TheSiteGeometryThroughThePublicCall) {
  const SiteLayout s = test_sites::two_towers(3.5);
  const auto at = [&](double slew) { return rest_airspace({slew, 1.0, 1.0}, s.paths); };
  const double pi = std::numbers::pi;
  const Timeline a{{{10, at(pi), true}, {110, at(0.0)}}};
  const Timeline b{{{50, at(pi), true}}};
  const SiteSchedule found = search_site_schedule(s, {a, b}, 1);
  EXPECT_EQ(found.cycles, 150);
  EXPECT_EQ(found.cycles, two_crane_bound(s, 0, a, 1, b, WaitRule::at_rest));
  ASSERT_EQ(found.departures.size(), 2u);
  EXPECT_EQ(found.departures[0], std::vector<std::int64_t>{50});
  EXPECT_EQ(found.departures[1], std::vector<std::int64_t>{50});
  EXPECT_THROW((void)search_site_schedule(s, {a}, 1), std::invalid_argument);
  const Timeline backwards{{{100, at(0.0)}, {100, at(0.0)}}};
  EXPECT_THROW((void)search_site_schedule(s, {a, backwards}, 1), std::invalid_argument);
}

// Seeded random planes of two and three cranes (1-5 intervals each, 2-6 cycles, half at rest, 35 %
// of the pairs of intervals forbidden): every schedule the search returns keeps the rule in every
// cycle (checked cycle by cycle above), is never shorter than the exact best of the same model (the
// breadth-first lattice) nor than any pair's two_crane_bound at rest, and finds none only where
// the lattice has none, or where it had none to return. How often it is the exact best is printed.
TEST(SiteScheduleSearch, RandomPlanesAgainstTheExactLattice) {
  std::mt19937_64 rng(20261130);
  std::uniform_int_distribution<int> count(1, 5), length(2, 6);
  std::bernoulli_distribution half(0.5), forbid(0.35);
  int compared[4] = {0, 0, 0, 0}, exact[4] = {0, 0, 0, 0}, missed[4] = {0, 0, 0, 0};
  std::int64_t over[4] = {0, 0, 0, 0}, total[4] = {0, 0, 0, 0};
  int with_path[4] = {0, 0, 0, 0};
  std::int64_t path_over[4] = {0, 0, 0, 0}, path_total[4] = {0, 0, 0, 0};
  int with_behind[4] = {0, 0, 0, 0};
  std::int64_t behind_over[4] = {0, 0, 0, 0}, behind_total[4] = {0, 0, 0, 0};
  for (int trial = 0; trial < 600; ++trial) {
    const std::size_t n = trial % 2 == 0 ? 2 : 3;
    Ends ends(n, {0});
    Rests rest(n);
    for (std::size_t c = 0; c < n; ++c) {
      for (int k = count(rng); k > 0; --k) {
        ends[c].push_back(ends[c].back() + length(rng));
        rest[c].push_back(rest[c].empty() || half(rng) ? 1 : 0);  // at rest first, as on a site
      }
    }
    Cells cells(n, std::vector<std::vector<char>>(n));
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        cells[i][j].assign(rest[i].size() * rest[j].size(), 0);
        cells[j][i].assign(rest[i].size() * rest[j].size(), 0);
        for (std::size_t k = 0; k < rest[i].size(); ++k) {
          for (std::size_t l = 0; l < rest[j].size(); ++l) {
            cells[i][j][k * rest[j].size() + l] = cells[j][i][l * rest[i].size() + k] = forbid(rng) ? 1 : 0;
          }
        }
      }
    }
    const SiteSchedule found = search(ends, rest, cells, 30);
    const std::int64_t best = exact_at_rest(ends, rest, cells);
    const SiteSchedule path = search(ends, rest, cells, 30, HoldRule::path);
    // Behind a moving crane a leg may wait before an interval, as when waiting anywhere: never
    // shorter than any pair's exact bound waiting anywhere, nor than the longest crane's work.
    const SiteSchedule behind = search(ends, rest, cells, 30, HoldRule::behind);
    if (behind.cycles >= 0) {
      ++with_behind[n];
      EXPECT_TRUE(keeps_the_rule(ends, rest, cells, behind)) << "trial " << trial << ", behind";
      for (std::size_t i = 0; i < n; ++i) {
        EXPECT_GE(behind.cycles, ends[i].back()) << "trial " << trial << ", behind";
        for (std::size_t j = i + 1; j < n; ++j) {
          EXPECT_GE(behind.cycles, internal::two_crane_bound(ends[i], ends[j], cells[i][j], {}, {}))
              << "trial " << trial << ", behind";
        }
      }
      if (best >= 0) behind_over[n] += behind.cycles - best, behind_total[n] += best;
    }
    if (best < 0) {
      EXPECT_EQ(found.cycles, -1) << "trial " << trial;
      EXPECT_EQ(path.cycles, -1) << "trial " << trial;
      continue;
    }
    // The first order only (tries 0): the departures in the order of time, each as soon as it may.
    const SiteSchedule first = search(ends, rest, cells, 0);
    if (first.cycles >= 0) {
      EXPECT_TRUE(keeps_the_rule(ends, rest, cells, first)) << "trial " << trial << ", the first order";
      EXPECT_GE(first.cycles, std::max(best, found.cycles)) << "trial " << trial << ", the first order";
    }
    if (path.cycles >= 0) {
      ++with_path[n];
      EXPECT_TRUE(keeps_the_rule(ends, rest, cells, path)) << "trial " << trial << ", the service's rule";
      EXPECT_GE(path.cycles, best) << "trial " << trial << ", the service's rule";
      path_over[n] += path.cycles - best;
      path_total[n] += best;
    }
    ++compared[n];
    if (found.cycles < 0) {
      ++missed[n];
      continue;
    }
    EXPECT_TRUE(keeps_the_rule(ends, rest, cells, found)) << "trial " << trial;
    EXPECT_GE(found.cycles, best) << "trial " << trial;
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        const std::int64_t pair = internal::two_crane_bound(ends[i], ends[j], cells[i][j], rest[i], rest[j]);
        EXPECT_GE(best, pair) << "trial " << trial << ": the lattice of all cranes is no shorter than a pair's";
      }
    }
    if (found.cycles == best) ++exact[n];
    over[n] += found.cycles - best;
    total[n] += best;
  }
  for (const std::size_t n : {std::size_t{2}, std::size_t{3}}) {
    std::printf("%zu cranes: %d planes with an order; the search found the best in %d, was %.2f %% over it in all, "
                "found none in %d\n",
                n, compared[n], exact[n], total[n] > 0 ? 100.0 * static_cast<double>(over[n]) / static_cast<double>(total[n]) : 0.0,
                missed[n]);
    std::printf("%zu cranes, the service's rule: an order found in %d, %.2f %% over the best in all\n", n, with_path[n],
                path_total[n] > 0 ? 100.0 * static_cast<double>(path_over[n]) / static_cast<double>(path_total[n]) : 0.0);
    std::printf("%zu cranes, leaving behind a moving crane: an order found in %d, %+.2f %% of the best at rest\n", n,
                with_behind[n],
                behind_total[n] > 0 ? 100.0 * static_cast<double>(behind_over[n]) / static_cast<double>(behind_total[n]) : 0.0);
    EXPECT_GT(compared[n], 40) << "the comparison must have planes to compare";
  }
}

}  // namespace
