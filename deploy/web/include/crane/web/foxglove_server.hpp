#pragma once
// crane_web's server: the Foxglove WebSocket protocol (foxglove_protocol.hpp) and plain HTTP on one
// port, over websocketpp (Debian's libwebsocketpp-dev) on Boost.Asio. One I/O thread owns every
// connection; publish() may be called from any thread and never blocks on a client: each client
// has a bounded SendQueue (the oldest frame dropped when full) that drains as its socket takes
// data. A client that reads nothing (every sample to it dropped for stalled_close_seconds,
// SendQueue::not_reading) is closed with 1008 (policy violation) and the reason; the others are
// not touched.

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "crane/web/foxglove_protocol.hpp"

namespace crane::web {

struct ServerOptions {
  std::string bind_address{"127.0.0.1"};       // IPv4 or IPv6 address to listen on (loopback by default)
  std::uint16_t port{8765};                    // TCP port; 0: any free port (see FoxgloveServer::port())
  std::size_t queue_frames{256};               // per-client send queue [frames]
  std::size_t socket_buffer_bytes{64 * 1024};  // [bytes] a client's kernel send buffer (SO_SNDBUF), and
                                               // what websocketpp may hold for it before the queue
  std::size_t max_request_bytes{64 * 1024};    // [bytes] largest frame a client may send (else closed, 1009)
  double stalled_close_seconds{10.0};          // [s] > 0: a client whose every sample was dropped this long
                                               // reads nothing: closed, 1008
  std::string name{"crane_web"};               // serverInfo name
  // Client publishing: the topics an operator's client may publish (empty: publishing off for all).
  std::vector<PublishableTopic> publishable{};
};

/// Counters of the server, read by the metrics (any thread).
struct ServerStats {
  std::atomic<std::uint64_t> clients{0};            // connected Foxglove clients now
  std::atomic<std::uint64_t> connections_total{0};  // accepted since start
  std::atomic<std::uint64_t> frames_sent{0};        // Message Data frames handed to sockets
  std::atomic<std::uint64_t> frames_dropped{0};     // dropped from full send queues (oldest first)
  std::atomic<std::uint64_t> bad_requests{0};       // refused text requests (malformed, unknown ids, unsupported)
  std::atomic<std::uint64_t> binary_refused{0};     // binary frames refused (publishing off, not advertised, refused by the bus)
  std::atomic<std::uint64_t> client_messages{0};    // operators' messages passed to the bus
  std::atomic<std::uint64_t> operator_clients{0};   // clients connected as an operator now
  std::atomic<std::uint64_t> handshakes_refused{0}; // WebSocket handshakes without foxglove.websocket.v1
  std::atomic<std::uint64_t> oversized_closed{0};   // clients closed (1009) for a frame over max_request_bytes
  std::atomic<std::uint64_t> stalled_closed{0};     // clients closed (1008) for reading nothing (stalled_close_seconds)
};

/// An HTTP request (not a WebSocket handshake) and the handler's answer.
struct HttpRequest {
  std::string method;  // "GET", "POST", ...
  std::string path;    // without the query
  std::string body;
  std::string cookie;  // the Cookie header ("" when absent)
  std::string origin;  // the Origin header ("" when absent)
  std::string host;    // the Host header
};
struct HttpResponse {
  int status{404};
  std::string content_type{"text/plain; charset=utf-8"};
  std::string body;
  std::string set_cookie;  // a Set-Cookie header value ("" for none)
};
using HttpHandler = std::function<HttpResponse(const HttpRequest& request)>;
/// Who a WebSocket handshake is: the operator's name, or "" (read-only). Called on the I/O thread
/// with the handshake's Cookie, Origin and Host headers.
using Authenticator = std::function<std::string(const std::string& cookie, const std::string& origin, const std::string& host)>;
/// Takes one message an operator's client published (`topic_index` into ServerOptions::publishable,
/// the CDR payload) and returns "" when it went to the bus, else the reason it was refused. Called
/// on the I/O thread; must not block.
using ClientMessageHandler =
    std::function<std::string(std::size_t topic_index, const std::uint8_t* data, std::size_t size, const std::string& operator_name)>;

class FoxgloveServer {
 public:
  /// `channels`: what every client is offered (ids unique). Throws std::invalid_argument on a bad
  /// option (naming it) or a repeated channel id. Does not open the socket yet.
  /// `authenticate` and `on_client_message` are only used when options.publishable is not empty.
  FoxgloveServer(ServerOptions options, std::vector<Channel> channels, HttpHandler http,
                 Authenticator authenticate = {}, ClientMessageHandler on_client_message = {});
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  /// Binds bind_address:port and starts the I/O thread. Throws std::runtime_error naming the
  /// address, the port and the reason (address in use, not an address...).
  void start();
  /// Closes every connection and joins the I/O thread. Idempotent.
  void stop() noexcept;
  /// The port listened on (the one chosen by the system when options.port was 0).
  [[nodiscard]] std::uint16_t port() const noexcept { return bound_port_.load(); }

  /// Forwards one sample of `channel_id` (its payload as it is, received at `receive_ns` since the
  /// Unix epoch) to every client subscribed to it. Any thread; never blocks on a client. Allocates.
  void publish(std::uint32_t channel_id, std::uint64_t receive_ns, std::shared_ptr<const std::vector<std::uint8_t>> payload);

  [[nodiscard]] const ServerStats& stats() const noexcept { return stats_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  ServerStats stats_;
  std::atomic<std::uint16_t> bound_port_{0};
};

}  // namespace crane::web
