#include "crane/web/foxglove_server.hpp"

#include <algorithm>
#include <boost/asio/ip/address.hpp>
#include <boost/asio/post.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <stdexcept>
#include <thread>
#include <utility>
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "crane/web/send_queue.hpp"

namespace crane::web {

namespace {

using WsServer = websocketpp::server<websocketpp::config::asio>;
using websocketpp::connection_hdl;

constexpr long kFlushPeriodMs = 10;  // [ms] the send queues drain at least this often

/// [s] on the steady clock: the send queues' timeline.
double steady_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string session_id() {
  return std::to_string(std::chrono::duration_cast<std::chrono::milliseconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count());
}

}  // namespace

struct FoxgloveServer::Impl {
  struct Client {
    ClientSession session;
    SendQueue queue;
    std::string operator_name;  // "" for a read-only client
    bool closing{false};        // closed for reading nothing: no more frames queued for it
  };

  ServerOptions options;
  std::vector<Channel> channels;
  std::vector<std::uint32_t> channel_ids;
  HttpHandler http;
  Authenticator authenticate;
  ClientMessageHandler on_client_message;
  ServerStats& stats;
  std::string server_session;
  std::string server_info;
  std::string advertise;
  WsServer server;
  std::map<connection_hdl, Client, std::owner_less<connection_hdl>> clients;  // I/O thread only
  std::thread io_thread;
  std::atomic<bool> running{false};

  Impl(ServerOptions o, std::vector<Channel> c, HttpHandler h, Authenticator a, ClientMessageHandler m, ServerStats& s)
      : options(std::move(o)),
        channels(std::move(c)),
        http(std::move(h)),
        authenticate(std::move(a)),
        on_client_message(std::move(m)),
        stats(s) {
    for (const auto& ch : channels) channel_ids.push_back(ch.id);
    server_session = session_id();
    server_info = server_info_json(options.name, server_session).dump();
    advertise = advertise_json(channels).dump();
  }

  void send_status(const connection_hdl& hdl, StatusLevel level, const std::string& message) {
    websocketpp::lib::error_code ec;
    server.send(hdl, status_json(level, message).dump(), websocketpp::frame::opcode::text, ec);
  }

  void flush(const connection_hdl& hdl, Client& client) {
    websocketpp::lib::error_code ec;
    auto con = server.get_con_from_hdl(hdl, ec);
    if (ec || con->get_state() != websocketpp::session::state::open) return;
    std::string frame;
    while (con->get_buffered_amount() < options.socket_buffer_bytes && client.queue.pop(frame)) {
      if (!con->send(frame, websocketpp::frame::opcode::binary)) stats.frames_sent.fetch_add(1);
    }
  }

  void flush_all() {
    for (auto& [hdl, client] : clients) flush(hdl, client);
  }

  void schedule_flush() {
    server.set_timer(kFlushPeriodMs, [this](const websocketpp::lib::error_code& ec) {
      if (ec || !running.load()) return;
      flush_all();
      schedule_flush();
    });
  }

  void setup() {
    server.clear_access_channels(websocketpp::log::alevel::all);
    server.clear_error_channels(websocketpp::log::elevel::all);
    server.set_error_channels(websocketpp::log::elevel::fatal);
    server.init_asio();
    server.set_reuse_addr(true);
    server.set_max_message_size(options.max_request_bytes);
    server.set_validate_handler([this](connection_hdl hdl) {
      auto con = server.get_con_from_hdl(hdl);
      const auto& requested = con->get_requested_subprotocols();
      if (std::find(requested.begin(), requested.end(), std::string(kSubprotocol)) == requested.end()) {
        stats.handshakes_refused.fetch_add(1);
        con->set_status(websocketpp::http::status_code::bad_request);
        con->set_body("this server speaks the WebSocket subprotocol " + std::string(kSubprotocol) + " only\n");
        return false;
      }
      con->select_subprotocol(std::string(kSubprotocol));
      return true;
    });
    server.set_open_handler([this](connection_hdl hdl) {
      // A fixed, small kernel send buffer per client (no autotuning to megabytes): a client that
      // stops reading fills it and websocketpp's buffer within seconds, and then its own queue
      // drops the oldest samples instead of the kernel holding many seconds of stale ones.
      boost::system::error_code option_ec;
      auto& socket = server.get_con_from_hdl(hdl)->get_socket();
      socket.set_option(boost::asio::socket_base::send_buffer_size(static_cast<int>(options.socket_buffer_bytes)),
                        option_ec);
      socket.set_option(boost::asio::ip::tcp::no_delay(true), option_ec);
      // An operator's handshake (the page's session cookie, same origin) may publish.
      std::string operator_name;
      if (!options.publishable.empty() && authenticate && on_client_message) {
        auto con = server.get_con_from_hdl(hdl);
        operator_name = authenticate(con->get_request_header("Cookie"), con->get_request_header("Origin"),
                                     con->get_request_header("Host"));
      }
      clients.emplace(hdl, Client{ClientSession(channel_ids, operator_name.empty() ? std::vector<PublishableTopic>{}
                                                                                    : options.publishable),
                                  SendQueue(options.queue_frames), operator_name});
      stats.clients.store(clients.size());
      if (!operator_name.empty()) stats.operator_clients.fetch_add(1);
      stats.connections_total.fetch_add(1);
      websocketpp::lib::error_code ec;
      server.send(hdl,
                  operator_name.empty() ? server_info
                                        : server_info_json(options.name, server_session, operator_name).dump(),
                  websocketpp::frame::opcode::text, ec);
      server.send(hdl, advertise, websocketpp::frame::opcode::text, ec);
    });
    const auto remove = [this](connection_hdl hdl) {
      websocketpp::lib::error_code ec;
      auto con = server.get_con_from_hdl(hdl, ec);
      if (!ec && con->get_local_close_code() == websocketpp::close::status::message_too_big) {
        stats.oversized_closed.fetch_add(1);
      }
      const auto found = clients.find(hdl);
      if (found == clients.end()) return;
      if (!found->second.operator_name.empty()) stats.operator_clients.fetch_sub(1);
      clients.erase(found);
      stats.clients.store(clients.size());
    };
    server.set_close_handler(remove);
    server.set_fail_handler(remove);
    server.set_message_handler([this](connection_hdl hdl, WsServer::message_ptr message) {
      const auto found = clients.find(hdl);
      if (found == clients.end()) return;
      if (message->get_opcode() != websocketpp::frame::opcode::text) {
        ClientMessage client_message;
        std::string error = found->second.session.handle_binary(message->get_payload(), client_message);
        if (error.empty()) {
          error = on_client_message(client_message.topic_index, client_message.data, client_message.size,
                                    found->second.operator_name);
        }
        if (!error.empty()) {
          stats.binary_refused.fetch_add(1);
          send_status(hdl, StatusLevel::error, error);
          return;
        }
        stats.client_messages.fetch_add(1);
        return;
      }
      const auto errors = found->second.session.handle_text(message->get_payload());
      for (const auto& error : errors) {
        stats.bad_requests.fetch_add(1);
        send_status(hdl, StatusLevel::error, error);
      }
    });
    server.set_http_handler([this](connection_hdl hdl) {
      auto con = server.get_con_from_hdl(hdl);
      HttpRequest request;
      request.method = con->get_request().get_method();
      request.path = con->get_resource();
      request.path = request.path.substr(0, request.path.find('?'));
      request.body = con->get_request_body();
      request.cookie = con->get_request_header("Cookie");
      request.origin = con->get_request_header("Origin");
      request.host = con->get_request_header("Host");
      HttpResponse response;
      if (http) response = http(request);
      con->set_status(static_cast<websocketpp::http::status_code::value>(response.status));
      con->replace_header("Content-Type", response.content_type);
      con->replace_header("Cache-Control", "no-store");
      if (!response.set_cookie.empty()) con->replace_header("Set-Cookie", response.set_cookie);
      con->set_body(response.body);
    });
  }
};

FoxgloveServer::FoxgloveServer(ServerOptions options, std::vector<Channel> channels, HttpHandler http,
                               Authenticator authenticate, ClientMessageHandler on_client_message) {
  if (options.queue_frames == 0) throw std::invalid_argument("web.queue_frames = 0: must be at least 1");
  if (options.socket_buffer_bytes == 0) throw std::invalid_argument("web.socket_buffer_bytes = 0: must be at least 1");
  if (!(options.stalled_close_seconds > 0.0) || !std::isfinite(options.stalled_close_seconds)) {
    throw std::invalid_argument("web.stalled_close_seconds = " + std::to_string(options.stalled_close_seconds) +
                                " s: must be finite and > 0");
  }
  if (options.max_request_bytes < 1024) {
    throw std::invalid_argument("web.max_request_bytes = " + std::to_string(options.max_request_bytes) +
                                ": must be at least 1024");
  }
  std::set<std::uint32_t> ids;
  for (const auto& c : channels) {
    if (!ids.insert(c.id).second) throw std::invalid_argument("channel id " + std::to_string(c.id) + " repeated");
  }
  if (!options.publishable.empty() && (!authenticate || !on_client_message)) {
    throw std::invalid_argument("web.publishable needs an authenticator and a client message handler");
  }
  impl_ = std::make_unique<Impl>(std::move(options), std::move(channels), std::move(http), std::move(authenticate),
                                 std::move(on_client_message), stats_);
  impl_->setup();
}

FoxgloveServer::~FoxgloveServer() { stop(); }

void FoxgloveServer::start() {
  auto& s = impl_->server;
  const auto& o = impl_->options;
  const std::string where = o.bind_address + ":" + std::to_string(o.port);
  boost::system::error_code ec;
  const auto address = boost::asio::ip::make_address(o.bind_address, ec);
  if (ec) throw std::runtime_error("--bind " + o.bind_address + " is not an IP address: " + ec.message());
  const boost::asio::ip::tcp::endpoint endpoint(address, o.port);
  {
    // websocketpp reports any failure to listen as "Underlying Transport Error": bind once here
    // to name the reason (address in use, permission denied...).
    boost::asio::ip::tcp::acceptor probe(s.get_io_service());
    probe.open(endpoint.protocol(), ec);
    if (!ec) probe.set_option(boost::asio::socket_base::reuse_address(true), ec);
    if (!ec) probe.bind(endpoint, ec);
    if (ec) throw std::runtime_error("cannot listen on " + where + ": " + ec.message());
  }
  websocketpp::lib::error_code wec;
  s.listen(endpoint, wec);
  if (wec) throw std::runtime_error("cannot listen on " + where + ": " + wec.message());
  s.start_accept(wec);
  if (wec) throw std::runtime_error("cannot accept on " + where + ": " + wec.message());
  boost::system::error_code local_ec;
  const auto local = s.get_local_endpoint(local_ec);
  bound_port_.store(local_ec ? o.port : local.port());
  impl_->running.store(true);
  impl_->schedule_flush();
  impl_->io_thread = std::thread([this] { impl_->server.run(); });
}

void FoxgloveServer::stop() noexcept {
  if (!impl_ || !impl_->running.exchange(false)) return;
  try {
    boost::asio::post(impl_->server.get_io_service(), [impl = impl_.get()] {
      websocketpp::lib::error_code ec;
      impl->server.stop_listening(ec);
      for (auto& [hdl, client] : impl->clients) impl->server.close(hdl, websocketpp::close::status::going_away, "server stopping", ec);
    });
    // Give the closing handshakes a moment, then stop the I/O loop.
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    impl_->server.stop();
    if (impl_->io_thread.joinable()) impl_->io_thread.join();
  } catch (...) {
  }
}

void FoxgloveServer::publish(std::uint32_t channel_id, std::uint64_t receive_ns,
                             std::shared_ptr<const std::vector<std::uint8_t>> payload) {
  if (!impl_->running.load()) return;
  boost::asio::post(impl_->server.get_io_service(), [impl = impl_.get(), channel_id, receive_ns, payload = std::move(payload)] {
    const double now = steady_seconds();
    const double limit = impl->options.stalled_close_seconds;
    std::vector<connection_hdl> not_reading;
    for (auto& [hdl, client] : impl->clients) {
      std::uint32_t subscription = 0;
      if (client.closing || !client.session.subscription_of(channel_id, subscription)) continue;
      if (client.queue.push(message_data_frame(subscription, receive_ns, payload->data(), payload->size()), now)) {
        impl->stats.frames_dropped.fetch_add(1);
      }
      impl->flush(hdl, client);
      if (client.queue.not_reading(now, limit)) {
        client.closing = true;
        not_reading.push_back(hdl);
      }
    }
    // After the loop: a close may end the connection at once (its close handler erases the client).
    char reason[96];
    std::snprintf(reason, sizeof reason, "not reading: every sample dropped for %.1f s", limit);
    for (const auto& hdl : not_reading) {
      impl->stats.stalled_closed.fetch_add(1);
      websocketpp::lib::error_code ec;
      impl->server.close(hdl, websocketpp::close::status::policy_violation, reason, ec);
    }
  });
}

}  // namespace crane::web
