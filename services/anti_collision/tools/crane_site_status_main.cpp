// crane_site_status (deploy/crane site status): what the site service holds, from any host on the
// site's domain (docs/site.md, "The site service on DDS"). Listens to rt/site/status for --wait
// seconds and prints the last status: one row per crane of the site file (what the service holds
// for it, whether a request waits and for which cranes), then the service's counters.
//
// Exit status: 0 when a status was heard; 1 when none within --wait ("no site service heard on
// domain 10 within 2 s"); 2 for a bad site file or option.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <optional>
#include <string>

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
  app.add_option("--wait", wait, "seconds to listen for the site service's status")->check(CLI::Range(0.1, 600.0));
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
    auto reader = participant->make_reader<tp::SiteStatus>(&wakeup);
    std::optional<SiteStatus> last;
    const auto until = Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait));
    tp::msgs::SiteStatus_ sample;
    while (Clock::now() < until) {
      while (reader->take_next(sample)) protocol::from_dds(sample, last.emplace());
      wakeup.wait_until(until);
    }
    while (reader->take_next(sample)) protocol::from_dds(sample, last.emplace());
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
    std::printf("%-8s %-12s %-8s %s\n", "crane", "holding", "request", "waits_for");
    for (std::size_t i = 0; i < layout.cranes.size() && i < last->holding.size(); ++i) {
      const auto holding = protocol::code_name(SiteStatus::kCodes, "HOLDING", last->holding[i]);
      std::printf("%-8s %-12s %-8s %s\n", layout.cranes[i].name.c_str(), std::string(holding).c_str(),
                  last->pending[i] ? "waiting" : "-", waits_for(layout, last->waits_for[i]).c_str());
    }
    std::printf("yields %llu, unresolved waits %llu, reports refused %llu\n",
                static_cast<unsigned long long>(last->yields), static_cast<unsigned long long>(last->unresolved),
                static_cast<unsigned long long>(last->reports_rejected));
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_site_status: %s\n", error.what());
    return 2;
  }
}
