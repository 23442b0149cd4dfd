#pragma once
// A sample of the bus as its bytes on the wire: the serialized payload a Fast DDS writer sends,
// for tools that forward samples without knowing their fields (crane_web, the Foxglove server).
//
// The bytes are what fastddsgen's type support writes into an RTPS DATA submessage: the 4-byte
// encapsulation header (0x00 0x01 0x00 0x00: plain CDR, little endian; XCDR1, as every type of
// idl/crane_msgs.idl is @final) followed by the fields in CDR, aligned from the end of that header.
// Cyclone DDS writes the same bytes for these types (docs/architecture.md, "Topics"), and a CDR
// reader that takes the encapsulation header first (Foxglove's @foxglove/cdr CdrReader, rosbag2's
// mcap storage) reads them.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <vector>

#include <fastdds/rtps/common/SerializedPayload.h>

#include "crane/transport/topics.hpp"

namespace crane::transport {

/// Serializes `message` of topic tag `Topic` (topics.hpp) into `bytes` (resized to the serialized
/// length, encapsulation header included). Returns false, `bytes` empty, if the type support
/// refuses it (it does not for these fixed-size types). Allocates.
template <class Topic>
[[nodiscard]] bool serialize_cdr(const typename Topic::Message& message, std::vector<std::uint8_t>& bytes) {
  typename Topic::FastDdsType type;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(type.m_typeSize);
  // The type support takes a non-const pointer; it only reads the message.
  if (!type.serialize(const_cast<typename Topic::Message*>(&message), &payload)) {
    bytes.clear();
    return false;
  }
  bytes.assign(payload.data, payload.data + payload.length);
  return true;
}

/// The inverse: reads `size` bytes (encapsulation header included) into `message`. Returns false,
/// `message` unspecified, when the type support refuses them (too short, unknown encapsulation).
template <class Topic>
[[nodiscard]] bool deserialize_cdr(const std::uint8_t* data, std::size_t size, typename Topic::Message& message) {
  typename Topic::FastDdsType type;
  if (size < 4 || size > type.m_typeSize) return false;
  eprosima::fastrtps::rtps::SerializedPayload_t payload(static_cast<std::uint32_t>(size));
  std::copy(data, data + size, payload.data);
  payload.length = static_cast<std::uint32_t>(size);
  return type.deserialize(&payload, &message);
}

}  // namespace crane::transport
