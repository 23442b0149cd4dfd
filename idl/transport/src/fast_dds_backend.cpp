// Fast DDS 2.9 adapter of the transport interface.
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/domain/DomainParticipantListener.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/DataWriterListener.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/Topic.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <algorithm>
#include <atomic>
#include <map>
#include <mutex>
#include <sstream>
#include <stdexcept>
#include <string>

#include "crane/transport/participant.hpp"

namespace crane::transport::detail {
namespace {

namespace dds = eprosima::fastdds::dds;
using eprosima::fastrtps::Duration_t;

Duration_t to_duration(std::chrono::nanoseconds value) {
  if (value.count() == 0) return eprosima::fastrtps::c_TimeInfinite;
  const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(value);
  return Duration_t(static_cast<int32_t>(seconds.count()),
                    static_cast<uint32_t>((value - seconds).count()));
}

template <class Qos>
void apply_common(const QosProfile& p, Qos& qos) {
  qos.reliability().kind = p.reliability == Reliability::reliable ? dds::RELIABLE_RELIABILITY_QOS
                                                                  : dds::BEST_EFFORT_RELIABILITY_QOS;
  qos.durability().kind = p.durability == Durability::transient_local ? dds::TRANSIENT_LOCAL_DURABILITY_QOS
                                                                      : dds::VOLATILE_DURABILITY_QOS;
  qos.history().kind = dds::KEEP_LAST_HISTORY_QOS;
  qos.history().depth = p.history_depth;
  if (p.manual_by_topic_liveliness) {
    qos.liveliness().kind = dds::MANUAL_BY_TOPIC_LIVELINESS_QOS;
    qos.liveliness().lease_duration = to_duration(p.liveliness_lease);
    qos.liveliness().announcement_period = to_duration(p.liveliness_lease / 2);
  } else {
    qos.liveliness().kind = dds::AUTOMATIC_LIVELINESS_QOS;
    qos.liveliness().lease_duration = eprosima::fastrtps::c_TimeInfinite;
  }
}

dds::DataWriterQos writer_qos(QosKind kind, Liveliness liveliness) {
  const QosProfile p = qos_profile(kind, liveliness);
  dds::DataWriterQos qos = dds::DATAWRITER_QOS_DEFAULT;
  apply_common(p, qos);
  qos.deadline().period = to_duration(p.writer_deadline);
  qos.data_sharing().off();  // see reader_qos()
  if (p.reliability == Reliability::best_effort) {
    qos.publish_mode().kind = dds::SYNCHRONOUS_PUBLISH_MODE;
  }
  return qos;
}

dds::DataReaderQos reader_qos(QosKind kind, Liveliness liveliness, std::int32_t history_depth) {
  QosProfile p = qos_profile(kind, liveliness);
  if (history_depth > 0) p.history_depth = history_depth;
  dds::DataReaderQos qos = dds::DATAREADER_QOS_DEFAULT;
  apply_common(p, qos);
  // Room for more than the kept history: a reliable reader also stores samples that arrive ahead
  // of a missing one; with room for only one it can wait forever for the gap to be filled (seen
  // here: a safety-status reader matched and alive, 0 samples delivered, in about 1 run of 15).
  qos.resource_limits().max_samples = std::max(p.history_depth, 256);
  qos.resource_limits().max_samples_per_instance = std::max(p.history_depth, 256);
  // Data sharing off (writers too): a deep reader history would only hold references into the
  // writer's keep-last-1 pool, which the next sample overwrites; and a reader whose remote writer's
  // process has exited crashed here when freeing its cache (Fast DDS 2.9, CacheChangePool
  // destructor).
  qos.data_sharing().off();
  qos.deadline().period = to_duration(p.reader_deadline);
  return qos;
}

class FastWriter final : public WriterBackend, public dds::DataWriterListener {
 public:
  FastWriter(dds::Publisher* publisher, dds::Topic* topic, QosKind kind, Liveliness liveliness)
      : publisher_(publisher) {
    writer_ = publisher->create_datawriter(topic, writer_qos(kind, liveliness), this, dds::StatusMask::all());
    if (writer_ == nullptr) {
      throw std::runtime_error(std::string("fast dds: cannot create a writer on ") + topic->get_name() +
                               " (with DDS Security: not in this identity's permissions to publish)");
    }
  }
  ~FastWriter() override {
    writer_->set_listener(nullptr);
    publisher_->delete_datawriter(writer_);
  }
  bool write(const void* sample) noexcept override {
    return writer_->write(const_cast<void*>(sample));
  }
  [[nodiscard]] WriterHealth health() const noexcept override {
    return WriterHealth{matched_.load(), deadline_missed_.load()};
  }
  void on_publication_matched(dds::DataWriter*, const dds::PublicationMatchedStatus& status) override {
    matched_.store(status.current_count);
  }
  void on_offered_deadline_missed(dds::DataWriter*, const dds::OfferedDeadlineMissedStatus& status) override {
    deadline_missed_.store(static_cast<std::uint64_t>(status.total_count));
  }

 private:
  dds::Publisher* publisher_;
  dds::DataWriter* writer_{nullptr};
  std::atomic<std::int32_t> matched_{0};
  std::atomic<std::uint64_t> deadline_missed_{0};
};

class FastReader final : public ReaderBackend, public dds::DataReaderListener {
 public:
  FastReader(dds::Subscriber* subscriber, dds::Topic* topic, QosKind kind, Liveliness liveliness, Wakeup* wakeup,
             std::int32_t depth)
      : subscriber_(subscriber), wakeup_(wakeup) {
    reader_ = subscriber->create_datareader(topic, reader_qos(kind, liveliness, depth), this, dds::StatusMask::all());
    if (reader_ == nullptr) {
      throw std::runtime_error(std::string("fast dds: cannot create a reader on ") + topic->get_name() +
                               " (with DDS Security: not in this identity's permissions to subscribe)");
    }
  }
  ~FastReader() override {
    reader_->set_listener(nullptr);
    subscriber_->delete_datareader(reader_);
  }
  bool take_next(void* sample) noexcept override {
    dds::SampleInfo info;
    while (reader_->take_next_sample(sample, &info) == ReturnCode_t::RETCODE_OK) {
      if (info.valid_data) {
        samples_.fetch_add(1);
        return true;
      }
    }
    return false;
  }
  [[nodiscard]] ReaderHealth health() const noexcept override {
    return ReaderHealth{matched_.load(), alive_.load(), deadline_missed_.load(), liveliness_lost_.load(),
                        samples_.load()};
  }
  void on_data_available(dds::DataReader*) override { poke(); }
  void on_subscription_matched(dds::DataReader*, const dds::SubscriptionMatchedStatus& status) override {
    matched_.store(status.current_count);
    poke();
  }
  void on_requested_deadline_missed(dds::DataReader*, const dds::RequestedDeadlineMissedStatus& status) override {
    deadline_missed_.store(static_cast<std::uint64_t>(status.total_count));
    poke();
  }
  void on_liveliness_changed(dds::DataReader*, const dds::LivelinessChangedStatus& status) override {
    alive_.store(status.alive_count);
    if (status.not_alive_count_change > 0) {
      liveliness_lost_.fetch_add(static_cast<std::uint64_t>(status.not_alive_count_change));
    }
    poke();
  }

 private:
  void poke() noexcept {
    if (wakeup_ != nullptr) wakeup_->notify();
  }
  dds::Subscriber* subscriber_;
  Wakeup* wakeup_;
  dds::DataReader* reader_{nullptr};
  std::atomic<std::int32_t> matched_{0};
  std::atomic<std::int32_t> alive_{0};
  std::atomic<std::uint64_t> deadline_missed_{0};
  std::atomic<std::uint64_t> liveliness_lost_{0};
  std::atomic<std::uint64_t> samples_{0};
};

std::string hex(const eprosima::fastrtps::rtps::GUID_t& guid) {
  std::ostringstream out;
  out << guid;
  return out.str();
}
std::string hex(const eprosima::fastrtps::rtps::GuidPrefix_t& prefix) {
  std::ostringstream out;
  out << prefix;
  return out.str();
}

// Keeps what discovery announces about the other participants' endpoints (crane topic list).
class DiscoveryListener final : public dds::DomainParticipantListener {
 public:
  void on_participant_discovery(dds::DomainParticipant*, eprosima::fastrtps::rtps::ParticipantDiscoveryInfo&& info) override {
    std::lock_guard lock(mutex_);
    using S = eprosima::fastrtps::rtps::ParticipantDiscoveryInfo;
    const auto prefix = hex(info.info.m_guid.guidPrefix);
    if (info.status == S::REMOVED_PARTICIPANT || info.status == S::DROPPED_PARTICIPANT) {
      names_.erase(prefix);
      for (auto it = endpoints_.begin(); it != endpoints_.end();) {
        it = it->second.guid.rfind(prefix, 0) == 0 ? endpoints_.erase(it) : std::next(it);
      }
    } else {
      names_[prefix] = info.info.m_participantName.to_string();
    }
  }
  void on_publisher_discovery(dds::DomainParticipant*, eprosima::fastrtps::rtps::WriterDiscoveryInfo&& info) override {
    using S = eprosima::fastrtps::rtps::WriterDiscoveryInfo;
    const auto& d = info.info;
    update(hex(d.guid()), info.status == S::REMOVED_WRITER, d.topicName().to_string(),
           d.typeName().to_string(), true, d.guid().guidPrefix, d.m_qos.m_reliability.kind == eprosima::fastrtps::RELIABLE_RELIABILITY_QOS,
           d.m_qos.m_durability.kind == eprosima::fastrtps::TRANSIENT_LOCAL_DURABILITY_QOS, d.m_qos.m_deadline.period);
  }
  void on_subscriber_discovery(dds::DomainParticipant*, eprosima::fastrtps::rtps::ReaderDiscoveryInfo&& info) override {
    using S = eprosima::fastrtps::rtps::ReaderDiscoveryInfo;
    const auto& d = info.info;
    update(hex(d.guid()), info.status == S::REMOVED_READER, d.topicName().to_string(),
           d.typeName().to_string(), false, d.guid().guidPrefix, d.m_qos.m_reliability.kind == eprosima::fastrtps::RELIABLE_RELIABILITY_QOS,
           d.m_qos.m_durability.kind == eprosima::fastrtps::TRANSIENT_LOCAL_DURABILITY_QOS, d.m_qos.m_deadline.period);
  }
  std::vector<DiscoveredEndpoint> snapshot(const std::string& own_prefix) const {
    std::lock_guard lock(mutex_);
    std::vector<DiscoveredEndpoint> out;
    for (const auto& [guid, e] : endpoints_) {
      if (guid.rfind(own_prefix, 0) == 0) continue;
      DiscoveredEndpoint copy = e;
      const auto name = names_.find(guid.substr(0, own_prefix.size()));
      copy.participant = name != names_.end() && !name->second.empty() ? name->second : guid.substr(0, own_prefix.size());
      out.push_back(std::move(copy));
    }
    std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) {
      return std::tie(a.topic, a.writer, a.participant) < std::tie(b.topic, b.writer, b.participant);
    });
    return out;
  }

 private:
  void update(const std::string& guid, bool removed, std::string topic, std::string type, bool writer,
              const eprosima::fastrtps::rtps::GuidPrefix_t&, bool reliable, bool transient_local,
              const eprosima::fastrtps::Duration_t& deadline) {
    std::lock_guard lock(mutex_);
    if (removed) {
      endpoints_.erase(guid);
      return;
    }
    DiscoveredEndpoint e;
    e.topic = std::move(topic);
    e.type = std::move(type);
    e.writer = writer;
    e.guid = guid;
    e.reliable = reliable;
    e.transient_local = transient_local;
    e.deadline = deadline == eprosima::fastrtps::c_TimeInfinite ? 0.0 : static_cast<double>(deadline.to_ns()) * 1e-9;
    endpoints_[guid] = std::move(e);
  }
  mutable std::mutex mutex_;
  std::map<std::string, std::string> names_;          // GUID prefix -> participant name
  std::map<std::string, DiscoveredEndpoint> endpoints_;  // endpoint GUID -> endpoint
};

// DDS Security through the participant's properties (Fast DDS 2.9, "Security" chapter): the builtin
// PKI-DH, Access-Permissions and AES-GCM-GMAC plugins, files as file:// URIs.
void apply_security(const SecurityFiles& files, dds::DomainParticipantQos& qos) {
  auto& properties = qos.properties().properties();
  const auto set = [&properties](const std::string& name, const std::string& value) {
    properties.emplace_back(name, value);
  };
  set("dds.sec.auth.plugin", "builtin.PKI-DH");
  set("dds.sec.auth.builtin.PKI-DH.identity_ca", "file://" + files.identity_ca);
  set("dds.sec.auth.builtin.PKI-DH.identity_certificate", "file://" + files.certificate);
  set("dds.sec.auth.builtin.PKI-DH.private_key", "file://" + files.private_key);
  set("dds.sec.access.plugin", "builtin.Access-Permissions");
  set("dds.sec.access.builtin.Access-Permissions.permissions_ca", "file://" + files.permissions_ca);
  set("dds.sec.access.builtin.Access-Permissions.governance", "file://" + files.governance);
  set("dds.sec.access.builtin.Access-Permissions.permissions", "file://" + files.permissions);
  set("dds.sec.crypto.plugin", "builtin.AES-GCM-GMAC");
}

// The UDP transport of the loopback and the UDP-only participants. Its sockets may buffer 4 MiB
// (the kernel caps this at net.core.rmem_max; Debian's default is 208 KiB, this machine's 4 MiB).
// On the loopback every sample of the stack is a datagram (the loopback participants announce
// their UDP locator for user data, so the shared-memory transport carries none), and the kernel
// charges each small datagram its allocation, far more than its payload: a recorder reading six
// topics whose receive thread was starved for a fraction of a second under load lost samples.
// Measured (docs/architecture.md, "QoS"): crane_demo's own threads at nice 19 beside four CPU
// hogs, the default buffer lost 289-708 of 1501 cycles of each recorded move (UDP RcvbufErrors
// 5720 in one run); 4 MiB lost none.
constexpr std::uint32_t kUdpReceiveBufferBytes = 4U * 1024U * 1024U;

std::shared_ptr<eprosima::fastdds::rtps::UDPv4TransportDescriptor> udp_transport() {
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->receiveBufferSize = kUdpReceiveBufferBytes;
  return udp;
}

class FastParticipant final : public ParticipantBackend {
 public:
  FastParticipant(const ParticipantOptions& options, const SecurityFiles* security)
      : liveliness_(effective_liveliness(options)) {
    dds::DomainParticipantQos qos = dds::PARTICIPANT_QOS_DEFAULT;
    qos.name(options.name);
    // Faster detection of vanished participants than the 20 s default; stages are watched by
    // deadline and liveliness anyway. Announced every 100 ms: a participant that joins a running
    // stack (crane_safety estop, crane_move, a monitor) learns of the others at their next
    // announcement, so the period is what an operator's command may wait before it can be sent.
    // With 1 s, `deploy/crane estop` braked after 1.04-1.14 s in 3 of 10 runs (idle machine); with
    // 100 ms, 104-224 ms in 10 of 10 (docs/operation.md). About 10 participants times 10 small
    // datagrams a second on the loopback. The LAN profiles set their own period.
    qos.wire_protocol().builtin.discovery_config.leaseDuration = Duration_t(3, 0);
    qos.wire_protocol().builtin.discovery_config.leaseDuration_announcementperiod = Duration_t(0, 100'000'000);
    if (!options.profile_file.empty()) {
      // A network profile (deploy/dds/): transports, discovery peers, lease from the XML.
      auto* factory = dds::DomainParticipantFactory::get_instance();
      if (factory->load_XML_profiles_file(options.profile_file) != ReturnCode_t::RETCODE_OK) {
        throw std::runtime_error("fast dds: cannot load the network profile " + options.profile_file);
      }
      if (factory->get_participant_qos_from_profile("crane_participant", qos) != ReturnCode_t::RETCODE_OK) {
        throw std::runtime_error("fast dds: " + options.profile_file + " has no participant profile \"crane_participant\"");
      }
      qos.name(options.name);
    } else if (options.loopback_only) {
      qos.transport().use_builtin_transports = false;
      auto udp = udp_transport();
      udp->interfaceWhiteList.emplace_back("127.0.0.1");
      udp->maxInitialPeersRange = 32;  // participants probed on 127.0.0.1 by unicast discovery
      qos.transport().user_transports.push_back(udp);
      qos.transport().user_transports.push_back(
          std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
      eprosima::fastrtps::rtps::Locator_t peer;
      eprosima::fastrtps::rtps::IPLocator::setIPv4(peer, 127, 0, 0, 1);
      peer.kind = LOCATOR_KIND_UDPv4;
      qos.wire_protocol().builtin.initialPeersList.push_back(peer);
      eprosima::fastrtps::rtps::Locator_t meta;
      eprosima::fastrtps::rtps::IPLocator::setIPv4(meta, 127, 0, 0, 1);
      meta.kind = LOCATOR_KIND_UDPv4;
      qos.wire_protocol().builtin.metatrafficUnicastLocatorList.push_back(meta);
      qos.wire_protocol().default_unicast_locator_list.push_back(meta);
    } else if (!options.shared_memory) {
      // A participant on another machine (crane_topic --lan): UDP only, and its readers ask for
      // user data on the RTPS default user multicast group and port of the domain, so that a
      // writer sends each sample once for all such monitors (Fast DDS picks a multicast locator
      // that several readers share) instead of once per monitor.
      qos.transport().use_builtin_transports = false;
      qos.transport().user_transports.push_back(udp_transport());
      eprosima::fastrtps::rtps::Locator_t group;
      eprosima::fastrtps::rtps::IPLocator::setIPv4(group, 239, 255, 0, 1);
      group.kind = LOCATOR_KIND_UDPv4;
      group.port = 7400U + 250U * options.domain_id + 1U;  // PB + DG * domain + d2 (RTPS 2.2, 9.6.1.1)
      qos.wire_protocol().default_multicast_locator_list.push_back(group);
    }
    if (security != nullptr) apply_security(*security, qos);
    // Only the discovery callbacks go to the listener; data and status stay with each endpoint.
    participant_ = dds::DomainParticipantFactory::get_instance()->create_participant(
        static_cast<dds::DomainId_t>(options.domain_id), qos, &discovery_, dds::StatusMask::none());
    if (participant_ == nullptr) {
      throw std::runtime_error("fast dds: cannot create a participant in domain " +
                               std::to_string(options.domain_id) +
                               (security != nullptr ? " with the DDS Security files of identity '" + options.identity +
                                                          "' in " + options.security_directory + " (refused by Fast DDS)"
                                                    : std::string()));
    }
    publisher_ = participant_->create_publisher(dds::PUBLISHER_QOS_DEFAULT);
    subscriber_ = participant_->create_subscriber(dds::SUBSCRIBER_QOS_DEFAULT);
    if (publisher_ == nullptr || subscriber_ == nullptr) {
      throw std::runtime_error("fast dds: cannot create a publisher or subscriber");
    }
  }
  ~FastParticipant() override {
    participant_->set_listener(nullptr);
    participant_->delete_contained_entities();
    dds::DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }
  std::vector<DiscoveredEndpoint> discovered_endpoints() const override {
    return discovery_.snapshot(hex(participant_->guid().guidPrefix));
  }
  std::unique_ptr<WriterBackend> create_writer(const TopicDescriptor& topic) override {
    return std::make_unique<FastWriter>(publisher_, topic_for(topic), topic.qos, liveliness_);
  }
  std::unique_ptr<ReaderBackend> create_reader(const TopicDescriptor& topic, Wakeup* wakeup,
                                              std::int32_t history_depth) override {
    return std::make_unique<FastReader>(subscriber_, topic_for(topic), topic.qos, liveliness_, wakeup, history_depth);
  }

 private:
  dds::Topic* topic_for(const TopicDescriptor& topic) {
    auto found = topics_.find(topic.name);
    if (found != topics_.end()) return found->second;
    dds::TypeSupport type(static_cast<dds::TopicDataType*>(topic.fast_dds_type_factory()));
    if (participant_->find_type(topic.type_name).empty()) {
      if (type.register_type(participant_) != ReturnCode_t::RETCODE_OK) {
        throw std::runtime_error(std::string("fast dds: cannot register type ") + topic.type_name);
      }
    }
    dds::Topic* created = participant_->create_topic(topic.name, topic.type_name, dds::TOPIC_QOS_DEFAULT);
    if (created == nullptr) throw std::runtime_error(std::string("fast dds: cannot create topic ") + topic.name);
    topics_.emplace(topic.name, created);
    return created;
  }

  Liveliness liveliness_;
  DiscoveryListener discovery_;  // declared before participant_: outlives it
  dds::DomainParticipant* participant_{nullptr};
  dds::Publisher* publisher_{nullptr};
  dds::Subscriber* subscriber_{nullptr};
  std::map<std::string, dds::Topic*> topics_;
};

}  // namespace

std::unique_ptr<ParticipantBackend> make_fast_dds_backend(const ParticipantOptions& options,
                                                          const SecurityFiles* security) {
  return std::make_unique<FastParticipant>(options, security);
}

}  // namespace crane::transport::detail
