#include "crane/tracking/friction_factor_estimate.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/LU>
#include <algorithm>
#include <cmath>

#include "crane/common/validation.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"

namespace crane::tracking {

FrictionFactorEstimate::FrictionFactorEstimate(const common::AxisFriction& trolley, const common::AxisFriction& second,
                                               const FrictionFactorParams& params)
    : friction_{trolley, second}, params_(params) {
  common::validate(trolley, "friction_factor.trolley");
  common::validate(second, "friction_factor.second");
  common::require_greater("friction_factor.min_reference_speed", params.min_reference_speed, 0.0);
  common::require_finite("friction_factor.min_reference_speed", params.min_reference_speed);
  common::require_in_range("friction_factor.min_rows", params.min_rows, 3, 1000000);
  common::require_greater("friction_factor.min_factor", params.min_factor, 0.0);
  common::require_in_range("friction_factor.max_factor", params.max_factor, params.min_factor, 100.0);
  common::require_in_range("friction_factor.max_standard_error", params.max_standard_error, 0.0, 100.0);
  common::require_in_range("friction_factor.resolution", params.resolution, 0.0, 0.1);
}

void FrictionFactorEstimate::reset(double prior) noexcept {
  prior_ = std::isfinite(prior) ? std::clamp(prior, params_.min_factor, params_.max_factor) : 1.0;
  for (auto& row : information_) std::fill(std::begin(row), std::end(row), 0.0);
  std::fill(std::begin(moment_), std::end(moment_), 0.0);
  rows_ = 0;
  squares_ = 0.0;
}

void FrictionFactorEstimate::add(int axis, double feedback_voltage, double reference_speed,
                                 double reference_acceleration, double compensated_share) noexcept {
  if (axis < 0 || axis > 1) return;
  if (!std::isfinite(feedback_voltage) || !std::isfinite(reference_speed) || !std::isfinite(reference_acceleration) ||
      !std::isfinite(compensated_share)) {
    return;
  }
  if (std::abs(reference_speed) < params_.min_reference_speed) return;
  // F(v_ref) (3.1), as the compensation computes it (the one place it is written).
  const double friction = friction_compensation::sliding_friction_voltage(friction_[axis], reference_speed,
                                                                          reference_speed > 0.0 ? 1 : -1);
  add_row(axis, feedback_voltage + compensated_share * friction, friction, reference_acceleration);
}

void FrictionFactorEstimate::add_row(int axis, double y, double friction, double inertia) noexcept {
  if (axis < 0 || axis > 1 || !std::isfinite(y) || !std::isfinite(friction) || !std::isfinite(inertia)) return;
  double phi[3] = {friction, 0.0, 0.0};
  phi[1 + axis] = inertia;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) information_[r][c] += phi[r] * phi[c];
    moment_[r] += phi[r] * y;
  }
  squares_ += y * y;
  ++rows_;
}

double FrictionFactorEstimate::factor() const noexcept {
  if (rows_ < params_.min_rows) return prior_;
  Eigen::Matrix3d a;
  Eigen::Vector3d b;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) a(r, c) = information_[r][c];
    b[r] = moment_[r];
  }
  const double ridge = 1e-9 * std::max(a.trace(), 1e-12);
  a.diagonal().array() += ridge;
  const Eigen::Vector3d theta = a.ldlt().solve(b);
  const double f = 1.0 + theta[0];
  if (!std::isfinite(f)) return prior_;
  if (params_.max_standard_error > 0.0) {
    // The standard error of theta_0 from the rows' residuals: sigma^2 (Phi^T Phi)^-1_00, sigma^2 the
    // residual sum of squares over the rows less the unknowns.
    const double residual = std::max(0.0, squares_ - 2.0 * theta.dot(b) + theta.dot(a * theta));
    int unknowns = 0;  // the columns with rows (the PD law's balance has the friction's alone)
    for (int c = 0; c < 3; ++c) unknowns += information_[c][c] > 0.0 ? 1 : 0;
    const double variance = residual / static_cast<double>(std::max(1, rows_ - unknowns));
    const double standard_error = std::sqrt(variance * a.inverse()(0, 0));
    if (!(standard_error <= params_.max_standard_error)) return prior_;
  }
  const double clamped = std::clamp(f, params_.min_factor, params_.max_factor);
  return params_.resolution > 0.0 ? params_.resolution * std::round(clamped / params_.resolution) : clamped;
}

}  // namespace crane::tracking
