// Friction least squares of section 3.1 ((3.10)-(3.15)): exactness on its own discrete model, the
// section-3.1 acceptance case (every ratio within 2 %), randomized parameter sets, standard errors
// (shrinking with data, and matching a Monte Carlo spread), the dead band, and the error paths.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numbers>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/model_audit/friction_experiment.hpp"
#include "crane/model_audit/friction_identification.hpp"

namespace ma = crane::model_audit;

namespace {

// The acceptance criterion of the task: every identified ratio within 2 % of the truth.
constexpr double kAcceptance = 0.02;

// Number of randomized parameter sets; CRANE_MODEL_AUDIT_CASES overrides (e.g. 1000 for a soak).
int randomized_cases() {
  const char* text = std::getenv("CRANE_MODEL_AUDIT_CASES");
  return text != nullptr ? std::max(1, std::atoi(text)) : 20;
}

struct Truth {
  double motor_constant;
  ma::FrictionRatios ratios;
};

Truth truth_of(const ma::FrictionExperimentParams& p) {
  return {p.motor_constant, {p.viscous_positive, p.viscous_negative, p.coulomb_positive, p.coulomb_negative}};
}

struct RelativeErrors {
  double b_plus, b_minus, c_plus, c_minus, k_m;
  [[nodiscard]] double worst_ratio() const {
    return std::max({std::abs(b_plus), std::abs(b_minus), std::abs(c_plus), std::abs(c_minus)});
  }
};

RelativeErrors relative_errors(const ma::FrictionIdentificationResult& result, const Truth& truth) {
  const auto rel = [](double estimate, double exact) { return estimate / exact - 1.0; };
  return {rel(result.estimate.viscous_positive, truth.ratios.viscous_positive),
          rel(result.estimate.viscous_negative, truth.ratios.viscous_negative),
          rel(result.estimate.coulomb_positive, truth.ratios.coulomb_positive),
          rel(result.estimate.coulomb_negative, truth.ratios.coulomb_negative),
          result.motor_constant ? rel(*result.motor_constant, truth.motor_constant) : 0.0};
}

std::string describe(const RelativeErrors& e) {
  char text[200];
  std::snprintf(text, sizeof(text), "b+ %+.4f%%  b- %+.4f%%  c+ %+.4f%%  c- %+.4f%%  K_m %+.4f%%", 100 * e.b_plus,
                100 * e.b_minus, 100 * e.c_plus, 100 * e.c_minus, 100 * e.k_m);
  return text;
}

ma::FrictionIdentificationResult identify(const ma::FrictionExperimentRecord& record,
                                          const ma::FrictionIdentificationOptions& options) {
  return ma::identify_friction(record.time, record.input, record.position, options);
}

// Data that satisfy the regression's own discrete model (3.13) exactly. Open loop, u(k) a sum of
// sinusoids; the direction s used for step k is the sign of the older backward difference
// x(k-1) - x(k-2). Every row the identification keeps has both backward differences of one sign,
// so its s is the one the generator used, and (3.13) holds for it to round-off:
//   centered:      acc = K_m [u(k-1) + u(k-2)]/2 - b_s [x(k) - x(k-2)]/(2 T_s) - c_s s
//                  -> x(k) (1/T_s^2 + b_s/(2 T_s)) = K_m ubar - c_s s + (2 x(k-1) - x(k-2))/T_s^2
//                                                    + b_s x(k-2)/(2 T_s)
//   dissertation:  acc = K_m u(k-2) - b_s [x(k-1) - x(k-2)]/T_s - c_s s   (explicit in x(k))
// `acceleration_noise` [m/s^2] (seeded, Gaussian) is added to acc: with the dissertation scheme all
// regressors are known before it, so ordinary least-squares theory (unbiased, covariance
// sigma^2 (Phi^T Phi)^-1) applies exactly.
struct DiscreteData {
  std::vector<double> time, input, position;
};

DiscreteData discrete_model_data(const Truth& truth, ma::DifferenceScheme scheme, std::size_t samples,
                                 double acceleration_noise = 0.0, std::uint64_t seed = 1) {
  const double t_s = 0.01;
  const double k_m = truth.motor_constant;
  std::mt19937_64 generator(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  DiscreteData data;
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * t_s;
    data.time.push_back(t);
    data.input.push_back(3.0 * std::sin(2.0 * std::numbers::pi * 0.4 * t) +
                         2.0 * std::sin(2.0 * std::numbers::pi * 1.1 * t + 0.5));
  }
  data.position = {0.0, 0.004};  // starts moving at +0.4 m/s
  for (std::size_t k = 2; k < samples; ++k) {
    const double x1 = data.position[k - 1];
    const double x2 = data.position[k - 2];
    const int s = x1 - x2 >= 0.0 ? 1 : -1;
    const double b = k_m * (s > 0 ? truth.ratios.viscous_positive : truth.ratios.viscous_negative);
    const double c = k_m * (s > 0 ? truth.ratios.coulomb_positive : truth.ratios.coulomb_negative);
    const double disturbance = acceleration_noise * noise(generator);
    double x = 0.0;
    if (scheme == ma::DifferenceScheme::centered) {
      const double u_bar = 0.5 * (data.input[k - 1] + data.input[k - 2]);
      x = (k_m * u_bar - c * s + disturbance + (2.0 * x1 - x2) / (t_s * t_s) + b * x2 / (2.0 * t_s)) /
          (1.0 / (t_s * t_s) + b / (2.0 * t_s));
    } else {
      x = 2.0 * x1 - x2 + t_s * t_s * (k_m * data.input[k - 2] - b * (x1 - x2) / t_s - c * s + disturbance);
    }
    data.position.push_back(x);
  }
  return data;
}

const Truth kDiscreteTruth{1.3, {2.1, 4.4, 0.7, 1.1}};

}  // namespace

TEST(FrictionIdentification, ExactOnItsOwnDiscreteModel) {
  for (const auto scheme : {ma::DifferenceScheme::centered, ma::DifferenceScheme::dissertation}) {
    const auto data = discrete_model_data(kDiscreteTruth, scheme, 3000);
    ma::FrictionIdentificationOptions options;
    options.scheme = scheme;
    const auto result = ma::identify_friction(data.time, data.input, data.position, options);
    const auto errors = relative_errors(result, kDiscreteTruth);
    SCOPED_TRACE(describe(errors));
    ASSERT_TRUE(result.motor_constant.has_value());
    EXPECT_LT(errors.worst_ratio(), 1e-6);
    EXPECT_LT(std::abs(errors.k_m), 1e-6);
    EXPECT_GT(result.samples_positive, 500u);
    EXPECT_GT(result.samples_negative, 500u);
    EXPECT_EQ(result.samples_positive + result.samples_negative + result.samples_excluded, 3000u - 2u);
    EXPECT_LT(result.residual_rms, 1e-6);
    EXPECT_DOUBLE_EQ(result.sample_time, 0.01);

    options.motor_constant = kDiscreteTruth.motor_constant;  // (3.14) with K_m known
    const auto known = ma::identify_friction(data.time, data.input, data.position, options);
    EXPECT_FALSE(known.motor_constant.has_value());
    EXPECT_LT(relative_errors(known, kDiscreteTruth).worst_ratio(), 1e-6);
  }
}

TEST(FrictionIdentification, Section31AcceptanceTrackingGains) {
  // Section 3.1: K_m = 1.7, exact ratios 2.8, 5.5, 1.0, 1.2 (Tables 3.1-3.5, ERRATA), PD (3.17) with
  // the tracking gains K = 100, K_d = 0.2 tracking (3.18), T_s = 0.01 s, d_s = 0.05 (Table 3.4).
  const ma::FrictionExperimentParams params;
  const auto record = ma::simulate_friction_experiment(params);
  ma::FrictionIdentificationOptions options;
  options.dead_band = 0.05;
  for (const auto scheme : {ma::DifferenceScheme::centered, ma::DifferenceScheme::dissertation}) {
    options.scheme = scheme;
    const auto result = identify(record, options);
    const auto errors = relative_errors(result, truth_of(params));
    std::printf("[section 3.1, tracking gains, %s] %s\n",
                scheme == ma::DifferenceScheme::centered ? "centered" : "dissertation", describe(errors).c_str());
    EXPECT_LT(errors.worst_ratio(), kAcceptance) << describe(errors);
    EXPECT_LT(std::abs(errors.k_m), kAcceptance) << describe(errors);
  }
}

TEST(FrictionIdentification, Section31GainSchedulingGains) {
  // The first gain set of section 3.1 (K_p = 4.4, K_d = 1.33, Table 3.1): long stuck phases.
  ma::FrictionExperimentParams params;
  params.proportional_gain = 4.4;
  params.derivative_time = 1.33;
  const auto record = ma::simulate_friction_experiment(params);
  ma::FrictionIdentificationOptions options;
  const auto result = identify(record, options);
  const auto errors = relative_errors(result, truth_of(params));
  std::printf("[section 3.1, gain-scheduling gains, centered] %s\n", describe(errors).c_str());
  EXPECT_LT(errors.worst_ratio(), kAcceptance) << describe(errors);
  EXPECT_GT(result.samples_excluded, 1000u);  // the "large band of zero velocity" of figure 3.2
}

TEST(FrictionIdentification, Section31WithEncoderNoiseAndPrefilter) {
  // A realistic measurement: trolley encoder quantum 0.5 in/rev / (2000 lines x 4) = 1.5875e-6 m,
  // 10 um Gaussian noise, the dissertation's zero-phase prefilter at 0.1 f_s = 10 Hz.
  ma::FrictionExperimentParams params;
  params.encoder_quantum = 0.0127 / 8000.0;
  params.noise_standard_deviation = 1e-5;
  params.seed = 42;
  const auto record = ma::simulate_friction_experiment(params);
  ma::FrictionIdentificationOptions options;
  options.cutoff_frequency = 10.0;
  const auto result = identify(record, options);
  const auto errors = relative_errors(result, truth_of(params));
  std::printf("[section 3.1, encoder + noise, 10 Hz prefilter] %s\n", describe(errors).c_str());
  EXPECT_LT(errors.worst_ratio(), kAcceptance) << describe(errors);
  EXPECT_LT(std::abs(errors.k_m), kAcceptance) << describe(errors);
}

TEST(FrictionIdentification, RandomizedParameterSetsWithinTolerance) {
  std::mt19937_64 generator(20030101);
  std::uniform_real_distribution<double> motor(0.8, 3.0);
  std::uniform_real_distribution<double> viscous(1.5, 8.0);
  std::uniform_real_distribution<double> coulomb(0.3, 2.0);
  double worst = 0.0;
  const int cases = randomized_cases();
  for (int i = 0; i < cases; ++i) {
    ma::FrictionExperimentParams params;
    params.motor_constant = motor(generator);
    params.viscous_positive = viscous(generator);
    params.viscous_negative = viscous(generator);
    params.coulomb_positive = coulomb(generator);
    params.coulomb_negative = coulomb(generator);
    params.encoder_quantum = 0.0127 / 8000.0;
    params.noise_standard_deviation = 1e-6;
    params.seed = static_cast<std::uint64_t>(i) + 1;
    const auto record = ma::simulate_friction_experiment(params);
    const auto result = identify(record, {});
    const auto errors = relative_errors(result, truth_of(params));
    worst = std::max({worst, errors.worst_ratio(), std::abs(errors.k_m)});
    EXPECT_LT(errors.worst_ratio(), kAcceptance)
        << "case " << i << ": K_m " << params.motor_constant << ", ratios " << params.viscous_positive << " "
        << params.viscous_negative << " " << params.coulomb_positive << " " << params.coulomb_negative << ": "
        << describe(errors);
    EXPECT_LT(std::abs(errors.k_m), kAcceptance) << "case " << i << ": " << describe(errors);
  }
  std::printf("[randomized, %d cases] worst relative error %.4f%%\n", cases, 100 * worst);
}

TEST(FrictionIdentification, StandardErrorsShrinkWithMoreData) {
  // With noise the standard errors scale like 1/sqrt(n): four times the data, about half the error.
  ma::FrictionExperimentParams params;
  params.noise_standard_deviation = 2e-5;
  params.seed = 5;
  ma::FrictionIdentificationOptions options;
  options.cutoff_frequency = 10.0;
  params.duration = 12.0;
  const auto short_run = identify(ma::simulate_friction_experiment(params), options);
  params.duration = 48.0;
  const auto long_run = identify(ma::simulate_friction_experiment(params), options);
  const auto& a = short_run.standard_error;
  const auto& b = long_run.standard_error;
  for (const auto& [name, short_error, long_error] :
       {std::tuple{"b+", a.viscous_positive, b.viscous_positive}, std::tuple{"b-", a.viscous_negative, b.viscous_negative},
        std::tuple{"c+", a.coulomb_positive, b.coulomb_positive}, std::tuple{"c-", a.coulomb_negative, b.coulomb_negative},
        std::tuple{"K_m", *short_run.motor_constant_standard_error, *long_run.motor_constant_standard_error}}) {
    EXPECT_GT(short_error, 0.0) << name;
    EXPECT_LT(long_error, 0.7 * short_error) << name << ": " << short_error << " -> " << long_error;
    EXPECT_GT(long_error, 0.3 * short_error) << name << ": " << short_error << " -> " << long_error;
  }
}

TEST(FrictionIdentification, StandardErrorsMatchMonteCarloSpread) {
  // Independent check of sigma^2 (Phi^T Phi)^-1 (and of the delta method for the ratios): over many
  // noise realizations of data that obey the dissertation scheme's model with white acceleration
  // noise (regressors known before the noise, so OLS theory is exact), the spread of the estimates
  // must equal the reported standard errors. 200 runs: the spread itself is known to about 5 %.
  const int runs = 200;
  for (const bool km_known : {true, false}) {
    std::vector<std::vector<double>> estimates(5);
    std::vector<double> mean_error(5, 0.0);
    for (int run = 0; run < runs; ++run) {
      const auto data = discrete_model_data(kDiscreteTruth, ma::DifferenceScheme::dissertation, 2000, 0.5,
                                            static_cast<std::uint64_t>(run) + 100);
      ma::FrictionIdentificationOptions options;
      options.scheme = ma::DifferenceScheme::dissertation;
      if (km_known) options.motor_constant = kDiscreteTruth.motor_constant;
      const auto r = ma::identify_friction(data.time, data.input, data.position, options);
      const double values[5] = {r.estimate.viscous_positive, r.estimate.viscous_negative, r.estimate.coulomb_positive,
                                r.estimate.coulomb_negative, r.motor_constant.value_or(0.0)};
      const double errors[5] = {r.standard_error.viscous_positive, r.standard_error.viscous_negative,
                                r.standard_error.coulomb_positive, r.standard_error.coulomb_negative,
                                r.motor_constant_standard_error.value_or(0.0)};
      for (int i = 0; i < 5; ++i) {
        estimates[static_cast<std::size_t>(i)].push_back(values[i]);
        mean_error[static_cast<std::size_t>(i)] += errors[i] / runs;
      }
    }
    const double exact[5] = {2.1, 4.4, 0.7, 1.1, 1.3};
    for (std::size_t i = 0; i < (km_known ? 4u : 5u); ++i) {
      double mean = 0.0;
      for (const double v : estimates[i]) mean += v / runs;
      double variance = 0.0;
      for (const double v : estimates[i]) variance += (v - mean) * (v - mean) / (runs - 1);
      const double spread = std::sqrt(variance);
      SCOPED_TRACE("parameter " + std::to_string(i) + (km_known ? ", K_m known" : ", K_m identified"));
      EXPECT_GT(spread / mean_error[i], 0.85) << spread << " vs " << mean_error[i];
      EXPECT_LT(spread / mean_error[i], 1.15) << spread << " vs " << mean_error[i];
      EXPECT_LT(std::abs(mean - exact[i]), 4.0 * spread / std::sqrt(runs)) << "biased: mean " << mean;
    }
  }
}

TEST(FrictionIdentification, MatchesNormalEquationsComputedIndependently) {
  // Cross-check of the QR solve, sigma^2 = RSS/(n - p), the covariance un-pivoting and the delta
  // method against a direct transcription of (3.11)-(3.15): rows built here from the centered
  // scheme, Theta = (Phi^T Phi)^-1 Phi^T Y by Cholesky, covariance sigma^2 (Phi^T Phi)^-1, ratio
  // covariance J C J^T with J = d(Theta_i / K_m)/d(K_m, Theta_i).
  const auto data = discrete_model_data(kDiscreteTruth, ma::DifferenceScheme::centered, 1500, 0.5, 77);
  const double t_s = 0.01;
  const double d_s = 0.05;
  const auto& x = data.position;
  const auto& u = data.input;
  for (const bool km_known : {false, true}) {
    const double k_m = kDiscreteTruth.motor_constant;
    std::vector<Eigen::RowVectorXd> rows;
    std::vector<double> targets;
    for (std::size_t k = 2; k < x.size(); ++k) {
      const double v1 = (x[k - 1] - x[k - 2]) / t_s;
      const double v2 = (x[k] - x[k - 1]) / t_s;
      const double eta = v1 > d_s && v2 > d_s ? 1.0 : 0.0;
      const double xi = v1 < -d_s && v2 < -d_s ? 1.0 : 0.0;
      if (eta + xi == 0.0) continue;
      const double acc = (x[k] - 2.0 * x[k - 1] + x[k - 2]) / (t_s * t_s);
      const double vel = (x[k] - x[k - 2]) / (2.0 * t_s);
      const double in = 0.5 * (u[k - 1] + u[k - 2]);
      Eigen::RowVectorXd phi(km_known ? 4 : 5);
      if (km_known) {
        phi << -vel * eta, -vel * xi, -eta, xi;
        targets.push_back(acc / k_m - in);
      } else {
        phi << in, -vel * eta, -vel * xi, -eta, xi;
        targets.push_back(acc);
      }
      rows.push_back(phi);
    }
    const auto n = static_cast<Eigen::Index>(rows.size());
    const Eigen::Index p = km_known ? 4 : 5;
    Eigen::MatrixXd phi(n, p);
    Eigen::VectorXd y(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      phi.row(i) = rows[static_cast<std::size_t>(i)];
      y(i) = targets[static_cast<std::size_t>(i)];
    }
    const Eigen::MatrixXd normal = phi.transpose() * phi;
    const Eigen::VectorXd theta = normal.llt().solve(phi.transpose() * y);
    const double sigma2 = (y - phi * theta).squaredNorm() / static_cast<double>(n - p);
    const Eigen::MatrixXd covariance = sigma2 * normal.inverse();
    Eigen::VectorXd ratios(4), ratio_errors(4);
    if (km_known) {
      ratios = theta;
      ratio_errors = covariance.diagonal().cwiseSqrt();
    } else {
      for (Eigen::Index i = 0; i < 4; ++i) {
        Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(1, p);
        jacobian(0, 0) = -theta(i + 1) / (theta(0) * theta(0));
        jacobian(0, i + 1) = 1.0 / theta(0);
        ratios(i) = theta(i + 1) / theta(0);
        ratio_errors(i) = std::sqrt((jacobian * covariance * jacobian.transpose())(0, 0));
      }
    }

    ma::FrictionIdentificationOptions options;
    options.dead_band = d_s;
    if (km_known) options.motor_constant = k_m;
    const auto result = ma::identify_friction(data.time, data.input, data.position, options);
    SCOPED_TRACE(km_known ? "K_m known" : "K_m identified");
    ASSERT_EQ(static_cast<Eigen::Index>(result.samples_positive + result.samples_negative), n);
    const double got[4] = {result.estimate.viscous_positive, result.estimate.viscous_negative,
                           result.estimate.coulomb_positive, result.estimate.coulomb_negative};
    const double got_errors[4] = {result.standard_error.viscous_positive, result.standard_error.viscous_negative,
                                  result.standard_error.coulomb_positive, result.standard_error.coulomb_negative};
    for (Eigen::Index i = 0; i < 4; ++i) {
      EXPECT_NEAR(got[i], ratios(i), 1e-9 * std::abs(ratios(i))) << i;
      EXPECT_NEAR(got_errors[i], ratio_errors(i), 1e-6 * ratio_errors(i)) << i;
      EXPECT_GT(ratio_errors(i), 0.0);
    }
    if (!km_known) {
      EXPECT_NEAR(*result.motor_constant, theta(0), 1e-9 * theta(0));
      EXPECT_NEAR(*result.motor_constant_standard_error, std::sqrt(covariance(0, 0)), 1e-6 * std::sqrt(covariance(0, 0)));
    }
  }
}

TEST(FrictionIdentification, DeadBandSelectsRowsByEveryVelocityInTheStencil) {
  // Piecewise motion with hand-countable rows (row k uses the backward differences k-1 and k):
  // intervals 1..99 move at +0.2 +- 0.05 m/s, 100..199 stand still, 200..299 move at -0.4 +- 0.05.
  // Positive rows: k-1 >= 1 and k <= 99 -> k = 2..99 (98). Negative: k-1 >= 200, k <= 299 -> 201..299
  // (99). The other 101 of the 298 rows straddle or sit in the stationary part.
  const double t_s = 0.01;
  std::vector<double> time{0.0}, input{0.0}, position{0.0};
  for (std::size_t j = 1; j < 300; ++j) {
    const double wiggle = 0.05 * std::sin(0.7 * static_cast<double>(j));
    const double velocity = j < 100 ? 0.2 + wiggle : (j < 200 ? 0.0 : -0.4 + wiggle);
    time.push_back(static_cast<double>(j) * t_s);
    input.push_back(std::cos(0.3 * static_cast<double>(j)));
    position.push_back(position.back() + velocity * t_s);
  }
  ma::FrictionIdentificationOptions options;
  options.dead_band = 0.1;
  const auto result = ma::identify_friction(time, input, position, options);
  EXPECT_EQ(result.samples_positive, 98u);
  EXPECT_EQ(result.samples_negative, 99u);
  EXPECT_EQ(result.samples_excluded, 101u);
  // A band above every positive velocity leaves no positive rows.
  options.dead_band = 0.26;
  try {
    (void)ma::identify_friction(time, input, position, options);
    ADD_FAILURE() << "identified without positive rows";
  } catch (const ma::IdentificationError& error) {
    EXPECT_NE(std::string(error.what()).find("too few moving samples outside the dead band d_s = 0.26: positive "
                                             "direction 0, negative direction 99, at least 20 each needed"),
              std::string::npos)
        << error.what();
  }
}

TEST(FrictionIdentification, RefusesDataThatCannotIdentify) {
  const auto data = discrete_model_data(kDiscreteTruth, ma::DifferenceScheme::centered, 400);
  const auto message = [](const std::vector<double>& t, const std::vector<double>& u, const std::vector<double>& x,
                          const ma::FrictionIdentificationOptions& options = {}) -> std::string {
    try {
      (void)ma::identify_friction(t, u, x, options);
    } catch (const ma::IdentificationError& error) {
      return error.what();
    }
    return "no error";
  };
  const auto has = [](const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
  };
  std::vector<double> short_input(data.input.begin(), data.input.end() - 1);
  EXPECT_TRUE(has(message(data.time, short_input, data.position), "differ in length: time 400, input 399"));
  EXPECT_TRUE(has(message({0.0, 0.01}, {0.0, 0.0}, {0.0, 0.0}), "2 samples, at least 3 needed"));
  auto jittered = data.time;
  jittered[123] += 0.002;  // 20 % of T_s
  EXPECT_TRUE(has(message(jittered, data.input, data.position), "non-uniform sampling: interval"));
  EXPECT_TRUE(has(message(jittered, data.input, data.position), "between samples 122 and 123"));
  auto damaged = data.position;
  damaged[7] = std::nan("");
  EXPECT_TRUE(has(message(data.time, data.input, damaged), "non-finite value at sample 7"));
  ma::FrictionIdentificationOptions demanding;
  demanding.minimum_samples_per_direction = 100000;
  EXPECT_TRUE(has(message(data.time, data.input, data.position, demanding), "at least 100000 each needed"));
  // Constant input and a constant speed per direction: K_m, b and c cannot be separated.
  std::vector<double> t, u, x;
  for (int k = 0; k < 200; ++k) {
    t.push_back(0.01 * k);
    u.push_back(1.0);
    x.push_back(k < 100 ? 0.003 * k : 0.3 - 0.002 * (k - 100));
  }
  EXPECT_TRUE(has(message(t, u, x), "rank"));
}

TEST(FrictionIdentification, RejectsBadOptions) {
  const auto data = discrete_model_data(kDiscreteTruth, ma::DifferenceScheme::centered, 400);
  const auto message = [&](auto mutate) -> std::string {
    ma::FrictionIdentificationOptions options;
    mutate(options);
    try {
      (void)ma::identify_friction(data.time, data.input, data.position, options);
    } catch (const crane::common::ConfigError& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message([](auto& o) { o.dead_band = -0.01; }), "dead_band = -0.01 is out of range: must be >= 0");
  EXPECT_EQ(message([](auto& o) { o.motor_constant = 0.0; }), "km = 0 is out of range: must be > 0");
  EXPECT_EQ(message([](auto& o) { o.cutoff_frequency = 60.0; }),
            "cutoff_hz = 60 is out of range: must be < half the sample rate 50");
  EXPECT_EQ(message([](auto& o) { o.minimum_samples_per_direction = 0; }),
            "minimum_samples_per_direction = 0 is out of range: must be >= 1");
}
