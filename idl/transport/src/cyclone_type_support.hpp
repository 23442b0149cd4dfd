#pragma once
// Cyclone DDS type support of the transport (internal). The table is generated at build time from
// idl/crane_msgs.idl by idl/tools/gen_cyclone_support.py: for every IDL struct, idlc's topic
// descriptor and the field-by-field conversions between the fastddsgen C++ class (the canonical
// in-process message) and idlc's C struct (what Cyclone DDS serializes).

#include <dds/dds.h>

#include <cstddef>
#include <string_view>

namespace crane::transport::detail {

struct CycloneTypeSupport {
  const char* type_name;                          // DDS type name, e.g. crane_msgs::msg::dds_::SensorSample_
  const dds_topic_descriptor_t* descriptor;       // idlc's descriptor of the C struct
  std::size_t c_size;                             // [bytes] sizeof the C struct
  void (*to_c)(const void* message, void* c_sample);    // C++ class -> C struct (every field)
  void (*from_c)(const void* c_sample, void* message);  // C struct -> C++ class (every field)
};

/// The entry of `type_name`, or nullptr when the IDL has no such struct.
[[nodiscard]] const CycloneTypeSupport* find_cyclone_type_support(std::string_view type_name) noexcept;
/// Number of IDL structs in the table (tests: every message type is covered).
[[nodiscard]] std::size_t cyclone_type_count() noexcept;

}  // namespace crane::transport::detail
