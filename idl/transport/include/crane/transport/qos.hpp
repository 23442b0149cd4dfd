#pragma once
// The four QoS profiles of the control bus, defined once (docs/architecture.md, "QoS").
//
//   stream      best effort, keep last 1, volatile, deadline 20 ms offered / 30 ms requested,
//               liveliness MANUAL_BY_TOPIC with a 100 ms lease (a sample written asserts it).
//   command     reliable, keep last 8, volatile.
//   safety      reliable, keep last 1, transient local, deadline 20 ms offered / 30 ms requested,
//               liveliness MANUAL_BY_TOPIC with a 100 ms lease.
//   diagnostics best effort, keep last 1, volatile.
//
// Every policy is set explicitly: Fast DDS and Cyclone DDS defaults differ.

#include <chrono>
#include <cstdint>

namespace crane::transport {

enum class QosKind : std::uint8_t { stream, command, safety, diagnostics };

enum class Reliability : std::uint8_t { best_effort, reliable };
enum class Durability : std::uint8_t { volatile_, transient_local };

/// Vendor-neutral description of one QoS profile; each vendor adapter maps it field by field.
struct QosProfile {
  Reliability reliability{Reliability::best_effort};
  Durability durability{Durability::volatile_};
  std::int32_t history_depth{1};                 // keep last N
  std::chrono::nanoseconds writer_deadline{0};   // 0 = infinite
  std::chrono::nanoseconds reader_deadline{0};   // 0 = infinite
  bool manual_by_topic_liveliness{false};
  std::chrono::nanoseconds liveliness_lease{0};  // 0 = infinite (AUTOMATIC liveliness then)
};

/// The single definition of every profile.
[[nodiscard]] QosProfile qos_profile(QosKind kind) noexcept;

}  // namespace crane::transport
