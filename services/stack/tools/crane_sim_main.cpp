// crane_sim: the crane stack in one process, no DDS (crane::stack::run_in_process: the same stage
// objects as the processes, in the lockstep order).
//
//   crane_sim demo  --config FILE [--controller C] [--profile P] [--maneuver M ...]
//                   [--friction-compensation on|off|both] [--acceleration-feedforward] [--out DIR]
//                   [--moves N --seed S] [--mismatch L m f]
//       the demo maneuvers: crane_demo's table (to the printed digit: the same stages on the same
//       inputs) and its CSV files, and the speed in multiples of real time; --mismatch: the plant's
//       cable length, load mass and friction factors (crane_demo's --plant-*-factor);
//   crane_sim sweep --config FILE [--controllers C,C,...] [--grid N | --random N --seed S]
//                   [--maneuver M] [--jobs J] [--out DIR] [--plot-script F --python P]
//       plant mismatches (cable length, load mass, friction level, sensor delay) over the
//       controllers, on J threads (default: every core): sweep.csv, one heat-map PNG per controller,
//       and the speed in multiples of real time;
//   crane_sim bench --config FILE [--cases N]
//       speed figures measured in one run: the demo maneuvers on one core (x real time), and a
//       sweep of N cases on 1 thread and on every core (the ratio);
//   crane_sim converge --config FILE [--maneuver M ...] [--reference-integrator M --reference-rtol R]
//       the convergence study (convergence_study.hpp): every demo run at the configured integrator
//       and at the reference; each printed figure at both, the integration error (same inputs) and
//       the closed-loop difference; exit 1 when a printed figure differs by more than half its last
//       printed digit;
//   crane_sim integrators --config FILE [--maneuver M ...]
//       the integrators compared on the demo runs' drive inputs (open loop, the plant alone): for
//       each method and tolerance the error against the reference, the right-hand sides and the
//       wall time per simulated second (docs/integration.md);
//   (demo, sweep, bench, converge and integrators take --integrator M [--rtol R --atol A]: the
//   plant's integrator instead of the configuration's plant.integrator)
//   crane_sim bound --config FILE [--maneuver M ...] [--intervals N] [--out DIR]
//       the minimum time T* of each demo maneuver on the plant's nonlinear model (maneuver_bound.hpp,
//       docs/optimal_control.md): T* on N and on 2N intervals (their difference: the
//       discretization's), the linear profile's time, IPOPT's iterations and solve time, the largest
//       drive voltage and swing; --out writes bound.csv and <maneuver>_bound.csv (the trajectory);
//   crane_sim follow --config FILE [--maneuver M ...] [--moves N --seed S] [--intervals N] [--corners] [--out DIR]
//       each demo maneuver followed in closed loop from its minimum-time trajectory (follower_run.hpp:
//       the bound's feedforward with time-varying LQR, friction compensation on; docs/optimal_control.md):
//       T*, the settle time and its ratio to T*, the final errors, swing, voltage and the supervisor's
//       faults; --corners: also with the plant's cable length and load mass off by +-20 % and its
//       friction by +-30 % (the eight corners) from what the follower assumes; --mismatch L m f: one
//       such plant instead; --hold-*: the hold at the target (FollowerHold); --out: one CSV per run;
//   crane_sim compare --config FILE [--maneuver M ...] [--moves N] [--seed S] [--corners]
//                     [--controllers C,C,...] [--intervals N] [--jobs J] [--out DIR]
//       issue 32's comparison (controller_comparison.hpp, docs/optimal_control.md): for the demo
//       maneuvers and N seeded random moves, T* and each controller's settle time as a ratio to it
//       (follower, delay1, delay2, time_optimal, zv, zvd), then per controller the median and worst
//       ratio, residual swing, final errors and peak voltage; --corners: also at the eight mismatch
//       corners; --out: compare.csv, one row per move, plant and controller;
//   (follow and compare: --maneuver names demo maneuvers or random moves, random_0 .. random_{N-1}
//   of --moves N, and runs only those; follow with --moves runs the random moves only)
//   crane_sim gantry-gains [--K K]
//       section 3.2.2 on the gantry crane (K_mx = 1.34): the gains of Figures 3.5 (over L, m_t = 0)
//       and 3.6 (over m_t, L = 1 m), and Figures 3.7/3.8 as measured closed-loop rows (overshoot,
//       settle time in swing periods, residual swing) with adapted and unadapted gains; K is the
//       forward gain of the full-state law of Figure 3.8 (crane::stack gantry_gain_study.hpp).
#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <numbers>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "crane/stack/controller_comparison.hpp"
#include "crane/stack/convergence_study.hpp"
#include "crane/stack/gantry_gain_study.hpp"
#include "crane/stack/in_process_stack.hpp"
#include "crane/stack/follower_run.hpp"
#include "crane/stack/maneuver_bound.hpp"
#include "crane/stack/swing_calibration_run.hpp"

namespace {

using namespace crane;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Selection {
  std::string config_path;
  std::string controller;            // empty: delay1, or auto with --profile time_optimal
  std::string profile{"trapezoid"};  // as crane_demo: step with a gain-scheduling controller unless given
  bool profile_given{false};
  std::vector<std::string> maneuvers;
  std::string compensation{"both"};
  bool acceleration_feedforward{false};
  std::string integrator;  // empty: the configuration's plant.integrator
  double rtol{0.0};        // 0: the configuration's
  double atol{0.0};
  int moves{0};            // demo: seeded random moves besides the demo maneuvers (crane_demo's --moves)
  std::uint64_t seed{1};
  plant::PlantMismatch mismatch{};  // demo: the plant's (crane_demo's --plant-*-factor)
};

// The configuration with the command line's integrator, if any.
stack::StackConfig load_config(const Selection& s) {
  auto cfg = stack::load_stack_config(s.config_path);
  if (!s.integrator.empty()) cfg.plant.integrator.method = plant::parse_integration_method(s.integrator, "--integrator");
  if (s.rtol > 0.0) cfg.plant.integrator.relative_tolerance = s.rtol;
  if (s.atol > 0.0) cfg.plant.integrator.absolute_tolerance = s.atol;
  return cfg;
}

std::string integrator_label(const plant::IntegratorSettings& i) {
  char b[128];
  std::snprintf(b, sizeof(b), "%s rtol %.0e atol %.0e", std::string(plant::integration_method_name(i.method)).c_str(),
                i.relative_tolerance, i.absolute_tolerance);
  return b;
}

std::uint8_t profile_of(const std::string& controller, const Selection& s) {
  if (const auto implied = stack::implied_profile(controller); implied && !s.profile_given) {
    return stack::profile_code(*implied);
  }
  return stack::profile_code(s.profile);
}

std::string default_controller(const Selection& s) {
  if (!s.controller.empty()) return s.controller;
  return stack::default_controller(s.profile_given ? std::string_view(s.profile) : std::string_view());
}

// ---------------------------------------------------------------------------------------------
// demo

struct DemoRun {
  stack::ManeuverConfig maneuver;
  bool compensation{true};
  stack::InProcessResult result;
};

// The demo's runs: every selected maneuver with friction compensation on and off (as selected).
std::vector<stack::InProcessRun> demo_runs(const stack::StackConfig& cfg, const Selection& s) {
  const std::string controller = default_controller(s);
  std::vector<stack::InProcessRun> runs;
  std::uint32_t request_id = 1;
  for (const auto& m : stack::select_moves(cfg, s.maneuvers, s.moves, s.seed)) {
    for (const bool compensation : {true, false}) {
      if ((compensation && s.compensation == "off") || (!compensation && s.compensation == "on")) continue;
      stack::InProcessRun run;
      run.maneuver = m;
      run.friction_compensation = compensation;
      run.controller = stack::choose_controller(controller, m, s.acceleration_feedforward);
      run.profile = profile_of(controller, s);
      run.request_id = request_id++;
      run.mismatch = s.mismatch;
      runs.push_back(run);
    }
  }
  return runs;
}

std::vector<DemoRun> run_demo(const stack::StackConfig& cfg, const Selection& s, double& wall_seconds) {
  std::vector<DemoRun> runs;
  const auto start = Clock::now();
  for (const auto& run : demo_runs(cfg, s)) {
    runs.push_back({run.maneuver, run.friction_compensation, stack::run_in_process(cfg, run)});
  }
  wall_seconds = std::chrono::duration<double>(Clock::now() - start).count();
  return runs;
}

double simulated_seconds(const stack::StackConfig& cfg, const std::vector<DemoRun>& runs) {
  double total = 0.0;
  for (const auto& r : runs) total += static_cast<double>(r.result.cycles) * cfg.facts.sample_period;
  return total;
}

int demo(const Selection& s, const std::string& out_dir) {
  const auto cfg = load_config(s);
  double wall = 0.0;
  const auto runs = run_demo(cfg, s, wall);
  const bool bridge = cfg.facts.crane_kind == common::CraneKind::overhead;
  if (!out_dir.empty()) {
    fs::create_directories(out_dir);
    for (const auto& r : runs) {
      std::ofstream csv(fs::path(out_dir) / (r.maneuver.name + (r.compensation ? "_fc_on" : "_fc_off") + ".csv"));
      stack::write_csv(csv, r.result.records, bridge);
    }
  }
  std::printf("\n%s\n", stack::table_header(bridge).c_str());
  for (const auto& r : runs) {
    std::printf("%s\n",
                stack::table_row(r.maneuver.name, r.compensation, r.result.metrics, r.result.swing_period, bridge).c_str());
  }
  const double simulated = simulated_seconds(cfg, runs);
  std::printf("\nspeed: %.1f s simulated in %.3f s on one core (%.0fx real time), controller %s, %zu runs, plant %s\n",
              simulated, wall, simulated / wall, default_controller(s).c_str(), runs.size(),
              integrator_label(cfg.plant.integrator).c_str());
  int failures = 0;
  for (const auto& r : runs) {
    if (r.result.plant_step_failures != 0) {
      std::printf("FAILED: %s: %llu plant steps failed\n", r.maneuver.name.c_str(),
                  static_cast<unsigned long long>(r.result.plant_step_failures));
      ++failures;
    }
  }
  return failures == 0 ? 0 : 1;
}

// ---------------------------------------------------------------------------------------------
// sweep

struct SweepCase {
  std::string controller;
  plant::PlantMismatch mismatch;
};

struct SweepRow {
  SweepCase c;
  stack::ManeuverMetrics metrics;
  double swing_period{0.0};
  std::uint64_t cycles{0};
  std::uint32_t latched_faults{0};
  std::string error;  // a run that could not complete (the row keeps the case)
};

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> items;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ',');) {
    if (!item.empty()) items.push_back(item);
  }
  return items;
}

// Ranges of the mismatches (the robustness the issue asks for: cable length, load mass, friction
// levels, sensor delay). The grid crosses cable length and load mass (the heat map's axes) with
// the configured friction and no delay; the random set draws all four.
constexpr double kCableMin = 0.5, kCableMax = 1.9;    // [-] x 1.0 m: 0.5 .. 1.9 m (within the hoist range)
constexpr double kMassMin = 0.25, kMassMax = 2.5;     // [-] x 2.0 kg
constexpr double kFrictionMin = 0.5, kFrictionMax = 1.5;
constexpr int kDelayMax = 3;                           // [cycles]

std::vector<SweepCase> sweep_cases(const std::vector<std::string>& controllers, int grid, int random, unsigned seed) {
  std::vector<SweepCase> cases;
  for (const auto& controller : controllers) {
    if (grid > 0) {
      for (int i = 0; i < grid; ++i) {
        for (int j = 0; j < grid; ++j) {
          SweepCase c;
          c.controller = controller;
          const double u = grid == 1 ? 0.5 : static_cast<double>(i) / (grid - 1);
          const double v = grid == 1 ? 0.5 : static_cast<double>(j) / (grid - 1);
          c.mismatch.cable_length_factor = kCableMin + u * (kCableMax - kCableMin);
          c.mismatch.load_mass_factor = kMassMin + v * (kMassMax - kMassMin);
          cases.push_back(c);
        }
      }
    } else {
      std::mt19937_64 rng(seed);  // the same mismatches for every controller
      std::uniform_real_distribution<double> unit(0.0, 1.0);
      std::uniform_int_distribution<int> delay(0, kDelayMax);
      for (int n = 0; n < random; ++n) {
        SweepCase c;
        c.controller = controller;
        c.mismatch.cable_length_factor = kCableMin + unit(rng) * (kCableMax - kCableMin);
        c.mismatch.load_mass_factor = kMassMin + unit(rng) * (kMassMax - kMassMin);
        c.mismatch.friction_factor = kFrictionMin + unit(rng) * (kFrictionMax - kFrictionMin);
        c.mismatch.sensor_delay_cycles = delay(rng);
        cases.push_back(c);
      }
    }
  }
  return cases;
}

// Runs every case on `jobs` threads (each run is independent: its own stages and integrator).
std::vector<SweepRow> run_sweep(const stack::StackConfig& cfg, const Selection& s, const stack::ManeuverConfig& maneuver,
                                const std::vector<SweepCase>& cases, unsigned jobs) {
  std::vector<SweepRow> rows(cases.size());
  std::atomic<std::size_t> next{0};
  const auto work = [&] {
    for (std::size_t i = next++; i < cases.size(); i = next++) {
      SweepRow& row = rows[i];
      row.c = cases[i];
      try {
        stack::InProcessRun run;
        run.maneuver = maneuver;
        run.controller = stack::choose_controller(cases[i].controller, maneuver, s.acceleration_feedforward);
        run.profile = profile_of(cases[i].controller, s);
        run.mismatch = cases[i].mismatch;
        const auto result = stack::run_in_process(cfg, run);
        row.metrics = result.metrics;
        row.swing_period = result.swing_period;
        row.cycles = result.cycles;
        row.latched_faults = result.latched_faults;
      } catch (const std::exception& error) {
        row.error = error.what();
      }
    }
  };
  std::vector<std::thread> threads;
  for (unsigned t = 1; t < jobs; ++t) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  return rows;
}

double sweep_simulated_seconds(const stack::StackConfig& cfg, const std::vector<SweepRow>& rows) {
  double total = 0.0;
  for (const auto& r : rows) total += static_cast<double>(r.cycles) * cfg.facts.sample_period;
  return total;
}

void write_sweep_csv(const fs::path& path, const std::vector<SweepRow>& rows) {
  std::ofstream out(path);
  out << "controller,cable_length_factor,load_mass_factor,friction_factor,sensor_delay_cycles,settle_s,settle_T,"
         "pos_err_mm,slew_err_mrad,max_swing_deg,resid_swing_deg,max_V,latched_faults,error\n";
  out.precision(6);
  for (const auto& r : rows) {
    const auto& m = r.metrics;
    const bool ok = r.error.empty();
    const auto num = [&](double v) { return ok && std::isfinite(v) ? std::to_string(v) : std::string(""); };
    out << r.c.controller << ',' << r.c.mismatch.cable_length_factor << ',' << r.c.mismatch.load_mass_factor << ','
        << r.c.mismatch.friction_factor << ',' << r.c.mismatch.sensor_delay_cycles << ',' << num(m.settle_time) << ','
        << num(m.settle_time / r.swing_period) << ',' << num(m.final_position_error * 1e3) << ','
        << num(m.final_slew_error * 1e3) << ',' << num(m.max_swing * 180 / M_PI) << ','
        << num(m.residual_swing * 180 / M_PI) << ',' << num(m.max_voltage) << ',' << r.latched_faults << ",\""
        << r.error << "\"\n";
  }
}

unsigned default_jobs() { return std::max(1U, std::thread::hardware_concurrency()); }

int sweep(const Selection& s, const std::string& controllers_text, int grid, int random, unsigned seed, unsigned jobs,
          const std::string& out_dir, const std::string& plot_script, const std::string& python) {
  const auto cfg = load_config(s);
  const auto maneuvers = stack::select_moves(cfg, s.maneuvers.empty() ? std::vector<std::string>{"trolley"} : s.maneuvers);
  if (maneuvers.size() != 1) throw std::invalid_argument("sweep: give one --maneuver");
  const auto controllers = split_list(controllers_text);
  for (const auto& c : controllers) (void)stack::choose_controller(c, maneuvers[0], false);  // names checked first
  const auto cases = sweep_cases(controllers, grid, random, seed);
  if (jobs == 0) jobs = default_jobs();
  const auto start = Clock::now();
  const auto rows = run_sweep(cfg, s, maneuvers[0], cases, jobs);
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  fs::create_directories(out_dir);
  const fs::path csv = fs::path(out_dir) / "sweep.csv";
  write_sweep_csv(csv, rows);
  std::size_t failed = 0;
  for (const auto& r : rows) failed += r.error.empty() ? 0 : 1;
  const double simulated = sweep_simulated_seconds(cfg, rows);
  std::printf("%-24s %6s %9s %12s %12s %10s\n", "controller", "cases", "settled", "settle_T_p50", "resid_deg_p50",
              "faults");
  for (const auto& c : controllers) {
    std::vector<double> settle, resid;
    std::size_t n = 0, settled = 0, faulted = 0;
    for (const auto& r : rows) {
      if (r.c.controller != c || !r.error.empty()) continue;
      ++n;
      if (std::isfinite(r.metrics.settle_time)) {
        ++settled;
        settle.push_back(r.metrics.settle_time / r.swing_period);
      }
      resid.push_back(r.metrics.residual_swing * 180 / M_PI);
      faulted += r.latched_faults != 0 ? 1 : 0;
    }
    const auto median = [](std::vector<double> v) {
      if (v.empty()) return std::nan("");
      std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
      return v[v.size() / 2];
    };
    std::printf("%-24s %6zu %9zu %12s %12s %10zu\n", c.c_str(), n, settled, stack::format_number(median(settle), 2).c_str(),
                stack::format_number(median(resid), 3).c_str(), faulted);
  }
  std::printf("\nsweep: %zu cases (%zu failed to run) on maneuver %s, %u threads: %.1f s simulated in %.2f s (%.0fx real "
              "time)\ntable: %s\n",
              rows.size(), failed, maneuvers[0].name.c_str(), jobs, simulated, wall, simulated / wall, csv.string().c_str());
  std::fflush(stdout);
  if (!plot_script.empty()) {
    const std::string command = "'" + python + "' '" + plot_script + "' --csv '" + csv.string() + "' --out '" + out_dir + "'";
    if (std::system(command.c_str()) != 0) throw std::runtime_error("plot script failed: " + command);
  }
  return failed == 0 ? 0 : 1;
}

// ---------------------------------------------------------------------------------------------
// bench

// The integrator the plant had before the measured choice (docs/integration.md): CVODE BDF with a
// dense difference-quotient Jacobian, rtol 1e-8, atol 1e-10.
plant::IntegratorSettings former_integrator() {
  plant::IntegratorSettings former;
  former.method = plant::IntegrationMethod::bdf;
  former.relative_tolerance = 1e-8;
  former.absolute_tolerance = 1e-10;
  return former;
}

// [x real time] of the demo maneuvers on one core, the best of `repeats` (the machine's own noise aside).
double demo_speed(const stack::StackConfig& cfg, const Selection& s, int repeats, double& simulated) {
  double best = 1e300;
  for (int repeat = 0; repeat < repeats; ++repeat) {
    double wall = 0.0;
    const auto runs = run_demo(cfg, s, wall);
    simulated = simulated_seconds(cfg, runs);
    best = std::min(best, wall);
  }
  return simulated / best;
}

int bench(Selection s, int cases) {
  // The simulation's speed, not IPOPT's: the default controller (the follower) solves a bound per
  // move, so the benchmark runs delay1 unless told otherwise.
  if (s.controller.empty()) s.controller = "delay1";
  const auto cfg = load_config(s);
  // 1. The demo maneuvers, one core, with the configured integrator and with the former one, in
  // turns in the same run.
  stack::StackConfig former = cfg;
  former.plant.integrator = former_integrator();
  double simulated = 0.0;
  double speed = 0.0, former_speed = 0.0;
  for (int round = 0; round < 3; ++round) {
    speed = std::max(speed, demo_speed(cfg, s, 1, simulated));
    former_speed = std::max(former_speed, demo_speed(former, s, 1, simulated));
  }
  std::printf("demo maneuvers, one core: %.1f s simulated: %.0fx real time with the plant's %s (best of 3)\n", simulated,
              speed, integrator_label(cfg.plant.integrator).c_str());
  std::printf("demo maneuvers, one core: %.1f s simulated: %.0fx real time with the former %s (best of 3)\n", simulated,
              former_speed, integrator_label(former.plant.integrator).c_str());
  std::printf("speed-up over the former integrator: %.2fx\n", speed / former_speed);
  // 2. A sweep on 1 thread and on every core, the same cases.
  const auto maneuvers = stack::select_moves(cfg, {"trolley"});
  const auto all = sweep_cases({default_controller(s)}, 0, cases, 7);
  const unsigned cores = default_jobs();
  double one = 0.0, many = 0.0, sim = 0.0;
  for (const unsigned jobs : {1U, cores}) {
    const auto start = Clock::now();
    const auto rows = run_sweep(cfg, s, maneuvers[0], all, jobs);
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
    sim = sweep_simulated_seconds(cfg, rows);
    (jobs == 1 ? one : many) = wall;
    std::printf("sweep of %d cases on %u thread%s: %.1f s simulated in %.2f s: %.0fx real time\n", cases, jobs,
                jobs == 1 ? "" : "s", sim, wall, sim / wall);
  }
  std::printf("sweep speed-up on %u cores: %.2fx (ideal %ux)\n", cores, one / many, cores);
  return 0;
}

// ---------------------------------------------------------------------------------------------
// converge, integrators

std::string figure_text(double value, int decimals) { return stack::format_number(value, decimals); }

void write_bound_trajectory(const fs::path& path, const optimal_control::MinimumTimeResult& r) {
  std::ofstream out(path);
  out << "t,x,phi,gamma,theta,x_dot,phi_dot,gamma_dot,theta_dot,L,L_dot,a_x,a_gamma,a_L,V_x,V_gamma\n";
  out.precision(10);
  for (const auto& n : r.nodes) {
    out << n.time;
    for (int i = 0; i < plant::kNumCoordinates; ++i) out << ',' << n.state.position[i];
    for (int i = 0; i < plant::kNumCoordinates; ++i) out << ',' << n.state.velocity[i];
    out << ',' << n.cable_length << ',' << n.cable_length_rate << ',' << n.trolley_acceleration << ','
        << n.second_acceleration << ',' << n.hoist_acceleration << ',' << n.trolley_voltage << ','
        << n.second_voltage << '\n';
  }
}

int bound(const Selection& s, int intervals, const std::string& out_dir) {
  const auto cfg = load_config(s);
  if (!out_dir.empty()) fs::create_directories(out_dir);
  std::ofstream summary;
  if (!out_dir.empty()) {
    summary.open(fs::path(out_dir) / "bound.csv");
    summary << "maneuver,T_star,T_star_refined,linear_profile,intervals,iterations,least_effort_iterations,"
               "solve_seconds,max_voltage,max_swing_deg\n";
  }
  std::printf("minimum time on the nonlinear model (%s crane; IPOPT, trapezoidal collocation)\n",
              common::to_string(cfg.facts.crane_kind));
  std::printf("(the trajectory: the least input and swing at (1 + %.2f) T*, or twice or four times the margin where "
              "IPOPT does not solve that; max |V| and max swing are its)\n",
              optimal_control::MinimumTimeProblem{}.least_effort_margin);
  std::printf("%-14s %9s %11s %9s %9s %6s %6s %8s %8s %10s\n", "maneuver", "T* [s]", "T*(2N) [s]", "change",
              "linear [s]", "iter", "effort", "solve s", "max |V|", "max swing");
  int failures = 0;
  for (const auto& m : stack::select_moves(cfg, s.maneuvers)) {
    const auto coarse = optimal_control::solve_minimum_time(stack::bound_problem(cfg, m, intervals));
    const auto fine = optimal_control::solve_minimum_time(stack::bound_problem(cfg, m, 2 * intervals));
    double max_voltage = 0.0;
    double max_swing = 0.0;
    for (const auto& n : fine.nodes) {
      max_voltage = std::max({max_voltage, std::abs(n.trolley_voltage), std::abs(n.second_voltage)});
      max_swing = std::max({max_swing, std::abs(n.state.position[plant::kInPlaneSwingIndex]),
                            std::abs(n.state.position[plant::kOutOfPlaneSwingIndex])});
    }
    if (!coarse.solved || !fine.solved) {
      std::printf("%-14s not solved: %s (N), %s (2N)\n", m.name.c_str(), coarse.status.c_str(), fine.status.c_str());
      ++failures;
      continue;
    }
    const double change = (fine.duration - coarse.duration) / coarse.duration;
    const std::string effort = fine.least_effort ? std::to_string(fine.effort_iterations) : "-";
    std::printf("%-14s %9.4f %11.4f %8.2f%% %9.4f %6d %6s %8.2f %8.2f %8.2f deg\n", m.name.c_str(), coarse.duration,
                fine.duration, 100.0 * change, coarse.initial_guess_duration, fine.iterations, effort.c_str(),
                fine.solve_seconds, max_voltage, max_swing * 180.0 / std::numbers::pi);
    if (!out_dir.empty()) {
      summary << m.name << ',' << coarse.duration << ',' << fine.duration << ',' << coarse.initial_guess_duration << ','
              << 2 * intervals << ',' << fine.iterations << ','
              << (fine.least_effort ? fine.effort_iterations : -1) << ',' << fine.solve_seconds << ',' << max_voltage
              << ',' << max_swing * 180.0 / std::numbers::pi << '\n';
      write_bound_trajectory(fs::path(out_dir) / (m.name + "_bound.csv"), fine);
    }
  }
  return failures == 0 ? 0 : 1;
}

int follow(const Selection& s, int intervals, bool corners, const std::vector<double>& mismatch,
           const optimal_control::FollowerParams& params, const std::string& out_dir, int moves, std::uint64_t seed,
           bool learn) {
  auto cfg = load_config(s);
  if (learn) cfg.state_estimator.swing_length.enabled = true;
  // The demo maneuvers, or with --moves the seeded random moves of crane_sim compare (those named).
  const auto maneuvers = stack::select_moves(cfg, s.maneuvers, moves, seed, moves <= 0);
  if (!out_dir.empty()) fs::create_directories(out_dir);
  const bool bridge = cfg.facts.crane_kind == common::CraneKind::overhead;
  struct Corner {
    std::string label;
    plant::PlantMismatch mismatch;
  };
  std::vector<Corner> runs{{"nominal", {}}};
  if (mismatch.size() == 3) {
    const plant::PlantMismatch m = plant::mismatch_from_factors(mismatch);
    runs = {{stack::mismatch_label(m), m}};
  }
  if (corners) {
    for (const auto& m : stack::mismatch_corners()) runs.push_back({stack::mismatch_label(m), m});
  }
  std::printf("the minimum-time trajectory followed in closed loop (%s crane; feedforward + time-varying LQR, "
              "friction compensation on)\n",
              common::to_string(cfg.facts.crane_kind));
  std::printf("(traj: the trajectory's duration, the least-effort solve's at 1.01-1.04 T* (1 + "
              "trajectory_planner.robust_margin with robust_length_range > 0), or T* where none solved)\n");
  std::printf("%-14s %-16s %8s %8s %8s %7s %10s %13s %13s %15s %6s %7s\n", "maneuver", "plant", "T* [s]",
              "traj [s]", "settle_s", "ratio", "pos_err_mm", bridge ? "bridge_err_mm" : "slew_err_mrad",
              "max_swing_deg", "resid_swing_deg", "max_V", "faults");
  int failures = 0;
  for (const auto& m : maneuvers) {
    for (const auto& corner : runs) {
      stack::FollowerRun run;
      run.maneuver = m;
      run.mismatch = corner.mismatch;
      run.intervals = intervals;
      run.follower = params;
      if (learn) run.first_move = stack::learning_move(cfg, m);
      const auto r = stack::run_follower(cfg, run);
      const auto& x = r.metrics;
      constexpr double deg = 180.0 / std::numbers::pi;
      std::printf("%-14s %-16s %8.4f %8.4f %8s %7s %10.2f %13.2f %13.2f %15.3f %6.2f %7u\n", m.name.c_str(),
                  corner.label.c_str(), r.bound.duration, r.bound.trajectory_duration,
                  stack::format_number(x.settle_time, 2).c_str(),
                  stack::format_number(x.settle_time / r.bound.duration, 2).c_str(), 1e3 * x.final_position_error,
                  bridge ? 1e3 * x.final_bridge_error : 1e3 * x.final_slew_error, deg * x.max_swing,
                  deg * x.residual_swing, x.max_voltage, r.latched_faults);
      if (r.latched_faults != 0) ++failures;
      if (r.unsolved_plans != 0) {
        std::printf("  (%llu goal(s) of this run not planned: the time-optimal profile ran, no swing feedback)\n",
                    static_cast<unsigned long long>(r.unsolved_plans));
      }
      if (!out_dir.empty()) {
        std::ofstream csv(fs::path(out_dir) / (m.name + "_follow_" + corner.label + ".csv"));
        stack::write_csv(csv, r.records, bridge);
      }
    }
  }
  return failures == 0 ? 0 : 1;
}

// The comparison of issue 32, item 3 (controller_comparison.hpp): the demo maneuvers and `moves`
// seeded random moves, each controller's settle time as a ratio to T*, on the nominal plant and,
// with `corners`, at the eight mismatch corners; one move (its bound and its runs) per thread. With
// `calibrate`, each corner's controllers first calibrated on its plant (swing_calibration_run.hpp):
// its runs follow a bound on the calibrated model, their ratio taken to the nominal T*. With `learn`,
// each run is made after a learning move on its plant (stack::learning_move) with the state
// estimator's swing_length on: the follower's move is planned on the pendulum it learnt.
int compare(const Selection& s, int moves, std::uint64_t seed, bool corners, bool calibrate, bool learn,
            const std::string& controllers_text, int intervals, unsigned jobs,
            const optimal_control::FollowerParams& follower, const std::string& out_dir) {
  auto cfg = load_config(s);
  if (learn) cfg.state_estimator.swing_length.enabled = true;
  const bool bridge = cfg.facts.crane_kind == common::CraneKind::overhead;
  const bool slews = cfg.facts.crane_kind == common::CraneKind::tower;
  const auto controllers = controllers_text.empty() ? stack::compared_controllers()
                                                    : stack::compared_controllers(split_list(controllers_text));
  const auto maneuvers = stack::select_moves(cfg, s.maneuvers, moves, seed, true);
  const auto demo_count = static_cast<std::size_t>(std::count_if(maneuvers.begin(), maneuvers.end(), [&](const auto& m) {
    return std::any_of(cfg.maneuvers.begin(), cfg.maneuvers.end(), [&](const auto& d) { return d.name == m.name; });
  }));
  std::vector<plant::PlantMismatch> plants{plant::PlantMismatch{}};
  if (corners) {
    const auto c = stack::mismatch_corners();
    plants.insert(plants.end(), c.begin(), c.end());
  }
  // One config per plant: the config itself, or calibrated on that corner's plant.
  std::vector<std::optional<stack::CalibratedStack>> calibrated(plants.size());
  if (calibrate) {
    std::atomic<std::size_t> next_plant{1};
    std::string calibration_error;
    std::mutex error_lock;
    const auto calibrate_plants = [&] {
      for (std::size_t p = next_plant++; p < plants.size(); p = next_plant++) {
        try {
          calibrated[p] = stack::calibrate_swing_on(cfg, plants[p], follower, intervals);
        } catch (const std::exception& error) {
          const std::lock_guard lock(error_lock);
          calibration_error = stack::mismatch_label(plants[p]) + ": " + error.what();
        }
      }
    };
    std::vector<std::thread> pool;
    for (unsigned t = 1; t < std::max(1U, jobs); ++t) pool.emplace_back(calibrate_plants);
    calibrate_plants();
    for (auto& t : pool) t.join();
    if (!calibration_error.empty()) throw std::runtime_error("calibration on " + calibration_error);
  }
  struct MoveResult {
    std::vector<stack::MoveComparison> runs;  // one per plant
    double solve_seconds{0.0};
    bool least_effort{false};  // the trajectory is the least-effort solve's (MinimumTimeResult::least_effort)
    bool robust{false};        // ... with the detuned pendulums (MinimumTimeResult::robust)
    bool asked_robust{false};  // the planner asked for them (trajectory_planner::plan_on_pendulum)
    std::string error;
  };
  std::vector<MoveResult> results(maneuvers.size());
  std::atomic<std::size_t> next{0};
  const auto start = std::chrono::steady_clock::now();
  const auto work = [&] {
    for (std::size_t i = next++; i < maneuvers.size(); i = next++) {
      try {
        const auto bound = stack::comparison_bound(cfg, maneuvers[i], intervals);
        results[i].solve_seconds = bound.solve_seconds;
        results[i].least_effort = bound.least_effort;
        results[i].robust = bound.robust;
        results[i].asked_robust = stack::plan_request_of(cfg, maneuvers[i]).robust_length_range > 0.0;
        for (std::size_t p = 0; p < plants.size(); ++p) {
          if (!calibrated[p]) {
            results[i].runs.push_back(stack::compare_move(
                cfg, maneuvers[i], bound, controllers, plants[p], intervals, follower, 0.0,
                learn ? std::optional(stack::learning_move(cfg, maneuvers[i])) : std::nullopt));
            continue;
          }
          const stack::StackConfig& own = calibrated[p]->config;
          try {
            const auto own_bound = stack::comparison_bound(own, maneuvers[i], intervals);
            results[i].runs.push_back(stack::compare_move(own, maneuvers[i], own_bound, controllers, plants[p],
                                                          intervals, follower, bound.duration));
          } catch (const std::exception& error) {  // that corner's bound alone: its runs are errors
            results[i].runs.push_back(stack::failed_comparison(maneuvers[i], plants[p], controllers, bound.duration,
                                                               std::string("calibrated: ") + error.what()));
          }
          results[i].runs.back().calibrated = true;
        }
      } catch (const std::exception& error) {
        results[i].error = error.what();
      }
    }
  };
  std::vector<std::thread> threads;
  for (unsigned t = 1; t < std::max(1U, jobs); ++t) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  std::printf("controllers against the minimum-time bound T* (%s crane, %zu demo maneuvers and %d random moves, seed "
              "%llu; friction compensation on; settle: 5 mm, 0.005 rad, 0.5 deg)\n",
              common::to_string(cfg.facts.crane_kind), demo_count, moves, static_cast<unsigned long long>(seed));
  if (calibrate) {
    std::printf("each corner's controllers calibrated on its plant ('+cal'; the nominal T* kept): the fitted "
                "equivalent pendulum a L + c against the plant's\n");
    for (std::size_t p = 1; p < plants.size(); ++p) {
      const auto& f = calibrated[p]->fit;
      const double configured = cfg.facts.crane.cable_length;
      std::printf("  %-16s on %-10s a %.4f  c %+.4f m  -> %.4f m at L %.3f m (the plant's %.4f m), rms %.2e rad\n",
                  stack::mismatch_label(plants[p]).c_str(), calibrated[p]->maneuver.c_str(), f.length_scale,
                  f.length_offset, f.length_scale * configured + f.length_offset, configured,
                  plants[p].cable_length_factor * configured, f.rms_residual);
    }
  }
  std::printf("settle time / T* per controller ('-': not settled within the record, '!': a supervisor fault or "
              "the brakes)\n%-12s %-16s %8s", "move", "plant", "T* [s]");
  for (const auto& c : controllers) std::printf(" %12s", c.name.c_str());
  std::printf("\n");
  int errors = 0;
  std::vector<stack::MoveComparison> demo_nominal, random_nominal, at_corners;
  std::vector<double> solve_times;
  std::size_t least_effort = 0;
  std::size_t robust = 0;
  std::size_t asked_robust = 0;
  std::string slowest;  // the move of the longest solve
  double slowest_seconds = -1.0;
  for (std::size_t i = 0; i < maneuvers.size(); ++i) {
    const MoveResult& r = results[i];
    if (!r.error.empty()) {
      std::printf("%-13s %s\n", maneuvers[i].name.c_str(), r.error.c_str());
      ++errors;
      continue;
    }
    solve_times.push_back(r.solve_seconds);
    if (r.solve_seconds > slowest_seconds) {
      slowest_seconds = r.solve_seconds;
      slowest = maneuvers[i].name;
    }
    if (r.least_effort) ++least_effort;
    if (r.robust) ++robust;
    if (r.asked_robust) ++asked_robust;
    for (const auto& run : r.runs) {
      const bool nominal = stack::mismatch_label(run.mismatch) == "nominal";
      (nominal ? (i < demo_count ? demo_nominal : random_nominal) : at_corners).push_back(run);
      const std::string label = stack::mismatch_label(run.mismatch) + (run.calibrated ? "+cal" : "") +
                                (run.learnt ? "+learn" : "");
      std::printf("%-13s %-16s %8.4f", maneuvers[i].name.c_str(), label.c_str(), run.bound);
      for (const auto& o : run.outcomes) {
        if (!o.error.empty()) ++errors;
        const bool faulted = o.latched_faults != 0 || o.braked_cycles != 0;
        std::printf(" %11s%s", o.error.empty() ? stack::format_number(o.ratio, 2).c_str() : "error", faulted ? "!" : " ");
      }
      std::printf("\n");
    }
  }
  constexpr double deg = 180.0 / std::numbers::pi;
  const auto print_summary = [&](const char* title, const std::vector<stack::MoveComparison>& runs) {
    if (runs.empty()) return;
    std::printf("\n%s (%zu runs per controller)\n%-13s %7s %7s %8s %7s %7s %16s %12s %15s %6s\n", title, runs.size(),
                "controller", "median", "worst", "settled", "faults", "errors", "median_resid_deg",
                bridge ? "worst_pos_mm*" : "worst_pos_mm", "worst_slew_mrad", "peak_V");
    for (const auto& x : stack::summarize(runs)) {
      std::printf("%-13s %7s %7s %4d/%-3d %7d %7d %16.3f %12.2f %15s %6.2f\n", x.controller.c_str(),
                  stack::format_number(x.median_ratio, 2).c_str(), stack::format_number(x.worst_ratio, 2).c_str(),
                  x.settled, x.runs, x.faulted, x.failed, deg * x.median_residual_swing, 1e3 * x.worst_position_error,
                  slews ? stack::format_number(1e3 * x.worst_slew_error, 2).c_str() : "-", x.peak_voltage);
    }
    if (bridge) std::printf("(* the trolley's or the bridge's, the larger)\n");
  };
  if (learn) {
    // What the follower's moves were planned on, per plant: the pendulum learnt in the first move.
    std::printf("\nthe follower's plans after the learning move: the pendulum a L + c at L %.3f m, per plant "
                "(min / median / max over its moves; the plant's own: L x its factor)\n",
                cfg.facts.crane.cable_length);
    for (const auto& plant : plants) {
      std::vector<double> lengths;
      for (const auto& r : results) {
        for (const auto& run : r.runs) {
          if (stack::mismatch_label(run.mismatch) != stack::mismatch_label(plant)) continue;
          for (const auto& o : run.outcomes) {
            if (o.controller == "follower" && o.error.empty()) {
              lengths.push_back(trajectory_planner::equivalent_swing_length(o.planned_swing, cfg.facts.crane.cable_length));
            }
          }
        }
      }
      if (lengths.empty()) continue;
      std::printf("  %-16s %.4f / %.4f / %.4f m (the plant's %.4f m)\n", stack::mismatch_label(plant).c_str(),
                  stack::nearest_rank_quantile(lengths, 0.0), stack::nearest_rank_quantile(lengths, 0.5),
                  stack::nearest_rank_quantile(lengths, 1.0), plant.cable_length_factor * cfg.facts.crane.cable_length);
    }
  }
  print_summary("demo maneuvers, nominal plant: settle / T*", demo_nominal);
  print_summary("random moves, nominal plant: settle / T*", random_nominal);
  print_summary(calibrate ? "every move at the eight corners (L, m x0.8/1.2, friction x0.7/1.3), each calibrated on its "
                            "plant: settle / nominal T*"
                          : "every move at the eight corners (L, m x0.8/1.2, friction x0.7/1.3): settle / T*",
                at_corners);
  // Goals the planner could not plan ran the time-optimal profile (no swing feedback under the
  // follower): where a run had one, it is not the follower's run.
  std::size_t unplanned_runs = 0, runs_counted = 0;
  for (const auto& r : results) {
    for (const auto& run : r.runs) {
      for (const auto& o : run.outcomes) {
        ++runs_counted;
        if (o.unsolved_plans != 0) ++unplanned_runs;
      }
    }
  }
  std::printf("\nruns with a goal the planner did not solve (the time-optimal profile ran instead): %zu of %zu\n",
              unplanned_runs, runs_counted);
  std::sort(solve_times.begin(), solve_times.end());
  if (!solve_times.empty()) {
    std::printf("\nbound solve (IPOPT, %d intervals, both solves): median %.2f s, max %.2f s (%s) over %zu moves; "
                "%.1f s wall on %u thread(s); the least-effort trajectory on %zu of them (the others the minimum-time "
                "solve's)\n",
                intervals, stack::nearest_rank_quantile(solve_times, 0.5), solve_times.back(), slowest.c_str(),
                solve_times.size(), wall, std::max(1U, jobs), least_effort);
    if (cfg.trajectory_planner.robust_length_range > 0.0) {
      std::printf("robust to the pendulum's length (trajectory_planner.robust_length_range %.2f): %zu of the %zu "
                  "moves asked for it (robust_within_radius %.2f m; 0: all); the others over the robust solve's %d "
                  "IPOPT iterations, planned as with it off\n",
                  cfg.trajectory_planner.robust_length_range, robust, asked_robust,
                  cfg.trajectory_planner.robust_within_radius,
                  optimal_control::MinimumTimeProblem{}.detuned_max_iterations);
    }
  }
  if (!out_dir.empty()) {
    fs::create_directories(out_dir);
    std::ofstream csv(fs::path(out_dir) / "compare.csv");
    csv << "move,plant,T_star_s,controller,settle_s,ratio,pos_err_mm,slew_err_mrad,bridge_err_mm,max_swing_deg,"
           "resid_swing_deg,max_V,latched_faults,braked_cycles,unsolved_plans,error\n";
    csv.precision(6);
    for (const auto& r : results) {
      for (const auto& run : r.runs) {
        for (const auto& o : run.outcomes) {
          const auto& x = o.metrics;
          csv << run.maneuver.name << ',' << stack::mismatch_label(run.mismatch) << (run.calibrated ? "+cal" : "")
              << (run.learnt ? "+learn" : "")
              << ',' << run.bound << ','
              << o.controller << ',' << x.settle_time << ',' << o.ratio << ',' << 1e3 * x.final_position_error << ','
              << 1e3 * x.final_slew_error << ',' << 1e3 * x.final_bridge_error << ',' << deg * x.max_swing << ','
              << deg * x.residual_swing << ',' << x.max_voltage << ',' << o.latched_faults << ',' << o.braked_cycles
              << ',' << o.unsolved_plans << ",\"" << o.error << "\"\n";
        }
      }
    }
  }
  return errors == 0 ? 0 : 1;
}

int converge(const Selection& s, const plant::IntegratorSettings& reference) {
  const auto cfg = load_config(s);
  std::printf("convergence study: %s against the reference %s\n", integrator_label(cfg.plant.integrator).c_str(),
              integrator_label(reference).c_str());
  const auto cases = stack::run_convergence_study(cfg, demo_runs(cfg, s), reference);
  int disagreements = 0;
  for (const auto& c : cases) {
    std::printf("\n%s %s  (friction events %ld / %ld; steps %ld, right-hand sides %ld, root functions %ld, restarts %ld)\n",
                c.maneuver.c_str(), c.friction_compensation ? "comp_on" : "comp_off", c.friction_events,
                c.reference_friction_events, c.work.steps, c.work.right_hand_sides, c.work.root_evaluations,
                c.work.restarts);
    std::printf("  %-16s %12s %12s %12s %s\n", "figure", "settings", "reference", "difference", "agrees");
    for (const auto& f : c.figures) {
      const double difference = f.at_settings - f.at_reference;
      std::printf("  %-16s %12s %12s %12.3g %s\n", f.name.c_str(), figure_text(f.at_settings, f.decimals + 3).c_str(),
                  figure_text(f.at_reference, f.decimals + 3).c_str(), std::isfinite(difference) ? difference : 0.0,
                  f.agrees() ? "yes" : "NO");
      if (!f.agrees()) ++disagreements;
    }
    const auto show = [](const char* what, const stack::StateDifference& d) {
      std::printf("  %-38s position %.2e m, angle %.2e rad, velocity %.2e m/s, rate %.2e rad/s\n", what, d.position,
                  d.angle, d.velocity, d.angular_rate);
    };
    show("integration error (same inputs):", c.integration_error);
    show("closed-loop difference (stack re-run):", c.closed_loop_difference);
  }
  std::printf("\n%zu runs, %d printed figures differ from the reference by more than half their last digit\n",
              cases.size(), disagreements);
  return disagreements == 0 ? 0 : 1;
}

int integrators(const Selection& s) {
  const auto cfg = load_config(s);
  // The drive inputs of the demo runs (closed loop at the configured settings), replayed open loop.
  struct Recorded {
    plant::SimulatorParameters parameters;
    std::vector<plant::DriveInput> inputs;
    std::vector<plant::PlantState> reference;
  };
  std::vector<Recorded> recorded;
  double simulated = 0.0;
  const auto reference = stack::reference_integrator_settings();
  for (auto run : demo_runs(cfg, s)) {
    run.record_plant = true;
    auto result = stack::run_in_process(cfg, run);
    Recorded r{result.plant_parameters, std::move(result.plant_inputs), {}};
    plant::SimulatorParameters p = r.parameters;
    p.integrator = reference;
    r.reference = stack::replay_plant(p, r.inputs);
    simulated += static_cast<double>(r.inputs.size()) * cfg.facts.sample_period;
    recorded.push_back(std::move(r));
  }
  std::printf("the plant alone on the drive inputs of %zu demo runs (%.1f s simulated), against %s\n", recorded.size(),
              simulated, integrator_label(reference).c_str());
  std::printf("%-15s %8s %12s %12s %12s %14s %12s %12s\n", "method", "rtol", "max_pos_m", "max_angle_rad", "max_vel",
              "rhs_per_s", "us_per_s", "x_real_time");
  for (const auto method : {plant::IntegrationMethod::bdf, plant::IntegrationMethod::adams,
                            plant::IntegrationMethod::dormand_prince, plant::IntegrationMethod::verner}) {
    for (const double rtol : {1e-6, 1e-7, 1e-8, 1e-9, 1e-10}) {
      stack::StateDifference worst;
      long evaluations = 0;
      double wall = 0.0;
      for (const auto& r : recorded) {
        plant::SimulatorParameters p = r.parameters;
        p.integrator.method = method;
        p.integrator.relative_tolerance = rtol;
        p.integrator.absolute_tolerance = rtol * 1e-2;
        plant::CraneSimulator simulator(p);
        std::vector<plant::PlantState> states;
        states.reserve(r.inputs.size());
        const auto start = Clock::now();
        for (const auto& input : r.inputs) {
          (void)simulator.step(input);
          states.push_back(simulator.state());
        }
        wall += std::chrono::duration<double>(Clock::now() - start).count();
        const auto work = simulator.integrator_work();
        evaluations += work.right_hand_sides + work.root_evaluations;
        const auto d = stack::max_state_difference(states, r.reference);
        worst.position = std::max(worst.position, d.position);
        worst.angle = std::max(worst.angle, d.angle);
        worst.velocity = std::max({worst.velocity, d.velocity, d.angular_rate});
      }
      std::printf("%-15s %8.0e %12.2e %12.2e %12.2e %14.0f %12.1f %12.0f\n",
                  std::string(plant::integration_method_name(method)).c_str(), rtol, worst.position, worst.angle,
                  worst.velocity, static_cast<double>(evaluations) / simulated, wall / simulated * 1e6, simulated / wall);
    }
  }
  return 0;
}

int gantry_gains(double full_forward_gain) {
  std::printf("%s\n", stack::format_gain_table(stack::gains_over_cable_length({0.5, 1.0, 2.0, 3.0, 4.0, 5.0}),
                                               "Figure 3.5: partial-state gains over the cable length, m_t = 0, K_mx = 1.34")
                          .c_str());
  std::printf("%s\n", stack::format_gain_table(stack::gains_over_mass_ratio({0.0, 1.0, 2.0, 3.0, 4.0, 5.0}),
                                               "Figure 3.6: partial-state gains over the load ratio m_t, L = 1 m, K_mx = 1.34")
                          .c_str());
  std::vector<stack::GantryStepResult> results;
  for (const stack::GantryStepCase& c : stack::section_322_cases(full_forward_gain)) {
    results.push_back(stack::run_gantry_step(c));
  }
  std::printf("Figures 3.7 and 3.8: 1 m trolley step on the gantry crane (frictionless, 100 Hz, true state fed back),\n"
              "full-state law with K = %g V/m; settle: |x - x_r| < 5 mm and |phi| < 0.5 deg for good\n%s",
              full_forward_gain, stack::format_step_table(results).c_str());
  return 0;
}

// The follower's weights and friction scales (optimal_control::FollowerParams), for follow and compare.
void add_follower_options(CLI::App* cmd, optimal_control::FollowerParams& params) {
  // Bryson's acceptable deviations, along the trajectory ("--NAME-weight") and at the target ("--hold-NAME-weight").
  const auto add_weights = [cmd](const std::string& prefix, const std::string& where,
                                 optimal_control::FollowerWeights& w) {
    const std::pair<const char*, double*> fields[] = {
        {"position", &w.position},   {"second-position", &w.second_position}, {"swing", &w.swing},
        {"out-of-plane-swing", &w.out_of_plane_swing}, {"speed", &w.speed}, {"swing-rate", &w.swing_rate},
        {"voltage", &w.voltage}};
    const char* units[] = {"(trolley) [m]", "(slew [rad] or bridge [m])", "(in plane) [rad]", "[rad]",
                           "[m/s or rad/s]", "[rad/s]", "[V]"};
    for (std::size_t i = 0; i < std::size(fields); ++i) {
      cmd->add_option("--" + prefix + fields[i].first + "-weight", *fields[i].second,
                      where + "acceptable " + std::string(fields[i].first) + " deviation " + units[i])
          ->check(CLI::PositiveNumber);
    }
  };
  add_weights("", "the LQR's ", params.weights);
  add_weights("hold-", "at the target: ", params.hold.weights);
  cmd->add_option("--trajectory-sliding-friction-scale", params.trajectory_sliding_friction_scale,
                  "along the trajectory: the fraction of the sliding friction compensated on the measured speed; "
                  "the rest fed forward at the reference speed [-]")
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--hold-slew-sideways", params.hold.slew_sideways,
                  "at the target: the slew held no tighter than this sideways displacement of the trolley "
                  "(radius times angle; a tower crane) [m]")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--hold-sliding-friction-scale", params.hold.sliding_friction_scale,
                  "at the target: the fraction of the plant's sliding friction compensated, the plant's estimated "
                  "along the move [-]")
      ->check(CLI::Range(0.0, 1.0));
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_sim: the crane stack in one process (no DDS): the demo maneuvers, mismatch sweeps, speed"};
  app.require_subcommand(1);
  Selection s;
  std::string out_dir;
  const auto common_options = [&](CLI::App* cmd) {
    cmd->add_option("--config", s.config_path, "crane configuration (YAML)")->required()->check(CLI::ExistingFile);
    cmd->add_option("--controller", s.controller,
                    "none | pd | delay1 | delay2 | fuzzy | gain_scheduling_partial | gain_scheduling_full | auto | "
                    "follower (as crane_demo; default follower, auto with --profile time_optimal, delay1 with "
                    "another --profile)");
    cmd->add_option("--profile", s.profile,
                    "step | trapezoid | zv | zvd | ei | time_optimal | minimum_time (as crane_demo)")
        ->check(CLI::IsMember({"step", "trapezoid", "zv", "zvd", "ei", "time_optimal", "minimum_time"}))
        ->each([&](const std::string&) { s.profile_given = true; });
    cmd->add_option("--maneuver", s.maneuvers,
                    "maneuver names (default: all; sweep: trolley; follow and compare: also random_0 .. of --moves)");
    cmd->add_flag("--acceleration-feedforward", s.acceleration_feedforward,
                  "tracking adds the reference acceleration (beyond the dissertation)");
    cmd->add_option("--integrator", s.integrator,
                    "the plant's integrator: dormand_prince | verner | adams | bdf (default: the config's)");
    cmd->add_option("--rtol", s.rtol, "the plant's relative tolerance (default: the config's)")->check(CLI::Range(1e-14, 1e-3));
    cmd->add_option("--atol", s.atol, "the plant's absolute tolerance (default: the config's)")->check(CLI::Range(1e-16, 1e-3));
  };
  auto* demo_cmd = app.add_subcommand("demo", "the demo maneuvers: crane_demo's table and CSV files, in one process");
  common_options(demo_cmd);
  demo_cmd->add_option("--friction-compensation", s.compensation, "on | off | both")
      ->check(CLI::IsMember({"on", "off", "both"}));
  demo_cmd->add_option("--out", out_dir, "write <maneuver>_fc_<on|off>.csv here");
  demo_cmd->add_option("--moves", s.moves, "seeded random moves besides the demo maneuvers (compare's; --maneuver random_N picks)")
      ->check(CLI::Range(0, 1000));
  demo_cmd->add_option("--seed", s.seed, "the random moves' seed");
  std::vector<double> demo_mismatch;
  demo_cmd->add_option("--mismatch", demo_mismatch,
                       "the plant's cable length, load mass and friction factors (crane_demo's --plant-cable-length-"
                       "factor, --plant-load-mass-factor, --plant-friction-factor)")
      ->expected(3)
      ->check(CLI::Range(0.0, 10.0));

  auto* sweep_cmd = app.add_subcommand("sweep", "plant mismatches over the controllers on every core, with heat maps");
  common_options(sweep_cmd);
  std::string controllers = "delay1,delay2,pd,fuzzy,none";
  int grid = 0;
  int random = 0;
  unsigned seed = 1;
  unsigned jobs = 0;
  std::string plot_script, python = "/usr/bin/python3";
  sweep_cmd->add_option("--controllers", controllers, "comma-separated controller names (default delay1,delay2,pd,fuzzy,none)");
  auto* grid_opt = sweep_cmd->add_option("--grid", grid, "N: an N x N grid of cable length x load mass factors")
                       ->check(CLI::Range(1, 100));
  sweep_cmd->add_option("--random", random, "N: N seeded random mismatches of all four kinds")
      ->check(CLI::Range(1, 100000))
      ->excludes(grid_opt);
  sweep_cmd->add_option("--seed", seed, "seed of --random");
  sweep_cmd->add_option("--jobs", jobs, "threads (default: every core)");
  sweep_cmd->add_option("--out", out_dir, "sweep.csv and the heat maps here")->required();
  sweep_cmd->add_option("--plot-script", plot_script, "matplotlib script that draws the heat maps");
  sweep_cmd->add_option("--python", python, "python interpreter with matplotlib");

  auto* bench_cmd = app.add_subcommand("bench", "speed: the demo on one core, a sweep on 1 and on every core");
  common_options(bench_cmd);
  int cases = 40;
  bench_cmd->add_option("--cases", cases, "sweep cases of the scaling figure")->check(CLI::Range(1, 100000));

  auto* converge_cmd = app.add_subcommand("converge", "the convergence study: the demo runs at the plant's settings and at a reference");
  common_options(converge_cmd);
  auto reference = stack::reference_integrator_settings();
  std::string reference_method{plant::integration_method_name(reference.method)};
  converge_cmd->add_option("--reference-integrator", reference_method, "the reference's method (default bdf)");
  converge_cmd->add_option("--reference-rtol", reference.relative_tolerance, "the reference's rtol (default 1e-12)")
      ->check(CLI::Range(1e-14, 1e-3));
  converge_cmd->add_option("--reference-atol", reference.absolute_tolerance, "the reference's atol (default 1e-14)")
      ->check(CLI::Range(1e-16, 1e-3));
  auto* integrators_cmd = app.add_subcommand("integrators", "the integrators compared on the demo runs' inputs (the plant alone)");
  common_options(integrators_cmd);

  auto* bound_cmd = app.add_subcommand("bound", "the minimum time of each maneuver on the nonlinear model (IPOPT)");
  common_options(bound_cmd);
  int intervals = 100;
  bound_cmd->add_option("--intervals", intervals, "collocation intervals N (also solved on 2N)")->check(CLI::Range(4, 1000));
  bound_cmd->add_option("--out", out_dir, "write bound.csv and <maneuver>_bound.csv here");

  auto* follow_cmd = app.add_subcommand("follow", "each maneuver's minimum-time trajectory followed in closed loop");
  common_options(follow_cmd);
  int follow_intervals = 200;
  bool corners = false;
  follow_cmd->add_option("--intervals", follow_intervals, "collocation intervals of the bound")->check(CLI::Range(4, 2000));
  follow_cmd->add_flag("--corners", corners, "also the eight +-20 % length and mass, +-30 % friction corners");
  follow_cmd->add_option("--out", out_dir, "write <maneuver>_follow_<plant>.csv here");
  std::vector<double> mismatch;
  int follow_moves = 0;
  std::uint64_t follow_seed = 1;
  follow_cmd->add_option("--moves", follow_moves, "N seeded random moves (crane_sim compare's) instead of the demo maneuvers")
      ->check(CLI::Range(0, 1000));
  follow_cmd->add_option("--seed", follow_seed, "the random moves' seed");
  follow_cmd->add_option("--mismatch", mismatch, "one plant instead of the nominal: cable length, load mass and friction factors")
      ->expected(3)->check(CLI::Range(0.1, 10.0));
  bool follow_learn = false;
  follow_cmd->add_flag("--learn", follow_learn,
                       "each run after a learning move on its plant, the state estimator's swing_length on (as compare's)");
  optimal_control::FollowerParams follower_params;
  add_follower_options(follow_cmd, follower_params);

  auto* compare_cmd = app.add_subcommand("compare", "every controller's settle time against T*: demo and seeded random moves");
  common_options(compare_cmd);
  int compare_moves = 20;
  std::uint64_t compare_seed = 1;
  bool compare_corners = false;
  bool compare_calibrate = false;
  std::string compare_controllers;
  int compare_intervals = 200;
  unsigned compare_jobs = default_jobs();
  compare_cmd->add_option("--moves", compare_moves, "seeded random moves besides the demo maneuvers")->check(CLI::Range(0, 1000));
  compare_cmd->add_option("--seed", compare_seed, "the random moves' seed");
  compare_cmd->add_flag("--corners", compare_corners, "also at the eight +-20 % length and mass, +-30 % friction corners");
  compare_cmd->add_flag("--calibrate", compare_calibrate,
                        "with --corners: each corner's controllers calibrated on its plant first (a recorded demo "
                        "maneuver, the swing fitted; tower and gantry cranes)")
      ->needs("--corners");
  bool compare_learn = false;
  compare_cmd->add_flag("--learn", compare_learn,
                        "each run made after a learning move on its plant (the first demo maneuver backwards to the "
                        "move's start) with state_estimator.swing_length on: the follower plans the pendulum it learnt")
      ->excludes("--calibrate");
  compare_cmd->add_option("--controllers", compare_controllers,
                          "comma-separated: follower,delay1,delay2,time_optimal,zv,zvd (default: all)");
  compare_cmd->add_option("--intervals", compare_intervals, "collocation intervals of the bound")->check(CLI::Range(4, 2000));
  compare_cmd->add_option("--jobs", compare_jobs, "threads (default: every core)")->check(CLI::Range(1, 256));
  compare_cmd->add_option("--out", out_dir, "write compare.csv here");
  optimal_control::FollowerParams compare_follower;
  add_follower_options(compare_cmd, compare_follower);

  auto* gantry_cmd = app.add_subcommand("gantry-gains", "section 3.2.2 on the gantry: Figures 3.5-3.6 gains, 3.7-3.8 rows");
  double full_forward_gain = 3.0;
  gantry_cmd->add_option("--K", full_forward_gain, "forward gain K [V/m] of the full-state law (Figure 3.8), > 0")
      ->check(CLI::PositiveNumber);
  CLI11_PARSE(app, argc, argv);
  try {
    if (*gantry_cmd) return gantry_gains(full_forward_gain);
    if (*demo_cmd) {
      if (demo_mismatch.size() == 3) s.mismatch = plant::mismatch_from_factors(demo_mismatch);
      return demo(s, out_dir);
    }
    if (*sweep_cmd) {
      if (grid == 0 && random == 0) random = 200;
      return sweep(s, controllers, grid, random, seed, jobs, out_dir, plot_script, python);
    }
    if (*bench_cmd) return bench(s, cases);
    if (*converge_cmd) {
      reference.method = plant::parse_integration_method(reference_method, "--reference-integrator");
      return converge(s, reference);
    }
    if (*integrators_cmd) return integrators(s);
    if (*bound_cmd) return bound(s, intervals, out_dir);
    if (*compare_cmd) {
      return compare(s, compare_moves, compare_seed, compare_corners, compare_calibrate, compare_learn, compare_controllers,
                     compare_intervals, compare_jobs, compare_follower, out_dir);
    }
    if (*follow_cmd) return follow(s, follow_intervals, corners, mismatch, follower_params, out_dir, follow_moves, follow_seed,
                                       follow_learn);
  } catch (const std::exception& error) {
    std::fprintf(stderr, "crane_sim: %s\n", error.what());
    return 1;
  }
  return 0;
}
