#pragma once
// The skeleton every data-driven stage shares: parse options, load the configuration, open the
// participant, then loop: wait for a wake-up (data or status change, at most `idle` apart), let the
// stage poll its readers, publish diagnostics once a second; stop cleanly on SIGINT/SIGTERM.
//
// Stages run when the inputs of cycle k have arrived (not on a timer of their own), stamp their
// output with seq = k and the origin of sensor sample k, and count as an overrun every cycle whose
// inputs they never saw complete (a jump in seq).

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "crane/config/stack_config.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/runtime/translate.hpp"

namespace crane::runtime {

struct StageContext {
  const config::StackConfig& config;
  transport::Participant& participant;
  transport::Wakeup& wakeup;
  LoopCounters& counters;
  LatencyStatistics& latency;  // this stage: origin of the sensor sample -> its own output written
};

/// Counts cycles skipped between consecutive sequence numbers.
class SequenceWatch {
 public:
  /// Returns true if `seq` is a new cycle (greater than any seen); adds skipped cycles to overruns.
  bool advance(std::uint64_t seq, LoopCounters& counters) noexcept;

 private:
  bool any_{false};
  std::uint64_t last_{0};
};

/// The NaN/Inf gate at a topic's entry: takes the next sample whose every floating-point field is
/// finite into `message` (true), counting and dropping the others; false when none is waiting.
template <class ReaderT, class Message>
bool take_finite(ReaderT& reader, Message& message, LoopCounters& counters) noexcept {
  while (reader.take_next(message)) {
    if (all_finite(message)) return true;
    ++counters.nonfinite_rejected;
  }
  return false;
}

/// Records (now - origin) of a header in microseconds.
void record_latency(LatencyStatistics& latency, const msgs::CycleHeader_& header) noexcept;

/// Runs a stage process. `add_options` may add stage-specific options to the command line;
/// `setup` creates readers/writers and returns the poll function called after every wake-up.
/// Returns the process exit code (0 on a clean stop, 1 on a configuration or DDS error, which is
/// logged with its message).
int run_stage(int argc, char** argv, ProcessId process, const std::string& description,
              const std::function<void(CLI::App&)>& add_options,
              const std::function<std::function<void()>(StageContext&)>& setup);

}  // namespace crane::runtime
