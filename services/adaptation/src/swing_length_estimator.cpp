#include "crane/adaptation/swing_length_estimator.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Cholesky>

#include "crane/adaptation/axis_identifier.hpp"
#include "crane/adaptation/online_adaptation.hpp"
#include "crane/common/validation.hpp"
#include "crane/plant/crane_simulator.hpp"
#include "crane/state_estimator/filter_design.hpp"

namespace crane::adaptation {

namespace {

constexpr const char* kPrefix = "state_estimator.swing_length";
constexpr double kOffsetUnit = 1.0;  // [m] c's typical size in the scaled information diag(1, 1 m)

enum Signal { kTrolley = 0, kSecond = 1, kInPlane = 2, kOutOfPlane = 3, kCable = 4 };

const SwingLengthParams& validated(const SwingLengthParams& p) {
  validate(p);
  return p;
}

}  // namespace

void validate(const SwingLengthParams& p) {
  const std::string f = kPrefix;
  common::require_in_range(f + ".sample_period", p.sample_period, 1e-6, 1.0);
  common::validate(p.crane, "crane");
  common::require_greater(f + ".filter_cutoff", p.filter_cutoff, 0.0);
  common::require_in_range(f + ".filter_cutoff", p.filter_cutoff, 0.0, 0.45 / p.sample_period);
  common::require_in_range(f + ".forgetting_factor", p.forgetting_factor, 0.9, 1.0);
  common::require_in_range(f + ".min_swing", p.min_swing, 0.0, 1.0);
  common::require_greater(f + ".min_information", p.min_information, 0.0);
  common::require_finite(f + ".min_information", p.min_information);
  common::require_in_range(f + ".max_condition", p.max_condition, 1.0, 1e12);
  common::require_in_range(f + ".solve_period", p.solve_period, p.sample_period, 60.0);
  common::require_greater(f + ".length_bound", p.length_bound, 0.0);
  common::require_in_range(f + ".length_bound", p.length_bound, 0.0, 10.0);
  common::require_greater(f + ".scale_bound", p.scale_bound, 0.0);
  common::require_in_range(f + ".scale_bound", p.scale_bound, 0.0, 10.0);
}

SwingLengthEstimator::SwingLengthEstimator(const SwingLengthParams& params)
    : params_(validated(params)),
      model_(plant::make_crane_dynamics(params_.crane_kind, params_.crane, params_.bridge)),
      low_pass_(state_estimator::butterworth_low_pass(params_.filter_cutoff, 1.0 / params_.sample_period)) {
  for (auto& f : filters_) f = state_estimator::DiscreteFilter(low_pass_);
  noise_correlation_ = impulse_figures(low_pass_).correlation;
  solve_interval_ = std::max(1, static_cast<int>(std::lround(params_.solve_period / params_.sample_period)));
  solve_countdown_ = solve_interval_;
}

void SwingLengthEstimator::step(const SwingLengthInput& in, SwingLengthEstimate& out) noexcept {
  if (!params_.enabled) {
    out = in_use_;
    return;
  }
  const std::array<double, kSignals> raw{in.trolley_position, in.second_axis, in.swing_in_plane,
                                         in.swing_out_of_plane, in.cable_length};
  const bool finite = std::all_of(raw.begin(), raw.end(), [](double v) { return std::isfinite(v); });
  if (!finite || !(in.cable_length > 0.0)) {
    out = in_use_;
    return;
  }
  for (int i = 0; i < kSignals; ++i) {
    auto& filter = filters_[static_cast<std::size_t>(i)];
    auto& h = history_[static_cast<std::size_t>(i)];
    if (samples_ == 0) filter.initialize(raw[static_cast<std::size_t>(i)], raw[static_cast<std::size_t>(i)] * low_pass_.dc_gain());
    h[2] = h[1];
    h[1] = h[0];
    h[0] = filter.update(raw[static_cast<std::size_t>(i)]);
  }
  if (samples_ < 3) ++samples_;
  if (samples_ >= 3 && !in.brakes_engaged) {
    // The filtered state centred at k-1 (header).
    const double t = params_.sample_period;
    const auto second = [&](Signal s) {
      const auto& h = history_[s];
      return (h[0] - 2.0 * h[1] + h[2]) / (t * t);
    };
    const auto first = [&](Signal s) {
      const auto& h = history_[s];
      return (h[0] - h[2]) / (2.0 * t);
    };
    plant::ModelState state;
    plant::CoordinateVector acceleration;
    constexpr std::array<Signal, plant::kNumCoordinates> kSlots{kTrolley, kInPlane, kSecond, kOutOfPlane};
    for (int j = 0; j < plant::kNumCoordinates; ++j) {
      const Signal s = kSlots[static_cast<std::size_t>(j)];
      state.position(j) = history_[s][1];
      state.velocity(j) = first(s);
      acceleration(j) = second(s);
    }
    if (params_.crane_kind == common::CraneKind::gantry) {  // the model holds slots 2 and 3
      for (const int j : {plant::kSlewIndex, plant::kOutOfPlaneSwingIndex}) {
        state.position(j) = state.velocity(j) = acceleration(j) = 0.0;
      }
    }
    const double length = history_[kCable][1];
    const double length_rate = first(kCable);
    take_row(plant::kInPlaneSwingIndex, state, acceleration, length, length_rate);
    if (params_.crane_kind != common::CraneKind::gantry) {
      take_row(plant::kOutOfPlaneSwingIndex, state, acceleration, length, length_rate);
    }
  }
  if (--solve_countdown_ <= 0) {
    solve_countdown_ = solve_interval_;
    solve();
  }
  out = in_use_;
}

void SwingLengthEstimator::take_row(int slot, const plant::ModelState& state,
                                    const plant::CoordinateVector& acceleration, double length,
                                    double length_rate) noexcept {
  const double g = params_.crane.gravity;
  const double angle = state.position(slot);
  if (std::max(std::abs(angle), std::abs(acceleration(slot)) * length / g) < params_.min_swing) return;
  // r(L_e, L_e') = row L_e / M_ss(L_e) at (1 m, 0), (2 m, 0), (1 m, 1 m/s): alpha + beta,
  // alpha + 2 beta, alpha + beta + delta (header).
  plant::CoordinateMatrix mass;
  plant::CoordinateVector bias;
  bool defined = true;
  const auto r = [&](double equivalent, double equivalent_rate) {
    model_->compute_dynamics(state, plant::HoistMotion{equivalent, equivalent_rate, 0.0}, mass, bias);
    defined = defined && mass(slot, slot) > 0.0;
    return (mass.row(slot).dot(acceleration) + bias(slot)) * equivalent / mass(slot, slot);
  };
  const double r1 = r(1.0, 0.0);
  const double r2 = r(2.0, 0.0);
  const double r3 = r(1.0, 1.0);
  if (!defined) return;
  const double beta = r2 - r1;
  const double alpha = r1 - beta;
  const double delta = r3 - r1;
  Eigen::Vector2d h;
  h << beta * length + delta * length_rate, beta;
  if (!std::isfinite(alpha) || !h.allFinite()) return;
  statistics_.add(params_.forgetting_factor, -alpha, h);
  ++solution_.rows;
}

void SwingLengthEstimator::solve() noexcept {
  const Eigen::Vector2d d(1.0, kOffsetUnit);
  const Eigen::Matrix2d& information = statistics_.information;
  const Eigen::Matrix2d scaled = d.asDiagonal() * information * d.asDiagonal();
  const Conditioning joint = conditioning<2>(scaled);
  Eigen::Vector2d next(in_use_.scale, in_use_.offset);
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();  // R^-1 of the solved parameters (0 where held)
  int parameters = 0;
  if (joint.min_eigenvalue >= params_.min_information && joint.condition <= params_.max_condition) {
    const Eigen::LDLT<Eigen::Matrix2d> ldlt(scaled);
    if (ldlt.info() != Eigen::Success) return;
    const Eigen::Vector2d z = ldlt.solve(d.asDiagonal() * statistics_.weighted_output);
    if (!z.allFinite()) return;
    next = d.asDiagonal() * z;
    covariance = d.asDiagonal() * ldlt.solve(Eigen::Matrix2d::Identity()) * d.asDiagonal();
    parameters = 2;
  } else if (scaled(1, 1) >= params_.min_information) {
    // c alone, a held at the value in use.
    next(1) = (statistics_.weighted_output(1) - information(1, 0) * next(0)) / information(1, 1);
    if (!std::isfinite(next(1))) return;
    covariance(1, 1) = 1.0 / information(1, 1);
    parameters = 1;
  } else {
    return;
  }
  const double rss = statistics_.residual_sum_of_squares(next);
  const double dof = std::max(1.0, statistics_.weight_sum - parameters);
  const double variance = noise_correlation_ * rss / dof;
  // The rows' mean cable length, weighted by their swing acceleration squared: h = (L s'', s'') at a
  // steady length, so R_ac / R_cc.
  const double mean_length = information(0, 1) / information(1, 1);
  double length_variance = 0.0;  // of a L + c at mean_length
  if (parameters == 2) {
    const Eigen::Vector2d at(mean_length, 1.0);
    length_variance = variance * at.dot(covariance * at);
    solution_.scale_deviation = std::sqrt(std::max(0.0, variance * covariance(0, 0)));
  } else {
    length_variance = variance * covariance(1, 1);
    solution_.scale_deviation = 0.0;
  }
  solution_.scale = next(0);
  solution_.offset = next(1);
  solution_.offset_deviation = std::sqrt(std::max(0.0, variance * covariance(1, 1)));
  solution_.length_deviation = std::sqrt(std::max(0.0, length_variance));
  solution_.mean_cable_length = mean_length;
  solution_.offset_solved = true;
  solution_.scale_solved = parameters == 2;
  solution_.residual_rms = std::sqrt(rss / std::max(1.0, statistics_.weight_sum));
  ++solution_.solves;

  const SwingLengthSolution& s = solution_;
  const bool confident = std::isfinite(mean_length) && 2.0 * s.length_deviation <= params_.length_bound &&
                         (!s.scale_solved || 2.0 * s.scale_deviation <= params_.scale_bound);
  if (confident) {
    in_use_.scale = s.scale;
    in_use_.offset = s.offset;
    in_use_.length_bound = 2.0 * s.length_deviation;
    in_use_.scale_bound = 2.0 * s.scale_deviation;
    in_use_.confident = true;
  }
}

}  // namespace crane::adaptation
