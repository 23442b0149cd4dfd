// crane_web's operators: client publishing in the protocol core (advertise, Client Message Data) and
// the operator tokens, sessions and same-origin rule (operator_auth.hpp).
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

#include "crane/web/foxglove_protocol.hpp"
#include "crane/web/operator_auth.hpp"

namespace {

namespace fs = std::filesystem;
using crane::web::ClientMessage;
using crane::web::ClientSession;
using crane::web::OperatorAuth;
using crane::web::PublishableTopic;

const std::vector<PublishableTopic> kPublishable{{"rt/crane/planner/goal", "crane_msgs::msg::dds_::MoveRequest_"},
                                                 {"rt/crane/safety/command", "crane_msgs::msg::dds_::SupervisorCommand_"}};

std::string frame(std::uint8_t opcode, std::uint32_t channel, const std::string& payload) {
  std::string f(5, '\0');
  f[0] = static_cast<char>(opcode);
  for (int i = 0; i < 4; ++i) f[1 + i] = static_cast<char>((channel >> (8 * i)) & 0xffU);
  return f + payload;
}

TEST(ClientPublishing, OnlyAnOperatorsSessionAdvertisesAndPublishesTheListedTopics) {
  ClientSession reader({1, 2});
  ClientMessage message;
  EXPECT_EQ(reader.handle_text(R"({"op":"advertise","channels":[{"id":1,"topic":"rt/crane/planner/goal","encoding":"cdr"}]})"),
            std::vector<std::string>{"advertise: client publishing is off (log in as an operator)"});
  EXPECT_EQ(reader.handle_binary(frame(1, 1, "xxxx"), message),
            "binary frame refused: client publishing is off (log in as an operator)");

  ClientSession operator_session({1, 2}, kPublishable);
  EXPECT_TRUE(operator_session.may_publish());
  EXPECT_TRUE(operator_session
                  .handle_text(R"({"op":"advertise","channels":[{"id":7,"topic":"rt/crane/safety/command","encoding":"cdr",)"
                               R"("schemaName":"crane_msgs::msg::dds_::SupervisorCommand_"}]})")
                  .empty());
  const auto refused = operator_session.handle_text(
      R"({"op":"advertise","channels":[{"id":8,"topic":"rt/crane/hw/actuators","encoding":"cdr"},)"
      R"({"id":9,"topic":"rt/crane/planner/goal","encoding":"json"},)"
      R"({"id":10,"topic":"rt/crane/planner/goal","encoding":"cdr","schemaName":"Other"},)"
      R"({"id":7,"topic":"rt/crane/planner/goal","encoding":"cdr"},{"id":-3}]})");
  ASSERT_EQ(refused.size(), 5U);
  EXPECT_EQ(refused[0], "advertise: topic rt/crane/hw/actuators is not published by operators here");
  EXPECT_EQ(refused[1], R"(advertise: topic rt/crane/planner/goal must be encoded "cdr", not "json")");
  EXPECT_EQ(refused[2], R"(advertise: topic rt/crane/planner/goal has schema crane_msgs::msg::dds_::MoveRequest_, not "Other")");
  EXPECT_EQ(refused[3], "advertise: client channel id 7 is already in use");
  EXPECT_NE(refused[4].find("needs an integer \"id\""), std::string::npos);

  ASSERT_EQ(operator_session.handle_binary(frame(1, 7, "CDRBYTES"), message), "");
  EXPECT_EQ(message.topic_index, 1U);
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(message.data), message.size), "CDRBYTES");
  EXPECT_EQ(operator_session.handle_binary(frame(1, 8, "x"), message), "client channel 8 was not advertised");
  EXPECT_EQ(operator_session.handle_binary(frame(2, 7, "x"), message), "binary opcode 2 refused: only Client Message Data (1)");
  EXPECT_EQ(operator_session.handle_binary(frame(1, 7, ""), message),
            "binary frame of 5 bytes: a Client Message Data frame has 5 header bytes and a payload");
  EXPECT_TRUE(operator_session.handle_text(R"({"op":"unadvertise","channelIds":[7]})").empty());
  EXPECT_EQ(operator_session.handle_binary(frame(1, 7, "x"), message), "client channel 7 was not advertised");
  EXPECT_EQ(operator_session.handle_text(R"({"op":"unadvertise","channelIds":[7]})"),
            std::vector<std::string>{"unadvertise: unknown client channel id 7"});
}

TEST(ClientPublishing, ServerInfoAnnouncesPublishingToTheOperatorOnly) {
  const auto reader = crane::web::server_info_json("crane_web", "1");
  EXPECT_TRUE(reader["capabilities"].empty());
  EXPECT_EQ(reader["metadata"]["clientPublish"], "off");
  const auto op = crane::web::server_info_json("crane_web", "1", "alice");
  EXPECT_EQ(op["capabilities"], nlohmann::json::array({"clientPublish"}));
  EXPECT_EQ(op["supportedEncodings"], nlohmann::json::array({"cdr"}));
  EXPECT_EQ(op["metadata"]["clientPublish"], "operator alice");
}

class OperatorsFile : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (fs::temp_directory_path() / ("crane_operators_" + std::to_string(getpid()))).string();
    fs::remove(path_);
  }
  void TearDown() override { fs::remove(path_); }
  std::string path_;
};

TEST_F(OperatorsFile, TokensLogInSessionsExpireAndTheFileHoldsOnlyHashes) {
  const std::string alice = OperatorAuth::add_operator(path_, "alice");
  const std::string bob = OperatorAuth::add_operator(path_, "bob");
  EXPECT_EQ(alice.size(), 64U);
  EXPECT_NE(alice, bob);
  struct stat info {};
  ASSERT_EQ(::stat(path_.c_str(), &info), 0);
  EXPECT_EQ(info.st_mode & 0777, 0600U);
  std::ifstream in(path_);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find(alice), std::string::npos) << "the token itself must not be stored";
  EXPECT_NE(text.find("alice " + OperatorAuth::sha256_hex(alice)), std::string::npos);
  // SHA-256 of "abc" (FIPS 180-2, appendix B.1).
  EXPECT_EQ(OperatorAuth::sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_THROW(OperatorAuth::add_operator(path_, "alice"), std::runtime_error);
  EXPECT_THROW(OperatorAuth::add_operator(path_, "no spaces"), std::runtime_error);

  OperatorAuth auth(path_, 60.0);
  // A token one digit off (the first digit changed: "0" + the rest was alice's own token whenever
  // it began with 0, one run in 16).
  EXPECT_FALSE(auth.login((alice[0] == '0' ? "1" : "0") + alice.substr(1), 0.0).has_value());
  EXPECT_FALSE(auth.login("", 0.0).has_value());
  const auto session = auth.login(alice, 100.0);
  ASSERT_TRUE(session.has_value());
  const std::string cookie = "theme=dark; crane_operator=" + *session + "; other=1";
  EXPECT_EQ(auth.operator_of(cookie, 159.0).value_or(""), "alice");
  EXPECT_FALSE(auth.operator_of(cookie, 160.0).has_value()) << "expired after the session lifetime";
  EXPECT_FALSE(auth.operator_of("crane_operator=" + std::string(64, 'a'), 100.0).has_value());
  EXPECT_FALSE(auth.operator_of("", 100.0).has_value());
  const auto bobs = auth.login(bob, 200.0);
  ASSERT_TRUE(bobs.has_value());
  EXPECT_EQ(auth.operator_of("crane_operator=" + *bobs, 200.0).value_or(""), "bob");
  auth.logout("crane_operator=" + *bobs);
  EXPECT_FALSE(auth.operator_of("crane_operator=" + *bobs, 200.0).has_value());
}

TEST_F(OperatorsFile, BadFilesAreRefusedNamingTheFileAndLine) {
  auto expect_refused = [&](const std::string& content, const std::string& part, mode_t mode = 0600) {
    {
      std::ofstream out(path_, std::ios::trunc);
      out << content;
    }
    ::chmod(path_.c_str(), mode);
    try {
      OperatorAuth auth(path_, 60.0);
      ADD_FAILURE() << "accepted: " << content;
    } catch (const std::runtime_error& error) {
      EXPECT_NE(std::string(error.what()).find(path_), std::string::npos) << error.what();
      EXPECT_NE(std::string(error.what()).find(part), std::string::npos) << error.what();
    }
  };
  expect_refused("# nobody\n", "no operator");
  expect_refused("alice 1234\n", "line 1");
  expect_refused("# x\nalice " + std::string(64, 'a') + "\nalice " + std::string(64, 'b') + "\n", "line 3: operator alice repeated");
  expect_refused("alice " + std::string(64, 'a') + "\n", "mode 644", 0644);
  fs::remove(path_);
  try {
    OperatorAuth auth(path_, 60.0);
    ADD_FAILURE() << "a missing file was accepted";
  } catch (const std::runtime_error& error) {
    EXPECT_EQ(std::string(error.what()), "operators file " + path_ + ": cannot be read");
  }
}

TEST(SameOrigin, TheHandshakeMustComeFromThePageOfThisServer) {
  EXPECT_TRUE(crane::web::same_origin("", "127.0.0.1:8765"));
  EXPECT_TRUE(crane::web::same_origin("http://127.0.0.1:8765", "127.0.0.1:8765"));
  EXPECT_TRUE(crane::web::same_origin("https://crane.local", "crane.local"));
  EXPECT_FALSE(crane::web::same_origin("http://evil.example", "127.0.0.1:8765"));
  EXPECT_FALSE(crane::web::same_origin("http://127.0.0.1:8765.evil", "127.0.0.1:8765"));
  EXPECT_FALSE(crane::web::same_origin("null", "127.0.0.1:8765"));
  EXPECT_EQ(crane::web::cookie_value("a=1; crane_operator=xyz; b=2", "crane_operator"), "xyz");
  EXPECT_EQ(crane::web::cookie_value("crane_operatorx=1", "crane_operator"), "");
}

}  // namespace
