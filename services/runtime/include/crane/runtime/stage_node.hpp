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

/// What the inputs of a cycle are to a stage (SequenceWatch::classify).
enum class CycleKind : std::uint8_t {
  new_cycle,  // a cycle after any seen: compute it once, then answered(seq)
  repeat,     // the cycle last answered, offered again (lockstep re-offer, docs/architecture.md): send
              // the stored output again, stamped anew, without stepping the core
  stale,      // older than the last cycle, or a repeat of a cycle never answered: ignore
};

/// Lockstep's rule that every stage computes each cycle exactly once, in one place: the plant
/// re-offers a cycle until the chain answers it, and every stage answers a re-offered cycle from
/// its stored output. Also counts cycles skipped between consecutive new cycles as overruns.
class SequenceWatch {
 public:
  /// Classifies the cycle `seq` of a complete set of inputs; adds skipped cycles to overruns and
  /// sets counters.last_seq for a new cycle.
  [[nodiscard]] CycleKind classify(std::uint64_t seq, LoopCounters& counters) noexcept;
  /// The stage computed cycle `seq` and stored its output: a repeat of `seq` is answered from it.
  void answered(std::uint64_t seq) noexcept {
    answered_ = seq;
    has_answer_ = true;
  }

 private:
  bool any_{false};
  std::uint64_t last_{0};
  bool has_answer_{false};
  std::uint64_t answered_{0};
};

/// The NaN/Inf gate at a topic's entry: takes the next sample whose every floating-point field is
/// finite into `message` (true), counting and dropping the others; false when none is waiting.
template <class ReaderT, class Message>
bool take_finite(ReaderT& reader, Message& message, LoopCounters& counters) noexcept {
  while (reader.take_next(message)) {
    if (injected_loss()) continue;  // tests only (CRANE_INJECT_LOSS): a lost sample
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
