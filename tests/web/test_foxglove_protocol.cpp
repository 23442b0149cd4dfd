// crane_web's protocol pieces without a socket: the Foxglove messages and requests
// (deploy/web/foxglove_protocol.hpp, against the spec's byte layout and JSON fields), the bounded
// send queue, and the CDR bytes of a sample (transport/cdr.hpp) against Fast DDS's own decoding.
// The end-to-end check with Foxglove's own client is tests/web/foxglove_client_test.sh.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "crane/protocol/dds.hpp"
#include "crane/protocol/idl_schema.hpp"
#include "crane/transport/cdr.hpp"
#include "crane/web/foxglove_protocol.hpp"
#include "crane/web/send_queue.hpp"
#include "crane_msgs_random.hpp"

namespace {

using namespace crane;
using nlohmann::json;

TEST(FoxgloveProtocol, MessageDataFrameIsOpcodeSubscriptionTimestampPayloadLittleEndian) {
  // spec.md, "Message Data": 1 byte opcode 0x01, uint32 subscription id, uint64 receive timestamp
  // [ns], then the payload; integers little endian.
  const std::vector<std::uint8_t> payload{0x00, 0x01, 0x00, 0x00, 0xab};
  const std::string frame = web::message_data_frame(0x04030201U, 0x0c0b0a0908070605ULL, payload.data(), payload.size());
  const std::vector<std::uint8_t> expected{0x01, 0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08,
                                           0x09, 0x0a, 0x0b, 0x0c, 0x00, 0x01, 0x00, 0x00, 0xab};
  ASSERT_EQ(frame.size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i) EXPECT_EQ(static_cast<std::uint8_t>(frame[i]), expected[i]) << i;
}

TEST(FoxgloveProtocol, ServerInfoAnnouncesNoClientPublishing) {
  const json info = web::server_info_json("crane_web", "1");
  EXPECT_EQ(info["op"], "serverInfo");
  EXPECT_TRUE(info["capabilities"].is_array());
  for (const auto& c : info["capabilities"]) EXPECT_NE(c, "clientPublish");
  EXPECT_EQ(info["metadata"]["clientPublish"], "off");
}

TEST(FoxgloveProtocol, AdvertiseCarriesEveryChannelField) {
  const json a = web::advertise_json({{7, "rt/x", "cdr", "m::X_", "omgidl", "struct X_ { double v; };"}});
  ASSERT_EQ(a["op"], "advertise");
  ASSERT_EQ(a["channels"].size(), 1U);
  const auto& c = a["channels"][0];
  EXPECT_EQ(c["id"], 7);
  EXPECT_EQ(c["topic"], "rt/x");
  EXPECT_EQ(c["encoding"], "cdr");
  EXPECT_EQ(c["schemaName"], "m::X_");
  EXPECT_EQ(c["schemaEncoding"], "omgidl");
  EXPECT_EQ(c["schema"], "struct X_ { double v; };");
}

TEST(FoxgloveProtocol, SubscribeAndUnsubscribeChangeWhatTheClientGets) {
  web::ClientSession session({1, 2, 3});
  EXPECT_TRUE(session.handle_text(R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":1},{"id":11,"channelId":3}]})").empty());
  std::uint32_t id = 0;
  ASSERT_TRUE(session.subscription_of(1, id));
  EXPECT_EQ(id, 10U);
  ASSERT_TRUE(session.subscription_of(3, id));
  EXPECT_EQ(id, 11U);
  EXPECT_FALSE(session.subscription_of(2, id));
  EXPECT_TRUE(session.handle_text(R"({"op":"unsubscribe","subscriptionIds":[10]})").empty());
  EXPECT_FALSE(session.subscription_of(1, id));
  // After unsubscribing, the client may reuse the id (spec.md, "Subscribe").
  EXPECT_TRUE(session.handle_text(R"({"op":"subscribe","subscriptions":[{"id":10,"channelId":2}]})").empty());
  ASSERT_TRUE(session.subscription_of(2, id));
  EXPECT_EQ(id, 10U);
  EXPECT_EQ(session.subscription_count(), 2U);
}

TEST(FoxgloveProtocol, BadRequestsAreRefusedNamingWhatWasWrongAndChangeNothing) {
  web::ClientSession session({1, 2});
  ASSERT_TRUE(session.handle_text(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":1}]})").empty());
  const auto first = [&](std::string_view text) {
    const auto errors = session.handle_text(text);
    return errors.empty() ? std::string("(accepted)") : errors.front();
  };
  EXPECT_EQ(first("{not json"), "malformed JSON (9 bytes)");
  EXPECT_EQ(first(R"([1,2])"), R"(a request must be a JSON object with a string field "op")");
  EXPECT_EQ(first(R"({"op":"subscribe","subscriptions":[{"id":6,"channelId":99}]})"), "subscribe: unknown channel id 99");
  EXPECT_EQ(first(R"({"op":"subscribe","subscriptions":[{"id":5,"channelId":2}]})"),
            "subscribe: subscription id 5 is already in use");
  EXPECT_EQ(first(R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":1}]})"),
            "subscribe: channel 1 is already subscribed (subscription 5)");
  EXPECT_NE(first(R"({"op":"subscribe","subscriptions":[{"id":-1,"channelId":2}]})").find("integer \"id\""),
            std::string::npos);
  EXPECT_EQ(first(R"({"op":"unsubscribe","subscriptionIds":[42]})"), "unsubscribe: unknown subscription id 42");
  EXPECT_EQ(first(R"({"op":"advertise","channels":[]})"),
            "advertise: client publishing is off (log in as an operator)");
  EXPECT_EQ(first(R"({"op":"getParameters","parameterNames":[]})"),
            "getParameters: not supported by this server (no parameters, services or assets)");
  // Nothing of that changed the session.
  std::uint32_t id = 0;
  ASSERT_TRUE(session.subscription_of(1, id));
  EXPECT_EQ(id, 5U);
  EXPECT_FALSE(session.subscription_of(2, id));
  EXPECT_EQ(session.subscription_count(), 1U);
}

TEST(SendQueue, DropsTheOldestFrameWhenFull) {
  web::SendQueue queue(3);
  for (int i = 1; i <= 5; ++i) EXPECT_EQ(queue.push(std::to_string(i), 0.01 * i), i > 3) << i;
  EXPECT_EQ(queue.dropped(), 2U);
  std::string frame;
  std::string order;
  while (queue.pop(frame)) order += frame;
  EXPECT_EQ(order, "345");
  EXPECT_THROW(web::SendQueue(0), std::invalid_argument);
}

// The rule that closes a client that never reads (crane_web --close-stalled): every push dropping a
// frame for the limit. Pushes at 100 Hz into a queue of 4 frames; the client takes `reads_per_push`
// frames after each push (what the socket took), or nothing.
TEST(SendQueue, AClientWhoseEverySampleIsDroppedForTheLimitIsNotReadingAndAnyReadEndsTheRun) {
  constexpr double kLimit = 10.0;  // [s]
  constexpr double kPeriod = 0.01;  // [s]
  std::string frame;
  {
    // Never reads: the queue fills at the 4th push; the 5th drops (t = 0.04 s) and every push after
    // it does; not reading once 10 s have passed since that first drop, not a push before.
    web::SendQueue queue(4);
    double first_not_reading = -1.0;
    for (int i = 0; i <= 1100 && first_not_reading < 0.0; ++i) {
      const double t = i * kPeriod;
      EXPECT_EQ(queue.push("s", t), i >= 4) << i;
      if (queue.not_reading(t, kLimit)) first_not_reading = t;
    }
    EXPECT_NEAR(first_not_reading, 0.04 + kLimit, 1e-9);
    EXPECT_NEAR(queue.dropping_for(first_not_reading), kLimit, 1e-9);
  }
  {
    // Reads one frame in three (a client at a third of the rate): drops most samples, but every
    // third push finds room, so it is never "not reading", over 60 s.
    web::SendQueue queue(4);
    double longest_run = 0.0;
    for (int i = 0; i < 6000; ++i) {
      const double t = i * kPeriod;
      queue.push("s", t);
      if (i % 3 == 0) queue.pop(frame);
      longest_run = std::max(longest_run, queue.dropping_for(t));
      ASSERT_FALSE(queue.not_reading(t, kLimit)) << "t = " << t;
    }
    EXPECT_GT(queue.dropped(), 3000U);  // it did lose most samples
    EXPECT_LT(longest_run, 3 * kPeriod);
  }
  {
    // Stalls for 9.96 s (dropping), reads once, stalls again: the run starts over at the next drop.
    web::SendQueue queue(4);
    int i = 0;
    for (; i * kPeriod < 10.0; ++i) queue.push("s", i * kPeriod);
    const double t_read = i * kPeriod;  // 10.0 s: dropping since 0.04 s, 9.96 s
    EXPECT_FALSE(queue.not_reading(t_read, kLimit));
    queue.pop(frame);
    EXPECT_FALSE(queue.push("s", t_read));  // found room: the run of drops ended
    EXPECT_EQ(queue.dropping_for(t_read), 0.0);
    EXPECT_FALSE(queue.not_reading(t_read + 5.0, kLimit));
    EXPECT_TRUE(queue.push("s", t_read + kPeriod));  // full again: a new run from here
    EXPECT_FALSE(queue.not_reading(t_read + kPeriod + 9.99, kLimit));
    EXPECT_TRUE(queue.not_reading(t_read + kPeriod + kLimit + 1e-9, kLimit));
  }
}

TEST(IdlSchema, IsTheIdlWithItsHexLiteralsInDecimal) {
  // Cross-check of the build-time embedding: every "const ... = 0x..." of the IDL appears in the
  // schema with the same value in decimal, and no hex literal is left.
  EXPECT_EQ(std::string(protocol::kIdlSchema).find("0x"), std::string::npos);
  EXPECT_NE(std::string(protocol::kIdlSchema).find("FAULT_EMERGENCY_STOP = 16;"), std::string::npos);
  EXPECT_NE(std::string(protocol::kIdlSchema).find("struct SensorSample_ {"), std::string::npos);
}

template <class Topic>
void expect_cdr_round_trip(std::mt19937_64& rng) {
  typename Topic::Message sent;
  transport::testing::fill_random(sent, rng);
  std::vector<std::uint8_t> bytes;
  ASSERT_TRUE(transport::serialize_cdr<Topic>(sent, bytes));
  // Encapsulation header of plain CDR, little endian (RTPS 2.x, 10.2: CDR_LE = 0x0001), options 0.
  ASSERT_GE(bytes.size(), 4U);
  EXPECT_EQ(bytes[0], 0x00);
  EXPECT_EQ(bytes[1], 0x01);
  EXPECT_EQ(bytes[2], 0x00);
  EXPECT_EQ(bytes[3], 0x00);
  // Fast DDS's own type support reads the bytes back to the same fields.
  typename Topic::FastDdsType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(bytes.size()));
  std::copy(bytes.begin(), bytes.end(), payload.data);
  payload.length = static_cast<std::uint32_t>(bytes.size());
  typename Topic::Message received;
  ASSERT_TRUE(type.deserialize(&payload, &received));
  EXPECT_TRUE(received == sent) << Topic::name;
}

TEST(Cdr, EveryTopicSerializesWithItsEncapsulationHeaderAndReadsBack) {
  std::mt19937_64 rng(16);
  for (int round = 0; round < 50; ++round) {
    transport::topics::for_each_topic([&]<class Topic>() { expect_cdr_round_trip<Topic>(rng); });
  }
}

}  // namespace
