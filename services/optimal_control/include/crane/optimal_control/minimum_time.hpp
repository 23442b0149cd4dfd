#pragma once
// The minimum time of a rest-to-rest crane maneuver on the plant's own nonlinear model, and the
// trajectory (states and inputs) that reaches it: the bound every controller is measured against
// (docs/optimal_control.md).
//
// Problem (the plant's equations, crane_dynamics.hpp, in every coordinate the model has):
//   minimize T  subject to
//     M(q, L) q'' + b(q, q', L, L', L'') = Q,  Q = (F_trolley, 0, F_second, 0[, 0, 0])
//     drive axes (slots 0 and 2): q'' = the inputs a_trolley, a_second;  hoist: L'' = a_hoist
//     passive coordinates (the swings, a hook's rigging, a rope's stretch): from the model, Q = 0
//     drive voltage V = F / force_per_volt + friction(q') in [-voltage_limit, voltage_limit]
//       (friction: the plant's Coulomb + viscous law (3.1) in volt-equivalents, direction
//       dependent, its sign smoothed over friction_smoothing_speed; static friction is not a
//       constraint of a moving axis)
//     |a| <= max_acceleration, |q'| <= max_speed, position within [min_position, max_position]
//       per axis; |swing| <= max_swing on every swing coordinate
//     rest at both ends: every velocity and every swing 0, the drive axes and the cable at the
//       maneuver's start and target; a drive axis whose start equals its target may move in
//       between (the slew's bound uses the trolley against the centripetal swing), the hoist not.
// Transcription: direct collocation, trapezoidal rule on `intervals` equal intervals of T/N, the
// inputs piecewise linear (J. T. Betts, "Practical Methods for Optimal Control Using Nonlinear
// Programming", SIAM 2010, section 4.5). Solved by IPOPT (A. Waechter, L. T. Biegler, Math.
// Program. 106, 2006) with a limited-memory Hessian. The constraint Jacobian is exact in its
// structure and differentiates the model's own equations at each node by central differences
// (the model is a virtual double-precision interface, not templated on a scalar type, so neither
// automatic differentiation nor a second, hand-derived copy of the equations: one model; step
// 1e-6 scaled by the variable, truncation error about 1e-10 relative).
//
// The initial guess: each drive axis and the hoist on the linear time-optimal swing-free profile
// (trajectory_planner/time_optimal_profile.hpp), the swings at 0.
//
// The trajectory returned is by default (MinimumTimeProblem::least_effort) not the minimum-time
// solution but a second solve at 1.01 T* (1.02 or 1.04 T* where IPOPT does not solve that) for
// the least input and swing (with detuned_pendulums, also the least swing left on cables of other
// lengths); MinimumTimeResult::duration is T*, trajectory_duration the nodes'.
//
// Errors: solve_minimum_time throws common::ConfigError naming the field, the value and the bound
// for a problem that is malformed (a non-finite or non-positive limit, a start or target outside
// its axis's range, intervals outside [4, 2000], least_effort_margin outside [0, 0.5],
// least_effort_tolerance outside [1e-14, 1e-2], more than kMaxDetunedPendulums detuned pendulums
// or one outside [0.5, 2], detuned_weight outside [0, 1e12], detuned_max_iterations outside
// [1, 1e6]); a problem IPOPT does not solve is returned with `solved == false` and IPOPT's status
// in `status` (never an exception).
//
// Threads: solve_minimum_time may be called from several threads; the solves run one at a time
// (IPOPT's linear solver, Debian's sequential MUMPS, is not reentrant), so solve_seconds counts
// only the solve, not the wait.

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "crane/common/crane_parameters.hpp"
#include "crane/plant/crane_dynamics.hpp"

namespace crane::optimal_control {

/// The most detuned pendulums a problem may carry (MinimumTimeProblem::detuned_pendulums).
inline constexpr int kMaxDetunedPendulums = 2;

/// Range and rated limits of one axis [m, m/s, m/s^2] or [rad, rad/s, rad/s^2].
struct AxisRange {
  double start{0.0};             // position at t = 0
  double target{0.0};            // position at t = T
  double min_position{-1e3};     // the axis stays within [min_position, max_position]
  double max_position{1e3};
  double max_speed{1.0};         // |q'| <= max_speed, > 0
  double max_acceleration{1.0};  // |q''| <= max_acceleration, > 0
};

struct MinimumTimeProblem {
  /// The plant's model (make_crane_dynamics); cloned by the solver.
  std::shared_ptr<const plant::CraneDynamics> model;
  AxisRange trolley;                  // slot 0 [m]
  AxisRange second;                   // slot 2: slew [rad] (tower) or bridge [m] (overhead); a model whose
                                      // second axis has no drive (gantry) keeps it at 0 whatever is set here
  AxisRange hoist;                    // the cable length L [m]; start == target: no hoisting
  common::AxisFriction trolley_friction;  // volt-equivalents (3.1)-(3.3)
  common::AxisFriction second_friction;   // the slew's (tower) or the bridge's (overhead)
  double voltage_limit{10.0};         // [V] |V| of each drive, > 0
  double max_swing{0.6};              // [rad] |phi|, |theta| (and a hook's rigging angles), > 0
  double friction_smoothing_speed{1e-3};  // [m/s or rad/s] sign(v) ~ tanh(v / this), > 0
  int intervals{100};                 // collocation intervals N, in [4, 2000]
  double input_smoothing{1e-5};       // [s] w in [0, 1]: the objective is T + w sum over the intervals and inputs
                                      // of ((a_k+1 - a_k) / max_acceleration)^2. It picks one of the equally fast
                                      // inputs where an axis has slack (without it IPOPT wanders on the overhead
                                      // crane's long moves); 1e-5 changes T* by < 1e-4 s on the demo maneuvers
                                      // (docs/optimal_control.md)
  /// After T* is found, solve again at the fixed duration (1 + least_effort_margin) T* for the
  /// least input and swing: the objective (1 / (N + 1)) sum over the nodes of sum_j (a_j /
  /// max_acceleration_j)^2 + sum_i (swing_i / max_swing)^2, plus the smoothing term above, started
  /// from the header's initial guess (the linear profiles) held to that duration: a lexicographic
  /// objective, the time first, then the effort. Where IPOPT does not solve it (it stops at a
  /// point it calls locally infeasible on some long moves), again at twice and at four times the
  /// margin. T* is the first solve's; the trajectory is the second's where IPOPT solves one of the
  /// three (else the first's, at T*).
  /// Why: at T* itself an axis with slack is not free. On the overhead crane's long bridge moves
  /// the first solve gains a fraction of a percent over the bridge's swing-free profile by swinging
  /// the load across the girder near the bound's swing limit (0.17 rad), the trolley drive at its
  /// 10 V for the whole move, so the follower had no drive left for feedback and tripped the
  /// overspeed on a mismatched crane; a second solve at T* exactly found the same trajectory, at
  /// 1.01 T* the trolley's swing is 0.007 rad at 1.4 V (tests/optimal_control/test_minimum_time.cpp;
  /// docs/optimal_control.md, "The least-effort trajectory").
  bool least_effort{true};
  double least_effort_margin{0.01};   // [-] in [0, 0.5]: the second solve's duration over T*, minus 1
  double least_effort_tolerance{1e-5};  // IPOPT's tol of the second solve, in [1e-14, 1e-2]: its optimum is a
                                      // preference, not a bound (the constraints keep constr_viol_tol 1e-9);
                                      // 1e-8 took 187 iterations on the test's overhead move, 1e-5 56, the
                                      // same trajectory to 1e-4 rad of swing
  /// Robust to the pendulum's length: in the least-effort solve (not the fallback's), copies
  /// of the passive coordinates (the swings) of a pendulum whose cable is each of these factors
  /// times the planned one, driven by the same drive and hoist motion (the hoist's length, rate and
  /// acceleration scaled), start at rest, and their amplitude at the end,
  /// (q / max_swing)^2 + (q' / (omega max_swing))^2 with omega = sqrt(g / (factor L_target)), is in
  /// the objective with detuned_weight: the multiple-model form of a robust input shaper (W. Singhose,
  /// W. Seering, N. Singer, "Residual vibration reduction using vector diagrams to generate shaped
  /// inputs", J. Mech. Des. 116, 1994: zero vibration at detuned frequencies) on the nonlinear
  /// model. The minimum-time solve (T*) never carries them. At most kMaxDetunedPendulums, each in
  /// [0.5, 2]; empty: none (docs/optimal_control.md, "Robust to the pendulum's length").
  std::vector<double> detuned_pendulums{};
  double detuned_weight{1e4};       // [-] >= 0, finite: the weight of the detuned pendulums' residual amplitude
  /// IPOPT iterations the least-effort solve with the detuned pendulums may take, in [1, 1e6]. Where
  /// it does not solve within them, the least-effort solves run as with none (the least-effort margins,
  /// no copies; MinimumTimeResult::robust false): a bound on the planning time that, unlike a clock,
  /// gives the same plan on every machine. Why 500: on the tower's 24 moves of seed 2 (200
  /// intervals) the robust solve took 31-249 iterations (0.9-11 s with T*'s) on 22 of them, and
  /// 970 and 2273 (23 and 52 s) on the other two (docs/optimal_control.md, "Robust to the
  /// pendulum's length").
  int detuned_max_iterations{500};
  double tolerance{1e-8};             // IPOPT's tol
  int max_iterations{3000};
  /// Where IPOPT does not solve the minimum-time problem from the linear profiles' guess, it is
  /// solved again from that guess stretched in time by each of these factors in turn (the profiles,
  /// then rest) until one solves (MinimumTimeResult::restarts). IPOPT can stop at a point of local
  /// infeasibility of a feasible problem: a 35 m overhead-crane move whose start was 4 um off one it
  /// solved did (tests/optimal_control/test_minimum_time.cpp; docs/optimal_control.md, "Learnt while
  /// working"). Each in [1, 10]; empty: no restart.
  std::vector<double> restart_stretch{1.25, 1.5};
  /// Where no restart solves either: the least-effort program at the fixed duration of each of these
  /// factors times the profiles' guess in turn (the profiles, then rest), until one solves. Its
  /// trajectory is a plan to follow, not the minimum time (MinimumTimeResult::fallback; `solved`
  /// stays false): a crane that follows it keeps its swing feedback, where no plan would leave the
  /// planner's time-optimal profile without any. Each in [1, 10]; empty: none.
  std::vector<double> fallback_stretch{1.5, 2.0};
};

/// One node of the trajectory.
struct TrajectoryNode {
  double time{0.0};                       // [s]
  plant::ExtendedState state;             // q, q' in the model's slots (crane_dynamics.hpp)
  double cable_length{1.0};               // [m] L
  double cable_length_rate{0.0};          // [m/s]
  double trolley_acceleration{0.0};       // [m/s^2] the input a_trolley
  double second_acceleration{0.0};        // [rad/s^2 or m/s^2]
  double hoist_acceleration{0.0};         // [m/s^2]
  double trolley_voltage{0.0};            // [V] drive voltage with friction (the feedforward)
  double second_voltage{0.0};             // [V]
};

struct MinimumTimeResult {
  bool solved{false};                     // T* found (the minimum-time solve, restarted or not)
  bool fallback{false};                   // not solved, but the nodes are a trajectory at a fixed duration
                                          // (MinimumTimeProblem::fallback_stretch): T = trajectory_duration,
                                          // an upper bound of T*; `duration` is then that too
  std::string status;                     // IPOPT's return status, e.g. "Solve_Succeeded"
  double duration{0.0};                   // [s] T*, the minimum time
  double trajectory_duration{0.0};        // [s] T of the nodes: (1 + k least_effort_margin) T*, k = 1, 2 or 4,
                                          // when least_effort (below) is true, else T*
  std::vector<TrajectoryNode> nodes;      // intervals + 1 nodes, t = k T / N
  int iterations{0};                      // of the last solve before the least-effort one: the minimum-time
                                          // solve that decided, or the fallback's
  int restarts{0};                        // minimum-time solves again from a stretched guess (restart_stretch)
  double solve_seconds{0.0};              // [s] wall time of IPOPT, every solve
  double max_defect{0.0};                 // largest collocation defect at the solution [SI]
  double initial_guess_duration{0.0};     // [s] the linear profiles' duration the solve started from
  bool least_effort{false};               // the nodes are the least-effort solve's (MinimumTimeProblem::least_effort)
  std::string effort_status;              // IPOPT's return status of the last least-effort solve, or of the
                                          // fallback ("" if none ran)
  int effort_iterations{0};               // of every least-effort solve
  /// [rad] each detuned pendulum's amplitude at the trajectory's end, sqrt(q^2 + (q' / omega)^2), the
  /// largest over its passive coordinates (0 where the nodes are not a solve that carried them)
  std::array<double, kMaxDetunedPendulums> detuned_residual_swing{};
  bool robust{false};                     // the nodes are the least-effort solve's with the detuned pendulums;
                                          // false with none, or where that solve took more than
                                          // detuned_max_iterations (the plain least-effort solve's then)
};

/// Validates `problem` (see the header's Errors) and solves it.
[[nodiscard]] MinimumTimeResult solve_minimum_time(const MinimumTimeProblem& problem);

/// Validates `problem`; throws common::ConfigError naming the field, the value and the bound.
void validate(const MinimumTimeProblem& problem);

/// The trajectory between nodes: states and inputs linear in time (the trapezoidal rule's own
/// interpolation of the inputs; the states to the same order). `time` [s] is clamped to [0, T],
/// T = result.trajectory_duration.
[[nodiscard]] TrajectoryNode sample(const MinimumTimeResult& result, double time);

/// Drive voltage [V] of one axis at speed `velocity` for a drive force `force` [N or N m]:
/// force / force_per_volt + the smoothed friction of the header, in volt-equivalents.
[[nodiscard]] double drive_voltage(double force, double force_per_volt, double velocity,
                                   const common::AxisFriction& friction, double smoothing_speed) noexcept;

}  // namespace crane::optimal_control
