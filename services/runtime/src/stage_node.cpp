#include "crane/runtime/stage_node.hpp"

#include <spdlog/spdlog.h>

#include <chrono>

namespace crane::runtime {

CycleKind SequenceWatch::classify(std::uint64_t seq, LoopCounters& counters) noexcept {
  if (any_ && seq == last_) return has_answer_ && answered_ == seq ? CycleKind::repeat : CycleKind::stale;
  if (any_ && seq < last_) return CycleKind::stale;
  if (any_) counters.overruns += seq - last_ - 1;
  any_ = true;
  last_ = seq;
  counters.last_seq = seq;
  return CycleKind::new_cycle;
}

void record_latency(LatencyStatistics& latency, const msgs::CycleHeader_& header) noexcept {
  latency.record(static_cast<double>(now_nanoseconds() - to_nanoseconds(header.origin())) / 1000.0);
}

void record_latency(LatencyStatistics& latency, const protocol::CycleHeader& header) noexcept {
  builtin_interfaces::msg::dds_::Time_ origin;
  protocol::to_dds(header.origin, origin);
  latency.record(static_cast<double>(now_nanoseconds() - to_nanoseconds(origin)) / 1000.0);
}

int run_stage(int argc, char** argv, ProcessId process, const std::string& description,
              const std::function<void(CLI::App&)>& add_options,
              const std::function<std::function<void()>(StageContext&)>& setup) {
  CLI::App app{description};
  NodeOptions options;
  add_node_options(app, options);
  std::string wake = "listener";
  add_wake_option(app, wake);
  if (add_options) add_options(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  }
  const std::string name = process_name(process);
  try {
    configure_logging(options.log_level, name);
    const auto cfg = config::ConfigDocument::load(options.config_path);
    auto participant = make_participant(options, name);
    transport::Wakeup wakeup;
    install_stop_handlers(&wakeup);
    LoopCounters counters;
    LatencyStatistics latency;
    DiagnosticsPublisher diagnostics(*participant, process);
    StageContext context{cfg, *participant, wakeup, counters, latency};
    const auto poll = setup(context);
    spdlog::info("running on {} dds, domain {}", transport::vendor_name(participant->vendor()), options.domain_id);
    {
      ListenerDispatch dispatch(wakeup, poll, wake == "listener");
      while (!stop_requested()) {
        wakeup.wait_until(std::chrono::steady_clock::now() + std::chrono::milliseconds(5));
        dispatch.run([&] { diagnostics.maybe_publish(counters, &latency); });
      }
    }
    leave_realtime();
    diagnostics.publish_final(counters, &latency);
    spdlog::info("stopping: {} cycles, {} overruns, {} non-finite samples rejected, latency p50 {:.0f} us p99 {:.0f} us",
                 counters.cycles, counters.overruns, counters.nonfinite_rejected, latency.percentile(50),
                 latency.percentile(99));
  } catch (const std::exception& error) {
    spdlog::critical("{}", error.what());
    return 1;
  }
  return 0;
}

}  // namespace crane::runtime
