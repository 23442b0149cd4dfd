// crane_site: the site of several cranes (services/anti_collision, docs/site.md).
//
//   crane_site check --site FILE
//       reads and validates the site file (exit 2 with the error naming the field, value and bound),
//       then prints one row per pair of cranes: how far apart their masts are, whether their
//       reaches overlap in plan view, which one is higher and the vertical clearance between the
//       higher jib's lowest point and the lower crane's highest point, whether the higher crane's
//       load can pass below the lower jib (a cable against jib conflict), and the distance between
//       the two cranes at rest with the jibs pointed at each other (trolleys and hooks at the
//       positions that bring them closest: the worst static case).
//
//   crane_site demo --site FILE [--sets N] [--jobs J] [--seed S] [--threads T]
//       the simulated site (stack::run_site, every crane with the stack config the site file names):
//       N seeded random job sets of J pick-and-place jobs per
//       crane, each run three ways, coordinated by the site service's rules, serialized (the
//       baseline: one crane at a time in shared airspace) and solo (each crane alone); prints the
//       first set per crane, then over all sets the minimum true distance between any two cranes'
//       parts (its distribution), the total times and their ratios, waits, yields and faults.
//       --faults K injects K random link faults in each coordinated set (stack::random_link_faults)
//       and prints the reaction times; --degraded D, D random degraded links (delay and loss,
//       stack::random_degraded_links); --stopped-hosts H, H cranes' hosts stopped for good
//       (stack::random_host_stops), put out of service by the site operator S s after the stop with
//       --out-of-service-after S; --shared-points P draws jobs that share fewer points;
//       --plant-mismatch L M F runs every crane's plant off its configuration (cable length, load
//       mass and friction factors, in every mode).
//
//   crane_site jobs --site FILE [--jobs J] [--seed S] --out DIR
//       the demo's seeded job set S (the same jobs `demo --sets 1 --seed S` runs) written as one job
//       file per crane, DIR/<crane>.csv, for each crane's site_link (--jobs) on DDS, and DIR/hosts.txt:
//       a line per crane, "name domain_id config start_slew start_trolley" (where the simulated site
//       starts it), for deploy/site_hosts.sh.
#include <CLI/CLI.hpp>

#include <atomic>
#include <thread>
#include <vector>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <numbers>
#include <numeric>
#include <string>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/crane_site_link.hpp"
#include "crane/anti_collision/schedule_bound.hpp"
#include "crane/anti_collision/site_file.hpp"
#include "crane/common/validation.hpp"
#include "crane/stack/maneuver_metrics.hpp"
#include "crane/stack/site_run.hpp"
#include "crane/stack/stack_config.hpp"

namespace {

using namespace crane::anti_collision;

double reach(const SiteCrane& c) { return std::max(c.jib_length, c.counter_jib_length) + jib_radius(c); }

// Both jibs pointed at the other mast, each trolley and hook at the grid point that brings its
// cable and load closest to the other crane: the smallest distance of the static pair.
PairDistance worst_static(const SiteCrane& a, const SiteCrane& b) {
  const auto heading = [](const SiteCrane& from, const SiteCrane& to) {
    return std::atan2(to.base[1] - from.base[1], to.base[0] - from.base[0]) - from.slew_zero_heading;
  };
  PairDistance best{std::numeric_limits<double>::infinity(), Part::jib, Part::jib};
  constexpr int kGrid = 6;
  for (int i = 0; i <= kGrid; ++i) {
    for (int j = 0; j <= kGrid; ++j) {
      CraneMotion ma, mb;
      ma.slew = heading(a, b);
      mb.slew = heading(b, a);
      ma.trolley = a.trolley_min + (a.trolley_max - a.trolley_min) * i / kGrid;
      mb.trolley = b.trolley_min + (b.trolley_max - b.trolley_min) * j / kGrid;
      ma.cable_length = a.jib_height - a.hook_height_min;
      mb.cable_length = b.jib_height - b.hook_height_min;
      const PairDistance d = distance(envelope(a, ma, StopKind::none), envelope(b, mb, StopKind::none));
      if (d.distance < best.distance) best = d;
    }
  }
  return best;
}

int check(const std::string& path) {
  SiteLayout site;
  try {
    site = load_site_layout(path);
  } catch (const crane::common::ConfigError& error) {
    std::cerr << error.what() << "\n";
    return 2;
  }
  std::printf("site '%s' on domain %d: %zu cranes, %zu fixed zones; margins warning %.3f, slow_down %.3f, stop %.3f m; "
              "link deadline %.3f s; max wait %.1f s\n\n",
              site.name.c_str(), site.domain_id, site.cranes.size(), site.zones.size(), site.margins.warning,
              site.margins.slow_down, site.margins.stop, site.link_deadline, site.max_wait);
  std::printf("%-8s %-8s %9s %8s %-8s %12s %14s %20s\n", "crane", "other", "apart_m", "overlap", "higher",
              "clearance_m", "cable_vs_jib", "worst_static_m");
  for (std::size_t i = 0; i < site.cranes.size(); ++i) {
    for (std::size_t j = i + 1; j < site.cranes.size(); ++j) {
      const SiteCrane& a = site.cranes[i];
      const SiteCrane& b = site.cranes[j];
      const double apart = std::hypot(a.base[0] - b.base[0], a.base[1] - b.base[1]);
      const bool overlap = apart < reach(a) + reach(b);
      const SiteCrane& high = jib_bottom(a) >= jib_bottom(b) ? a : b;
      const SiteCrane& low = &high == &a ? b : a;
      const double clearance = jib_bottom(high) - top_of_structure(low);
      // The higher crane's load below the lower crane's jib, somewhere the lower jib sweeps.
      const bool hook_below = high.hook_height_min - high.load_radius < top_of_structure(low);
      const bool hook_reaches = apart - reach(low) < high.trolley_max && apart + reach(low) > high.trolley_min;
      const PairDistance worst = worst_static(a, b);
      char worst_text[64];
      std::snprintf(worst_text, sizeof worst_text, "%.3f (%s-%s)", worst.distance, to_string(worst.first),
                    to_string(worst.second));
      std::printf("%-8s %-8s %9.3f %8s %-8s %12.3f %14s %20s\n", a.name.c_str(), b.name.c_str(), apart,
                  overlap ? "yes" : "no", high.name.c_str(), clearance,
                  overlap && hook_below && hook_reaches ? "yes" : "no", worst_text);
    }
  }
  return 0;
}

// The faults each coordinated set gets (--faults, --degraded, --stopped-hosts).
struct DemoFaults {
  int lost{0};
  int degraded{0};
  int stopped_hosts{0};
  double out_of_service_after{std::numeric_limits<double>::infinity()};  // [s]
};

struct SetResult {
  crane::stack::SiteOutcome coordinated, serialized, solo;
  // [s] --bound: the largest of its pairs' bounds, waiting anywhere and only at rest (NaN: none
  // computed, or at rest a pair with no order: each in the other's way)
  double bound{std::numeric_limits<double>::quiet_NaN()}, bound_at_rest{std::numeric_limits<double>::quiet_NaN()};
  // [s] --bound: the best schedule of whole legs for every crane at once found by search
  // (search_site_schedule; NaN: none computed or none found)
  double searched{std::numeric_limits<double>::quiet_NaN()};
  // [s] the same under the site service's rule (HoldRule::path): a leg waits until its whole path is clear
  double searched_path{std::numeric_limits<double>::quiet_NaN()};
  // [s] the same replayed in one order: each request as soon as its crane stands, none held back
  double replayed{std::numeric_limits<double>::quiet_NaN()};
  // [s] timed, in the order of time: each departure as soon as the legs' timing allows
  double timed_greedy{std::numeric_limits<double>::quiet_NaN()};
  // [s] HoldRule::behind: the service's rule, and a leg may also leave behind a crane that left on a
  // clear path, waiting before what that one still holds; the best order found, and in one order
  double behind_path{std::numeric_limits<double>::quiet_NaN()};
  double behind_replayed{std::numeric_limits<double>::quiet_NaN()};
  std::string error;
};

int demo(const std::string& site_path, int sets, int jobs, std::uint64_t seed, int threads, const DemoFaults& injected,
         const crane::stack::SiteJobDraw& draw, bool bound, const crane::plant::PlantMismatch& mismatch) {
  const int faults = injected.lost;
  const int degraded = injected.degraded;
  using namespace crane::stack;
  SiteLayout site;
  StackConfig config;
  try {
    site = load_site_layout(site_path);
    config = load_site_crane_config(site);
  } catch (const crane::common::ConfigError& error) {
    std::cerr << error.what() << "\n";
    return 2;
  }
  std::vector<SetResult> results(static_cast<std::size_t>(sets));
  std::atomic<int> next{0};
  const auto worker = [&] {
    for (int s = next++; s < sets; s = next++) {
      SetResult& r = results[static_cast<std::size_t>(s)];
      try {
        const auto set = random_site_jobs(site, config, jobs, seed + static_cast<std::uint64_t>(s), draw);
        SiteRunOptions options;
        options.faults = random_link_faults(site, faults, seed + static_cast<std::uint64_t>(s));
        const auto slow = random_degraded_links(site, degraded, seed + static_cast<std::uint64_t>(s));
        options.faults.insert(options.faults.end(), slow.begin(), slow.end());
        options.host_stops = random_host_stops(site, injected.stopped_hosts, seed + static_cast<std::uint64_t>(s));
        for (HostStop& h : options.host_stops) h.out_of_service_after = injected.out_of_service_after;
        options.loss_seed = seed + static_cast<std::uint64_t>(s);
        options.plant_mismatch = mismatch;  // every mode's plants alike
        r.coordinated = run_site(site, config, set, options);
        options.faults.clear();
        options.host_stops.clear();
        options.mode = SiteMode::serialized;
        r.serialized = run_site(site, config, set, options);
        options.mode = SiteMode::solo;
        r.solo = run_site(site, config, set, options);
        // The bound of any order of grants: each pair's, from the cranes' solo timelines.
        if (bound && r.solo.completed) {
          using crane::anti_collision::WaitRule;
          const auto site_bound = [&](WaitRule rule) {
            double worst = 0.0;
            for (std::size_t i = 0; i < site.cranes.size(); ++i) {
              for (std::size_t j = i + 1; j < site.cranes.size(); ++j) {
                const std::int64_t pair = crane::anti_collision::two_crane_bound(
                    site, i, r.solo.cranes[i].timeline, j, r.solo.cranes[j].timeline, rule);
                if (pair < 0) return std::numeric_limits<double>::quiet_NaN();
                worst = std::max(worst, config.facts.sample_period * static_cast<double>(pair));
              }
            }
            return worst;
          };
          r.bound = site_bound(WaitRule::anywhere);
          r.bound_at_rest = site_bound(WaitRule::at_rest);
          std::vector<crane::anti_collision::Timeline> timelines;
          for (const auto& c : r.solo.cranes) timelines.push_back(c.timeline);
          const auto found = crane::anti_collision::search_site_schedule(site, timelines,
                                                                         seed + static_cast<std::uint64_t>(s));
          if (found.cycles >= 0) r.searched = config.facts.sample_period * static_cast<double>(found.cycles);
          const auto path = crane::anti_collision::search_site_schedule(
              site, timelines, seed + static_cast<std::uint64_t>(s), 200, crane::anti_collision::HoldRule::path);
          if (path.cycles >= 0) r.searched_path = config.facts.sample_period * static_cast<double>(path.cycles);
          const auto first = crane::anti_collision::search_site_schedule(
              site, timelines, seed + static_cast<std::uint64_t>(s), 0, crane::anti_collision::HoldRule::path);
          if (first.cycles >= 0) r.replayed = config.facts.sample_period * static_cast<double>(first.cycles);
          const auto greedy = crane::anti_collision::search_site_schedule(
              site, timelines, seed + static_cast<std::uint64_t>(s), 0, crane::anti_collision::HoldRule::timed);
          if (greedy.cycles >= 0) r.timed_greedy = config.facts.sample_period * static_cast<double>(greedy.cycles);
          const auto behind = crane::anti_collision::search_site_schedule(
              site, timelines, seed + static_cast<std::uint64_t>(s), 200, crane::anti_collision::HoldRule::behind);
          if (behind.cycles >= 0) r.behind_path = config.facts.sample_period * static_cast<double>(behind.cycles);
          const auto behind_first = crane::anti_collision::search_site_schedule(
              site, timelines, seed + static_cast<std::uint64_t>(s), 0, crane::anti_collision::HoldRule::behind);
          if (behind_first.cycles >= 0) {
            r.behind_replayed = config.facts.sample_period * static_cast<double>(behind_first.cycles);
          }
        }
      } catch (const std::exception& error) {
        r.error = error.what();
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 0; t < std::max(1, threads); ++t) pool.emplace_back(worker);
  for (auto& t : pool) t.join();

  const SetResult& first = results[0];
  if (!first.error.empty()) {
    std::cerr << "set 0: " << first.error << "\n";
    return 1;
  }
  std::printf("site '%s', %d set(s) of %d job(s) per crane, seeds %llu..%llu", site.name.c_str(), sets, jobs,
              static_cast<unsigned long long>(seed), static_cast<unsigned long long>(seed + sets - 1));
  if (draw.others_clear) {  // --shared-points
    std::printf("; points within another crane's reach with probability %.2f, the others clear of every other jib",
                draw.shared_probability);
  }
  if (mismatch.cable_length_factor != 1.0 || mismatch.load_mass_factor != 1.0 || mismatch.friction_factor != 1.0) {
    std::printf("; every crane's plant off its configuration: cable length x%.2f, load mass x%.2f, friction x%.2f",
                mismatch.cable_length_factor, mismatch.load_mass_factor, mismatch.friction_factor);
  }
  std::printf("\n\n");
  std::printf("set 0 (seed %llu):\n%-12s %-6s %5s %10s %10s %7s %10s %7s\n", static_cast<unsigned long long>(seed),
              "mode", "crane", "jobs", "finish_s", "waiting_s", "yields", "unsettled", "faults");
  for (const auto* o : {&first.coordinated, &first.serialized, &first.solo}) {
    const char* mode = o == &first.coordinated ? "coordinated" : o == &first.serialized ? "serialized" : "solo";
    for (const auto& c : o->cranes) {
      std::printf("%-12s %-6s %5d %10.1f %10.1f %7d %10d %7u\n", mode, c.name.c_str(), c.jobs_done, c.finish_time,
                  c.waiting_time, c.yields, c.unsettled_moves, c.latched_faults);
    }
    std::printf("%-12s %-6s %5s %10.1f   min distance %.3f m (%s)\n", mode, "site", "", o->total_time,
                o->min_distance, o->closest.c_str());
  }

  std::vector<double> min_distance, serial_min, vs_serialized, vs_solo, searched_vs_rest;
  double worst_vs_solo = 0.0;  // and its set's seed, to trace it alone (--sets 1 --seed)
  std::uint64_t worst_vs_solo_seed = 0;
  // One row of --bound: per set, the schedule's total time / solo, and the site's / the schedule's.
  struct Ratios {
    std::vector<double> vs_solo, of;
    void add(double schedule, const SetResult& r) {
      if (std::isnan(schedule)) return;
      vs_solo.push_back(schedule / r.solo.total_time);
      of.push_back(r.coordinated.total_time / schedule);
    }
  };
  Ratios anywhere, at_rest, searched, path, replayed, greedy, behind, behind_replayed;
  int no_rest_order = 0, none_searched = 0, none_path = 0;
  int failed = 0, incomplete = 0, faulted = 0;
  std::uint64_t unresolved = 0;
  int yields = 0;
  double waiting = 0.0, simulated = 0.0;
  for (const SetResult& r : results) {
    if (!r.error.empty()) {
      ++failed;
      std::cerr << "a set failed: " << r.error << "\n";
      continue;
    }
    for (const auto* o : {&r.coordinated, &r.serialized, &r.solo}) {
      if (!o->completed) ++incomplete;
      for (const auto& c : o->cranes) faulted += c.latched_faults != 0 ? 1 : 0;
      simulated += o->simulated_seconds;
      if (!o->completed || std::any_of(o->cranes.begin(), o->cranes.end(), [](const auto& c) { return c.latched_faults != 0; })) {
        const char* mode = o == &r.coordinated ? "coordinated" : o == &r.serialized ? "serialized" : "solo";
        std::fprintf(stderr, "set seed %llu, %s:%s", static_cast<unsigned long long>(seed + (&r - results.data())), mode,
                     o->completed ? "" : " incomplete;");
        for (const auto& c : o->cranes) {
          std::fprintf(stderr, " %s %d jobs, faults 0x%x%s%s", c.name.c_str(), c.jobs_done, c.latched_faults,
                       std::isnan(c.host_stopped_at) ? "" : " (its host stopped)", c.stuck ? " (stuck)" : "");
        }
        std::fprintf(stderr, "\n");
      }
      for (const auto& c : o->cranes) {
        if (c.out_of_service_refused.empty()) continue;
        std::fprintf(stderr, "set seed %llu, %s: %s not put out of service: %s\n",
                     static_cast<unsigned long long>(seed + (&r - results.data())),
                     o == &r.coordinated ? "coordinated" : o == &r.serialized ? "serialized" : "solo", c.name.c_str(),
                     c.out_of_service_refused.c_str());
      }
    }
    min_distance.push_back(r.coordinated.min_distance);
    serial_min.push_back(r.serialized.min_distance);
    // The time ratios of the sets that every mode completed (a crane braked by its guard leaves
    // its jobs undone: no total time to compare; so does a stopped host).
    if (r.coordinated.completed && r.serialized.completed && r.solo.completed && r.coordinated.stopped_hosts == 0) {
      vs_serialized.push_back(r.coordinated.total_time / r.serialized.total_time);
      vs_solo.push_back(r.coordinated.total_time / r.solo.total_time);
      if (vs_solo.back() > worst_vs_solo) worst_vs_solo = vs_solo.back(), worst_vs_solo_seed = seed + (&r - results.data());
      if (!std::isnan(r.bound)) {
        anywhere.add(r.bound, r);
        at_rest.add(r.bound_at_rest, r);
        no_rest_order += std::isnan(r.bound_at_rest) ? 1 : 0;
        searched.add(r.searched, r);
        none_searched += std::isnan(r.searched) ? 1 : 0;
        if (!std::isnan(r.searched) && !std::isnan(r.bound_at_rest)) searched_vs_rest.push_back(r.searched / r.bound_at_rest);
        path.add(r.searched_path, r);
        none_path += std::isnan(r.searched_path) ? 1 : 0;
        greedy.add(r.timed_greedy, r);
        replayed.add(r.replayed, r);
        behind.add(r.behind_path, r);
        behind_replayed.add(r.behind_replayed, r);
      }
    }
    unresolved += r.coordinated.unresolved + r.serialized.unresolved;
    for (const auto& c : r.coordinated.cranes) yields += c.yields, waiting += c.waiting_time;
  }
  std::printf("\nover %zu set(s) (%d failed, %d runs incomplete, %d cranes with a supervisor fault, %llu unresolved "
              "waits; %.0f crane-seconds simulated)\n",
              min_distance.size(), failed, incomplete, faulted, static_cast<unsigned long long>(unresolved), simulated);
  std::printf("  min distance, coordinated [m]: min %.3f  p1 %.3f  p10 %.3f  median %.3f  (stop margin %.3f)\n",
              crane::stack::nearest_rank_quantile(min_distance, 0.0), crane::stack::nearest_rank_quantile(min_distance, 0.01), crane::stack::nearest_rank_quantile(min_distance, 0.1),
              crane::stack::nearest_rank_quantile(min_distance, 0.5), site.margins.stop);
  std::printf("  min distance, serialized [m]:  min %.3f  median %.3f\n", crane::stack::nearest_rank_quantile(serial_min, 0.0),
              crane::stack::nearest_rank_quantile(serial_min, 0.5));
  std::printf("  total time coordinated / serialized (%zu sets every mode completed): median %.3f  worst %.3f  best %.3f\n",
              vs_serialized.size(), crane::stack::nearest_rank_quantile(vs_serialized, 0.5),
              crane::stack::nearest_rank_quantile(vs_serialized, 1.0), crane::stack::nearest_rank_quantile(vs_serialized, 0.0));
  std::printf("  total time coordinated / solo:       median %.3f  p90 %.3f  worst %.3f  best %.3f", crane::stack::nearest_rank_quantile(vs_solo, 0.5),
              crane::stack::nearest_rank_quantile(vs_solo, 0.9), crane::stack::nearest_rank_quantile(vs_solo, 1.0),
              crane::stack::nearest_rank_quantile(vs_solo, 0.0));
  if (!vs_solo.empty()) std::printf("  (the worst: set seed %llu)", static_cast<unsigned long long>(worst_vs_solo_seed));
  std::printf("\n");
  const auto print_bound = [](const char* what, const Ratios& row) {
    using crane::stack::nearest_rank_quantile;
    const std::vector<double>& vs_solo_of = row.vs_solo;
    const std::vector<double>& of = row.of;
    std::printf("  %s: bound / solo median %.3f  worst %.3f  best %.3f; coordinated / bound median %.3f  worst %.3f  "
                "best %.3f  (%zu sets)\n",
                what, nearest_rank_quantile(vs_solo_of, 0.5), nearest_rank_quantile(vs_solo_of, 1.0),
                nearest_rank_quantile(vs_solo_of, 0.0), nearest_rank_quantile(of, 0.5), nearest_rank_quantile(of, 1.0),
                nearest_rank_quantile(of, 0.0), of.size());
  };
  if (!anywhere.of.empty()) {
    std::printf("  the bound of any order of grants (--bound: each pair of cranes on Akers' plane, from their solo "
                "runs; docs/site.md):\n");
    print_bound("waiting anywhere (any order, any cut of the legs)", anywhere);
    print_bound("waiting at rest between legs (the site's whole legs)", at_rest);
    if (!searched.of.empty()) {
      std::printf("  every crane at once, whole legs (the best schedule a search found from the solo runs: the best "
                  "order of whole legs needs at most this, each leg as long as alone):\n");
      print_bound("found", searched);
      std::printf("    found / the pairs' bound at rest: median %.3f  worst %.3f  best %.3f  (%zu sets; at least 1: "
                  "the pairs miss the other cranes, the search may miss the best)\n",
                  crane::stack::nearest_rank_quantile(searched_vs_rest, 0.5),
                  crane::stack::nearest_rank_quantile(searched_vs_rest, 1.0),
                  crane::stack::nearest_rank_quantile(searched_vs_rest, 0.0), searched_vs_rest.size());
    }
    if (!greedy.of.empty()) {
      std::printf("  the same timed, in the order of time (each leg as soon as the legs' timing allows):\n");
      print_bound("found", greedy);
    }
    if (!path.of.empty()) {
      std::printf("  the same under the service's rule (a leg waits until its whole path is clear of what the others "
                  "hold), the best order found:\n");
      print_bound("found", path);
      std::printf("  the same replayed in one order (each crane asking as soon as it stands, the first listed first, "
                  "none held back):\n");
      print_bound("replayed", replayed);
    }
    if (!behind.of.empty()) {
      std::printf("  the service's rule, and a leg may leave behind a crane that left on a clear path, waiting before "
                  "what it still holds (HoldRule::behind; the waits cost no time), the best order found:\n");
      print_bound("found", behind);
      std::printf("  the same replayed in one order:\n");
      print_bound("replayed", behind_replayed);
    }
    if (none_searched + none_path > 0) {
      std::printf("  (sets with no schedule found: %d timed, %d under the service's rule)\n", none_searched, none_path);
    }
    if (no_rest_order > 0) {
      std::printf("  (%d sets with no order at rest: two cranes in each other's way, which the site resolves by a "
                  "yield)\n", no_rest_order);
    }
  }
  int slow = 0, stops = 0, emergency = 0;
  for (const SetResult& r : results) {
    slow += r.coordinated.watch_slow_downs, stops += r.coordinated.watch_stops, emergency += r.coordinated.watch_emergency_stops;
  }
  std::printf("  distance-watching rule on the coordinated runs (counted, not applied): %d slow-downs, %d stops, %d "
              "emergency stops\n", slow, stops, emergency);
  std::vector<double> reactions;
  int halts = 0, at_waypoint = 0, per_axis = 0;
  std::string longest_reaction;
  double longest_reaction_seconds = 0.0;
  for (std::size_t s = 0; s < results.size(); ++s) {
    const SetResult& r = results[s];
    reactions.insert(reactions.end(), r.coordinated.reactions.begin(), r.coordinated.reactions.end());
    halts += r.coordinated.halts;
    at_waypoint += r.coordinated.halts_at_waypoint;
    per_axis += r.coordinated.halts_per_axis;
    if (r.coordinated.longest_reaction_seconds > longest_reaction_seconds) {
      longest_reaction_seconds = r.coordinated.longest_reaction_seconds;
      longest_reaction = "set seed " + std::to_string(seed + s) + ", " + r.coordinated.longest_reaction;
    }
  }
  if (faults > 0) {
    std::printf("  link faults: %d per coordinated set (a crane's link lost 0.5-30 s, or the site service killed and "
                "restarted after 0.5-10 s); %zu link losses past the %.3f s deadline, %d stops (%d of them of some axes, "
                "the others on to the waypoint, and %d at the waypoint: a soft stop would have left the grant)\n",
                faults, reactions.size(), site.link_deadline, halts, per_axis, at_waypoint);
  }
  if (!reactions.empty()) {  // with --degraded alone too: a late message past the deadline is a loss
    std::printf("  reaction, link lost -> crane at rest or on a path outside shared airspace (%zu losses) [ms]: min %.0f  "
                "median %.0f  p90 %.0f  p99 %.0f  max %.0f\n", reactions.size(),
                1e3 * crane::stack::nearest_rank_quantile(reactions, 0.0), 1e3 * crane::stack::nearest_rank_quantile(reactions, 0.5), 1e3 * crane::stack::nearest_rank_quantile(reactions, 0.9),
                1e3 * crane::stack::nearest_rank_quantile(reactions, 0.99), 1e3 * crane::stack::nearest_rank_quantile(reactions, 1.0));
    if (!longest_reaction.empty()) std::printf("  the longest: %s\n", longest_reaction.c_str());
  }
  if (degraded > 0) {
    std::uint64_t delayed = 0, resent = 0;
    for (const SetResult& r : results) delayed += r.coordinated.delayed_messages, resent += r.coordinated.resent_messages;
    std::printf("  degraded links: %d per coordinated set (a crane's link, or the site service's host, for 5-30 s: "
                "0-200 ms each way, 0-30 %% of the messages lost and sent again %.0f ms later); %llu messages delayed, "
                "%llu of them sent again\n",
                degraded, 1e3 * crane::stack::kResendDelay, static_cast<unsigned long long>(delayed),
                static_cast<unsigned long long>(resent));
  }
  if (injected.stopped_hosts > 0) {
    std::vector<double> rest;
    int stopped = 0, stuck = 0, left = 0, total = 0, stopped_left = 0, put_out = 0, refused = 0;
    for (const SetResult& r : results) {
      stopped += r.coordinated.stopped_hosts;
      for (std::size_t i = 0; i < r.coordinated.cranes.size(); ++i) {
        const auto& c = r.coordinated.cranes[i];
        total += jobs;
        if (!std::isnan(c.host_stopped_at)) {
          stopped_left += jobs - c.jobs_done;
          put_out += std::isnan(c.out_of_service_at) ? 0 : 1;
          refused += c.out_of_service_refused.empty() ? 0 : 1;
          if (!std::isnan(c.rest_after_host_stop)) rest.push_back(c.rest_after_host_stop);
          continue;
        }
        stuck += c.stuck ? 1 : 0;
        left += jobs - c.jobs_done;
      }
    }
    std::printf("  stopped hosts: %d per coordinated set (a crane's host stopped for good in the first 80 s); %d stopped, "
                "%zu of their cranes at rest after it [ms]: min %.0f  median %.0f  max %.0f; %d jobs of %d left undone "
                "by the stopped cranes and %d by the %d other cranes stuck waiting %.0f s for their reach\n",
                injected.stopped_hosts, stopped, rest.size(), 1e3 * crane::stack::nearest_rank_quantile(rest, 0.0),
                1e3 * crane::stack::nearest_rank_quantile(rest, 0.5), 1e3 * crane::stack::nearest_rank_quantile(rest, 1.0),
                stopped_left, total, left, stuck, crane::stack::kStuckWait);
    if (std::isfinite(injected.out_of_service_after)) {
      std::printf("  out of service: the site operator's word %.0f s after each stop; %d of the %d stopped cranes put "
                  "out of service, %d refused (stderr says why), %d not given (the run ended first, or the service was "
                  "down for the word's %.0f s)\n",
                  injected.out_of_service_after, put_out, stopped, refused, stopped - put_out - refused,
                  crane::stack::kWordWindow);
    }
  }
  int guard_emergency = 0, guard_soft = 0;
  std::string guard_first;
  for (const SetResult& r : results) {
    guard_emergency += r.coordinated.guard_emergency_stops, guard_soft += r.coordinated.guard_soft_stops;
    if (guard_first.empty() && !r.coordinated.guard_first.empty()) guard_first = r.coordinated.guard_first;
  }
  std::printf("  each crane's guard on its grant, coordinated runs: %d cranes braked (leaving their grant), %d cycles "
              "asking for a soft stop for the swing (counted, not applied)%s%s\n",
              guard_emergency, guard_soft, guard_first.empty() ? "" : "; first: ", guard_first.c_str());
  std::printf("  coordinated: %d yields, %.1f s waiting per set\n", yields,
              min_distance.empty() ? 0.0 : waiting / static_cast<double>(min_distance.size()));
  // Where the waits go: what the cranes waited for were doing (SiteOutcome::waited_for).
  std::array<double, CraneSiteLink::kActivityCount> waited_for{};
  double waited_for_none = 0.0, waited_for_stopped = 0.0;
  for (const SetResult& r : results) {
    if (!r.error.empty()) continue;
    for (std::size_t a = 0; a < waited_for.size(); ++a) waited_for[a] += r.coordinated.waited_for[a];
    waited_for_none += r.coordinated.waited_for_none;
    waited_for_stopped += r.coordinated.waited_for_stopped_host;
  }
  const double asked = std::accumulate(waited_for.begin(), waited_for.end(), waited_for_none + waited_for_stopped);
  if (asked > 0.0) {
    std::printf("  coordinated waits, by what the crane waited for was doing [%% of %.0f crane-seconds]:", asked);
    for (std::size_t a = 0; a < waited_for.size(); ++a) {
      std::printf(" %s %.1f,", to_string(static_cast<CraneSiteLink::Activity>(a)), 100.0 * waited_for[a] / asked);
    }
    std::printf(" no crane (the request or the go on their way, the service down) %.1f", 100.0 * waited_for_none / asked);
    if (waited_for_stopped > 0.0) std::printf(", a stopped host %.1f", 100.0 * waited_for_stopped / asked);
    std::printf("\n");
  }
  // Why the service had them wait (SiteOutcome::waited_why): the rules' own share of the waiting.
  std::array<double, kWaitReasonCount> waited_why{};
  for (const SetResult& r : results) {
    if (!r.error.empty()) continue;
    for (std::size_t w = 0; w < waited_why.size(); ++w) waited_why[w] += r.coordinated.waited_why[w];
  }
  const double asked_why = std::accumulate(waited_why.begin(), waited_why.end(), 0.0);
  if (asked_why > 0.0) {
    std::printf("  coordinated waits, by why [%% of %.0f crane-seconds]: its path meets what they hold %.1f, "
                "a starving request's path (rule 0) %.1f, the most work left's path (rule 0) %.1f, its jib gives "
                "way to a higher cable (rule 2) %.1f, no crane %.1f\n",
                asked_why, 100.0 * waited_why[static_cast<std::size_t>(WaitReason::held)] / asked_why,
                100.0 * waited_why[static_cast<std::size_t>(WaitReason::starving)] / asked_why,
                100.0 * waited_why[static_cast<std::size_t>(WaitReason::most_work_left)] / asked_why,
                100.0 * waited_why[static_cast<std::size_t>(WaitReason::higher_cable)] / asked_why,
                100.0 * waited_why[static_cast<std::size_t>(WaitReason::none)] / asked_why);
  }
  const bool safe = !min_distance.empty() && crane::stack::nearest_rank_quantile(min_distance, 0.0) >= site.margins.stop;
  return failed == 0 && incomplete == 0 && faulted == 0 && safe ? 0 : 1;
}

int write_jobs(const std::string& path, int jobs, std::uint64_t seed, const std::string& out) {
  try {
    const SiteLayout site = load_site_layout(path);
    const auto config = crane::stack::load_site_crane_config(site);
    const auto sets = crane::stack::random_site_jobs(site, config, jobs, seed);
    std::filesystem::create_directories(out);
    std::ofstream hosts(std::filesystem::path(out) / "hosts.txt");
    for (std::size_t i = 0; i < site.cranes.size(); ++i) {
      const SiteCrane& c = site.cranes[i];
      const std::string file = (std::filesystem::path(out) / (c.name + ".csv")).string();
      write_site_jobs(file, sets[i]);
      std::printf("%s: %zu jobs -> %s\n", c.name.c_str(), sets[i].size(), file.c_str());
      // Where it starts: where the simulated site starts it (site_start_pose).
      const Pose start = site_start_pose(site, i, config.trajectory_planner.slew_min_angle,
                                         config.trajectory_planner.slew_max_angle,
                                         config.trajectory_planner.trolley_min_position + 0.1);
      char line[512];
      std::snprintf(line, sizeof line, "%s %d %s %.17g %.17g\n", c.name.c_str(), c.domain_id, c.config.c_str(), start.slew,
                    start.trolley);
      hosts << line;
    }
    if (!hosts) throw std::runtime_error("cannot write " + out + "/hosts.txt");
    return 0;
  } catch (const std::exception& error) {
    std::cerr << error.what() << "\n";
    return 2;
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_site: the site of several cranes (docs/site.md)"};
  app.require_subcommand(1);
  std::string site_path;
  CLI::App* check_command = app.add_subcommand("check", "validate a site file and print its pairs of cranes");
  check_command->add_option("--site", site_path, "the site file (deploy/config/site_three_towers.yaml)")->required();
  int sets = 10, jobs = 3, threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  std::uint64_t seed = 1;
  CLI::App* demo_command = app.add_subcommand("demo", "the simulated site: seeded job sets, coordinated vs serialized vs solo");
  demo_command->add_option("--site", site_path, "the site file")->required();
  demo_command->add_option("--sets", sets, "job sets")->check(CLI::Range(1, 100000));
  demo_command->add_option("--jobs", jobs, "pick-and-place jobs per crane and set")->check(CLI::Range(1, 100));
  demo_command->add_option("--seed", seed, "the first set's seed");
  demo_command->add_option("--threads", threads, "sets run in parallel")->check(CLI::Range(1, 256));
  DemoFaults injected;
  demo_command->add_option("--faults", injected.lost, "link faults injected in each coordinated set")->check(CLI::Range(0, 20));
  demo_command->add_option("--degraded", injected.degraded, "degraded links (delay, loss) in each coordinated set")
      ->check(CLI::Range(0, 20));
  demo_command->add_option("--stopped-hosts", injected.stopped_hosts, "cranes' hosts stopped for good in each coordinated set")
      ->check(CLI::Range(0, 20));
  demo_command
      ->add_option("--out-of-service-after", injected.out_of_service_after,
                   "seconds after a host's stop when the site operator puts its crane out of service (default: never)")
      ->check(CLI::Range(0.01, 3600.0));
  crane::stack::SiteJobDraw draw;
  CLI::Option* shared_option =
      demo_command
          ->add_option("--shared-points", draw.shared_probability,
                       "probability that a pick or place point lies within another crane's reach, the others then "
                       "clear of every other crane's jib (default: 0.7, the others anywhere: the jobs of docs/site.md)")
          ->check(CLI::Range(0.0, 1.0));
  std::vector<double> plant_mismatch;
  demo_command
      ->add_option("--plant-mismatch", plant_mismatch,
                   "every crane's simulated plant off its configuration, in every mode (crane_sim's --mismatch): cable "
                   "length, load mass and friction factors (default: 1 1 1)")
      ->expected(3)
      ->check(CLI::Range(0.1, 10.0));
  bool bound = false;
  demo_command->add_flag("--bound", bound,
                         "also the bound of any order of grants, from the solo runs (about 13 s of CPU a set more)");
  std::string out;
  CLI::App* jobs_command = app.add_subcommand("jobs", "a seeded job set written as one job file per crane (site_link --jobs)");
  jobs_command->add_option("--site", site_path, "the site file")->required();
  jobs_command->add_option("--jobs", jobs, "pick-and-place jobs per crane")->check(CLI::Range(1, 100));
  jobs_command->add_option("--seed", seed, "the set's seed (as crane_site demo's)");
  jobs_command->add_option("--out", out, "the folder for <crane>.csv")->required();
  CLI11_PARSE(app, argc, argv);
  if (check_command->parsed()) return check(site_path);
  if (jobs_command->parsed()) return write_jobs(site_path, jobs, seed, out);
  if (demo_command->parsed()) {
    draw.others_clear = shared_option->count() > 0;
    const crane::plant::PlantMismatch mismatch =
        plant_mismatch.empty() ? crane::plant::PlantMismatch{} : crane::plant::mismatch_from_factors(plant_mismatch);
    return demo(site_path, sets, jobs, seed, threads, injected, draw, bound, mismatch);
  }
  return 1;
}
