// libFuzzer harness: the MCAP reader of crane_topic convert / replay and the audit's --data
// run.mcap (crane::launch::read_mcap_messages). Contract (mcap_reader.hpp): any bytes either give
// messages whose payload lies inside the input, or throw std::runtime_error naming the offset.
// Seeds: MCAP files written by McapWriter (tests/fuzz/corpus/mcap_reader).
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>

#include "crane/launch/mcap_reader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  try {
    crane::launch::read_mcap_messages(data, size, "fuzz.mcap", [&](const crane::launch::McapMessageView& m) {
      if (m.channel == nullptr || m.data < data || m.data + m.size > data + size) std::abort();
      volatile std::uint8_t sum = 0;  // read every payload byte: ASan checks the bounds
      for (std::size_t i = 0; i < m.size; ++i) sum = static_cast<std::uint8_t>(sum + m.data[i]);
      (void)m.channel->topic.size();
    });
  } catch (const std::runtime_error&) {
  }
  return 0;
}
