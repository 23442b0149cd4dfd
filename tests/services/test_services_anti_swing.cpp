// Tests of the anti-swing core (section 3.3.2), including the derivation of the sign of K_del
// for this project's tower convention (load at x - L cos(theta) sin(phi)).
//
// Derivation. Linear model (2.28)-(2.29): x_dd + m_t g phi = K_mx V_x, L phi_dd + g phi - x_dd = 0.
// Normalizing with tau = t/T, T = 2 pi sqrt(L/g), x_bar = x/L gives phi'' + a phi = +x_bar'',
// a = 4 pi^2 (3.28), and (3.37) makes x_bar'' = V_bar_x = V_xp + V_xs. With the PD tracking law
// (3.40) and a zero reference, x_bar'' = -K_px x_bar - K_dx x_bar' + V_xs, so in Laplace (normalized
// s): X = V_xs / (s^2 + K_dx s + K_px), (s^2 + a) Phi = s^2 X and V_xs = G_s Phi give
//     (s^2 + a)(s^2 + K_dx s + K_px) - s^2 G_s(s) = 0.
// (3.39)/(3.48) print "+ s^2 G_s": the opposite phi sign. With G_s = K_del e^{-tau_del s} the
// roots at the design point |K_del| = 90, tau_del = 0.1 (Pade l = 20, (3.49)) are
//   K_del = -90: dominant (slowest) pair -1.90 +- 4.37j, damping 0.40; next -2.48 +- 10.33j (0.23)
//   K_del = +90: a pair at +1.36 +- 5.85j: unstable.
// Small-gain check: at the swing frequency w = 2 pi, s^2/(s^2+20s+100) has phase +115.7 deg and the
// delay -36 deg; the loop adds u = 0.284 K_del e^{+j 79.7 deg} phi to phi'' + a phi, which moves the
// roots by 0.284 K_del e^{-j 10.3 deg}/(4 pi): left for K_del < 0.
// So K_del = -90 in our convention (and the PD point is K_ps = -30, K_ds = +8).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "crane/anti_swing/anti_swing.hpp"
#include "crane/common/validation.hpp"
#include "crane/tracking/tracking_controller.hpp"

namespace as = crane::anti_swing;
using crane::common::CraneStateEstimate;
using crane::common::StepStatus;

namespace {

constexpr double kG = 9.8;

double period(double cable_length) { return 2.0 * std::numbers::pi * std::sqrt(cable_length / kG); }

using Poly = std::vector<double>;  // ascending powers
Poly multiply(const Poly& a, const Poly& b) {
  Poly r(a.size() + b.size() - 1, 0.0);
  for (std::size_t i = 0; i < a.size(); ++i)
    for (std::size_t j = 0; j < b.size(); ++j) r[i + j] += a[i] * b[j];
  return r;
}

// Roots (normalized s) of (s^2+a)(s^2+K_dx s+K_px)(1+cs)^l - K_del s^2 (1-cs)^l = 0, the Pade
// (3.49) form of our characteristic equation, c = tau_del/(2l). Solved in w = c s to keep the
// coefficients well scaled, then s = w/c.
std::vector<std::complex<double>> closed_loop_roots(double k_del, double tau_del, int l = 20) {
  const double a = 4.0 * std::numbers::pi * std::numbers::pi;
  const double c = tau_del / (2.0 * l);
  Poly lead{1.0}, lag{1.0};
  for (int i = 0; i < l; ++i) {
    lead = multiply(lead, Poly{1.0, 1.0});
    lag = multiply(lag, Poly{1.0, -1.0});
  }
  Poly p = multiply(multiply(Poly{a * c * c, 0.0, 1.0}, Poly{100.0 * c * c, 20.0 * c, 1.0}), lead);
  const Poly delay_term = multiply(Poly{0.0, 0.0, -k_del * c * c}, lag);
  for (std::size_t i = 0; i < delay_term.size(); ++i) p[i] += delay_term[i];
  const int n = static_cast<int>(p.size()) - 1;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (int i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  for (int i = 0; i < n; ++i) companion(i, n - 1) = -p[static_cast<std::size_t>(i)] / p.back();
  const Eigen::VectorXcd eigenvalues = Eigen::EigenSolver<Eigen::MatrixXd>(companion).eigenvalues();
  std::vector<std::complex<double>> roots;
  for (int i = 0; i < n; ++i) roots.push_back(eigenvalues[i] / c);
  return roots;
}

// Simulates the linear SI plant (2.28)-(2.29) under TrackingController + AntiSwing at 100 Hz with
// exact state feedback, reference 0, starting from swing phi0. Returns max |phi| over each period.
std::vector<double> simulate_swing_envelope(double k_del, double cable_length, int periods) {
  as::AntiSwingParams ap;
  ap.delay_gain = k_del;
  as::AntiSwing anti_swing(ap);
  crane::tracking::TrackingController tracking(crane::tracking::TrackingParams{});
  const double dt = 0.01, m_t = 0.09, k_mx = 2.0;
  double x = 0.5, x_dot = 0.0, phi = 0.05, phi_dot = 0.0;
  const double t_swing = period(cable_length);
  const int substeps = 10;
  const double h = dt / substeps;
  std::vector<double> envelope(static_cast<std::size_t>(periods), 0.0);
  for (int k = 0; k * dt < periods * t_swing; ++k) {
    CraneStateEstimate estimate;
    estimate.trolley_position = x;
    estimate.trolley_velocity = x_dot;
    estimate.swing_in_plane = phi;
    estimate.swing_in_plane_rate = phi_dot;
    estimate.cable_length = cable_length;
    as::AntiSwingOutput action;
    (void)anti_swing.step(estimate, action);  // not_ready at start: zero action
    crane::tracking::TrackingInput in;
    in.estimate = estimate;
    in.reference.trolley.position = 0.5;
    in.trolley_anti_swing_action = action.trolley_action;
    crane::tracking::TrackingOutput out;
    EXPECT_EQ(tracking.step(in, out), StepStatus::ok);
    const double v_x = out.command.trolley_voltage;  // zero-order hold over dt
    for (int s = 0; s < substeps; ++s) {             // semi-implicit Euler, h = 1 ms
      const double x_dd = k_mx * v_x - m_t * kG * phi;               // (2.28)
      const double phi_dd = (x_dd - kG * phi) / cable_length;        // (2.29)
      x_dot += h * x_dd;
      phi_dot += h * phi_dd;
      x += h * x_dot;
      phi += h * phi_dot;
    }
    const auto index = static_cast<std::size_t>(k * dt / t_swing);
    if (index < envelope.size()) envelope[index] = std::max(envelope[index], std::abs(phi));
  }
  return envelope;
}

}  // namespace

TEST(AntiSwing, DelayLineIsExactInSamples) {
  // L = 1: T = 2.0071 s, tau_del T = 0.20071 s = 20.07 samples -> 20. Feeding phi_k = 0.001 k,
  // the action at k >= 20 is K_del * 0.001 (k - 20).
  as::AntiSwing anti_swing(as::AntiSwingParams{});
  CraneStateEstimate e;
  e.cable_length = 1.0;
  as::AntiSwingOutput out;
  for (int k = 0; k < 60; ++k) {
    e.swing_in_plane = 0.001 * k;
    e.swing_out_of_plane = -0.002 * k;
    const auto status = anti_swing.step(e, out);
    EXPECT_EQ(out.delay_samples, 20);
    if (k < 20) {
      EXPECT_EQ(status, StepStatus::not_ready);
      EXPECT_EQ(out.trolley_action, 0.0);
    } else {
      ASSERT_EQ(status, StepStatus::ok);
      EXPECT_NEAR(out.trolley_action, -90.0 * 0.001 * (k - 20), 1e-12);
      EXPECT_NEAR(out.slew_action, -90.0 * -0.002 * (k - 20), 1e-12);
    }
  }
  // L = 4 m: T = 4.0142 s -> 40.14 samples -> 40, recomputed from the measured length.
  e.cable_length = 4.0;
  e.swing_in_plane = 0.001 * 60;
  ASSERT_EQ(anti_swing.step(e, out), StepStatus::ok);
  EXPECT_EQ(out.delay_samples, 40);
  EXPECT_NEAR(out.trolley_action, -90.0 * 0.001 * 20, 1e-12);
  EXPECT_NEAR(out.swing_period, period(4.0), 1e-12);
  // Capacity from max_cable_length 5 m: 0.1*4.4880/0.01 = 44.9 -> 45 + 2.
  EXPECT_EQ(anti_swing.delay_line_capacity(), 47);
}

TEST(AntiSwing, PdLawUsesNormalizedRate) {
  // (3.45): V_xs = K_ps phi + K_ds T phi_dot = -30*0.02 + 8*2.0071*0.1 = 1.00568
  as::AntiSwingParams p;
  p.kind = as::AntiSwingKind::pd;
  as::AntiSwing anti_swing(p);
  CraneStateEstimate e;
  e.cable_length = 1.0;
  e.swing_in_plane = 0.02;
  e.swing_in_plane_rate = 0.1;
  as::AntiSwingOutput out;
  ASSERT_EQ(anti_swing.step(e, out), StepStatus::ok);
  EXPECT_NEAR(out.trolley_action, -30.0 * 0.02 + 8.0 * period(1.0) * 0.1, 1e-12);
  p.kind = as::AntiSwingKind::none;
  as::AntiSwing none(p);
  ASSERT_EQ(none.step(e, out), StepStatus::ok);
  EXPECT_EQ(out.trolley_action, 0.0);
}

TEST(AntiSwing, DesignPointRootsGiveDamping045Region) {
  // Dominant = complex pair with the largest real part (the slowest to decay).
  auto dominant = [](const std::vector<std::complex<double>>& roots) {
    std::complex<double> best(-1e9, 0.0);
    for (const auto& r : roots)
      if (std::abs(r.imag()) > 1e-6 && r.real() > best.real()) best = r;
    return best;
  };
  auto max_real = [](const std::vector<std::complex<double>>& roots) {
    double m = -1e9;
    for (const auto& r : roots) m = std::max(m, r.real());
    return m;
  };
  const auto stable = closed_loop_roots(-90.0, 0.1);
  EXPECT_LT(max_real(stable), -1.0);
  const auto d = dominant(stable);
  const double zeta = -d.real() / std::abs(d);
  EXPECT_GT(zeta, 0.35);
  EXPECT_LT(zeta, 0.46);
  // Without anti-swing the swing pair sits on the imaginary axis at 2 pi (zero damping).
  // (1e-2: the 20-fold Pade pole at K_del = 0 limits the companion-matrix accuracy.)
  EXPECT_NEAR(max_real(closed_loop_roots(0.0, 0.1)), 0.0, 1e-2);
  // The opposite sign (the one printed in (3.48) taken literally in our convention) is unstable.
  EXPECT_GT(max_real(closed_loop_roots(+90.0, 0.1)), 1.0);
}

TEST(AntiSwing, ClosedLoopSwingDecaysWithDerivedSignAndGrowsWithOpposite) {
  // Feedback-linearized linear plant at L = 1 m and L = 3 m: with K_del = -90 the swing envelope
  // after 3 periods is below 5% of the initial 0.05 rad (exp(-1.9*3) = 0.3% predicted, plus the
  // 20-sample start-up); with K_del = +90 it grows; with 0 it stays (undamped).
  for (const double length : {1.0, 3.0}) {
    const auto damped = simulate_swing_envelope(-90.0, length, 5);
    EXPECT_LT(damped[3], 0.05 * 0.05) << "L=" << length;
    EXPECT_LT(damped[4], damped[1]) << "L=" << length;
    const auto undamped = simulate_swing_envelope(0.0, length, 5);
    EXPECT_GT(undamped[4], 0.8 * undamped[0]) << "L=" << length;
    const auto unstable = simulate_swing_envelope(+90.0, length, 5);
    EXPECT_GT(unstable[4], unstable[0]) << "L=" << length;
  }
}

TEST(AntiSwing, NonFiniteRejectedAndHistoryUnchanged) {
  as::AntiSwing a(as::AntiSwingParams{});
  as::AntiSwing b(as::AntiSwingParams{});
  CraneStateEstimate e;
  e.cable_length = 1.0;
  as::AntiSwingOutput oa, ob;
  for (int k = 0; k < 40; ++k) {
    e.swing_in_plane = std::sin(0.1 * k);
    (void)a.step(e, oa);
    (void)b.step(e, ob);
    if (k == 25) {
      auto bad = e;
      bad.swing_in_plane = std::numeric_limits<double>::quiet_NaN();
      EXPECT_EQ(b.step(bad, ob), StepStatus::rejected_nonfinite);
      EXPECT_EQ(ob.trolley_action, 0.0);
      bad = e;
      bad.cable_length = std::numeric_limits<double>::infinity();
      EXPECT_EQ(b.step(bad, ob), StepStatus::rejected_nonfinite);
    }
  }
  EXPECT_EQ(oa.trolley_action, ob.trolley_action);
}

TEST(AntiSwing, BadParamsThrowNamingField) {
  auto expect_throw = [](const as::AntiSwingParams& p, const std::string& field) {
    try {
      as::AntiSwing anti_swing(p);
      FAIL() << "no throw for " << field;
    } catch (const crane::common::ConfigError& error) {
      EXPECT_NE(std::string(error.what()).find(field), std::string::npos) << error.what();
    }
  };
  as::AntiSwingParams p;
  p.normalized_delay = 0.0;
  expect_throw(p, "normalized_delay");
  p = {};
  p.max_cable_length = 0.05;
  expect_throw(p, "max_cable_length");
  p = {};
  p.delay_gain = std::numeric_limits<double>::infinity();
  expect_throw(p, "delay_gain");
  p = {};
  p.sample_period = 0.0;
  expect_throw(p, "sample_period");
  p = {};
  p.kind = static_cast<as::AntiSwingKind>(9);
  expect_throw(p, "kind");
  p = {};
  p.short_cable.enabled = true;
  p.short_cable.full_gain_length = p.short_cable.short_length;
  expect_throw(p, "short_cable.full_gain_length");
  p = {};
  p.short_cable.enabled = true;
  p.short_cable.short_length = 0.0;
  expect_throw(p, "short_cable.short_length");
  p = {};
  p.short_cable.enabled = true;
  p.short_cable.gain = std::nan("");
  expect_throw(p, "short_cable.delay_gain");
  p = {};
  p.short_cable.short_length = 0.0;  // disabled: not checked
  EXPECT_NO_THROW(as::AntiSwing{p});
}

// K_del at short cables (ShortCableGain): gain at and below short_length, delay_gain at and above
// full_gain_length, linear between, on both axes; disabled, delay_gain at every length. Both actions
// on a constant swing of 0.01 rad, read after the delay.
TEST(AntiSwing, TheShortCableGainFollowsTheCableLength) {
  const auto actions = [](const as::AntiSwingParams& params, double cable_length) {
    as::AntiSwing law(params);
    CraneStateEstimate e;
    e.swing_in_plane = 0.01;
    e.swing_out_of_plane = 0.01;
    e.cable_length = cable_length;
    as::AntiSwingOutput out;
    for (int k = 0; k < 400; ++k) (void)law.step(e, out);
    return std::pair{out.trolley_action, out.slew_action};
  };
  as::AntiSwingParams p;
  p.delay_gain = -90.0;
  p.short_cable = {true, 0.25, 0.4, -75.0};
  const struct {
    double L, gain;
  } cases[] = {{0.15, -75.0}, {0.25, -75.0}, {0.3, -80.0}, {0.325, -82.5}, {0.4, -90.0}, {1.0, -90.0}};
  for (const auto& c : cases) {
    const auto [trolley, slew] = actions(p, c.L);
    EXPECT_NEAR(trolley, c.gain * 0.01, 1e-12) << "L = " << c.L;
    EXPECT_NEAR(slew, c.gain * 0.01, 1e-12) << "L = " << c.L;
  }
  p.short_cable.enabled = false;
  EXPECT_NEAR(actions(p, 0.2).first, -0.9, 1e-12);
  EXPECT_NEAR(actions(p, 0.2).second, -0.9, 1e-12);
}
