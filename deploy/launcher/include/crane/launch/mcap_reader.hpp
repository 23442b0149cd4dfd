#pragma once
// Reads the messages of an MCAP file (mcap.dev/spec, major version 0) in file order: what
// McapWriter writes (Schema, Channel, Message records in the data section), and any file whose
// messages are outside chunks. Chunked files (Chunk records) are refused by name: compression
// would need lz4/zstd, and crane_topic writes none.

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

namespace crane::launch {

struct McapChannelInfo {
  std::uint16_t id{0};
  std::string topic;
  std::string message_encoding;
  std::string schema_name;  // "" when the channel has no schema
};

struct McapMessageView {
  const McapChannelInfo* channel{nullptr};
  std::uint32_t sequence{0};
  std::uint64_t log_time{0};      // [ns]
  std::uint64_t publish_time{0};  // [ns]
  const std::uint8_t* data{nullptr};
  std::size_t size{0};
};

/// Calls `on_message` for every Message record of `path`, in file order, until the Data End
/// record. Throws std::runtime_error naming the file and the byte offset on a file that is not
/// MCAP, is truncated, holds a Chunk, or a message of an undeclared channel.
void read_mcap_messages(const std::string& path, const std::function<void(const McapMessageView&)>& on_message);

/// The same on `size` bytes in memory (the file's whole content); `source_name` (the file's path)
/// starts the messages. The views point into `data`. What the fuzz harness drives (tests/fuzz).
void read_mcap_messages(const std::uint8_t* data, std::size_t size, const std::string& source_name,
                        const std::function<void(const McapMessageView&)>& on_message);

}  // namespace crane::launch
