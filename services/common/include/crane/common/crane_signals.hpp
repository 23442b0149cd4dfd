#pragma once
// Core structs exchanged between the pure control libraries (no DDS type ever crosses a core API).
// Symbols as in the dissertation (2.11): x trolley position, gamma slew angle, phi in-plane swing,
// theta out-of-plane swing, L cable length. Tower sign convention: the load sits at
// x - L cos(theta) sin(phi) along the jib.

#include <array>

namespace crane::common {

/// What the sensors give each cycle, in SI units (already converted from counts).
struct CraneMeasurement {
  double trolley_position{0.0};    // [m] x
  double slew_angle{0.0};          // [rad] gamma
  double swing_in_plane{0.0};      // [rad] phi
  double swing_out_of_plane{0.0};  // [rad] theta
  double cable_length{1.0};        // [m] L
  double bridge_position{0.0};     // [m] y, overhead crane (0 elsewhere)
};

/// Estimated state: positions and their rates (section 4.3).
struct CraneStateEstimate {
  double trolley_position{0.0};          // [m]
  double trolley_velocity{0.0};          // [m/s] filtered then differentiated
  double slew_angle{0.0};                // [rad]
  double slew_rate{0.0};                 // [rad/s]
  double swing_in_plane{0.0};            // [rad]
  double swing_in_plane_rate{0.0};       // [rad/s]
  double swing_out_of_plane{0.0};        // [rad]
  double swing_out_of_plane_rate{0.0};   // [rad/s]
  double cable_length{1.0};              // [m]
  double cable_length_rate{0.0};         // [m/s]
  double trolley_velocity_raw{0.0};      // [m/s] differentiated without the low-pass filter
  double slew_rate_raw{0.0};             // [rad/s] differentiated without the low-pass filter
};

/// Reference for one axis at one instant.
struct AxisReference {
  double position{0.0};      // [m] or [rad]
  double velocity{0.0};      // [m/s] or [rad/s]
  double acceleration{0.0};  // [m/s^2] or [rad/s^2]
};

/// Reference for the whole crane at one instant.
struct MotionReference {
  AxisReference trolley;
  AxisReference slew;
  AxisReference cable_length;
};

/// The feedback law of one cycle of a trajectory that carries one (the minimum-time follower,
/// optimal_control/trajectory_follower.hpp; Reference.feedback_law on the wire): per drive r,
///   u_r = feedforward[r] - sum_j (gain[r][j] (position_j - reference_position_j)
///                               + gain[r][4 + j] (velocity_j - reference_velocity_j)),
/// j over the model's coordinate slots 0..3 (trolley, in-plane swing, the second axis: the slew or
/// the bridge, out-of-plane swing; crane_dynamics.hpp), u before the friction the compensation adds.
struct TrajectoryFeedback {
  std::array<double, 4> position{};   // [m, rad, rad or m, rad] z_ref, the positions
  std::array<double, 4> velocity{};   // [m/s, rad/s, rad/s or m/s, rad/s]
  std::array<double, 2> feedforward{};  // [V] trolley, second axis
  std::array<double, 16> gain{};      // row-major 2 x 8 [V/m, V/rad; V s/m, V s/rad]; 0 where an axis is absent
  double sliding_friction_reduction{0.0};  // [-] in [0, 1]: of the compensation's sliding part, left out
};

/// The load as the controllers' model sees it, (2.25): m_t = m/M [-] and m_r = m/J_o [1/m^2]. The
/// controllers take one per cycle when the online estimate is confident (crane::adaptation), and use
/// their configured ratios otherwise.
struct LoadRatios {
  double mass_ratio{0.0};          // [-] m_t, finite, >= 0
  double load_inertia_ratio{0.0};  // [1/m^2] m_r, finite, >= 0
};

/// Drive commands (after or before friction compensation, depending on where it is used).
struct DriveCommand {
  double trolley_voltage{0.0};  // [V]
  double slew_voltage{0.0};     // [V]
  double hoist_speed{0.0};      // [m/s]
  double bridge_voltage{0.0};   // [V] overhead crane (0 elsewhere)
};

/// Result of a cyclic step() of any core: the cyclic path never throws (STYLE.md habit 7).
enum class [[nodiscard]] StepStatus {
  ok,                 // outputs valid
  rejected_nonfinite, // an input was NaN or Inf; outputs hold their safe value
  not_ready,          // not enough history yet (e.g. a delay line filling); outputs are safe
};

}  // namespace crane::common
