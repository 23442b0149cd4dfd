#include "crane/launch/mcap_reader.hpp"

#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace crane::launch {

namespace {

constexpr std::uint8_t kMagic[8] = {0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};

class Cursor {
 public:
  Cursor(const std::uint8_t* bytes, std::size_t begin, std::size_t end, const std::string& where)
      : bytes_(bytes), at_(begin), end_(end), where_(where) {}
  template <class T>
  T integer() {
    need(sizeof(T));
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<std::uint64_t>(bytes_[at_ + i]) << (8 * i);
    at_ += sizeof(T);
    return static_cast<T>(v);
  }
  std::string string() {
    const auto n = integer<std::uint32_t>();
    need(n);
    std::string s(reinterpret_cast<const char*>(bytes_ + at_), n);
    at_ += n;
    return s;
  }
  void skip(std::size_t n) {
    need(n);
    at_ += n;
  }
  [[nodiscard]] std::size_t at() const noexcept { return at_; }
  [[nodiscard]] std::size_t end() const noexcept { return end_; }

 private:
  void need(std::size_t n) const {
    if (n > end_ - at_) throw std::runtime_error(where_ + ": truncated record at byte " + std::to_string(at_));
  }
  const std::uint8_t* bytes_;
  std::size_t at_, end_;
  std::string where_;
};

}  // namespace

void read_mcap_messages(const std::string& path, const std::function<void(const McapMessageView&)>& on_message) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("cannot read " + path);
  const std::vector<std::uint8_t> bytes{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  read_mcap_messages(bytes.data(), bytes.size(), path, on_message);
}

void read_mcap_messages(const std::uint8_t* bytes, std::size_t size, const std::string& path,
                        const std::function<void(const McapMessageView&)>& on_message) {
  if (size < 8 || std::memcmp(bytes, kMagic, 8) != 0) {
    throw std::runtime_error(path + ": not an MCAP file (no magic 0x89 MCAP0 at byte 0)");
  }
  std::map<std::uint16_t, std::string> schema_names;
  std::map<std::uint16_t, McapChannelInfo> channels;
  Cursor file(bytes, 8, size, path);
  while (file.at() < file.end()) {
    const auto start = file.at();
    const auto opcode = file.integer<std::uint8_t>();
    const auto length = file.integer<std::uint64_t>();
    if (length > file.end() - file.at()) throw std::runtime_error(path + ": truncated record at byte " + std::to_string(start));
    Cursor record(bytes, file.at(), file.at() + static_cast<std::size_t>(length), path);
    file.skip(static_cast<std::size_t>(length));
    switch (opcode) {
      case 0x03: {  // Schema
        const auto id = record.integer<std::uint16_t>();
        schema_names[id] = record.string();
        break;
      }
      case 0x04: {  // Channel
        McapChannelInfo c;
        c.id = record.integer<std::uint16_t>();
        const auto schema_id = record.integer<std::uint16_t>();
        c.topic = record.string();
        c.message_encoding = record.string();
        const auto found = schema_names.find(schema_id);
        if (found != schema_names.end()) c.schema_name = found->second;
        channels[c.id] = c;
        break;
      }
      case 0x05: {  // Message
        McapMessageView m;
        const auto channel_id = record.integer<std::uint16_t>();
        const auto found = channels.find(channel_id);
        if (found == channels.end()) {
          throw std::runtime_error(path + ": message of undeclared channel " + std::to_string(channel_id) + " at byte " +
                                   std::to_string(start));
        }
        m.channel = &found->second;
        m.sequence = record.integer<std::uint32_t>();
        m.log_time = record.integer<std::uint64_t>();
        m.publish_time = record.integer<std::uint64_t>();
        m.data = bytes + record.at();
        m.size = record.end() - record.at();
        on_message(m);
        break;
      }
      case 0x06:
        throw std::runtime_error(path + ": chunked MCAP (Chunk record at byte " + std::to_string(start) +
                                 ") is not read by this reader");
      case 0x0F:  // Data End: the summary that follows repeats what was read
        return;
      default:  // Header, attachments, metadata, indexes: not needed for the messages
        break;
    }
  }
  throw std::runtime_error(path + ": no Data End record (truncated file?)");
}

}  // namespace crane::launch
