// The operator's command exchange (crane/supervisor/operator_command.hpp) and the operator socket's
// messages (operator_socket.hpp), without DDS: what is written when, what is printed from which
// status, the exit codes, and the framing against malformed and random input.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <random>

#include "crane/supervisor/operator_command.hpp"
#include "crane/supervisor/operator_socket.hpp"

namespace {

using crane::supervisor::OperatorExchange;
using crane::supervisor::OperatorRequest;
using Status = crane::protocol::SupervisorStatus;
using Command = crane::protocol::SupervisorCommand;
using Clock = OperatorExchange::Clock;
using std::chrono::milliseconds;
namespace sock = crane::supervisor::operator_socket;

OperatorRequest request(std::string action, std::vector<std::string> arguments = {}, double timeout = 3.0) {
  OperatorRequest r;
  r.action = std::move(action);
  r.arguments = std::move(arguments);
  r.timeout = timeout;
  return r;
}

Status echo(std::uint32_t id, std::uint8_t result, std::uint8_t mode) {
  Status s;
  s.last_request_id = id;
  s.last_request_result = result;
  s.mode = mode;
  s.operating_mode = Status::OPERATION_FULLAUTOMATIC;
  s.stages_alive = Status::STAGES_ALL;
  return s;
}

TEST(OperatorExchange, EstopIsWrittenOnceMatchedAgainEvery50msAndAnsweredByItsEcho) {
  const auto t0 = Clock::now();
  OperatorExchange x(request("estop"), 77, 3, t0);
  EXPECT_FALSE(x.command_due(t0, false).has_value()) << "nothing is written before the supervisor's reader matches";
  const auto first = x.command_due(t0 + milliseconds(10), true);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->command, Command::COMMAND_EMERGENCY_STOP);
  EXPECT_EQ(first->request_id, 77U);
  EXPECT_FALSE(x.command_due(t0 + milliseconds(59), true).has_value());
  EXPECT_TRUE(x.command_due(t0 + milliseconds(60), true).has_value()) << "again after the resend period";
  EXPECT_EQ(x.next_check(t0 + milliseconds(61)), t0 + milliseconds(110));
  x.on_status(echo(76, Status::RESULT_ACCEPTED, Status::MODE_EMERGENCY_STOP), t0 + milliseconds(62));
  EXPECT_FALSE(x.done(t0 + milliseconds(62))) << "another request's echo is not the answer";
  auto answer = echo(77, Status::RESULT_ACCEPTED, Status::MODE_EMERGENCY_STOP);
  x.on_status(answer, t0 + milliseconds(70));
  ASSERT_TRUE(x.done(t0 + milliseconds(70)));
  EXPECT_EQ(x.outcome().exit_code, 0);
  EXPECT_EQ(x.outcome().out,
            "estop accepted: mode emergency_stop, operating mode fullautomatic, zones enforced none, brakes engaged\n");
  EXPECT_TRUE(x.outcome().err.empty());
  EXPECT_FALSE(x.command_due(t0 + milliseconds(200), true).has_value()) << "nothing once answered";
}

TEST(OperatorExchange, ARefusalExitsThreeNamingTheLatchedFaultsAndSilentStages) {
  const auto t0 = Clock::now();
  OperatorExchange x(request("arm"), 5, 0, t0);
  ASSERT_TRUE(x.command_due(t0, true).has_value());
  auto refused = echo(5, Status::RESULT_REFUSED, Status::MODE_FAULT);
  refused.latched_faults = Status::FAULT_STAGE_SILENT | Status::FAULT_SWING;
  refused.stages_alive = Status::STAGES_ALL & ~Status::STAGE_TRACKING;
  x.on_status(refused, t0 + milliseconds(20));
  ASSERT_TRUE(x.done(t0 + milliseconds(20)));
  EXPECT_EQ(x.outcome().exit_code, 3);
  EXPECT_NE(x.outcome().out.find("arm refused: mode fault"), std::string::npos) << x.outcome().out;
  EXPECT_NE(x.outcome().out.find("latched faults: stage_silent,swing; active: none; silent stages: tracking"),
            std::string::npos)
      << x.outcome().out;
}

TEST(OperatorExchange, TimeoutsSayWhetherTheSupervisorWasEverMatched) {
  const auto t0 = Clock::now();
  OperatorExchange unmatched(request("reset", {}, 0.5), 9, 12, t0);
  EXPECT_FALSE(unmatched.command_due(t0, false).has_value());
  EXPECT_FALSE(unmatched.done(t0 + milliseconds(499)));
  ASSERT_TRUE(unmatched.done(t0 + milliseconds(500)));
  EXPECT_EQ(unmatched.outcome().exit_code, 1);
  EXPECT_EQ(unmatched.outcome().err, "no supervisor listens on rt/crane/safety/command (domain 12) within 0.5 s\n");

  OperatorExchange silent(request("reset", {}, 0.5), 9, 12, t0);
  ASSERT_TRUE(silent.command_due(t0, true).has_value());
  ASSERT_TRUE(silent.done(t0 + milliseconds(600)));
  EXPECT_EQ(silent.outcome().exit_code, 1);
  EXPECT_EQ(silent.outcome().err, "the supervisor did not answer request 9 within 0.5 s\n");
}

TEST(OperatorExchange, BadUsageIsDoneAtOnceWithExitTwoNamingWhatIsWrong) {
  const auto t0 = Clock::now();
  const auto usage = [&](OperatorRequest r) {
    OperatorExchange x(std::move(r), 1, 0, t0);
    EXPECT_TRUE(x.done(t0));
    EXPECT_FALSE(x.command_due(t0, true).has_value());
    EXPECT_EQ(x.outcome().exit_code, 2);
    return x.outcome().err;
  };
  EXPECT_EQ(usage(request("mode", {"bogus"})), "mode needs one of manual, semiautomatic, fullautomatic, maintenance\n");
  EXPECT_EQ(usage(request("mode", {})), "mode needs one of manual, semiautomatic, fullautomatic, maintenance\n");
  EXPECT_EQ(usage(request("zone", {"enable", "32"})), "zone needs enable | disable and a zone index in [0, 31]\n");
  EXPECT_EQ(usage(request("zone", {"enable", "1x"})), "zone needs enable | disable and a zone index in [0, 31]\n");
  EXPECT_EQ(usage(request("zone", {"open", "1"})), "zone needs enable | disable and a zone index in [0, 31]\n");
  EXPECT_EQ(usage(request("estop", {"now"})), "estop takes no argument\n");
  EXPECT_EQ(usage(request("status", {"x"})), "status takes no argument\n");
  EXPECT_EQ(usage(request("launch")), "unknown command 'launch' (arm, disarm, estop, reset, status, mode, zone)\n");
  // The commands that take arguments build the right command.
  OperatorExchange mode(request("mode", {"maintenance"}), 2, 0, t0);
  const auto m = mode.command_due(t0, true);
  ASSERT_TRUE(m.has_value());
  EXPECT_EQ(m->command, Command::COMMAND_SET_OPERATING_MODE);
  EXPECT_EQ(m->operating_mode, Status::OPERATION_MAINTENANCE);
  OperatorExchange zone(request("zone", {"disable", "31"}), 3, 0, t0);
  const auto z = zone.command_due(t0, true);
  ASSERT_TRUE(z.has_value());
  EXPECT_EQ(z->command, Command::COMMAND_DISABLE_ZONE);
  EXPECT_EQ(z->zone, 31U);
}

TEST(OperatorExchange, StatusWaitsHalfASecondForTheEstimateThenPrintsWithoutIt) {
  const auto t0 = Clock::now();
  auto r = request("status");
  r.json = true;
  OperatorExchange x(r, 1, 0, t0);
  EXPECT_FALSE(x.command_due(t0, true).has_value()) << "status writes nothing";
  auto s = echo(0, Status::RESULT_NONE, Status::MODE_READY);
  s.active_faults = Status::FAULT_ZONE;
  s.header.seq = 1234;
  x.on_status(s, t0 + milliseconds(10));
  EXPECT_FALSE(x.done(t0 + milliseconds(509)));
  ASSERT_TRUE(x.done(t0 + milliseconds(510)));
  EXPECT_EQ(x.outcome().exit_code, 0);
  const auto json = nlohmann::json::parse(x.outcome().out);  // throws on a malformed object
  EXPECT_EQ(json["mode"], "ready");
  EXPECT_EQ(json["active_faults"], nlohmann::json::array({"zone"}));
  EXPECT_EQ(json["seq"], 1234);
  EXPECT_TRUE(json["estimate"].is_null());

  OperatorExchange with_estimate(request("status"), 1, 0, t0);
  with_estimate.on_status(s, t0);
  crane::protocol::CraneState e;
  e.adaptation = crane::protocol::CraneState::ADAPTATION_ENABLED;
  e.payload_mass = 3.012;
  e.payload_mass_bound = 0.041;
  e.payload_confident = true;
  with_estimate.on_estimate(e);
  ASSERT_TRUE(with_estimate.done(t0 + milliseconds(1)));
  EXPECT_NE(with_estimate.outcome().out.find("payload         3.012 kg +- 0.041 kg (online estimate, 2 sigma; in use)"),
            std::string::npos)
      << with_estimate.outcome().out;
  EXPECT_NE(with_estimate.outcome().out.find("pendulum        the planner's configured a L + c"), std::string::npos)
      << with_estimate.outcome().out;

  OperatorExchange learnt(request("status"), 1, 0, t0);
  learnt.on_status(s, t0);
  e.swing_length_scale = 1.0;
  e.swing_length_offset = 0.2031;
  e.swing_length_bound = 0.0042;
  e.swing_length_confident = true;
  learnt.on_estimate(e);
  ASSERT_TRUE(learnt.done(t0 + milliseconds(1)));
  EXPECT_NE(learnt.outcome().out.find("pendulum        1.0000 L +0.2031 m, +- 0.0042 m where learnt"), std::string::npos)
      << learnt.outcome().out;

  OperatorExchange nothing(request("status", {}, 0.2), 1, 4, t0);
  ASSERT_TRUE(nothing.done(t0 + milliseconds(200)));
  EXPECT_EQ(nothing.outcome().exit_code, 1);
  EXPECT_EQ(nothing.outcome().err, "no supervisor status on domain 4 within 0.2 s\n");
}

TEST(OperatorSocket, RequestsAndRepliesRoundTripAndMalformedOnesAreRefused) {
  EXPECT_EQ(sock::name(7), std::string("\0crane/operator_relay/7", 23));
  const std::vector<std::string> args{"zone", "enable", "3", "--timeout", "0.5", ""};
  const auto encoded = sock::encode_request(args);
  ASSERT_TRUE(encoded.has_value());
  EXPECT_EQ(sock::decode_request(*encoded), args);
  EXPECT_EQ(sock::decode_request("\n"), std::vector<std::string>{});
  EXPECT_FALSE(sock::encode_request({"a\nb"}).has_value());
  EXPECT_FALSE(sock::encode_request({std::string("a\0b", 3)}).has_value());
  EXPECT_FALSE(sock::encode_request({std::string(sock::kMaxRequestBytes, 'x')}).has_value());
  EXPECT_FALSE(sock::decode_request("estop").has_value()) << "no newline";
  EXPECT_FALSE(sock::decode_request("estop\n").has_value()) << "an argument without its NUL";
  EXPECT_FALSE(sock::decode_request(std::string("a\nb\0\n", 5)).has_value());
  EXPECT_FALSE(sock::decode_request(std::string(sock::kMaxRequestBytes, '\0') + "\n").has_value());

  const auto header = sock::reply_header(3, 120, 0);
  EXPECT_EQ(header, "3 120 0\n");
  const auto parsed = sock::decode_reply_header(std::string_view(header).substr(0, header.size() - 1));
  ASSERT_TRUE(parsed.has_value());
  EXPECT_EQ(parsed->exit_code, 3);
  EXPECT_EQ(parsed->out_bytes, 120U);
  EXPECT_EQ(parsed->err_bytes, 0U);
  for (const char* bad : {"", "3", "3 1", "3 1 2 ", "a 1 2", "256 1 2", "3  1 2", "3 1 2x", "3 99999999 0", "-1 0 0"}) {
    EXPECT_FALSE(sock::decode_reply_header(bad).has_value()) << "'" << bad << "'";
  }
}

// Seeded random requests: every encodable one decodes to itself; random bytes never crash the
// decoders and decode only to what encodes back to the same bytes.
TEST(OperatorSocket, SeededRandomRequestsRoundTripAndRandomBytesNeverDecodeToSomethingElse) {
  std::mt19937 random(20261123);
  std::uniform_int_distribution<int> byte(0, 255), count(0, 6), length(0, 40);
  int encodable = 0, decoded_random = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    std::vector<std::string> args(static_cast<std::size_t>(count(random)));
    for (auto& a : args) {
      a.resize(static_cast<std::size_t>(length(random)));
      for (auto& c : a) c = static_cast<char>(trial % 2 ? byte(random) : 'a' + byte(random) % 26);
    }
    if (const auto e = sock::encode_request(args)) {
      ++encodable;
      EXPECT_EQ(sock::decode_request(*e), args);
    }
    std::string bytes(static_cast<std::size_t>(length(random)), '\0');
    for (auto& c : bytes) c = static_cast<char>(byte(random) % 4 == 0 ? '\0' : byte(random));
    if (trial % 3 == 0) bytes += '\n';
    if (const auto d = sock::decode_request(bytes)) {
      ++decoded_random;
      EXPECT_EQ(sock::encode_request(*d), bytes);
    }
    (void)sock::decode_reply_header(bytes);
  }
  std::printf("20000 seeded trials: %d encodable argument lists round-tripped, %d random byte strings decoded\n",
              encodable, decoded_random);
  EXPECT_GT(encodable, 10000);
  EXPECT_GT(decoded_random, 0);
}

}  // namespace
