#include "crane/transport/participant.hpp"

#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>

#include "crane/transport/iceoryx_rule.hpp"

namespace crane::transport {

Vendor parse_vendor(std::string_view text) {
  if (text == "fast" || text == "fastdds" || text == "fast_dds") return Vendor::fast_dds;
  if (text == "cyclone" || text == "cyclonedds" || text == "cyclone_dds") return Vendor::cyclone_dds;
  throw std::invalid_argument("dds vendor '" + std::string(text) + "' is not known: must be 'fast' or 'cyclone'");
}

Vendor vendor_from_environment() {
  const char* value = std::getenv("CRANE_DDS");
  if (value == nullptr || *value == '\0') return Vendor::fast_dds;
  return parse_vendor(value);
}

const char* vendor_name(Vendor vendor) noexcept {
  switch (vendor) {
    case Vendor::fast_dds: return "fast";
    case Vendor::cyclone_dds: return "cyclone";
  }
  return "unknown";
}

std::string profile_for_vendor(const std::string& path, Vendor vendor) {
  if (path.empty()) return path;
  const std::filesystem::path file(path);
  const std::string name = file.filename().string();
  const std::string want = vendor == Vendor::fast_dds ? "fastdds_" : "cyclone_";
  const std::string other = vendor == Vendor::fast_dds ? "cyclone_" : "fastdds_";
  if (name.rfind(want, 0) == 0 || name.rfind(other, 0) != 0) return path;
  const std::filesystem::path counterpart = file.parent_path() / (want + name.substr(other.size()));
  if (!std::filesystem::exists(counterpart)) {
    throw std::invalid_argument("network profile " + path + " is for the other vendor and " + counterpart.string() +
                                " (its " + vendor_name(vendor) + " counterpart) does not exist");
  }
  return counterpart.string();
}

void Wakeup::notify() noexcept {
  if (dispatching_.load(std::memory_order_acquire)) {
    dispatch_pending_.store(true, std::memory_order_release);
    run_pending_dispatch();
    return;
  }
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = true;
  }
  condition_.notify_one();
}

bool Wakeup::wait_until(std::chrono::steady_clock::time_point deadline) {
  std::unique_lock<std::mutex> lock(mutex_);
  const bool notified = condition_.wait_until(lock, deadline, [this] { return pending_; });
  pending_ = false;
  return notified;
}

void Wakeup::run_pending_dispatch() noexcept {
  // Whoever holds the mutex handles every notify() made before it lets go: a notify() that finds
  // the mutex held leaves its flag for the holder, who looks again after unlocking.
  while (dispatch_pending_.load(std::memory_order_acquire)) {
    std::unique_lock<std::mutex> lock(dispatch_mutex_, std::try_to_lock);
    if (!lock.owns_lock()) return;
    while (dispatch_pending_.exchange(false, std::memory_order_acq_rel)) {
      if (dispatch_) dispatch_();
    }
  }
}

void Wakeup::dispatch_on_notify(std::function<void()> handler) {
  std::lock_guard<std::mutex> lock(dispatch_mutex_);
  dispatch_ = std::move(handler);
  dispatching_.store(static_cast<bool>(dispatch_), std::memory_order_release);
}

void Wakeup::stop_dispatch() {
  std::lock_guard<std::mutex> lock(dispatch_mutex_);
  dispatching_.store(false, std::memory_order_release);
  dispatch_ = nullptr;
}

Participant::Participant(const ParticipantOptions& options) : options_(options) {
  options_.profile_file = profile_for_vendor(options.profile_file, options.vendor);
  if (options_.iceoryx) {
    const std::string refusal = iceoryx_refusal(options_.vendor == Vendor::cyclone_dds, vendor_name(options_.vendor),
                                                !options_.loopback_only, options_.profile_file, options_.security_directory);
    if (!refusal.empty()) throw std::invalid_argument(refusal);
  }
  std::optional<SecurityFiles> security;
  if (!options_.security_directory.empty()) {
    if (options_.identity.empty()) options_.identity = options_.name;
    security = security_files(options_.security_directory, options_.identity);
  }
  const SecurityFiles* files = security ? &*security : nullptr;
  switch (options.vendor) {
    case Vendor::fast_dds:
      backend_ = detail::make_fast_dds_backend(options_, files);
      break;
    case Vendor::cyclone_dds:
      backend_ = detail::make_cyclone_dds_backend(options_, files);
      break;
  }
}

Participant::~Participant() = default;

}  // namespace crane::transport
