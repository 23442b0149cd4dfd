#pragma once
// Friction compensation, (3.1)-(3.5) of H. M. Omar, "Control of Gantry and Tower Cranes",
// Virginia Tech 2003, in volt-equivalents (friction force divided by mass times drive gain):
//   u = V + F_f/K_m                                                    (3.5)
// with the compensation F_f/K_m pushing WITH the motion (Coulomb and viscous friction oppose it):
//   velocity >  d_s:  + (c+ + b+ |v|)                                  (3.1), (3.3) eta = 1
//   velocity < -d_s:  - (c- + b- |v|)                                  (3.1), (3.3) xi = 1
//   |velocity| <= d_s: f_sh + f_s tanh(A V)  (stiction, driven by the commanded V)   (3.2)
// with f_s = (fs+ + fs-)/2 and f_sh = (fs+ - fs-)/2, so the stiction term tends to +fs+ for
// large positive V and to -fs- for large negative V ((4.13): 1.0/1.2 trolley, (4.15): 0.7/0.6 slew).
// The velocity used is selectable per axis: raw (unfiltered) for the trolley by default as in
// section 4.4.1, filtered for the slew as in section 4.4.2.
//
// Real-time: step() is noexcept, allocates nothing.

#include <array>
#include <optional>

#include "crane/common/crane_parameters.hpp"
#include "crane/common/crane_signals.hpp"

namespace crane::friction_compensation {

enum class VelocitySource {
  raw,       // CraneStateEstimate::trolley_velocity_raw / slew_rate_raw
  filtered,  // CraneStateEstimate::trolley_velocity / slew_rate
};

struct AxisCompensationParams {
  common::AxisFriction friction;           // volt-equivalents (see crane_parameters.hpp)
  double zero_velocity_band{0.01};         // [m/s] or [rad/s] d_s (3.3), >= 0
  double stiction_slope{20.0};             // [1/V] A in tanh(A V) (3.2), > 0
  VelocitySource velocity_source{VelocitySource::raw};
};

struct FrictionCompensationParams {
  bool enabled{true};  // false: u = V (still clamped)
  AxisCompensationParams trolley{common::CraneParameters{}.trolley_friction, 0.01, 20.0,
                                 VelocitySource::raw};       // (4.12), (4.13); section 4.4.1
  AxisCompensationParams slew{common::CraneParameters{}.slew_friction, 0.01, 20.0,
                              VelocitySource::filtered};     // (4.16), (4.15); section 4.4.2
  double voltage_limit{10.0};  // [V] outputs clamped to +-voltage_limit, > 0
  // An overhead crane's bridge (facts.crane_kind): compensated like the trolley, on its gantry view
  // (common::bridge_view), with the bridge's friction; absent elsewhere.
  std::optional<AxisCompensationParams> bridge{};
};

struct FrictionCompensationInput {
  common::CraneStateEstimate estimate;  // velocities [m/s], [rad/s]
  common::DriveCommand command;         // V from the linear controller [V]; hoist passes through
  // Friction in use instead of the configured one this cycle (the online re-estimate, released by
  // crane::adaptation within its safe bounds); empty, or with a non-finite or negative coefficient:
  // the configured one.
  std::optional<common::AxisFriction> trolley_friction;
  std::optional<common::AxisFriction> slew_friction;
  // [-] in [0, 1]: the fraction of the sliding part ((3.1), (3.3): outside the zero-velocity band)
  // left out on every axis this cycle, the stiction part (3.2) kept whole (LinearCommand's, asked by
  // the minimum-time follower, whose feedforward carries the rest; optimal_control/
  // trajectory_follower.hpp). 0 keeps the compensation as configured.
  double sliding_friction_reduction{0.0};
  // [-] >= 0: the plant's friction over the model's (LinearCommand's friction_factor, the minimum-time
  // follower's estimate at the target; tracking/friction_factor_estimate.hpp): the stiction part (3.2)
  // at rest is multiplied by it and the sliding part kept by min(1, (1 - sliding_friction_reduction)
  // x it). 0 (unset) or 1: the model's friction.
  double friction_factor{0.0};
};

struct FrictionCompensationOutput {
  common::DriveCommand command;       // u (3.5), clamped [V]
  double trolley_friction{0.0};       // [V] F_f/K_m added on the trolley
  double slew_friction{0.0};          // [V] F_f/K_m added on the slew
  bool trolley_saturated{false};
  bool slew_saturated{false};
};

/// Which branch of (3.3) a velocity is in: +1 (eta = 1, v > d_s), -1 (xi = 1, v < -d_s), 0 (the
/// zero-velocity band, where friction is static and not a function of v).
[[nodiscard]] int friction_direction(double velocity, double zero_velocity_band) noexcept;

/// The sliding-friction regressor of (3.13)-(3.14) at `velocity` [m/s or rad/s] in `direction`
/// (friction_direction): r = [v eta, v xi, eta, -xi], so that outside the band
///   F_f/K_m = b+ v eta + b- v xi + c+ eta - c- xi = sliding_coefficients(f) . r        (3.1)
/// in volts. The one place the regressor is written: the compensation (friction_voltage) and the
/// online re-estimation (crane::adaptation) both use it. Zero in the band (direction 0).
[[nodiscard]] std::array<double, 4> friction_regressor(double velocity, int direction) noexcept;

/// (b+, b-, c+, c-) of `friction`, in the order of friction_regressor [V s/m, V s/m, V, V].
[[nodiscard]] std::array<double, 4> sliding_coefficients(const common::AxisFriction& friction) noexcept;

/// The sliding friction (3.1) F_f/K_m [V] of `friction` at `velocity` [m/s or rad/s] in `direction`
/// (friction_direction, or the sign of a reference speed): sliding_coefficients . friction_regressor;
/// 0 for direction 0.
[[nodiscard]] double sliding_friction_voltage(const common::AxisFriction& friction, double velocity,
                                              int direction) noexcept;

/// The share of the sliding friction the compensation applies while an axis slides, given the
/// share the command's feedforward already carries (`sliding_friction_reduction`, in [0, 1]) and the
/// plant's friction over the model's the tracking stage estimated (`friction_factor` > 0; 1: the
/// model's): min(1, (1 - reduction) x factor) (docs/optimal_control.md, "The friction the hold
/// compensates"). Preconditions: the inputs in their ranges (FrictionCompensation::step checks them).
[[nodiscard]] double kept_sliding_share(double sliding_friction_reduction, double friction_factor) noexcept;

/// F_f/K_m [V] for one axis at `velocity` [m/s or rad/s] and commanded voltage [V].
/// Preconditions: finite inputs, validated params.
[[nodiscard]] double friction_voltage(const AxisCompensationParams& axis, double velocity,
                                      double commanded_voltage) noexcept;

class FrictionCompensation {
 public:
  /// Throws common::ConfigError naming the field, value and bound for negative or non-finite
  /// friction coefficients, zero_velocity_band < 0, stiction_slope <= 0, voltage_limit <= 0, or an
  /// unknown velocity source.
  explicit FrictionCompensation(const FrictionCompensationParams& params);

  /// rejected_nonfinite if a used input is NaN/Inf or sliding_friction_reduction is outside [0, 1],
  /// or finite inputs overflow the friction voltage
  /// (an absurd online coefficient times an absurd rate): output set to zero voltages and hoist speed.
  [[nodiscard]] common::StepStatus step(const FrictionCompensationInput& input,
                                        FrictionCompensationOutput& output) const noexcept;

  [[nodiscard]] const FrictionCompensationParams& params() const noexcept { return params_; }

 private:
  FrictionCompensationParams params_;
};

}  // namespace crane::friction_compensation
