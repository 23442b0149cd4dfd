#pragma once
// crane_web's /metrics: the Prometheus text exposition format (version 0.0.4) through
// prometheus-cpp (Debian's prometheus-cpp-dev: its core registry and text serializer; the HTTP
// side is crane_web's own websocketpp server, not prometheus-cpp's civetweb exposer).
//
// What it shows, all from what crane_web receives on the bus (it never asks a process):
//   crane_topic_samples_received_total{topic}     samples taken from the bus
//   crane_topic_nonfinite_rejected_total{topic}   of those, rejected for NaN/Inf (not forwarded)
//   crane_topic_rate_hz{topic}                    samples per second over the last update_rates() window
//   crane_supervisor_mode{mode}                   1 for the supervisor's current mode, 0 for the others
//   crane_supervisor_fault_active{fault}, crane_supervisor_fault_latched{fault}   0/1 per fault bit
//   crane_supervisor_faults_raised                faults raised since the supervisor started
//   crane_supervisor_nonfinite_rejected           samples the supervisor rejected for NaN/Inf
//   crane_process_cycles{process}, crane_process_overruns{process},
//   crane_process_nonfinite_rejected{process}     each process's LoopDiagnostics_ (once a second)
//   crane_process_latency_us{process,quantile}    its latency p50 ("0.5"), p99 ("0.99"), max ("1")
//   crane_web_clients, crane_web_connections_total, crane_web_samples_sent_total,
//   crane_web_samples_dropped_total, crane_web_requests_refused_total{kind=request|binary|handshake|oversized},
//   crane_web_stalled_clients_closed_total
// Label values are the IDL's code names (protocol::code_name): mode="operating", fault="swing".
//
// Thread safety: the updates come from one thread (the DDS loop); text() may run concurrently on
// another (prometheus-cpp's metrics are atomic, its families locked).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "crane/protocol/messages.hpp"

namespace crane::web {

struct ServerStats;

class WebMetrics {
 public:
  /// `topics`: the bus's topic names, indexed as in sample()/nonfinite(). Throws
  /// std::invalid_argument on an empty list.
  explicit WebMetrics(const std::vector<std::string>& topics);
  ~WebMetrics();
  WebMetrics(const WebMetrics&) = delete;
  WebMetrics& operator=(const WebMetrics&) = delete;

  /// A sample of topic `topic_index` arrived (finite). Out-of-range indices are ignored.
  void sample(std::size_t topic_index) noexcept;
  /// A sample of topic `topic_index` arrived and was rejected for NaN/Inf.
  void nonfinite(std::size_t topic_index) noexcept;
  /// Sets every topic's rate from the samples counted since the last call, `elapsed` [s] ago
  /// (> 0; otherwise nothing changes).
  void update_rates(double elapsed) noexcept;
  /// The supervisor's status (rt/crane/safety/status): mode, faults.
  void supervisor(const protocol::SupervisorStatus& status);
  /// A process's loop diagnostics (rt/crane/diag/loop). Allocates on a process's first report.
  void loop(const protocol::LoopDiagnostics& diagnostics);
  /// The text of every metric, the server's counters read from `server` (may be null) first.
  [[nodiscard]] std::string text(const ServerStats* server);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crane::web
