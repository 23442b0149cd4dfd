#pragma once
// Operator speed control with sway control (manual mode), and the controlled anti-sway stop.
//
// What the industrial anti-sway products do in manual mode, here per axis: the operator's speed
// command (a fraction of the rated speed) is rate-limited to the axis's acceleration (a ramp), then
// convolved with an input shaper tuned to the load's swing w = sqrt(g/L) at the current cable length
// (ZV by default: Singer and Seering 1990; input_shaper.hpp). The shaped speed is the reference
// velocity; its integral the reference position. The load follows without swing and, when the stick
// is released (command 0), comes to rest without swing, half a swing period (ZV) after the ramp
// ends. The hoist axis is ramped only (the cable does not swing).
//
// A stop is the same thing with the command 0: the planner hands its running profile's position
// and velocity over to a SpeedReference (start()), whose history is filled as if that velocity had
// been commanded for ever (so the shaped velocity is continuous), and commands 0.
//
// rest() predicts where each axis comes to rest if the command is 0 from now on: the same
// discrete-time ramp and shaper run forward on the stored history, so the prediction is exact for
// the reference (tests/services/test_speed_reference.cpp checks it against stepping).
//
// Real time: step(), rest(), start() are noexcept and allocate nothing (fixed history ring).

#include <array>
#include <string>
#include <cstddef>
#include <cstdint>

#include "crane/common/crane_signals.hpp"
#include "crane/common/site.hpp"
#include "crane/trajectory_planner/input_shaper.hpp"
#include "crane/trajectory_planner/planned_path.hpp"

namespace crane::trajectory_planner {

enum class SpeedShaping {
  none,  // ramp only (maintenance mode)
  zv,
  zvd,
  ei,           // the InputShaper kinds of the same names (input_shaper.hpp); the last three are what
  mzv,          // `deploy/crane calibrate swing` may recommend (docs/calibration.md)
  two_hump_ei,
};
/// "none", "zv", "zvd", "ei", "mzv", "two_hump_ei" (the config's names).
[[nodiscard]] const char* to_string(SpeedShaping shaping) noexcept;
/// Parses a config name; throws common::ConfigError naming `field`, the value and the names.
[[nodiscard]] SpeedShaping speed_shaping_from_string(const std::string& text, const std::string& field);
/// The mean delay of `shaping`'s shaper (InputShaper::mean_delay) in undamped swing periods
/// 2 pi sqrt(L/g) [-], for a swing of damping ratio `damping_ratio` [-]: how much further a stop
/// shaped with it travels, v T times this (zvd 0.5, zv 0.25, none 0; independent of L). It is the
/// supervisor's zone_stop_delay_periods and the site's stopping model of the crane (stack_config.hpp
/// checks the first against manual.shaping). Throws common::ConfigError for a damping ratio the
/// shaper cannot be designed for (InputShaper's bounds).
[[nodiscard]] double shaper_delay_periods(SpeedShaping shaping, double damping_ratio);

/// One axis's rated motion. Units: [m], [m/s], [m/s^2] for the trolley and the hoist (cable
/// length), [rad], [rad/s], [rad/s^2] for the slew.
struct SpeedAxisParams {
  double rated_speed{0.5};        // > 0: the speed of a full command (1.0)
  double acceleration{1.0};       // > 0: the ramp's rate of change of the commanded speed
  bool swings{true};              // shaped (trolley, slew) or ramped only (hoist)
};

/// One axis: ramp, then shaper, then integration.
class SpeedAxis {
 public:
  static constexpr std::size_t kHistory = 1024;  // cycles of commanded speed kept (10.24 s at 100 Hz)

  /// Starts at `position` moving at `velocity` (history filled with it: a continuous hand-over).
  void start(double position, double velocity) noexcept;
  /// One cycle of `dt` [s]: ramps the commanded speed toward `target_speed` by at most
  /// acceleration * dt, shapes it with `shaper` (its impulse times must be below kHistory * dt) and
  /// integrates. Non-finite arguments are treated as a target of 0.
  void step(double target_speed, double dt, const SpeedAxisParams& params, const InputShaper& shaper) noexcept;
  static constexpr std::size_t kMaxRestCycles = 1000000;  // longest stop rest() runs forward (10^4 s at 100 Hz)

  /// Where the reference comes to rest if the target is 0 from now on, with `shaper` [axis unit].
  /// A stop longer than kMaxRestCycles cycles (an absurd handed-over speed) gives
  /// +-std::numeric_limits<double>::max() in the direction of the command, without running it.
  [[nodiscard]] double rest(double dt, const SpeedAxisParams& params, const InputShaper& shaper) const noexcept;
  /// True when the commanded and the shaped speeds are both 0 and the shaper (of the last step) has
  /// let all of the commanded motion through.
  [[nodiscard]] bool at_rest() const noexcept {
    return command_ == 0.0 && velocity_ == 0.0 && quiet_time_ > shaper_length_;
  }

  [[nodiscard]] double position() const noexcept { return position_; }
  [[nodiscard]] double velocity() const noexcept { return velocity_; }
  [[nodiscard]] double acceleration() const noexcept { return acceleration_; }
  [[nodiscard]] double commanded_speed() const noexcept { return command_; }

 private:
  /// Commanded speed `age` cycles ago (fractional, linear interpolation; beyond the history: the oldest).
  [[nodiscard]] double history(double age) const noexcept;

  std::array<double, kHistory> commands_{};  // ring: commands_[head_] is the newest
  std::size_t head_{0};
  double command_{0.0};
  double quiet_time_{1e9};     // [s] since the commanded speed was last non-zero
  double shaper_length_{0.0};  // [s] of the shaper of the last step
  double position_{0.0};
  double velocity_{0.0};
  double acceleration_{0.0};
};

/// Manual mode's rated motion (the `trajectory_planner.manual:` block), after the limits of (3.54)
/// and (3.55) for the lab crane.
struct ManualParams {
  SpeedAxisParams trolley{0.4982, 0.9929, true};   // [m/s], [m/s^2]
  SpeedAxisParams slew{1.0435, 2.0796, true};      // [rad/s], [rad/s^2]
  SpeedAxisParams hoist{0.2, 0.5, false};          // [m/s], [m/s^2] (+ lowers the load)
  SpeedAxisParams bridge{0.5, 0.5, true};          // [m/s], [m/s^2] an overhead crane's bridge (read there only)
  double micro_speed_fraction{0.1};        // (0, 1]: fine positioning (OperatorSpeed RANGE_MICRO)
  double maintenance_speed_fraction{0.25}; // (0, 1]: every speed in MAINTENANCE mode
  double dead_man_timeout{0.2};            // [s] no operator input for longer: every axis released
  SpeedShaping shaping{SpeedShaping::zv};  // sway control in MANUAL and SEMIAUTOMATIC
  // The swing the shaper is designed for: w = sqrt(g / (swing_length_scale L + swing_length_offset)),
  // damping swing_damping_ratio. 1, 0, 0 is the single pendulum sqrt(g/L); a calibration
  // (deploy/crane calibrate swing) fits them from a recording (a hook, rigging, a stiff rope). The
  // minimum-time plans use the same equivalent length (equivalent_swing_length; optimal_control's
  // minimum_time_problem), so one calibration serves manual and automatic moves.
  double swing_length_scale{1.0};   // [-] in [0.1, 10] (EquivalentPendulum's ranges, planned_path.hpp)
  double swing_length_offset{0.0};  // [m] in [-1, 10]; an equivalent length <= 0 gets no shaping
  double swing_damping_ratio{0.0};  // [-] in [0, 0.3]
  [[nodiscard]] EquivalentPendulum pendulum() const noexcept { return {swing_length_scale, swing_length_offset}; }
};
/// [m] The equivalent pendulum length of `params` at cable length `cable_length` [m]:
/// swing_length_scale L + swing_length_offset (1 L + 0 = L exactly, uncalibrated). Not checked > 0.
[[nodiscard]] inline double equivalent_swing_length(const ManualParams& params, double cable_length) noexcept {
  return equivalent_swing_length(params.pendulum(), cable_length);
}

/// Throws common::ConfigError naming the field ("trajectory_planner.manual.<name>") unless every
/// speed and acceleration is finite and > 0, both fractions in (0, 1], the timeout in [0.02, 5] s,
/// the swing model's fields in their ranges above.
void validate(const ManualParams& params);

/// The bounds the speed reference keeps: each axis's rest position inside its travel (trolley,
/// slew, cable length), and the load out of the site's enabled zones.
struct SpeedBounds {
  std::array<double, 3> min{0.1, -6.283185307179586, 0.2};  // trolley [m], slew [rad], cable [m]
  std::array<double, 3> max{1.2, 6.283185307179586, 5.0};
  double gravity{9.8};                                      // [m/s^2] swing frequency sqrt(g/L)
};

/// The three axes under speed control (trolley, slew, hoist), with the bounds as a positioning
/// assist: each cycle the operator's speeds are taken only if the load can still come to rest
/// inside the travel and outside every zone; otherwise the offending axes are released (their
/// speed ramps to 0 and the shaper stops them without swing). Index 0 trolley, 1 slew, 2 hoist.
class SpeedReference {
 public:
  /// Hands over from `from` (positions and velocities of a running reference, or at rest).
  void start(const common::MotionReference& from) noexcept;
  /// Hands axis `axis` (0 trolley, 1 slew, 2 hoist; others ignored) over from `from` as start() does
  /// every axis: its position and velocity, the history filled with that velocity. The planner stage
  /// calls it each cycle for an axis that runs on to its target while the others stop, so that the
  /// axis rests where its profile ends.
  void start_axis(std::size_t axis, const common::AxisReference& from) noexcept;

  /// One cycle of dt [s] toward the target speeds (axis units; non-finite = 0), shaped for the cable
  /// length of the reference with `shaping`. `site` and `zones_enabled` (bit i: site.zones[i]) are the
  /// zones to keep out of. Returns the AXIS bits (1 trolley, 2 slew, 4 hoist) whose targets were
  /// replaced by 0 to keep the bounds.
  std::uint8_t step(const std::array<double, 3>& target_speeds, double dt, const ManualParams& params,
                    SpeedShaping shaping, const SpeedBounds& bounds, const common::Site& site,
                    std::uint32_t zones_enabled) noexcept;

  /// Where each axis comes to rest if every target is 0 from now on (SpeedAxis::rest).
  [[nodiscard]] std::array<double, 3> rest(double dt, const ManualParams& params, SpeedShaping shaping,
                                           const SpeedBounds& bounds) const noexcept;
  [[nodiscard]] bool at_rest() const noexcept;
  [[nodiscard]] common::MotionReference reference() const noexcept;

 private:
  [[nodiscard]] std::array<InputShaper, 3> shapers(SpeedShaping shaping, const ManualParams& params,
                                                   const SpeedBounds& bounds, double dt) const noexcept;
  [[nodiscard]] bool keeps_bounds(double dt, const ManualParams& params, const std::array<InputShaper, 3>& shapers,
                                  const SpeedBounds& bounds, const common::Site& site, std::uint32_t zones_enabled,
                                  const std::array<double, common::Site::kMaxZones>& caps) const noexcept;

  std::array<SpeedAxis, 3> axes_{};
};

}  // namespace crane::trajectory_planner
