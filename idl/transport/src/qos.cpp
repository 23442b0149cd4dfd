#include "crane/transport/qos.hpp"

namespace crane::transport {

using std::chrono::milliseconds;

QosProfile qos_profile(QosKind kind) noexcept {
  QosProfile p;
  switch (kind) {
    case QosKind::stream:
      p.reliability = Reliability::best_effort;
      p.durability = Durability::volatile_;
      p.history_depth = 1;
      p.writer_deadline = milliseconds(20);
      p.reader_deadline = milliseconds(30);
      p.manual_by_topic_liveliness = true;
      p.liveliness_lease = milliseconds(100);
      break;
    case QosKind::command:
      p.reliability = Reliability::reliable;
      p.durability = Durability::volatile_;
      p.history_depth = 8;
      break;
    case QosKind::safety:
      p.reliability = Reliability::reliable;
      p.durability = Durability::transient_local;
      p.history_depth = 1;
      p.writer_deadline = milliseconds(20);
      p.reader_deadline = milliseconds(30);
      p.manual_by_topic_liveliness = true;
      p.liveliness_lease = milliseconds(100);
      break;
    case QosKind::diagnostics:
      p.reliability = Reliability::best_effort;
      p.durability = Durability::volatile_;
      p.history_depth = 1;
      break;
  }
  return p;
}

}  // namespace crane::transport
