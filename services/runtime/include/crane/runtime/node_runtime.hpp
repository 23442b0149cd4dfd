#pragma once
// Plumbing shared by every process of the stack (the "thin node" side of STYLE.md habit 1):
// command-line options, signal handling, wall-clock stamps, latency statistics, loop diagnostics
// and the NaN/Inf gate at every topic entry. Nothing here is crane physics or control.

#include <array>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <exception>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "crane/protocol/dds.hpp"
#include "crane/protocol/messages.hpp"
#include "crane/transport/participant.hpp"
#include "crane/transport/topics.hpp"

namespace CLI {
class App;
}

namespace crane::runtime {

namespace msgs = crane_msgs::msg::dds_;

/// Process identifiers carried in LoopDiagnostics_.process (the IDL's PROCESS_* codes).
enum class ProcessId : std::uint8_t {
  plant = protocol::LoopDiagnostics::PROCESS_PLANT,
  hardware_bridge = protocol::LoopDiagnostics::PROCESS_HARDWARE_BRIDGE,
  state_estimator = protocol::LoopDiagnostics::PROCESS_STATE_ESTIMATOR,
  trajectory_planner = protocol::LoopDiagnostics::PROCESS_TRAJECTORY_PLANNER,
  anti_swing = protocol::LoopDiagnostics::PROCESS_ANTI_SWING,
  tracking = protocol::LoopDiagnostics::PROCESS_TRACKING,
  friction_compensation = protocol::LoopDiagnostics::PROCESS_FRICTION_COMPENSATION,
  supervisor = protocol::LoopDiagnostics::PROCESS_SUPERVISOR,
  operator_console = protocol::LoopDiagnostics::PROCESS_OPERATOR,
};
/// "plant", "state_estimator", ..., "operator" (the IDL's code names).
[[nodiscard]] const char* process_name(ProcessId id) noexcept;

/// Options every node accepts.
struct NodeOptions {
  std::string config_path;  // YAML configuration (deploy/config/*.yaml)
  std::string dds{};        // "fast" | "cyclone"; empty: CRANE_DDS, else fast
  std::uint32_t domain_id{0};
  bool loopback_only{true};
  bool shared_memory{true};  // false: UDP only when not loopback_only (crane_topic --lan)
  std::string dds_profile;   // network profile XML (deploy/dds/); empty: $CRANE_DDS_PROFILE, else none
  std::string log_level{"info"};
  int realtime_priority{0};  // > 0: SCHED_FIFO at this priority and memory locked, where the system allows
  std::string security_directory;  // DDS Security material (deploy/crane security init); empty: $CRANE_SECURITY,
                                   // else none (transport/security.hpp)
  std::string identity;            // identity in it; empty: the participant's name (tools: their role)
  bool insecure_lan{false};        // the network without security, said explicitly (else refused)
  bool iceoryx{false};             // the stack runs on iceoryx shared memory: on loopback the participant joins it
                                   // (transport::ParticipantOptions::iceoryx: Cyclone DDS, RouDi running), else it
                                   // speaks its QoS over UDP (add_iceoryx_option); never the site's domain
  transport::Liveliness liveliness{transport::Liveliness::dds};  // watchdogs: a participant off iceoryx that talks
                                   // to a stack on it (a launcher's own, a test's monitor; transport/qos.hpp)
};

/// Adds --config, --dds, --domain, --lan, --log-level, --dds-profile, --realtime-priority, --iceoryx
/// and the security options (add_security_options) to `app`, bound to `options`.
void add_node_options(CLI::App& app, NodeOptions& options);

/// Adds --iceoryx to `app` (every node, and the tools that read or write the stack's topics): the
/// stack runs on iceoryx shared memory. make_participant() then joins iceoryx on loopback, and speaks
/// the stack's QoS (transport::Liveliness::watchdogs) over UDP with --lan or a profile.
void add_iceoryx_option(CLI::App& app, NodeOptions& options);

/// Adds --security DIR, --identity NAME and --insecure-lan to `app` (every node and tool).
void add_security_options(CLI::App& app, NodeOptions& options);

/// A crane's process on a site (the supervisor's guard, the site link): adds --site-lan to `app`,
/// bound to `site_lan`: the site's domain on every interface while the crane's own domain keeps
/// what --lan says (loopback by default). A crane on a host of its own talks to the site over the
/// network, and its stack's 100 Hz traffic stays on its host (docs/site.md, "The site on its own
/// hosts").
void add_site_network_option(CLI::App& app, bool& site_lan);

/// The options of the participant on the site's domain `site_domain`: the crane's `options` on that
/// domain, on every interface when `site_lan` (else as the crane's own), never on iceoryx (the site
/// spans hosts; its guards rely on DDS liveliness and deadlines). The network rule
/// (check_network_security) applies to it when the participant is made.
[[nodiscard]] NodeOptions site_domain_options(NodeOptions options, std::uint32_t site_domain, bool site_lan);

/// The rule for the network: a participant that leaves the loopback interface (--lan or a
/// --dds-profile) needs --security, or --insecure-lan said explicitly. Throws std::invalid_argument
/// saying why otherwise; nothing on loopback. `security_directory` as resolved ($CRANE_SECURITY).
void check_network_security(bool loopback_only, const std::string& dds_profile, const std::string& security_directory,
                            bool insecure_lan);

/// Puts the calling process (and the threads it creates afterwards, DDS's among them) on SCHED_FIFO
/// at `priority` (1-99) and locks its memory (mlockall), as the systemd units ask. Returns an empty
/// string on success, else what failed and why (e.g. "SCHED_FIFO 70: Operation not permitted"); the
/// process then runs on at normal priority. `priority` <= 0: nothing, empty string.
std::string enter_realtime(int priority);

/// Puts every thread of the process back on SCHED_OTHER (a stopping process: the middleware's shutdown
/// is not written for real-time priority, and a thread of it spinning at SCHED_FIFO would starve
/// everything else on the cores). Never throws; nothing happens when the process never entered.
void leave_realtime() noexcept;

/// Puts the calling thread alone on SCHED_OTHER (a worker of a real-time stage that computes
/// outside the cycle, e.g. the planner's minimum-time solve: it must not starve the cycle's threads).
/// Never throws; nothing happens on a thread that is not SCHED_FIFO.
void leave_realtime_this_thread() noexcept;

/// Creates the participant for `options` (vendor resolved from --dds / CRANE_DDS); first enters
/// real time when options.realtime_priority > 0 (a warning in the log when it cannot).
/// With --security (or $CRANE_SECURITY) the participant uses identity options.identity, else `name`.
/// Throws std::invalid_argument on a bad vendor name or the network without security
/// (check_network_security), transport::SecurityError naming a bad security file,
/// std::runtime_error if DDS fails.
std::unique_ptr<transport::Participant> make_participant(const NodeOptions& options, const std::string& name);

/// The transport's options make_participant() creates the participant with: the profile from
/// $CRANE_DDS_PROFILE when options name none, the vendor from $CRANE_DDS when options.dds is empty,
/// the security folder from $CRANE_SECURITY; --iceoryx joins iceoryx on loopback without a
/// profile, else keeps the stack's QoS (Liveliness::watchdogs) over UDP. Throws
/// std::invalid_argument on a bad vendor name.
[[nodiscard]] transport::ParticipantOptions participant_options(const NodeOptions& options, const std::string& name);

/// The DDS Security material a participant of `options` uses: --security, else $CRANE_SECURITY,
/// else "" (none).
[[nodiscard]] std::string security_directory_of(const NodeOptions& options);

/// Applies --log-level to spdlog's default logger; throws std::invalid_argument on an unknown level.
void configure_logging(const std::string& level, const std::string& process);

/// Fault injection for tests: with CRANE_INJECT_LOSS="P:SEED" in the environment, true for a
/// fraction P of the calls (a generator seeded with SEED and the process id), and every reader of
/// the chain drops the sample it just took, as a lossy best-effort link would. Lockstep must give
/// the same run with it (docs/architecture.md). Unset or empty: always false. Throws
/// std::invalid_argument naming the variable on the first call when it is malformed or P is not
/// in [0, 0.5].
[[nodiscard]] bool injected_loss();

/// Adds --wake listener|thread to `app`, bound to `wake` ("listener" by default): where the chain's
/// nodes (the stages and the plant) run a cycle (ListenerDispatch).
void add_wake_option(CLI::App& app, std::string& wake);

/// A chain node's poll on the DDS listener thread that delivers its input
/// (transport::Wakeup::dispatch_on_notify): a hop of the 100 Hz chain costs one thread wake-up (the
/// vendor's receive thread) instead of two (it, then the node's thread; docs/integration.md, "One
/// wake-up per hop"). The node's own thread keeps its timer work (a poll at least every few
/// milliseconds, re-offers, diagnostics) through run(), never at the same time as the poll. With
/// `on_listener` false, or `wake` "thread", the poll runs only through run(), after the node's
/// thread is woken. The poll must not block (a DDS listener thread held holds the participant's
/// traffic) and is called with nothing else of the node running; an exception it throws on a
/// listener thread stops further calls and is rethrown by the next run().
class ListenerDispatch {
 public:
  ListenerDispatch(transport::Wakeup& wakeup, std::function<void()> poll, bool on_listener);
  ~ListenerDispatch();  // ends the dispatch (waits for a poll in progress)
  ListenerDispatch(const ListenerDispatch&) = delete;
  ListenerDispatch& operator=(const ListenerDispatch&) = delete;
  /// On the node's thread: the poll, then `timer_work`, serialized with the listener's polls.
  /// Rethrows what a poll or `timer_work` threw (on either thread). Allocates nothing.
  template <class TimerWork>
  void run(TimerWork&& timer_work) {
    std::exception_ptr failure;
    wakeup_.run_exclusive([&] {
      guarded_poll();
      if (!failure_) {
        try {
          timer_work();
        } catch (...) {
          failure_ = std::current_exception();
        }
      }
      failure = failure_;
    });
    if (failure) {
      wakeup_.stop_dispatch();
      std::rethrow_exception(failure);
    }
  }

 private:
  void guarded_poll() noexcept;
  transport::Wakeup& wakeup_;
  std::function<void()> poll_;
  std::exception_ptr failure_;  // guarded by the wakeup's exclusion
};

/// SIGINT/SIGTERM set a flag (async-signal-safe) and wake the given Wakeup.
void install_stop_handlers(transport::Wakeup* wakeup);
[[nodiscard]] bool stop_requested() noexcept;

/// Wall-clock (CLOCK_REALTIME) stamps for message headers.
[[nodiscard]] builtin_interfaces::msg::dds_::Time_ now_stamp() noexcept;
[[nodiscard]] std::int64_t to_nanoseconds(const builtin_interfaces::msg::dds_::Time_& stamp) noexcept;
[[nodiscard]] std::int64_t now_nanoseconds() noexcept;

/// A MoveRequest_ id above every id a client took before (the planner ignores an id not above the
/// last it took): tenths of a second since 2025-01-01, from the wall clock. A client that sends
/// several goals counts up from it, and stays below a later client's first id as long as it sends
/// fewer than ten a second on average. Good for 13 years in 32 bits.
[[nodiscard]] std::uint32_t fresh_request_id() noexcept;

/// Fills header.stamp = now, header.seq, header.origin.
void stamp_header(msgs::CycleHeader_& header, std::uint64_t seq, const builtin_interfaces::msg::dds_::Time_& origin) noexcept;

/// Latency statistics over a sliding window, with all storage sized at construction: record() and
/// percentile() never allocate. percentile() is O(window) (nth_element on a scratch copy), about
/// 20 us for the default 4096-sample window (41 s at 100 Hz).
class LatencyStatistics {
 public:
  explicit LatencyStatistics(std::size_t capacity = 4096);
  void record(double microseconds) noexcept;
  [[nodiscard]] std::uint64_t count() const noexcept { return count_; }
  /// p in [0, 100] over the last `capacity` samples (nearest rank); 0 when empty.
  [[nodiscard]] double percentile(double p) const noexcept;
  /// Largest sample since construction.
  [[nodiscard]] double maximum() const noexcept { return maximum_; }

 private:
  std::vector<double> window_;
  mutable std::vector<double> scratch_;
  std::size_t next_{0};
  std::uint64_t count_{0};
  double maximum_{0.0};
};

/// Counters every node keeps and publishes once per second on rt/crane/diag/loop.
struct LoopCounters {
  std::uint64_t cycles{0};
  std::uint64_t overruns{0};
  std::uint64_t nonfinite_rejected{0};
  std::uint64_t last_seq{0};
};

class DiagnosticsPublisher {
 public:
  DiagnosticsPublisher(transport::Participant& participant, ProcessId process);
  /// Publishes if at least one second passed since the last publication.
  void maybe_publish(const LoopCounters& counters, const LatencyStatistics* latency);
  /// Publishes now.
  void publish(const LoopCounters& counters, const LatencyStatistics* latency);
  /// Publishes once more on the way out and gives the best-effort sample 100 ms to be delivered
  /// before the participant is destroyed, so the last figures are not lost.
  void publish_final(const LoopCounters& counters, const LatencyStatistics* latency);

 private:
  ProcessId process_;
  std::uint8_t vendor_;
  std::unique_ptr<transport::Writer<transport::topics::LoopDiagnostics>> writer_;
  std::chrono::steady_clock::time_point next_;
};

/// NaN/Inf gate at the entry of each topic: true when every floating-point field of the DDS
/// message `m` (arrays and nested structs included) is finite. The checks are generated from the
/// IDL (crane::protocol::all_finite, idl/tools/gen_protocol.py); this converts `m` to its plain
/// struct on the stack first (no allocation, no lock). Any fastddsgen message type of the IDL.
template <class DdsMessage>
  requires requires { typename protocol::PlainOf<DdsMessage>::type; }
[[nodiscard]] bool all_finite(const DdsMessage& m) noexcept {
  typename protocol::PlainOf<DdsMessage>::type plain;
  protocol::from_dds(m, plain);
  return protocol::all_finite(plain);
}

}  // namespace crane::runtime
