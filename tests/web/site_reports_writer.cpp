// The cranes of a site as the site page's test plays them (tests/web/site_page_test.sh): on the
// site's domain, every 100 ms, one report per crane named with --at: at rest at its pose, and,
// for a crane named with --ask, a request for a leg from there (hook up at the pose's cable
// length, to the slew and trolley asked, down to the cable length asked), with the work left a
// crane named with --work reports (0 for the others). It obeys nothing; the
// site service grants or holds as it would for real cranes. Ends on SIGINT/SIGTERM or after
// --seconds.
//
//   site_reports_writer --site F --at tc1:SLEW:TROLLEY:CABLE ... [--ask tc1:SLEW:TROLLEY:CABLE]
//                       [--work tc1:SECONDS ...] [--seconds S]
//   (SLEW in rad, TROLLEY and CABLE in m)
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "crane/anti_collision/site_file.hpp"
#include "crane/anti_collision/site_messages.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace {

using namespace crane;
namespace ac = anti_collision;
namespace tp = transport::topics;

// "tc1:0.5:0.6:0.2" -> ("tc1", pose); throws std::invalid_argument naming the text.
std::pair<std::string, ac::Pose> parse(const std::string& text) {
  std::stringstream in(text);
  std::string name, a, b, c;
  if (!std::getline(in, name, ':') || !std::getline(in, a, ':') || !std::getline(in, b, ':') || !std::getline(in, c)) {
    throw std::invalid_argument("'" + text + "' is not NAME:SLEW:TROLLEY:CABLE");
  }
  return {name, {std::stod(a), std::stod(b), std::stod(c)}};
}

std::size_t index_of(const ac::SiteLayout& layout, const std::string& name) {
  for (std::size_t i = 0; i < layout.cranes.size(); ++i) {
    if (layout.cranes[i].name == name) return i;
  }
  throw std::invalid_argument("no crane '" + name + "' on site '" + layout.name + "'");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"site_reports_writer: cranes' reports for the site page's test"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  app.remove_option(app.get_option("--config"));
  std::string site_path;
  app.add_option("--site", site_path, "the site file")->required();
  std::vector<std::string> at, ask;
  app.add_option("--at", at, "NAME:SLEW:TROLLEY:CABLE, a crane at rest")->required();
  app.add_option("--ask", ask, "NAME:SLEW:TROLLEY:CABLE, the leg a crane asks for");
  std::vector<std::string> work;
  app.add_option("--work", work, "NAME:SECONDS, the work left a crane reports");
  double seconds = 60.0;
  app.add_option("--seconds", seconds, "how long to report");
  CLI11_PARSE(app, argc, argv);
  try {
    const ac::SiteLayout layout = ac::load_site_layout(site_path);
    std::map<std::size_t, ac::CraneReport> reports;
    for (const auto& text : at) {
      const auto [name, pose] = parse(text);
      ac::CraneReport r;
      r.crane = index_of(layout, name);
      r.waypoints = {pose};
      reports[r.crane] = r;
    }
    for (const auto& text : ask) {
      const auto [name, to] = parse(text);
      auto& r = reports.at(index_of(layout, name));
      const ac::Pose from = r.waypoints.front();
      r.request_id = 1;
      r.request = {from, {to.slew, to.trolley, from.cable_length}, to};
    }
    for (const auto& text : work) {
      const auto colon = text.find(':');
      if (colon == std::string::npos) throw std::invalid_argument("'" + text + "' is not NAME:SECONDS");
      reports.at(index_of(layout, text.substr(0, colon))).work_left = std::stod(text.substr(colon + 1));
    }
    if (app.count("--domain") == 0) options.domain_id = static_cast<std::uint32_t>(layout.domain_id);
    runtime::install_stop_handlers(nullptr);
    auto participant = runtime::make_participant(options, "site_reports_writer");
    auto writer = participant->make_writer<tp::SiteReport>();
    const auto start = std::chrono::steady_clock::now();
    std::uint64_t seq = 0;
    for (auto next = start; !runtime::stop_requested() &&
                            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count() < seconds;
         next += std::chrono::milliseconds(100), std::this_thread::sleep_until(next)) {
      ++seq;
      for (const auto& [crane, r] : reports) {
        protocol::SiteReport m{};
        ac::to_message(r, m);
        ac::CraneMotion motion;
        motion.slew = r.waypoints.front().slew;
        motion.trolley = r.waypoints.front().trolley;
        motion.cable_length = r.waypoints.front().cable_length;
        ac::set_motion(motion, m);
        m.header.seq = seq;
        tp::msgs::SiteReport_ out;
        protocol::to_dds(m, out);
        writer->write(out);
      }
    }
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "site_reports_writer: %s\n", error.what());
    return 2;
  }
}
