#include "crane/anti_collision/schedule_bound.hpp"

#include <algorithm>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace crane::anti_collision {
namespace {

void check(const Timeline& t, const std::string& which, const char* who = "two_crane_bound") {
  std::int64_t before = 0;
  for (std::size_t k = 0; k < t.steps.size(); ++k) {
    if (t.steps[k].end_cycle <= before) {
      throw std::invalid_argument(std::string(who) + ": " + which + " step " + std::to_string(k) +
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


// search_site_schedule: a crane's work as legs between rest intervals (the header's model).
struct LegStep {
  std::int64_t from{0}, to{0};  // [cycles] after the departure
  std::size_t step{0};
};
struct Stop {
  std::size_t rest{0};          // the rest interval
  std::int64_t length{0};       // [cycles] it lasted alone: the least time in it
  std::vector<LegStep> leg;     // the leg that leaves it (empty: straight into the next rest interval)
  std::int64_t leg_length{0};   // [cycles]
};
struct Work {
  std::size_t steps{0};            // intervals
  std::vector<LegStep> first_leg;  // from cycle 0, before the first rest interval
  std::int64_t first_leg_length{0};
  std::vector<Stop> stops;
};

Work parse_work(const std::vector<std::int64_t>& ends, const std::vector<char>& rest) {
  Work w;
  w.steps = rest.size();
  w.stops.reserve(rest.size());  // the pointers below stay valid
  std::vector<LegStep>* leg = &w.first_leg;
  std::int64_t* length = &w.first_leg_length;
  for (std::size_t k = 0; k + 1 < ends.size(); ++k) {
    const std::int64_t cycles = ends[k + 1] - ends[k];
    if (rest[k]) {
      w.stops.push_back({k, cycles, {}, 0});
      leg = &w.stops.back().leg;
      length = &w.stops.back().leg_length;
    } else {
      leg->push_back({*length, *length + cycles, k});
      *length += cycles;
    }
  }
  return w;
}

constexpr std::int64_t kHeld = std::numeric_limits<std::int64_t>::max() / 4;  // held until further notice

struct Held {
  std::int64_t from{0}, to{0};  // [cycles) of the site; to == kHeld: at rest until its next departure
  std::size_t step{0};
};

class Decoder {
 public:
  Decoder(const std::vector<Work>& work, const std::vector<std::vector<std::vector<char>>>& forbidden)
      : work_(work), forbidden_(forbidden) {}

  // Places the departures in `order`'s priority (each time the first that can be placed); false
  // when at some point none can.
  bool decode(const std::vector<std::size_t>& order, SiteSchedule& out) {
    if (!start()) return false;
    std::vector<std::size_t> pending(order);
    while (!pending.empty()) {
      bool placed = false;
      for (std::size_t p = 0; p < pending.size() && !placed; ++p) {
        const std::int64_t s = earliest(pending[p]);
        if (s < 0) continue;
        depart(pending[p], s);
        pending.erase(pending.begin() + static_cast<std::ptrdiff_t>(p));
        placed = true;
      }
      if (!placed) return false;
    }
    finish(out);
    return true;
  }

  // Builds an order as it places: each time the departure that can leave soonest, or with
  // probability `wander` any that can be placed. false when at some point none can.
  bool construct(std::mt19937_64& rng, double wander, std::vector<std::size_t>& order, SiteSchedule& out) {
    order.clear();
    if (!start()) return false;
    std::bernoulli_distribution roam(wander);
    for (;;) {
      std::vector<std::pair<std::int64_t, std::size_t>> can;
      for (std::size_t c = 0; c < work_.size(); ++c) {
        if (left_[c] == 0) continue;
        const std::int64_t s = earliest(c);
        if (s >= 0) can.emplace_back(s, c);
      }
      if (can.empty()) {
        if (std::all_of(left_.begin(), left_.end(), [](std::size_t n) { return n == 0; })) break;
        return false;
      }
      std::sort(can.begin(), can.end());
      std::size_t pick = 0;
      if (can.size() > 1 && roam(rng)) pick = std::uniform_int_distribution<std::size_t>(0, can.size() - 1)(rng);
      order.push_back(can[pick].second);
      depart(can[pick].second, can[pick].first);
    }
    finish(out);
    return true;
  }

  // How many departures crane c has that an order places (its last rest interval, with no leg
  // after it, it leaves as soon as it may, as nothing follows).
  [[nodiscard]] std::size_t departures(std::size_t c) const {
    const auto& stops = work_[c].stops;
    return stops.size() - (!stops.empty() && stops.back().leg.empty() ? 1 : 0);
  }

 private:
  bool start() {
    const std::size_t n = work_.size();
    held_.assign(n, {});
    next_.assign(n, 0);
    left_.assign(n, 0);
    done_.assign(n, 0);
    departed_.assign(n, {});
    for (std::size_t c = 0; c < n; ++c) {
      left_[c] = departures(c);
      // The first leg leaves at cycle 0 (or the crane stands at rest from cycle 0).
      if (earliest_of(c, work_[c].first_leg, work_[c].first_leg_length, work_[c].stops.empty() ? nullptr
                                                                                                : &work_[c].stops[0],
                      0) != 0) {
        return false;
      }
      for (const LegStep& l : work_[c].first_leg) held_[c].push_back({l.from, l.to, l.step});
      done_[c] = work_[c].first_leg_length;
      arrive(c);
    }
    return true;
  }

  [[nodiscard]] std::int64_t earliest(std::size_t c) const {
    const Stop& stop = work_[c].stops[next_[c]];
    const Stop* then = next_[c] + 1 < work_[c].stops.size() ? &work_[c].stops[next_[c] + 1] : nullptr;
    return earliest_of(c, stop.leg, stop.leg_length, then, held_[c].back().from + stop.length);
  }

  // The first cycle >= from at which crane c may start `leg` and then stand in `then`'s rest
  // interval (none: it is done) until further notice; -1 if none.
  [[nodiscard]] std::int64_t earliest_of(std::size_t c, const std::vector<LegStep>& leg, std::int64_t length,
                                         const Stop* then, std::int64_t from) const {
    std::vector<std::pair<std::int64_t, std::int64_t>> closed;  // departures [lo, hi] that break the rule
    for (std::size_t o = 0; o < work_.size(); ++o) {
      if (o == c) continue;
      const std::vector<char>& cells = forbidden_[c][o];
      const std::size_t width = work_[o].steps;
      for (const Held& h : held_[o]) {
        if (h.to <= from) continue;
        for (const LegStep& l : leg) {
          if (cells[l.step * width + h.step] == 0) continue;
          // [s + l.from, s + l.to) meets [h.from, h.to)
          closed.emplace_back(h.from - l.to + 1, h.to == kHeld ? kHeld : h.to - l.from - 1);
        }
        if (then != nullptr && cells[then->rest * width + h.step] != 0) {
          if (h.to == kHeld) return -1;  // both at rest in each other's way until further notice
          closed.emplace_back(std::numeric_limits<std::int64_t>::min() / 4, h.to - length - 1);
        }
      }
    }
    std::sort(closed.begin(), closed.end());
    std::int64_t s = from;
    for (const auto& [lo, hi] : closed) {
      if (lo > s) break;
      if (hi >= kHeld) return -1;
      s = std::max(s, hi + 1);
    }
    return s;
  }

  void depart(std::size_t c, std::int64_t s) {
    Held& resting = held_[c].back();
    resting.to = s;
    departed_[c].push_back(s);
    const Stop& stop = work_[c].stops[next_[c]];
    for (const LegStep& l : stop.leg) held_[c].push_back({s + l.from, s + l.to, l.step});
    done_[c] = s + stop.leg_length;
    ++next_[c];
    --left_[c];
    arrive(c);
  }

  // Crane c at the end of a leg: at rest in its next rest interval, if it has one; a last one with
  // no leg after it, it leaves as soon as it may.
  void arrive(std::size_t c) {
    const auto& stops = work_[c].stops;
    if (next_[c] >= stops.size()) return;
    held_[c].push_back({done_[c], kHeld, stops[next_[c]].rest});
    if (next_[c] + 1 == stops.size() && stops[next_[c]].leg.empty()) {
      const std::int64_t s = done_[c] + stops[next_[c]].length;
      held_[c].back().to = s;
      departed_[c].push_back(s);
      done_[c] = s;
      ++next_[c];
    }
  }

  void finish(SiteSchedule& out) const {
    out.cycles = 0;
    for (const std::int64_t d : done_) out.cycles = std::max(out.cycles, d);
    out.departures = departed_;
    out.waits.clear();
    for (const Work& w : work_) out.waits.emplace_back(w.steps, 0);  // a leg runs without a stop
  }

  const std::vector<Work>& work_;
  const std::vector<std::vector<std::vector<char>>>& forbidden_;
  std::vector<std::vector<Held>> held_;
  std::vector<std::size_t> next_, left_;
  std::vector<std::int64_t> done_;
  std::vector<std::vector<std::int64_t>> departed_;
};

// HoldRule::path and HoldRule::behind: the site service's rule replayed cycle by cycle in `keys`'
// order (per crane, per departure; lower first), each crane asking as soon as it has stood its rest
// interval's time; with `reserve`, a request that must wait also holds back the later-keyed ones
// whose leg meets its own. false: at some point no crane moves and none may leave.
class Replay {
 public:
  Replay(const std::vector<Work>& work, const std::vector<std::vector<std::vector<char>>>& forbidden, HoldRule rule)
      : work_(work), forbidden_(forbidden), rule_(rule) {}

  bool run(const std::vector<std::vector<double>>& keys, bool reserve, SiteSchedule& out) {
    const std::size_t n = work_.size();
    cranes_.assign(n, {});
    out.departures.assign(n, {});
    out.waits.clear();
    for (std::size_t c = 0; c < n; ++c) {
      out.waits.emplace_back(work_[c].steps, 0);
      State& k = cranes_[c];
      k.left = work_[c].stops.size();
      start(k, &work_[c].first_leg, work_[c].stops.empty() ? nullptr : &work_[c].stops[0], 0);
    }
    for (std::size_t c = 0; c < n; ++c) {  // the first legs go at cycle 0: clear of each other's
      for (std::size_t o = c + 1; o < n; ++o) {
        if (meets(c, *cranes_[c].leg, cranes_[c].then, o, held(o))) return false;
      }
    }
    std::int64_t t = 0;
    for (;;) {
      // Each moving crane into its next interval: first those that left on a clear path, then those
      // that left behind one (HoldRule::behind), each only when that interval meets nothing held.
      for (const bool behind : {false, true}) {
        for (std::size_t c = 0; c < n; ++c) {
          State& k = cranes_[c];
          if (k.leg == nullptr || k.behind != behind) continue;
          while (k.cur + 1 < k.leg->size() && k.cur_end <= t) {
            const LegStep& next = (*k.leg)[k.cur + 1];
            if (behind && blocked(c, next.step)) {  // it waits where it is, one cycle
              out.waits[c][next.step] += t + 1 - k.cur_end;
              k.end += t + 1 - k.cur_end;
              k.cur_end = t + 1;
              break;
            }
            ++k.cur;
            k.cur_end += next.to - next.from;
          }
        }
      }
      // Legs that end now: at rest in the next rest interval, or done.
      for (std::size_t c = 0; c < n; ++c) {
        State& k = cranes_[c];
        if (k.leg != nullptr && k.end <= t) {
          k.leg = nullptr;
          k.behind = false;
          if (k.then == nullptr) {
            k.done = true;
          } else {
            k.stop = static_cast<std::size_t>(k.then - work_[c].stops.data());
            k.arrived = k.end;
          }
        }
        // A last rest interval with no leg after it: left as soon as stood.
        if (!k.done && k.leg == nullptr && k.left == 1 && work_[c].stops[k.stop].leg.empty() &&
            k.arrived + work_[c].stops[k.stop].length <= t) {
          out.departures[c].push_back(k.arrived + work_[c].stops[k.stop].length);
          k.end = out.departures[c].back();
          k.left = 0;
          k.done = true;
        }
      }
      if (std::all_of(cranes_.begin(), cranes_.end(), [](const State& k) { return k.done; })) break;
      // The requests standing now, in the keys' order.
      std::vector<std::pair<double, std::size_t>> asking;
      for (std::size_t c = 0; c < n; ++c) {
        const State& k = cranes_[c];
        if (k.done || k.leg != nullptr || k.arrived + work_[c].stops[k.stop].length > t) continue;
        if (k.left == 1 && work_[c].stops[k.stop].leg.empty()) continue;
        asking.emplace_back(keys[c][out.departures[c].size()], c);
      }
      std::sort(asking.begin(), asking.end());
      std::vector<std::size_t> held_back;
      bool moved = false;
      for (const auto& [key, c] : asking) {
        const Stop& stop = work_[c].stops[cranes_[c].stop];
        const Stop* then = cranes_[c].stop + 1 < work_[c].stops.size() ? &work_[c].stops[cranes_[c].stop + 1] : nullptr;
        bool clear = true;
        bool behind = false;
        for (std::size_t o = 0; o < n && clear; ++o) {
          if (o == c) continue;
          const State& other = cranes_[o];
          if (rule_ == HoldRule::behind && other.leg != nullptr && !other.behind && !stop.leg.empty()) {
            // Behind a crane that left on a clear path: its rest box at the end, and whatever it
            // holds against this leg's first interval and rest box at the end, stay out of the way.
            const std::vector<std::size_t> h = held(o);
            const std::vector<LegStep> first(stop.leg.begin(), stop.leg.begin() + 1);
            clear = !meets(c, first, then, o, h) &&
                    (other.then == nullptr || !meets(c, stop.leg, nullptr, o, {other.then->rest}));
            behind = behind || (clear && meets(c, stop.leg, nullptr, o, h));
          } else {
            clear = !meets(c, stop.leg, then, o, held(o));
          }
        }
        for (const std::size_t w : held_back) {
          if (!clear) break;
          const Stop& other = work_[w].stops[cranes_[w].stop];
          const Stop* other_then =
              cranes_[w].stop + 1 < work_[w].stops.size() ? &work_[w].stops[cranes_[w].stop + 1] : nullptr;
          clear = !meets(c, stop.leg, then, w, path(other.leg, other_then));
        }
        if (clear) {
          State& k = cranes_[c];
          out.departures[c].push_back(t);
          start(k, &stop.leg, then, t);
          k.behind = behind;
          --k.left;
          moved = true;
        } else if (reserve) {
          held_back.push_back(c);
        }
      }
      // The next cycle at which what is held or asked changes.
      std::int64_t next = std::numeric_limits<std::int64_t>::max();
      for (std::size_t c = 0; c < n; ++c) {
        const State& k = cranes_[c];
        if (k.done) continue;
        if (k.leg != nullptr) {
          if (k.cur_end > t) next = std::min(next, k.cur_end);
          next = std::min(next, std::max(k.end, t + 1));
        } else {
          const std::int64_t ready = k.arrived + work_[c].stops[k.stop].length;
          if (ready > t) next = std::min(next, ready);
        }
      }
      if (next == std::numeric_limits<std::int64_t>::max()) {
        if (!moved) return false;  // every crane stands, none may leave
        next = t + 1;
      }
      t = next;
    }
    out.cycles = 0;
    for (std::size_t c = 0; c < n; ++c) out.cycles = std::max(out.cycles, cranes_[c].end);
    return true;
  }

 private:
  struct State {
    const std::vector<LegStep>* leg{nullptr};  // moving on it; none: at rest or done
    const Stop* then{nullptr};                 // the rest interval at its end (none: done after it)
    std::size_t cur{0};                        // the interval of `leg` it is in, until cycle cur_end
    std::int64_t cur_end{0}, end{0}, arrived{0};  // end: the cycle its leg ends, waits included
    std::size_t stop{0}, left{0};              // the rest interval it stands in; departures left
    bool behind{false};                        // left behind a moving crane (HoldRule::behind)
    bool done{false};
  };

  static void start(State& k, const std::vector<LegStep>* leg, const Stop* then, std::int64_t t) {
    k.leg = leg;
    k.then = then;
    k.cur = 0;
    k.cur_end = t + (leg->empty() ? 0 : leg->front().to - leg->front().from);
    k.end = t + (leg->empty() ? 0 : leg->back().to);
  }

  // What crane o holds now: at rest its box; moving the rest of its leg (the interval it is in and
  // those after it) and the rest box at its end; done nothing.
  [[nodiscard]] std::vector<std::size_t> held(std::size_t o) const {
    const State& k = cranes_[o];
    if (k.done) return {};
    if (k.leg == nullptr) return {work_[o].stops[k.stop].rest};
    std::vector<std::size_t> h;
    for (std::size_t l = k.cur; l < k.leg->size(); ++l) h.push_back((*k.leg)[l].step);
    if (k.then != nullptr) h.push_back(k.then->rest);
    return h;
  }

  // Whether interval `step` of crane c meets what another crane holds now.
  [[nodiscard]] bool blocked(std::size_t c, std::size_t step) const {
    const std::vector<LegStep> one{{0, 0, step}};
    for (std::size_t o = 0; o < cranes_.size(); ++o) {
      if (o != c && meets(c, one, nullptr, o, held(o))) return true;
    }
    return false;
  }

  [[nodiscard]] static std::vector<std::size_t> path(const std::vector<LegStep>& leg, const Stop* then) {
    std::vector<std::size_t> h;
    for (const LegStep& l : leg) h.push_back(l.step);
    if (then != nullptr) h.push_back(then->rest);
    return h;
  }

  [[nodiscard]] bool meets(std::size_t c, const std::vector<LegStep>& leg, const Stop* then, std::size_t o,
                           const std::vector<std::size_t>& other) const {
    const std::vector<char>& cells = forbidden_[c][o];
    const std::size_t width = work_[o].steps;
    for (const std::size_t h : other) {
      for (const LegStep& l : leg) {
        if (cells[l.step * width + h] != 0) return true;
      }
      if (then != nullptr && cells[then->rest * width + h] != 0) return true;
    }
    return false;
  }

  const std::vector<Work>& work_;
  const std::vector<std::vector<std::vector<char>>>& forbidden_;
  HoldRule rule_;
  std::vector<State> cranes_;
};

SiteSchedule search(const std::vector<std::vector<std::int64_t>>& ends, const std::vector<std::vector<char>>& rest,
                    const std::vector<std::vector<std::vector<char>>>& forbidden, std::uint64_t seed, int tries,
                    HoldRule rule) {
  std::vector<Work> work;
  for (std::size_t c = 0; c < ends.size(); ++c) work.push_back(parse_work(ends[c], rest[c]));
  if (rule == HoldRule::path || rule == HoldRule::behind) {
    Replay replay(work, forbidden, rule);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    SiteSchedule best, found;
    std::vector<std::vector<double>> keys(work.size());
    for (int t = 0; t <= std::max(0, tries); ++t) {
      // The first: the crane listed first goes first, nothing held back; then random keys, every
      // other try holding back behind a waiting request.
      for (std::size_t c = 0; c < work.size(); ++c) {
        keys[c].assign(work[c].stops.size(), static_cast<double>(c));
        if (t > 0) {
          for (double& k : keys[c]) k = uniform(rng);
        }
      }
      if (replay.run(keys, t % 2 == 0 && t > 0, found) && (best.cycles < 0 || found.cycles < best.cycles)) {
        best = found;
      }
    }
    return best;
  }
  Decoder decoder(work, forbidden);
  std::mt19937_64 rng(seed);
  SiteSchedule best;
  const auto better = [&](const SiteSchedule& s) { return best.cycles < 0 || s.cycles < best.cycles; };
  std::vector<std::size_t> order;
  SiteSchedule found;
  for (int t = 0; t <= std::max(0, tries); ++t) {
    // The first order: the soonest departure first; the others wander from it.
    if (!decoder.construct(rng, t == 0 ? 0.0 : 0.3, order, found)) continue;
    if (better(found)) best = found;
    // Neighbours of two cranes swapped, kept when no slower.
    std::int64_t here = found.cycles;
    for (std::size_t swaps = 0; tries > 0 && order.size() > 1 && swaps < 3 * order.size(); ++swaps) {
      const std::size_t p = std::uniform_int_distribution<std::size_t>(0, order.size() - 2)(rng);
      if (order[p] == order[p + 1]) continue;
      std::swap(order[p], order[p + 1]);
      if (decoder.decode(order, found) && found.cycles <= here) {
        here = found.cycles;
        if (better(found)) best = found;
      } else {
        std::swap(order[p], order[p + 1]);
      }
    }
  }
  return best;
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

SiteSchedule search_site_schedule(const SiteLayout& layout, const std::vector<Timeline>& timelines,
                                  std::uint64_t seed, int tries, HoldRule rule) {
  if (timelines.size() != layout.cranes.size()) {
    throw std::invalid_argument("search_site_schedule: " + std::to_string(timelines.size()) + " timelines for " +
                                std::to_string(layout.cranes.size()) + " cranes");
  }
  std::vector<std::vector<std::int64_t>> ends;
  std::vector<std::vector<char>> rest;
  for (std::size_t c = 0; c < timelines.size(); ++c) {
    check(timelines[c], "crane " + std::to_string(c) + "'s", "search_site_schedule");
    ends.push_back({0});
    rest.emplace_back();
    for (const TimelineStep& step : timelines[c].steps) {
      ends.back().push_back(step.end_cycle);
      rest.back().push_back(step.rest ? 1 : 0);
    }
  }
  return internal::search_site_schedule(
      ends, rest,
      [&](std::size_t i, std::size_t k, std::size_t j, std::size_t l) {
        return airspace_distance(layout.cranes[i], timelines[i].steps[k].uses, layout.cranes[j],
                                 timelines[j].steps[l].uses)
                   .distance < layout.margins.slow_down;
      },
      seed, tries, rule);
}

namespace internal {
SiteSchedule search_site_schedule(
    const std::vector<std::vector<std::int64_t>>& ends, const std::vector<std::vector<char>>& rest,
    const std::function<bool(std::size_t, std::size_t, std::size_t, std::size_t)>& forbidden, std::uint64_t seed,
    int tries, HoldRule rule) {
  const std::size_t n = ends.size();
  if (rest.size() != n) {
    throw std::invalid_argument("search_site_schedule: " + std::to_string(n) + " cranes' ends, " +
                                std::to_string(rest.size()) + " cranes' rest flags");
  }
  for (std::size_t c = 0; c < n; ++c) {
    if (ends[c].empty() || ends[c][0] != 0 || rest[c].size() + 1 != ends[c].size()) {
      throw std::invalid_argument("search_site_schedule: crane " + std::to_string(c) +
                                  "'s ends must start at 0 and be one more than its rest flags");
    }
    for (std::size_t k = 1; k < ends[c].size(); ++k) {
      if (ends[c][k] <= ends[c][k - 1]) {
        throw std::invalid_argument("search_site_schedule: crane " + std::to_string(c) + "'s interval " +
                                    std::to_string(k - 1) + " ends at cycle " + std::to_string(ends[c][k]) +
                                    ", not after the one before (" + std::to_string(ends[c][k - 1]) + ")");
      }
    }
  }
  std::vector<std::vector<std::vector<char>>> cells(n, std::vector<std::vector<char>>(n));
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const std::size_t a = rest[i].size(), b = rest[j].size();
      cells[i][j].assign(a * b, 0);
      cells[j][i].assign(b * a, 0);
      for (std::size_t k = 0; k < a; ++k) {
        for (std::size_t l = 0; l < b; ++l) {
          const char f = forbidden(i, k, j, l) ? 1 : 0;
          cells[i][j][k * b + l] = f;
          cells[j][i][l * a + k] = f;
        }
      }
    }
  }
  return search(ends, rest, cells, seed, tries, rule);
}

std::int64_t two_crane_bound(const std::vector<std::int64_t>& x, const std::vector<std::int64_t>& y,
                             const std::vector<char>& forbidden, const std::vector<char>& rest_x,
                             const std::vector<char>& rest_y) {
  return lattice_path(x, y, forbidden, rest_x, rest_y);
}
}  // namespace internal

}  // namespace crane::anti_collision
