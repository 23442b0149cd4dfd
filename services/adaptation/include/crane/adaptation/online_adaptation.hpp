#pragma once
// Online payload mass estimation and friction re-estimation while the crane works: the
// dissertation's future work (section 5.1 of H. M. Omar, "Control of Gantry and Tower Cranes",
// Virginia Tech 2003). Runs in the state estimator stage on each sensor sample; no DDS, clock or
// thread.
//
// Axis equations in volt-equivalents (the drive gains K_mx [m/s^2/V], K_mgamma [rad/s^2/V]):
//   trolley, (3.31) with friction (3.1) and the slew's centrifugal term of the plant's Lagrangian:
//     x''/K_mx - u_x - (M_t/M) x gamma'^2 / K_mx = - m_t g phi / K_mx - F_f(x')/K_m
//   slew, (3.32) with the Coriolis term of d/dt[(1 + M_r x^2) gamma']:
//     [(1 + M_r x^2) gamma']' / K_mgamma - u_gamma = + m_r g x theta / K_mgamma - F_f(gamma')/K_m
// with m_t = m/M (M = trolley_drive_mass) and m_r = m/J_o, F_f/K_m the sliding friction
// b+ v eta + b- v xi + c+ eta - c- xi of (3.1), (3.13) (friction_compensation::friction_regressor),
// u the drive voltage applied (SensorSample's applied_*_voltage: after the DAC, the compensation
// included). Each row is an AxisIdentifier regression (axis_identifier.hpp).
//
// No double differentiation of encoder noise: every signal of both sides passes one stable
// low-pass H (second-order Butterworth, `filter_cutoff`, state_estimator::butterworth_low_pass)
// and the derivatives are the filtered positions' differences (state-variable filtering):
// x'' from [x(k) - 2 x(k-1) + x(k-2)]/T^2, centred at k-1, paired with the mean of the voltages
// applied over [k-2, k-1) and [k-1, k) and the central velocity [x(k) - x(k-2)]/(2T), as
// model_audit::DifferenceScheme::centered (exact to O(T^2) with a held input).
// A row is taken only while the axis has slid in one direction of (3.3) (outside the zero-velocity
// band d_s, brakes off) for longer than H's memory (its impulse response down to 1 %), because
// static friction in the band is not a function of the velocity.
//
// What is released:
//   payload mass m = m_t M (trolley) and m_r J_o (slew), combined by inverse variance when both
//   axes identify it; bound = 2 standard deviations; confident while the bound is within
//   `mass_relative_bound` of the mass and the mass within [min_mass, max_mass]. The consumers
//   (gain schedule (3.37)-(3.38), tracking) use it only when confident.
//   friction coefficients in use: once a direction is excited (AxisIdentifier's check), each of its
//   coefficients whose estimate is within its safe range [min_friction_factor, max_friction_factor]
//   x configured, with a 2-sigma bound within `friction_relative_bound` of it (of its typical size
//   when larger: the configured value, at least 0.5 V s/m or 0.1 V); a coefficient approaches its
//   estimate at most `max_friction_rate` x that size per second (the bounded update rate; the
//   estimate itself is re-solved every `solve_period`). The others stay as they are.
//   Breakaway (static) friction, which the sliding regression cannot see, is scaled with the Coulomb
//   coefficient of its direction (fs/c as configured, (4.13)/(4.15)).
//   Limit cycle (the stiction hazard of section 3.1): LimitCycleDetector on each drive; when it
//   fires, that axis falls back to the configured coefficients and stays there (latched).
//
// Errors: the constructor validates (common::ConfigError naming the field, value and bound);
// step() is noexcept, allocates nothing, and ignores samples with a non-finite value.

#include <array>
#include <cstdint>

#include "crane/adaptation/axis_identifier.hpp"
#include "crane/adaptation/limit_cycle_detector.hpp"
#include "crane/common/crane_parameters.hpp"
#include "crane/state_estimator/discrete_filter.hpp"

namespace crane::adaptation {

struct OnlineAdaptationParams {
  bool enabled{false};                   // false: step() reports the configured values, nothing adapts
  common::CraneParameters crane{};       // the configured crane (load mass, M, J_o, M_t, gains, friction)
  double sample_period{0.01};            // [s] T, in (0, 1]
  double filter_cutoff{4.0};             // [Hz] H's cutoff, in (0, 0.45 / T)
  double trolley_zero_velocity_band{0.01};  // [m/s] d_s of (3.3) for the trolley, >= 0
  double slew_zero_velocity_band{0.01};     // [rad/s] for the slew, >= 0
  double forgetting_factor{0.998};       // [-] in [0.9, 1]
  double min_information{1.0};           // [V^2] AxisIdentifierParams::min_information, > 0
  double max_condition{1e4};             // [-] AxisIdentifierParams::max_condition, >= 1
  double solve_period{0.1};              // [s] the estimate is re-solved at most this often, >= T
  double mass_relative_bound{0.05};      // [-] confident while bound <= this x mass, in (0, 1]
  double min_mass{0.0};                  // [kg] >= 0, <= crane.load_mass
  double max_mass{20.0};                 // [kg] > min_mass, >= crane.load_mass
  bool adapt_friction{true};             // false: the payload mass only, the compensation keeps the configured
                                         // friction (the regression still solves it: printed, never released)
  double friction_relative_bound{0.2};   // [-] a coefficient is released while 2 sigma <= this x value
  double min_friction_factor{0.5};       // [-] safe range of a released coefficient, x configured, in (0, 1]
  double max_friction_factor{2.0};       // [-] >= 1
  double max_friction_rate{0.1};         // [1/s] released coefficients move at most this x configured per s, > 0
  LimitCycleParams limit_cycle{};        // both drives
};

/// Throws common::ConfigError naming the field ("state_estimator.adaptation.<name>"), the value and
/// the bound.
void validate(const OnlineAdaptationParams& params);

/// A stable low-pass's impulse response h: its memory [samples] (the last sample with |h| >= 1 % of
/// the peak) and the equivalent number of correlated samples (sum h)^2 / sum h^2 (>= 1) of rows
/// filtered by it. Allocates (the response); for constructors.
struct ImpulseFigures {
  int memory{0};
  double correlation{1.0};
};
[[nodiscard]] ImpulseFigures impulse_figures(const state_estimator::DiscreteTransferFunction& low_pass);

/// One sensor sample as the estimator sees it (SI; voltages applied during the previous cycle).
struct AdaptationInput {
  double trolley_position{0.0};        // [m] x(k)
  double slew_angle{0.0};              // [rad] gamma(k)
  double swing_in_plane{0.0};          // [rad] phi(k)
  double swing_out_of_plane{0.0};      // [rad] theta(k)
  double applied_trolley_voltage{0.0}; // [V] over [k-1, k)
  double applied_slew_voltage{0.0};    // [V] over [k-1, k)
  bool brakes_engaged{true};
};

/// What the stage publishes (CraneState_'s adaptation fields).
struct AdaptationEstimate {
  double payload_mass{0.0};            // [kg] estimated (the configured load mass until identified)
  double payload_mass_bound{0.0};      // [kg] 2 standard deviations (0 until identified)
  bool payload_confident{false};       // consumers may use payload_mass
  common::AxisFriction trolley_friction{};  // in use by the compensation [V, V s/m]
  common::AxisFriction slew_friction{};     // [V, V s/rad]
  bool trolley_friction_adapted{false};     // trolley_friction differs from the configured
  bool slew_friction_adapted{false};
  bool trolley_limit_cycle{false};     // detector fired: configured trolley friction, latched
  bool slew_limit_cycle{false};
  std::uint32_t trolley_voltage_sign_changes{0};  // drive-voltage sign changes at rest, since start
  std::uint32_t slew_voltage_sign_changes{0};
};

class OnlineAdaptation {
 public:
  /// Throws common::ConfigError (validate).
  explicit OnlineAdaptation(const OnlineAdaptationParams& params);

  /// One sample. Never throws, never allocates; a sample with a non-finite value is skipped (the
  /// previous estimate stays). Disabled: `estimate` is the configured values.
  void step(const AdaptationInput& input, AdaptationEstimate& estimate) noexcept;

  [[nodiscard]] const AxisIdentifier& trolley() const noexcept { return trolley_; }
  [[nodiscard]] const AxisIdentifier& slew() const noexcept { return slew_; }
  [[nodiscard]] const OnlineAdaptationParams& params() const noexcept { return params_; }
  /// [samples] H's memory: rows are taken only after this many samples sliding in one direction.
  [[nodiscard]] int settle_samples() const noexcept { return settle_samples_; }
  /// [samples] (sum h)^2 / sum h^2 of H: the equivalent number of correlated residuals.
  [[nodiscard]] double noise_correlation() const noexcept { return noise_correlation_; }

 private:
  // Per axis: the three parts of y (derivative, voltage, known coupling), then the kParameterCount
  // regressors; the trolley's first, then the slew's.
  static constexpr int kFiltersPerAxis = 3 + kParameterCount;
  struct History {
    double x[3]{};      // x(k), x(k-1), x(k-2)
    double gamma[3]{};
    double phi[2]{};    // phi(k), phi(k-1)
    double theta[2]{};
    double u_x[2]{};    // applied over [k-1,k), [k-2,k-1)
    double u_gamma[2]{};
    int count{0};
  };
  void release(AdaptationEstimate& estimate) noexcept;
  void release_axis(const AxisIdentifier& id, const common::AxisFriction& configured, bool limit_cycle,
                    common::AxisFriction& in_use) noexcept;
  // Filters the raw row `raw` (y parts, then regressors) of `axis` (0 trolley, 1 slew).
  void filter_row(int axis, const std::array<double, kFiltersPerAxis>& raw,
                  std::array<double, kFiltersPerAxis>& filtered) noexcept;

  OnlineAdaptationParams params_;
  AxisIdentifier trolley_;
  AxisIdentifier slew_;
  LimitCycleDetector trolley_cycles_;
  LimitCycleDetector slew_cycles_;
  state_estimator::DiscreteTransferFunction low_pass_{};
  std::array<state_estimator::DiscreteFilter, 2 * kFiltersPerAxis> filters_{};
  History history_{};
  int settle_samples_{0};
  double noise_correlation_{1.0};
  int trolley_sliding_{0};   // samples sliding in one direction (0: in the band or braked)
  int slew_sliding_{0};
  int trolley_direction_{0};
  int slew_direction_{0};
  int solve_countdown_{0};
  int solve_interval_{1};
  common::AxisFriction trolley_in_use_{};
  common::AxisFriction slew_in_use_{};
  bool filters_initialized_{false};
  double confident_mass_{0.0};
  double confident_bound_{0.0};
  bool ever_confident_{false};
};

}  // namespace crane::adaptation
