#include "crane/web/foxglove_protocol.hpp"

#include <algorithm>
#include <cstring>
#include <utility>

namespace crane::web {

using nlohmann::json;

json server_info_json(const std::string& name, const std::string& session_id, const std::string& operator_name) {
  json info{{"op", "serverInfo"},
            {"name", name},
            {"capabilities", json::array()},
            {"metadata", {{"clientPublish", "off"}}},
            {"sessionId", session_id}};
  if (!operator_name.empty()) {
    info["capabilities"].push_back("clientPublish");
    info["supportedEncodings"] = json::array({"cdr"});
    info["metadata"]["clientPublish"] = "operator " + operator_name;
  }
  return info;
}

json advertise_json(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const auto& c : channels) {
    list.push_back({{"id", c.id},
                    {"topic", c.topic},
                    {"encoding", c.encoding},
                    {"schemaName", c.schema_name},
                    {"schema", c.schema},
                    {"schemaEncoding", c.schema_encoding}});
  }
  return json{{"op", "advertise"}, {"channels", std::move(list)}};
}

json status_json(StatusLevel level, const std::string& message) {
  return json{{"op", "status"}, {"level", static_cast<int>(level)}, {"message", message}};
}

std::string message_data_frame(std::uint32_t subscription_id, std::uint64_t receive_ns, const std::uint8_t* payload,
                               std::size_t size) {
  std::string frame(kMessageDataHeaderBytes + size, '\0');
  frame[0] = static_cast<char>(kOpMessageData);
  for (int i = 0; i < 4; ++i) frame[1 + i] = static_cast<char>((subscription_id >> (8 * i)) & 0xffU);
  for (int i = 0; i < 8; ++i) frame[5 + i] = static_cast<char>((receive_ns >> (8 * i)) & 0xffU);
  if (size > 0) std::memcpy(frame.data() + kMessageDataHeaderBytes, payload, size);
  return frame;
}

ClientSession::ClientSession(std::vector<std::uint32_t> channel_ids, std::vector<PublishableTopic> publishable)
    : channel_ids_(std::move(channel_ids)), publishable_(std::move(publishable)) {}

namespace {

/// A JSON number that is an integer in [0, 2^32): the ids of the protocol.
bool as_uint32(const json& value, std::uint32_t& out) {
  if (!value.is_number_integer()) return false;
  if (value.is_number_unsigned()) {
    const auto v = value.get<std::uint64_t>();
    if (v > 0xffffffffULL) return false;
    out = static_cast<std::uint32_t>(v);
    return true;
  }
  const auto v = value.get<std::int64_t>();
  if (v < 0 || v > 0xffffffffLL) return false;
  out = static_cast<std::uint32_t>(v);
  return true;
}

}  // namespace

std::vector<std::string> ClientSession::handle_text(std::string_view text) {
  std::vector<std::string> errors;
  const json request = json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (request.is_discarded()) return {"malformed JSON (" + std::to_string(text.size()) + " bytes)"};
  if (!request.is_object() || !request.contains("op") || !request["op"].is_string()) {
    return {"a request must be a JSON object with a string field \"op\""};
  }
  const std::string op = request["op"];
  if (op == "subscribe") {
    if (!request.contains("subscriptions") || !request["subscriptions"].is_array()) {
      return {"subscribe: \"subscriptions\" must be an array"};
    }
    for (const auto& item : request["subscriptions"]) {
      std::uint32_t id = 0, channel = 0;
      if (!item.is_object() || !item.contains("id") || !item.contains("channelId") || !as_uint32(item["id"], id) ||
          !as_uint32(item["channelId"], channel)) {
        errors.push_back("subscribe: each subscription needs integer \"id\" and \"channelId\" in [0, 2^32), got " +
                         item.dump());
        continue;
      }
      if (std::find(channel_ids_.begin(), channel_ids_.end(), channel) == channel_ids_.end()) {
        errors.push_back("subscribe: unknown channel id " + std::to_string(channel));
        continue;
      }
      if (channel_of_subscription_.count(id) != 0) {
        errors.push_back("subscribe: subscription id " + std::to_string(id) + " is already in use");
        continue;
      }
      if (subscription_of_channel_.count(channel) != 0) {
        errors.push_back("subscribe: channel " + std::to_string(channel) + " is already subscribed (subscription " +
                         std::to_string(subscription_of_channel_[channel]) + ")");
        continue;
      }
      channel_of_subscription_[id] = channel;
      subscription_of_channel_[channel] = id;
    }
    return errors;
  }
  if (op == "unsubscribe") {
    if (!request.contains("subscriptionIds") || !request["subscriptionIds"].is_array()) {
      return {"unsubscribe: \"subscriptionIds\" must be an array"};
    }
    for (const auto& item : request["subscriptionIds"]) {
      std::uint32_t id = 0;
      if (!as_uint32(item, id)) {
        errors.push_back("unsubscribe: a subscription id must be an integer in [0, 2^32), got " + item.dump());
        continue;
      }
      const auto found = channel_of_subscription_.find(id);
      if (found == channel_of_subscription_.end()) {
        errors.push_back("unsubscribe: unknown subscription id " + std::to_string(id));
        continue;
      }
      subscription_of_channel_.erase(found->second);
      channel_of_subscription_.erase(found);
    }
    return errors;
  }
  if (op == "advertise" || op == "unadvertise") {
    if (!may_publish()) return {op + ": client publishing is off (log in as an operator)"};
    const char* list = op == "advertise" ? "channels" : "channelIds";
    if (!request.contains(list) || !request[list].is_array()) return {op + ": \"" + list + "\" must be an array"};
    for (const auto& item : request[list]) {
      std::uint32_t id = 0;
      if (op == "unadvertise") {
        if (!as_uint32(item, id) || advertised_.erase(id) == 0) {
          errors.push_back("unadvertise: unknown client channel id " + item.dump());
        }
        continue;
      }
      if (!item.is_object() || !item.contains("id") || !as_uint32(item["id"], id) || !item.contains("topic") ||
          !item["topic"].is_string() || !item.contains("encoding") || !item["encoding"].is_string()) {
        errors.push_back("advertise: each channel needs an integer \"id\" in [0, 2^32), a string \"topic\" and "
                         "\"encoding\", got " + item.dump());
        continue;
      }
      const std::string topic = item["topic"];
      const auto found = std::find_if(publishable_.begin(), publishable_.end(),
                                      [&](const PublishableTopic& t) { return t.topic == topic; });
      if (found == publishable_.end()) {
        errors.push_back("advertise: topic " + topic + " is not published by operators here");
        continue;
      }
      if (item["encoding"] != "cdr") {
        errors.push_back("advertise: topic " + topic + " must be encoded \"cdr\", not " + item["encoding"].dump());
        continue;
      }
      if (item.contains("schemaName") && item["schemaName"] != found->schema_name) {
        errors.push_back("advertise: topic " + topic + " has schema " + found->schema_name + ", not " +
                         item["schemaName"].dump());
        continue;
      }
      if (advertised_.count(id) != 0) {
        errors.push_back("advertise: client channel id " + std::to_string(id) + " is already in use");
        continue;
      }
      advertised_[id] = static_cast<std::size_t>(found - publishable_.begin());
    }
    return errors;
  }
  return {op + ": not supported by this server (no parameters, services or assets)"};
}

std::string ClientSession::handle_binary(std::string_view frame, ClientMessage& message) const {
  if (!may_publish()) return "binary frame refused: client publishing is off (log in as an operator)";
  if (frame.size() <= kClientMessageHeaderBytes) {
    return "binary frame of " + std::to_string(frame.size()) + " bytes: a Client Message Data frame has " +
           std::to_string(kClientMessageHeaderBytes) + " header bytes and a payload";
  }
  if (static_cast<std::uint8_t>(frame[0]) != kOpClientMessageData) {
    return "binary opcode " + std::to_string(static_cast<unsigned>(static_cast<std::uint8_t>(frame[0]))) +
           " refused: only Client Message Data (1)";
  }
  std::uint32_t id = 0;
  for (int i = 0; i < 4; ++i) id |= static_cast<std::uint32_t>(static_cast<std::uint8_t>(frame[1 + i])) << (8 * i);
  const auto found = advertised_.find(id);
  if (found == advertised_.end()) return "client channel " + std::to_string(id) + " was not advertised";
  message.topic_index = found->second;
  message.data = reinterpret_cast<const std::uint8_t*>(frame.data()) + kClientMessageHeaderBytes;
  message.size = frame.size() - kClientMessageHeaderBytes;
  return {};
}

bool ClientSession::subscription_of(std::uint32_t channel_id, std::uint32_t& subscription_id) const noexcept {
  const auto found = subscription_of_channel_.find(channel_id);
  if (found == subscription_of_channel_.end()) return false;
  subscription_id = found->second;
  return true;
}

}  // namespace crane::web
