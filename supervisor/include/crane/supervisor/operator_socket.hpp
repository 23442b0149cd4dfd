#pragma once
// The local socket between crane_operator (the operator's command in a shell) and operator_relay
// (the stack's long-lived operator participant): its name and its two messages. Header-only and
// without DDS, so that crane_operator starts in a few milliseconds (docs/operation.md, "Operator
// commands").
//
// The socket is a Linux abstract Unix socket: it lives in the network namespace, as the DDS domain
// it serves does (a stack in a private namespace has its own), and has no file to leave behind. The
// relay answers only a peer of its own user id or root (SO_PEERCRED).
//
//   request: the command's arguments as typed (e.g. "estop", "mode", "manual"), each followed by a
//            NUL byte, the whole ended by a newline; at most kMaxRequestBytes.
//   reply:   "<exit code> <stdout bytes> <stderr bytes>\n", then the standard output's bytes, then
//            the standard error's.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace crane::supervisor::operator_socket {

inline constexpr std::size_t kMaxRequestBytes = 4096;

/// The abstract socket's name for DDS domain `domain`: a leading NUL, then "crane/operator_relay/<domain>".
[[nodiscard]] inline std::string name(std::uint32_t domain) {
  return std::string(1, '\0') + "crane/operator_relay/" + std::to_string(domain);
}

/// The request for `arguments`; nullopt when an argument holds a NUL or a newline, or the request
/// would exceed kMaxRequestBytes.
[[nodiscard]] inline std::optional<std::string> encode_request(const std::vector<std::string>& arguments) {
  std::string request;
  for (const auto& a : arguments) {
    if (a.find('\0') != std::string::npos || a.find('\n') != std::string::npos) return std::nullopt;
    request += a;
    request += '\0';
  }
  request += '\n';
  if (request.size() > kMaxRequestBytes) return std::nullopt;
  return request;
}

/// The arguments of a request read up to and including its newline; nullopt when it is not one
/// (no final newline, an argument not ended by its NUL, a newline inside, too long).
[[nodiscard]] inline std::optional<std::vector<std::string>> decode_request(std::string_view request) {
  if (request.empty() || request.back() != '\n' || request.size() > kMaxRequestBytes) return std::nullopt;
  request.remove_suffix(1);
  std::vector<std::string> arguments;
  while (!request.empty()) {
    const auto end = request.find('\0');
    if (end == std::string_view::npos) return std::nullopt;
    const auto argument = request.substr(0, end);
    if (argument.find('\n') != std::string_view::npos) return std::nullopt;
    arguments.emplace_back(argument);
    request.remove_prefix(end + 1);
  }
  return arguments;
}

/// The reply's first line for an exit code and the two texts' sizes.
[[nodiscard]] inline std::string reply_header(int exit_code, std::size_t out_bytes, std::size_t err_bytes) {
  return std::to_string(exit_code) + " " + std::to_string(out_bytes) + " " + std::to_string(err_bytes) + "\n";
}

struct ReplyHeader {
  int exit_code{0};
  std::size_t out_bytes{0};
  std::size_t err_bytes{0};
};

/// Parses a reply's first line (without its newline); nullopt when malformed or a size is beyond 1 MiB.
[[nodiscard]] inline std::optional<ReplyHeader> decode_reply_header(std::string_view line) {
  ReplyHeader h;
  std::size_t pos = 0;
  const auto number = [&](std::size_t& value) {
    const auto start = pos;
    value = 0;
    while (pos < line.size() && line[pos] >= '0' && line[pos] <= '9' && pos - start < 8) {
      value = value * 10 + static_cast<std::size_t>(line[pos++] - '0');
    }
    return pos > start;
  };
  std::size_t code = 0;
  if (!number(code) || code > 255 || pos >= line.size() || line[pos++] != ' ') return std::nullopt;
  if (!number(h.out_bytes) || pos >= line.size() || line[pos++] != ' ') return std::nullopt;
  if (!number(h.err_bytes) || pos != line.size()) return std::nullopt;
  if (h.out_bytes > (1U << 20) || h.err_bytes > (1U << 20)) return std::nullopt;
  h.exit_code = static_cast<int>(code);
  return h;
}

}  // namespace crane::supervisor::operator_socket
