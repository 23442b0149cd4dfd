#include "crane/adaptation/axis_identifier.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <limits>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::adaptation {

namespace {

// At most 5 rows and columns, stored inline: no allocation in the cyclic path.
using SmallMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kParameterCount, kParameterCount>;
using SmallVector = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kParameterCount, 1>;

// The parameter groups of the excitation check (header): the load, moving +, moving -.
constexpr std::array<std::array<int, 2>, 2> kFrictionGroups{{{1, 3}, {2, 4}}};

Conditioning conditioning_of(const SmallMatrix& m) noexcept {
  Conditioning c;
  if (m.rows() == 0) return c;
  const Eigen::SelfAdjointEigenSolver<SmallMatrix> solver(m, Eigen::EigenvaluesOnly);
  if (solver.info() != Eigen::Success) return c;
  const double smallest = solver.eigenvalues().minCoeff();
  const double largest = solver.eigenvalues().maxCoeff();
  c.min_eigenvalue = smallest;
  c.condition = smallest > 0.0 ? largest / smallest : std::numeric_limits<double>::infinity();
  return c;
}

}  // namespace

template <int N>
Conditioning conditioning(const Eigen::Matrix<double, N, N>& matrix) noexcept {
  return conditioning_of(SmallMatrix(matrix));
}
template Conditioning conditioning<2>(const Eigen::Matrix<double, 2, 2>&) noexcept;
template Conditioning conditioning<kParameterCount>(const InformationMatrix&) noexcept;

void validate(const AxisIdentifierParams& p, const char* prefix) {
  const std::string f = prefix;
  common::require_in_range(f + ".forgetting_factor", p.forgetting_factor, 0.9, 1.0);
  static constexpr const char* kNames[kParameterCount] = {"load", "viscous_positive", "viscous_negative",
                                                          "coulomb_positive", "coulomb_negative"};
  for (int i = 0; i < kParameterCount; ++i) {
    common::require_finite(f + ".initial." + kNames[i], p.initial(i));
    common::require_greater(f + ".scale." + kNames[i], p.scale(i), 0.0);
    common::require_finite(f + ".scale." + kNames[i], p.scale(i));
  }
  common::require_greater(f + ".min_information", p.min_information, 0.0);
  common::require_finite(f + ".min_information", p.min_information);
  common::require_at_least(f + ".max_condition", p.max_condition, 1.0);
  common::require_finite(f + ".max_condition", p.max_condition);
  common::require_at_least(f + ".noise_correlation", p.noise_correlation, 1.0);
  common::require_finite(f + ".noise_correlation", p.noise_correlation);
}

AxisIdentifier::AxisIdentifier(const AxisIdentifierParams& params, const char* prefix) : params_(params) {
  validate(params_, prefix);
  reset();
}

void AxisIdentifier::reset() noexcept {
  statistics_ = WeightedLeastSquares<kParameterCount>{};
  state_ = AxisIdentification{};
  state_.estimate = params_.initial;
  state_.standard_deviation.setZero();
}

bool AxisIdentifier::update(double y, const ParameterVector& phi) noexcept {
  if (!std::isfinite(y) || !phi.allFinite()) return false;
  statistics_.add(params_.forgetting_factor, y, phi);
  ++state_.accepted_samples;
  return true;
}

bool AxisIdentifier::solve() noexcept {
  // Scaled information S = D R D: each parameter at its typical size.
  const ParameterVector& d = params_.scale;
  const InformationMatrix& information = statistics_.information;
  const InformationMatrix scaled = d.asDiagonal() * information * d.asDiagonal();

  // Candidates: the load when its information alone passes, and every friction group with any data
  // (a group without data is exactly decoupled). The candidates together must pass both bounds (so
  // the load is told apart from the friction); failing that, the friction groups that pass on their
  // own are solved with the load held.
  const bool load_informed = scaled(kLoadIndex, kLoadIndex) >= params_.min_information;
  std::array<bool, 2> group_present{};
  std::array<bool, 2> group_passes{};
  for (std::size_t g = 0; g < kFrictionGroups.size(); ++g) {
    const auto [i, j] = kFrictionGroups[g];
    Eigen::Matrix2d block;
    block << scaled(i, i), scaled(i, j), scaled(j, i), scaled(j, j);
    const Conditioning c = conditioning<2>(block);
    group_present[g] = scaled(i, i) > 0.0 || scaled(j, j) > 0.0;
    group_passes[g] = c.min_eigenvalue >= params_.min_information && c.condition <= params_.max_condition;
  }

  std::array<bool, kParameterCount> active{};
  int n = 0;
  std::array<int, kParameterCount> index{};
  SmallMatrix s_aa;
  SmallMatrix r_aa;
  SmallVector rhs;
  const ParameterVector& theta = state_.estimate;
  const auto choose = [&](bool with_load, const std::array<bool, 2>& groups) {
    active.fill(false);
    active[kLoadIndex] = with_load;
    for (std::size_t g = 0; g < kFrictionGroups.size(); ++g) {
      for (int i : kFrictionGroups[g]) active[static_cast<std::size_t>(i)] = groups[g];
    }
    n = 0;
    for (int i = 0; i < kParameterCount; ++i) {
      if (active[static_cast<std::size_t>(i)]) index[static_cast<std::size_t>(n++)] = i;
    }
    if (n == 0) return false;
    s_aa.resize(n, n);
    r_aa.resize(n, n);
    rhs.resize(n);
    for (int a = 0; a < n; ++a) {
      const int i = index[static_cast<std::size_t>(a)];
      rhs(a) = statistics_.weighted_output(i);
      for (int j = 0; j < kParameterCount; ++j) {
        if (!active[static_cast<std::size_t>(j)]) rhs(a) -= information(i, j) * theta(j);  // held
      }
      for (int b = 0; b < n; ++b) {
        const int j = index[static_cast<std::size_t>(b)];
        s_aa(a, b) = scaled(i, j);
        r_aa(a, b) = information(i, j);
      }
    }
    const Conditioning joint = conditioning_of(s_aa);
    return joint.min_eigenvalue >= params_.min_information && joint.condition <= params_.max_condition;
  };
  bool load_excited = false;
  std::array<bool, 2> group_excited{};
  if (load_informed && choose(true, group_present)) {
    load_excited = true;
    group_excited = group_present;
  } else if (choose(false, group_passes)) {
    group_excited = group_passes;
  } else {
    return false;
  }

  // Solve in scaled coordinates (well conditioned by the check): S_aa z = D_a rhs, theta_a = D_a z.
  SmallVector scaled_rhs(n);
  for (int a = 0; a < n; ++a) scaled_rhs(a) = d(index[static_cast<std::size_t>(a)]) * rhs(a);
  const Eigen::LDLT<SmallMatrix> ldlt(s_aa);
  if (ldlt.info() != Eigen::Success) return false;
  const SmallVector z = ldlt.solve(scaled_rhs);
  if (!z.allFinite()) return false;
  ParameterVector next = theta;
  for (int a = 0; a < n; ++a) next(index[static_cast<std::size_t>(a)]) = d(index[static_cast<std::size_t>(a)]) * z(a);

  // Weighted residual sum of squares from the sufficient statistics: E - 2 theta^T r + theta^T R theta.
  const double rss = statistics_.residual_sum_of_squares(next);
  const double dof = std::max(1.0, statistics_.weight_sum - static_cast<double>(n));
  const double variance = params_.noise_correlation * rss / dof;
  // Covariance of the excited parameters: s^2 R_aa^-1 = s^2 D_a S_aa^-1 D_a.
  const SmallMatrix s_inverse = ldlt.solve(SmallMatrix::Identity(n, n));
  state_.standard_deviation.setZero();
  for (int a = 0; a < n; ++a) {
    const int i = index[static_cast<std::size_t>(a)];
    state_.standard_deviation(i) = d(i) * std::sqrt(std::max(0.0, variance * s_inverse(a, a)));
  }
  state_.estimate = next;
  state_.load_excited = load_excited;
  state_.positive_excited = group_excited[0];
  state_.negative_excited = group_excited[1];
  state_.residual_rms = std::sqrt(rss / std::max(1.0, statistics_.weight_sum));
  ++state_.solves;
  return true;
}

}  // namespace crane::adaptation
