#pragma once
// DDS transport of the crane stack: a participant, and typed readers and writers as RAII objects.
//
// One interface, one adapter per vendor (STYLE.md habit 3). Processes pick the vendor at start
// (`--dds fast|cyclone`, default from the CRANE_DDS environment variable, else fast). Fast DDS is
// implemented; the Cyclone DDS adapter plugs in behind detail::ParticipantBackend.
//
// Network scope: by default a participant binds to the loopback interface only and discovers its
// peers by unicast on 127.0.0.1 (no multicast leaves the host), as ROS 2's localhost-only mode.
//
// Threading: Reader callbacks run on the vendor's listener thread; they only copy status and poke
// the Wakeup given at creation. take_next() and health() may be called from any single thread.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>
#include <string_view>

#include "crane/transport/qos.hpp"

namespace crane::transport {

enum class Vendor : std::uint8_t { fast_dds = 1, cyclone_dds = 2 };

/// "fast" -> fast_dds, "cyclone" -> cyclone_dds. Throws std::invalid_argument naming the value.
[[nodiscard]] Vendor parse_vendor(std::string_view text);
/// CRANE_DDS if set (parsed as above; throws on a bad value), else fast_dds.
[[nodiscard]] Vendor vendor_from_environment();
[[nodiscard]] const char* vendor_name(Vendor vendor) noexcept;

struct ParticipantOptions {
  std::string name{"crane"};      // participant name shown by discovery tools
  std::uint32_t domain_id{0};     // DDS domain
  bool loopback_only{true};       // bind to 127.0.0.1 only, unicast discovery on loopback
  bool shared_memory{true};       // with loopback_only false: also the shared-memory transport (false: UDP
                                  // only, as a participant on another machine talks to the stack)
  std::string profile_file;       // a network profile (deploy/dds/*.xml): its participant profile
                                  // "crane_participant" replaces loopback_only/shared_memory; empty: none
  Vendor vendor{Vendor::fast_dds};
};

/// Reader-side health, updated from DDS status events.
struct ReaderHealth {
  std::int32_t matched_writers{0};  // writers matched (discovery)
  std::int32_t alive_writers{0};    // writers whose liveliness is asserted within the lease
  std::uint64_t deadline_missed{0}; // requested-deadline-missed events since creation
  std::uint64_t liveliness_lost{0}; // transitions of a writer from alive to not alive
  std::uint64_t samples{0};         // valid samples taken
};

/// Writer-side health.
struct WriterHealth {
  std::int32_t matched_readers{0};
  std::uint64_t deadline_missed{0};
};

/// A writer or reader of another participant, as DDS discovery announced it (crane topic list).
struct DiscoveredEndpoint {
  std::string topic;             // e.g. "rt/crane/hw/sensors"
  std::string type;              // e.g. "crane_msgs::msg::dds_::SensorSample_"
  bool writer{false};            // true: a DataWriter, false: a DataReader
  std::string participant;       // the participant's name ("plant", ...), or its GUID prefix if unnamed
  std::string guid;              // endpoint GUID, hex
  bool reliable{false};          // RELIABLE (else BEST_EFFORT)
  bool transient_local{false};   // TRANSIENT_LOCAL durability (else VOLATILE)
  double deadline{0.0};          // [s] offered/requested deadline period, 0 = infinite
};

/// A wake-up shared by all readers of one process: readers notify it on data and status changes,
/// the node's loop waits on it. Blocks only in wait_until().
class Wakeup {
 public:
  void notify() noexcept;
  /// Waits until notified (returns true) or the deadline passes (false). Consumes the notification.
  bool wait_until(std::chrono::steady_clock::time_point deadline);

 private:
  std::mutex mutex_;
  std::condition_variable condition_;
  bool pending_{false};
};

namespace detail {

/// Type-erased description of one topic, filled from a topics:: tag.
struct TopicDescriptor {
  const char* name;
  const char* type_name;
  QosKind qos;
  std::function<void*()> fast_dds_type_factory;  // returns a new TopicDataType (ownership passed)
};

class WriterBackend {
 public:
  virtual ~WriterBackend() = default;
  virtual bool write(const void* sample) noexcept = 0;
  [[nodiscard]] virtual WriterHealth health() const noexcept = 0;
};

class ReaderBackend {
 public:
  virtual ~ReaderBackend() = default;
  virtual bool take_next(void* sample) noexcept = 0;
  [[nodiscard]] virtual ReaderHealth health() const noexcept = 0;
};

class ParticipantBackend {
 public:
  virtual ~ParticipantBackend() = default;
  [[nodiscard]] virtual std::vector<DiscoveredEndpoint> discovered_endpoints() const = 0;
  virtual std::unique_ptr<WriterBackend> create_writer(const TopicDescriptor& topic) = 0;
  /// history_depth > 0 overrides the profile's keep-last depth (a recorder that must not drop
  /// samples of a best-effort stream keeps more; the wire QoS stays compatible).
  virtual std::unique_ptr<ReaderBackend> create_reader(const TopicDescriptor& topic, Wakeup* wakeup,
                                                       std::int32_t history_depth) = 0;
};

std::unique_ptr<ParticipantBackend> make_fast_dds_backend(const ParticipantOptions& options);

template <class Topic>
TopicDescriptor describe() {
  return TopicDescriptor{Topic::name, Topic::type_name, Topic::qos,
                         [] { return static_cast<void*>(new typename Topic::FastDdsType()); }};
}

}  // namespace detail

/// Typed writer of topic tag T (see topics.hpp). Destroying it deletes the DDS writer.
template <class T>
class Writer {
 public:
  using Message = typename T::Message;
  explicit Writer(std::unique_ptr<detail::WriterBackend> backend) : backend_(std::move(backend)) {}
  /// Publishes one sample; false if the vendor refused it. Never throws, does not block on
  /// best-effort topics.
  bool write(const Message& message) noexcept { return backend_->write(&message); }
  [[nodiscard]] WriterHealth health() const noexcept { return backend_->health(); }

 private:
  std::unique_ptr<detail::WriterBackend> backend_;
};

/// Typed reader of topic tag T. Destroying it deletes the DDS reader.
template <class T>
class Reader {
 public:
  using Message = typename T::Message;
  explicit Reader(std::unique_ptr<detail::ReaderBackend> backend) : backend_(std::move(backend)) {}
  /// Takes the oldest unread valid sample into `message`; false when none is waiting.
  bool take_next(Message& message) noexcept { return backend_->take_next(&message); }
  /// Drains the reader and keeps the newest sample; false when none was waiting.
  bool take_latest(Message& message) noexcept {
    bool any = false;
    while (backend_->take_next(&message)) any = true;
    return any;
  }
  [[nodiscard]] ReaderHealth health() const noexcept { return backend_->health(); }

 private:
  std::unique_ptr<detail::ReaderBackend> backend_;
};

/// A DDS domain participant of the chosen vendor. Throws std::runtime_error if the vendor cannot
/// create it (message names the vendor and domain).
class Participant {
 public:
  explicit Participant(const ParticipantOptions& options);
  ~Participant();
  Participant(const Participant&) = delete;
  Participant& operator=(const Participant&) = delete;

  template <class T>
  std::unique_ptr<Writer<T>> make_writer() {
    return std::make_unique<Writer<T>>(backend_->create_writer(detail::describe<T>()));
  }
  /// `wakeup` (may be null) is notified on every sample and status change of this reader.
  template <class T>
  std::unique_ptr<Reader<T>> make_reader(Wakeup* wakeup) {
    return std::make_unique<Reader<T>>(backend_->create_reader(detail::describe<T>(), wakeup, 0));
  }
  /// A reader that keeps the last `history_depth` samples instead of the profile's depth (recorders).
  template <class T>
  std::unique_ptr<Reader<T>> make_recording_reader(Wakeup* wakeup, std::int32_t history_depth) {
    return std::make_unique<Reader<T>>(backend_->create_reader(detail::describe<T>(), wakeup, history_depth));
  }
  [[nodiscard]] Vendor vendor() const noexcept { return options_.vendor; }
  /// Writers and readers of the other participants discovered so far (this one's own excluded),
  /// sorted by topic. Safe to call from any thread.
  [[nodiscard]] std::vector<DiscoveredEndpoint> discovered_endpoints() const { return backend_->discovered_endpoints(); }
  [[nodiscard]] const ParticipantOptions& options() const noexcept { return options_; }

 private:
  ParticipantOptions options_;
  std::unique_ptr<detail::ParticipantBackend> backend_;
};

}  // namespace crane::transport
