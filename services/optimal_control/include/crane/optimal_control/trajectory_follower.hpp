#pragma once
// A closed-loop follower of a minimum-time trajectory (issue 32, item 2; docs/optimal_control.md):
// the bound's drive forces as feedforward, plus time-varying LQR state feedback around the bound's
// states, from the model's own linearization along the trajectory.
//
// At each sample t_k = k T_s of the trajectory (and at the rest state at the target after it ends):
//   u_k = u_ff(t_k + T_s / 2) - K_k (z_k - z_ref(t_k)),   |u_k| <= voltage_limit
// where
//   z    the generalized positions and velocities of the model's driven and swing coordinates
//        (crane_dynamics.hpp slots 0..3; a crane without a second drive axis, the gantry, keeps
//        slots 0 and 1 only), [m, rad, rad or m, rad, m/s, rad/s, rad/s or m/s, rad/s]
//   u    the drive voltages without the friction that the friction compensation stage adds on the
//        measured speed ((3.1)-(3.5), its sliding part scaled by trajectory_sliding_friction_scale
//        s): u_ff = the bound's voltage less s x its smoothed friction at the reference speed (the
//        other (1 - s) of the friction fed forward), the average over the sample (zero-order hold)
//        taken at its middle; K_k is computed on the friction-free model either way
//   K_k  from the backward Riccati recursion of the discrete linear-quadratic regulator,
//        P_k = Q + A_k' P_k+1 (A_k - B_k K_k), K_k = (R + B_k' P_k+1 B_k)^-1 B_k' P_k+1 A_k
//        (B. D. O. Anderson, J. B. Moore, "Optimal Control: Linear Quadratic Methods", 1990,
//        section 2.3), started from the stationary solution at the target's rest state (the
//        discrete algebraic Riccati equation, iterated to convergence, with the hold's weights,
//        FollowerHold): after the trajectory the law is the time-invariant LQR that holds the
//        load at rest at the target
//   A_k, B_k  the Jacobians of the model's zero-order-hold map over one sample (RK4, 4 sub-steps,
//        the hoist following the trajectory) by central differences at (z_ref(t_k), u_ff): the
//        plant's equations, not a second copy of them
//   Q, R diagonal, Bryson's rule: 1 / (the acceptable deviation)^2 of each state and input
//        (A. E. Bryson, Y.-C. Ho, "Applied Optimal Control", 1975, section 5.7).
// The hoist is not a feedback axis: hoist_speed is the trajectory's cable-length rate.
//
// The command asks the friction compensation for a fraction of its sliding part
// (FollowerCommand::sliding_friction_scale; on the wire 1 - it, LinearCommand_.sliding_friction_reduction,
// which the friction compensation stage applies): s along the
// trajectory, where its other part is fed forward (compensated on the measured speed alone, a
// friction 30 % below the model's drove the trolley past its overspeed on random moves), and the
// hold's after it. After the trajectory (FollowerHold) the stationary gain comes from the hold's
// own weights.
//
// Errors: the constructor throws common::ConfigError naming the field for a model with more than
// four coordinates (a hook or a rope), a non-positive weight, sample period or voltage limit, a
// sliding_friction_scale (the hold's or the trajectory's) outside [0, 1], or a trajectory that is
// neither solved nor a fallback (MinimumTimeResult) or has fewer than two nodes. step() is noexcept
// and allocates nothing; a non-finite state gives 0 V (the safe output) and rejected_nonfinite.

#include <cstddef>
#include <vector>

#include <Eigen/Core>

#include "crane/common/crane_signals.hpp"
#include "crane/optimal_control/minimum_time.hpp"

namespace crane::optimal_control {

/// Acceptable deviations (Bryson's rule), each > 0.
struct FollowerWeights {
  double position{0.005};      // [m] the trolley (the settle band of the demo table)
  double second_position{0.005};  // [rad] the slew, [m] the bridge
  double swing{0.006};         // [rad] the in-plane swing phi (0.34 deg; docs/optimal_control.md, "The
                               // swing weights": at 0.5 deg fewer mismatch corners settle within 2 T*)
  double out_of_plane_swing{0.006};  // [rad] theta
  double speed{0.05};          // [m/s or rad/s] drive axes
  double swing_rate{0.05};     // [rad/s] both swing angles
  double voltage{0.2};         // [V] the input (measured on the demo maneuvers, docs/optimal_control.md)
};

/// The hold at the target after the trajectory ends (docs/optimal_control.md, "Following the bound
/// in closed loop": measured at the +-20 % length and mass, +-30 % friction corners).
struct FollowerHold {
  /// Bryson's weights of the stationary regulator (and so of the time-varying gains near the
  /// trajectory's end). The swing tighter than along the trajectory, so that a small swing still
  /// commands the breakaway of a trolley whose stiction is under-compensated by 30 % (0.23 deg;
  /// 0.2 deg drives the trolley unstable on a random tower move with a 20 % shorter cable and 30 %
  /// less friction: docs/optimal_control.md, "The swing weights"). The second axis looser and the
  /// out-of-plane swing tighter (0.01 rad or m, 0.0025 rad = 0.14 deg): a slew held as tightly as
  /// the trolley damps the out-of-plane swing a 20 % longer cable leaves only through its slower
  /// period; the tracking stage's breakaway ramp (tracking/breakaway_ramp.hpp) brings back a drive
  /// that friction holds off the target (docs/optimal_control.md, "Breaking the drive loose at the
  /// target"). The out-of-plane swing was 0.003 rad until the slew was held to a sideways distance
  /// near the mast (slew_sideways); with it, 0.002-0.00275 rad settle more mismatch corners
  /// (docs/optimal_control.md, "The out-of-plane swing's hold weight, chosen again"). The trolley
  /// stays at 0.005 m: at 0.0075 or 0.01 m the gantry's trolley overshot into its travel limiter's
  /// stop margin.
  FollowerWeights weights{.position = 0.005,
                          .second_position = 0.01,
                          .swing = 0.004,
                          .out_of_plane_swing = 0.0025,
                          .speed = 0.05,
                          .swing_rate = 0.05,
                          .voltage = 0.2};
  /// [m] > 0, a tower crane's, after a plan robust to the pendulum's length (MinimumTimeResult::robust:
  /// the configured pendulum, near the mast): the slew is held no tighter than this sideways
  /// displacement of the trolley (the target's radius times the slew angle), its weight
  /// max(weights.second_position, slew_sideways / radius). Near the mast the slew is a weak actuator
  /// for the out-of-plane swing (an angle moves the trolley sideways by the radius times it); held at
  /// 0.01 rad there, the slew and the out-of-plane swing a 20 % longer cable leaves ring together for
  /// periods, the slew outside its settle band (docs/optimal_control.md, "Robust near the mast"). On
  /// a known pendulum (learnt) there is little swing to damp, and the looser slew sticks further off
  /// its target with 30 % more friction (1.10 -> 1.62 T*), so it applies after a robust plan only. At
  /// 0.006 m every target beyond 0.6 m keeps 0.01 rad. The bridge (overhead crane) keeps
  /// weights.second_position.
  double slew_sideways{0.006};
  /// [-] in [0, 1]: the fraction of the plant's sliding friction (Coulomb and viscous, (3.1),
  /// (3.3)) the compensation applies while a drive slides after the trajectory; the stiction part
  /// (3.2) is scaled as the plant's. The law carries it as a fraction of the model's friction; the
  /// tracking stage estimates the plant's friction over the model's along the move
  /// (tracking/friction_factor_estimate.hpp) and the compensation multiplies both parts by it
  /// (LinearCommand_.friction_factor). Compensation of
  /// a friction 30 % above the plant's pushes the drive along its motion and sustains a 1.5-2.5 Hz
  /// hunting around the target; 30 % too little leaves the drive stuck with the swing undamped.
  /// 0.7 with the estimate (0.5 of the model's before it: docs/optimal_control.md, "The friction
  /// the hold compensates"). 1 keeps the compensation as configured.
  double sliding_friction_scale{0.7};
};

struct FollowerParams {
  double sample_period{0.01};  // [s] T_s, the control cycle, > 0
  double voltage_limit{10.0};  // [V] |u| before friction, > 0
  FollowerWeights weights{};
  FollowerHold hold{};
  /// [-] in [0, 1]: along the trajectory, the fraction of the friction compensation's sliding part
  /// applied on the measured speed (FollowerCommand::sliding_friction_scale); the rest of the
  /// model's friction (Coulomb and viscous at the reference speed) is fed forward with u_ff.
  double trajectory_sliding_friction_scale{0.5};
};

/// The law's output for one cycle.
struct FollowerCommand {
  double trolley_voltage{0.0};  // [V] without friction
  double second_voltage{0.0};   // [V] the slew (tower) or the bridge (overhead); 0 on a gantry
  double hoist_speed{0.0};      // [m/s] the trajectory's cable length rate (positive lowers)
  common::AxisReference trolley;  // the reference at this cycle [m, m/s, m/s^2]
  common::AxisReference second;   // [rad or m, ...]
  common::AxisReference cable;    // [m, m/s, m/s^2]
  double swing_in_plane{0.0};     // [rad] the trajectory's phi
  double swing_out_of_plane{0.0};  // [rad] theta
  double sliding_friction_scale{1.0};  // [-] FollowerHold::sliding_friction_scale after the trajectory, 1 along it
};

class TrajectoryFollower {
 public:
  /// The follower of `trajectory` (solve_minimum_time of `problem`) on `problem.model`, the
  /// controller's model of the crane. Throws common::ConfigError (see the header).
  TrajectoryFollower(const MinimumTimeProblem& problem, const MinimumTimeResult& trajectory, const FollowerParams& params);

  /// Cycle `k` (0 at the trajectory's start; k beyond its end: regulation at the target) from the
  /// measured state in the model's slots (the estimate: positions, rates, swings; slots 2 and 3
  /// ignored without a second drive). ok, or rejected_nonfinite (every voltage 0). Never throws,
  /// never allocates.
  [[nodiscard]] common::StepStatus step(std::size_t k, const plant::ModelState& measured,
                                        FollowerCommand& command) const noexcept;

  /// The law of cycle `k` (beyond the trajectory: the hold at the target), as the reference carries
  /// it to the tracking stage's `follower` law (Reference.feedback_law): z_ref in the model's slots,
  /// the feedforward with the friction fed forward, the gain, and the sliding friction left out
  /// (1 - the scale of FollowerParams or FollowerHold). step() is this law applied.
  [[nodiscard]] common::TrajectoryFeedback law(std::size_t k) const noexcept;
  /// The trajectory's node at cycle `k` (clamped to its end).
  [[nodiscard]] const TrajectoryNode& node(std::size_t k) const noexcept;
  /// True while cycle `k` is on the trajectory (before its end).
  [[nodiscard]] bool moving(std::size_t k) const noexcept { return k + 1 < samples_.size(); }
  /// Samples of the trajectory (the last is its end, t >= T*).
  [[nodiscard]] std::size_t samples() const noexcept { return gains_.size() - 1; }
  /// The gain of sample k (clamped to the stationary one), rows: inputs, columns: the state z.
  [[nodiscard]] const Eigen::MatrixXd& gain(std::size_t k) const noexcept;
  /// The number of state coordinates of z (8, or 4 without a second axis).
  [[nodiscard]] int state_size() const noexcept { return static_cast<int>(slots_.size()) * 2; }

 private:
  struct Sample {
    plant::ModelState state;  // the reference in the model's slots
    Eigen::Vector2d input;    // u_ff [V] (trolley, second), without friction
    Eigen::Vector2d friction;  // [V] the friction feedforward: (1 - trajectory_sliding_friction_scale) x
                               // the model's friction at the reference speed
    TrajectoryNode node;      // the reference (rates, accelerations, the hoist)
  };
  std::vector<int> slots_;  // model coordinates in z
  std::vector<Sample> samples_;
  std::vector<Eigen::MatrixXd> gains_;  // K_k; the last is the stationary gain at the target
  double voltage_limit_;
  double sliding_friction_scale_;
  double trajectory_sliding_friction_scale_;
  bool second_drive_;
};

}  // namespace crane::optimal_control
