// libFuzzer harness: crane_web's parser of a Foxglove client's frames (crane::web::ClientSession:
// handle_text for text frames, handle_binary for binary ones), for a read-only client and for an
// operator's client that may publish two topics. Contract (foxglove_protocol.hpp): never throws on
// a client's input; a bad request changes nothing and is answered with error messages. The
// subscriptions stay consistent with the advertised channels; an accepted binary frame names a
// publishable topic and its payload lies inside the frame, after the 5 header bytes.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "crane/web/foxglove_protocol.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  crane::web::ClientSession reader({1, 2, 3, 7});
  crane::web::ClientSession operator_session({1, 2, 3, 7}, {{"rt/crane/planner/goal", "crane_msgs::msg::dds_::MoveRequest_"},
                                                            {"rt/crane/safety/command", "crane_msgs::msg::dds_::SupervisorCommand_"}});
  // Several frames per input (a session's state carries over): split at NUL bytes; a frame whose
  // first byte is 0x01 is a binary frame, any other a text frame.
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  while (true) {
    const auto cut = rest.find('\0');
    const std::string_view frame = rest.substr(0, cut);
    for (auto* session : {&reader, &operator_session}) {
      if (!frame.empty() && static_cast<std::uint8_t>(frame[0]) == 0x01) {
        crane::web::ClientMessage message;
        if (session->handle_binary(frame, message).empty()) {
          if (session == &reader) std::abort();  // a read-only client published
          if (message.topic_index >= 2) std::abort();
          if (message.data != reinterpret_cast<const std::uint8_t*>(frame.data()) + crane::web::kClientMessageHeaderBytes ||
              message.size + crane::web::kClientMessageHeaderBytes != frame.size() || message.size == 0) {
            std::abort();
          }
        }
      } else {
        (void)session->handle_text(frame);
      }
    }
    if (cut == std::string_view::npos) break;
    rest.remove_prefix(cut + 1);
  }
  if (reader.subscription_count() > 4 || operator_session.subscription_count() > 4) std::abort();
  return 0;
}
