#include "crane/trajectory_planner/planned_path.hpp"

#include <algorithm>
#include <cmath>

namespace crane::trajectory_planner {

bool swings_down_to(const EquivalentPendulum& pendulum, double shortest_cable) noexcept {
  return pendulum.scale >= kMinSwingLengthScale && pendulum.scale <= kMaxSwingLengthScale &&
         pendulum.offset >= kMinSwingLengthOffset && pendulum.offset <= kMaxSwingLengthOffset &&
         equivalent_swing_length(pendulum, shortest_cable) > 0.0;
}

std::size_t PlannedPath::index(double time) const noexcept {
  if (trolley.empty()) return 0;
  const double k = std::round(time / sample_period);
  if (!(k > 0.0)) return 0;
  return std::min(static_cast<std::size_t>(std::min(k, 1e15)), trolley.size() - 1);
}

bool PlannedPath::valid() const noexcept {
  const std::size_t n = trolley.size();
  if (!(sample_period > 0.0) || !std::isfinite(sample_period) || n < 2 || slew.size() != n || cable.size() != n ||
      laws.size() != n || (!bridge.empty() && bridge.size() != n)) {
    return false;
  }
  const auto finite = [](const common::AxisReference& r) {
    return std::isfinite(r.position) && std::isfinite(r.velocity) && std::isfinite(r.acceleration);
  };
  for (const auto* axis : {&trolley, &slew, &cable, &bridge}) {
    if (!std::all_of(axis->begin(), axis->end(), finite)) return false;
  }
  for (const common::TrajectoryFeedback& law : laws) {
    for (const auto* values : {&law.position, &law.velocity}) {
      if (!std::all_of(values->begin(), values->end(), [](double v) { return std::isfinite(v); })) return false;
    }
    if (!std::all_of(law.gain.begin(), law.gain.end(), [](double v) { return std::isfinite(v); }) ||
        !std::isfinite(law.feedforward[0]) || !std::isfinite(law.feedforward[1]) ||
        !(law.sliding_friction_reduction >= 0.0 && law.sliding_friction_reduction <= 1.0)) {
      return false;
    }
  }
  return true;
}

common::AxisReference PlannedProfile::sample(double time) const noexcept {
  if (!path_ || axis_ == nullptr) return {};
  const auto& samples = (*path_).*axis_;
  if (samples.empty()) return {};
  const std::size_t k = path_->index(time);
  common::AxisReference r = samples[k];
  if (k + 1 == samples.size()) r.velocity = r.acceleration = 0.0;  // at rest at the target
  return r;
}

}  // namespace crane::trajectory_planner
