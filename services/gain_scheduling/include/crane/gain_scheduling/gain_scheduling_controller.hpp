#pragma once
// Gain-scheduling adaptive state-feedback controller, section 3.2 of H. M. Omar, "Control of
// Gantry and Tower Cranes", Virginia Tech 2003: (3.19) partial or (3.26) full state feedback on the
// trolley and (section 3.2.1) on the slew, gains re-placed every cycle from the MEASURED cable length
// L and trolley position x with the closed-form pole placement of gain_schedule.hpp ((3.20), (3.21)).
//
// Signs, tower convention (2.28)-(2.31): x'' + m_t g phi = K_mx V_x, L phi'' + g phi - x'' = 0;
//   (1 + M_r x^2) gamma'' - m_r g x theta = K_mg V_gamma, L theta'' + g theta + x gamma'' = 0.
//   V_x     = K (x_r     - K_x x     - K_xd x'     + K_phi phi     + K_phid phi')      (3.19)/(3.26)
//   V_gamma = K (gamma_r - K_x gamma - K_gd gamma' + K_theta theta + K_thetad theta')
// With these signs K_phi < 0 (4.18 prints |K_phi|) and K_theta > 0 for x > 0 (4.19).
// Step references: only reference positions are used (trolley.position, slew.position); their
// velocities and accelerations are ignored. hoist_speed passes reference cable_length.velocity
// through (this controller does not act on the hoist).
// The measured L is floored at min_cable_length; |x| is floored at min_radius keeping its sign
// (+ at 0), because K_theta ~ 1/x. Voltages are clamped to +-voltage_limit.
//
// Real-time: step() is noexcept, allocates nothing (closed-form gains, no cache).

#include "crane/common/crane_parameters.hpp"
#include "crane/common/crane_signals.hpp"
#include "crane/gain_scheduling/gain_schedule.hpp"

namespace crane::gain_scheduling {

enum class FeedbackKind {
  partial,  // (3.19): K determined by the poles (4.18), K_x = 1, no swing-rate feedback
  full,     // (3.26): K given (trolley_forward_gain / slew_forward_gain), K_x = 1
};

struct GainSchedulingParams {
  FeedbackKind kind{FeedbackKind::partial};
  double trolley_forward_gain{2.0};    // [V/m] K of (3.26), > 0; used only when kind == full
  double slew_forward_gain{2.0};       // [V/rad] K of the slew law, > 0; used only when kind == full
  double trolley_drive_gain{2.0};      // [m/s^2/V] K_mx (4.4), > 0
  double slew_drive_gain{1.14};        // [rad/s^2/V] K_mgamma (4.5), > 0
  double mass_ratio{0.09};             // [-] m_t = m/M (2.25), >= 0
  double load_inertia_ratio{0.28};     // [1/m^2] m_r = m/J_o (2.25), >= 0
  double trolley_inertia_ratio{0.27};  // [1/m^2] M_r = M/J_o (2.25), >= 0
  double gravity{kDefaultGravity};     // [m/s^2] > 0
  double damping_ratio{kDefaultDampingRatio};  // [-] zeta of (3.20), in (0, 1)
  double min_cable_length{0.1};        // [m] floor on the measured L, > 0
  double min_radius{0.1};              // [m] floor on |x| in the slew gains, > 0
  double voltage_limit{10.0};          // [V] outputs clamped to +-voltage_limit, > 0
  bool slew_enabled{true};             // false: slew voltage 0 (gantry crane)
};

/// Model constants and the drive range from the crane description; the rest keeps its defaults.
[[nodiscard]] GainSchedulingParams gain_scheduling_params_from(const common::CraneParameters& crane);

class GainSchedulingController {
 public:
  /// Throws common::ConfigError naming the field ("gain_scheduling.<field>"), value and bound if a
  /// value is non-finite or out of the range given in GainSchedulingParams.
  explicit GainSchedulingController(const GainSchedulingParams& params);

  /// One control cycle. Uses estimate trolley_position/velocity, slew_angle/rate, both swing angles
  /// and rates, cable_length; reference trolley.position, slew.position, cable_length.velocity.
  /// Returns rejected_nonfinite (command zeroed, gains unchanged) if any used value is NaN/Inf.
  /// `load`: the m_t and m_r the gains are placed for this cycle (the online estimate when it is
  /// confident); nullptr, or a non-finite or negative ratio: the configured ones.
  [[nodiscard]] common::StepStatus step(const common::CraneStateEstimate& estimate,
                                        const common::MotionReference& reference, common::DriveCommand& command,
                                        const common::LoadRatios* load = nullptr) noexcept;

  /// Gains used by the last successful step() (default-constructed before the first).
  [[nodiscard]] const GainSchedulingGains& trolley_gains() const noexcept { return trolley_gains_; }
  [[nodiscard]] const GainSchedulingGains& slew_gains() const noexcept { return slew_gains_; }
  [[nodiscard]] const GainSchedulingParams& params() const noexcept { return params_; }

 private:
  GainSchedulingParams params_;
  GainSchedulingGains trolley_gains_;
  GainSchedulingGains slew_gains_;
};

}  // namespace crane::gain_scheduling
