#pragma once
// The skeleton every data-driven stage process shares: parse options, open the configuration,
// open the participant, then loop: wait for a wake-up (data or status change, at most 5 ms apart),
// let the node poll its readers, publish diagnostics once a second; stop cleanly on SIGINT/SIGTERM.
// The poll runs on the DDS listener thread that brings the input (runtime::ListenerDispatch; --wake
// thread: only on the node's thread) and, every 5 ms, on the node's own thread; never two at once.
// It must not block: work that may take long (the planner's solve) goes to a thread of its own.
//
// A node only translates: DDS samples to the protocol's plain structs (take_plain), its stage
// object's step(), the output back to DDS (write_plain). The stage runs when the inputs of cycle k
// have arrived (not on a timer of its own), its output carries seq = k and the origin of sensor
// sample k, and the node counts as an overrun every cycle whose inputs it never saw complete (a
// jump in seq).

#include <CLI/CLI.hpp>
#include <functional>
#include <string>

#include "crane/config/config_document.hpp"
#include "crane/protocol/dds.hpp"
#include "crane/runtime/node_runtime.hpp"

namespace crane::runtime {

struct StageContext {
  const config::ConfigDocument& config;  // read your own blocks: config.read("tracking", tracking::read_params)
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

/// take_finite into the plain protocol struct (crane/protocol/messages.hpp) of the topic's message.
template <class ReaderT, class Plain>
bool take_plain(ReaderT& reader, Plain& plain, LoopCounters& counters) noexcept {
  typename std::remove_reference_t<decltype(reader)>::Message message;
  if (!take_finite(reader, message, counters)) return false;
  protocol::from_dds(message, plain);
  return true;
}

/// Writes `plain` (its header stamped now; seq and origin as they are) as the topic's message.
template <class WriterT, class Plain>
bool write_plain(WriterT& writer, const Plain& plain) noexcept {
  typename std::remove_reference_t<decltype(writer)>::Message message;
  protocol::to_dds(plain, message);
  message.header().stamp(now_stamp());
  return writer.write(message);
}

/// Records (now - origin) of a header in microseconds.
void record_latency(LatencyStatistics& latency, const msgs::CycleHeader_& header) noexcept;
void record_latency(LatencyStatistics& latency, const protocol::CycleHeader& header) noexcept;

/// Runs a stage process. `add_options` may add stage-specific options to the command line;
/// `setup` creates readers/writers and returns the poll function called after every wake-up.
/// Returns the process exit code (0 on a clean stop, 1 on a configuration or DDS error, which is
/// logged with its message).
int run_stage(int argc, char** argv, ProcessId process, const std::string& description,
              const std::function<void(CLI::App&)>& add_options,
              const std::function<std::function<void()>(StageContext&)>& setup);

}  // namespace crane::runtime
