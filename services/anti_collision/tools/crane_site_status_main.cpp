// crane_site_status (deploy/crane site status): what the site service holds and where the cranes
// are, from any host on the site's domain (docs/site.md, "The site service on DDS"). Listens to
// rt/site/status and rt/site/report for --wait seconds (or until SIGINT/SIGTERM) and prints the
// last status: one row per crane of the site file (what the service holds for it, whether a
// request waits and for which cranes, what the crane last reported: at rest or moving, its pose),
// then the service's counters, then the distance between every two cranes that reported: at their
// last reports and the smallest over the listening time (the parts of crane_geometry.hpp at each
// reported pose, the load as its swing envelope; each report pairs with the other crane's latest).
// --json FILE writes the same figures.
//
// Exit status: 0 when a status was heard; 1 when none within --wait ("no site service heard on
// domain 10 within 2 s"); 2 for a bad site file or option.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/site_messages.hpp"

#include "crane/anti_collision/site_file.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
using protocol::SiteStatus;

std::string waits_for(const anti_collision::SiteLayout& layout, std::uint32_t bits) {
  std::string out;
  for (std::size_t j = 0; j < layout.cranes.size() && j < 32; ++j) {
    if ((bits & (std::uint32_t{1} << j)) == 0) continue;
    out += (out.empty() ? "" : ",") + layout.cranes[j].name;
  }
  return out.empty() ? "-" : out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_site_status: what the site service holds, heard on the site's domain (docs/site.md)"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  app.remove_option(app.get_option("--config"));  // no crane's config: the site file gives the names
  options.log_level = "warn";
  std::string site_path;
  app.add_option("--site", site_path, "the site file (deploy/config/site_three_towers.yaml)")->required();
  double wait = 2.0;
  app.add_option("--wait", wait, "seconds to listen (SIGINT ends it sooner)")->check(CLI::Range(0.1, 86400.0));
  std::string json_path;
  app.add_option("--json", json_path, "the figures as JSON");
  CLI11_PARSE(app, argc, argv);
  anti_collision::SiteLayout layout;
  try {
    layout = anti_collision::load_site_layout(site_path);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_site_status: %s\n", error.what());
    return 2;
  }
  try {
    runtime::configure_logging(options.log_level, "crane_site_status");
    if (app.count("--domain") == 0) options.domain_id = static_cast<std::uint32_t>(layout.domain_id);
    runtime::require_site_without_security(options);
    auto participant = runtime::make_participant(options, "crane_site_status");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto reader = participant->make_reader<tp::SiteStatus>(&wakeup);
    auto report_reader = participant->make_recording_reader<tp::SiteReport>(&wakeup, 256);
    const std::size_t n = layout.cranes.size();
    std::optional<SiteStatus> last;
    std::vector<std::optional<protocol::SiteReport>> reports(n);
    std::vector<std::uint64_t> heard(n, 0);
    double closest = std::numeric_limits<double>::infinity();
    std::string closest_parts = "-";
    const auto start = Clock::now();
    const auto until = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait));
    const auto pair_distance = [&](std::size_t i, std::size_t j) {
      const auto a = anti_collision::envelope(layout.cranes[i], anti_collision::motion_of(*reports[i]),
                                              anti_collision::StopKind::none);
      const auto b = anti_collision::envelope(layout.cranes[j], anti_collision::motion_of(*reports[j]),
                                              anti_collision::StopKind::none);
      return anti_collision::distance(a, b);
    };
    const auto take = [&] {
      tp::msgs::SiteStatus_ sample;
      while (reader->take_next(sample)) protocol::from_dds(sample, last.emplace());
      tp::msgs::SiteReport_ report;
      while (report_reader->take_next(report)) {
        if (report.crane() >= n) continue;
        protocol::from_dds(report, reports[report.crane()].emplace());
        ++heard[report.crane()];
        for (std::size_t j = 0; j < n; ++j) {
          if (j == report.crane() || !reports[j]) continue;
          const std::size_t i = std::min<std::size_t>(j, report.crane()), k = std::max<std::size_t>(j, report.crane());
          const auto d = pair_distance(i, k);
          if (d.distance < closest) {
            closest = d.distance;
            closest_parts = layout.cranes[i].name + "." + anti_collision::to_string(d.first) + "-" + layout.cranes[k].name +
                            "." + anti_collision::to_string(d.second) + " at " +
                            std::to_string(std::chrono::duration<double>(Clock::now() - start).count()) + " s";
          }
        }
      }
    };
    while (Clock::now() < until && !runtime::stop_requested()) {
      take();
      wakeup.wait_until(until);
    }
    take();
    if (!last) {
      std::fprintf(stderr, "no site service heard on domain %u within %g s\n", options.domain_id, wait);
      return 1;
    }
    std::printf("site '%s' on domain %u: site service epoch %u, status %llu\n", layout.name.c_str(), options.domain_id,
                last->epoch, static_cast<unsigned long long>(last->header.seq));
    if (last->crane_count != layout.cranes.size()) {
      std::printf("warning: the service has %u cranes, the site file %zu: is it running another site file?\n",
                  last->crane_count, layout.cranes.size());
    }
    nlohmann::json out{{"epoch", last->epoch}, {"cranes", nlohmann::json::array()}, {"pairs", nlohmann::json::array()}};
    std::printf("%-8s %-12s %-8s %-10s %-9s %s\n", "crane", "holding", "request", "waits_for", "reported",
                "slew_deg trolley_m cable_m");
    for (std::size_t i = 0; i < n && i < last->holding.size(); ++i) {
      const std::string holding(protocol::code_name(SiteStatus::kCodes, "HOLDING", last->holding[i]));
      const std::string state = !reports[i] ? "-"
                                : reports[i]->state == protocol::SiteReport::STATE_MOVING ? "moving"
                                                                                         : "at_rest";
      char pose[96] = "-";
      if (reports[i]) {
        std::snprintf(pose, sizeof pose, "%8.1f %9.3f %7.3f", reports[i]->slew * 180.0 / 3.14159265358979323846,
                      reports[i]->trolley, reports[i]->cable_length);
      }
      std::printf("%-8s %-12s %-8s %-10s %-9s %s\n", layout.cranes[i].name.c_str(), holding.c_str(),
                  last->pending[i] ? "waiting" : "-", waits_for(layout, last->waits_for[i]).c_str(), state.c_str(), pose);
      out["cranes"].push_back({{"name", layout.cranes[i].name}, {"holding", holding}, {"reports", heard[i]},
                               {"state", state}});
    }
    std::printf("yields %llu, unresolved waits %llu, reports refused %llu\n",
                static_cast<unsigned long long>(last->yields), static_cast<unsigned long long>(last->unresolved),
                static_cast<unsigned long long>(last->reports_rejected));
    for (std::size_t i = 0; i < n; ++i) {
      for (std::size_t j = i + 1; j < n; ++j) {
        if (!reports[i] || !reports[j]) continue;
        const auto d = pair_distance(i, j);
        std::printf("%s-%s: %.3f m (%s-%s)\n", layout.cranes[i].name.c_str(), layout.cranes[j].name.c_str(), d.distance,
                    anti_collision::to_string(d.first), anti_collision::to_string(d.second));
        out["pairs"].push_back({{"cranes", layout.cranes[i].name + "-" + layout.cranes[j].name}, {"distance_m", d.distance}});
      }
    }
    if (std::isfinite(closest)) {
      std::printf("closest over %.1f s: %.3f m, %s (stop margin %.3f m)\n",
                  std::chrono::duration<double>(Clock::now() - start).count(), closest, closest_parts.c_str(),
                  layout.margins.stop);
      out["min_distance_m"] = closest;
      out["closest"] = closest_parts;
    }
    out["yields"] = last->yields;
    out["unresolved"] = last->unresolved;
    out["reports_rejected"] = last->reports_rejected;
    if (!json_path.empty()) std::ofstream(json_path) << out.dump(1) << '\n';
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_site_status: %s\n", error.what());
    return 2;
  }
}
