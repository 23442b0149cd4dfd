// The online estimator core (services/adaptation): the recursive least squares against exact rows,
// its excitation check, the whole OnlineAdaptation on a simulated trolley axis with a pendulum
// (an independent integrator written here: (3.31) with the friction (3.1)-(3.3), the linear
// pendulum L phi'' + g phi = x'' of (2.28)), and the limit-cycle detector.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "crane/adaptation/axis_identifier.hpp"
#include "crane/adaptation/limit_cycle_detector.hpp"
#include "crane/adaptation/online_adaptation.hpp"
#include "crane/common/validation.hpp"

namespace {

using crane::adaptation::AxisIdentifier;
using crane::adaptation::AxisIdentifierParams;
using crane::adaptation::LimitCycleDetector;
using crane::adaptation::LimitCycleParams;
using crane::adaptation::OnlineAdaptation;
using crane::adaptation::OnlineAdaptationParams;
using crane::adaptation::ParameterVector;

AxisIdentifierParams identifier_params() {
  AxisIdentifierParams p;
  p.forgetting_factor = 1.0;
  p.initial << 0.09, 1.5, 6.0, 0.9, 1.2;
  p.scale << 0.09, 1.5, 6.0, 0.9, 1.2;
  p.min_information = 1.0;
  p.max_condition = 1e4;
  return p;
}

// A row of the trolley regression at velocity v [m/s], swing phi [rad]: phi = (-g phi/K, -r(v)).
ParameterVector row(double v, double phi) {
  const double eta = v > 0.0 ? 1.0 : 0.0;
  const double xi = v < 0.0 ? 1.0 : 0.0;
  ParameterVector r;
  r << -9.8 * phi / 2.0, -v * eta, -v * xi, -eta, xi;
  return r;
}

TEST(AxisIdentifier, ConditioningOfADiagonalMatrix) {
  // diag(4, 1): eigenvalues 4 and 1, condition 4.
  Eigen::Matrix2d m;
  m << 4.0, 0.0, 0.0, 1.0;
  const auto c = crane::adaptation::conditioning<2>(m);
  EXPECT_DOUBLE_EQ(c.min_eigenvalue, 1.0);
  EXPECT_DOUBLE_EQ(c.condition, 4.0);
}

TEST(AxisIdentifier, RecoversExactParametersFromRowsOfBothDirections) {
  AxisIdentifier id(identifier_params(), "test");
  ParameterVector truth;
  truth << 0.135, 2.25, 9.0, 1.35, 1.8;  // 3 kg on M = 22.2 kg, friction x 1.5
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> speed(0.05, 0.5);
  std::uniform_real_distribution<double> swing(-0.3, 0.3);
  for (int k = 0; k < 1000; ++k) {
    const double v = (k / 50) % 2 == 0 ? speed(rng) : -speed(rng);
    const ParameterVector phi = row(v, swing(rng));
    ASSERT_TRUE(id.update(phi.dot(truth), phi));
  }
  ASSERT_TRUE(id.solve());
  const auto& s = id.identification();
  EXPECT_TRUE(s.load_excited && s.positive_excited && s.negative_excited);
  for (int i = 0; i < crane::adaptation::kParameterCount; ++i) EXPECT_NEAR(s.estimate(i), truth(i), 1e-9) << i;
  // The residual is computed from the sufficient statistics, E - 2 theta^T r + theta^T R theta, whose
  // cancellation leaves about sqrt(eps) |y| = 1.5e-8 x 1 V: exact rows give no more than that.
  EXPECT_LT(s.residual_rms, 1e-6);
}

TEST(AxisIdentifier, OneDirectionLeavesTheOtherDirectionUnchanged) {
  const auto params = identifier_params();
  AxisIdentifier id(params, "test");
  ParameterVector truth;
  truth << 0.135, 2.25, 9.0, 1.35, 1.8;
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> speed(0.05, 0.5);
  std::uniform_real_distribution<double> swing(-0.3, 0.3);
  for (int k = 0; k < 1000; ++k) {
    const ParameterVector phi = row(speed(rng), swing(rng));
    (void)id.update(phi.dot(truth), phi);
  }
  ASSERT_TRUE(id.solve());
  const auto& s = id.identification();
  EXPECT_TRUE(s.positive_excited);
  EXPECT_FALSE(s.negative_excited);
  EXPECT_NEAR(s.estimate(0), truth(0), 1e-9);
  EXPECT_NEAR(s.estimate(1), truth(1), 1e-9);
  EXPECT_NEAR(s.estimate(3), truth(3), 1e-9);
  EXPECT_EQ(s.estimate(2), params.initial(2));  // b-, c-: no data, held
  EXPECT_EQ(s.estimate(4), params.initial(4));
  EXPECT_EQ(s.standard_deviation(2), 0.0);
}

TEST(AxisIdentifier, CollinearRegressorsAreNotSolved) {
  // The swing proportional to the direction (phi = 0.1 while moving +) and a constant speed: the
  // load, viscous and Coulomb columns are collinear; the data cannot tell them apart.
  const auto params = identifier_params();
  AxisIdentifier id(params, "test");
  ParameterVector truth;
  truth << 0.135, 2.25, 9.0, 1.35, 1.8;
  for (int k = 0; k < 1000; ++k) {
    const ParameterVector phi = row(0.3, 0.1);
    (void)id.update(phi.dot(truth), phi);
  }
  EXPECT_FALSE(id.solve());
  EXPECT_EQ(id.identification().estimate, params.initial);
  EXPECT_EQ(id.identification().solves, 0u);
}

TEST(AxisIdentifier, NoDataNoSolveAndNonFiniteRowsAreIgnored) {
  const auto params = identifier_params();
  AxisIdentifier id(params, "test");
  ParameterVector bad = row(0.3, 0.1);
  bad(0) = std::nan("");
  EXPECT_FALSE(id.update(1.0, bad));
  EXPECT_FALSE(id.update(std::numeric_limits<double>::infinity(), row(0.3, 0.1)));
  EXPECT_FALSE(id.solve());
  EXPECT_EQ(id.identification().estimate, params.initial);
  EXPECT_EQ(id.identification().accepted_samples, 0u);
}

TEST(AxisIdentifier, InvalidParamsNameTheField) {
  auto p = identifier_params();
  p.forgetting_factor = 1.5;
  try {
    AxisIdentifier id(p, "state_estimator.adaptation.trolley");
    FAIL() << "no error";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("state_estimator.adaptation.trolley.forgetting_factor = 1.5"), std::string::npos)
        << e.what();
  }
  p = identifier_params();
  p.scale(3) = 0.0;
  EXPECT_THROW(AxisIdentifier(p, "x"), crane::common::ConfigError);
}

// ---- The whole estimator on a simulated trolley axis ------------------------------------------

// The trolley of the lab crane (section 4.2) under a PD on a sinusoidal reference, with stick-slip
// friction (3.1)-(3.3) and a linear pendulum, integrated here by explicit Euler at 0.1 ms (an
// integrator independent of the plant's SUNDIALS model); encoders quantized like the lab crane's
// motor encoder (2000 lines x 4 through 0.5 in/rev), the drive's 13-bit DAC over +-10 V.
struct AxisRun {
  double load_mass{3.0};            // [kg] the truth
  double friction_factor{1.5};      // truth = configured x factor
  double amplitude{0.3};            // [m] reference amplitude
  double period{4.0};               // [s]
  double duration{30.0};            // [s]
  double hunting{0.0};              // [s] then at rest at x = 0.6 m hunting: every 0.4 s the drive
                                    // flips sign and the trolley slides 1 mm the other way
};

struct AxisRunResult {
  crane::adaptation::AdaptationEstimate estimate;
  double time_to_confident{-1.0};   // [s]
};

AxisRunResult run_axis(const OnlineAdaptationParams& params, const AxisRun& run) {
  OnlineAdaptation adaptation(params);
  const auto& crane = params.crane;
  crane::common::AxisFriction f = crane.trolley_friction;
  for (double* c : {&f.viscous_positive, &f.viscous_negative, &f.coulomb_positive, &f.coulomb_negative,
                    &f.static_positive, &f.static_negative}) {
    *c *= run.friction_factor;
  }
  const double k = crane.trolley_drive_gain;
  const double m_t = run.load_mass / crane.trolley_drive_mass;
  const double g = crane.gravity;
  const double length = 1.0;
  const double encoder = crane.leadscrew_pitch * 2.0 * 3.14159265358979323846 / (4.0 * crane.motor_encoder_lines);
  const double dac = 2.0 * crane.dac_range / 8192.0;
  double x = 0.6;
  double v = 0.0;
  double phi = 0.0;
  double phi_rate = 0.0;
  double u = 0.0;
  double last_measured = x;
  AxisRunResult result;
  const int substeps = 100;
  const double t_s = params.sample_period;
  const double h = t_s / substeps;
  for (int n = 0; n * t_s < run.duration; ++n) {
    const double t = n * t_s;
    crane::adaptation::AdaptationInput in;
    in.trolley_position = std::round(x / encoder) * encoder;
    in.swing_in_plane = std::round(phi / 1.0472e-3) * 1.0472e-3;  // 6000 lines x 4
    in.applied_trolley_voltage = u;
    in.brakes_engaged = false;
    adaptation.step(in, result.estimate);
    if (result.estimate.payload_confident && result.time_to_confident < 0.0) result.time_to_confident = t;
    // PD on the reference plus the configured friction as feedforward on the reference velocity.
    const double w = 2.0 * 3.14159265358979323846 / run.period;
    const double x_ref = 0.6 + run.amplitude * std::sin(w * t);
    const double v_ref = run.amplitude * w * std::cos(w * t);
    const double measured_velocity = (in.trolley_position - last_measured) / t_s;
    last_measured = in.trolley_position;
    double command = 12.0 * (x_ref - in.trolley_position) + 3.0 * (v_ref - measured_velocity);
    const auto& c = crane.trolley_friction;
    command += v_ref > 0.0 ? c.coulomb_positive + c.viscous_positive * v_ref : -c.coulomb_negative + c.viscous_negative * v_ref;
    u = std::clamp(std::round(command / dac) * dac, -crane.dac_range, crane.dac_range);
    if (t >= run.duration - run.hunting) {  // the hunting phase replaces the axis (a limit cycle)
      const int half = static_cast<int>((t - (run.duration - run.hunting)) / 0.4) % 2 == 0 ? 1 : -1;
      const double into = std::fmod(t - (run.duration - run.hunting), 0.4);
      u = 1.6 * half;
      if (into < 0.05) x += half * 0.02 * t_s;  // 1 mm in 0.05 s
      v = 0.0;
      phi = phi_rate = 0.0;
      continue;
    }
    for (int s = 0; s < substeps; ++s) {
      const double drive = k * u - m_t * g * phi;  // [m/s^2] (3.31) without friction
      double friction = 0.0;                        // [m/s^2]
      if (v > 0.0) friction = k * (f.coulomb_positive + f.viscous_positive * v);
      if (v < 0.0) friction = -k * (f.coulomb_negative - f.viscous_negative * v);
      double a = drive - friction;
      if (v == 0.0) {  // stuck until the drive beats breakaway (3.2)
        if (drive > k * f.static_positive) {
          a = drive - k * f.coulomb_positive;
        } else if (drive < -k * f.static_negative) {
          a = drive + k * f.coulomb_negative;
        } else {
          a = 0.0;
        }
      }
      const double v_next = v + h * a;
      const bool crossed = (v > 0.0 && v_next < 0.0) || (v < 0.0 && v_next > 0.0);
      x += h * v;
      v = crossed ? 0.0 : v_next;
      const double phi_acc = (a - g * phi) / length;  // L phi'' + g phi = x''
      phi += h * phi_rate;
      phi_rate += h * phi_acc;
    }
  }
  return result;
}

OnlineAdaptationParams adaptation_params() {
  OnlineAdaptationParams p;
  p.enabled = true;
  return p;
}

TEST(OnlineAdaptation, FilterMemoryAndCorrelationOfItsLowPass) {
  // A moving average of N samples has (sum h)^2 / sum h^2 = N; the Butterworth's figure is printed.
  const auto params = adaptation_params();
  const OnlineAdaptation a(params);
  std::printf("low pass %.1f Hz: memory %d samples (impulse response down to 1 %%, + 2 for the stencil), "
              "%.2f correlated samples\n", params.filter_cutoff, a.settle_samples(), a.noise_correlation());
  // Its equivalent noise bandwidth is about 1.11 f_c for a second-order Butterworth: fs / (2 x 1.11 f_c).
  EXPECT_NEAR(a.noise_correlation(), 100.0 / (2.0 * 1.11 * params.filter_cutoff), 1.0);
  EXPECT_GT(a.settle_samples(), 10);
  EXPECT_LT(a.settle_samples(), 60);
}

TEST(OnlineAdaptation, RecoversMassAndFrictionOfASimulatedTrolley) {
  const auto params = adaptation_params();
  const AxisRunResult r = run_axis(params, AxisRun{});
  const auto& e = r.estimate;
  std::printf("mass %.4f kg +- %.4f (truth 3.0), confident after %.2f s; friction b+ %.3f b- %.3f c+ %.3f c- %.3f "
              "(truth %.3f %.3f %.3f %.3f)\n",
              e.payload_mass, e.payload_mass_bound, r.time_to_confident, e.trolley_friction.viscous_positive,
              e.trolley_friction.viscous_negative, e.trolley_friction.coulomb_positive,
              e.trolley_friction.coulomb_negative, 1.5 * 1.5, 1.5 * 6.0, 1.5 * 0.9, 1.5 * 1.2);
  ASSERT_TRUE(e.payload_confident);
  EXPECT_NEAR(e.payload_mass, 3.0, 0.05 * 3.0);
  EXPECT_LE(std::abs(e.payload_mass - 3.0), e.payload_mass_bound) << "truth outside the printed bound";
  EXPECT_TRUE(e.trolley_friction_adapted);
  const auto& cfg = params.crane.trolley_friction;
  EXPECT_NEAR(e.trolley_friction.coulomb_positive, 1.5 * cfg.coulomb_positive, 0.05 * 1.5 * cfg.coulomb_positive);
  EXPECT_NEAR(e.trolley_friction.coulomb_negative, 1.5 * cfg.coulomb_negative, 0.05 * 1.5 * cfg.coulomb_negative);
  // Breakaway follows the Coulomb coefficient (header).
  EXPECT_NEAR(e.trolley_friction.static_positive / cfg.static_positive,
              e.trolley_friction.coulomb_positive / cfg.coulomb_positive, 1e-12);
  EXPECT_FALSE(e.trolley_limit_cycle);
}

TEST(OnlineAdaptation, ALimitCycleFallsBackToTheConfiguredFriction) {
  // The trolley is identified (friction x 1.5 released), then hunts at rest for 10 s: the detector
  // fires and the compensation gets the configured coefficients back.
  const auto params = adaptation_params();
  AxisRun run;
  run.duration = 40.0;
  run.hunting = 10.0;  // at rest once the 4 s window holds no travel, then 15 reversals
  const AxisRunResult r = run_axis(params, run);
  EXPECT_TRUE(r.estimate.trolley_limit_cycle);
  EXPECT_FALSE(r.estimate.trolley_friction_adapted);
  EXPECT_EQ(r.estimate.trolley_friction.coulomb_positive, params.crane.trolley_friction.coulomb_positive);
  EXPECT_EQ(r.estimate.trolley_friction.static_negative, params.crane.trolley_friction.static_negative);
  EXPECT_GE(r.estimate.trolley_voltage_sign_changes, 10u);
  // Without the hunting phase the same run adapts (the previous test): the fallback is the detector's.
  run.hunting = 0.0;
  EXPECT_TRUE(run_axis(params, run).estimate.trolley_friction_adapted);
}

TEST(OnlineAdaptation, AnAxisThatNeverSlidesLeavesEverythingConfigured) {
  // Reference amplitude 0.1 mm: the PD's voltage stays below breakaway, the trolley never slides.
  const auto params = adaptation_params();
  AxisRun run;
  run.amplitude = 1e-4;
  const AxisRunResult r = run_axis(params, run);
  EXPECT_FALSE(r.estimate.payload_confident);
  EXPECT_EQ(r.estimate.payload_mass, params.crane.load_mass);
  EXPECT_FALSE(r.estimate.trolley_friction_adapted);
  const auto& f = r.estimate.trolley_friction;
  const auto& cfg = params.crane.trolley_friction;
  EXPECT_EQ(f.coulomb_positive, cfg.coulomb_positive);
  EXPECT_EQ(f.coulomb_negative, cfg.coulomb_negative);
  EXPECT_EQ(f.viscous_positive, cfg.viscous_positive);
  EXPECT_EQ(f.viscous_negative, cfg.viscous_negative);
}

TEST(OnlineAdaptation, DisabledReportsTheConfiguration) {
  OnlineAdaptationParams p;  // enabled false by default
  OnlineAdaptation adaptation(p);
  crane::adaptation::AdaptationEstimate e;
  crane::adaptation::AdaptationInput in;
  in.trolley_position = 0.5;
  in.applied_trolley_voltage = 3.0;
  in.brakes_engaged = false;
  adaptation.step(in, e);
  EXPECT_EQ(e.payload_mass, p.crane.load_mass);
  EXPECT_FALSE(e.payload_confident);
  EXPECT_EQ(e.trolley_friction.coulomb_positive, p.crane.trolley_friction.coulomb_positive);
  EXPECT_EQ(e.slew_friction.static_negative, p.crane.slew_friction.static_negative);
}

TEST(OnlineAdaptation, InvalidFieldIsNamed) {
  auto p = adaptation_params();
  p.max_friction_factor = 0.5;
  try {
    OnlineAdaptation a(p);
    FAIL() << "no error";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("state_estimator.adaptation.max_friction_factor = 0.5"), std::string::npos)
        << e.what();
  }
  p = adaptation_params();
  p.filter_cutoff = 60.0;  // above 0.45 fs
  EXPECT_THROW(OnlineAdaptation{p}, crane::common::ConfigError);
}

// ---- Limit cycles -----------------------------------------------------------------------------

TEST(LimitCycleDetector, HuntingAtRestFiresDitherDoesNot) {
  LimitCycleParams p;  // window 4 s, rest span 10 mm, 6 reversals
  // Hunting: every 0.5 s the drive flips sign and the trolley slides 2 mm the other way (0.04 s at
  // 0.05 m/s), then sticks: 8 reversals in 4 s, at rest (span 2 mm).
  LimitCycleDetector hunting(p, 0.01, 0.01, "test");
  double x = 0.5;
  for (int k = 0; k < 400; ++k) {
    const int half = (k / 50) % 2 == 0 ? 1 : -1;
    const bool sliding = k % 50 < 4;
    if (sliding) x += half * 0.05 * 0.01;
    hunting.step(x, half * 1.5);
  }
  EXPECT_TRUE(hunting.fired());
  EXPECT_GE(hunting.hunting_reversals(), 6u);
  // Dither: the drive flips sign every 0.5 s, the trolley does not move: counted, not a limit cycle.
  LimitCycleDetector dither(p, 0.01, 0.01, "test");
  for (int k = 0; k < 400; ++k) dither.step(0.5, (k / 50) % 2 == 0 ? 1.0 : -1.0);
  EXPECT_FALSE(dither.fired());
  EXPECT_EQ(dither.sign_changes_at_rest(), 7u);  // flips at k = 50, 100, ..., 350
  // A move back and forth over 0.3 m is not at rest.
  LimitCycleDetector move(p, 0.01, 0.01, "test");
  for (int k = 0; k < 2000; ++k) {
    const double t = 0.01 * k;
    move.step(0.5 + 0.15 * std::sin(3.0 * t), 3.0 * std::cos(3.0 * t));
  }
  EXPECT_FALSE(move.fired());
  EXPECT_EQ(move.hunting_reversals(), 0u);
}

}  // namespace
