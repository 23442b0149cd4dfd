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
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <numbers>
#include <string>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/site_file.hpp"
#include "crane/common/validation.hpp"

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
  std::printf("site '%s': %zu cranes, %zu fixed zones; margins warning %.3f, slow_down %.3f, stop %.3f m; link "
              "deadline %.3f s\n\n",
              site.name.c_str(), site.cranes.size(), site.zones.size(), site.margins.warning, site.margins.slow_down,
              site.margins.stop, site.link_deadline);
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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_site: the site of several cranes (docs/site.md)"};
  app.require_subcommand(1);
  std::string site_path;
  CLI::App* check_command = app.add_subcommand("check", "validate a site file and print its pairs of cranes");
  check_command->add_option("--site", site_path, "the site file (deploy/config/site_three_towers.yaml)")->required();
  CLI11_PARSE(app, argc, argv);
  if (check_command->parsed()) return check(site_path);
  return 1;
}
