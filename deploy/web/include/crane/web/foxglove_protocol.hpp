#pragma once
// The Foxglove WebSocket protocol, server side, without a socket: the messages a server sends and
// the requests it accepts (subprotocol foxglove.websocket.v1, github.com/foxglove/ws-protocol,
// docs/spec.md). crane_web's server (foxglove_server.hpp) moves these over websocketpp; the tests
// drive them directly.
//
// Supported: serverInfo, advertise, status, subscribe, unsubscribe, binary Message Data (opcode 1),
// and, for a client the server has authenticated as an operator only, client publishing
// (capability clientPublish: the client's advertise/unadvertise and its binary Client Message Data,
// opcode 1, on the topics the server accepts from operators). Not supported, and not announced:
// parameters, services, time, connection graph, assets.

#include <cstddef>
#include <cstdint>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace crane::web {

/// The WebSocket subprotocol the server selects (and requires) in the handshake.
inline constexpr std::string_view kSubprotocol = "foxglove.websocket.v1";
/// Binary server opcode of a Message Data frame.
inline constexpr std::uint8_t kOpMessageData = 0x01;
/// Binary client opcode of a Client Message Data frame: opcode, channel id (uint32 LE), payload.
inline constexpr std::uint8_t kOpClientMessageData = 0x01;
inline constexpr std::size_t kClientMessageHeaderBytes = 5;
/// Bytes before the payload in a Message Data frame: opcode, subscription id (uint32 LE),
/// receive timestamp (uint64 LE, nanoseconds).
inline constexpr std::size_t kMessageDataHeaderBytes = 13;

/// One advertised channel: a bus topic. `schema` is the text of the schema (for the crane's topics
/// the whole IDL, schemaEncoding "omgidl", schemaName the DDS type name).
struct Channel {
  std::uint32_t id{0};
  std::string topic;            // e.g. "rt/crane/hw/sensors"
  std::string encoding;         // message encoding, "cdr"
  std::string schema_name;      // e.g. "crane_msgs::msg::dds_::SensorSample_"
  std::string schema_encoding;  // "omgidl"
  std::string schema;
};

enum class StatusLevel : int { info = 0, warning = 1, error = 2 };

/// A topic the server accepts from an authenticated operator's client: its name and the schema
/// name the client must advertise it with (the DDS type name).
struct PublishableTopic {
  std::string topic;        // e.g. "rt/crane/planner/goal"
  std::string schema_name;  // e.g. "crane_msgs::msg::dds_::MoveRequest_"
};

/// {"op":"serverInfo", "name", "capabilities": [] or ["clientPublish"] (for `operator_name` not
/// empty), "supportedEncodings": ["cdr"] with publishing, "metadata": {"clientPublish": "off" or
/// "operator NAME"}, "sessionId"}.
[[nodiscard]] nlohmann::json server_info_json(const std::string& name, const std::string& session_id,
                                              const std::string& operator_name = "");
/// {"op":"advertise","channels":[{id, topic, encoding, schemaName, schema, schemaEncoding}...]}.
[[nodiscard]] nlohmann::json advertise_json(const std::vector<Channel>& channels);
/// {"op":"status","level":0|1|2,"message":...}.
[[nodiscard]] nlohmann::json status_json(StatusLevel level, const std::string& message);

/// A Message Data frame: opcode 1, `subscription_id`, `receive_ns` (both little endian), then the
/// `size` bytes of `payload` as they are (for the crane: CDR with its encapsulation header).
/// Allocates.
[[nodiscard]] std::string message_data_frame(std::uint32_t subscription_id, std::uint64_t receive_ns,
                                             const std::uint8_t* payload, std::size_t size);

/// One Client Message Data frame accepted by ClientSession::handle_binary: the index of its topic in
/// the publishable list and its payload (CDR with the encapsulation header, as a DDS writer sends),
/// a view into the frame.
struct ClientMessage {
  std::size_t topic_index{0};
  const std::uint8_t* data{nullptr};
  std::size_t size{0};
};

/// What one client is subscribed to and, for an operator's client, what it advertised to publish,
/// and the requests that change it. Never throws on a client's input: a bad request changes nothing
/// and is answered with an error naming what was wrong.
class ClientSession {
 public:
  /// `channel_ids`: the channels the server advertises (others are refused by id). `publishable`:
  /// the topics this client may publish; empty: publishing off for this client.
  explicit ClientSession(std::vector<std::uint32_t> channel_ids, std::vector<PublishableTopic> publishable = {});

  /// Applies one text frame of the client: subscribe, unsubscribe and, when publishing is on,
  /// advertise ({"op":"advertise","channels":[{id, topic, encoding "cdr", schemaName}]}) and
  /// unadvertise ({"op":"unadvertise","channelIds":[...]}). Returns the error messages, one per
  /// refused item, e.g. "subscribe: unknown channel id 99", "advertise: topic rt/x is not
  /// published by operators here" or "malformed JSON: ..."; an empty list when everything was
  /// applied. Requests the server does not support are refused with "<op>: not supported by this
  /// server (...)"; advertise without publishing: "advertise: client publishing is off (log in as an
  /// operator)". Allocates.
  std::vector<std::string> handle_text(std::string_view text);

  /// Checks one binary frame of the client: opcode 1, a channel id this client advertised, a
  /// non-empty payload. On success fills `message` and returns an empty string; otherwise returns
  /// the reason (publishing off, unknown opcode, short frame, channel not advertised).
  std::string handle_binary(std::string_view frame, ClientMessage& message) const;

  [[nodiscard]] bool may_publish() const noexcept { return !publishable_.empty(); }

  /// The subscription id of `channel_id` for this client, or false when not subscribed.
  [[nodiscard]] bool subscription_of(std::uint32_t channel_id, std::uint32_t& subscription_id) const noexcept;
  [[nodiscard]] std::size_t subscription_count() const noexcept { return channel_of_subscription_.size(); }

 private:
  std::vector<std::uint32_t> channel_ids_;
  std::vector<PublishableTopic> publishable_;
  std::map<std::uint32_t, std::size_t> advertised_;                 // client channel id -> publishable index
  std::map<std::uint32_t, std::uint32_t> channel_of_subscription_;  // subscription id -> channel id
  std::map<std::uint32_t, std::uint32_t> subscription_of_channel_;  // channel id -> subscription id
};

}  // namespace crane::web
