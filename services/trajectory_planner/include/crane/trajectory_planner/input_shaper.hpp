#pragma once
// Input shapers for the load swing: ZV and ZVD (N. C. Singer and W. P. Seering, "Preshaping command
// inputs to reduce system vibration", 1990), EI (W. Singhose, W. Seering, N. Singer, "Residual
// vibration reduction using vector diagrams to generate shaped inputs", 1994), MZV (a three-impulse
// zero-vibration shaper of length 3/4 T_d, from the same vector diagrams) and the two-hump EI
// (W. Singhose, L. Porter, T. Tuttle, N. Singer, "Vibration reduction using multi-hump input
// shapers", J. Dyn. Sys. Meas. Control 119, 1997).
//
// The linearized load swing of the tower crane, L phi'' + g phi = x'' (trolley) or
// L theta'' + g theta = -x gamma'' (slew), is an undamped oscillator of natural frequency
// w = sqrt(g/L), period T = 2 pi sqrt(L/g). A shaper is a train of impulses (amplitudes A_i >= 0
// summing to 1, times t_i >= 0, t_1 = 0); convolving a command with it cancels the residual
// vibration at w (ZV, ZVD) or keeps it below a tolerance V over a band around w (EI).
//
// Shapers hold their impulses by value (no allocation); design() is noexcept for run-time use.

#include <array>
#include <cstddef>

namespace crane::trajectory_planner {

/// Gravity used by the swing model [m/s^2] (the thesis uses 9.8).
inline constexpr double kSwingGravity = 9.8;

/// Outcome of a noexcept plan()/design() call.
enum class [[nodiscard]] ProfileStatus {
  ok,
  invalid_parameters,  // non-finite or out-of-range argument; the object is left unchanged
  no_solution,         // the solver found no profile (time-optimal only; should not happen)
};

enum class ShaperKind {
  zv,   // zero vibration: 2 impulses, length T_d/2
  zvd,  // zero vibration and derivative: 3 impulses, length T_d
  ei,   // extra insensitive: 3 impulses, length T_d, residual <= V over about +-20 % (V = 5 %)
  mzv,  // modified ZV: 3 impulses at 0, 3/8 T_d, 3/4 T_d; zero residual at w, between ZV and ZVD in
        // robustness and length
  two_hump_ei,  // two-hump EI: 4 impulses, length 3/2 T_d, residual <= V over about +-40 % (V = 5 %)
};
/// "zv", "zvd", "ei", "mzv", "two_hump_ei".
[[nodiscard]] const char* to_string(ShaperKind kind) noexcept;

struct ShaperParams {
  ShaperKind kind{ShaperKind::zvd};
  double natural_frequency{3.1304951684997055};  // [rad/s] undamped w = sqrt(g/L), > 0
  double damping_ratio{0.0};          // [-] 0 <= zeta < 1 (EI: zeta <= 0.3, curve fit; two-hump EI:
                                      //     zeta <= 0.3, the undamped design with damped amplitudes)
  double vibration_tolerance{0.05};   // [-] EI and two-hump EI: 0 < V <= 0.2
};

/// sqrt(gravity / cable_length) [rad/s]. Throws common::ConfigError unless cable_length [m] and
/// gravity [m/s^2] are finite and > 0.
[[nodiscard]] double pendulum_natural_frequency(double cable_length, double gravity = kSwingGravity);

class InputShaper {
 public:
  static constexpr std::size_t kMaxImpulses = 4;

  /// The identity shaper: one impulse of amplitude 1 at t = 0.
  InputShaper() = default;
  /// Designs the shaper. Throws common::ConfigError naming the field, value and bound unless
  /// natural_frequency is finite and > 0, 0 <= damping_ratio < 1 (<= 0.3 for EI) and, for EI,
  /// 0 < vibration_tolerance <= 0.2.
  explicit InputShaper(const ShaperParams& params);

  /// Same as the constructor without exceptions or allocation; invalid_parameters leaves *this
  /// unchanged.
  ProfileStatus design(const ShaperParams& params) noexcept;

  [[nodiscard]] std::size_t impulse_count() const noexcept { return count_; }
  /// Amplitude of impulse i [-] (precondition i < impulse_count(), asserted).
  [[nodiscard]] double amplitude(std::size_t i) const noexcept;
  /// Time of impulse i [s] after the start (precondition i < impulse_count(), asserted).
  [[nodiscard]] double time(std::size_t i) const noexcept;
  /// Time of the last impulse [s]: the delay the shaper adds to a command.
  [[nodiscard]] double length() const noexcept { return times_[count_ - 1]; }
  /// Mean delay [s], sum A_i t_i: how much later than the unshaped command the shaped one's
  /// displacement comes, once both have ended (a shaped stop travels v * mean_delay() further).
  [[nodiscard]] double mean_delay() const noexcept;

  /// Percentage residual vibration [-] of a mode of frequency `frequency` [rad/s] and damping
  /// `damping_ratio` [-] excited by the impulse train, relative to a single unit impulse
  /// (Singer & Seering's V(w, zeta)). 0 means no residual swing, 1 means unshaped.
  [[nodiscard]] double residual_vibration(double frequency, double damping_ratio = 0.0) const noexcept;

 private:
  std::array<double, kMaxImpulses> amplitudes_{1.0, 0.0, 0.0, 0.0};
  std::array<double, kMaxImpulses> times_{0.0, 0.0, 0.0, 0.0};
  std::size_t count_{1};
};

}  // namespace crane::trajectory_planner
