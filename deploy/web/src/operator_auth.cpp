#include "crane/web/operator_auth.hpp"

#include <openssl/crypto.h>
#include <openssl/evp.h>
#include <openssl/rand.h>
#include <sys/stat.h>

#include <cctype>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace crane::web {
namespace {

std::string hex(const unsigned char* bytes, std::size_t size) {
  static const char* digits = "0123456789abcdef";
  std::string out;
  out.reserve(2 * size);
  for (std::size_t i = 0; i < size; ++i) {
    out += digits[bytes[i] >> 4];
    out += digits[bytes[i] & 0xf];
  }
  return out;
}

std::string random_hex(std::size_t bytes) {
  std::vector<unsigned char> buffer(bytes);
  if (RAND_bytes(buffer.data(), static_cast<int>(bytes)) != 1) throw std::runtime_error("OpenSSL RAND_bytes failed");
  return hex(buffer.data(), bytes);
}

bool is_hex64(const std::string& text) {
  if (text.size() != 64) return false;
  for (const char c : text)
    if (!std::isxdigit(static_cast<unsigned char>(c)) || std::isupper(static_cast<unsigned char>(c))) return false;
  return true;
}

bool valid_name(const std::string& name) {
  if (name.empty() || name.size() > 64) return false;
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') return false;
  return true;
}

bool equal_secret(const std::string& a, const std::string& b) {
  return a.size() == b.size() && CRYPTO_memcmp(a.data(), b.data(), a.size()) == 0;
}

}  // namespace

std::string OperatorAuth::sha256_hex(std::string_view text) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int size = 0;
  if (EVP_Digest(text.data(), text.size(), digest, &size, EVP_sha256(), nullptr) != 1) {
    throw std::runtime_error("OpenSSL EVP_Digest(SHA-256) failed");
  }
  return hex(digest, size);
}

OperatorAuth::OperatorAuth(const std::string& path, double session_lifetime) : session_lifetime_(session_lifetime) {
  if (!(session_lifetime > 0.0)) throw std::runtime_error("operator session lifetime must be > 0 s");
  struct stat info {};
  if (::stat(path.c_str(), &info) != 0) throw std::runtime_error("operators file " + path + ": cannot be read");
  if ((info.st_mode & 077) != 0) {
    char mode[8];
    std::snprintf(mode, sizeof mode, "%03o", static_cast<unsigned>(info.st_mode & 0777));
    throw std::runtime_error("operators file " + path + ": mode " + mode +
                             " lets others read it; chmod 600 " + path);
  }
  std::ifstream in(path);
  if (!in) throw std::runtime_error("operators file " + path + ": cannot be read");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto hash_at = line.find('#');
    if (hash_at != std::string::npos) line.erase(hash_at);
    std::istringstream fields(line);
    std::string name, digest, extra;
    if (!(fields >> name)) continue;  // blank or comment
    if (!(fields >> digest) || (fields >> extra) || !valid_name(name) || !is_hex64(digest)) {
      throw std::runtime_error("operators file " + path + ", line " + std::to_string(number) +
                               ": expected \"NAME SHA256HEX\" (NAME of letters, digits, _-., SHA256HEX 64 lower-case "
                               "hex digits)");
    }
    if (!hash_of_operator_.emplace(name, digest).second) {
      throw std::runtime_error("operators file " + path + ", line " + std::to_string(number) + ": operator " + name +
                               " repeated");
    }
  }
  if (hash_of_operator_.empty()) throw std::runtime_error("operators file " + path + ": no operator in it");
}

std::string OperatorAuth::add_operator(const std::string& path, const std::string& name) {
  if (!valid_name(name)) {
    throw std::runtime_error("operator name '" + name + "': 1-64 letters, digits, '_', '-' or '.'");
  }
  {
    std::ifstream in(path);
    std::string line;
    while (in && std::getline(in, line)) {
      std::istringstream fields(line);
      std::string existing;
      if ((fields >> existing) && existing == name) {
        throw std::runtime_error("operators file " + path + ": operator " + name + " is already there");
      }
    }
  }
  const std::string token = random_hex(32);
  const mode_t old_mask = ::umask(077);
  std::ofstream out(path, std::ios::app);
  ::umask(old_mask);
  if (!out) throw std::runtime_error("operators file " + path + ": cannot be written");
  out << name << ' ' << sha256_hex(token) << '\n';
  if (!out) throw std::runtime_error("operators file " + path + ": cannot be written");
  return token;
}

std::optional<std::string> OperatorAuth::login(std::string_view token, double now) {
  const std::string digest = sha256_hex(token);
  std::optional<std::string> who;
  for (const auto& [name, expected] : hash_of_operator_) {
    if (equal_secret(digest, expected)) who = name;  // every entry compared: no early exit
  }
  if (!who) return std::nullopt;
  for (auto it = sessions_.begin(); it != sessions_.end();) it = it->second.expires <= now ? sessions_.erase(it) : std::next(it);
  std::string session = random_hex(32);
  sessions_[session] = Session{*who, now + session_lifetime_};
  return session;
}

std::optional<std::string> OperatorAuth::operator_of(std::string_view cookie_header, double now) const {
  const std::string session = cookie_value(cookie_header, kSessionCookie);
  if (session.empty()) return std::nullopt;
  const auto found = sessions_.find(session);
  if (found == sessions_.end() || found->second.expires <= now) return std::nullopt;
  return found->second.name;
}

void OperatorAuth::logout(std::string_view cookie_header) { sessions_.erase(cookie_value(cookie_header, kSessionCookie)); }

std::string cookie_value(std::string_view cookie_header, std::string_view name) {
  std::size_t at = 0;
  while (at < cookie_header.size()) {
    const auto end = std::min(cookie_header.find(';', at), cookie_header.size());
    std::string_view item = cookie_header.substr(at, end - at);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    const auto equals = item.find('=');
    if (equals != std::string_view::npos && item.substr(0, equals) == name) return std::string(item.substr(equals + 1));
    at = end + 1;
  }
  return {};
}

bool same_origin(std::string_view origin, std::string_view host) {
  if (origin.empty()) return true;
  for (const std::string_view scheme : {"http://", "https://"}) {
    if (origin.substr(0, scheme.size()) == scheme) return !host.empty() && origin.substr(scheme.size()) == host;
  }
  return false;
}

}  // namespace crane::web
