#pragma once
// Closed-loop runs of the whole stack without DDS: crane::stack::run_in_process, the same stage
// objects the processes run (estimator, planner, anti-swing, tracking, friction compensation,
// supervisor, the plant behind the actuation gate), in the lockstep order, with the demo's rest of
// 400 cycles before the move. So a run here is the DDS lockstep demo's run (tests/integration
// checks that to the printed digit), and the figures of merit are the demo's.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "crane/stack/in_process_stack.hpp"

namespace crane::closed_loop {

struct Trace {
  std::string maneuver;
  bool friction_compensation{true};
  double trolley_target{0.0};   // [m]
  double slew_target{0.0};      // [rad]
  double swing_period{0.0};     // [s] T = 2 pi sqrt(L/g) at the target cable length
  std::vector<stack::CycleRecord> samples;  // the move's cycles (the demo's CSV rows)
  stack::ManeuverMetrics metrics;
  long plant_step_failures{0};
  long friction_events{0};
};

/// Non-asserted diagnostics of the end of a run (limit cycles / chatter).
struct TailStatistics {
  int trolley_voltage_sign_changes{0};  // sign changes of the applied trolley voltage (|V| > 1 DAC step)
  int slew_voltage_sign_changes{0};
  double trolley_voltage_peak{0.0};     // [V] max |applied trolley voltage|
  double slew_voltage_peak{0.0};        // [V]
  double trolley_span{0.0};             // [m] max x - min x
  double slew_span{0.0};                // [rad]
  double trolley_voltage_max_jump{0.0}; // [V] max |u(k) - u(k-1)| of the applied trolley voltage
  double slew_voltage_max_jump{0.0};    // [V]
};

/// Statistics over the samples with time >= end_time - window.
inline TailStatistics tail_statistics(const Trace& trace, double window) {
  TailStatistics s;
  if (trace.samples.empty()) return s;
  const double start = trace.samples.back().t - window;
  constexpr double kDeadband = 2.5e-3;  // [V] about one DAC code: ignore +-0 flicker
  double last_x_sign = 0.0;
  double last_g_sign = 0.0;
  double x_min = 1e300, x_max = -1e300, g_min = 1e300, g_max = -1e300;
  const stack::CycleRecord* previous = nullptr;
  for (const auto& c : trace.samples) {
    if (c.t < start) continue;
    if (previous != nullptr) {
      s.trolley_voltage_max_jump =
          std::max(s.trolley_voltage_max_jump, std::fabs(c.u_x - previous->u_x));
      s.slew_voltage_max_jump = std::max(s.slew_voltage_max_jump, std::fabs(c.u_gamma - previous->u_gamma));
    }
    previous = &c;
    s.trolley_voltage_peak = std::max(s.trolley_voltage_peak, std::fabs(c.u_x));
    s.slew_voltage_peak = std::max(s.slew_voltage_peak, std::fabs(c.u_gamma));
    x_min = std::min(x_min, c.x);
    x_max = std::max(x_max, c.x);
    g_min = std::min(g_min, c.gamma);
    g_max = std::max(g_max, c.gamma);
    if (std::fabs(c.u_x) > kDeadband) {
      const double sign = c.u_x > 0.0 ? 1.0 : -1.0;
      if (last_x_sign != 0.0 && sign != last_x_sign) ++s.trolley_voltage_sign_changes;
      last_x_sign = sign;
    }
    if (std::fabs(c.u_gamma) > kDeadband) {
      const double sign = c.u_gamma > 0.0 ? 1.0 : -1.0;
      if (last_g_sign != 0.0 && sign != last_g_sign) ++s.slew_voltage_sign_changes;
      last_g_sign = sign;
    }
  }
  s.trolley_span = x_max - x_min;
  s.slew_span = g_max - g_min;
  return s;
}

/// Runs `maneuver` through the whole stack configured by `cfg` with its configured anti-swing law
/// and PD tracking, the trapezoid (3.43); `friction_compensation` = false is the
/// friction_compensation node's --disable (u = V, still clamped). `mismatch`: the simulated plant's
/// difference from the configuration (friction_factor 0: a frictionless plant).
inline Trace run_closed_loop(const stack::StackConfig& cfg, const stack::ManeuverConfig& maneuver,
                             bool friction_compensation, const plant::PlantMismatch& mismatch = {}) {
  stack::InProcessRun run;
  run.maneuver = maneuver;
  run.friction_compensation = friction_compensation;
  run.controller.anti_swing = cfg.anti_swing.law;
  run.mismatch = mismatch;
  auto result = stack::run_in_process(cfg, run);
  Trace trace;
  trace.maneuver = maneuver.name;
  trace.friction_compensation = friction_compensation;
  trace.trolley_target = maneuver.trolley_target;
  trace.slew_target = maneuver.slew_target;
  trace.swing_period = result.swing_period;
  trace.samples = std::move(result.records);
  trace.metrics = result.metrics;
  trace.plant_step_failures = static_cast<long>(result.plant_step_failures);
  trace.friction_events = result.friction_events;
  return trace;
}

}  // namespace crane::closed_loop
