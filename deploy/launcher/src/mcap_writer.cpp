#include "crane/launch/mcap_writer.hpp"

#include <zlib.h>

#include <cstdio>
#include <limits>
#include <stdexcept>

namespace crane::launch {

namespace {

// Serialization (spec, "Serialization"): integers little endian, String = uint32 length + bytes,
// Map = uint32 byte length + entries.
constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
enum Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

class Bytes {
 public:
  template <class T>
  Bytes& integer(T value) {
    for (std::size_t i = 0; i < sizeof(T); ++i) data.push_back(static_cast<std::uint8_t>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xffU));
    return *this;
  }
  Bytes& string(const std::string& text) {
    integer(static_cast<std::uint32_t>(text.size()));
    data.insert(data.end(), text.begin(), text.end());
    return *this;
  }
  Bytes& raw(const std::uint8_t* bytes, std::size_t size) {
    data.insert(data.end(), bytes, bytes + size);
    return *this;
  }
  Bytes& raw(const std::vector<std::uint8_t>& bytes) { return raw(bytes.data(), bytes.size()); }
  std::vector<std::uint8_t> data;
};

std::vector<std::uint8_t> record(std::uint8_t opcode, const std::vector<std::uint8_t>& content) {
  Bytes r;
  r.integer(opcode).integer(static_cast<std::uint64_t>(content.size())).raw(content);
  return r.data;
}

}  // namespace

McapWriter::McapWriter(const std::string& path, const std::string& profile, const std::string& library)
    : path_(path), out_(path, std::ios::binary | std::ios::trunc) {
  if (!out_) throw std::runtime_error("cannot write " + path);
  write_bytes(kMagic, sizeof(kMagic));
  write_record(kHeader, Bytes().string(profile).string(library).data);
}

McapWriter::~McapWriter() {
  try {
    finish();
  } catch (const std::exception& error) {
    std::fprintf(stderr, "McapWriter: %s\n", error.what());
  }
}

void McapWriter::write_bytes(const std::uint8_t* data, std::size_t size) {
  out_.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  if (!out_) throw std::runtime_error("cannot write " + path_);
  crc_ = static_cast<std::uint32_t>(crc32(crc_, data, static_cast<uInt>(size)));
  offset_ += size;
}

void McapWriter::write_record(std::uint8_t opcode, const std::vector<std::uint8_t>& content) {
  const auto r = record(opcode, content);
  write_bytes(r.data(), r.size());
}

std::uint16_t McapWriter::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  const auto id = static_cast<std::uint16_t>(schema_records_.size() + 1);  // 0 is "no schema"
  Bytes content;
  content.integer(id).string(name).string(encoding).string(data);  // data: uint32 length-prefixed bytes
  schema_records_.push_back(content.data);
  write_record(kSchema, content.data);
  return id;
}

std::uint16_t McapWriter::add_channel(std::uint16_t schema_id, const std::string& topic,
                                      const std::string& message_encoding,
                                      const std::map<std::string, std::string>& metadata) {
  if (schema_id > schema_records_.size()) {
    throw std::invalid_argument("MCAP channel " + topic + ": unknown schema id " + std::to_string(schema_id));
  }
  const auto id = static_cast<std::uint16_t>(channel_records_.size());
  Bytes map;
  for (const auto& [key, value] : metadata) map.string(key).string(value);
  Bytes content;
  content.integer(id).integer(schema_id).string(topic).string(message_encoding);
  content.integer(static_cast<std::uint32_t>(map.data.size())).raw(map.data);
  channel_records_.push_back(content.data);
  channel_message_counts_[id] = 0;
  write_record(kChannel, content.data);
  return id;
}

void McapWriter::write_message(std::uint16_t channel_id, std::uint32_t sequence, std::uint64_t log_time,
                               std::uint64_t publish_time, const std::uint8_t* data, std::size_t size) {
  const auto count = channel_message_counts_.find(channel_id);
  if (count == channel_message_counts_.end()) {
    throw std::invalid_argument("MCAP message: unknown channel id " + std::to_string(channel_id));
  }
  Bytes content;
  content.integer(channel_id).integer(sequence).integer(log_time).integer(publish_time).raw(data, size);
  write_record(kMessage, content.data);
  ++count->second;
  if (message_count_ == 0 || log_time < first_log_time_) first_log_time_ = log_time;
  if (log_time > last_log_time_) last_log_time_ = log_time;
  ++message_count_;
}

void McapWriter::finish() {
  if (finished_) return;
  finished_ = true;
  write_record(kDataEnd, Bytes().integer(crc_).data);  // CRC32 of every byte before this record

  // Summary section, grouped by opcode; the summary CRC runs from here through the footer's
  // summary_offset_start.
  crc_ = 0;
  const std::uint64_t summary_start = offset_;
  struct Group {
    std::uint8_t opcode;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  const auto write_group = [&](std::uint8_t opcode, const std::vector<std::vector<std::uint8_t>>& contents) {
    if (contents.empty()) return;
    const std::uint64_t start = offset_;
    for (const auto& c : contents) write_record(opcode, c);
    groups.push_back({opcode, start, offset_ - start});
  };
  write_group(kSchema, schema_records_);
  write_group(kChannel, channel_records_);
  Bytes counts;
  for (const auto& [id, n] : channel_message_counts_) counts.integer(id).integer(n);
  Bytes statistics;
  statistics.integer(message_count_)
      .integer(static_cast<std::uint16_t>(schema_records_.size()))
      .integer(static_cast<std::uint32_t>(channel_records_.size()))
      .integer(std::uint32_t{0})   // attachments
      .integer(std::uint32_t{0})   // metadata
      .integer(std::uint32_t{0})   // chunks
      .integer(message_count_ == 0 ? std::uint64_t{0} : first_log_time_)
      .integer(message_count_ == 0 ? std::uint64_t{0} : last_log_time_)
      .integer(static_cast<std::uint32_t>(counts.data.size()))
      .raw(counts.data);
  write_group(kStatistics, {statistics.data});

  const std::uint64_t summary_offset_start = offset_;
  for (const auto& g : groups) write_record(kSummaryOffset, Bytes().integer(g.opcode).integer(g.start).integer(g.length).data);

  Bytes footer_head;
  footer_head.integer(kFooter).integer(std::uint64_t{20}).integer(summary_start).integer(summary_offset_start);
  write_bytes(footer_head.data.data(), footer_head.data.size());
  Bytes footer_crc;
  footer_crc.integer(crc_);
  write_bytes(footer_crc.data.data(), footer_crc.data.size());
  write_bytes(kMagic, sizeof(kMagic));
  out_.close();
  if (!out_) throw std::runtime_error("cannot write " + path_);
}

}  // namespace crane::launch
