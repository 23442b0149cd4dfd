// Section-3.1 experiment simulator: the exact piecewise solution of (3.6) against closed forms and
// against an independent fine-step RK4 of a regularized model; and the zero-phase prefilter.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/model_audit/friction_experiment.hpp"
#include "crane/model_audit/zero_phase_filter.hpp"

namespace ma = crane::model_audit;

TEST(FrictionExperiment, SlidesToAStopInClosedForm) {
  // u = 0, v0 > 0: x'' = -b v - c (b = b+ K_m, c = c+ K_m). v(t) = -c/b + (v0 + c/b) e^{-bt} = 0 at
  // t* = ln(1 + b v0 / c) / b; x(t*) = v0/b - c t*/b (integrate v: (v0 + c/b)(1 - e^{-bt*})/b = v0/b).
  ma::FrictionExperimentParams params;  // K_m 1.7, b+/K_m 2.8, c+/K_m 1.0
  const double b = 2.8 * 1.7;
  const double c = 1.0 * 1.7;
  const double v0 = 0.8;
  const double t_stop = std::log(1.0 + b * v0 / c) / b;
  const double x_stop = v0 / b - c * t_stop / b;
  double x = 0.0;
  double v = v0;
  ma::advance_friction_axis(params, 0.0, 0.5 * t_stop, x, v);
  EXPECT_GT(v, 0.0);
  ma::advance_friction_axis(params, 0.0, 0.5 * t_stop + 0.3, x, v);  // stops, then rests 0.3 s
  EXPECT_EQ(v, 0.0);
  EXPECT_NEAR(x, x_stop, 1e-14);
}

TEST(FrictionExperiment, RestsBelowTheCoulombLevelAndBreaksAwayAbove) {
  ma::FrictionExperimentParams params;  // c+/K_m = 1.0 V, c-/K_m = 1.2 V
  double x = 0.25;
  double v = 0.0;
  for (const double u : {0.99, -1.19, 0.0}) {
    ma::advance_friction_axis(params, u, 1.0, x, v);
    EXPECT_EQ(v, 0.0) << u;
    EXPECT_EQ(x, 0.25) << u;
  }
  // u = -1.7 V: x'' = K_m (u + c-/K_m) - b- v = -0.85 - 9.35 v from rest:
  // v(t) = v_inf (1 - e^{-b t}), v_inf = -0.85 / 9.35.
  ma::advance_friction_axis(params, -1.7, 0.1, x, v);
  const double v_inf = 1.7 * (-1.7 + 1.2) / (5.5 * 1.7);
  EXPECT_NEAR(v, v_inf * (1.0 - std::exp(-5.5 * 1.7 * 0.1)), 1e-15);
}

TEST(FrictionExperiment, MatchesAnIndependentFineStepIntegration) {
  // Independent check: RK4 with h = 1e-5 s of the same loop with Coulomb friction regularized as
  // c tanh(v / eps), eps = 1e-5 m/s (stiffness c/eps ~ 2e5 1/s, h * 2e5 = 2, inside RK4's 2.78
  // stability limit). Creep while "stuck" is ~eps, so over 6 s positions agree to a few 1e-5 m; a
  // wrong closed form (a sign, a missed stop) is off by millimetres or more.
  ma::FrictionExperimentParams params;
  params.velocity_feedback = ma::VelocityFeedback::exact;
  params.duration = 6.0;
  const auto record = ma::simulate_friction_experiment(params);

  const double k_m = params.motor_constant;
  const double eps = 1e-5;
  const auto acceleration = [&](double u, double v) {
    const double b = v >= 0.0 ? params.viscous_positive * k_m : params.viscous_negative * k_m;
    const double c = v >= 0.0 ? params.coulomb_positive * k_m : params.coulomb_negative * k_m;
    return k_m * u - b * v - c * std::tanh(v / eps);
  };
  const int substeps = 1000;
  const double h = params.sample_time / substeps;
  double x = 0.0;
  double v = 0.0;
  double worst = 0.0;
  for (std::size_t k = 0; k < record.time.size(); ++k) {
    worst = std::max(worst, std::abs(x - record.true_position[k]));
    const double t = record.time[k];
    const double reference =
        0.3 * std::sin(2.0 * std::numbers::pi * 0.25 * t) - 0.4 * std::sin(2.0 * std::numbers::pi / 3.0 * t);
    const double u = params.proportional_gain * (reference - x - params.derivative_time * v);
    for (int i = 0; i < substeps; ++i) {
      const double k1x = v, k1v = acceleration(u, v);
      const double k2x = v + 0.5 * h * k1v, k2v = acceleration(u, v + 0.5 * h * k1v);
      const double k3x = v + 0.5 * h * k2v, k3v = acceleration(u, v + 0.5 * h * k2v);
      const double k4x = v + h * k3v, k4v = acceleration(u, v + h * k3v);
      x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
      v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    }
  }
  EXPECT_LT(worst, 1e-4) << "max |x_exact - x_rk4| [m]";
}

TEST(FrictionExperiment, RecordsTheLoopAndTheMeasurement) {
  ma::FrictionExperimentParams params;
  params.encoder_quantum = 1e-3;
  params.noise_standard_deviation = 2e-4;
  params.seed = 7;
  const auto record = ma::simulate_friction_experiment(params);
  ASSERT_EQ(record.time.size(), 2401u);  // 24 s at 0.01 s, both ends
  EXPECT_DOUBLE_EQ(record.time.back(), 24.0);
  double worst_error = 0.0;
  for (std::size_t k = 1; k < record.time.size(); ++k) {
    // Quantized: a multiple of the quantum; within noise (6 sigma) + half a quantum of the truth.
    EXPECT_NEAR(std::remainder(record.position[k], 1e-3), 0.0, 1e-12);
    EXPECT_LT(std::abs(record.position[k] - record.true_position[k]), 6 * 2e-4 + 0.5e-3 + 1e-12);
    // (3.17) with the backward-difference velocity of the measurement.
    const double velocity = (record.position[k] - record.position[k - 1]) / 0.01;
    EXPECT_NEAR(record.input[k], 100.0 * (record.reference[k] - record.position[k] - 0.2 * velocity), 1e-9);
    worst_error = std::max(worst_error, std::abs(record.reference[k] - record.true_position[k]));
  }
  // (3.17) feeds back -K K_d x' without the reference velocity, so the loop lags: quasi-statically
  // e = X_ref - x ~ (K_d + b/(K K_m)) X_ref' + c/K + X_ref''/(K K_m); with |X_ref'| <= 0.3 pi/2 +
  // 0.4 (2 pi/3) = 1.309 m/s, b/K_m <= 5.5, c/K_m <= 1.2, |X_ref''| <= 2.5 m/s^2: e <= 0.36 m.
  EXPECT_LT(worst_error, 0.37);
  EXPECT_GT(worst_error, 0.2);
  // Same seed, same record; another seed, another record.
  EXPECT_EQ(ma::simulate_friction_experiment(params).position, record.position);
  params.seed = 8;
  EXPECT_NE(ma::simulate_friction_experiment(params).position, record.position);
}

TEST(FrictionExperiment, RejectsBadParameters) {
  const auto message = [](auto mutate) -> std::string {
    ma::FrictionExperimentParams params;
    mutate(params);
    try {
      (void)ma::simulate_friction_experiment(params);
    } catch (const crane::common::ConfigError& error) {
      return error.what();
    }
    return "no error";
  };
  EXPECT_EQ(message([](auto& p) { p.motor_constant = 0.0; }),
            "motor_constant = 0 is out of range: must be > 0");
  EXPECT_EQ(message([](auto& p) { p.viscous_negative = -1.0; }),
            "viscous_negative = -1 is out of range: must be > 0");
  EXPECT_EQ(message([](auto& p) { p.coulomb_positive = std::nan(""); }),
            "coulomb_positive = nan is out of range: must be >= 0");
  EXPECT_EQ(message([](auto& p) { p.duration = 0.01; }), "duration = 0.01 is out of range: must be > 0.02");
  EXPECT_EQ(message([](auto& p) { p.reference.clear(); }), "reference: needs at least one sinusoid");
  EXPECT_EQ(message([](auto& p) { p.encoder_quantum = -1e-6; }),
            "encoder_quantum = -1e-06 is out of range: must be >= 0");
}

TEST(ZeroPhaseFilter, GainIsSquaredButterworthAndPhaseIsZero) {
  // One pass: |H|^2 = 1 / (1 + (tan(pi f/fs) / tan(pi fc/fs))^4) (second-order Butterworth, bilinear,
  // pre-warped); forward then backward multiplies by H and its conjugate: gain |H|^2, phase 0. At
  // f = fc: 1/2. Zero phase: the output is a scaled copy of the input sinusoid, not shifted.
  const double fs = 100.0;
  const double fc = 5.0;
  for (const double f : {0.25, 2.0, 5.0, 12.0}) {
    std::vector<double> signal(4000);
    for (std::size_t k = 0; k < signal.size(); ++k) {
      signal[k] = std::sin(2.0 * std::numbers::pi * f * static_cast<double>(k) / fs + 0.3);
    }
    const auto filtered = ma::zero_phase_low_pass(signal, fc, fs);
    ASSERT_EQ(filtered.size(), signal.size());
    const double ratio = std::tan(std::numbers::pi * f / fs) / std::tan(std::numbers::pi * fc / fs);
    const double gain = 1.0 / (1.0 + std::pow(ratio, 4));
    double worst = 0.0;
    for (std::size_t k = 1000; k < 3000; ++k) worst = std::max(worst, std::abs(filtered[k] - gain * signal[k]));
    EXPECT_LT(worst, 1e-9) << "f = " << f << " Hz, expected gain " << gain;
  }
}

TEST(ZeroPhaseFilter, KeepsConstantsAndRamps) {
  const std::vector<double> constant(50, 3.25);
  for (const double value : ma::zero_phase_low_pass(constant, 1.0, 100.0)) EXPECT_NEAR(value, 3.25, 1e-12);
  // A ramp: odd reflection continues it beyond both ends, and a zero-phase DC-gain-1 filter passes a
  // ramp unchanged once its start-up transient (outside the padding) has decayed.
  std::vector<double> ramp(400);
  for (std::size_t k = 0; k < ramp.size(); ++k) ramp[k] = 0.5 + 0.01 * static_cast<double>(k);
  const auto filtered = ma::zero_phase_low_pass(ramp, 10.0, 100.0);
  for (std::size_t k = 0; k < ramp.size(); ++k) EXPECT_NEAR(filtered[k], ramp[k], 1e-9) << k;
  EXPECT_TRUE(ma::zero_phase_low_pass(std::vector<double>{}, 1.0, 100.0).empty());
}

TEST(ZeroPhaseFilter, RejectsCutoffsOutsideTheNyquistBand) {
  const std::vector<double> signal(10, 1.0);
  for (const double cutoff : {0.0, -1.0, 50.0, 70.0}) {
    try {
      (void)ma::zero_phase_low_pass(signal, cutoff, 100.0);
      ADD_FAILURE() << cutoff << " accepted";
    } catch (const crane::common::ConfigError& error) {
      EXPECT_EQ(std::string(error.what()).rfind("cutoff_hz = ", 0), 0u) << error.what();
    }
  }
}
