#include "crane/runtime/node_runtime.hpp"

#include <spdlog/spdlog.h>
#include <sched.h>
#include <sys/mman.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <system_error>

#include <cstdlib>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <csignal>
#include <ctime>
#include <random>
#include <string>
#include <stdexcept>
#include <thread>

namespace crane::runtime {

const char* process_name(ProcessId id) noexcept {
  return protocol::code_name(protocol::LoopDiagnostics::kCodes, "PROCESS", static_cast<std::uint64_t>(id)).data();
}

void add_node_options(CLI::App& app, NodeOptions& options) {
  app.add_option("--config", options.config_path, "crane configuration (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--dds", options.dds, "DDS vendor: fast | cyclone (default: $CRANE_DDS, else fast)");
  app.add_option("--domain", options.domain_id, "DDS domain id")->check(CLI::Range(0, 232));
  app.add_flag_callback(
      "--lan", [&options] { options.loopback_only = false; },
      "let DDS use every interface (default: loopback 127.0.0.1 only, unicast discovery)");
  app.add_option("--log-level", options.log_level, "trace | debug | info | warn | error");
  app.add_option("--dds-profile", options.dds_profile,
                 "network profile (deploy/dds/*.xml; default: $CRANE_DDS_PROFILE): replaces loopback/--lan")
      ->check(CLI::ExistingFile);
  app.add_option("--realtime-priority", options.realtime_priority,
                 "SCHED_FIFO priority (1-99) and locked memory, where the system allows it (0: normal priority)")
      ->check(CLI::Range(0, 99));
  add_iceoryx_option(app, options);
  add_security_options(app, options);
}

void add_iceoryx_option(CLI::App& app, NodeOptions& options) {
  app.add_flag("--iceoryx", options.iceoryx,
               "the stack runs on iceoryx shared memory (its launcher's --iceoryx): join it there (Cyclone DDS, "
               "its RouDi running; RouDi ends this process when it stops), or with --lan or a profile speak its "
               "QoS over UDP");
}

void add_security_options(CLI::App& app, NodeOptions& options) {
  app.add_option("--security", options.security_directory,
                 "DDS Security material (deploy/crane security init; default: $CRANE_SECURITY): authenticated, "
                 "access-controlled and encrypted DDS")
      ->check(CLI::ExistingDirectory);
  app.add_option("--identity", options.identity,
                 "identity in the --security folder (default: this process's own, or the tool's role)");
  app.add_flag("--insecure-lan", options.insecure_lan,
               "allow --lan or a --dds-profile without --security: anyone on that network can read and command "
               "the crane");
}

void add_site_network_option(CLI::App& app, bool& site_lan) {
  app.add_flag("--site-lan", site_lan,
               "the site's domain on every interface (the crane's own stays on loopback unless --lan): a crane on a "
               "host of its own");
}

NodeOptions site_domain_options(NodeOptions options, std::uint32_t site_domain, bool site_lan) {
  options.domain_id = site_domain;
  options.iceoryx = false;
  options.liveliness = transport::Liveliness::dds;
  if (site_lan) options.loopback_only = false;
  return options;
}

void check_network_security(bool loopback_only, const std::string& dds_profile, const std::string& security_directory,
                            bool insecure_lan) {
  if ((loopback_only && dds_profile.empty()) || !security_directory.empty() || insecure_lan) return;
  throw std::invalid_argument(
      std::string(dds_profile.empty() ? "--lan" : "--dds-profile " + dds_profile) +
      " without --security: every participant on that network could read the sensors and write goals and "
      "supervisor commands, with nothing to authenticate it. Give --security DIR (deploy/crane security init), "
      "or --insecure-lan to run unprotected on purpose");
}

std::string enter_realtime(int priority) {
  if (priority <= 0) return {};
  sched_param param{};
  param.sched_priority = priority;
  if (sched_setscheduler(0, SCHED_FIFO, &param) != 0) {
    return "SCHED_FIFO " + std::to_string(priority) + ": " + std::strerror(errno);
  }
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    return "SCHED_FIFO " + std::to_string(priority) + " set, but mlockall: " + std::strerror(errno);
  }
  return {};
}

void leave_realtime() noexcept {
  if (sched_getscheduler(0) != SCHED_FIFO) return;
  sched_param normal{};
  normal.sched_priority = 0;
  std::error_code error;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", error)) {
    const auto tid = static_cast<pid_t>(std::strtol(task.path().filename().c_str(), nullptr, 10));
    if (tid > 0) (void)sched_setscheduler(tid, SCHED_OTHER, &normal);
  }
}

void leave_realtime_this_thread() noexcept {
  if (sched_getscheduler(0) != SCHED_FIFO) return;
  sched_param normal{};
  normal.sched_priority = 0;
  (void)sched_setscheduler(0, SCHED_OTHER, &normal);  // 0: the calling thread (Linux: per thread)
}

std::unique_ptr<transport::Participant> make_participant(const NodeOptions& options, const std::string& name) {
  (void)injected_loss();  // a malformed CRANE_INJECT_LOSS is refused here, at start
  if (options.realtime_priority > 0) {
    const auto failure = enter_realtime(options.realtime_priority);
    if (failure.empty()) {
      spdlog::info("real time: SCHED_FIFO priority {}, memory locked", options.realtime_priority);
    } else {
      spdlog::warn("real time not available ({}): running at normal priority", failure);
    }
  }
  const transport::ParticipantOptions p = participant_options(options, name);
  check_network_security(p.loopback_only, p.profile_file, p.security_directory, options.insecure_lan);
  if (!p.security_directory.empty()) {
    spdlog::info("DDS Security: identity '{}' of {}", p.identity.empty() ? name : p.identity, p.security_directory);
  }
  return std::make_unique<transport::Participant>(p);
}

transport::ParticipantOptions participant_options(const NodeOptions& options, const std::string& name) {
  transport::ParticipantOptions p;
  p.name = name;
  p.domain_id = options.domain_id;
  p.loopback_only = options.loopback_only;
  p.shared_memory = options.shared_memory;
  p.profile_file = options.dds_profile;
  if (p.profile_file.empty()) {
    if (const char* env = std::getenv("CRANE_DDS_PROFILE"); env != nullptr) p.profile_file = env;
  }
  // --iceoryx: the stack runs on iceoryx. On its machine a process joins it there; over the network
  // (--lan, a profile) it speaks that stack's QoS over UDP.
  p.iceoryx = options.iceoryx && p.loopback_only && p.profile_file.empty();
  p.liveliness = options.iceoryx ? transport::Liveliness::watchdogs : options.liveliness;
  p.vendor = options.dds.empty() ? transport::vendor_from_environment() : transport::parse_vendor(options.dds);
  p.security_directory = security_directory_of(options);
  p.identity = options.identity;
  return p;
}

std::string security_directory_of(const NodeOptions& options) {
  if (!options.security_directory.empty()) return options.security_directory;
  const char* env = std::getenv("CRANE_SECURITY");
  return env != nullptr ? env : "";
}

void configure_logging(const std::string& level, const std::string& process) {
  const auto parsed = spdlog::level::from_str(level);
  if (parsed == spdlog::level::off && level != "off") {
    throw std::invalid_argument("--log-level '" + level + "' is not known");
  }
  spdlog::set_level(parsed);
  spdlog::set_pattern("[%H:%M:%S.%e] [" + process + "] [%^%l%$] %v");
}

namespace {
std::atomic<bool> g_stop{false};
std::atomic<transport::Wakeup*> g_wakeup{nullptr};
extern "C" void on_stop_signal(int) {
  g_stop.store(true);
  // Wakeup::notify takes a mutex; instead of calling it from the handler a watcher thread would be
  // cleaner, but every loop also wakes at least every few milliseconds, so the flag is enough.
}
}  // namespace

bool injected_loss() {
  struct Loss {
    double probability{0.0};
    std::mt19937_64 generator;
  };
  static Loss loss = [] {
    Loss l;
    const char* text = std::getenv("CRANE_INJECT_LOSS");
    if (text == nullptr || *text == '\0') return l;
    const std::string value(text);
    const auto colon = value.find(':');
    char* end = nullptr;
    const double p = std::strtod(value.c_str(), &end);
    if (colon == std::string::npos || end != value.c_str() + colon || !(p >= 0.0 && p <= 0.5)) {
      throw std::invalid_argument("CRANE_INJECT_LOSS = '" + value + "' must be P:SEED with P in [0, 0.5]");
    }
    const auto seed = std::strtoull(value.c_str() + colon + 1, nullptr, 10);
    l.probability = p;
    l.generator.seed(seed ^ (static_cast<std::uint64_t>(getpid()) << 20));
    return l;
  }();
  if (loss.probability <= 0.0) return false;
  return std::uniform_real_distribution<double>(0.0, 1.0)(loss.generator) < loss.probability;
}

void install_stop_handlers(transport::Wakeup* wakeup) {
  g_wakeup.store(wakeup);
  struct sigaction action {};
  action.sa_handler = on_stop_signal;
  sigemptyset(&action.sa_mask);
  sigaction(SIGINT, &action, nullptr);
  sigaction(SIGTERM, &action, nullptr);
}

bool stop_requested() noexcept { return g_stop.load(); }

void add_wake_option(CLI::App& app, std::string& wake) {
  app.add_option("--wake", wake,
                 "listener: a cycle runs on the DDS listener thread that delivers its input (one thread wake-up "
                 "per hop, the default); thread: on the node's own thread, which the listener wakes (two)")
      ->check(CLI::IsMember({"listener", "thread"}));
}

ListenerDispatch::ListenerDispatch(transport::Wakeup& wakeup, std::function<void()> poll, bool on_listener)
    : wakeup_(wakeup), poll_(std::move(poll)) {
  if (on_listener) wakeup_.dispatch_on_notify([this] { guarded_poll(); });
}

ListenerDispatch::~ListenerDispatch() { wakeup_.stop_dispatch(); }

void ListenerDispatch::guarded_poll() noexcept {
  if (failure_) return;
  try {
    poll_();
  } catch (...) {
    failure_ = std::current_exception();
  }
}

std::uint32_t fresh_request_id() noexcept {
  const auto now = std::chrono::system_clock::now().time_since_epoch();
  const auto tenths = std::chrono::duration_cast<std::chrono::milliseconds>(now).count() / 100 - 17356896000LL;
  return static_cast<std::uint32_t>(std::max<long long>(tenths, 1));
}

builtin_interfaces::msg::dds_::Time_ now_stamp() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_REALTIME, &ts);
  builtin_interfaces::msg::dds_::Time_ t;
  t.sec(static_cast<int32_t>(ts.tv_sec));
  t.nanosec(static_cast<uint32_t>(ts.tv_nsec));
  return t;
}

std::int64_t to_nanoseconds(const builtin_interfaces::msg::dds_::Time_& stamp) noexcept {
  return static_cast<std::int64_t>(stamp.sec()) * 1000000000LL + static_cast<std::int64_t>(stamp.nanosec());
}

std::int64_t now_nanoseconds() noexcept { return to_nanoseconds(now_stamp()); }

void stamp_header(msgs::CycleHeader_& header, std::uint64_t seq,
                  const builtin_interfaces::msg::dds_::Time_& origin) noexcept {
  header.stamp(now_stamp());
  header.seq(seq);
  header.origin(origin);
}

LatencyStatistics::LatencyStatistics(std::size_t capacity)
    : window_(std::max<std::size_t>(capacity, 1)), scratch_(window_.size()) {}

void LatencyStatistics::record(double microseconds) noexcept {
  window_[next_] = microseconds;
  next_ = (next_ + 1) % window_.size();
  ++count_;
  maximum_ = std::max(maximum_, microseconds);
}

double LatencyStatistics::percentile(double p) const noexcept {
  const std::size_t n = static_cast<std::size_t>(std::min<std::uint64_t>(count_, window_.size()));
  if (n == 0) return 0.0;
  std::copy_n(window_.begin(), n, scratch_.begin());
  const double rank = std::clamp(p, 0.0, 100.0) / 100.0 * static_cast<double>(n - 1);
  const auto nth = scratch_.begin() + static_cast<std::ptrdiff_t>(std::lround(rank));
  std::nth_element(scratch_.begin(), nth, scratch_.begin() + static_cast<std::ptrdiff_t>(n));
  return *nth;
}

DiagnosticsPublisher::DiagnosticsPublisher(transport::Participant& participant, ProcessId process)
    : process_(process),
      vendor_(static_cast<std::uint8_t>(participant.vendor())),
      writer_(participant.make_writer<transport::topics::LoopDiagnostics>()),
      next_(std::chrono::steady_clock::now() + std::chrono::seconds(1)) {}

void DiagnosticsPublisher::maybe_publish(const LoopCounters& counters, const LatencyStatistics* latency) {
  const auto now = std::chrono::steady_clock::now();
  if (now < next_) return;
  publish(counters, latency);
}

void DiagnosticsPublisher::publish_final(const LoopCounters& counters, const LatencyStatistics* latency) {
  publish(counters, latency);
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
}

void DiagnosticsPublisher::publish(const LoopCounters& counters, const LatencyStatistics* latency) {
  next_ = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  msgs::LoopDiagnostics_ d;
  stamp_header(d.header(), counters.last_seq, now_stamp());
  d.process(static_cast<std::uint8_t>(process_));
  d.dds_vendor(vendor_);
  d.pid(static_cast<std::uint32_t>(getpid()));
  d.cycles(counters.cycles);
  d.overruns(counters.overruns);
  d.nonfinite_rejected(counters.nonfinite_rejected);
  if (latency != nullptr) {
    d.latency_p50_us(latency->percentile(50.0));
    d.latency_p99_us(latency->percentile(99.0));
    d.latency_max_us(latency->maximum());
  }
  writer_->write(d);
}

}  // namespace crane::runtime
