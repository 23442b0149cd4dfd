#pragma once
// Gain-scheduling state-feedback gains, section 3.2 of H. M. Omar, "Control of Gantry and Tower
// Cranes", Virginia Tech 2003: pole placement (3.20) with the settling-time criterion (3.21),
// results (4.18), (4.19), (4.21) and Table 4.3 (see /work/shared/seed/ERRATA.md).
//
// Linear models, tower sign convention (2.28)-(2.31), g = gravity:
//   trolley: x'' + m_t g phi = K_mx V_x,                L phi'' + g phi - x'' = 0
//   slew:    (1 + M_r x^2) gamma'' - m_r g x theta = K_mgamma V_gamma,
//            L theta'' + g theta + x gamma'' = 0        (x frozen over the cycle, section 3.2.1)
// Control laws, (3.19) partial (swing_rate_gain = 0) and (3.26) full:
//   V_x     = K (x_r     - K_x x     - K_xd x'         + K_phi phi       + K_phid phi')
//   V_gamma = K (gamma_r - K_x gamma - K_xd gamma'     + K_phi theta     + K_phid theta')
// (for the slew the same struct fields hold K_gammad, K_theta, K_thetad).
// Closed-loop characteristic polynomial matched to (3.20)
//   (s + a)^2 (s^2 + 2 zeta w_n s + w_n^2),   a = 4/T = 2 sqrt(g/L)/pi (3.21), zeta = 1/sqrt(2).
// With the tower convention K_phi < 0 for the trolley (4.18 prints magnitudes) and K_theta > 0
// for the slew at x > 0 (4.19).
//
// All functions are closed form, allocate nothing and are deterministic. The public functions
// validate their arguments and throw crane::common::ConfigError naming the argument, its value and
// the bound; detail::place_poles is the unchecked noexcept kernel used by the cyclic controller.

#include <optional>

namespace crane::gain_scheduling {

/// Damping ratio of the load poles, section 3.2 ("xi" in (3.22) is this zeta).
inline constexpr double kDefaultDampingRatio = 0.70710678118654752440;
/// Gravity used by the dissertation's numbers (ERRATA) [m/s^2].
inline constexpr double kDefaultGravity = 9.8;

/// Gains of one axis. Units for the trolley (slew in brackets).
struct GainSchedulingGains {
  double forward_gain{0.0};       // [V/m]   ([V/rad]) K
  double position_gain{1.0};      // [-]     K_x; 1 unless a partial law is given a fixed K
  double velocity_gain{0.0};      // [s]     K_xd (K_gammad)
  double swing_gain{0.0};         // [m/rad] ([rad/rad]) K_phi (K_theta)
  double swing_rate_gain{0.0};    // [m s/rad] ([s]) K_phid (K_thetad); 0 for partial feedback
  double natural_frequency{0.0};  // [rad/s] w_n of the load pole pair (3.20)
  double trolley_pole{0.0};       // [1/s]   a, the repeated real pole (3.21)
  double damping_ratio{0.0};      // [-]     zeta
};

/// Partial state feedback (3.19) for the trolley, (3.22)-(3.25) with K_x = 1.
///   forward_gain empty: K is determined by the poles, K = a^2 w_n^2 L/(g K_mx) (4.18);
///   forward_gain given: K is fixed and K_x = K_auto/K is determined instead (steady-state error
///   A(1 - 1/K_x), section 3.2).
/// cable_length [m] > 0, mass_ratio m_t [-] >= 0, trolley_drive_gain K_mx [m/s^2/V] > 0,
/// forward_gain [V/m] > 0, gravity [m/s^2] > 0, damping_ratio in (0, 1).
/// Throws common::ConfigError naming the argument, value and bound.
[[nodiscard]] GainSchedulingGains partial_state_gains(double cable_length, double mass_ratio,
                                                      double trolley_drive_gain,
                                                      std::optional<double> forward_gain,
                                                      double gravity = kDefaultGravity,
                                                      double damping_ratio = kDefaultDampingRatio);

/// Full state feedback (3.26) for the trolley with K given and K_x = 1: K_xd, K_phi, K_phid, w_n
/// (4.21). Arguments and errors as partial_state_gains, forward_gain [V/m] > 0 required.
[[nodiscard]] GainSchedulingGains full_state_gains(double cable_length, double mass_ratio,
                                                   double trolley_drive_gain, double forward_gain,
                                                   double gravity = kDefaultGravity,
                                                   double damping_ratio = kDefaultDampingRatio);

/// Constants of the slewing model (2.30)-(2.31).
struct SlewModel {
  double load_inertia_ratio{0.28};     // [1/m^2] m_r = m/J_o, >= 0
  double trolley_inertia_ratio{0.27};  // [1/m^2] M_r = M/J_o, >= 0
  double slew_drive_gain{1.14};        // [rad/s^2/V] K_mgamma, > 0
};

/// Slew gains (section 3.2.1): the same pole placement applied EXACTLY to (2.30)-(2.31) at a fixed
/// trolley position (not the series (4.19)). trolley_position x [m], finite and != 0 (K_theta ~ 1/x).
/// forward_gain empty: partial law with K determined; given: partial law with K fixed (K_x free).
/// Throws common::ConfigError naming the argument, value and bound.
[[nodiscard]] GainSchedulingGains slew_partial_state_gains(double cable_length, double trolley_position,
                                                           const SlewModel& model,
                                                           std::optional<double> forward_gain,
                                                           double gravity = kDefaultGravity,
                                                           double damping_ratio = kDefaultDampingRatio);

/// Slew full state feedback (3.26 applied to the slew, Table 4.3) with K [V/rad] > 0 given, K_x = 1.
/// Throws common::ConfigError naming the argument, value and bound.
[[nodiscard]] GainSchedulingGains slew_full_state_gains(double cable_length, double trolley_position,
                                                        const SlewModel& model, double forward_gain,
                                                        double gravity = kDefaultGravity,
                                                        double damping_ratio = kDefaultDampingRatio);

/// Voltage-limit remedy (section 3.2): the largest forward gain K [V/m] such that the initial
/// voltage K * distance of a step from rest stays within voltage_limit:
///   K_max = voltage_limit / |distance|.
/// distance [m] (or [rad]) finite and != 0; voltage_limit [V] > 0 (drive range, 10 V).
/// Throws common::ConfigError naming the argument, value and bound.
[[nodiscard]] double max_forward_gain(double distance, double voltage_limit = 10.0);

namespace detail {

/// Generic axis  q'' = b V + f psi,  L psi'' + g psi = rho q''  under
/// V = K(q_r - K_x q - K_d q' + K_psi psi + K_psid psi'), characteristic polynomial divided by L:
///   s^4 + (k K_d - rho k K_psid/L) s^3 + (k K_x + (g - rho (k K_psi + f))/L) s^2
///       + (g/L) k K_d s + (g/L) k K_x,      k = b K.
/// Trolley: b = K_mx, f = -m_t g, rho = 1.  Slew: b = K_mg/J, f = m_r g x/J, rho = -x, J = 1 + M_r x^2.
/// full == false: K_psid = 0; forward_gain <= 0 means "determine K" (K_x = 1), else K_x is solved.
/// full == true: K given (> 0), K_x = 1. Preconditions (unchecked): L, g, b > 0, rho != 0,
/// zeta in (0, 1).
[[nodiscard]] GainSchedulingGains place_poles(double cable_length, double gravity, double damping_ratio,
                                              double drive_gain, double swing_force, double coupling,
                                              bool full, double forward_gain) noexcept;

}  // namespace detail

}  // namespace crane::gain_scheduling
