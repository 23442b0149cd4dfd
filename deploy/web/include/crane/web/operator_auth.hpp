#pragma once
// Who may command the crane through crane_web (issue 16: client publishing "only for authenticated
// operators"). A browser cannot present a DDS identity, so the page's operator logs in with a token
// and gets a session cookie; the WebSocket handshake that carries the cookie (same origin: the
// cookie is HttpOnly and SameSite=Strict, and the handshake's Origin must name the Host it was sent
// to) is the operator's, and only that client may publish (goals, supervisor commands).
//
// The operators file: one line per operator, "NAME SHA256HEX" (the SHA-256 of the token, never the
// token itself), '#' comments; created and extended by add_operator() with mode 0600. A token is 32
// random bytes from OpenSSL's RAND_bytes in hex (64 characters); sessions are 32 random bytes too.
// Hashing and randomness: OpenSSL (libcrypto). Comparisons of secrets are constant-time
// (CRYPTO_memcmp).
//
// Not thread-safe: crane_web calls it from its one I/O thread.

#include <map>
#include <optional>
#include <string>
#include <string_view>

namespace crane::web {

/// The name of the session cookie.
inline constexpr std::string_view kSessionCookie = "crane_operator";

class OperatorAuth {
 public:
  /// Reads the operators file. Throws std::runtime_error naming the file and the line for an
  /// unreadable file, a line that is not "NAME SHA256HEX" (64 hex digits), a repeated name, or no
  /// operator at all; and naming the file when it is readable by group or others (mode & 077).
  /// `session_lifetime` [s] > 0: how long a login lasts.
  OperatorAuth(const std::string& path, double session_lifetime);

  /// Appends a new operator NAME (letters, digits, '_', '-', '.', 1-64 characters) to the file at
  /// `path` (created 0600 when missing) and returns its token, the only time it exists in clear.
  /// Throws std::runtime_error naming the file, or the name when it is invalid or already there.
  static std::string add_operator(const std::string& path, const std::string& name);

  /// The operator whose token this is: a new session id (the cookie's value) valid until
  /// `now` + session_lifetime [s, any monotonic timeline], or nullopt for an unknown token.
  std::optional<std::string> login(std::string_view token, double now);

  /// The operator of a request's Cookie header (`kSessionCookie`=session), or nullopt when there is
  /// none, it is unknown or expired at `now` [s].
  [[nodiscard]] std::optional<std::string> operator_of(std::string_view cookie_header, double now) const;

  /// Ends the session of this Cookie header, if any.
  void logout(std::string_view cookie_header);

  /// SHA-256 of `text`, lower-case hex.
  [[nodiscard]] static std::string sha256_hex(std::string_view text);

 private:
  struct Session {
    std::string name;
    double expires{0.0};
  };
  std::map<std::string, std::string> hash_of_operator_;  // name -> SHA-256 hex of the token
  std::map<std::string, Session> sessions_;              // session id -> operator
  double session_lifetime_{0.0};
};

/// The value of cookie `name` in a Cookie header ("a=1; b=2"), or "" when absent.
[[nodiscard]] std::string cookie_value(std::string_view cookie_header, std::string_view name);

/// Whether a WebSocket handshake's Origin header names the host it was sent to (Host header):
/// "http://HOST" or "https://HOST". An absent Origin (a non-browser client) counts as same-origin.
[[nodiscard]] bool same_origin(std::string_view origin, std::string_view host);

}  // namespace crane::web
