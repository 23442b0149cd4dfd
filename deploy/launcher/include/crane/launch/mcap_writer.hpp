#pragma once
// A small MCAP writer (the format of rosbag2's default storage, Foxglove and Lichtblick), written
// from the specification (mcap.dev/spec, major version 0) because Debian packages no MCAP library.
//
// What it writes: <magic><Header><Schema, Channel and Message records><Data End><summary: the
// Schema records, the Channel records, one Statistics record><a Summary Offset per group><Footer>
// <magic>. Messages are not chunked (no Chunk, Message Index or Chunk Index records): readers scan
// the data section (@mcap/core's stream reader, rosbag2's mcap storage with its fallback scan);
// no compression. CRC32s (zlib's) of the data section and of the summary are filled in.
//
// crane_topic record --mcap uses it with the ros2 profile (message encoding cdr, schemas ros2msg).

#include <cstdint>
#include <fstream>
#include <map>
#include <string>
#include <vector>

namespace crane::launch {

class McapWriter {
 public:
  /// Creates `path` and writes the magic and the Header record (`profile`, e.g. "ros2"; `library`,
  /// free text). Throws std::runtime_error naming the path when it cannot be written.
  McapWriter(const std::string& path, const std::string& profile, const std::string& library);
  /// Finishes the file if finish() was not called (errors then only logged to stderr).
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// Writes a Schema record; returns its id (1, 2, ...). `encoding` e.g. "ros2msg".
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  /// Writes a Channel record; returns its id (0, 1, ...). Throws std::invalid_argument on an
  /// unknown schema id.
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                            const std::map<std::string, std::string>& metadata);
  /// Writes a Message record. Times [ns] since the Unix epoch. Throws std::invalid_argument on an
  /// unknown channel id, std::runtime_error when the file cannot be written.
  void write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                     std::uint64_t publish_time, const std::uint8_t* data, std::size_t size);
  /// Writes the Data End record, the summary, the summary offsets, the footer and the magic, and
  /// closes the file. Throws std::runtime_error when it cannot be written. Idempotent.
  void finish();

  [[nodiscard]] std::uint64_t message_count() const noexcept { return message_count_; }

 private:
  void write_record(std::uint8_t opcode, const std::vector<std::uint8_t>& content);
  void write_bytes(const std::uint8_t* data, std::size_t size);

  std::string path_;
  std::ofstream out_;
  std::uint64_t offset_{0};
  std::uint32_t crc_{0};  // running CRC32 of everything written since the last reset
  std::vector<std::vector<std::uint8_t>> schema_records_, channel_records_;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts_;
  std::uint64_t message_count_{0};
  std::uint64_t first_log_time_{0}, last_log_time_{0};
  bool finished_{false};
};

}  // namespace crane::launch
