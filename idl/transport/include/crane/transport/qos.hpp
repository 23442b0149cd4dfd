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
//
// With Liveliness::watchdogs (a stack on iceoryx shared memory, and every participant that talks to
// one) stream and safety keep everything but the deadlines and the lease: AUTOMATIC liveliness, no
// deadline. Cyclone DDS 0.10 delivers through iceoryx only for such endpoints
// (dds_writer_support_shm() and its reader counterpart) and falls back to UDP for any other. The
// chain's failure detection is then the supervisor's own receive-time watchdog (stage_timeout,
// stage_dead_timeout) and the actuation gate's command-age watchdog, which bound it on the network
// too (docs/architecture.md, "Shared memory"). A writer and a reader match only with the same
// choice (a reader may not ask for a lease or a deadline its writer does not offer).

#include <chrono>
#include <cstdint>

namespace crane::transport {

enum class QosKind : std::uint8_t { stream, command, safety, diagnostics };

/// What tells a reader that a stream's writer is gone: DDS liveliness and deadlines beside the
/// application's watchdogs (the default), or the watchdogs alone (a stack on iceoryx).
enum class Liveliness : std::uint8_t { dds, watchdogs };

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

/// The single definition of every profile, with the failure detection `liveliness` says.
[[nodiscard]] QosProfile qos_profile(QosKind kind, Liveliness liveliness = Liveliness::dds) noexcept;

}  // namespace crane::transport
