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

}  // namespace
