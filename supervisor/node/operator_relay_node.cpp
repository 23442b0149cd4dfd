// operator_relay process: the stack's long-lived operator participant. It serves the operator's
// commands to the supervisor (arm, disarm, estop, reset, mode, zone, status) that crane_operator
// sends over a local socket (crane/supervisor/operator_socket.hpp), so that `deploy/crane estop`
// does not wait for a new participant's discovery: this one matched the supervisor when the stack
// started. Each command runs the same exchange as crane_safety (crane/supervisor/operator_command.hpp:
// written at once, again every 50 ms until the supervisor's status echoes it, the answer printed
// from that status); the relay adds nothing to the supervisor's rules. DDS identity: "operator"
// (the tool role's permissions, deploy/crane security init).
//
// One thread: Boost.Asio accepts and reads the clients; while an exchange is pending, a 5 ms timer
// takes the status and estimate samples and advances it (idle, the relay does not wake). A client must be this process's user or root, send
// its request within 5 s and keep it under operator_socket::kMaxRequestBytes; at most 16 clients
// are admitted at once, from connection to answer (a command waits at most its --timeout, 60 s).
// A client that goes away mid-exchange loses only its reply: a command already written stays written.
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <utility>  // before Boost.Asio 1.74: its awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>
#include <chrono>
#include <list>
#include <memory>
#include <sstream>
#include <string>

#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/supervisor/operator_command.hpp"
#include "crane/supervisor/operator_socket.hpp"

namespace {

using namespace crane;
namespace asio = boost::asio;
namespace tp = transport::topics;
using Local = asio::local::stream_protocol;
using Clock = std::chrono::steady_clock;
using supervisor::OperatorExchange;

constexpr auto kPollPeriod = std::chrono::milliseconds(5);
constexpr auto kRequestTimeout = std::chrono::seconds(5);
constexpr std::size_t kMaxClients = 16;

class Relay {
 public:
  Relay(asio::io_context& io, transport::Participant& participant, std::uint32_t domain, std::string config_path)
      : io_(io),
        acceptor_(io),
        poll_(io),
        domain_(domain),
        config_path_(std::move(config_path)),
        status_reader_(participant.make_reader<tp::SafetyStatus>(&wakeup_)),
        estimate_reader_(participant.make_reader<tp::StateEstimate>(&wakeup_)),
        command_writer_(participant.make_writer<tp::SafetyCommand>()) {
    const Local::endpoint endpoint(supervisor::operator_socket::name(domain));
    acceptor_.open(endpoint.protocol());
    boost::system::error_code error;
    acceptor_.bind(endpoint, error);
    if (error) {
      throw std::runtime_error("cannot listen on the operator socket of domain " + std::to_string(domain) + ": " +
                               error.message() +
                               (error == asio::error::address_in_use
                                    ? " (another stack's operator relay serves this domain in this network namespace)"
                                    : ""));
    }
    acceptor_.listen();
    accept();
  }

 private:
  struct Client {
    explicit Client(asio::io_context& io) : socket(io), request_timer(io), buffer(supervisor::operator_socket::kMaxRequestBytes) {}
    Local::socket socket;
    asio::steady_timer request_timer;
    asio::streambuf buffer;
    std::unique_ptr<OperatorExchange> exchange;
    std::string reply;
    bool counted{false};  // one of the kMaxClients, from admission to its answer
  };
  using ClientPtr = std::shared_ptr<Client>;

  void accept() {
    auto client = std::make_shared<Client>(io_);
    acceptor_.async_accept(client->socket, [this, client](const boost::system::error_code& error) {
      if (error == asio::error::operation_aborted) return;
      if (!error) admit(client);
      accept();
    });
  }

  void admit(const ClientPtr& client) {
    ucred peer{};
    socklen_t size = sizeof peer;
    if (getsockopt(client->socket.native_handle(), SOL_SOCKET, SO_PEERCRED, &peer, &size) != 0 ||
        (peer.uid != geteuid() && peer.uid != 0)) {
      spdlog::warn("operator socket: refused a client of uid {} (this stack runs as uid {})", peer.uid, geteuid());
      answer(client, {1, "", "refused: the operator relay serves its own user (uid " +
                                 std::to_string(geteuid()) + ") and root\n"});
      return;
    }
    if (active_ >= kMaxClients) {
      answer(client, {1, "", "refused: " + std::to_string(kMaxClients) + " commands already pending\n"});
      return;
    }
    ++active_;
    client->counted = true;
    client->request_timer.expires_after(kRequestTimeout);
    client->request_timer.async_wait([client](const boost::system::error_code& error) {
      if (!error) client->socket.close();  // no complete request in time
    });
    asio::async_read_until(client->socket, client->buffer, '\n',
                           [this, client](const boost::system::error_code& error, std::size_t bytes) {
                             client->request_timer.cancel();
                             if (error) {
                               release(*client);
                               if (error != asio::error::operation_aborted && error != asio::error::eof) {
                                 answer(client, {2, "", "request not read: " + error.message() +
                                                            " (at most " +
                                                            std::to_string(supervisor::operator_socket::kMaxRequestBytes) +
                                                            " bytes, ended by a newline)\n"});
                               }
                               return;
                             }
                             const std::string request(asio::buffers_begin(client->buffer.data()),
                                                       asio::buffers_begin(client->buffer.data()) +
                                                           static_cast<std::ptrdiff_t>(bytes));
                             start(client, request);
                           });
  }

  void start(const ClientPtr& client, const std::string& request) {
    const auto arguments = supervisor::operator_socket::decode_request(request);
    if (!arguments) {
      answer(client, {2, "", "malformed request (arguments each ended by NUL, then a newline)\n"});
      return;
    }
    supervisor::OperatorRequest parsed;
    parsed.config_path = config_path_;  // the stack's, unless the command names another
    CLI::App app{"operator_relay: a command for the supervisor"};
    supervisor::add_operator_options(app, parsed);
    try {
      std::vector<std::string> reversed(arguments->rbegin(), arguments->rend());  // CLI11 takes them reversed
      app.parse(reversed);
    } catch (const CLI::ParseError& error) {
      std::ostringstream out, err;
      const int code = app.exit(error, out, err);
      answer(client, {code == 0 ? 0 : 2, out.str(), err.str()});
      return;
    }
    // Samples taken before the request predate it (the readers keep the last one, however old:
    // the supervisor may have gone since): an exchange sees only those that arrive after it starts.
    drain();
    const auto now = Clock::now();
    const auto id = static_cast<std::uint32_t>((static_cast<std::uint64_t>(getpid()) << 20) ^
                                               static_cast<std::uint64_t>(runtime::now_nanoseconds()) ^ ++requests_);
    client->exchange = std::make_unique<OperatorExchange>(parsed, id == 0 ? 1U : id, domain_, now);
    spdlog::info("operator command '{}' (request {})", parsed.action, id);
    if (advance(client, now)) return;
    pending_.push_back(client);
    if (pending_.size() == 1) schedule_poll();
  }

  void drain() {
    tp::msgs::SupervisorStatus_ status;
    while (status_reader_->take_next(status)) {
    }
    tp::msgs::CraneState_ estimate;
    while (estimate_reader_->take_next(estimate)) {
    }
  }

  // Idle, the relay sleeps: the timer runs only while an exchange is pending.
  void schedule_poll() {
    poll_.expires_after(kPollPeriod);
    poll_.async_wait([this](const boost::system::error_code& error) {
      if (!error) poll();
    });
  }

  // Writes what the exchange asks for; answers and returns true once it is done.
  bool advance(const ClientPtr& client, Clock::time_point now) {
    auto& exchange = *client->exchange;
    if (auto command = exchange.command_due(now, command_writer_->health().matched_readers > 0)) {
      tp::msgs::SupervisorCommand_ message;
      protocol::to_dds(*command, message);
      runtime::stamp_header(message.header(), 0, runtime::now_stamp());
      command_writer_->write(message);
    }
    if (!exchange.done(now)) return false;
    answer(client, exchange.outcome());
    return true;
  }

  void poll() {
    const auto now = Clock::now();
    tp::msgs::SupervisorStatus_ status;
    while (status_reader_->take_next(status)) {
      protocol::SupervisorStatus plain;
      protocol::from_dds(status, plain);
      for (auto& client : pending_) client->exchange->on_status(plain, now);
    }
    tp::msgs::CraneState_ estimate;
    while (estimate_reader_->take_next(estimate)) {
      protocol::CraneState plain;
      protocol::from_dds(estimate, plain);
      for (auto& client : pending_) client->exchange->on_estimate(plain);
    }
    pending_.remove_if([&](const ClientPtr& client) { return advance(client, now); });
    if (!pending_.empty()) schedule_poll();
  }

  void release(Client& client) {
    if (!client.counted) return;
    client.counted = false;
    --active_;
  }

  void answer(const ClientPtr& client, const supervisor::OperatorOutcome& outcome) {
    release(*client);
    client->reply = supervisor::operator_socket::reply_header(outcome.exit_code, outcome.out.size(), outcome.err.size()) +
                    outcome.out + outcome.err;
    asio::async_write(client->socket, asio::buffer(client->reply), [client](const boost::system::error_code&, std::size_t) {
      boost::system::error_code ignored;
      client->socket.shutdown(Local::socket::shutdown_both, ignored);
      client->socket.close(ignored);
    });
  }

  asio::io_context& io_;
  Local::acceptor acceptor_;
  asio::steady_timer poll_;
  std::uint32_t domain_;
  std::string config_path_;
  transport::Wakeup wakeup_;  // the readers' (polled: the timer paces this loop)
  std::unique_ptr<transport::Reader<tp::SafetyStatus>> status_reader_;
  std::unique_ptr<transport::Reader<tp::StateEstimate>> estimate_reader_;
  std::unique_ptr<transport::Writer<tp::SafetyCommand>> command_writer_;
  std::list<ClientPtr> pending_;
  std::size_t active_{0};
  std::uint64_t requests_{0};
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"operator_relay: the stack's operator participant, serving crane_operator on a local socket"};
  runtime::NodeOptions options;
  runtime::add_node_options(app, options);
  CLI11_PARSE(app, argc, argv);
  try {
    runtime::configure_logging(options.log_level, "operator_relay");
    auto participant = runtime::make_participant(options, "operator");
    asio::io_context io;
    Relay relay(io, *participant, options.domain_id, options.config_path);
    asio::signal_set signals(io, SIGINT, SIGTERM);
    signals.async_wait([&](const boost::system::error_code&, int) { io.stop(); });
    spdlog::info("operator relay on domain {}: serving crane_operator", options.domain_id);
    io.run();
    spdlog::info("operator relay stopped");
    return 0;
  } catch (const std::exception& error) {
    spdlog::error("operator_relay: {}", error.what());
    return 1;
  }
}
