#pragma once
// The emulated interface board: a POSIX shared-memory segment /crane_board_NAME (layout and
// protocol in shm_board_layout.hpp) that behaves like the dissertation's board (section 4.1):
// counter_bits-wide wrapping counters, DAC codes over the range the emulator reports (the plant's
// 13-bit +-10 V DAC, plant_dac_range()), digital inputs and outputs. The segment always holds every
// channel of board_channels.hpp, the bridge's included (a crane without a bridge leaves its counter
// at 0 and its output at 0 V): the layout does not depend on the configuration.
//
//   ShmBoard          the driver side (the bridge): a Board, plus the board-paced sample clock.
//   ShmBoardEmulator  the other side (the simulated plant behind the board): creates the segment
//                     (and unlinks it when destroyed), publishes counter samples, reads the outputs,
//                     sets the digital inputs. ShmBoardEmulator::attach() maps a segment someone
//                     else created, with the same capabilities, without unlinking it (monitors and
//                     fault-injection tests).
//
// Errors: a malformed NAME throws common::ConfigError; system-call failures, a missing segment, a
// wrong magic/version/size, or counter_bits different from the configuration throw BoardError
// naming the segment. Waits poll with short sleeps (kShmPollInterval); nothing takes a lock.

#include <chrono>
#include <cstdint>
#include <string>

#include "crane/common/crane_parameters.hpp"
#include "crane/hardware_bridge/board.hpp"
#include "crane/hardware_bridge/shm_board_layout.hpp"

namespace crane::hardware_bridge {

/// Sleep between two polls of a wait_for_*() function.
inline constexpr std::chrono::microseconds kShmPollInterval{50};

/// "/crane_board_NAME" for a NAME of 1..200 letters, digits, '_' or '-'; throws common::ConfigError
/// naming NAME otherwise.
[[nodiscard]] std::string shm_segment_path(const std::string& name);

/// How far [sample periods] a driver advances the counters of a free-running emulator past the
/// time its last sample was due (ShmBoard::read_counters): a plant late by more holds its counters.
inline constexpr double kMaxCounterExtrapolation = 2.0;

/// CLOCK_MONOTONIC now [ns] (the clock of ShmBoardLayout::last_output_write_ns; the same clock as
/// std::chrono::steady_clock on Linux).
[[nodiscard]] std::int64_t monotonic_time_ns() noexcept;

/// RAII mapping of one segment (shm_open + mmap). Move-only.
class ShmSegment {
 public:
  /// Removes any segment of that name, creates a new one of sizeof(ShmBoardLayout) zero bytes
  /// (mode 0600) and maps it; the destructor unlinks it. Throws BoardError naming the segment.
  [[nodiscard]] static ShmSegment create(const std::string& name);
  /// Maps an existing segment read-write; never unlinks it. Throws BoardError naming the segment
  /// if it does not exist or is smaller than sizeof(ShmBoardLayout).
  [[nodiscard]] static ShmSegment open_existing(const std::string& name);

  ShmSegment(ShmSegment&& other) noexcept;
  ShmSegment& operator=(ShmSegment&& other) noexcept;
  ShmSegment(const ShmSegment&) = delete;
  ShmSegment& operator=(const ShmSegment&) = delete;
  ~ShmSegment();

  /// Precondition: is_mapped().
  [[nodiscard]] ShmBoardLayout& layout() const noexcept { return *layout_; }
  /// False only for a moved-from segment.
  [[nodiscard]] bool is_mapped() const noexcept { return layout_ != nullptr; }
  [[nodiscard]] const std::string& path() const noexcept { return path_; }  // "/crane_board_NAME"

 private:
  ShmSegment(std::string path, ShmBoardLayout* layout, bool unlink_on_destroy) noexcept;
  void release() noexcept;

  std::string path_;
  ShmBoardLayout* layout_{nullptr};
  bool unlink_on_destroy_{false};
};

/// Driver side of the emulated board.
class ShmBoard final : public Board {
 public:
  /// Maps /crane_board_NAME and checks it: BoardError naming the segment if it is missing, too
  /// small, or its magic, version or layout size differ (message gives found and expected values),
  /// or if its counter_bits differs from config.counter_bits. Does not write to the board.
  explicit ShmBoard(const std::string& name, const BoardConfig& config = {});

  /// Seqlock read of the counter registers; also remembers the sample_tick they belong to (the tick
  /// the next write_outputs() answers). From a free-running emulator (publish_timed_sample) each
  /// register is advanced along its published rate by the time since the sample was due, at most
  /// kMaxCounterExtrapolation sample periods: the counters move between two samples as an
  /// encoder's do. Throws BoardError if the emulator stays mid-update for more than ~10 ms (it
  /// died while writing).
  void read_counters(std::array<std::uint32_t, kCounterCount>& raw_counts) override;
  /// Seqlock write of codes (clamped to maxdata), digital word, outputs_tick (the tick of the last
  /// read_counters()/wait_for_sample()), write count + 1 and the CLOCK_MONOTONIC time. noexcept in
  /// practice; never throws.
  void write_outputs(const BoardOutputs& outputs) override;
  [[nodiscard]] std::uint32_t read_digital_inputs() override;
  [[nodiscard]] int counter_bits() const noexcept override { return counter_bits_; }
  [[nodiscard]] AnalogRange analog_range(AnalogOutput channel) const noexcept override;
  [[nodiscard]] std::string describe() const override;

  /// Board-paced sample clock: waits (polling every kShmPollInterval) until the emulator has
  /// published a sample with tick > `after_tick`; sets `tick` to it and returns true, or returns
  /// false once `deadline` has passed (`tick` unchanged). Does not read the counters.
  [[nodiscard]] bool wait_for_sample(std::uint64_t after_tick, std::chrono::steady_clock::time_point deadline,
                                     std::uint64_t& tick) noexcept;
  /// Latest published sample tick (0: none yet).
  [[nodiscard]] std::uint64_t sample_tick() const noexcept;
  /// True once the emulator has shut down (its segment is unlinked; no more samples will come).
  [[nodiscard]] bool emulator_closed() const noexcept;

 private:
  ShmSegment segment_;
  int counter_bits_;
  std::uint32_t counter_mask_;
  std::array<AnalogRange, kAnalogOutputCount> ranges_;
  std::uint64_t answered_tick_{0};  // tick of the counters last read: written as outputs_tick
  BoardAxes axes_{};                // BoardConfig::axes: describe() names the crane's outputs
};

/// Snapshot of what the driver last wrote (one consistent write_outputs() call).
struct ShmOutputs {
  BoardOutputs outputs;                  // codes and logical digital word
  std::uint64_t outputs_tick{0};         // sample tick these outputs answer (0: none)
  std::uint64_t write_count{0};          // write_outputs() calls so far (0: never written)
  std::int64_t last_write_ns{0};         // [ns] CLOCK_MONOTONIC time of that write
};

/// The board side: what the simulated plant (or a test) sees.
class ShmBoardEmulator {
 public:
  /// (Re-)creates /crane_board_NAME: counter_bits wide counters holding `initial_counts` (sample
  /// tick 0), the analog outputs with plant_dac_range(crane) and code 0 V, inputs and outputs
  /// 0, then publishes the magic: a driver that opens the board as soon as it exists reads the
  /// plant's initial state, never a zero the plant has not reached. Unlinks the segment when
  /// destroyed. Throws common::ConfigError for a bad NAME, invalid `crane` parameters or
  /// counter_bits outside [2, 32]; BoardError if the segment cannot be created.
  [[nodiscard]] static ShmBoardEmulator create(const std::string& name, const common::CraneParameters& crane,
                                               int counter_bits = 24,
                                               const std::array<std::int64_t, kCounterCount>& initial_counts = {});
  /// Maps an existing, initialized segment (same checks as ShmBoard); never unlinks it.
  [[nodiscard]] static ShmBoardEmulator attach(const std::string& name);

  ShmBoardEmulator(ShmBoardEmulator&&) noexcept = default;
  ShmBoardEmulator& operator=(ShmBoardEmulator&&) = delete;
  /// A creating emulator marks the segment closed before it is unlinked.
  ~ShmBoardEmulator();

  /// Publishes one sample: each register = counter_register_value(count, counter_bits), then
  /// sample_tick + 1 (release). Returns the new tick. Single writer (one emulator per segment).
  std::uint64_t publish_sample(const std::array<std::int64_t, kCounterCount>& encoder_counts) noexcept;
  /// A free-running (realtime) emulator's sample: as publish_sample(), plus `sample_time_ns` [ns,
  /// CLOCK_MONOTONIC], when the step that produced it was due, and each counter's rate [count/s],
  /// its change since the previous published sample over `sample_period` [s]. The driver then
  /// reads counters that move between samples (ShmBoard::read_counters). Without it a driver on
  /// its own timer, in phase with the plant's, reads 0 or 2 of the plant's steps in one of its
  /// cycles and differentiates 0 or twice the speed (the supervisor's overspeed fault at 1.03
  /// m/s on a 0.5 m/s move, tests/fault_injection). `sample_period` <= 0 or non-finite publishes
  /// held counters (rates 0), as publish_sample().
  std::uint64_t publish_timed_sample(const std::array<std::int64_t, kCounterCount>& encoder_counts,
                                     std::int64_t sample_time_ns, double sample_period) noexcept;
  [[nodiscard]] std::uint64_t sample_tick() const noexcept;

  /// Waits (polling every kShmPollInterval) until the driver's outputs answer `tick`
  /// (outputs_tick >= tick): true, or false once `deadline` has passed.
  [[nodiscard]] bool wait_for_outputs(std::uint64_t tick, std::chrono::steady_clock::time_point deadline) const noexcept;
  /// Seqlock read of the driver's last outputs. Throws BoardError if the driver stays mid-write
  /// for more than ~10 ms (it died while writing).
  [[nodiscard]] ShmOutputs read_outputs() const;
  /// Voltage [V] of one channel's code in `outputs`: code_to_volts(code, analog_range(channel)).
  [[nodiscard]] double output_volts(const ShmOutputs& outputs, AnalogOutput channel) const noexcept;

  /// Sets the whole logical input word (bits above kDigitalInputCount are dropped).
  void set_digital_inputs(std::uint32_t logical_inputs) noexcept;
  /// Sets or clears one input (atomic read-modify-write).
  void set_digital_input(DigitalInput line, bool active) noexcept;
  [[nodiscard]] std::uint32_t digital_inputs() const noexcept;

  [[nodiscard]] int counter_bits() const noexcept { return counter_bits_; }
  [[nodiscard]] AnalogRange analog_range(AnalogOutput channel) const noexcept;
  [[nodiscard]] const std::string& segment_path() const noexcept { return segment_.path(); }
  /// True for create(), false for attach().
  [[nodiscard]] bool owns_segment() const noexcept { return owns_segment_; }

 private:
  ShmBoardEmulator(ShmSegment segment, bool owns_segment) noexcept;

  ShmSegment segment_;
  bool owns_segment_{false};
  int counter_bits_{0};
  std::array<AnalogRange, kAnalogOutputCount> ranges_{};
  std::array<std::int64_t, kCounterCount> last_counts_{};  // the counts last published (the rates' base)
  bool published_{false};                                  // a sample was published by this emulator
};

}  // namespace crane::hardware_bridge
