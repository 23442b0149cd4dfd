// Cost of one 100 Hz cycle of each core, with the worst case, not only the mean
// (STYLE.md habit 11). Run: build/bin/bench_cycle  (prints figures; asserts nothing).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <cmath>

#include "crane/anti_swing/anti_swing.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/runtime/node_runtime.hpp"
#include "crane/stack/stack_config.hpp"
#include "crane/state_estimator/state_estimator.hpp"
#include "crane/tracking/tracking_controller.hpp"

namespace {

using namespace crane;
using Clock = std::chrono::steady_clock;

const crane::stack::StackConfig& lab() {
  static const crane::stack::StackConfig cfg =
      crane::stack::load_stack_config(std::string(CRANE_SOURCE_DIR) + "/deploy/config/lab_tower_crane.yaml");
  return cfg;
}

// One 10 ms sample of the nonlinear plant (the configured integrator with friction events), driven by a voltage that
// reverses every 0.5 s so the trolley keeps sticking and slipping.
void BM_PlantSample(benchmark::State& state) {
  plant::SimulatorParameters p;
  p.crane = lab().facts.crane;
  p.initial_state.trolley_position = 0.6;
  p.initial_state.cable_length = p.crane.cable_length;
  plant::CraneSimulator simulator(p);
  double worst = 0.0;
  long k = 0;
  for (auto _ : state) {
    plant::DriveInput input;
    input.brakes_engaged = false;
    input.trolley_voltage = ((k / 50) % 2 == 0 ? 1.5 : -1.5);
    input.slew_voltage = 0.8 * std::sin(0.02 * static_cast<double>(k));
    const auto start = Clock::now();
    benchmark::DoNotOptimize(simulator.step(input));
    worst = std::max(worst, std::chrono::duration<double, std::micro>(Clock::now() - start).count());
    ++k;
  }
  state.counters["worst_us"] = worst;
  state.counters["friction_events"] = static_cast<double>(simulator.friction_event_count());
}
BENCHMARK(BM_PlantSample)->Iterations(6000);

// The whole control chain of one cycle: estimator, anti-swing, tracking, friction compensation.
void BM_ControlChainCycle(benchmark::State& state) {
  state_estimator::StateEstimator estimator(lab().state_estimator.estimator);
  anti_swing::AntiSwing anti_swing(lab().anti_swing.anti_swing);
  tracking::TrackingController tracking(lab().tracking.tracking);
  friction_compensation::FrictionCompensation compensation(lab().friction_compensation);
  common::CraneMeasurement m;
  common::CraneStateEstimate e;
  anti_swing::AntiSwingOutput a;
  tracking::TrackingOutput t;
  friction_compensation::FrictionCompensationOutput f;
  double worst = 0.0;
  long k = 0;
  for (auto _ : state) {
    m.trolley_position = 0.5 + 0.1 * std::sin(0.01 * static_cast<double>(k));
    m.swing_in_plane = 0.05 * std::sin(0.031 * static_cast<double>(k));
    const auto start = Clock::now();
    (void)estimator.step(m, e);
    (void)anti_swing.step(e, a);
    tracking::TrackingInput in{e, {}, a.trolley_action, a.slew_action, std::nullopt};  // the configured load
    in.reference.trolley.position = 0.6;
    (void)tracking.step(in, t);
    (void)compensation.step({e, t.command, std::nullopt, std::nullopt}, f);  // the configured friction
    benchmark::DoNotOptimize(f);
    worst = std::max(worst, std::chrono::duration<double, std::micro>(Clock::now() - start).count());
    ++k;
  }
  state.counters["worst_us"] = worst;
}
BENCHMARK(BM_ControlChainCycle)->Iterations(100000);

// The once-a-second latency percentiles every node computes for its diagnostics.
void BM_LatencyPercentiles(benchmark::State& state) {
  runtime::LatencyStatistics latency;
  for (int i = 0; i < 10000; ++i) latency.record(300.0 + 50.0 * std::sin(i * 0.7));
  for (auto _ : state) {
    benchmark::DoNotOptimize(latency.percentile(50.0));
    benchmark::DoNotOptimize(latency.percentile(99.0));
  }
}
BENCHMARK(BM_LatencyPercentiles);

}  // namespace

BENCHMARK_MAIN();
