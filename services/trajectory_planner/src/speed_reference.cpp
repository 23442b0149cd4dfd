#include "crane/trajectory_planner/speed_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace crane::trajectory_planner {
namespace {

// The ramp toward 0 from `command`, `steps` cycles ahead: what step() computes with target 0.
double ramp_to_zero(double command, double decrement, double steps) {
  const double magnitude = std::max(0.0, std::abs(command) - decrement * steps);
  return std::copysign(magnitude, command);
}

}  // namespace

void SpeedAxis::start(double position, double velocity) noexcept {
  const double v = std::isfinite(velocity) ? velocity : 0.0;
  commands_.fill(v);
  head_ = 0;
  command_ = v;
  quiet_time_ = v == 0.0 ? 1e9 : 0.0;
  position_ = std::isfinite(position) ? position : 0.0;
  velocity_ = v;
  acceleration_ = 0.0;
}

double SpeedAxis::history(double age) const noexcept {
  const double clamped = std::clamp(age, 0.0, static_cast<double>(kHistory - 1));
  const auto whole = static_cast<std::size_t>(clamped);
  const double fraction = clamped - static_cast<double>(whole);
  const auto at = [&](std::size_t cycles_ago) {
    return commands_[(head_ + kHistory - std::min(cycles_ago, kHistory - 1)) % kHistory];
  };
  return fraction == 0.0 ? at(whole) : (1.0 - fraction) * at(whole) + fraction * at(whole + 1);
}

void SpeedAxis::step(double target_speed, double dt, const SpeedAxisParams& params,
                     const InputShaper& shaper) noexcept {
  const double target = std::isfinite(target_speed) ? target_speed : 0.0;
  const double step_limit = params.acceleration * dt;
  command_ += std::clamp(target - command_, -step_limit, step_limit);
  head_ = (head_ + 1) % kHistory;
  commands_[head_] = command_;
  quiet_time_ = command_ == 0.0 ? quiet_time_ + dt : 0.0;
  shaper_length_ = shaper.length();
  double v = 0.0;
  for (std::size_t i = 0; i < shaper.impulse_count(); ++i) v += shaper.amplitude(i) * history(shaper.time(i) / dt);
  acceleration_ = (v - velocity_) / dt;
  position_ += 0.5 * (velocity_ + v) * dt;
  velocity_ = v;
}

double SpeedAxis::rest(double dt, const SpeedAxisParams& params, const InputShaper& shaper) const noexcept {
  const double decrement = params.acceleration * dt;
  const double ramp_steps = std::ceil(std::abs(command_) / decrement);
  const double horizon = ramp_steps + shaper.length() / dt + 2.0;
  // No crane ramps this long to a stop; only an absurd speed handed over from a corrupted state gets
  // here (fuzz finding 7: 8e32 m/s, 1e38 cycles). Reported as not coming to rest: the largest finite
  // position in the direction of the command, at once.
  if (!(horizon <= static_cast<double>(kMaxRestCycles))) {
    return std::copysign(std::numeric_limits<double>::max(), command_);
  }
  double position = position_;
  double velocity = velocity_;
  for (double j = 1.0; j <= horizon; j += 1.0) {
    double v = 0.0;
    for (std::size_t i = 0; i < shaper.impulse_count(); ++i) {
      const double s = j - shaper.time(i) / dt;  // cycles from now of the command this impulse reads
      double c = 0.0;
      if (s <= 0.0) {
        c = history(-s);
      } else {
        const double whole = std::floor(s);
        const double fraction = s - whole;
        const double lower = ramp_to_zero(command_, decrement, whole);
        c = fraction == 0.0 ? lower : (1.0 - fraction) * lower + fraction * ramp_to_zero(command_, decrement, whole + 1.0);
      }
      v += shaper.amplitude(i) * c;
    }
    position += 0.5 * (velocity + v) * dt;
    velocity = v;
  }
  return position;
}

}  // namespace crane::trajectory_planner

#include "crane/common/validation.hpp"
#include "crane/trajectory_planner/zone_guard.hpp"

namespace crane::trajectory_planner {

void validate(const ManualParams& p) {
  const std::string prefix = "trajectory_planner.manual.";
  const std::pair<const char*, const SpeedAxisParams*> axes[] = {
      {"trolley", &p.trolley}, {"slew", &p.slew}, {"hoist", &p.hoist}, {"bridge", &p.bridge}};
  for (const auto& [name, axis] : axes) {
    common::require_greater(prefix + name + "_speed", axis->rated_speed, 0.0);
    common::require_greater(prefix + name + "_acceleration", axis->acceleration, 0.0);
  }
  common::require_greater(prefix + "micro_speed_fraction", p.micro_speed_fraction, 0.0);
  common::require_in_range(prefix + "micro_speed_fraction", p.micro_speed_fraction, 0.0, 1.0);
  common::require_greater(prefix + "maintenance_speed_fraction", p.maintenance_speed_fraction, 0.0);
  common::require_in_range(prefix + "maintenance_speed_fraction", p.maintenance_speed_fraction, 0.0, 1.0);
  common::require_in_range(prefix + "dead_man_timeout", p.dead_man_timeout, 0.02, 5.0);
  common::require_in_range(prefix + "swing_length_scale", p.swing_length_scale, kMinSwingLengthScale,
                           kMaxSwingLengthScale);
  common::require_in_range(prefix + "swing_length_offset", p.swing_length_offset, kMinSwingLengthOffset,
                           kMaxSwingLengthOffset);
  common::require_in_range(prefix + "swing_damping_ratio", p.swing_damping_ratio, 0.0, 0.3);
}

void SpeedReference::start(const common::MotionReference& from) noexcept {
  axes_[0].start(from.trolley.position, from.trolley.velocity);
  axes_[1].start(from.slew.position, from.slew.velocity);
  axes_[2].start(from.cable_length.position, from.cable_length.velocity);
}

void SpeedReference::start_axis(std::size_t axis, const common::AxisReference& from) noexcept {
  if (axis < axes_.size()) axes_[axis].start(from.position, from.velocity);
}

const char* to_string(SpeedShaping shaping) noexcept {
  switch (shaping) {
    case SpeedShaping::none: return "none";
    case SpeedShaping::zv: return "zv";
    case SpeedShaping::zvd: return "zvd";
    case SpeedShaping::ei: return "ei";
    case SpeedShaping::mzv: return "mzv";
    case SpeedShaping::two_hump_ei: return "two_hump_ei";
  }
  return "none";
}

SpeedShaping speed_shaping_from_string(const std::string& text, const std::string& field) {
  std::string names;
  for (SpeedShaping s : {SpeedShaping::none, SpeedShaping::zv, SpeedShaping::zvd, SpeedShaping::ei, SpeedShaping::mzv,
                         SpeedShaping::two_hump_ei}) {
    if (text == to_string(s)) return s;
    names += names.empty() ? "" : ", ";
    names += to_string(s);
  }
  throw common::ConfigError(field + " = \"" + text + "\" is not a shaping: must be one of " + names);
}

namespace {
ShaperKind shaper_kind(SpeedShaping shaping) noexcept {
  switch (shaping) {
    case SpeedShaping::zv: return ShaperKind::zv;
    case SpeedShaping::ei: return ShaperKind::ei;
    case SpeedShaping::mzv: return ShaperKind::mzv;
    case SpeedShaping::two_hump_ei: return ShaperKind::two_hump_ei;
    default: return ShaperKind::zvd;
  }
}
}  // namespace

double shaper_delay_periods(SpeedShaping shaping, double damping_ratio) {
  if (shaping == SpeedShaping::none) return 0.0;
  ShaperParams p;
  p.kind = shaper_kind(shaping);
  p.natural_frequency = 1.0;  // [rad/s]: the period is 2 pi s
  p.damping_ratio = damping_ratio;
  return InputShaper(p).mean_delay() / (2.0 * std::numbers::pi);
}

std::array<InputShaper, 3> SpeedReference::shapers(SpeedShaping shaping, const ManualParams& params,
                                                   const SpeedBounds& bounds, double dt) const noexcept {
  std::array<InputShaper, 3> s{};  // identity shapers
  if (shaping == SpeedShaping::none) return s;
  // The equivalent pendulum length (1 * L + 0 = L exactly for the uncalibrated single pendulum).
  const double cable = equivalent_swing_length(params, axes_[2].position());
  if (!(cable > 0.0) || !(bounds.gravity > 0.0)) return s;
  ShaperParams p;
  p.kind = shaper_kind(shaping);
  p.damping_ratio = params.swing_damping_ratio;
  p.natural_frequency = std::sqrt(bounds.gravity / cable);
  // A shaper longer than the history cannot be applied; the identity stays (cable beyond ~25 m at 100 Hz).
  // design() does not know the history: its length is checked here. Before this check an absurd cable
  // (3e180 m from a corrupted estimate: a 3.5e90 s shaper) made rest() loop for ever (tests/fuzz).
  if (s[0].design(p) != ProfileStatus::ok ||
      !(s[0].length() < static_cast<double>(SpeedAxis::kHistory - 1) * dt)) {
    return std::array<InputShaper, 3>{};
  }
  s[1] = s[0];
  return s;
}

bool SpeedReference::keeps_bounds(double dt, const ManualParams& params, const std::array<InputShaper, 3>& shapers,
                                  const SpeedBounds& bounds, const common::Site& site, std::uint32_t zones_enabled,
                                  const ZoneDistances& caps) const noexcept {
  const SpeedAxisParams* axis_params[3] = {&params.trolley, &params.slew, &params.hoist};
  std::array<double, 3> rest{};
  for (std::size_t i = 0; i < 3; ++i) {
    rest[i] = axes_[i].rest(dt, *axis_params[i], shapers[i]);
    // Travel: the rest position inside, or (already outside) no further out than now.
    const double now = axes_[i].position();
    if (rest[i] > bounds.max[i] && rest[i] > now) return false;
    if (rest[i] < bounds.min[i] && rest[i] < now) return false;
  }
  if (zones_enabled == 0 || site.zones.empty()) return true;
  // The swing of stopping from the current horizontal speed (at most the ramps' accelerations), and
  // no closer to a zone than the crane is now if it is already inside a margin.
  const double reach = std::max(std::abs(axes_[0].position()), std::abs(rest[0]));
  const double acceleration = std::hypot(params.trolley.acceleration, reach * params.slew.acceleration);
  const double speed = std::hypot(axes_[0].velocity(), axes_[0].position() * axes_[1].velocity());
  const double cable = std::max(axes_[2].position(), rest[2]);
  const double allowance = swing_allowance(cable, acceleration, speed, bounds.gravity);
  return intruded_zone(site, zones_enabled, axes_[0].position(), rest[0], axes_[1].position(), rest[1],
                       axes_[2].position(), rest[2], allowance, &caps) < 0;
}

std::uint8_t SpeedReference::step(const std::array<double, 3>& targets, double dt, const ManualParams& params,
                                  SpeedShaping shaping, const SpeedBounds& bounds, const common::Site& site,
                                  std::uint32_t zones_enabled) noexcept {
  const auto shaper = shapers(shaping, params, bounds, dt);
  const SpeedAxisParams* axis_params[3] = {&params.trolley, &params.slew, &params.hoist};
  // Candidates, in order: every target as asked, then with the axes in `released` set to 0.
  static constexpr std::uint8_t kReleased[] = {0, 1, 2, 4, 3, 5, 6, 7};
  // Where the crane is now: a zone margin it is already inside may not be entered further.
  const ZoneDistances caps = zone_distances(site, reference());
  for (const std::uint8_t released : kReleased) {
    SpeedReference next = *this;
    for (std::size_t i = 0; i < 3; ++i) {
      const double target = (released & (1U << i)) != 0 ? 0.0 : targets[i];
      next.axes_[i].step(target, dt, *axis_params[i], shaper[i]);
    }
    if (released == 7 || next.keeps_bounds(dt, params, shaper, bounds, site, zones_enabled, caps)) {
      *this = next;
      // Axes that were asked to move but were held back.
      std::uint8_t held = 0;
      for (std::size_t i = 0; i < 3; ++i) {
        if ((released & (1U << i)) != 0 && std::isfinite(targets[i]) && targets[i] != 0.0) held |= 1U << i;
      }
      return held;
    }
  }
  return 0;  // not reached: the last candidate is always taken
}

std::array<double, 3> SpeedReference::rest(double dt, const ManualParams& params, SpeedShaping shaping,
                                           const SpeedBounds& bounds) const noexcept {
  const auto shaper = shapers(shaping, params, bounds, dt);
  return {axes_[0].rest(dt, params.trolley, shaper[0]), axes_[1].rest(dt, params.slew, shaper[1]),
          axes_[2].rest(dt, params.hoist, shaper[2])};
}

bool SpeedReference::at_rest() const noexcept {
  return axes_[0].at_rest() && axes_[1].at_rest() && axes_[2].at_rest();
}

common::MotionReference SpeedReference::reference() const noexcept {
  common::MotionReference r;
  r.trolley = {axes_[0].position(), axes_[0].velocity(), axes_[0].acceleration()};
  r.slew = {axes_[1].position(), axes_[1].velocity(), axes_[1].acceleration()};
  r.cable_length = {axes_[2].position(), axes_[2].velocity(), axes_[2].acceleration()};
  return r;
}

}  // namespace crane::trajectory_planner
