#pragma once
// Tracking controller with feedback linearization, (3.37)-(3.42) of H. M. Omar, "Control of
// Gantry and Tower Cranes", Virginia Tech 2003.
//
// Normalized time tau = t/T, T = 2 pi sqrt(L/g) from the MEASURED cable length every cycle.
// Trolley: V_xp = (1/L)(K_px e + T K_dx e_dot), e = x_ref - x, e_dot = x_ref_dot - x_dot (3.40);
//   V_bar_x = V_xp + V_xs; V_x = (1/K_mx)[(L/T^2) V_bar_x + m_t g phi]   (3.37)
// Slew, in y = -(x/L) gamma (3.34) with x held constant over the cycle:
//   V_yp = K_py e_y_bar + K_dy e_y_bar', e_y_bar = -(x/L)(gamma_ref - gamma),
//   e_y_bar' = -(x/L) T (gamma_ref_dot - gamma_dot);   V_bar_y = V_yp + V_ys;
//   V_gamma = (1/K_mgamma)[ -L(1 + M_r x^2)/(x T^2) V_bar_y - m_r g x theta ]   (3.38)
// (3.38) prints m_r g x_bar theta; (2.30) and (3.32) give m_r g x theta with x in metres.
// |x| is floored at min_radius (keeping its sign, + at 0) where x divides.
// Hoist: hoist_speed = reference cable_length velocity [m/s].
// Beside the voltages, the crane's generalized momenta along its two drives, for the friction
// factor's momentum balance (friction_momentum_balance.hpp): from the kinetic energy T of the jib,
// the trolley and the load (the tower crane of plant/src/tower_crane_model.cpp, (2.11) with ERRATA:
// the load at r = x e_x + L u(phi, theta), u = (-cos theta sin phi, sin theta, -cos theta cos phi), in
// the jib frame turning at gamma_dot), each over the drive's force per volt, with the law's own
// constants (M = M_drive, J_o):
//   p_x / (M K_mx)          = (x_dot + m_t v_x) / K_mx
//   p_gamma / (J_o K_mgamma) = ((1 + M_r x^2) gamma_dot + m_r (r x v)_z) / K_mgamma
//   dT/dx / (M K_mx)        = (M_t/M x gamma_dot^2 + m_t gamma_dot v_y) / K_mx
// v = r_dot + gamma_dot e_z x r the load's velocity. Lagrange's equations of x and gamma then read
// dp_x/dt - dT/dx = the trolley's drive force less its friction, dp_gamma/dt = the slew's torque
// less its friction: the load's swing, the jib's Coriolis and the trolley's centripetal force are
// in the momenta, not left in a voltage. A gantry (slew disabled) has gamma_dot = 0.
//
// Real-time: step() is noexcept, allocates nothing.

#include <optional>

#include "crane/common/crane_parameters.hpp"
#include "crane/common/crane_signals.hpp"

namespace crane::tracking {

struct TrackingParams {
  double proportional_gain{100.0};     // [-] K_px (normalized), (3.42)
  double derivative_gain{20.0};        // [-] K_dx = 2 sqrt(K_px) (3.42)
  double trolley_drive_gain{2.0};      // [m/s^2/V] K_mx (3.53)
  double slew_drive_gain{1.14};        // [rad/s^2/V] K_mgamma (3.53)
  double mass_ratio{0.09};             // [-] m_t = m/M (3.53)
  double load_inertia_ratio{0.28};     // [1/m^2] m_r = m/J_o (3.53)
  double trolley_inertia_ratio{0.27};  // [1/m^2] M_r = M/J_o (3.53)
  double trolley_mass_ratio{0.087};    // [-] M_t/M: the trolley's own mass over the mass its drive moves
                                       // (its centripetal force in dT/dx; the momenta only)
  double gravity{9.8};                 // [m/s^2]
  double min_radius{0.1};              // [m] floor on |x| in (3.38), > 0
  double min_cable_length{0.1};        // [m] floor on the measured L, > 0
  double voltage_limit{10.0};          // [V] outputs clamped to +-voltage_limit, > 0
  bool slew_enabled{true};             // false: slew voltage 0 (gantry crane)
  bool acceleration_feedforward{false};  // add the reference acceleration to the PD action (beyond the
                                         // dissertation, whose (3.40) uses the reference velocity only):
                                         // V_x += a_ref / K_mx, V_gamma += (1 + M_r x^2) gamma''_ref / K_mgamma
};

/// Model constants taken from the crane description; gains and limits keep their defaults.
[[nodiscard]] TrackingParams tracking_params_from(const common::CraneParameters& crane);

struct TrackingInput {
  common::CraneStateEstimate estimate;
  common::MotionReference reference;
  double trolley_anti_swing_action{0.0};  // [-] V_xs (normalized) from the anti-swing core
  double slew_anti_swing_action{0.0};     // [-] V_ys (normalized)
  // The load of (3.37)-(3.38) this cycle: the online estimate when it is confident; empty (or not
  // finite, or negative): the configured mass_ratio and load_inertia_ratio.
  std::optional<common::LoadRatios> load;
};

struct TrackingOutput {
  common::DriveCommand command;            // [V], [V], [m/s], clamped
  double trolley_tracking_action{0.0};     // [-] V_xp (3.40)
  double slew_tracking_action{0.0};        // [-] V_yp
  double trolley_normalized_action{0.0};   // [-] V_bar_x = V_xp + V_xs
  double slew_normalized_action{0.0};      // [-] V_bar_y = V_yp + V_ys
  double swing_period{0.0};                // [s] T
  // The generalized momenta along the trolley and the slew over the drive's force per volt [V s],
  // and dT/dx over the trolley's [V] (see the header), from the estimate and the law's load (m_t,
  // m_r of this cycle); 0 on the slew with the slew disabled. NaN when a rate only they use (the
  // swings', the cable's) is not finite: the voltages do not need them.
  double trolley_momentum{0.0};
  double slew_momentum{0.0};
  double trolley_centripetal_voltage{0.0};
  bool trolley_saturated{false};
  bool slew_saturated{false};
};

class TrackingController {
 public:
  /// Throws common::ConfigError naming the field, value and bound if a gain or model constant is
  /// non-finite, gains < 0, drive gains/gravity/min_radius/min_cable_length/voltage_limit <= 0,
  /// or a mass/inertia ratio < 0.
  explicit TrackingController(const TrackingParams& params);

  /// rejected_nonfinite if any used input is NaN/Inf, or if finite inputs so large that the law
  /// overflows (e.g. a trolley position of 1e200 m: x^2 is Inf, and Inf - Inf a NaN voltage) give a
  /// non-finite output: output set to zero voltages and actions. ok: every output field is finite
  /// but the momenta (see TrackingOutput).
  [[nodiscard]] common::StepStatus step(const TrackingInput& input, TrackingOutput& output) const noexcept;

  [[nodiscard]] const TrackingParams& params() const noexcept { return params_; }

 private:
  TrackingParams params_;
};

}  // namespace crane::tracking
