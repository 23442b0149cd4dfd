#include "crane/transport/qos.hpp"

namespace crane::transport {

using std::chrono::milliseconds;

QosProfile qos_profile(QosKind kind, Liveliness liveliness) noexcept {
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
  if (liveliness == Liveliness::watchdogs) {
    p.writer_deadline = p.reader_deadline = std::chrono::nanoseconds(0);
    p.manual_by_topic_liveliness = false;
    p.liveliness_lease = std::chrono::nanoseconds(0);
  }
  return p;
}

}  // namespace crane::transport
