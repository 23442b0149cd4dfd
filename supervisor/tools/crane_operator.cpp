// crane_operator: the operator's commands to the supervisor as typed in a shell (deploy/crane arm |
// disarm | estop | reset | status | mode | zone), at once. It hands the command to the stack's
// operator relay over the local socket (crane/supervisor/operator_socket.hpp), whose participant is
// already matched with the supervisor, and prints its answer; it links no DDS, so it starts in a few
// milliseconds. Where no relay listens for the domain (the stack runs elsewhere, or was started
// without one), or the relay fails before it answers, it runs crane_safety (next to this binary)
// with the same arguments: a participant of its own, which discovers the supervisor first (about
// 100-200 ms). Options that choose a participant of one's own go to crane_safety directly:
// --dds, --security, --identity, --insecure-lan, --dds-profile, and --direct (said explicitly).
//
// Exit codes: those of crane_safety (0 done, 1 no supervisor answered, 2 bad usage, 3 refused).
#include <unistd.h>

#include <utility>  // before Boost.Asio 1.74: its awaitable.hpp uses std::exchange without it
#include <boost/asio.hpp>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <string>
#include <vector>

#include "crane/supervisor/operator_socket.hpp"

namespace {

namespace asio = boost::asio;
namespace sock = crane::supervisor::operator_socket;
using Local = asio::local::stream_protocol;

// crane_safety next to this executable.
std::string direct_tool(const char* argv0) {
  std::vector<char> path(4096);
  const auto n = readlink("/proc/self/exe", path.data(), path.size() - 1);
  std::string self = n > 0 ? std::string(path.data(), static_cast<std::size_t>(n)) : std::string(argv0);
  const auto slash = self.rfind('/');
  return (slash == std::string::npos ? std::string(".") : self.substr(0, slash)) + "/crane_safety";
}

[[noreturn]] void run_direct(const char* argv0, const std::vector<std::string>& arguments) {
  const auto tool = direct_tool(argv0);
  std::vector<char*> argv;
  argv.push_back(const_cast<char*>(tool.c_str()));
  for (const auto& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  execv(tool.c_str(), argv.data());
  std::fprintf(stderr, "crane_operator: cannot run %s: %s (build it: deploy/crane build)\n", tool.c_str(),
               std::strerror(errno));
  std::exit(1);
}

// The relay's answer to `request`, or nullopt when no relay listens or it fails before answering.
std::optional<std::pair<sock::ReplyHeader, std::string>> ask_relay(std::uint32_t domain, const std::string& request,
                                                                   double timeout) {
  asio::io_context io;
  Local::socket socket(io);
  boost::system::error_code error;
  socket.connect(Local::endpoint(sock::name(domain)), error);
  if (error) return std::nullopt;
  std::optional<std::pair<sock::ReplyHeader, std::string>> reply;
  asio::streambuf buffer;
  sock::ReplyHeader header;
  asio::async_write(socket, asio::buffer(request), [&](const boost::system::error_code& e, std::size_t) {
    if (e) return;
    asio::async_read_until(socket, buffer, '\n', [&](const boost::system::error_code& e2, std::size_t line) {
      if (e2) return;
      const std::string text(asio::buffers_begin(buffer.data()),
                             asio::buffers_begin(buffer.data()) + static_cast<std::ptrdiff_t>(line) - 1);
      buffer.consume(line);
      const auto parsed = sock::decode_reply_header(text);
      if (!parsed) return;
      header = *parsed;
      const auto total = header.out_bytes + header.err_bytes;
      const auto have = buffer.size();
      asio::async_read(socket, buffer, asio::transfer_exactly(total > have ? total - have : 0),
                       [&](const boost::system::error_code& e3, std::size_t) {
                         if (e3 && e3 != asio::error::eof) return;
                         if (buffer.size() < total) return;
                         reply.emplace(header, std::string(asio::buffers_begin(buffer.data()),
                                                           asio::buffers_begin(buffer.data()) +
                                                               static_cast<std::ptrdiff_t>(total)));
                       });
    });
  });
  // The relay ends the exchange at the command's own timeout; a relay that does not answer by then
  // (stopped, hung) loses the command to crane_safety.
  io.run_for(std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::duration<double>(timeout + 1.0)));
  return reply;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> arguments(argv + 1, argv + argc);
  std::vector<std::string> forwarded;  // to the relay: without --domain (the relay's own)
  std::uint32_t domain = 0;
  double timeout = 3.0;
  bool direct = false;
  std::vector<std::string> for_direct;  // to crane_safety: without --direct
  for (std::size_t i = 0; i < arguments.size(); ++i) {
    const auto& a = arguments[i];
    const bool has_value = i + 1 < arguments.size();
    if (a == "--direct") {
      direct = true;
      continue;
    }
    for_direct.push_back(a);
    if (a == "--domain" && has_value) {
      char* end = nullptr;
      const auto value = std::strtoul(arguments[i + 1].c_str(), &end, 10);
      if (*end != '\0' || value > 232) direct = true;  // crane_safety names the bad value
      domain = static_cast<std::uint32_t>(value);
      for_direct.push_back(arguments[++i]);
      continue;
    }
    if (a == "--timeout" && has_value) timeout = std::strtod(arguments[i + 1].c_str(), nullptr);
    if (a == "--dds" || a == "--security" || a == "--identity" || a == "--insecure-lan" || a == "--dds-profile" ||
        a == "--lan" || a == "--help" || a == "-h" || a.rfind("--domain=", 0) == 0 || a.rfind("--dds=", 0) == 0) {
      direct = true;
    }
    forwarded.push_back(a);
  }
  if (!(timeout > 0.0 && timeout <= 60.0)) direct = true;  // crane_safety names the bound
  const auto request = sock::encode_request(forwarded);
  if (direct || !request) run_direct(argv[0], for_direct);
  const auto reply = ask_relay(domain, *request, timeout);
  if (!reply) run_direct(argv[0], for_direct);
  const auto& [header, text] = *reply;
  std::fwrite(text.data(), 1, header.out_bytes, stdout);
  if (header.err_bytes > 0) {
    std::fputs("crane_operator: ", stderr);
    std::fwrite(text.data() + header.out_bytes, 1, header.err_bytes, stderr);
  }
  return header.exit_code;
}
