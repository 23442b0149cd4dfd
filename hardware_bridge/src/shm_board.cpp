#include "crane/hardware_bridge/shm_board.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <new>
#include <sstream>
#include <system_error>
#include <thread>
#include <utility>

#include "crane/common/validation.hpp"

namespace crane::hardware_bridge {

namespace {

using Clock = std::chrono::steady_clock;

// A seqlock reader gives up after this long with the sequence odd or changing: the writer died
// mid-update (a live writer holds it odd for well under a microsecond).
constexpr std::chrono::milliseconds kSeqlockGiveUp{10};
constexpr int kSeqlockSpinsBeforeClock = 64;
constexpr std::size_t kMaxNameLength = 200;
constexpr std::uint32_t kDigitalOutputMask = (1U << kDigitalOutputCount) - 1U;

std::string system_error_text(int error) { return std::generic_category().message(error); }

[[noreturn]] void fail(const std::string& path, const std::string& what) {
  throw BoardError("shared-memory board " + path + ": " + what);
}

std::string hex(std::uint32_t value) {
  char buffer[16];
  std::snprintf(buffer, sizeof(buffer), "0x%08x", value);
  return buffer;
}

// Seqlock (Boehm, "Can seqlocks get along with programming language memory models?", 2012):
// the writer makes the sequence odd, stores the data (relaxed), makes it even again (release); the
// reader retries until it saw the same even sequence before and after its (relaxed) loads.
void begin_write(std::atomic<std::uint64_t>& sequence) noexcept {
  const std::uint64_t current = sequence.load(std::memory_order_relaxed);
  sequence.store(current + 1U, std::memory_order_relaxed);
  std::atomic_thread_fence(std::memory_order_release);
}

void end_write(std::atomic<std::uint64_t>& sequence) noexcept {
  sequence.store(sequence.load(std::memory_order_relaxed) + 1U, std::memory_order_release);
}

/// Runs `read` until it saw a consistent snapshot (true) or the writer stayed mid-update for
/// kSeqlockGiveUp (false).
template <class Read>
bool read_consistent(const std::atomic<std::uint64_t>& sequence, Read&& read) noexcept {
  Clock::time_point give_up{};
  for (int attempt = 0;; ++attempt) {
    const std::uint64_t before = sequence.load(std::memory_order_acquire);
    if ((before & 1U) == 0U) {
      read();
      std::atomic_thread_fence(std::memory_order_acquire);
      if (sequence.load(std::memory_order_relaxed) == before) return true;
    }
    if (attempt == kSeqlockSpinsBeforeClock) give_up = Clock::now() + kSeqlockGiveUp;
    if (attempt > kSeqlockSpinsBeforeClock) {
      if (Clock::now() > give_up) return false;
      std::this_thread::yield();
    }
  }
}

/// Checks identification and constants of an initialized segment; throws BoardError.
const ShmBoardLayout& checked_layout(const ShmSegment& segment) {
  const ShmBoardLayout& layout = segment.layout();
  const std::uint32_t magic = layout.magic.load(std::memory_order_acquire);
  if (magic != kShmBoardMagic) {
    fail(segment.path(), "magic " + hex(magic) + " does not match " + hex(kShmBoardMagic) +
                             " (not a crane board segment, or its emulator has not initialized it yet)");
  }
  if (layout.version != kShmBoardVersion) {
    fail(segment.path(), "layout version " + std::to_string(layout.version) + " does not match " +
                             std::to_string(kShmBoardVersion) + " (emulator and bridge built from different sources)");
  }
  if (layout.layout_size != sizeof(ShmBoardLayout)) {
    fail(segment.path(), "layout size " + std::to_string(layout.layout_size) + " bytes does not match " +
                             std::to_string(sizeof(ShmBoardLayout)));
  }
  if (layout.counter_bits < 2U || layout.counter_bits > 32U) {
    fail(segment.path(), "counter_bits " + std::to_string(layout.counter_bits) + " is not in [2, 32]");
  }
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    const AnalogRange range{layout.analog_min_volts[i], layout.analog_max_volts[i], layout.analog_maxdata[i]};
    if (!is_valid(range)) {
      fail(segment.path(), std::string("analog output ") + channel_name(static_cast<AnalogOutput>(i)) + " range [" +
                               common::format_value(range.min_volts) + ", " + common::format_value(range.max_volts) +
                               "] V, maxdata " + std::to_string(range.maxdata) + " is not a valid range");
    }
  }
  return layout;
}

std::array<AnalogRange, kAnalogOutputCount> ranges_of(const ShmBoardLayout& layout) noexcept {
  std::array<AnalogRange, kAnalogOutputCount> ranges{};
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    ranges[i] = AnalogRange{layout.analog_min_volts[i], layout.analog_max_volts[i], layout.analog_maxdata[i]};
  }
  return ranges;
}

std::uint32_t mask_of(int counter_bits) noexcept {
  return static_cast<std::uint32_t>((std::uint64_t{1} << counter_bits) - 1U);
}

}  // namespace

std::string shm_segment_path(const std::string& name) {
  const bool length_ok = !name.empty() && name.size() <= kMaxNameLength;
  const bool characters_ok = std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
  if (!length_ok || !characters_ok) {
    throw common::ConfigError("shared-memory board name '" + name +
                              "' is not accepted: must be 1..200 letters, digits, '_' or '-'");
  }
  return std::string(kShmSegmentPrefix) + name;
}

std::int64_t monotonic_time_ns() noexcept {
  timespec now{};
  clock_gettime(CLOCK_MONOTONIC, &now);
  return static_cast<std::int64_t>(now.tv_sec) * 1'000'000'000 + static_cast<std::int64_t>(now.tv_nsec);
}

// ---------------------------------------------------------------------------------------------
// ShmSegment

ShmSegment::ShmSegment(std::string path, ShmBoardLayout* layout, bool unlink_on_destroy) noexcept
    : path_(std::move(path)), layout_(layout), unlink_on_destroy_(unlink_on_destroy) {}

ShmSegment ShmSegment::create(const std::string& name) {
  std::string path = shm_segment_path(name);
  (void)shm_unlink(path.c_str());  // re-create: a stale segment of a crashed emulator goes away
  const int fd = shm_open(path.c_str(), O_CREAT | O_EXCL | O_RDWR, S_IRUSR | S_IWUSR);
  if (fd < 0) fail(path, "shm_open(O_CREAT | O_EXCL) failed: " + system_error_text(errno));
  if (ftruncate(fd, static_cast<off_t>(sizeof(ShmBoardLayout))) != 0) {
    const int error = errno;
    close(fd);
    shm_unlink(path.c_str());
    fail(path, "ftruncate failed: " + system_error_text(error));
  }
  void* memory = mmap(nullptr, sizeof(ShmBoardLayout), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  const int error = errno;
  close(fd);
  if (memory == MAP_FAILED) {
    shm_unlink(path.c_str());
    fail(path, "mmap failed: " + system_error_text(error));
  }
  auto* layout = new (memory) ShmBoardLayout{};  // zero registers; magic 0 until the emulator publishes it
  return ShmSegment(std::move(path), layout, true);
}

ShmSegment ShmSegment::open_existing(const std::string& name) {
  std::string path = shm_segment_path(name);
  const int fd = shm_open(path.c_str(), O_RDWR, 0);
  if (fd < 0) {
    const int error = errno;
    if (error == ENOENT) fail(path, "no such shared-memory segment (is the board emulator running?)");
    fail(path, "shm_open failed: " + system_error_text(error));
  }
  struct stat status {};
  if (fstat(fd, &status) != 0) {
    const int error = errno;
    close(fd);
    fail(path, "fstat failed: " + system_error_text(error));
  }
  if (status.st_size < static_cast<off_t>(sizeof(ShmBoardLayout))) {
    close(fd);
    fail(path, "segment size " + std::to_string(status.st_size) + " bytes is smaller than the layout (" +
                   std::to_string(sizeof(ShmBoardLayout)) + " bytes)");
  }
  void* memory = mmap(nullptr, sizeof(ShmBoardLayout), PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  const int error = errno;
  close(fd);
  if (memory == MAP_FAILED) fail(path, "mmap failed: " + system_error_text(error));
  // The emulator constructed the object in this memory (placement new in create()).
  return ShmSegment(std::move(path), static_cast<ShmBoardLayout*>(memory), false);
}

ShmSegment::ShmSegment(ShmSegment&& other) noexcept
    : path_(std::move(other.path_)),
      layout_(std::exchange(other.layout_, nullptr)),
      unlink_on_destroy_(std::exchange(other.unlink_on_destroy_, false)) {}

ShmSegment& ShmSegment::operator=(ShmSegment&& other) noexcept {
  if (this != &other) {
    release();
    path_ = std::move(other.path_);
    layout_ = std::exchange(other.layout_, nullptr);
    unlink_on_destroy_ = std::exchange(other.unlink_on_destroy_, false);
  }
  return *this;
}

ShmSegment::~ShmSegment() { release(); }

void ShmSegment::release() noexcept {
  if (layout_ != nullptr) {
    munmap(layout_, sizeof(ShmBoardLayout));
    layout_ = nullptr;
  }
  if (unlink_on_destroy_) {
    shm_unlink(path_.c_str());
    unlink_on_destroy_ = false;
  }
}

// ---------------------------------------------------------------------------------------------
// ShmBoard (driver side)

ShmBoard::ShmBoard(const std::string& name, const BoardConfig& config)
    : segment_(ShmSegment::open_existing(name)),
      counter_bits_(static_cast<int>(checked_layout(segment_).counter_bits)),
      counter_mask_(mask_of(counter_bits_)),
      ranges_(ranges_of(segment_.layout())),
      axes_(config.axes) {
  if (counter_bits_ != config.counter_bits) {
    fail(segment_.path(), "counter_bits " + std::to_string(counter_bits_) + " of the segment differs from board.counter_bits = " +
                              std::to_string(config.counter_bits));
  }
}

void ShmBoard::read_counters(std::array<std::uint32_t, kCounterCount>& raw_counts) {
  const ShmBoardLayout& layout = segment_.layout();
  std::array<std::uint32_t, kCounterCount> values{};
  std::array<std::int64_t, kCounterCount> rates{};
  std::uint64_t tick = 0;
  std::int64_t due_ns = 0;
  std::int64_t period_ns = 0;
  const bool consistent = read_consistent(layout.counter_sequence, [&]() noexcept {
    for (std::size_t i = 0; i < kCounterCount; ++i) {
      values[i] = layout.counters[i].load(std::memory_order_relaxed);
      rates[i] = layout.count_rates[i].load(std::memory_order_relaxed);
    }
    tick = layout.sample_tick.load(std::memory_order_relaxed);
    due_ns = layout.sample_time_ns.load(std::memory_order_relaxed);
    period_ns = layout.sample_period_ns.load(std::memory_order_relaxed);
  });
  if (!consistent) fail(segment_.path(), "the counters stayed mid-update (did the emulator die while writing?)");
  // A free-running emulator's counters move on between its samples, along their rates.
  double elapsed = 0.0;  // [s] since the sample was due, in [0, kMaxCounterExtrapolation periods]
  if (due_ns > 0 && period_ns > 0) {
    const double cap = kMaxCounterExtrapolation * static_cast<double>(period_ns);
    elapsed = std::clamp(static_cast<double>(monotonic_time_ns() - due_ns), 0.0, cap) * 1e-9;
  }
  for (std::size_t i = 0; i < kCounterCount; ++i) {
    const auto advance = static_cast<std::int64_t>(std::llround(static_cast<double>(rates[i]) * elapsed));
    raw_counts[i] = static_cast<std::uint32_t>(static_cast<std::uint64_t>(values[i]) + static_cast<std::uint64_t>(advance)) &
                    counter_mask_;
  }
  answered_tick_ = tick;
}

void ShmBoard::write_outputs(const BoardOutputs& outputs) {
  ShmBoardLayout& layout = segment_.layout();
  begin_write(layout.output_sequence);
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    layout.dac_codes[i].store(std::min(outputs.dac_codes[i], ranges_[i].maxdata), std::memory_order_relaxed);
  }
  layout.digital_outputs.store(outputs.digital_outputs & kDigitalOutputMask, std::memory_order_relaxed);
  layout.outputs_tick.store(answered_tick_, std::memory_order_relaxed);
  layout.output_write_count.store(layout.output_write_count.load(std::memory_order_relaxed) + 1U,
                                  std::memory_order_relaxed);
  layout.last_output_write_ns.store(monotonic_time_ns(), std::memory_order_relaxed);
  end_write(layout.output_sequence);
}

std::uint32_t ShmBoard::read_digital_inputs() {
  return segment_.layout().digital_inputs.load(std::memory_order_acquire) & kAllInputsMask;
}

AnalogRange ShmBoard::analog_range(AnalogOutput channel) const noexcept { return ranges_[index(channel)]; }

std::string ShmBoard::describe() const {
  std::ostringstream text;
  text << "shm:" << segment_.path().substr(std::char_traits<char>::length(kShmSegmentPrefix))
       << " (emulated interface board in " << segment_.path() << ": " << counter_bits_ << "-bit counters";
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    if (!uses(axes_, static_cast<AnalogOutput>(i))) continue;
    text << ", " << channel_name(static_cast<AnalogOutput>(i)) << " [" << common::format_value(ranges_[i].min_volts)
         << ", " << common::format_value(ranges_[i].max_volts) << "] V maxdata " << ranges_[i].maxdata;
  }
  text << ")";
  return text.str();
}

bool ShmBoard::wait_for_sample(std::uint64_t after_tick, Clock::time_point deadline, std::uint64_t& tick) noexcept {
  const ShmBoardLayout& layout = segment_.layout();
  for (;;) {
    const std::uint64_t current = layout.sample_tick.load(std::memory_order_acquire);
    if (current > after_tick) {
      tick = current;
      answered_tick_ = current;
      return true;
    }
    const auto now = Clock::now();
    if (now >= deadline) return false;
    std::this_thread::sleep_for(std::min<Clock::duration>(kShmPollInterval, deadline - now));
  }
}

std::uint64_t ShmBoard::sample_tick() const noexcept {
  return segment_.layout().sample_tick.load(std::memory_order_acquire);
}

bool ShmBoard::emulator_closed() const noexcept {
  return segment_.layout().emulator_closed.load(std::memory_order_acquire) != 0U;
}

// ---------------------------------------------------------------------------------------------
// ShmBoardEmulator (board side)

ShmBoardEmulator::ShmBoardEmulator(ShmSegment segment, bool owns_segment) noexcept
    : segment_(std::move(segment)),
      owns_segment_(owns_segment),
      counter_bits_(static_cast<int>(segment_.layout().counter_bits)),
      ranges_(ranges_of(segment_.layout())) {}

ShmBoardEmulator ShmBoardEmulator::create(const std::string& name, const common::CraneParameters& crane,
                                          int counter_bits,
                                          const std::array<std::int64_t, kCounterCount>& initial_counts) {
  (void)shm_segment_path(name);
  common::validate(crane, "crane");
  common::require_in_range("counter_bits", static_cast<double>(counter_bits), 2.0, 32.0);
  ShmSegment segment = ShmSegment::create(name);
  ShmBoardLayout& layout = segment.layout();
  layout.version = kShmBoardVersion;
  layout.layout_size = static_cast<std::uint32_t>(sizeof(ShmBoardLayout));
  layout.counter_bits = static_cast<std::uint32_t>(counter_bits);
  const AnalogRange range = plant_dac_range(crane);
  for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
    layout.analog_min_volts[i] = range.min_volts;
    layout.analog_max_volts[i] = range.max_volts;
    layout.analog_maxdata[i] = range.maxdata;
    layout.dac_codes[i].store(volts_to_code(0.0, range), std::memory_order_relaxed);
  }
  for (std::size_t i = 0; i < kCounterCount; ++i) {
    layout.counters[i].store(counter_register_value(initial_counts[i], counter_bits), std::memory_order_relaxed);
  }
  layout.magic.store(kShmBoardMagic, std::memory_order_release);  // last: the segment is ready
  return ShmBoardEmulator(std::move(segment), true);
}

ShmBoardEmulator ShmBoardEmulator::attach(const std::string& name) {
  ShmSegment segment = ShmSegment::open_existing(name);
  (void)checked_layout(segment);
  return ShmBoardEmulator(std::move(segment), false);
}

ShmBoardEmulator::~ShmBoardEmulator() {
  if (owns_segment_ && segment_.is_mapped()) segment_.layout().emulator_closed.store(1U, std::memory_order_release);
}

std::uint64_t ShmBoardEmulator::publish_sample(const std::array<std::int64_t, kCounterCount>& encoder_counts) noexcept {
  return publish_timed_sample(encoder_counts, 0, 0.0);
}

std::uint64_t ShmBoardEmulator::publish_timed_sample(const std::array<std::int64_t, kCounterCount>& encoder_counts,
                                                     std::int64_t sample_time_ns, double sample_period) noexcept {
  const bool timed = sample_time_ns > 0 && std::isfinite(sample_period) && sample_period > 0.0;
  ShmBoardLayout& layout = segment_.layout();
  begin_write(layout.counter_sequence);
  for (std::size_t i = 0; i < kCounterCount; ++i) {
    layout.counters[i].store(counter_register_value(encoder_counts[i], counter_bits_), std::memory_order_relaxed);
    const double rate = timed && published_ ? static_cast<double>(encoder_counts[i] - last_counts_[i]) / sample_period : 0.0;
    layout.count_rates[i].store(static_cast<std::int64_t>(std::llround(rate)), std::memory_order_relaxed);
  }
  layout.sample_time_ns.store(timed ? sample_time_ns : 0, std::memory_order_relaxed);
  layout.sample_period_ns.store(timed ? static_cast<std::int64_t>(std::llround(sample_period * 1e9)) : 0,
                                std::memory_order_relaxed);
  last_counts_ = encoder_counts;
  published_ = true;
  const std::uint64_t tick = layout.sample_tick.load(std::memory_order_relaxed) + 1U;
  layout.sample_tick.store(tick, std::memory_order_release);  // counters first, then the tick
  end_write(layout.counter_sequence);
  return tick;
}

std::uint64_t ShmBoardEmulator::sample_tick() const noexcept {
  return segment_.layout().sample_tick.load(std::memory_order_acquire);
}

bool ShmBoardEmulator::wait_for_outputs(std::uint64_t tick, Clock::time_point deadline) const noexcept {
  const ShmBoardLayout& layout = segment_.layout();
  for (;;) {
    if (layout.outputs_tick.load(std::memory_order_acquire) >= tick) return true;
    const auto now = Clock::now();
    if (now >= deadline) return false;
    std::this_thread::sleep_for(std::min<Clock::duration>(kShmPollInterval, deadline - now));
  }
}

ShmOutputs ShmBoardEmulator::read_outputs() const {
  const ShmBoardLayout& layout = segment_.layout();
  ShmOutputs snapshot;
  const bool consistent = read_consistent(layout.output_sequence, [&]() noexcept {
    for (std::size_t i = 0; i < kAnalogOutputCount; ++i) {
      snapshot.outputs.dac_codes[i] = layout.dac_codes[i].load(std::memory_order_relaxed);
    }
    snapshot.outputs.digital_outputs = layout.digital_outputs.load(std::memory_order_relaxed);
    snapshot.outputs_tick = layout.outputs_tick.load(std::memory_order_relaxed);
    snapshot.write_count = layout.output_write_count.load(std::memory_order_relaxed);
    snapshot.last_write_ns = layout.last_output_write_ns.load(std::memory_order_relaxed);
  });
  if (!consistent) fail(segment_.path(), "the outputs stayed mid-update (did the bridge die while writing?)");
  return snapshot;
}

double ShmBoardEmulator::output_volts(const ShmOutputs& outputs, AnalogOutput channel) const noexcept {
  return code_to_volts(outputs.outputs.dac_codes[index(channel)], ranges_[index(channel)]);
}

void ShmBoardEmulator::set_digital_inputs(std::uint32_t logical_inputs) noexcept {
  segment_.layout().digital_inputs.store(logical_inputs & kAllInputsMask, std::memory_order_release);
}

void ShmBoardEmulator::set_digital_input(DigitalInput line, bool active) noexcept {
  std::atomic<std::uint32_t>& inputs = segment_.layout().digital_inputs;
  if (active) {
    inputs.fetch_or(bit(line), std::memory_order_acq_rel);
  } else {
    inputs.fetch_and(~bit(line), std::memory_order_acq_rel);
  }
}

std::uint32_t ShmBoardEmulator::digital_inputs() const noexcept {
  return segment_.layout().digital_inputs.load(std::memory_order_acquire);
}

AnalogRange ShmBoardEmulator::analog_range(AnalogOutput channel) const noexcept { return ranges_[index(channel)]; }

}  // namespace crane::hardware_bridge
