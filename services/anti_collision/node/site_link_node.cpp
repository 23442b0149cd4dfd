// site_link process (issue 34, items 2-4; docs/site.md, "Each crane's site link"): one per crane,
// on the crane's host. It works through the crane's job file (--jobs) under the site service's
// grants: on the crane's domain it reads the state estimate, the planner's reference and move
// status and the supervisor's status, and writes goals to the planner (rt/crane/planner/goal); on
// the site's domain it writes the crane's reports (rt/site/report, 10 Hz and on every change) and
// hears the service's instructions and heartbeat. Translation and wiring only: the crane's side of
// the protocol is anti_collision::CraneSiteLink (crane_site_link.hpp).
//
// It starts once the crane is ready (an estimate heard, and ac::ready_for_site: every stage alive,
// brakes released, no latched fault, its supervisor's guard hearing the site service); before that
// it reports nothing, so the service holds the crane's whole reach.
// A latched supervisor fault afterwards ends its reports and its goals for good (the service then
// holds the crane's whole reach). --summary FILE gets its figures as JSON whenever a job is done
// and at exit (written to FILE.tmp, then renamed). SIGINT/SIGTERM stop it.
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "crane/anti_collision/crane_site_link.hpp"
#include "crane/anti_collision/site_file.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/config/config_document.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/trajectory_planner/trajectory_planner_stage.hpp"

namespace {

using namespace crane;
namespace ac = crane::anti_collision;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
using Status = protocol::SupervisorStatus;

constexpr auto kCycle = std::chrono::milliseconds(10);

void write_summary(const std::string& path, const std::string& name, const ac::CraneSiteLink& link) {
  if (path.empty()) return;
  nlohmann::json j{{"crane", name},
                   {"jobs", link.jobs()},
                   {"jobs_done", link.jobs_done()},
                   {"phase", ac::to_string(link.phase())},
                   {"finish_time_s", link.finish_time()},
                   {"waiting_time_s", link.waiting_time()},
                   {"yields", link.yields()},
                   {"unsettled_moves", link.unsettled_moves()},
                   {"halts", link.halts()},
                   {"halts_at_waypoint", link.halts_at_waypoint()},
                   {"halts_per_axis", link.halts_per_axis()},
                   {"aborted_moves", link.aborted_moves()},
                   {"reactions_s", link.reactions()}};
  const std::string tmp = path + ".tmp";
  std::ofstream(tmp) << j.dump(1) << '\n';
  std::filesystem::rename(tmp, path);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"site_link: a crane's jobs under the site service's grants (docs/site.md)"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  app.remove_option(app.get_option("--config"));  // the site file names the crane's config
  std::string site_path, crane_name, jobs_path, summary_path;
  app.add_option("--site", site_path, "the site file (deploy/config/site_three_towers.yaml)")->required();
  app.add_option("--site-crane", crane_name, "this crane's name in the site file")->required();
  app.add_option("--jobs", jobs_path, "this crane's jobs (CSV, crane_site jobs writes them)")->required();
  app.add_option("--summary", summary_path, "JSON figures, written when a job is done and at exit");
  ac::CraneLinkParams params;
  app.add_option("--dwell", params.dwell, "[s] at the pick and at the place")->check(CLI::Range(0.0, 600.0));
  app.add_option("--slew-acceleration", params.slew_acceleration, "[rad/s^2] of every move")
      ->check(CLI::Range(0.01, 10.0));
  app.add_option("--slew-speed", params.slew_speed, "[rad/s] of every move (0: the crane's rated slew rate)")
      ->check(CLI::Range(0.0, 10.0));
  bool site_lan = false;
  runtime::add_site_network_option(app, site_lan);
  CLI11_PARSE(app, argc, argv);
  try {
    runtime::configure_logging(options.log_level, "site_link");
    const ac::SiteLayout layout = ac::load_site_layout(site_path);
    const int index = ac::find_crane(layout, crane_name);
    if (index < 0) throw std::runtime_error("--site-crane " + crane_name + ": no crane of that name in " + site_path);
    const ac::SiteCrane& me = layout.cranes[static_cast<std::size_t>(index)];
    const auto document = config::ConfigDocument::load(me.config);
    const auto planner = document.read("trajectory_planner", trajectory_planner::read_params);
    params.travel_cable_length = planner.cable_min_length;
    params.rated = planner.manual;
    params.gravity = document.facts().crane.gravity;
    // Its goals count up from a fresh id (one goal a waypoint: far fewer than ten a second).
    ac::CraneSiteLink link(layout, static_cast<std::size_t>(index), params, ac::load_site_jobs(jobs_path),
                           runtime::fresh_request_id());

    if (app.count("--domain") == 0) options.domain_id = static_cast<std::uint32_t>(me.domain_id);
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);
    auto crane_side = runtime::make_participant(options, "site_link");
    auto estimates = crane_side->make_reader<tp::StateEstimate>(nullptr);
    auto references = crane_side->make_reader<tp::Reference>(nullptr);
    auto statuses = crane_side->make_reader<tp::SafetyStatus>(nullptr);
    auto move_statuses = crane_side->make_recording_reader<tp::MoveStatus>(nullptr, 64);
    auto goals = crane_side->make_writer<tp::Goal>();
    auto site_side = runtime::make_participant(
        runtime::site_domain_options(options, static_cast<std::uint32_t>(layout.domain_id), site_lan), "site_link");
    auto reports = site_side->make_writer<tp::SiteReport>();
    auto instructions = site_side->make_recording_reader<tp::SiteInstruction>(nullptr, 64);
    auto site_status = site_side->make_reader<tp::SiteStatus>(nullptr);
    spdlog::info("{} on site '{}' (crane domain {}, site domain {}): {} jobs; waiting for the crane to be ready",
                 crane_name, layout.name, options.domain_id, layout.domain_id, link.jobs());

    const auto start = Clock::now();
    auto next = start;
    std::optional<protocol::CraneState> estimate;
    protocol::Reference reference{};
    std::optional<Status> status;
    bool ready = false;
    double next_report = 0.0;
    std::uint64_t report_seq = 0;
    auto phase = link.phase();
    int jobs_done = -1;
    for (; !runtime::stop_requested(); next += kCycle, std::this_thread::sleep_until(next)) {
      const double now = std::chrono::duration<double>(Clock::now() - start).count();
      tp::msgs::CraneState_ e;
      if (estimates->take_latest(e)) protocol::from_dds(e, estimate.emplace());
      tp::msgs::Reference_ r;
      if (references->take_latest(r)) protocol::from_dds(r, reference);
      tp::msgs::SupervisorStatus_ s;
      if (statuses->take_latest(s)) protocol::from_dds(s, status.emplace());
      tp::msgs::MoveStatus_ m;
      while (move_statuses->take_next(m)) {
        protocol::MoveStatus feedback;
        protocol::from_dds(m, feedback);
        const int aborted = link.aborted_moves();
        link.move_status(feedback, now);
        if (link.aborted_moves() != aborted) {
          spdlog::warn("the planner ended move {} short (result {}, reason {}): sent again once the crane rests, "
                       "{} attempts at a waypoint", feedback.request_id, feedback.result, feedback.reason, ac::kMoveAttempts);
        }
      }
      tp::msgs::SiteStatus_ beat;
      while (site_status->take_next(beat)) link.heard(now);
      tp::msgs::SiteInstruction_ dds_instruction;
      while (instructions->take_next(dds_instruction)) {
        protocol::SiteInstruction message;
        protocol::from_dds(dds_instruction, message);
        ac::SiteOrder order;
        const std::string why = ac::from_message(message, order);
        if (!why.empty()) {
          spdlog::warn("site instruction ignored: {}", why);
          link.heard(now);
          continue;
        }
        if (link.instruction(order, message.epoch, now)) {
          spdlog::info("{} {} (epoch {}, instruction {}) through {} waypoints",
                       order.kind == ac::Instruction::Kind::go ? "granted: go" : "told to yield",
                       order.request_id != 0 ? "request " + std::to_string(order.request_id) : std::string(),
                       message.epoch, order.seq, order.waypoints.size());
        } else {
          link.heard(now);
        }
      }
      if (!ready) {
        ready = estimate && status && ac::ready_for_site(*status);
        if (!ready) continue;
        spdlog::info("the crane is ready: reporting to the site service");
      }
      const bool braked = status->latched_faults != 0;
      if (auto goal = link.step(now, *estimate, reference, braked)) {
        tp::msgs::MoveRequest_ out;
        protocol::to_dds(*goal, out);
        out.header().stamp(runtime::now_stamp());
        goals->write(out);
      }
      if (link.phase() != phase) {
        if (link.phase() == ac::CraneSiteLink::Phase::braked) {
          spdlog::error("the supervisor latched faults 0x{:x}: no more reports or goals (the site service will hold "
                        "this crane's whole reach)", status->latched_faults);
        } else {
          spdlog::info("{} -> {}", ac::to_string(phase), ac::to_string(link.phase()));
        }
        phase = link.phase();
        write_summary(summary_path, crane_name, link);
      }
      if (link.jobs_done() != jobs_done) {
        jobs_done = link.jobs_done();
        spdlog::info("jobs done: {} of {}", jobs_done, link.jobs());
        write_summary(summary_path, crane_name, link);
      }
      const bool changed = link.report_changed();
      if (!changed && now < next_report) continue;
      if (const auto report = link.report()) {
        protocol::SiteReport message{};
        ac::to_message(*report, message);  // its measured motion too, from the estimate of its last step
        message.header.seq = ++report_seq;
        tp::msgs::SiteReport_ out;
        protocol::to_dds(message, out);
        out.header().stamp(runtime::now_stamp());
        reports->write(out);
      }
      next_report = now + ac::kReportPeriod;
    }
    write_summary(summary_path, crane_name, link);
    spdlog::info("site link stopping: {} of {} jobs done", link.jobs_done(), link.jobs());
    return 0;
  } catch (const std::exception& error) {
    spdlog::error("site_link: {}", error.what());
    return 1;
  }
}
