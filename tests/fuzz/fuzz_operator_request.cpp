// libFuzzer harness: what operator_relay does with the bytes a local client sends it, without the
// socket and DDS (supervisor/node/operator_relay_node.cpp): the request framing
// (operator_socket::decode_request; a decoded request must encode back to the same bytes), the
// operator commands' syntax (add_operator_options, CLI11, the arguments reversed as the relay gives
// them), and the exchange the relay starts for a parsed command (OperatorExchange: it must end with
// one of its exit codes, 0-3, and a command it writes must carry a code of the IDL). The same bytes'
// first line as a reply header (what crane_operator reads back): a decoded header must stay within
// the documented bounds and encode back to itself.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "crane/protocol/messages.hpp"
#include "crane/supervisor/operator_command.hpp"
#include "crane/supervisor/operator_socket.hpp"

namespace {

namespace os = crane::supervisor::operator_socket;
using crane::protocol::SupervisorCommand;
using crane::protocol::SupervisorStatus;

void exchange(crane::supervisor::OperatorRequest request) {
  using Clock = crane::supervisor::OperatorExchange::Clock;
  request.config_path.clear();  // the relay's own configuration; the fuzzer's bytes name no file to read
  const auto t0 = Clock::now();
  crane::supervisor::OperatorExchange x(request, 7, 0, t0);
  auto now = t0;
  for (int step = 0; step < 4 && !x.done(now); ++step) {
    if (const auto command = x.command_due(now, true)) {
      if (command->command < SupervisorCommand::COMMAND_ARM || command->command > SupervisorCommand::COMMAND_DISABLE_ZONE ||
          command->request_id != 7) {
        std::abort();
      }
    }
    SupervisorStatus status{};
    status.last_request_id = step >= 1 ? 7U : 0U;  // the echo from the second status on
    status.last_request_result = step == 2 ? SupervisorStatus::RESULT_REFUSED : SupervisorStatus::RESULT_ACCEPTED;
    x.on_status(status, now);
    now += std::chrono::milliseconds(60);
  }
  (void)x.done(now + std::chrono::seconds(120));  // past any timeout: done, whatever happened
  const int code = x.outcome().exit_code;
  if (code < 0 || code > 3) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  if (const auto arguments = os::decode_request(bytes)) {
    const auto again = os::encode_request(*arguments);
    if (!again || *again != bytes) std::abort();
    crane::supervisor::OperatorRequest parsed;
    CLI::App app{"fuzz"};
    crane::supervisor::add_operator_options(app, parsed);
    try {
      std::vector<std::string> reversed(arguments->rbegin(), arguments->rend());
      app.parse(reversed);
      exchange(parsed);
    } catch (const CLI::ParseError&) {
    }
  }
  const std::string_view line = std::string_view(bytes).substr(0, bytes.find('\n'));
  if (const auto header = os::decode_reply_header(line)) {
    constexpr std::size_t kMiB = 1U << 20;
    if (header->exit_code < 0 || header->exit_code > 255 || header->out_bytes > kMiB || header->err_bytes > kMiB) {
      std::abort();
    }
    std::string text = os::reply_header(header->exit_code, header->out_bytes, header->err_bytes);
    text.pop_back();  // its newline
    const auto back = os::decode_reply_header(text);
    if (!back || back->exit_code != header->exit_code || back->out_bytes != header->out_bytes ||
        back->err_bytes != header->err_bytes) {
      std::abort();
    }
  }
  return 0;
}
