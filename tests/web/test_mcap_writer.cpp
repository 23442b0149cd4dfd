// The MCAP writer (deploy/launcher/mcap_writer.hpp) against the specification's layout; the
// independent check (npm's @mcap/core reading a live recording) is in foxglove_client_test.sh.
#include <gtest/gtest.h>

#include <zlib.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "crane/launch/mcap_reader.hpp"
#include "crane/launch/mcap_writer.hpp"

namespace {

std::vector<std::uint8_t> read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::uint64_t u64(const std::vector<std::uint8_t>& b, std::size_t at) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8) | b[at + static_cast<std::size_t>(i)];
  return v;
}

TEST(McapWriter, FileHasMagicHeaderSummaryAndFooterWhereTheSpecSays) {
  const std::string path = (std::filesystem::temp_directory_path() / "crane_test_writer.mcap").string();
  {
    crane::launch::McapWriter writer(path, "ros2", "test");
    const auto schema = writer.add_schema("crane_msgs/msg/X", "ros2msg", "float64 v\n");
    const auto channel = writer.add_channel(schema, "/x", "cdr", {{"offered_qos_profiles", ""}});
    const std::uint8_t payload[12] = {0x00, 0x01, 0x00, 0x00, 1, 2, 3, 4, 5, 6, 7, 8};
    writer.write_message(channel, 0, 1000, 900, payload, sizeof(payload));
    EXPECT_THROW(writer.write_message(7, 0, 0, 0, payload, 1), std::invalid_argument);
    EXPECT_THROW(writer.add_channel(9, "/y", "cdr", {}), std::invalid_argument);
    writer.finish();
    EXPECT_EQ(writer.message_count(), 1U);
  }
  const auto b = read_all(path);
  const std::vector<std::uint8_t> magic{0x89, 'M', 'C', 'A', 'P', 0x30, '\r', '\n'};
  ASSERT_GT(b.size(), 2 * magic.size() + 29);
  EXPECT_TRUE(std::equal(magic.begin(), magic.end(), b.begin()));
  EXPECT_TRUE(std::equal(magic.begin(), magic.end(), b.end() - 8));
  EXPECT_EQ(b[8], 0x01);  // Header right after the magic
  // Footer: opcode 0x02, length 20, summary_start, summary_offset_start, summary_crc; then magic.
  const std::size_t footer = b.size() - 8 - 29;
  ASSERT_EQ(b[footer], 0x02);
  EXPECT_EQ(u64(b, footer + 1), 20U);
  const auto summary_start = u64(b, footer + 9);
  const auto summary_offset_start = u64(b, footer + 17);
  EXPECT_EQ(b[summary_start], 0x03);         // the summary's first group: the Schema records
  EXPECT_EQ(b[summary_offset_start], 0x0E);  // Summary Offset records
  // summary_crc: CRC32 from the summary's start through summary_offset_start in the footer.
  const auto crc = static_cast<std::uint32_t>(
      crc32(0, b.data() + summary_start, static_cast<uInt>(footer + 25 - summary_start)));
  const std::uint32_t stored = b[footer + 25] | (b[footer + 26] << 8) | (b[footer + 27] << 16) |
                               (static_cast<std::uint32_t>(b[footer + 28]) << 24);
  EXPECT_EQ(stored, crc);
  std::filesystem::remove(path);
}

TEST(McapReader, ReadsBackWhatTheWriterWroteAndRefusesATruncatedFile) {
  const std::string path = (std::filesystem::temp_directory_path() / "crane_test_reader.mcap").string();
  {
    crane::launch::McapWriter writer(path, "ros2", "test");
    const auto schema = writer.add_schema("crane_msgs/msg/X", "ros2msg", "float64 v\n");
    const auto a = writer.add_channel(schema, "/a", "cdr", {});
    const auto b = writer.add_channel(schema, "/b", "cdr", {{"k", "v"}});
    for (std::uint8_t i = 0; i < 5; ++i) {
      const std::uint8_t payload[3] = {i, static_cast<std::uint8_t>(i + 1), static_cast<std::uint8_t>(i + 2)};
      writer.write_message(i % 2 == 0 ? a : b, i, 1000U + i, 900U + i, payload, sizeof(payload));
    }
  }
  std::string seen;
  crane::launch::read_mcap_messages(path, [&](const crane::launch::McapMessageView& m) {
    seen += m.channel->topic + ":" + std::to_string(m.sequence) + ":" + std::to_string(m.log_time) + ":" +
            std::to_string(m.publish_time) + ":" + std::to_string(m.size) + ":" + std::to_string(m.data[2]) + ";";
    EXPECT_EQ(m.channel->schema_name, "crane_msgs/msg/X");
  });
  EXPECT_EQ(seen, "/a:0:1000:900:3:2;/b:1:1001:901:3:3;/a:2:1002:902:3:4;/b:3:1003:903:3:5;/a:4:1004:904:3:6;");
  // Cut inside the data section: refused naming the file.
  const auto bytes = read_all(path);
  {
    std::ofstream cut(path, std::ios::binary | std::ios::trunc);
    cut.write(reinterpret_cast<const char*>(bytes.data()), 100);
  }
  try {
    crane::launch::read_mcap_messages(path, [](const crane::launch::McapMessageView&) {});
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
  std::filesystem::remove(path);
}

TEST(McapWriter, RefusesAPathItCannotWriteNamingIt) {
  try {
    crane::launch::McapWriter writer("/nonexistent-dir/x.mcap", "ros2", "test");
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent-dir/x.mcap"), std::string::npos);
  }
}

}  // namespace
