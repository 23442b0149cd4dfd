// Tests of the state estimator core (section 4.3).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/state_estimator/state_estimator.hpp"

namespace se = crane::state_estimator;
using crane::common::CraneMeasurement;
using crane::common::CraneStateEstimate;
using crane::common::StepStatus;

namespace {
constexpr double kFs = 100.0;
constexpr se::DifferentiatorKind kKinds[] = {se::DifferentiatorKind::backward,
                                             se::DifferentiatorKind::al_alaoui_first_order,
                                             se::DifferentiatorKind::al_alaoui_second_order};
}  // namespace

TEST(ButterworthLowPass, UnitDcGainAndMinus3dBAtCutoff) {
  const auto tf = se::butterworth_low_pass(5.0, kFs);
  // DC: b0+b1+b2 = 4 K^2 n and 1+a1+a2 = 4 K^2 n, so H(1) = 1 exactly (up to rounding).
  EXPECT_NEAR(tf.dc_gain(), 1.0, 1e-12);
  EXPECT_NEAR(std::abs(tf.frequency_response(0.0, kFs)), 1.0, 1e-12);
  // Pre-warped bilinear transform: |H| = 1/sqrt(2) exactly at the cutoff.
  EXPECT_NEAR(std::abs(tf.frequency_response(5.0, kFs)), 1.0 / std::sqrt(2.0), 1e-12);
  // Second order: about -12 dB/octave well above the cutoff, and a zero at Nyquist.
  EXPECT_LT(std::abs(tf.frequency_response(20.0, kFs)), 0.07);
  EXPECT_NEAR(std::abs(tf.frequency_response(50.0, kFs)), 0.0, 1e-12);
}

TEST(ButterworthLowPass, SimulatedSinusoidAtCutoffHasGain0707) {
  // Cross-check of the coefficient formula against the running difference equation.
  se::DiscreteFilter filter(se::butterworth_low_pass(5.0, kFs));
  filter.initialize(0.0, 0.0);
  double peak = 0.0;
  for (int k = 0; k < 4000; ++k) {
    const double y = filter.update(std::sin(2.0 * std::numbers::pi * 5.0 * k / kFs));
    if (k > 3000) peak = std::max(peak, std::abs(y));
  }
  // Sampled at 20 points per period the discrete peak sits within cos(pi/20) of the true amplitude.
  EXPECT_LE(peak, 1.0 / std::sqrt(2.0) + 1e-9);
  EXPECT_GE(peak, std::cos(std::numbers::pi / 20.0) / std::sqrt(2.0) - 1e-9);
}

TEST(Differentiator, RampGivesExactSlopeAfterTransient) {
  // x(k) = x0 + v k/fs: x(k)-x(k-1) = v/fs is constant, so y converges to the DC value of the
  // recursion: backward fs*v/fs = v; (4.9) (8/7)v/(1+1/7) = v; (4.10) 3r*2v/(1+r)^2 = v (r=2-sqrt3).
  for (const auto kind : kKinds) {
    se::DiscreteFilter d(se::differentiator_coefficients(kind, kFs));
    const double x0 = 0.3, v = 0.4982;
    d.initialize(x0, 0.0);
    double y = 0.0;
    for (int k = 1; k <= 200; ++k) y = d.update(x0 + v * k / kFs);
    EXPECT_NEAR(y, v, 1e-12) << static_cast<int>(kind);
  }
}

// differentiator_lag: the backward difference (4.8) followed by G(z) gives what the differentiator
// gives, sample by sample, on a seeded random signal; G's DC gain is 1 and (4.8)'s G is 1.
TEST(Differentiator, ItsLagAfterTheBackwardDifferenceIsTheDifferentiator) {
  std::mt19937 random(7);
  std::uniform_real_distribution<double> step(-0.01, 0.01);
  for (const auto kind : kKinds) {
    const auto tf = se::differentiator_coefficients(kind, kFs);
    const auto lag = se::differentiator_lag(tf, kFs);
    EXPECT_NEAR(lag.dc_gain(), 1.0, 1e-12) << static_cast<int>(kind);
    se::DiscreteFilter direct(tf);
    se::DiscreteFilter lagged(lag);
    double x = 0.2;
    double previous = x;
    direct.initialize(x, 0.0);
    lagged.initialize(0.0, 0.0);
    double worst = 0.0;
    for (int k = 0; k < 500; ++k) {
      x += step(random);
      const double expected = direct.update(x);
      worst = std::max(worst, std::abs(lagged.update(kFs * (x - previous)) - expected));
      previous = x;
    }
    EXPECT_LT(worst, 1e-12) << static_cast<int>(kind);
  }
  const auto backward = se::differentiator_lag(se::differentiator_coefficients(se::DifferentiatorKind::backward, kFs), kFs);
  EXPECT_DOUBLE_EQ(backward.b0, 1.0);
  EXPECT_DOUBLE_EQ(backward.b1, 0.0);
  EXPECT_DOUBLE_EQ(backward.a1, 0.0);
}

TEST(Differentiator, PrintedCoefficientsOf410RoundTheExactOnes) {
  const auto tf = se::differentiator_coefficients(se::DifferentiatorKind::al_alaoui_second_order, kFs);
  EXPECT_NEAR(tf.a1, 0.5358, 1e-4);
  EXPECT_NEAR(tf.a2, 0.0718, 1e-4);
  EXPECT_NEAR(tf.b0 / (3.0 * kFs / 3.7321), 1.0, 2e-5);  // 3.7321 is 2+sqrt3 to 5 digits
  EXPECT_DOUBLE_EQ(tf.b2, -tf.b0);  // x(k) - x(k-2): see filter_design.hpp
  const auto first = se::differentiator_coefficients(se::DifferentiatorKind::al_alaoui_first_order, kFs);
  EXPECT_DOUBLE_EQ(first.a1, 1.0 / 7.0);
  EXPECT_DOUBLE_EQ(first.b0, 8.0 * kFs / 7.0);
}

TEST(Differentiator, FrequencyResponseMatchesDifferenceEquation) {
  // Drive each differentiator with a sampled sinusoid, fit the steady-state output to
  // A cos + B sin by correlation over whole periods, and compare with H(e^{jwT}).
  for (const auto kind : kKinds) {
    const auto tf = se::differentiator_coefficients(kind, kFs);
    for (const double f : {0.5, 2.0, 10.0}) {
      se::DiscreteFilter d(tf);
      d.initialize(0.0, 0.0);
      const double w = 2.0 * std::numbers::pi * f / kFs;
      const int settle = 2000, periods_samples = static_cast<int>(std::lround(20.0 * kFs / f));
      double c = 0.0, s = 0.0;
      for (int k = 0; k < settle + periods_samples; ++k) {
        const double y = d.update(std::sin(w * k));
        if (k >= settle) {
          c += y * std::cos(w * k);
          s += y * std::sin(w * k);
        }
      }
      // y = |H| sin(wk + arg H) = Re(H) sin + Im(H) cos
      const double re = 2.0 * s / periods_samples, im = 2.0 * c / periods_samples;
      const auto h = tf.frequency_response(f, kFs);
      EXPECT_NEAR(re, h.real(), 1e-6 * std::abs(h) + 1e-9) << static_cast<int>(kind) << " f=" << f;
      EXPECT_NEAR(im, h.imag(), 1e-6 * std::abs(h) + 1e-9) << static_cast<int>(kind) << " f=" << f;
      // Low frequencies: close to the ideal j*2*pi*f.
      if (f <= 2.0) {
        EXPECT_NEAR(std::abs(h) / (2.0 * std::numbers::pi * f), 1.0, 0.02);
      }
    }
  }
}

TEST(StateEstimator, FirstSampleInitializesWithoutTransient) {
  se::StateEstimator estimator(se::StateEstimatorParams{});
  CraneMeasurement m{0.25, 0.3, 0.01, -0.02, 1.5};
  CraneStateEstimate e;
  for (int k = 0; k < 5; ++k) {
    ASSERT_EQ(estimator.step(m, e), StepStatus::ok);
    EXPECT_NEAR(e.trolley_position, 0.25, 1e-12);
    EXPECT_NEAR(e.slew_angle, 0.3, 1e-12);
    EXPECT_NEAR(e.swing_in_plane, 0.01, 1e-12);
    EXPECT_NEAR(e.swing_out_of_plane, -0.02, 1e-12);
    EXPECT_NEAR(e.cable_length, 1.5, 1e-12);
    EXPECT_NEAR(e.trolley_velocity, 0.0, 1e-12);
    EXPECT_NEAR(e.trolley_velocity_raw, 0.0, 1e-12);
  }
}

TEST(StateEstimator, RampRatesConvergeFilteredAndRaw) {
  se::StateEstimator estimator(se::StateEstimatorParams{});
  CraneStateEstimate e;
  const double v = 0.4, w = -0.7;
  for (int k = 0; k < 300; ++k) {
    const double t = k / kFs;
    ASSERT_EQ(estimator.step(CraneMeasurement{0.2 + v * t, w * t, 0.0, 0.0, 1.0}, e), StepStatus::ok);
  }
  EXPECT_NEAR(e.trolley_velocity, v, 1e-9);
  EXPECT_NEAR(e.trolley_velocity_raw, v, 1e-12);
  EXPECT_NEAR(e.slew_rate, w, 1e-9);
  EXPECT_NEAR(e.slew_rate_raw, w, 1e-12);
  // The filtered position lags a ramp by the group delay at DC: sqrt2/(2 pi fc) for Butterworth-2
  // = 0.045 s continuous; the raw position is not available, so compare to the ramp.
  EXPECT_NEAR(e.trolley_position, 0.2 + v * 299 / kFs - v * 0.045, 2e-3);
}

TEST(StateEstimator, NonFiniteRejectedAndStateUnchanged) {
  se::StateEstimator a(se::StateEstimatorParams{});
  se::StateEstimator b(se::StateEstimatorParams{});
  CraneStateEstimate ea, eb;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (int k = 0; k < 50; ++k) {
    const CraneMeasurement m{0.01 * k, 0.0, 0.001 * k, 0.0, 1.0};
    ASSERT_EQ(a.step(m, ea), StepStatus::ok);
    ASSERT_EQ(b.step(m, eb), StepStatus::ok);
    if (k == 20) {
      CraneMeasurement bad = m;
      bad.swing_out_of_plane = nan;
      CraneStateEstimate before = eb;
      EXPECT_EQ(b.step(bad, eb), StepStatus::rejected_nonfinite);
      bad.swing_out_of_plane = 0.0;
      bad.cable_length = inf;
      EXPECT_EQ(b.step(bad, eb), StepStatus::rejected_nonfinite);
      EXPECT_EQ(eb.trolley_position, before.trolley_position);
    }
  }
  // b skipped the bad samples entirely, so it matches a bit for bit.
  EXPECT_EQ(ea.trolley_position, eb.trolley_position);
  EXPECT_EQ(ea.trolley_velocity, eb.trolley_velocity);
  EXPECT_EQ(ea.swing_in_plane_rate, eb.swing_in_plane_rate);
}

TEST(StateEstimator, AbsurdMagnitudeRejectedBeforeItOverflowsTheRates) {
  // Found by the topic-gates fuzzer (tests/fuzz): a finite trolley position of -1.47e307 m after a
  // sample at 0 gave a raw velocity (x_k - x_k-1)/T = -1.47e309 = -Inf, returned as ok. Beyond
  // kMaxMeasurementMagnitude a sample is refused like a NaN, and the state is unchanged.
  se::StateEstimator a(se::StateEstimatorParams{});
  se::StateEstimator b(se::StateEstimatorParams{});
  CraneStateEstimate ea, eb;
  const CraneMeasurement rest{0.25, 0.0, 0.0, 0.0, 1.0};
  ASSERT_EQ(a.step(rest, ea), StepStatus::ok);
  ASSERT_EQ(b.step(rest, eb), StepStatus::ok);
  for (const double absurd : {-1.4746701496917433e+307, 2.0 * se::kMaxMeasurementMagnitude}) {
    for (int channel = 0; channel < 5; ++channel) {
      CraneMeasurement bad = rest;
      double* fields[] = {&bad.trolley_position, &bad.slew_angle, &bad.swing_in_plane, &bad.swing_out_of_plane,
                          &bad.cable_length};
      *fields[channel] = absurd;
      EXPECT_EQ(b.step(bad, eb), StepStatus::rejected_nonfinite) << "channel " << channel << " = " << absurd;
    }
  }
  // The bound itself is a measurement (a 1000 km trolley is absurd, but its rates stay finite).
  CraneMeasurement edge = rest;
  edge.trolley_position = se::kMaxMeasurementMagnitude;
  se::StateEstimator c(se::StateEstimatorParams{});
  CraneStateEstimate ec;
  ASSERT_EQ(c.step(rest, ec), StepStatus::ok);
  ASSERT_EQ(c.step(edge, ec), StepStatus::ok);
  EXPECT_TRUE(std::isfinite(ec.trolley_velocity_raw));
  EXPECT_TRUE(std::isfinite(ec.trolley_velocity));
  // b skipped the bad samples entirely: it matches a, which never saw them, bit for bit.
  ASSERT_EQ(a.step(rest, ea), StepStatus::ok);
  ASSERT_EQ(b.step(rest, eb), StepStatus::ok);
  EXPECT_EQ(ea.trolley_position, eb.trolley_position);
  EXPECT_EQ(ea.trolley_velocity_raw, eb.trolley_velocity_raw);
}

TEST(StateEstimator, BadParamsThrowNamingField) {
  auto expect_throw = [](const se::StateEstimatorParams& p, const std::string& field) {
    try {
      se::StateEstimator estimator(p);
      FAIL() << "no throw for " << field;
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
    }
  };
  se::StateEstimatorParams p;
  p.sample_rate = 0.0;
  expect_throw(p, "sample_rate");
  p = {};
  p.cutoff_frequency = 60.0;
  expect_throw(p, "cutoff_frequency");
  p = {};
  p.cutoff_frequency = std::numeric_limits<double>::quiet_NaN();
  expect_throw(p, "cutoff_frequency");
  p = {};
  p.differentiator = static_cast<se::DifferentiatorKind>(7);
  expect_throw(p, "differentiator");
}
