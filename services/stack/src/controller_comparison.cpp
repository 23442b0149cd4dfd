#include "crane/stack/controller_comparison.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <stdexcept>

#include "crane/stack/follower_run.hpp"
#include "crane/stack/in_process_stack.hpp"
#include "crane/trajectory_planner/trajectory_planner.hpp"

namespace crane::stack {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// [s] a rest-to-rest trapezoid (or triangle) over `distance` at `velocity` and `acceleration`.
double trapezoid_time(double distance, double velocity, double acceleration) {
  distance = std::abs(distance);
  if (distance * acceleration > velocity * velocity) return distance / velocity + velocity / acceleration;
  return 2.0 * std::sqrt(distance / acceleration);
}

}  // namespace

std::vector<ComparedController> compared_controllers() {
  using Request = protocol::MoveRequest;
  return {
      {"follower", true, "", false, Request::PROFILE_TRAPEZOID},
      {"delay1", false, "delay1", false, Request::PROFILE_TRAPEZOID},
      {"delay2", false, "delay2", false, Request::PROFILE_TRAPEZOID},
      {"time_optimal", false, "none", true, Request::PROFILE_TIME_OPTIMAL},
      {"zv", false, "none", false, Request::PROFILE_ZV},
      {"zvd", false, "none", false, Request::PROFILE_ZVD},
  };
}

std::vector<ComparedController> compared_controllers(const std::vector<std::string>& names) {
  const auto all = compared_controllers();
  std::vector<ComparedController> chosen;
  for (const std::string& name : names) {
    const auto it = std::find_if(all.begin(), all.end(), [&](const ComparedController& c) { return c.name == name; });
    if (it == all.end()) {
      std::string known;
      for (const auto& c : all) known += (known.empty() ? "" : ", ") + c.name;
      throw std::invalid_argument("unknown controller '" + name + "' (known: " + known + ")");
    }
    chosen.push_back(*it);
  }
  return chosen;
}

std::vector<ManeuverConfig> select_moves(const StackConfig& cfg, const std::vector<std::string>& names, int random_count,
                                         std::uint64_t seed, bool demo_maneuvers) {
  std::vector<ManeuverConfig> pool;
  if (demo_maneuvers) pool = cfg.maneuvers;
  if (random_count > 0) {
    const auto random = random_moves(cfg, random_count, seed);
    pool.insert(pool.end(), random.begin(), random.end());
  }
  for (const auto& name : names) {
    if (std::none_of(pool.begin(), pool.end(), [&](const auto& m) { return m.name == name; })) {
      const std::string random = "the " + std::to_string(random_count) + " random moves (random_0 .. random_" +
                                 std::to_string(random_count - 1) + ", --moves)";
      std::string is = "' is not a move: no demo maneuvers and no random moves asked for";
      if (demo_maneuvers && random_count > 0) {
        is = "' is neither a demo maneuver of the configuration nor one of " + random;
      } else if (demo_maneuvers) {
        is = "' is not a demo maneuver of the configuration";
      } else if (random_count > 0) {
        is = "' is not one of " + random;
      }
      throw std::invalid_argument("--maneuver '" + name + is);
    }
  }
  if (names.empty()) return pool;
  std::vector<ManeuverConfig> out;  // in the pool's order: the demo maneuvers first
  for (const auto& m : pool) {
    if (std::find(names.begin(), names.end(), m.name) != names.end()) out.push_back(m);
  }
  return out;
}

std::vector<ManeuverConfig> random_moves(const StackConfig& cfg, int count, std::uint64_t seed, double record_factor) {
  if (count < 1 || count > 1000) {
    throw std::invalid_argument("random moves: count " + std::to_string(count) + " outside [1, 1000]");
  }
  if (!(record_factor >= 1.0)) throw std::invalid_argument("random moves: record_factor below 1");
  if (cfg.maneuvers.empty()) {
    throw std::invalid_argument("random moves: the config has no demo maneuver to take the rated limits from");
  }
  const ManeuverConfig& rated = cfg.maneuvers.front();
  const auto& planner = cfg.trajectory_planner;
  const common::CraneKind kind = cfg.facts.crane_kind;
  const double cable = cfg.facts.crane.cable_length;
  const double gravity = cfg.facts.crane.gravity;
  const trajectory_planner::AxisLimits hoist = trajectory_planner::MoveGoal{}.cable_limits;

  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto between = [&](double lo, double hi) { return lo + (hi - lo) * unit(rng); };
  // A start and a target anywhere in [lo, hi], at least a fifth of the range apart.
  const auto travel = [&](double lo, double hi, const char* axis) {
    if (!(hi - lo > 0.0)) throw std::invalid_argument(std::string("random moves: the planner's ") + axis + " range is empty");
    const double start = between(lo, hi);
    double target = between(lo, hi);
    while (std::abs(target - start) < 0.2 * (hi - lo)) target = between(lo, hi);
    return std::pair{start, target};
  };

  std::vector<ManeuverConfig> moves;
  for (int i = 0; i < count; ++i) {
    ManeuverConfig m = rated;
    m.name = "random_" + std::to_string(i);
    std::tie(m.initial_trolley_position, m.trolley_target) =
        travel(planner.trolley_min_position, planner.trolley_max_position, "trolley");
    double linear_time = trapezoid_time(m.trolley_target - m.initial_trolley_position, m.trolley_max_velocity,
                                        m.trolley_max_acceleration);
    m.initial_slew_angle = m.slew_target = 0.0;
    m.initial_bridge_position = m.bridge_target = rated.initial_bridge_position;
    if (kind == common::CraneKind::tower) {
      const double lo = planner.slew_min_angle, hi = planner.slew_max_angle;
      if (!(hi - lo > std::numbers::pi / 9.0)) throw std::invalid_argument("random moves: the planner's slew range is under 20 deg");
      for (;;) {
        const double start = between(lo, hi);
        const double delta = (unit(rng) < 0.5 ? -1.0 : 1.0) * between(std::numbers::pi / 18.0, std::numbers::pi);
        const double target = start + delta >= lo && start + delta <= hi ? start + delta : start - delta;
        if (target < lo || target > hi) continue;
        m.initial_slew_angle = start;
        m.slew_target = target;
        break;
      }
      linear_time = std::max(linear_time, trapezoid_time(m.slew_target - m.initial_slew_angle, m.slew_max_velocity,
                                                         m.slew_max_acceleration));
    } else if (kind == common::CraneKind::overhead) {
      std::tie(m.initial_bridge_position, m.bridge_target) =
          travel(planner.bridge_min_position, planner.bridge_max_position, "bridge");
      linear_time = std::max(linear_time, trapezoid_time(m.bridge_target - m.initial_bridge_position,
                                                         m.bridge_max_velocity, m.bridge_max_acceleration));
    }
    m.cable_length_target = cable;
    if (unit(rng) < 0.25) {
      const double lo = std::max(planner.cable_min_length, 0.5 * cable);
      const double hi = std::min(planner.cable_max_length, 1.5 * cable);
      double target = between(lo, hi);
      while (std::abs(target - cable) < 0.1 * cable) target = between(lo, hi);
      m.cable_length_target = target;
      linear_time =
          std::max(linear_time, trapezoid_time(target - cable, hoist.max_velocity, hoist.max_acceleration));
    }
    const double period = 2.0 * std::numbers::pi * std::sqrt(m.cable_length_target / gravity);
    m.duration = std::ceil(record_factor * linear_time + 10.0 * period);
    moves.push_back(m);
  }
  return moves;
}

optimal_control::MinimumTimeResult comparison_bound(const StackConfig& cfg, const ManeuverConfig& m, int intervals) {
  auto bound = optimal_control::solve_minimum_time(follower_problem(cfg, m, intervals));
  if (!bound.solved) throw std::runtime_error("the bound of " + m.name + " was not solved (" + bound.status + ")");
  return bound;
}

namespace {

// A run that could not be made: its error, NaN figures.
ControllerOutcome failed_outcome(const std::string& controller, const std::string& error) {
  ControllerOutcome o;
  o.controller = controller;
  o.error = error;
  o.metrics = ManeuverMetrics{kNaN, kNaN, kNaN, kNaN, kNaN, kNaN, kNaN};
  o.ratio = kNaN;
  return o;
}

}  // namespace

MoveComparison compare_move(const StackConfig& cfg, const ManeuverConfig& m,
                            const optimal_control::MinimumTimeResult& bound,
                            const std::vector<ComparedController>& controllers, const plant::PlantMismatch& mismatch,
                            int intervals, const optimal_control::FollowerParams& follower, double reference_bound,
                            const std::optional<ManeuverConfig>& first_move) {
  MoveComparison out;
  out.learnt = first_move.has_value();
  out.maneuver = m;
  out.mismatch = mismatch;
  out.bound = reference_bound > 0.0 ? reference_bound : bound.duration;
  out.swing_period = swing_period(m, cfg.facts);
  for (const ComparedController& c : controllers) {
    ControllerOutcome o;
    o.controller = c.name;
    try {
      if (c.follower) {
        FollowerRun run;
        run.maneuver = m;
        run.mismatch = mismatch;
        run.intervals = intervals;
        run.bound = bound;
        run.follower = follower;
        run.first_move = first_move;
        const FollowerResult r = run_follower(cfg, run);
        o.planned_swing = r.planned_swing;
        o.metrics = r.metrics;
        o.latched_faults = r.latched_faults;
        o.braked_cycles = r.braked_cycles;
        o.unsolved_plans = r.unsolved_plans;
      } else {
        InProcessRun run;
        run.maneuver = m;
        run.controller = choose_controller(c.controller, m, c.acceleration_feedforward);
        run.profile = c.profile;
        run.mismatch = mismatch;
        run.first_move = first_move;
        const InProcessResult r = run_in_process(cfg, run);
        o.metrics = r.metrics;
        o.latched_faults = r.latched_faults;
        o.braked_cycles = r.braked_cycles;
        o.unsolved_plans = r.unsolved_plans;
      }
      o.ratio = o.metrics.settle_time / out.bound;
    } catch (const std::exception& error) {
      o = failed_outcome(c.name, error.what());
    }
    out.outcomes.push_back(std::move(o));
  }
  return out;
}

MoveComparison failed_comparison(const ManeuverConfig& maneuver, const plant::PlantMismatch& mismatch,
                                 const std::vector<ComparedController>& controllers, double bound,
                                 const std::string& error) {
  MoveComparison out;
  out.maneuver = maneuver;
  out.mismatch = mismatch;
  out.bound = bound;
  for (const ComparedController& c : controllers) out.outcomes.push_back(failed_outcome(c.name, error));
  return out;
}

std::vector<plant::PlantMismatch> mismatch_corners() {
  std::vector<plant::PlantMismatch> corners;
  for (const double length : {0.8, 1.2}) {
    for (const double mass : {0.8, 1.2}) {
      for (const double friction : {0.7, 1.3}) {
        plant::PlantMismatch m;
        m.cable_length_factor = length;
        m.load_mass_factor = mass;
        m.friction_factor = friction;
        corners.push_back(m);
      }
    }
  }
  return corners;
}

std::string mismatch_label(const plant::PlantMismatch& m) {
  if (m.cable_length_factor == 1.0 && m.load_mass_factor == 1.0 && m.friction_factor == 1.0) return "nominal";
  char label[64];
  std::snprintf(label, sizeof label, "L%.2g_m%.2g_f%.2g", m.cable_length_factor, m.load_mass_factor, m.friction_factor);
  return label;
}

std::vector<ControllerSummary> summarize(const std::vector<MoveComparison>& moves) {
  std::vector<ControllerSummary> out;
  if (moves.empty()) return out;
  for (std::size_t c = 0; c < moves.front().outcomes.size(); ++c) {
    ControllerSummary s;
    s.controller = moves.front().outcomes[c].controller;
    std::vector<double> ratios, residual;
    for (const MoveComparison& move : moves) {
      if (c >= move.outcomes.size()) continue;
      const ControllerOutcome& o = move.outcomes[c];
      ++s.runs;
      if (!o.error.empty()) {
        ++s.failed;
        ratios.push_back(std::numeric_limits<double>::infinity());
        continue;
      }
      if (o.latched_faults != 0 || o.braked_cycles != 0) ++s.faulted;
      if (std::isfinite(o.ratio)) ++s.settled;
      ratios.push_back(std::isfinite(o.ratio) ? o.ratio : std::numeric_limits<double>::infinity());
      residual.push_back(o.metrics.residual_swing);
      s.worst_position_error =
          std::max({s.worst_position_error, o.metrics.final_position_error, o.metrics.final_bridge_error});
      s.worst_slew_error = std::max(s.worst_slew_error, o.metrics.final_slew_error);
      s.peak_voltage = std::max(s.peak_voltage, o.metrics.max_voltage);
    }
    s.median_ratio = nearest_rank_quantile(ratios, 0.5);
    s.worst_ratio = nearest_rank_quantile(ratios, 1.0);
    s.median_residual_swing = nearest_rank_quantile(residual, 0.5);
    out.push_back(s);
  }
  return out;
}

}  // namespace crane::stack
