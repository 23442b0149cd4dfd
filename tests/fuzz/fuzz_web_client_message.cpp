// libFuzzer harness: crane_web's parser of a Foxglove client's text frames
// (crane::web::ClientSession::handle_text). Contract (foxglove_protocol.hpp): never throws on a
// client's input; a bad request changes nothing and is answered with error messages. The
// subscriptions must stay consistent with the advertised channels.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "crane/web/foxglove_protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  crane::web::ClientSession session({1, 2, 3, 7});
  // Several frames per input (a session's state carries over): split at NUL bytes.
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  while (true) {
    const auto cut = rest.find('\0');
    (void)session.handle_text(rest.substr(0, cut));
    if (cut == std::string_view::npos) break;
    rest.remove_prefix(cut + 1);
  }
  if (session.subscription_count() > 4) std::abort();  // one subscription per advertised channel at most
  return 0;
}
