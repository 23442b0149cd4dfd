// site_service process (issue 34, item 3; docs/site.md, "The site service on DDS"): the site's
// anti-collision service on the site's own DDS domain (the site file's domain_id unless --domain).
// It reads every crane's reports (rt/site/report), runs anti_collision::SiteService (the protocol
// of site_service.hpp and the rules of site_arbiter.hpp), writes each instruction
// (rt/site/instruction) and, at 10 Hz, its heartbeat and what it holds (rt/site/status). It reads
// the site operator's words (rt/site/command: a silent crane out of service) and logs what came of
// each. It only translates and wires: every rule is in the core.
//
// One thread, paced at kCycle: take the reports, step the core, write. A report that cannot be read
// or that the core refuses is logged (the first of each crane, then every 100th) and counted in the
// status; the service goes on. Its epoch (SiteInstruction_.epoch) is drawn at start, so that a
// restarted service is told from the one before. SIGINT/SIGTERM stop it.
//
// With --memory FILE it remembers, across a crash or a kill, where each crane stood
// (site_memory.hpp, SiteService::memory): it writes the file whenever that changes, before the
// instructions of the same step leave, and at least every kMemoryRefresh; it recalls it at its
// start (SiteService::recall) unless the file is older than --memory-max-age (a site stopped for
// longer may have had its cranes moved by hand). A file that cannot be read or recalled, or is too
// old, is logged, kept as FILE.bad, and the service starts with no memory; a write that fails is
// logged and the service goes on (the memory serves only the operator's word). Each cycle compares
// the memory (a vector of one small entry per crane) with the one written; the JSON and the write
// (with its fdatasync: 0.25 ms mean, 0.5 ms worst of 200 on this machine's ext4) happen only on a
// change, a few times a second, and once a second.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <cstdint>
#include <random>
#include <string>
#include <thread>
#include <vector>

#include "crane/anti_collision/site_file.hpp"
#include "crane/anti_collision/site_memory.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {

using namespace crane;
namespace ac = crane::anti_collision;
namespace tp = transport::topics;

constexpr auto kCycle = std::chrono::milliseconds(10);
constexpr int kStatusEvery = 10;  // cycles: 10 Hz
constexpr double kMemoryRefresh = 1.0;  // [s] the memory file is written at least this often

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

std::uint32_t draw_epoch() {
  std::random_device device;
  std::uint32_t epoch = 0;
  while (epoch == 0) epoch = device();
  return epoch;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"site_service: the site's anti-collision service on the site's DDS domain (docs/site.md)"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  app.remove_option(app.get_option("--config"));  // no crane's config: the site file gives everything
  std::string site_path;
  app.add_option("--site", site_path, "the site file (deploy/config/site_three_towers.yaml)")->required();
  std::string mode_name = "coordinated";
  app.add_option("--mode", mode_name, "coordinated | serialized (one crane at a time in shared airspace)")
      ->check(CLI::IsMember({"coordinated", "serialized"}));
  std::string memory_path;
  app.add_option("--memory", memory_path,
                 "a file to remember where each crane stood across a restart (the operator's word for a crane "
                 "that went silent before it)");
  double memory_max_age = 300.0;
  app.add_option("--memory-max-age", memory_max_age, "[s] a memory file older than this is not recalled")
      ->check(CLI::Range(0.0, 86400.0));
  CLI11_PARSE(app, argc, argv);
  try {
    runtime::configure_logging(options.log_level, "site_service");
    const ac::SiteLayout layout = ac::load_site_layout(site_path);
    if (app.count("--domain") == 0) options.domain_id = static_cast<std::uint32_t>(layout.domain_id);
    const ac::ArbiterMode mode = mode_name == "serialized" ? ac::ArbiterMode::serialized : ac::ArbiterMode::coordinated;
    ac::SiteService service(layout, mode, draw_epoch());
    ac::SiteMemory memory_written;  // as last written to the file
    if (!memory_path.empty()) {
      std::string why;
      try {
        std::error_code error;
        const auto written = std::filesystem::last_write_time(memory_path, error);
        const double age = error ? 0.0
                                 : std::chrono::duration<double>(std::filesystem::file_time_type::clock::now() - written)
                                       .count();
        if (age > memory_max_age) {
          why = memory_path + " was written " + std::to_string(static_cast<long long>(age)) +
                " s ago: older than --memory-max-age " + std::to_string(static_cast<long long>(memory_max_age)) + " s";
        } else if (const auto memory = ac::read_memory_file(memory_path, layout)) {
          why = service.recall(*memory);
          if (why.empty()) spdlog::info("recalled where the cranes stood from {}", memory_path);
        }
      } catch (const std::exception& error) {
        why = error.what();
      }
      if (!why.empty()) {
        const std::string kept = memory_path + ".bad";
        std::rename(memory_path.c_str(), kept.c_str());
        spdlog::error("{}: not recalled, kept as {}; starting with no memory", why, kept);
      }
    }
    std::uint64_t memory_failures = 0;
    double memory_written_at = -kMemoryRefresh;

    auto participant = runtime::make_participant(options, "site_service");
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    // Every crane writes reports: a history deep enough for all of them between two cycles.
    auto reports = participant->make_recording_reader<tp::SiteReport>(&wakeup, 256);
    auto instructions = participant->make_writer<tp::SiteInstruction>();
    auto status_writer = participant->make_writer<tp::SiteStatus>();
    auto commands = participant->make_recording_reader<tp::SiteCommand>(&wakeup, 16);
    spdlog::info("site service for '{}' ({} cranes) on domain {}, {} mode, epoch {}", layout.name, layout.cranes.size(),
                 options.domain_id, mode_name, service.epoch());

    const auto start = std::chrono::steady_clock::now();
    auto next = start;
    std::vector<std::uint64_t> refused(layout.cranes.size() + 1, 0);  // the last slot: unknown cranes
    std::vector<bool> was_heard(layout.cranes.size(), false);
    std::uint64_t status_seq = 0;
    std::uint64_t unreadable = 0;  // reports refused before the core (a count beyond the arrays, a code)
    tp::msgs::SiteReport_ dds_report;
    tp::msgs::SiteCommand_ dds_command;
    for (std::uint64_t cycle = 0; !runtime::stop_requested(); ++cycle) {
      const double now = seconds_since(start);
      while (reports->take_next(dds_report)) {
        protocol::SiteReport message;
        protocol::from_dds(dds_report, message);
        ac::CraneReport report;
        std::string why = ac::from_message(message, report);
        if (!why.empty()) {
          ++unreadable;
        } else {
          why = service.report(report, now);
        }
        if (why.empty()) continue;
        const std::size_t slot = std::min<std::size_t>(message.crane, layout.cranes.size());
        if (refused[slot]++ % 100 == 0) spdlog::warn("{} ({} refused from this sender)", why, refused[slot]);
      }
      while (commands->take_next(dds_command)) {
        protocol::SiteCommand command;
        protocol::from_dds(dds_command, command);
        const std::string crane = command.crane < layout.cranes.size() ? layout.cranes[command.crane].name
                                                                       : std::to_string(command.crane);
        if (command.command != protocol::SiteCommand::COMMAND_OUT_OF_SERVICE) {
          spdlog::warn("operator command {} for crane {}: unknown code {}", command.header.seq, crane,
                       static_cast<unsigned>(command.command));
          continue;
        }
        const std::string why = service.out_of_service(command.crane, now);
        if (why.empty()) {
          spdlog::info("operator: {} out of service, held where it stood when it went silent", crane);
        } else {
          spdlog::warn("operator: {} not put out of service: {}", crane, why);
        }
      }
      const std::vector<ac::SiteOrder> orders = service.step(now);
      if (!memory_path.empty()) {  // before the orders leave: every grant carried out is remembered
        ac::SiteMemory memory = service.memory();
        if (!ac::same_memory(memory, memory_written) || now - memory_written_at >= kMemoryRefresh) {
          try {
            ac::write_memory_file(memory_path, ac::memory_to_json(memory, layout));
            memory_written = std::move(memory);
            memory_written_at = now;
          } catch (const std::exception& error) {
            if (memory_failures++ % 100 == 0) spdlog::error("{} ({} failed writes)", error.what(), memory_failures);
          }
        }
      }
      for (const ac::SiteOrder& order : orders) {
        protocol::SiteInstruction message;
        ac::to_message(order, service.epoch(), message);
        tp::msgs::SiteInstruction_ out;
        protocol::to_dds(message, out);
        out.header().stamp(runtime::now_stamp());
        instructions->write(out);
        spdlog::info("instruction {} to {}: {} through {} waypoints{}", order.seq, layout.cranes[order.crane].name,
                     order.kind == ac::Instruction::Kind::go ? "go" : "yield", order.waypoints.size(),
                     order.request_id != 0 ? " (request " + std::to_string(order.request_id) + ")" : std::string());
      }
      for (std::size_t i = 0; i < was_heard.size(); ++i) {
        const bool heard = service.heard(i, now);
        if (heard != was_heard[i]) {
          spdlog::info("crane {}: {}", layout.cranes[i].name,
                       heard ? "reporting" : "silent past the link deadline: its whole reach is held");
        }
        was_heard[i] = heard;
      }
      if (cycle % kStatusEvery == 0) {
        protocol::SiteStatus message;
        ac::to_message(service, now, message);
        message.reports_rejected += unreadable;
        message.header.seq = ++status_seq;
        tp::msgs::SiteStatus_ out;
        protocol::to_dds(message, out);
        out.header().stamp(runtime::now_stamp());
        status_writer->write(out);
      }
      next += kCycle;
      std::this_thread::sleep_until(next);  // the reports wait in the reader's history
    }
    spdlog::info("site service stopping: {} reports refused, {} moves without a grant, {} yields",
                 service.reports_rejected() + unreadable,
                 service.moves_without_grant(), service.arbiter().yields());
    return 0;
  } catch (const std::exception& error) {
    spdlog::error("site_service: {}", error.what());
    return 1;
  }
}
