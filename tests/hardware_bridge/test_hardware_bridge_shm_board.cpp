// The emulated interface board in POSIX shared memory: driver (ShmBoard) and board side
// (ShmBoardEmulator) in one process, a segment name unique per test (pid + test name).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <optional>
#include <random>
#include <string>
#include <thread>

#include "crane/common/validation.hpp"
#include "crane/hardware_bridge/shm_board.hpp"
#include "crane/plant/drives_and_sensors.hpp"

namespace crane::hardware_bridge {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

constexpr int kRandomSamples = 5000;
constexpr int kHandshakeSamples = 300;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

std::string unique_name() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  return std::string("test_") + std::to_string(getpid()) + "_" + info->name();
}

std::string board_error(const std::string& name, const BoardConfig& config = {}) {
  try {
    const ShmBoard board(name, config);
  } catch (const BoardError& error) {
    return error.what();
  }
  return "";
}

// (count mod 2^bits) computed independently of counter_register_value().
std::uint32_t modulo(std::int64_t count, int bits) {
  const std::int64_t modulus = std::int64_t{1} << bits;
  return static_cast<std::uint32_t>(((count % modulus) + modulus) % modulus);
}

TEST(ShmBoard, ReportsThePlantsDacAndCounterWidth) {
  const std::string name = unique_name();
  const common::CraneParameters crane;
  const ShmBoardEmulator emulator = ShmBoardEmulator::create(name, crane);
  EXPECT_TRUE(emulator.owns_segment());
  EXPECT_EQ(emulator.segment_path(), "/crane_board_" + name);
  ShmBoard board(name);
  EXPECT_EQ(board.counter_bits(), 24);
  for (const AnalogRange range : board.analog_ranges()) {
    // 13 bits over +-10 V, offset binary: [-10, 10 - 20/8192] V over codes 0..8191.
    EXPECT_EQ(range.min_volts, -10.0);
    EXPECT_EQ(range.max_volts, 10.0 - 20.0 / 8192.0);
    EXPECT_EQ(range.maxdata, 8191U);
  }
  EXPECT_TRUE(contains(board.describe(), "shm:" + name)) << board.describe();
  // Before any write the outputs hold 0 V and every line is off.
  const ShmOutputs initial = emulator.read_outputs();
  EXPECT_EQ(initial.write_count, 0U);
  EXPECT_EQ(initial.outputs.digital_outputs, 0U);
  EXPECT_EQ(emulator.output_volts(initial, AnalogOutput::trolley_drive), 0.0);
}

TEST(ShmBoard, CountersWrapLikeTheHardware) {
  const std::string name = unique_name();
  ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
  ShmBoard board(name);
  const std::array<std::int64_t, kCounterCount> counts{-1, 8388607, 123456789, -8388609, 10185916};
  EXPECT_EQ(emulator.publish_sample(counts), 1U);
  std::array<std::uint32_t, kCounterCount> raw{};
  board.read_counters(raw);
  for (std::size_t i = 0; i < kCounterCount; ++i) EXPECT_EQ(raw[i], modulo(counts[i], 24)) << i;
  EXPECT_EQ(raw[0], 0xFFFFFFU);
  // First readings are sign-extended: -8388609 does not fit in 24 bits and reads as 8388607.
  CounterUnwrapper unwrapper(24);
  EXPECT_EQ(unwrapper.update(raw[3]), 8388607);
}

// A driver that opens the board the moment it exists reads the plant's initial state, before
// any sample is published (a bridge that read zeros there saw the trolley jump from 0 m to its
// initial 0.25 m: travel and overspeed faults at start-up).
TEST(ShmBoard, HoldsTheInitialCountsFromTheStart) {
  const std::string name = unique_name();
  const std::array<std::int64_t, kCounterCount> initial{70000, -5, 123456789, 0, 2546479};
  const ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{}, 24, initial);
  EXPECT_EQ(emulator.sample_tick(), 0U);
  ShmBoard board(name);
  std::array<std::uint32_t, kCounterCount> raw{};
  board.read_counters(raw);
  for (std::size_t i = 0; i < kCounterCount; ++i) EXPECT_EQ(raw[i], modulo(initial[i], 24)) << i;
}

// A free-running emulator (the realtime plant): between two samples the driver reads counters
// advanced along the last step's rate, as an encoder's move between two reads, at most two periods;
// board-paced samples hold. Without it a driver on its own timer read 0 or 2 plant steps per cycle.
TEST(ShmBoard, FreeRunningCountersMoveBetweenSamplesAndBoardPacedOnesHold) {
  const std::string name = unique_name();
  ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
  ShmBoard board(name);
  constexpr double kPeriod = 0.01;                 // [s]
  constexpr std::int64_t kPeriodNs = 10'000'000;   // [ns]
  const std::int64_t now = monotonic_time_ns();
  // Steps of +1000 counts on the trolley, -300 on the slew (wrapping below 0), every 10 ms.
  (void)emulator.publish_timed_sample({5000, 100, 0, 0, 0}, now - 2 * kPeriodNs, kPeriod);
  (void)emulator.publish_timed_sample({6000, -200, 0, 0, 0}, now - kPeriodNs / 2, kPeriod);  // due 5 ms ago
  std::array<std::uint32_t, kCounterCount> raw{};
  board.read_counters(raw);
  const double waited = static_cast<double>(monotonic_time_ns() - now) * 1e-9;  // >= 0, tiny
  CounterUnwrapper trolley(24), slew(24);
  const double moved = static_cast<double>(trolley.update(raw[0]) - 6000);
  EXPECT_GE(moved, 500.0 - 1.0) << "5 ms at 100000 count/s";
  EXPECT_LE(moved, 500.0 + 1e5 * waited + 1.0);
  EXPECT_LE(static_cast<double>(slew.update(raw[1]) - (-200)), -150.0 + 1.0) << "5 ms at -30000 count/s";
  EXPECT_EQ(raw[2], 0U) << "a counter at rest stays";
  // A plant late by a second: at most two periods of extrapolation (its counters then hold).
  (void)emulator.publish_timed_sample({7000, -500, 0, 0, 0}, monotonic_time_ns() - 1'000'000'000, kPeriod);
  board.read_counters(raw);
  EXPECT_EQ(trolley.update(raw[0]), 7000 + 2000);
  EXPECT_EQ(slew.update(raw[1]), -500 - 600);
  // Board-paced lockstep (publish_sample): held exactly, whatever the time.
  (void)emulator.publish_sample({8000, -800, 0, 0, 0});
  board.read_counters(raw);
  EXPECT_EQ(trolley.update(raw[0]), 8000);
  EXPECT_EQ(slew.update(raw[1]), -800);
  // A bad period publishes held counters.
  (void)emulator.publish_timed_sample({9000, -800, 0, 0, 0}, monotonic_time_ns() - kPeriodNs, 0.0);
  board.read_counters(raw);
  EXPECT_EQ(trolley.update(raw[0]), 9000);
}

TEST(ShmBoard, OutputsReachTheEmulatorWithTickCountAndTime) {
  const std::string name = unique_name();
  ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
  ShmBoard board(name);
  for (int k = 0; k < 3; ++k) (void)emulator.publish_sample({k, 0, 0, 0, 0});
  std::array<std::uint32_t, kCounterCount> raw{};
  board.read_counters(raw);  // counters of tick 3: the next outputs answer tick 3
  BoardOutputs outputs;
  outputs.dac_codes = {100U, 9000U, 4096U, 6000U};  // 9000 > maxdata: clamped to 8191
  outputs.digital_outputs = bit(DigitalOutput::drive_enable) | bit(DigitalOutput::brake_release_slew) |
                            bit(DigitalOutput::brake_release_bridge) | 0xE0U;  // bits above the five lines dropped
  const std::int64_t before = monotonic_time_ns();
  board.write_outputs(outputs);
  const std::int64_t after = monotonic_time_ns();
  const ShmOutputs seen = emulator.read_outputs();
  EXPECT_EQ(seen.outputs.dac_codes[0], 100U);
  EXPECT_EQ(seen.outputs.dac_codes[1], 8191U);
  EXPECT_EQ(seen.outputs.dac_codes[2], 4096U);
  EXPECT_EQ(seen.outputs.dac_codes[index(AnalogOutput::bridge_drive)], 6000U);
  EXPECT_EQ(seen.outputs.digital_outputs, bit(DigitalOutput::drive_enable) | bit(DigitalOutput::brake_release_slew) |
                                              bit(DigitalOutput::brake_release_bridge));
  EXPECT_EQ(seen.outputs_tick, 3U);
  EXPECT_EQ(seen.write_count, 1U);
  EXPECT_GE(seen.last_write_ns, before);
  EXPECT_LE(seen.last_write_ns, after);
  // code 100 = -10 V + 100 * 20/8192 V.
  EXPECT_DOUBLE_EQ(emulator.output_volts(seen, AnalogOutput::trolley_drive), -10.0 + 100.0 * 20.0 / 8192.0);
  board.write_outputs(outputs);
  EXPECT_EQ(emulator.read_outputs().write_count, 2U);
  // steady_clock is CLOCK_MONOTONIC: a test can compare its own clock with the write time.
  const auto steady_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now().time_since_epoch()).count();
  EXPECT_NEAR(static_cast<double>(steady_ns), static_cast<double>(emulator.read_outputs().last_write_ns), 1e9);
}

TEST(ShmBoard, DigitalInputsFromTheEmulator) {
  const std::string name = unique_name();
  ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
  ShmBoard board(name);
  EXPECT_EQ(board.read_digital_inputs(), 0U);
  emulator.set_digital_input(DigitalInput::emergency_stop, true);
  EXPECT_EQ(board.read_digital_inputs(), bit(DigitalInput::emergency_stop));
  emulator.set_digital_input(DigitalInput::slew_max_limit, true);
  emulator.set_digital_input(DigitalInput::emergency_stop, false);
  EXPECT_EQ(board.read_digital_inputs(), 1U << 3);  // slew max: bit 3 of SensorSample_.limit_switches
  emulator.set_digital_input(DigitalInput::slew_max_limit, false);
  emulator.set_digital_input(DigitalInput::bridge_max_limit, true);
  EXPECT_EQ(board.read_digital_inputs(), 64U);  // bridge max: SWITCH_BRIDGE_MAX of SensorSample_.limit_switches
  emulator.set_digital_inputs(0xFFFFFFFFU);    // only the seven defined inputs exist
  EXPECT_EQ(board.read_digital_inputs(), 0x7FU);
}

// The code the bridge writes for v, decoded by the emulator, is the voltage the plant itself
// applies for v (drives_and_sensors.hpp), within one DAC step (exactly, except at ties).
TEST(ShmBoard, EmulatorDecodesThePlantsAppliedVoltage) {
  const std::string name = unique_name();
  const common::CraneParameters crane;
  const plant::DrivesAndSensors io{crane};
  ShmBoardEmulator emulator = ShmBoardEmulator::create(name, crane);
  ShmBoard board(name);
  std::mt19937 rng(31);
  std::uniform_real_distribution<double> volts(-11.0, 11.0);
  for (int i = 0; i < kRandomSamples; ++i) {
    const std::array<double, kAnalogOutputCount> v{volts(rng), volts(rng), volts(rng), volts(rng)};
    BoardOutputs outputs;
    for (std::size_t c = 0; c < kAnalogOutputCount; ++c) {
      outputs.dac_codes[c] = volts_to_code(v[c], board.analog_range(static_cast<AnalogOutput>(c)));
    }
    board.write_outputs(outputs);
    const ShmOutputs seen = emulator.read_outputs();
    for (std::size_t c = 0; c < kAnalogOutputCount; ++c) {
      ASSERT_LE(std::abs(emulator.output_volts(seen, static_cast<AnalogOutput>(c)) - io.applied_voltage(v[c])),
                io.dac_step_voltage() + 1e-12)
          << v[c];
    }
  }
}

TEST(ShmBoard, MissingSegmentThrowsNamingIt) {
  const std::string name = unique_name();
  const std::string message = board_error(name);
  EXPECT_TRUE(contains(message, "/crane_board_" + name)) << message;
  EXPECT_TRUE(contains(message, "no such shared-memory segment")) << message;
  EXPECT_THROW((void)ShmBoardEmulator::attach(name), BoardError);
}

TEST(ShmBoard, BadNamesAreConfigErrors) {
  EXPECT_THROW((void)shm_segment_path(""), common::ConfigError);
  EXPECT_THROW((void)shm_segment_path("a/b"), common::ConfigError);
  EXPECT_THROW((void)shm_segment_path(std::string(201, 'a')), common::ConfigError);
  EXPECT_EQ(shm_segment_path("crane-1_A"), "/crane_board_crane-1_A");
  EXPECT_THROW((void)ShmBoardEmulator::create("x y", common::CraneParameters{}), common::ConfigError);
}

TEST(ShmBoard, MagicVersionAndCounterWidthMismatchesThrow) {
  const std::string name = unique_name();
  const ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{}, 16);
  {
    const std::string message = board_error(name);  // configured 24 bits, the board has 16
    EXPECT_TRUE(contains(message, "counter_bits 16")) << message;
    BoardConfig sixteen;
    sixteen.counter_bits = 16;
    EXPECT_EQ(board_error(name, sixteen), "");
  }
  // Corrupt the identification through a second mapping.
  const ShmSegment raw = ShmSegment::open_existing(name);
  raw.layout().version = 99;
  std::string message = board_error(name, BoardConfig{});
  EXPECT_TRUE(contains(message, "layout version 99 does not match " + std::to_string(kShmBoardVersion))) << message;
  EXPECT_TRUE(contains(message, "/crane_board_" + name)) << message;
  raw.layout().version = kShmBoardVersion;
  raw.layout().magic.store(0xDEADBEEFU);
  message = board_error(name);
  EXPECT_TRUE(contains(message, "magic 0xdeadbeef does not match 0x43524e42")) << message;
  EXPECT_THROW((void)ShmBoardEmulator::attach(name), BoardError);
}

TEST(ShmBoard, EmulatorUnlinksItsSegmentAndAttachDoesNot) {
  const std::string name = unique_name();
  {
    const ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
    ShmBoard board(name);
    EXPECT_FALSE(board.emulator_closed());
    {
      ShmBoardEmulator monitor = ShmBoardEmulator::attach(name);
      EXPECT_FALSE(monitor.owns_segment());
      monitor.set_digital_input(DigitalInput::trolley_min_limit, true);
      board.write_outputs(safe_board_outputs(board.analog_ranges()));
      EXPECT_EQ(monitor.read_outputs().write_count, 1U);
    }
    // The monitor is gone; the segment is still there.
    EXPECT_EQ(board_error(name), "");
    EXPECT_EQ(board.read_digital_inputs(), bit(DigitalInput::trolley_min_limit));
  }
  const std::string message = board_error(name);
  EXPECT_TRUE(contains(message, "no such shared-memory segment")) << message;
}

TEST(ShmBoard, DriverSeesTheEmulatorClose) {
  const std::string name = unique_name();
  std::optional<ShmBoardEmulator> emulator{ShmBoardEmulator::create(name, common::CraneParameters{})};
  ShmBoard board(name);
  EXPECT_FALSE(board.emulator_closed());
  emulator.reset();
  EXPECT_TRUE(board.emulator_closed());
}

TEST(ShmBoard, RecreatesAStaleSegmentAndRejectsATooSmallOne) {
  const std::string name = unique_name();
  const std::string path = "/crane_board_" + name;
  // A leftover of a crashed emulator: 16 bytes.
  const int fd = shm_open(path.c_str(), O_CREAT | O_RDWR, 0600);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(ftruncate(fd, 16), 0);
  close(fd);
  const std::string message = board_error(name);
  EXPECT_TRUE(contains(message, "smaller than the layout")) << message;
  {
    const ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
    EXPECT_EQ(board_error(name), "");
  }
  EXPECT_NE(board_error(name), "");  // and cleaned up
}

TEST(ShmBoard, WaitsTimeOut) {
  const std::string name = unique_name();
  const ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
  ShmBoard board(name);
  std::uint64_t tick = 77;
  const auto start = Clock::now();
  EXPECT_FALSE(board.wait_for_sample(0, start + 20ms, tick));
  const auto waited = Clock::now() - start;
  EXPECT_GE(waited, 20ms);
  EXPECT_LT(waited, 500ms);
  EXPECT_EQ(tick, 77U);
  EXPECT_FALSE(emulator.wait_for_outputs(1, Clock::now() + 5ms));
  // A deadline in the past still looks once.
  EXPECT_TRUE(emulator.wait_for_outputs(0, Clock::now() - 1s));
}

// Board-paced lockstep between two threads: the emulator publishes sample k and waits for the
// outputs answering k; the driver waits for each sample, unwraps the counters (which wrap the 24-bit
// register several times), and answers with codes derived from what it read. Neither side may miss
// or repeat a sample, and each sees exactly the other's values.
TEST(ShmBoard, BoardPacedTickHandshakeBetweenThreads) {
  const std::string name = unique_name();
  ShmBoardEmulator emulator = ShmBoardEmulator::create(name, common::CraneParameters{});
  ShmBoard board(name);
  // Counts of sample k: trolley climbs 3,000,000 counts per sample (wraps every ~5.6 samples),
  // slew descends, the swing counters oscillate in sign, the bridge climbs 1,000,003 per sample.
  const auto counts_of = [](std::uint64_t k) {
    const auto s = static_cast<std::int64_t>(k);
    return std::array<std::int64_t, kCounterCount>{3'000'000 * s - 7, -2'500'000 * s, (s % 2 == 0 ? s : -s), -1,
                                                   1'000'003 * s};
  };
  // The driver's answer to counts n: trolley code n mod 8192, slew code (-n) mod 8192.
  const auto code_of = [](std::int64_t n) { return modulo(n, 13); };

  std::atomic<int> emulator_failures{0};
  std::thread plant([&] {
    for (std::uint64_t k = 1; k <= kHandshakeSamples; ++k) {
      const std::uint64_t tick = emulator.publish_sample(counts_of(k));
      if (tick != k) ++emulator_failures;
      if (!emulator.wait_for_outputs(tick, Clock::now() + 5s)) {
        ++emulator_failures;
        return;
      }
      const ShmOutputs seen = emulator.read_outputs();
      const auto expected = counts_of(k);
      if (seen.outputs_tick != k || seen.write_count != k || seen.outputs.dac_codes[0] != code_of(expected[0]) ||
          seen.outputs.dac_codes[1] != code_of(-expected[1]) || seen.outputs.dac_codes[3] != code_of(expected[4])) {
        ++emulator_failures;
      }
    }
  });

  std::array<CounterUnwrapper, kCounterCount> unwrappers{CounterUnwrapper{24}, CounterUnwrapper{24}, CounterUnwrapper{24},
                                                         CounterUnwrapper{24}, CounterUnwrapper{24}};
  std::uint64_t last_tick = 0;
  int driver_failures = 0;
  for (int i = 0; i < kHandshakeSamples; ++i) {
    std::uint64_t tick = 0;
    if (!board.wait_for_sample(last_tick, Clock::now() + 5s, tick)) {
      ++driver_failures;
      break;
    }
    if (tick != last_tick + 1) ++driver_failures;  // the emulator waits for us: no sample is skipped
    std::array<std::uint32_t, kCounterCount> raw{};
    board.read_counters(raw);
    std::array<std::int64_t, kCounterCount> counts{};
    for (std::size_t c = 0; c < kCounterCount; ++c) counts[c] = unwrappers[c].update(raw[c]);
    if (counts != counts_of(tick)) ++driver_failures;
    BoardOutputs outputs;
    outputs.dac_codes = {code_of(counts[0]), code_of(-counts[1]), 4096U, code_of(counts[4])};
    board.write_outputs(outputs);
    last_tick = tick;
  }
  plant.join();
  EXPECT_EQ(driver_failures, 0);
  EXPECT_EQ(emulator_failures.load(), 0);
  EXPECT_EQ(last_tick, static_cast<std::uint64_t>(kHandshakeSamples));
  // The trolley count went well beyond the register: 3e6 * 300 = 9e8 counts.
  EXPECT_EQ(unwrappers[0].count(), 3'000'000LL * kHandshakeSamples - 7);
  EXPECT_EQ(unwrappers[4].count(), 1'000'003LL * kHandshakeSamples);
}

}  // namespace
}  // namespace crane::hardware_bridge
