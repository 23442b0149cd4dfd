// crane_site_status (deploy/crane site status): what the site service holds and where the cranes
// are, from any host on the site's domain (docs/site.md, "The site service on DDS"). Listens to
// rt/site/status and rt/site/report for --wait seconds (or until SIGINT/SIGTERM) and prints the
// last status: one row per crane of the site file (what the service holds for it, whether a
// request waits, for which cranes, why (held, starving, higher_cable, most_work_left: SiteStatus_'s WAIT_*) and for how
// long, what the crane last reported: at rest or moving, its pose),
// then the service's counters, then the distance between every two cranes that reported: at their
// last reports and the smallest over the listening time (the parts of crane_geometry.hpp at each
// reported pose, the load as its swing envelope; each report pairs with the other crane's latest).
// --json FILE writes the same figures.
//
// --out-of-service CRANE (deploy/crane site out-of-service): the site operator's word that CRANE,
// silent (its host stopped, say), stands braked where it was when it went silent
// (rt/site/command, COMMAND_OUT_OF_SERVICE; the operator's identity on a secured site). It is
// written every 0.5 s until the status shows HOLDING_OUT_OF_SERVICE for the crane, or --wait ends;
// the service logs why it refused (the crane reports, or the service never knew where it was).
//
// Exit status: 0 when a status was heard (and, with --out-of-service, the crane is out of
// service); 1 when none within --wait ("no site service heard on domain 10 within 2 s"); 2 for a
// bad site file or option; 3 when the service did not put the crane out of service within --wait.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>

#include "crane/anti_collision/crane_geometry.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/anti_collision/site_watch.hpp"
#include "crane/anti_collision/site_file.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
using protocol::SiteStatus;

// "tc1,tc3", or "-" for none.
std::string waits_for(const anti_collision::SiteLayout& layout, const SiteStatus& status, std::size_t crane) {
  std::string out;
  for (const auto& name : anti_collision::waits_for_names(layout, status, crane)) out += (out.empty() ? "" : ",") + name;
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
  std::string out_of_service;
  app.add_option("--out-of-service", out_of_service,
                 "the operator's word: this silent crane stands braked where it went silent (the service then "
                 "holds that instead of its whole reach)");
  CLI11_PARSE(app, argc, argv);
  anti_collision::SiteLayout layout;
  std::optional<std::size_t> target;
  try {
    layout = anti_collision::load_site_layout(site_path);
    if (!out_of_service.empty()) {
      for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
        if (layout.cranes[i].name == out_of_service) target = i;
      }
      if (!target) throw std::invalid_argument("--out-of-service " + out_of_service + ": no such crane in " + site_path);
    }
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_site_status: %s\n", error.what());
    return 2;
  }
  try {
    runtime::configure_logging(options.log_level, "crane_site_status");
    if (app.count("--domain") == 0) options.domain_id = static_cast<std::uint32_t>(layout.domain_id);
    // A read-only tool: the monitor role; the operator's when it writes a command.
    if (options.identity.empty()) options.identity = target ? "operator" : "monitor";
    auto participant = runtime::make_participant(options, "crane_site_status");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto reader = participant->make_reader<tp::SiteStatus>(&wakeup);
    auto report_reader = participant->make_recording_reader<tp::SiteReport>(&wakeup, 256);
    const std::size_t n = layout.cranes.size();
    anti_collision::SiteWatch watch(layout);
    std::unique_ptr<transport::Writer<tp::SiteCommand>> command_writer;
    if (target) command_writer = participant->make_writer<tp::SiteCommand>();
    const auto applied = [&] {
      const auto& status = watch.last_status();
      return target && status && *target < status->holding.size() &&
             status->holding[*target] == SiteStatus::HOLDING_OUT_OF_SERVICE;
    };
    auto next_command = Clock::now();
    const auto command_seq = static_cast<std::uint64_t>(runtime::now_nanoseconds());  // new for each run
    const auto start = Clock::now();
    const auto until = start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait));
    const auto take = [&] {
      const double now = std::chrono::duration<double>(Clock::now() - start).count();
      tp::msgs::SiteStatus_ sample;
      while (reader->take_next(sample)) {
        SiteStatus status;
        protocol::from_dds(sample, status);
        watch.status(status, now);
      }
      tp::msgs::SiteReport_ report;
      while (report_reader->take_next(report)) {
        protocol::SiteReport message;
        protocol::from_dds(report, message);
        (void)watch.report(message, now);
      }
    };
    while (Clock::now() < until && !runtime::stop_requested()) {
      take();
      if (target && applied()) break;
      if (command_writer && Clock::now() >= next_command) {
        protocol::SiteCommand command;
        command.header.seq = command_seq;
        command.crane = static_cast<std::uint8_t>(*target);
        command.command = protocol::SiteCommand::COMMAND_OUT_OF_SERVICE;
        tp::msgs::SiteCommand_ out;
        protocol::to_dds(command, out);
        out.header().stamp(runtime::now_stamp());
        command_writer->write(out);
        next_command += std::chrono::milliseconds(500);
      }
      wakeup.wait_until(target ? std::min(until, next_command) : until);
    }
    take();
    const auto& last = watch.last_status();
    const auto& cranes = watch.cranes();
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
    std::printf("%-8s %-12s %-8s %-10s %-12s %-8s %-9s %s\n", "crane", "holding", "request", "waits_for", "why",
                "waited_s", "reported", "slew_deg trolley_m cable_m work_left_s");
    for (std::size_t i = 0; i < n && i < last->holding.size(); ++i) {
      const std::string holding(protocol::code_name(SiteStatus::kCodes, "HOLDING", last->holding[i]));
      const auto& report = cranes[i].report;
      const std::string state = !report ? "-"
                                : report->state == protocol::SiteReport::STATE_MOVING ? "moving"
                                                                                     : "at_rest";
      char pose[128] = "-";
      if (report) {  // and its work left (the rule of the most work left first)
        std::snprintf(pose, sizeof pose, "%8.1f %9.3f %7.3f %11.1f", report->slew * 180.0 / 3.14159265358979323846,
                      report->trolley, report->cable_length, report->work_left);
      }
      // Why it waits for them (a WAIT_* name) and how long its request has waited.
      const std::string why = last->waits_for[i] == 0
                                  ? "-"
                                  : std::string(protocol::code_name(SiteStatus::kCodes, "WAIT", last->wait_reason[i]));
      char waited[32] = "-";
      if (last->pending[i]) std::snprintf(waited, sizeof waited, "%.1f", last->waited[i]);
      std::printf("%-8s %-12s %-8s %-10s %-12s %-8s %-9s %s\n", layout.cranes[i].name.c_str(), holding.c_str(),
                  last->pending[i] ? "waiting" : "-", waits_for(layout, *last, i).c_str(), why.c_str(), waited,
                  state.c_str(), pose);
      nlohmann::json row{{"name", layout.cranes[i].name}, {"holding", holding}, {"reports", cranes[i].reports},
                         {"state", state}, {"waits_for", waits_for(layout, *last, i)}, {"why", why}};
      if (last->pending[i]) row["waited_s"] = last->waited[i];
      if (report) row["work_left_s"] = report->work_left;
      if (cranes[i].reports > 0) {  // [s] since the tool started: the rate is reports over the span
        row["first_report_s"] = cranes[i].first_heard;
        row["last_report_s"] = cranes[i].heard;
      }
      out["cranes"].push_back(std::move(row));
    }
    std::printf("yields %llu, unresolved waits %llu, reports refused %llu\n",
                static_cast<unsigned long long>(last->yields), static_cast<unsigned long long>(last->unresolved),
                static_cast<unsigned long long>(last->reports_rejected));
    for (const auto& pair : watch.distances()) {
      const auto& d = pair.distance;
      const std::string names = layout.cranes[pair.first].name + "-" + layout.cranes[pair.second].name;
      std::printf("%s: %.3f m (%s-%s)\n", names.c_str(), d.distance, anti_collision::to_string(d.first),
                  anti_collision::to_string(d.second));
      out["pairs"].push_back({{"cranes", names}, {"distance_m", d.distance}});
    }
    if (std::isfinite(watch.closest())) {
      std::printf("closest over %.1f s: %.3f m, %s at %.3f s (stop margin %.3f m)\n",
                  std::chrono::duration<double>(Clock::now() - start).count(), watch.closest(),
                  watch.closest_parts().c_str(), watch.closest_time(), layout.margins.stop);
      out["min_distance_m"] = watch.closest();
      out["closest"] = watch.closest_parts() + " at " + std::to_string(watch.closest_time()) + " s";
      // What the two cranes reported then: a late report pairs two moments.
      std::string context;
      for (const auto& report : watch.closest_reports()) {
        const double swing = std::hypot(report.swing_in_plane, report.swing_out_of_plane);
        // The load's swing envelope the distance used (crane_geometry.hpp: L sin A, A the amplitude
        // of the swing with its rate), in every direction of the load's capsule.
        const double envelope = anti_collision::stopping_travel(layout.cranes.at(report.crane),
                                                                anti_collision::motion_of(report),
                                                                anti_collision::StopKind::none)
                                    .swing_radius;
        char text[256];
        std::snprintf(text, sizeof text,
                      "%s%s %s: slew %.3f rad at %.3f rad/s, trolley %.3f m at %.3f m/s, cable %.3f m, swing %.3f rad "
                      "(envelope %.3f m)",
                      context.empty() ? "" : "; ", layout.cranes.at(report.crane).name.c_str(),
                      report.state == protocol::SiteReport::STATE_MOVING ? "moving" : "at rest", report.slew,
                      report.slew_rate, report.trolley, report.trolley_velocity, report.cable_length, swing, envelope);
        context += text;
        out["closest_reports"].push_back({{"crane", layout.cranes.at(report.crane).name},
                                          {"moving", report.state == protocol::SiteReport::STATE_MOVING},
                                          {"slew_rad", report.slew},
                                          {"slew_rate_rad_s", report.slew_rate},
                                          {"trolley_m", report.trolley},
                                          {"trolley_velocity_m_s", report.trolley_velocity},
                                          {"cable_length_m", report.cable_length},
                                          {"swing_rad", swing},
                                          {"swing_envelope_m", envelope}});
      }
      std::printf("  then: %s; the older report heard %.3f s before\n", context.c_str(), watch.closest_apart());
      out["closest_reports_apart_s"] = watch.closest_apart();
    }
    out["yields"] = last->yields;
    out["unresolved"] = last->unresolved;
    out["reports_rejected"] = last->reports_rejected;
    if (!json_path.empty()) std::ofstream(json_path) << out.dump(1) << '\n';
    if (target) {
      if (!applied()) {
        std::fprintf(stderr, "the site service did not put %s out of service within %g s (its log says why: a crane "
                     "that reports, or one it never knew the place of)\n", out_of_service.c_str(), wait);
        return 3;
      }
      std::printf("%s is out of service: the service holds where it stood when it went silent\n", out_of_service.c_str());
    }
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_site_status: %s\n", error.what());
    return 2;
  }
}
