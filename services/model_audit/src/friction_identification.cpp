#include "crane/model_audit/friction_identification.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/friction_compensation/friction_compensation.hpp"
#include "crane/model_audit/zero_phase_filter.hpp"

namespace crane::model_audit {

namespace {

std::string number(double value) { return common::format_value(value); }

void check_data(std::span<const double> time, std::span<const double> input, std::span<const double> position) {
  if (time.size() != input.size() || time.size() != position.size()) {
    throw IdentificationError("friction identification: columns differ in length: time " +
                              std::to_string(time.size()) + ", input " + std::to_string(input.size()) +
                              ", position " + std::to_string(position.size()));
  }
  if (time.size() < 3) {
    throw IdentificationError("friction identification: " + std::to_string(time.size()) +
                              " samples, at least 3 needed for a second difference");
  }
  for (std::size_t i = 0; i < time.size(); ++i) {
    if (!std::isfinite(time[i]) || !std::isfinite(input[i]) || !std::isfinite(position[i])) {
      throw IdentificationError("friction identification: non-finite value at sample " + std::to_string(i));
    }
  }
}

// T_s from the span of the record; every interval must match it within the tolerance.
double uniform_sample_time(std::span<const double> time, double tolerance) {
  const double sample_time = (time.back() - time.front()) / static_cast<double>(time.size() - 1);
  if (!(sample_time > 0.0)) {
    throw IdentificationError("friction identification: time does not increase (first " + number(time.front()) +
                              " s, last " + number(time.back()) + " s)");
  }
  for (std::size_t i = 1; i < time.size(); ++i) {
    const double interval = time[i] - time[i - 1];
    if (std::abs(interval - sample_time) > tolerance * sample_time) {
      throw IdentificationError("friction identification: non-uniform sampling: interval " + number(interval) +
                                " s between samples " + std::to_string(i - 1) + " and " + std::to_string(i) +
                                " (t = " + number(time[i - 1]) + " s) differs from T_s = " + number(sample_time) +
                                " s by more than " + number(100.0 * tolerance) + " %");
    }
  }
  return sample_time;
}

}  // namespace

void validate(const FrictionIdentificationOptions& options) {
  common::require_at_least("dead_band", options.dead_band, 0.0);
  common::require_at_least("cutoff_hz", options.cutoff_frequency, 0.0);
  if (options.motor_constant) common::require_greater("km", *options.motor_constant, 0.0);
  if (options.minimum_samples_per_direction < 1) {
    throw common::ConfigError("minimum_samples_per_direction = 0 is out of range: must be >= 1");
  }
  if (!(options.sample_time_tolerance > 0.0 && options.sample_time_tolerance < 0.5)) {
    throw common::ConfigError("sample_time_tolerance = " + number(options.sample_time_tolerance) +
                              " is out of range: must be in (0, 0.5)");
  }
}

FrictionIdentificationResult identify_friction(std::span<const double> time, std::span<const double> input,
                                               std::span<const double> position,
                                               const FrictionIdentificationOptions& options) {
  validate(options);
  check_data(time, input, position);
  const double t_s = uniform_sample_time(time, options.sample_time_tolerance);  // T_s [s]

  std::vector<double> x(position.begin(), position.end());
  std::vector<double> u(input.begin(), input.end());
  if (options.cutoff_frequency > 0.0) {
    x = zero_phase_low_pass(x, options.cutoff_frequency, 1.0 / t_s);
    if (options.filter_input) u = zero_phase_low_pass(u, options.cutoff_frequency, 1.0 / t_s);
  }

  // Regression rows (3.11)-(3.13), k = 2 .. n-1; eta/xi from the zero-velocity band (3.3).
  struct Row {
    double acc;        // acc(k) [m/s^2]
    double vel;        // vel(k) [m/s]
    double in;         // in(k) [V]
    int direction;     // +1: eta = 1, -1: xi = 1
  };
  std::vector<Row> rows;
  rows.reserve(x.size());
  FrictionIdentificationResult result;
  result.sample_time = t_s;
  const double d_s = options.dead_band;
  for (std::size_t k = 2; k < x.size(); ++k) {
    const double v_older = (x[k - 1] - x[k - 2]) / t_s;
    const double v_newer = (x[k] - x[k - 1]) / t_s;
    int direction = 0;
    if (v_older > d_s && v_newer > d_s) direction = 1;
    if (v_older < -d_s && v_newer < -d_s) direction = -1;
    if (direction == 0) {
      ++result.samples_excluded;
      continue;
    }
    Row row{};
    row.acc = (x[k] - 2.0 * x[k - 1] + x[k - 2]) / (t_s * t_s);
    if (options.scheme == DifferenceScheme::centered) {
      row.vel = (x[k] - x[k - 2]) / (2.0 * t_s);
      row.in = 0.5 * (u[k - 1] + u[k - 2]);
    } else {
      row.vel = v_older;
      row.in = u[k - 2];
    }
    row.direction = direction;
    (direction > 0 ? result.samples_positive : result.samples_negative) += 1;
    rows.push_back(row);
  }
  const std::size_t minimum = options.minimum_samples_per_direction;
  if (result.samples_positive < minimum || result.samples_negative < minimum) {
    throw IdentificationError(
        "friction identification: too few moving samples outside the dead band d_s = " + number(d_s) +
        ": positive direction " + std::to_string(result.samples_positive) + ", negative direction " +
        std::to_string(result.samples_negative) + ", at least " + std::to_string(minimum) +
        " each needed (excite both directions, or lower the dead band)");
  }

  const bool km_known = options.motor_constant.has_value();
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size());
  const Eigen::Index p = km_known ? 4 : 5;
  if (n <= p) {
    throw IdentificationError("friction identification: " + std::to_string(n) + " regression rows for " +
                              std::to_string(p) + " parameters");
  }
  Eigen::MatrixXd phi(n, p);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const Row& row = rows[static_cast<std::size_t>(i)];
    const Eigen::Index offset = km_known ? 0 : 1;
    if (km_known) {
      y(i) = row.acc / *options.motor_constant - row.in;  // (3.14)
    } else {
      y(i) = row.acc;
      phi(i, 0) = row.in;
    }
    // (3.13): minus the sliding-friction regressor [v eta, v xi, eta, -xi] the compensation uses.
    const auto regressor = friction_compensation::friction_regressor(row.vel, row.direction);
    for (Eigen::Index j = 0; j < 4; ++j) phi(i, offset + j) = -regressor[static_cast<std::size_t>(j)];
  }

  // Theta = argmin |Y - Phi Theta| by column-pivoted QR; (Phi^T Phi)^-1 = P R^-1 R^-T P^T.
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(phi);
  if (qr.rank() < p) {
    throw IdentificationError("friction identification: the regressor matrix has rank " +
                              std::to_string(qr.rank()) + " < " + std::to_string(p) +
                              " (the excitation does not separate the parameters)");
  }
  const Eigen::VectorXd theta = qr.solve(y);
  const Eigen::VectorXd residual = y - phi * theta;
  const double rss = residual.squaredNorm();
  const double sigma_squared = rss / static_cast<double>(n - p);
  const Eigen::MatrixXd r = qr.matrixR().topLeftCorner(p, p).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inverse =
      r.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(p, p));
  const Eigen::MatrixXd permuted_inverse = r_inverse * r_inverse.transpose();
  const auto& permutation = qr.colsPermutation();
  const Eigen::MatrixXd covariance =
      sigma_squared * (permutation * permuted_inverse * permutation.transpose());
  result.residual_rms = std::sqrt(rss / static_cast<double>(n));

  const auto set = [](FrictionRatios& ratios, Eigen::Index index, double value) {
    switch (index) {
      case 0: ratios.viscous_positive = value; break;
      case 1: ratios.viscous_negative = value; break;
      case 2: ratios.coulomb_positive = value; break;
      default: ratios.coulomb_negative = value; break;
    }
  };
  if (km_known) {
    for (Eigen::Index i = 0; i < 4; ++i) {
      set(result.estimate, i, theta(i));
      set(result.standard_error, i, std::sqrt(covariance(i, i)));
    }
  } else {
    // Ratios r_i = Theta_i / K_m; delta method: grad = (-Theta_i / K_m^2 at K_m, 1 / K_m at i).
    const double k_m = theta(0);
    if (!(k_m > 0.0)) {
      throw IdentificationError("friction identification: identified K_m = " + number(k_m) +
                                " is not positive (the input does not drive the axis as modelled)");
    }
    result.motor_constant = k_m;
    result.motor_constant_standard_error = std::sqrt(covariance(0, 0));
    for (Eigen::Index i = 0; i < 4; ++i) {
      const Eigen::Index j = i + 1;
      Eigen::VectorXd gradient = Eigen::VectorXd::Zero(p);
      gradient(0) = -theta(j) / (k_m * k_m);
      gradient(j) = 1.0 / k_m;
      set(result.estimate, i, theta(j) / k_m);
      set(result.standard_error, i, std::sqrt(gradient.dot(covariance * gradient)));
    }
  }
  return result;
}

}  // namespace crane::model_audit
