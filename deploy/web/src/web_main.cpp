// crane_web: the crane's bus for Foxglove Studio, Lichtblick and any Foxglove WebSocket client.
//
//   crane_web --config FILE [--port 8765] [--bind 127.0.0.1] [--queue 256] [--close-stalled 10] [--nice 10]
//             [--dds fast|cyclone] [--domain N] [--lan]
//
// A read-only DDS participant (readers only) takes every topic of the bus (the topic table,
// transport::topics::for_each_topic) and forwards each sample, as the CDR bytes a DDS writer puts
// on the wire (encapsulation header included), to the WebSocket clients subscribed to its channel:
// one channel per topic, encoding "cdr", schema encoding "omgidl", schema the IDL
// (crane::protocol::kIdlSchema, generated from idl/crane_msgs.idl), schema name the DDS type name.
// Samples with NaN or Inf are rejected where they enter (as every process of the stack does) and
// counted. Client publishing is off unless --operators names an operators file (operator_auth.hpp):
// then a client whose handshake carries a logged-in operator's session cookie may publish goals
// (rt/crane/planner/goal) and supervisor commands (rt/crane/safety/command), as CDR; each one is
// deserialized, checked for NaN/Inf and written to the bus by this process, and logged with the
// operator's name. HTTP on the same port: / the operator page (deploy/web/www: views, plots, mode
// and faults over the same protocol, and the controls for a logged-in operator), POST /login (the
// token as the body: sets the session cookie), POST /logout, GET /whoami, /site.json (the crane's
// kind, travel and no-go zones from --config, the file the stack runs with: site_view.hpp),
// with --site the site page (/site.html, /site_view.js) and its view (/site/view.json, rebuilt
// every 200 ms: site_page.hpp; 404 without --site; and the site's scene for Foxglove's 3D panel on
// the channel /site/scene), /about
// (what this is) and /metrics (the Prometheus text format, web_metrics.hpp: per topic, the
// supervisor, each process, the server). A client that reads nothing is closed (--close-stalled).
// With --site FILE, a second read-only participant on the site's domain (the site file's
// domain_id) forwards the site's topics too (transport::topics::for_each_site_topic: every
// crane's reports with its pose, the site service's instructions and status), channels after the
// bus's: a Foxglove client on any host sees every crane of the site.
//   crane_web --operators FILE --new-operator NAME   appends an operator and prints its token once.
// Exit codes: 0 stopped by SIGINT/SIGTERM, 1 could not start (port in use, DDS...); a bad option:
// CLI11's message and code.
#include <CLI/CLI.hpp>
#include <spdlog/spdlog.h>
#include <sys/resource.h>

#include <cctype>
#include <cerrno>
#include <cstring>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <algorithm>
#include <functional>
#include <sstream>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "crane/anti_collision/site_file.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/protocol/idl_schema.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/transport/cdr.hpp"
#include "crane/web/foxglove_server.hpp"
#include "crane/web/operator_auth.hpp"
#include "crane/web/site_page.hpp"
#include "crane/web/site_view.hpp"
#include "crane/web/web_metrics.hpp"

namespace {

using namespace crane;
namespace tp = transport::topics;
using Clock = std::chrono::steady_clock;
/// How often the site page's view (/site/view.json) is rebuilt.
constexpr auto kSiteViewPeriod = std::chrono::milliseconds(200);

/// One advertised channel per topic of the bus, ids 1..N in the topic table's order; with a site,
/// then one per site topic (transport::topics::for_each_site_topic), N+1.., and the site's scene
/// (JSON, foxglove.SceneUpdate) last.
std::vector<web::Channel> bus_channels(bool with_site) {
  std::vector<web::Channel> channels;
  const auto add = [&]<class Topic>() {
    channels.push_back(web::Channel{static_cast<std::uint32_t>(channels.size() + 1), Topic::name, "cdr",
                                    Topic::type_name, "omgidl", std::string(protocol::kIdlSchema)});
  };
  tp::for_each_topic(add);
  if (with_site) {
    tp::for_each_site_topic(add);
    // The site's scene for Foxglove's 3D panel, last (site_page.hpp).
    channels.push_back(web::Channel{static_cast<std::uint32_t>(channels.size() + 1), std::string(web::kSceneTopic),
                                    "json", std::string(web::kSceneSchemaName), "jsonschema",
                                    std::string(web::scene_json_schema())});
  }
  return channels;
}

/// The text of `path`; empty when it cannot be read.
std::string file_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  return in ? text.str() : std::string();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_web: the crane's topics over the Foxglove WebSocket protocol (read-only unless --operators)"};
  runtime::NodeOptions node;
  web::ServerOptions server_options;
  bool lan = false;
  app.add_option("--port", server_options.port, "TCP port (0: any free port, printed at start)")
      ->check(CLI::Range(0, 65535));
  app.add_option("--bind", server_options.bind_address,
                 "address to listen on (default loopback only; 0.0.0.0: every interface)");
  app.add_option("--queue", server_options.queue_frames, "per-client send queue [samples]; the oldest is dropped when full")
      ->check(CLI::Range(1, 1000000));
  app.add_option("--close-stalled", server_options.stalled_close_seconds,
                 "[s] close a client (1008) when every sample to it has been dropped this long: it reads nothing")
      ->check(CLI::Range(0.1, 86400.0));
  app.add_option("--dds", node.dds, "DDS vendor: fast | cyclone (default: $CRANE_DDS, else fast)");
  app.add_option("--domain", node.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_option("--dds-profile", node.dds_profile, "network profile (deploy/dds/*.xml)")->check(CLI::ExistingFile);
  app.add_flag("--lan", lan, "reach the stack over the network (UDP) instead of loopback only");
  runtime::add_iceoryx_option(app, node);
  runtime::add_security_options(app, node);
  std::string config_path;
  app.add_option("--config", config_path, "the stack's configuration (YAML): the crane and the no-go zones the page draws")
      ->check(CLI::ExistingFile);
  std::string site_path;
  app.add_option("--site", site_path,
                 "the crane's site file (docs/site.md): the site's topics (rt/site/report, instruction, status) too, "
                 "from the site's DDS domain")
      ->check(CLI::ExistingFile);
  std::string assets = CRANE_WEB_ASSETS_DIR;
  app.add_option("--assets", assets, "folder of the operator page (index.html, crane_view.js)");
  std::string operators_path;
  app.add_option("--operators", operators_path,
                 "operators file (NAME SHA256-of-token lines, mode 600): logged-in operators may publish goals and "
                 "supervisor commands; without it the server is read-only");
  std::string new_operator;
  app.add_option("--new-operator", new_operator, "with --operators: add operator NAME, print its token, and exit");
  double session_hours = 12.0;
  app.add_option("--session-hours", session_hours, "[h] how long an operator's login lasts")->check(CLI::Range(0.01, 720.0));
  int nice_value = 10;
  app.add_option("--nice", nice_value, "scheduling niceness of the whole server (0-19): below the stack's processes, "
                                       "so viewers never take CPU from the control loop")
      ->check(CLI::Range(0, 19));
  CLI11_PARSE(app, argc, argv);
  if (!new_operator.empty()) {
    if (operators_path.empty()) {
      std::fprintf(stderr, "crane_web: --new-operator needs --operators FILE\n");
      return 2;
    }
    try {
      const std::string token = web::OperatorAuth::add_operator(operators_path, new_operator);
      std::printf("%s\n", token.c_str());
      std::fprintf(stderr, "crane_web: operator %s added to %s; the token above is its only copy\n", new_operator.c_str(),
                   operators_path.c_str());
      return 0;
    } catch (const std::exception& error) {
      std::fprintf(stderr, "crane_web: %s\n", error.what());
      return 2;
    }
  }
  if (config_path.empty()) {
    std::fprintf(stderr, "crane_web: --config FILE is required (the stack's configuration: what the page draws)\n");
    return 2;
  }
  std::string site;  // /site.json
  try {
    site = web::site_json_of_config(config_path).dump();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_web: %s\n", error.what());
    return 2;
  }
  std::unique_ptr<web::OperatorAuth> auth;
  if (!operators_path.empty()) {
    try {
      auth = std::make_unique<web::OperatorAuth>(operators_path, session_hours * 3600.0);
    } catch (const std::exception& error) {
      std::fprintf(stderr, "crane_web: %s\n", error.what());
      return 2;
    }
  }
  // Before any thread exists (DDS's, the I/O thread): they inherit it. What it changes for the
  // stack's latency with 20 clients: deploy/bench_web.sh, docs/operation.md.
  if (nice_value > 0 && setpriority(PRIO_PROCESS, 0, nice_value) != 0) {
    std::fprintf(stderr, "crane_web: --nice %d: %s (running at the default niceness)\n", nice_value, std::strerror(errno));
  }
  node.loopback_only = !lan;
  node.shared_memory = !lan;
  // Secured bus: a read-only server is a monitor; one that publishes operators' commands is an operator.
  if (node.identity.empty()) node.identity = operators_path.empty() ? "monitor" : "operator";

  try {
    // With operators, every login and every published command is logged (the audit trail).
    runtime::configure_logging(auth ? "info" : "warn", "crane_web");
    auto participant = runtime::make_participant(node, "crane_web");
    // The site's topics come from the site's own domain (read-only, like the bus).
    std::unique_ptr<transport::Participant> site_participant;
    std::unique_ptr<anti_collision::SiteWatch> site_watch;  // the site page's (/site/view.json)
    if (!site_path.empty()) {
      auto layout = anti_collision::load_site_layout(site_path);
      const runtime::NodeOptions site_node =
          runtime::site_domain_options(node, static_cast<std::uint32_t>(layout.domain_id), !node.loopback_only);
      site_watch = std::make_unique<anti_collision::SiteWatch>(std::move(layout));
      site_participant = runtime::make_participant(site_node, "crane_web");
    }
    transport::Wakeup wakeup;
    runtime::install_stop_handlers(&wakeup);

    // The operator page: its two files, read once (deploy/web/www).
    const std::string page = file_text(assets + "/index.html");
    const std::string page_script = file_text(assets + "/crane_view.js");
    const std::string site_page = file_text(assets + "/site.html");
    const std::string site_page_script = file_text(assets + "/site_view.js");
    // The site page's view, rebuilt by the main loop every kSiteViewPeriod, served as it stands.
    std::mutex site_view_mutex;
    std::string site_view = R"j({"error": "no site view yet"})j";
    if (page.empty() || page_script.empty()) {
      std::fprintf(stderr, "crane_web: no operator page in %s (index.html, crane_view.js): / describes the server\n",
                   assets.c_str());
    }
    const auto channels = bus_channels(site_participant != nullptr);
    std::vector<std::string> topic_names;
    for (const auto& c : channels) topic_names.push_back(c.topic);
    web::WebMetrics metrics(topic_names);
    const web::ServerStats* server_stats = nullptr;  // set before the server starts
    // What operators may publish, and the writers that put it on the bus.
    auto goal_writer = auth ? participant->make_writer<tp::Goal>() : nullptr;
    auto command_writer = auth ? participant->make_writer<tp::SafetyCommand>() : nullptr;
    if (auth) {
      server_options.publishable = {{tp::Goal::name, tp::Goal::type_name},
                                    {tp::SafetyCommand::name, tp::SafetyCommand::type_name}};
    }
    const auto started = Clock::now();
    const auto seconds_since_start = [started] { return std::chrono::duration<double>(Clock::now() - started).count(); };
    const auto seconds_now = [] {
      return std::chrono::duration<double>(Clock::now().time_since_epoch()).count();
    };
    auto authenticate = [&](const std::string& cookie, const std::string& origin, const std::string& host) {
      if (!auth || !web::same_origin(origin, host)) return std::string();
      return auth->operator_of(cookie, seconds_now()).value_or(std::string());
    };
    auto on_client_message = [&](std::size_t topic_index, const std::uint8_t* data, std::size_t size,
                                 const std::string& operator_name) -> std::string {
      const auto forward = [&]<class T>(transport::Writer<T>& writer, const char* topic) -> std::string {
        typename T::Message m;
        if (!transport::deserialize_cdr<T>(data, size, m)) {
          return std::string(topic) + ": " + std::to_string(size) + " bytes are not a CDR " + T::type_name;
        }
        if (!runtime::all_finite(m)) return std::string(topic) + ": refused, a field is NaN or Inf";
        writer.write(m);
        if constexpr (std::is_same_v<T, tp::Goal>) {
          spdlog::info("operator {} published {} request {} (command {}, trolley {} m, slew {} rad, cable {} m)",
                       operator_name, topic, m.request_id(), m.command(), m.trolley_target(), m.slew_target(),
                       m.cable_length_target());
        } else {
          spdlog::info("operator {} published {} request {} (command {})", operator_name, topic, m.request_id(),
                       m.command());
        }
        spdlog::default_logger()->flush();  // the audit trail is on disk before the next command
        return {};
      };
      if (topic_index == 0) return forward(*goal_writer, tp::Goal::name);
      if (topic_index == 1) return forward(*command_writer, tp::SafetyCommand::name);
      return "no such publishable topic";
    };
    web::FoxgloveServer server(server_options, channels, [&](const web::HttpRequest& request) {
      web::HttpResponse response;
      const std::string& path = request.path;
      if (path == "/login" || path == "/logout" || path == "/whoami") {
        response.content_type = "application/json";
        if (!auth) {
          response.status = 403;
          response.body = R"j({"error": "this server is read-only (started without --operators)"})j";
        } else if (path == "/whoami") {
          const auto who = auth->operator_of(request.cookie, seconds_now());
          response.status = who ? 200 : 401;
          response.body = who ? nlohmann::json{{"operator", *who}}.dump() : R"j({"operator": null})j";
        } else if (request.method != "POST" || !web::same_origin(request.origin, request.host)) {
          response.status = 405;
          response.body = R"j({"error": "POST from this page only"})j";
        } else if (path == "/logout") {
          auth->logout(request.cookie);
          response.status = 200;
          response.set_cookie = std::string(web::kSessionCookie) + "=; Max-Age=0; Path=/; HttpOnly; SameSite=Strict";
          response.body = R"j({"operator": null})j";
        } else {
          std::string token = request.body;
          while (!token.empty() && std::isspace(static_cast<unsigned char>(token.back()))) token.pop_back();
          const auto session = auth->login(token, seconds_now());
          const auto who = session ? auth->operator_of(std::string(web::kSessionCookie) + "=" + *session, seconds_now())
                                   : std::nullopt;
          response.status = who ? 200 : 403;
          if (who) {
            response.set_cookie = std::string(web::kSessionCookie) + "=" + *session +
                                  "; Path=/; HttpOnly; SameSite=Strict; Max-Age=" +
                                  std::to_string(static_cast<long>(session_hours * 3600.0));
            spdlog::info("operator {} logged in", *who);
          } else {
            spdlog::warn("a login with an unknown token was refused");
          }
          spdlog::default_logger()->flush();
          response.body = who ? nlohmann::json{{"operator", *who}}.dump() : R"j({"error": "unknown token"})j";
        }
      } else if (path == "/site.json") {
        response.status = 200;
        response.content_type = "application/json";
        response.body = site;
      } else if (path == "/site/view.json" || path == "/site.html" || path == "/site_view.js") {
        if (!site_watch) {
          response.status = 404;
          response.content_type = "application/json";
          response.body = R"j({"error": "this server watches no site (started without --site)"})j";
        } else if (path == "/site/view.json") {
          response.status = 200;
          response.content_type = "application/json";
          const std::lock_guard lock(site_view_mutex);
          response.body = site_view;
        } else {
          const bool html = path == "/site.html";
          response.status = (html ? site_page : site_page_script).empty() ? 404 : 200;
          response.content_type = html ? "text/html; charset=utf-8" : "text/javascript; charset=utf-8";
          response.body = html ? site_page : site_page_script;
        }
      } else if (path == "/metrics") {
        response.status = 200;
        response.content_type = "text/plain; version=0.0.4; charset=utf-8";
        response.body = metrics.text(server_stats);
      } else if ((path == "/" || path == "/index.html") && !page.empty()) {
        response.status = 200;
        response.content_type = "text/html; charset=utf-8";
        response.body = page;
      } else if (path == "/crane_view.js" && !page_script.empty()) {
        response.status = 200;
        response.content_type = "text/javascript; charset=utf-8";
        response.body = page_script;
      } else if (path == "/" || path == "/about") {
        response.status = 200;
        response.body = "crane_web: the crane's topics over the Foxglove WebSocket protocol (subprotocol " +
                        std::string(web::kSubprotocol) + ") on this port; " + std::to_string(channels.size()) +
                        " channels, encoding cdr, schema omgidl. Open it in Foxglove or Lichtblick "
                        "(Foxglove WebSocket, ws://HOST:PORT). Metrics: /metrics\n";
      } else {
        response.body = "not found: " + path + "\n";
      }
      return response;
    }, authenticate, on_client_message);
    server_stats = &server.stats();

    // One reader per topic (history deep enough that a busy moment never drops a sample here),
    // and its drain: take, reject non-finite, serialize, forward.
    std::vector<std::function<void()>> drains;
    std::vector<std::shared_ptr<void>> readers;
    std::uint32_t channel_id = 0;
    transport::Participant* source = participant.get();
    const auto forward_topic = [&]<class T>() {
      const std::uint32_t id = ++channel_id;
      auto reader = std::shared_ptr(source->make_recording_reader<T>(&wakeup, 64));
      readers.push_back(reader);
      const std::size_t topic_index = id - 1;
      drains.push_back([reader, id, topic_index, &server, &metrics, &site_watch, &seconds_since_start] {
        typename T::Message m;
        while (reader->take_next(m)) {
          const auto receive_ns = static_cast<std::uint64_t>(runtime::now_nanoseconds());
          if (!runtime::all_finite(m)) {
            metrics.nonfinite(topic_index);
            continue;
          }
          metrics.sample(topic_index);
          if constexpr (std::is_same_v<T, tp::SiteReport> || std::is_same_v<T, tp::SiteStatus> ||
                        std::is_same_v<T, tp::SiteInstruction>) {
            typename protocol::PlainOf<typename T::Message>::type plain;
            protocol::from_dds(m, plain);
            const double now = seconds_since_start();
            if constexpr (std::is_same_v<T, tp::SiteReport>) {
              (void)site_watch->report(plain, now);
            } else if constexpr (std::is_same_v<T, tp::SiteStatus>) {
              site_watch->status(plain, now);
            } else {
              (void)site_watch->instruction(plain);
            }
          }
          if constexpr (std::is_same_v<T, tp::SafetyStatus> || std::is_same_v<T, tp::LoopDiagnostics>) {
            typename protocol::PlainOf<typename T::Message>::type plain;
            protocol::from_dds(m, plain);
            if constexpr (std::is_same_v<T, tp::SafetyStatus>) {
              metrics.supervisor(plain);
            } else {
              metrics.loop(plain);
            }
          }
          auto bytes = std::make_shared<std::vector<std::uint8_t>>();
          if (!transport::serialize_cdr<T>(m, *bytes)) continue;
          server.publish(id, receive_ns, std::move(bytes));
        }
      });
    };
    tp::for_each_topic(forward_topic);
    if (site_participant) {
      source = site_participant.get();
      tp::for_each_site_topic(forward_topic);
    }

    server.start();
    std::printf("crane_web: ws://%s:%u (subprotocol %s), %zu channels; Ctrl-C to stop\n",
                server_options.bind_address.c_str(), static_cast<unsigned>(server.port()),
                std::string(web::kSubprotocol).c_str(), channels.size());
    std::fflush(stdout);
    auto window_start = Clock::now();
    auto next_site_view = Clock::now();
    while (!runtime::stop_requested()) {
      for (auto& d : drains) d();
      const auto now = Clock::now();
      if (site_watch && now >= next_site_view) {
        std::string view = web::site_page_json(*site_watch, seconds_since_start()).dump();
        {
          const std::lock_guard lock(site_view_mutex);
          site_view = std::move(view);
        }
        const auto stamp_ns = runtime::now_nanoseconds();
        const std::string scene = web::site_scene_json(*site_watch, stamp_ns).dump();
        const auto scene_index = channels.size() - 1;
        metrics.sample(scene_index);
        server.publish(channels.back().id, static_cast<std::uint64_t>(stamp_ns),
                       std::make_shared<std::vector<std::uint8_t>>(scene.begin(), scene.end()));
        next_site_view = now + kSiteViewPeriod;
      }
      if (now - window_start >= std::chrono::seconds(1)) {
        metrics.update_rates(std::chrono::duration<double>(now - window_start).count());
        window_start = now;
      }
      wakeup.wait_until(std::min(now + std::chrono::milliseconds(100), site_watch ? next_site_view : now + std::chrono::hours(1)));
    }
    server.stop();
    return 0;
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_web: %s\n", error.what());
    return 1;
  }
}
