#include "crane/anti_collision/schedule_bound.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace crane::anti_collision {
namespace {

void check(const Timeline& t, const char* which) {
  std::int64_t before = 0;
  for (std::size_t k = 0; k < t.steps.size(); ++k) {
    if (t.steps[k].end_cycle <= before) {
      throw std::invalid_argument(std::string("two_crane_bound: ") + which + " step " + std::to_string(k) +
                                  " ends at cycle " + std::to_string(t.steps[k].end_cycle) +
                                  ", not after the one before (" + std::to_string(before) + ")");
    }
    before = t.steps[k].end_cycle;
  }
}

constexpr std::int32_t kFree = -1;   // waiting here holds nothing
constexpr std::int32_t kNever = -2;  // no waiting here

// Where a crane may wait, per cycle p of its work (0 .. its end): kNever, kFree, or the intervals
// whose cells with the other crane's interval must be free (`first`, and `second` or kFree).
struct WaitPoints {
  std::vector<std::int32_t> first, second;
};

// `ends`: the intervals' ends (ends[0] = 0); `rest`: empty, the crane waits anywhere (inside an
// interval holding it, at an end holding nothing); else per interval whether it is at rest, the
// only intervals it waits in (holding them, at their ends too). Done, it waits anywhere, holding
// nothing.
WaitPoints wait_points(const std::vector<std::int64_t>& ends, const std::vector<char>& rest) {
  const std::int64_t T = ends.back();
  WaitPoints w{std::vector<std::int32_t>(static_cast<std::size_t>(T) + 1, kNever),
               std::vector<std::int32_t>(static_cast<std::size_t>(T) + 1, kFree)};
  const std::size_t count = ends.size() - 1;
  for (std::size_t l = 0; l < count; ++l) {
    const auto id = static_cast<std::int32_t>(l);
    for (std::int64_t p = ends[l]; p <= ends[l + 1]; ++p) {
      const auto P = static_cast<std::size_t>(p);
      const bool end = p == ends[l] || p == ends[l + 1];
      if (rest.empty()) {
        if (!end) w.first[P] = id;
        else if (w.first[P] == kNever) w.first[P] = kFree;
      } else if (rest[l]) {
        if (w.first[P] == kNever || w.first[P] == kFree) {
          w.first[P] = id;
        } else if (w.first[P] != id) {
          w.second[P] = id;
        }
      }
    }
  }
  w.first[static_cast<std::size_t>(T)] = kFree;
  w.second[static_cast<std::size_t>(T)] = kFree;
  return w;
}

// The shortest monotone path over every cycle (the lattice of whole cycles: every interval ends on
// it), row by row, two rows kept. A move of one cycle: diagonally through the unit square of a
// cell that is not forbidden, or along one axis while the other crane waits where it may
// (wait_points).
std::int64_t lattice_path(const std::vector<std::int64_t>& x, const std::vector<std::int64_t>& y,
                          const std::vector<char>& forbidden, const std::vector<char>& rest_x,
                          const std::vector<char>& rest_y) {
  const std::int64_t X = x.back(), Y = y.back();
  const std::size_t n = y.size() - 1;
  std::vector<std::size_t> row(static_cast<std::size_t>(Y) + 1, n);  // cycle j .. j + 1 of the second
  for (std::size_t l = 0; l < n; ++l) {
    for (std::int64_t j = y[l]; j < y[l + 1]; ++j) row[static_cast<std::size_t>(j)] = l;
  }
  const WaitPoints wait_x = wait_points(x, rest_x), wait_y = wait_points(y, rest_y);
  const auto may_wait = [&](const WaitPoints& w, std::size_t p, auto cell_with) {
    const std::int32_t first = w.first[p], second = w.second[p];
    if (first == kNever) return false;
    if (first != kFree && cell_with(static_cast<std::size_t>(first))) return false;
    return second == kFree || !cell_with(static_cast<std::size_t>(second));
  };
  constexpr std::int64_t kFar = std::numeric_limits<std::int64_t>::max() / 2;
  std::vector<std::int64_t> before(static_cast<std::size_t>(Y) + 1, kFar), now(before.size(), kFar);
  std::size_t k = 0;  // the first crane's interval holding cycle i - 1 .. i
  for (std::int64_t i = 0; i <= X; ++i) {
    const auto I = static_cast<std::size_t>(i);
    if (i > 0) {
      while (x[k + 1] <= i - 1) ++k;
    }
    for (std::int64_t j = 0; j <= Y; ++j) {
      const auto J = static_cast<std::size_t>(j);
      std::int64_t best = i == 0 && j == 0 ? 0 : kFar;
      if (i > 0) {
        // The first crane's cycle i - 1 .. i while the second waits at j.
        if (may_wait(wait_y, J, [&](std::size_t l) { return forbidden[k * n + l] != 0; })) {
          best = std::min(best, before[J] + 1);
        }
        // Both: diagonally from (i - 1, j - 1).
        if (j > 0 && !forbidden[k * n + row[J - 1]]) best = std::min(best, before[J - 1] + 1);
      }
      // The second crane's cycle j - 1 .. j while the first waits at i.
      if (j > 0 && may_wait(wait_x, I, [&](std::size_t c) { return forbidden[c * n + row[J - 1]] != 0; })) {
        best = std::min(best, now[J - 1] + 1);
      }
      now[J] = best;
    }
    std::swap(before, now);
  }
  return before[static_cast<std::size_t>(Y)] >= kFar ? -1 : before[static_cast<std::size_t>(Y)];
}

}  // namespace

std::int64_t two_crane_bound(const SiteLayout& layout, std::size_t first, const Timeline& a, std::size_t second,
                             const Timeline& b, WaitRule rule) {
  if (first >= layout.cranes.size() || second >= layout.cranes.size() || first == second) {
    throw std::invalid_argument("two_crane_bound: cranes " + std::to_string(first) + " and " + std::to_string(second) +
                                " are not two cranes of the site (" + std::to_string(layout.cranes.size()) + ")");
  }
  check(a, "the first crane's");
  check(b, "the second crane's");
  std::vector<std::int64_t> x{0}, y{0};
  for (const TimelineStep& step : a.steps) x.push_back(step.end_cycle);
  for (const TimelineStep& step : b.steps) y.push_back(step.end_cycle);
  std::vector<char> forbidden(a.steps.size() * b.steps.size());
  for (std::size_t k = 0; k < a.steps.size(); ++k) {
    for (std::size_t l = 0; l < b.steps.size(); ++l) {
      forbidden[k * b.steps.size() + l] =
          airspace_distance(layout.cranes[first], a.steps[k].uses, layout.cranes[second], b.steps[l].uses).distance <
          layout.margins.slow_down;
    }
  }
  std::vector<char> rest_a, rest_b;
  if (rule == WaitRule::at_rest) {
    for (const TimelineStep& step : a.steps) rest_a.push_back(step.rest ? 1 : 0);
    for (const TimelineStep& step : b.steps) rest_b.push_back(step.rest ? 1 : 0);
  }
  return lattice_path(x, y, forbidden, rest_a, rest_b);
}

namespace internal {
std::int64_t two_crane_bound(const std::vector<std::int64_t>& x, const std::vector<std::int64_t>& y,
                             const std::vector<char>& forbidden, const std::vector<char>& rest_x,
                             const std::vector<char>& rest_y) {
  return lattice_path(x, y, forbidden, rest_x, rest_y);
}
}  // namespace internal

}  // namespace crane::anti_collision
