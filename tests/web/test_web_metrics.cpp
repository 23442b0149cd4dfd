// crane_web's /metrics (deploy/web/web_metrics.hpp): what the bus says, in the Prometheus text
// format, line by line.
#include <gtest/gtest.h>

#include <string>

#include "crane/web/foxglove_server.hpp"
#include "crane/web/web_metrics.hpp"

namespace {

using namespace crane;

bool has_line(const std::string& text, const std::string& line) {
  return text.find("\n" + line + "\n") != std::string::npos;
}

TEST(WebMetrics, CountsRatesSupervisorProcessesAndServer) {
  web::WebMetrics metrics({"rt/a", "rt/b"});
  for (int i = 0; i < 50; ++i) metrics.sample(0);
  metrics.nonfinite(1);
  metrics.sample(7);  // out of range: ignored
  metrics.update_rates(0.5);  // 50 samples in 0.5 s: 100 Hz; 0 finite samples of rt/b: 0 Hz

  protocol::SupervisorStatus status;
  status.mode = protocol::SupervisorStatus::MODE_FAULT;
  status.active_faults = protocol::SupervisorStatus::FAULT_SWING;
  status.latched_faults = protocol::SupervisorStatus::FAULT_SWING | protocol::SupervisorStatus::FAULT_VOLTAGE;
  status.fault_count = 3;
  metrics.supervisor(status);

  protocol::LoopDiagnostics plant;
  plant.process = protocol::LoopDiagnostics::PROCESS_PLANT;
  plant.cycles = 1234;
  plant.overruns = 2;
  plant.latency_p99_us = 1420.5;
  metrics.loop(plant);

  web::ServerStats server;
  server.clients = 3;
  server.frames_dropped = 17;
  server.bad_requests = 4;
  server.stalled_closed = 1;
  const std::string text = "\n" + metrics.text(&server);

  EXPECT_TRUE(has_line(text, R"(crane_topic_samples_received_total{topic="rt/a"} 50)")) << text;
  EXPECT_TRUE(has_line(text, R"(crane_topic_samples_received_total{topic="rt/b"} 1)"));
  EXPECT_TRUE(has_line(text, R"(crane_topic_nonfinite_rejected_total{topic="rt/b"} 1)"));
  EXPECT_TRUE(has_line(text, R"(crane_topic_rate_hz{topic="rt/a"} 100)"));
  EXPECT_TRUE(has_line(text, R"(crane_topic_rate_hz{topic="rt/b"} 0)"));
  EXPECT_TRUE(has_line(text, R"(crane_supervisor_mode{mode="fault"} 1)"));
  EXPECT_TRUE(has_line(text, R"(crane_supervisor_mode{mode="ready"} 0)"));
  EXPECT_TRUE(has_line(text, R"(crane_supervisor_fault_active{fault="swing"} 1)"));
  EXPECT_TRUE(has_line(text, R"(crane_supervisor_fault_active{fault="voltage"} 0)"));
  EXPECT_TRUE(has_line(text, R"(crane_supervisor_fault_latched{fault="voltage"} 1)"));
  EXPECT_TRUE(has_line(text, "crane_supervisor_faults_raised 3"));
  EXPECT_TRUE(has_line(text, R"(crane_process_cycles{process="plant"} 1234)"));
  EXPECT_TRUE(has_line(text, R"(crane_process_overruns{process="plant"} 2)"));
  EXPECT_TRUE(has_line(text, R"(crane_process_latency_us{process="plant",quantile="0.99"} 1420.5)"));
  EXPECT_TRUE(has_line(text, "crane_web_clients 3"));
  EXPECT_TRUE(has_line(text, "crane_web_samples_dropped_total 17"));
  EXPECT_TRUE(has_line(text, R"(crane_web_requests_refused_total{kind="request"} 4)"));
  EXPECT_TRUE(has_line(text, "crane_web_stalled_clients_closed_total 1"));
  EXPECT_NE(text.find("# TYPE crane_web_samples_dropped_total counter"), std::string::npos);

  // Counters follow the server's counts up, never down.
  server.frames_dropped = 20;
  EXPECT_TRUE(has_line("\n" + metrics.text(&server), "crane_web_samples_dropped_total 20"));
  EXPECT_THROW(web::WebMetrics({}), std::invalid_argument);
}

}  // namespace
