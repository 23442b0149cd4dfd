#pragma once
// Memory layout of the emulated interface board: one POSIX shared-memory segment
// /crane_board_NAME shared by the bridge (ShmBoard, the driver side) and the simulated plant behind
// the board (ShmBoardEmulator). Every register is a lock-free std::atomic; nothing blocks.
//
// Protocol (board-paced sample clock, for deterministic simulation):
//   emulator: initialize everything, then store `magic` (release);
//   emulator, each sample k = 1, 2, ...: counter_sequence odd -> counters -> sample_tick = k
//             (release) -> counter_sequence even (a seqlock: a reader never sees counters of two
//             samples);
//   driver:   wait until sample_tick > the last tick it handled, read counters (seqlock), compute,
//             then write outputs: output_sequence odd -> dac_codes, digital_outputs,
//             outputs_tick = k (the sample its outputs answer), output_write_count + 1,
//             last_output_write_ns -> output_sequence even (release);
//   emulator: wait until outputs_tick >= k, read the outputs (seqlock), advance the plant, publish
//             k + 1.
// One writer per direction. Digital inputs are a single atomic word (logical layout,
// board_channels.hpp); digital outputs too.
//
// Change kShmBoardVersion whenever this struct changes.

#include <array>
#include <atomic>
#include <cstdint>
#include <type_traits>

#include "crane/hardware_bridge/board_channels.hpp"

namespace crane::hardware_bridge {

inline constexpr std::uint32_t kShmBoardMagic = 0x43524E42U;  // "CRNB"
inline constexpr std::uint32_t kShmBoardVersion = 3U;  // 2: the bridge axis; 3: counter rates of a free-running emulator
inline constexpr const char* kShmSegmentPrefix = "/crane_board_";

struct ShmBoardLayout {
  // --- identification and constants: written once by the emulator before `magic` -------------
  std::atomic<std::uint32_t> magic;   // kShmBoardMagic once initialized (stored last, release)
  std::uint32_t version;              // kShmBoardVersion
  std::uint32_t layout_size;          // [byte] sizeof(ShmBoardLayout)
  std::uint32_t counter_bits;         // [bit] width of the counter registers
  std::array<double, kAnalogOutputCount> analog_min_volts;       // [V] voltage of code 0
  std::array<double, kAnalogOutputCount> analog_max_volts;       // [V] voltage of code maxdata
  std::array<std::uint32_t, kAnalogOutputCount> analog_maxdata;  // [code]

  // --- emulator -> driver ---------------------------------------------------------------------
  alignas(64) std::atomic<std::uint64_t> counter_sequence;        // seqlock: odd while writing
  std::array<std::atomic<std::uint32_t>, kCounterCount> counters;  // raw registers, (count & mask)
  std::atomic<std::uint64_t> sample_tick;     // samples published so far (0: none yet)
  // A free-running (realtime) emulator also publishes when its sample was due and each counter's
  // rate, so that the driver reads counters that move between samples as a real encoder's do
  // (ShmBoardEmulator::publish_timed_sample); 0 in board-paced lockstep: the counters hold.
  std::array<std::atomic<std::int64_t>, kCounterCount> count_rates;  // [count/s]
  std::atomic<std::int64_t> sample_time_ns;    // [ns] CLOCK_MONOTONIC time the sample was due (0: held)
  std::atomic<std::int64_t> sample_period_ns;  // [ns] the emulator's sample period (0: held)
  std::atomic<std::uint32_t> digital_inputs;  // logical input word, bit(DigitalInput) = active
  std::atomic<std::uint32_t> emulator_closed; // 1 once the emulator has shut down

  // --- driver -> emulator ---------------------------------------------------------------------
  alignas(64) std::atomic<std::uint64_t> output_sequence;             // seqlock: odd while writing
  std::array<std::atomic<std::uint32_t>, kAnalogOutputCount> dac_codes;  // [code] indexed by AnalogOutput
  std::atomic<std::uint32_t> digital_outputs;      // logical output word, bit(DigitalOutput) = energized
  std::atomic<std::uint64_t> outputs_tick;         // sample_tick the last outputs answer (0: none)
  std::atomic<std::uint64_t> output_write_count;   // write_outputs() calls so far
  std::atomic<std::int64_t> last_output_write_ns;  // [ns] CLOCK_MONOTONIC time of the last write
};

static_assert(std::is_standard_layout_v<ShmBoardLayout>);
static_assert(std::atomic<std::uint64_t>::is_always_lock_free && std::atomic<std::uint32_t>::is_always_lock_free &&
                  std::atomic<std::int64_t>::is_always_lock_free,
              "the shared-memory registers must be lock-free atomics");

}  // namespace crane::hardware_bridge
