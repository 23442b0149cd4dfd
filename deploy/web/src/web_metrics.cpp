#include "crane/web/web_metrics.hpp"

#include <map>
#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/registry.h>
#include <prometheus/text_serializer.h>
#include <stdexcept>

#include "crane/web/foxglove_server.hpp"

namespace crane::web {

namespace {

using prometheus::BuildCounter;
using prometheus::BuildGauge;
using prometheus::Counter;
using prometheus::Family;
using prometheus::Gauge;

/// Moves a counter up to `value` (a count kept elsewhere; prometheus counters only increase).
void counter_to(Counter& counter, double value) {
  const double delta = value - counter.Value();
  if (delta > 0.0) counter.Increment(delta);
}

}  // namespace

struct WebMetrics::Impl {
  prometheus::Registry registry;
  Family<Counter>& received = BuildCounter().Name("crane_topic_samples_received_total")
                                  .Help("Samples crane_web took from the bus, per topic").Register(registry);
  Family<Counter>& rejected = BuildCounter().Name("crane_topic_nonfinite_rejected_total")
                                  .Help("Samples with NaN or Inf rejected (not forwarded), per topic").Register(registry);
  Family<Gauge>& rate = BuildGauge().Name("crane_topic_rate_hz")
                            .Help("Samples per second over the last second, per topic").Register(registry);
  Family<Gauge>& mode = BuildGauge().Name("crane_supervisor_mode")
                            .Help("1 for the supervisor's current mode, 0 for the others").Register(registry);
  Family<Gauge>& fault_active = BuildGauge().Name("crane_supervisor_fault_active")
                                    .Help("1 while the fault is active").Register(registry);
  Family<Gauge>& fault_latched = BuildGauge().Name("crane_supervisor_fault_latched")
                                     .Help("1 while the fault is latched (until reset)").Register(registry);
  Family<Gauge>& faults_raised = BuildGauge().Name("crane_supervisor_faults_raised")
                                     .Help("Faults raised since the supervisor started").Register(registry);
  Family<Gauge>& supervisor_nonfinite = BuildGauge().Name("crane_supervisor_nonfinite_rejected")
                                            .Help("Samples the supervisor rejected for NaN/Inf").Register(registry);
  Family<Gauge>& cycles = BuildGauge().Name("crane_process_cycles")
                              .Help("Cycles processed since start (LoopDiagnostics_)").Register(registry);
  Family<Gauge>& overruns = BuildGauge().Name("crane_process_overruns")
                                .Help("Cycles whose inputs were late or missing (LoopDiagnostics_)").Register(registry);
  Family<Gauge>& process_nonfinite = BuildGauge().Name("crane_process_nonfinite_rejected")
                                         .Help("Input samples rejected for NaN/Inf (LoopDiagnostics_)").Register(registry);
  Family<Gauge>& latency = BuildGauge().Name("crane_process_latency_us")
                               .Help("The process's measured latency [us]: p50, p99 and max (quantile 1)")
                               .Register(registry);
  Family<Gauge>& clients = BuildGauge().Name("crane_web_clients").Help("Connected Foxglove clients").Register(registry);
  Family<Counter>& connections = BuildCounter().Name("crane_web_connections_total")
                                     .Help("Foxglove clients accepted since start").Register(registry);
  Family<Counter>& sent = BuildCounter().Name("crane_web_samples_sent_total")
                              .Help("Samples handed to client sockets").Register(registry);
  Family<Counter>& dropped = BuildCounter().Name("crane_web_samples_dropped_total")
                                 .Help("Samples dropped from full client queues (oldest first)").Register(registry);
  Family<Counter>& refused = BuildCounter().Name("crane_web_requests_refused_total")
                                 .Help("Client input refused: request (malformed, unknown id, unsupported), "
                                       "binary (publishing off, channel not advertised, refused for the bus), "
                                       "handshake (no foxglove.websocket.v1), "
                                       "oversized (frame over the limit: client closed, 1009)")
                                 .Register(registry);
  Family<Counter>& stalled = BuildCounter().Name("crane_web_stalled_clients_closed_total")
                                 .Help("Clients closed (1008) for reading nothing: every sample to them dropped "
                                       "for --close-stalled seconds")
                                 .Register(registry);
  Family<Gauge>& operator_clients = BuildGauge().Name("crane_web_operator_clients")
                                        .Help("Connected clients logged in as an operator (may publish)").Register(registry);
  Family<Counter>& client_messages = BuildCounter().Name("crane_web_operator_messages_total")
                                         .Help("Goals and supervisor commands operators published to the bus")
                                         .Register(registry);
  std::vector<Counter*> received_of, rejected_of;
  std::vector<Gauge*> rate_of;
  std::vector<std::uint64_t> window_counts;
};

WebMetrics::WebMetrics(const std::vector<std::string>& topics) : impl_(std::make_unique<Impl>()) {
  if (topics.empty()) throw std::invalid_argument("WebMetrics: the topic list is empty");
  for (const auto& t : topics) {
    impl_->received_of.push_back(&impl_->received.Add({{"topic", t}}));
    impl_->rejected_of.push_back(&impl_->rejected.Add({{"topic", t}}));
    impl_->rate_of.push_back(&impl_->rate.Add({{"topic", t}}));
  }
  impl_->window_counts.assign(topics.size(), 0);
}

WebMetrics::~WebMetrics() = default;

void WebMetrics::sample(std::size_t topic_index) noexcept {
  if (topic_index >= impl_->received_of.size()) return;
  impl_->received_of[topic_index]->Increment();
  ++impl_->window_counts[topic_index];
}

void WebMetrics::nonfinite(std::size_t topic_index) noexcept {
  if (topic_index >= impl_->rejected_of.size()) return;
  impl_->received_of[topic_index]->Increment();
  impl_->rejected_of[topic_index]->Increment();
}

void WebMetrics::update_rates(double elapsed) noexcept {
  if (!(elapsed > 0.0)) return;
  for (std::size_t i = 0; i < impl_->rate_of.size(); ++i) {
    impl_->rate_of[i]->Set(static_cast<double>(impl_->window_counts[i]) / elapsed);
    impl_->window_counts[i] = 0;
  }
}

void WebMetrics::supervisor(const protocol::SupervisorStatus& status) {
  using S = protocol::SupervisorStatus;
  for (const auto& code : S::kCodes) {
    if (code.group == "MODE") {
      impl_->mode.Add({{"mode", std::string(code.name)}}).Set(status.mode == code.value ? 1.0 : 0.0);
    } else if (code.group == "FAULT") {
      const std::string name(code.name);
      impl_->fault_active.Add({{"fault", name}}).Set((status.active_faults & code.value) != 0 ? 1.0 : 0.0);
      impl_->fault_latched.Add({{"fault", name}}).Set((status.latched_faults & code.value) != 0 ? 1.0 : 0.0);
    }
  }
  impl_->faults_raised.Add({}).Set(static_cast<double>(status.fault_count));
  impl_->supervisor_nonfinite.Add({}).Set(static_cast<double>(status.nonfinite_rejected));
}

void WebMetrics::loop(const protocol::LoopDiagnostics& d) {
  const std::string process(protocol::code_name(protocol::LoopDiagnostics::kCodes, "PROCESS", d.process));
  impl_->cycles.Add({{"process", process}}).Set(static_cast<double>(d.cycles));
  impl_->overruns.Add({{"process", process}}).Set(static_cast<double>(d.overruns));
  impl_->process_nonfinite.Add({{"process", process}}).Set(static_cast<double>(d.nonfinite_rejected));
  impl_->latency.Add({{"process", process}, {"quantile", "0.5"}}).Set(d.latency_p50_us);
  impl_->latency.Add({{"process", process}, {"quantile", "0.99"}}).Set(d.latency_p99_us);
  impl_->latency.Add({{"process", process}, {"quantile", "1"}}).Set(d.latency_max_us);
}

std::string WebMetrics::text(const ServerStats* server) {
  if (server != nullptr) {
    impl_->clients.Add({}).Set(static_cast<double>(server->clients.load()));
    counter_to(impl_->connections.Add({}), static_cast<double>(server->connections_total.load()));
    counter_to(impl_->sent.Add({}), static_cast<double>(server->frames_sent.load()));
    counter_to(impl_->dropped.Add({}), static_cast<double>(server->frames_dropped.load()));
    counter_to(impl_->refused.Add({{"kind", "request"}}), static_cast<double>(server->bad_requests.load()));
    counter_to(impl_->refused.Add({{"kind", "binary"}}), static_cast<double>(server->binary_refused.load()));
    counter_to(impl_->refused.Add({{"kind", "handshake"}}), static_cast<double>(server->handshakes_refused.load()));
    counter_to(impl_->refused.Add({{"kind", "oversized"}}), static_cast<double>(server->oversized_closed.load()));
    counter_to(impl_->stalled.Add({}), static_cast<double>(server->stalled_closed.load()));
    impl_->operator_clients.Add({}).Set(static_cast<double>(server->operator_clients.load()));
    counter_to(impl_->client_messages.Add({}), static_cast<double>(server->client_messages.load()));
  }
  return prometheus::TextSerializer().Serialize(impl_->registry.Collect());
}

}  // namespace crane::web
