// Gain-scheduling controller, section 3.2 of Omar 2003 (see gain_schedule.hpp for the equations).
//
// Derivation used by the expected values (tower convention, trolley; the slew is the same with
// b = K_mg/J, f = m_r g x/J, rho = -x, J = 1 + M_r x^2):
//   closed loop  (s^2 + k K_xd s + k)(L s^2 + g) - s^2 (k K_phi - m_t g) - k K_phid s^3 = 0, k = K K_mx,
//   desired      (s + a)^2 (s^2 + 2 zeta w s + w^2), a = 2 sqrt(g/L)/pi (3.21), zeta = 1/sqrt(2).
// Partial, L = 1, g = 9.8: w0 = 3.1305, a = 1.99296; a w^2 + zeta (a^2 - w0^2) w - w0^2 a = 0 gives
//   w = 4.3307; k = a^2 w^2/w0^2 = 7.601 -> K = 3.80 (4.18); K_xd = (2a + 2 zeta w)/k = 1.330;
//   K_phi = (k + g(1 + m_t) - (a^2 + 4 a zeta w + w^2))/k = -3.9125 + 1.2893 m_t.
//   Scaling: a, w ~ 1/sqrt(L), k ~ 1/L, so K ~ 1/L, K_xd ~ sqrt(L), K_phi ~ L: (4.18) for all L.

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <limits>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "crane/common/validation.hpp"
#include "crane/gain_scheduling/gain_schedule.hpp"
#include "crane/gain_scheduling/gain_scheduling_controller.hpp"

namespace gs = crane::gain_scheduling;
using crane::common::ConfigError;
using crane::common::StepStatus;

namespace {

constexpr double kG = 9.8;
constexpr double kPi = std::numbers::pi;

// "Agrees to 3 significant digits": relative difference below half a unit of the 3rd digit.
void expect_3_digits(double actual, double expected, const std::string& what) {
  EXPECT_LE(std::abs(actual - expected), 5e-3 * std::abs(expected)) << what << ": " << actual << " vs " << expected;
}

// Closed-loop A matrix of the linear axis  q'' = b V + f psi, L psi'' + g psi = rho q''  with
// V = K(-K_x q - K_d q' + K_psi psi + K_psid psi'), state (q, q', psi, psi'). Built directly from
// the model equations, independent of the pole-placement formulas.
Eigen::Matrix4d closed_loop_matrix(const gs::GainSchedulingGains& k, double L, double b, double f, double rho) {
  // V = v . state
  const Eigen::RowVector4d v{-k.forward_gain * k.position_gain, -k.forward_gain * k.velocity_gain,
                             k.forward_gain * k.swing_gain, k.forward_gain * k.swing_rate_gain};
  Eigen::RowVector4d q_dd = b * v;
  q_dd(2) += f;
  Eigen::RowVector4d psi_dd = rho * q_dd / L;
  psi_dd(2) -= kG / L;
  Eigen::Matrix4d A = Eigen::Matrix4d::Zero();
  A(0, 1) = 1.0;
  A(1, Eigen::all) = q_dd;
  A(2, 3) = 1.0;
  A(3, Eigen::all) = psi_dd;
  return A;
}

// Every designed root (double -a, -zeta w +- j w sqrt(1 - zeta^2)) is an eigenvalue of A.
void expect_designed_poles(const Eigen::Matrix4d& A, const gs::GainSchedulingGains& k, double L) {
  const double a_expected = 2.0 * std::sqrt(kG / L) / kPi;  // 4/a = T (3.21)
  EXPECT_NEAR(k.trolley_pole, a_expected, 1e-12);
  const Eigen::Vector4cd eig = A.eigenvalues();
  const double w = k.natural_frequency;
  const double zeta = 1.0 / std::sqrt(2.0);
  const std::array<std::complex<double>, 4> expected{
      std::complex<double>{-a_expected, 0.0}, std::complex<double>{-a_expected, 0.0},
      std::complex<double>{-zeta * w, w * std::sqrt(1 - zeta * zeta)},
      std::complex<double>{-zeta * w, -w * std::sqrt(1 - zeta * zeta)}};
  std::array<bool, 4> used{};
  for (const auto& root : expected) {
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    for (int i = 0; i < 4; ++i) {
      const double d = std::abs(eig(i) - root);
      if (!used[static_cast<std::size_t>(i)] && d < best_distance) {
        best_distance = d;
        best = i;
      }
    }
    ASSERT_GE(best, 0);
    used[static_cast<std::size_t>(best)] = true;
    // The double root splits by ~sqrt(eps) in floating point.
    EXPECT_LT(best_distance, 1e-6 * (1.0 + std::abs(root))) << "root " << root << " eig " << eig(best);
  }
  // The complex pair has the designed damping ratio.
  for (int i = 0; i < 4; ++i) {
    if (std::abs(eig(i).imag()) > 1e-3) {
      EXPECT_NEAR(-eig(i).real() / std::abs(eig(i)), zeta, 1e-9);
      EXPECT_NEAR(std::abs(eig(i)), w, 1e-9 * w);
    }
  }
}

}  // namespace

// (4.18): K = 3.8/L, K_xd = 1.33 sqrt(L), K_phi = -L(3.9122 - 1.28925 m_t) for K_mx = 2 (ERRATA signs).
TEST(PartialStateGains, MatchEquation418OnGrid) {
  for (const double L : {0.5, 1.0, 2.0, 3.0, 5.0}) {
    for (const double m_t : {0.0, 0.09, 1.0, 2.5, 5.0}) {
      const auto k = gs::partial_state_gains(L, m_t, 2.0, std::nullopt);
      const std::string at = "L=" + std::to_string(L) + " m_t=" + std::to_string(m_t);
      expect_3_digits(k.forward_gain, 3.8 / L, "K " + at);
      expect_3_digits(k.velocity_gain, 1.33 * std::sqrt(L), "K_xd " + at);
      expect_3_digits(k.swing_gain, -L * (3.9122 - 1.28925 * m_t), "K_phi " + at);
      EXPECT_DOUBLE_EQ(k.position_gain, 1.0);
      EXPECT_DOUBLE_EQ(k.swing_rate_gain, 0.0);
      EXPECT_GT(k.natural_frequency, 0.0);
    }
  }
  // Worked value at L = 1 (header derivation): w = 4.3307 rad/s.
  EXPECT_NEAR(gs::partial_state_gains(1.0, 0.0, 2.0, std::nullopt).natural_frequency, 4.3307, 1e-3);
}

// A fixed K in the partial law leaves K_x free: k K_x = a^2 w^2/w0^2 is unchanged, so K_x = K_auto/K
// (steady-state error A(1 - 1/K_x), section 3.2); K_xd scales as 1/K, w is unchanged.
TEST(PartialStateGains, FixedForwardGainSolvesPositionGain) {
  const auto automatic = gs::partial_state_gains(1.0, 0.09, 2.0, std::nullopt);
  const auto fixed = gs::partial_state_gains(1.0, 0.09, 2.0, 2.0);
  EXPECT_DOUBLE_EQ(fixed.forward_gain, 2.0);
  EXPECT_NEAR(fixed.position_gain, automatic.forward_gain / 2.0, 1e-12);
  EXPECT_NEAR(fixed.velocity_gain, automatic.velocity_gain * automatic.forward_gain / 2.0, 1e-12);
  EXPECT_NEAR(fixed.natural_frequency, automatic.natural_frequency, 1e-12);
  expect_designed_poles(closed_loop_matrix(fixed, 1.0, 2.0, -0.09 * kG, 1.0), fixed, 1.0);
}

// (4.21), magnitudes and square roots restored by ERRATA, L = 1, m_t = 0.09, K_mx = 2. With the tower
// signs, K_phi < 0 and K_phid = 1.00354 - 1.9929/K - 0.93417/sqrt(K) (< 0 for K = 2, > 0 for K = 8).
// Closed form: w = pi sqrt(K K_mx)/2, K_xd = pi sqrt(L/g) + 4 zeta/(pi sqrt(K K_mx)).
TEST(FullStateGains, MatchEquation421) {
  for (const double K : {2.0, 4.0, 8.0}) {
    const auto k = gs::full_state_gains(1.0, 0.09, 2.0, K);
    const std::string at = "K=" + std::to_string(K);
    EXPECT_DOUBLE_EQ(k.forward_gain, K);
    EXPECT_DOUBLE_EQ(k.position_gain, 1.0);
    expect_3_digits(k.velocity_gain, 1.00354 + 0.63662 / std::sqrt(K), "K_xd " + at);
    expect_3_digits(k.swing_gain, -(1.4674 - 3.3551 / K + 6.261 / std::sqrt(K)), "K_phi " + at);
    expect_3_digits(k.swing_rate_gain, -(-1.00354 + 1.9929 / K + 0.93417 / std::sqrt(K)), "K_phid " + at);
    EXPECT_NEAR(k.natural_frequency, kPi * std::sqrt(2.0 * K) / 2.0, 1e-12);
  }
}

// Independent cross-check: eigenvalues of the closed-loop A matrix built from (2.28)-(2.31).
TEST(PolePlacement, ClosedLoopEigenvaluesAreTheDesignedPoles) {
  for (const double L : {0.5, 1.0, 3.0, 5.0}) {
    for (const double m_t : {0.0, 0.09, 5.0}) {
      const auto partial = gs::partial_state_gains(L, m_t, 2.0, std::nullopt);
      expect_designed_poles(closed_loop_matrix(partial, L, 2.0, -m_t * kG, 1.0), partial, L);
      for (const double K : {0.4, 2.0, 12.0}) {
        const auto full = gs::full_state_gains(L, m_t, 2.0, K);
        expect_designed_poles(closed_loop_matrix(full, L, 2.0, -m_t * kG, 1.0), full, L);
      }
    }
    const gs::SlewModel slew{0.28, 0.27, 1.14};
    for (const double x : {-0.5, 0.2, 0.9, 2.0}) {
      const double J = 1.0 + slew.trolley_inertia_ratio * x * x;
      const double b = slew.slew_drive_gain / J;
      const double f = slew.load_inertia_ratio * kG * x / J;
      const auto partial = gs::slew_partial_state_gains(L, x, slew, std::nullopt);
      expect_designed_poles(closed_loop_matrix(partial, L, b, f, -x), partial, L);
      const auto full = gs::slew_full_state_gains(L, x, slew, 2.0);
      expect_designed_poles(closed_loop_matrix(full, L, b, f, -x), full, L);
    }
  }
}

// (4.19), L = 1, K_mg = 1.14: K = 6.66 + 1.8 x^2, K_gd = 1.33, K_theta = 3.9122/x - 0.360989 x.
// Exact: K = k (1 + M_r x^2)/K_mg with k = 7.601 (the trolley's loop gain), so K = 6.6675 + 6.6675 M_r x^2;
// the printed 1.8 needs M_r = 0.27 and 0.360989 = 1.28925 m_r needs m_r = 0.28 (the text's
// "M_r = 0.28" swaps the two). K_gd = 1.33 for every x (printed as "K_xd").
// K_theta = 3.9125/x - 1.2893 m_r x/(1 + M_r x^2) = (4.19) + O(x^3).
TEST(SlewGains, AgreeWithSeries419AtSmallX) {
  const gs::SlewModel slew{0.28, 0.27, 1.14};
  for (const double x : {0.05, 0.1, 0.2, 0.3, 0.5}) {
    const auto k = gs::slew_partial_state_gains(1.0, x, slew, std::nullopt);
    const std::string at = "x=" + std::to_string(x);
    expect_3_digits(k.forward_gain, 6.66 + 1.8 * x * x, "K " + at);
    expect_3_digits(k.velocity_gain, 1.33, "K_gd " + at);
    expect_3_digits(k.swing_gain, 3.9122 / x - 0.360989 * x, "K_theta " + at);
  }
  // The series drops 1.2893 m_r M_r x^3: visible at large x.
  const auto far = gs::slew_partial_state_gains(1.0, 3.0, slew, std::nullopt);
  EXPECT_GT(std::abs(far.swing_gain - (3.9122 / 3.0 - 0.360989 * 3.0)), 0.1);
}

// Table 4.3 rows for K_gd (1.5416 + 0.075326 x^2, 1.384 + 0.05326 x^2, 1.27257 + 0.037663 x^2)
// follow exactly from K_gd = pi sqrt(L/g) + (4 zeta/pi) sqrt(J/(K K_mg)) with K_mg = 1.4 (not the
// 1.14 printed beside it) and M_r = 0.28 (x^2 coefficient = (4 zeta/pi) M_r /(2 sqrt(K K_mg))).
TEST(SlewGains, Table43VelocityGainsWithDriveGain1p4) {
  const gs::SlewModel slew{0.27, 0.28, 1.4};
  const std::array<std::array<double, 3>, 3> rows{{{2.0, 1.5416, 0.075326}, {4.0, 1.384, 0.05326},
                                                   {8.0, 1.27257, 0.037663}}};
  for (const auto& row : rows) {
    for (const double x : {0.05, 0.2}) {
      const auto k = gs::slew_full_state_gains(1.0, x, slew, row[0]);
      expect_3_digits(k.velocity_gain, row[1] + row[2] * x * x, "K_gd K=" + std::to_string(row[0]));
    }
  }
}

// Table 4.3, 1/x coefficients of K_theta and K_thetad (same K_mg = 1.4, m_r = 0.27, M_r = 0.28):
// K_theta: 4.6674 (we get 4.6774: one digit swapped in print), 4.1683, 3.59278;
// K_thetad: "01.2095" (garbled, 1.2095), 0.2665, -0.2529. Coefficient = lim x->0 x K.
TEST(SlewGains, Table43InverseXCoefficients) {
  const gs::SlewModel slew{0.27, 0.28, 1.4};
  const double x = 1e-4;
  const std::array<std::array<double, 3>, 3> rows{{{2.0, 4.6774, 1.2095}, {4.0, 4.1683, 0.2665},
                                                   {8.0, 3.59278, -0.2529}}};
  for (const auto& row : rows) {
    const auto k = gs::slew_full_state_gains(1.0, x, slew, row[0]);
    expect_3_digits(x * k.swing_gain, row[1], "K_theta K=" + std::to_string(row[0]));
    expect_3_digits(x * k.swing_rate_gain, row[2], "K_thetad K=" + std::to_string(row[0]));
  }
}

// Voltage-limit remedy: V(0) = K * distance <= 10 V  ->  K_max = 10/distance.
TEST(MaxForwardGain, KeepsInitialVoltageInRange) {
  EXPECT_DOUBLE_EQ(gs::max_forward_gain(0.5), 20.0);
  EXPECT_DOUBLE_EQ(gs::max_forward_gain(-2.0, 10.0), 5.0);
  EXPECT_DOUBLE_EQ(gs::max_forward_gain(0.75, 5.0), 5.0 / 0.75);
  // The controller's first voltage from rest with that K is exactly at the limit.
  gs::GainSchedulingParams p;
  p.kind = gs::FeedbackKind::full;
  p.trolley_forward_gain = gs::max_forward_gain(2.0);
  gs::GainSchedulingController controller(p);
  crane::common::CraneStateEstimate est;
  est.trolley_position = 0.3;
  crane::common::MotionReference ref;
  ref.trolley.position = 2.3;
  crane::common::DriveCommand cmd;
  ASSERT_EQ(controller.step(est, ref, cmd), StepStatus::ok);
  EXPECT_NEAR(cmd.trolley_voltage, 10.0, 1e-12);
  EXPECT_THROW((void)gs::max_forward_gain(0.0), ConfigError);
}

namespace {

struct StepResult {
  double settling_time{0.0};  // [s] last time |x - x_r| > 1 % of the step or |phi| > 0.5 deg
  double overshoot{0.0};      // [m] max(x - x_r)
  double max_voltage{0.0};    // [V]
  double position_settling_time{0.0};    // [s] 1 % band only
  double position_settling_time_2{0.0};  // [s] 2 % band only
  double swing_settling_time{0.0};       // [s] 0.5 deg band only
  double max_swing{0.0};                 // [rad]
};

// RK4 at 1 ms of the linear trolley model (2.28)-(2.29), tower convention, voltage held over each step,
// controller core in the loop; 0.5 m step from rest.
StepResult simulate_trolley_step(gs::FeedbackKind kind, double L, double m_t, double K = 2.0) {
  gs::GainSchedulingParams p;
  p.kind = kind;
  p.trolley_forward_gain = K;
  p.mass_ratio = m_t;
  p.slew_enabled = false;
  gs::GainSchedulingController controller(p);
  const double K_mx = p.trolley_drive_gain;
  const double step = 0.5;
  const double dt = 1e-3;
  const double T = 2.0 * kPi * std::sqrt(L / kG);
  using State = std::array<double, 4>;  // x, x', phi, phi'
  auto f = [&](const State& s, double V) {
    const double x_dd = K_mx * V - m_t * kG * s[2];  // (2.28)
    const double phi_dd = (x_dd - kG * s[2]) / L;     // (2.29)
    return State{s[1], x_dd, s[3], phi_dd};
  };
  State s{};
  crane::common::MotionReference ref;
  ref.trolley.position = step;
  crane::common::CraneStateEstimate est;
  est.cable_length = L;
  crane::common::DriveCommand cmd;
  StepResult result;
  const int n = static_cast<int>(std::lround(6.0 * T / dt));
  for (int i = 0; i < n; ++i) {
    const double t = i * dt;
    if (std::abs(s[0] - step) > 0.01 * step || std::abs(s[2]) > 0.5 * kPi / 180.0) {
      result.settling_time = t + dt;
    }
    if (std::abs(s[0] - step) > 0.01 * step) {
      result.position_settling_time = t + dt;
    }
    if (std::abs(s[0] - step) > 0.02 * step) {
      result.position_settling_time_2 = t + dt;
    }
    if (std::abs(s[2]) > 0.5 * kPi / 180.0) {
      result.swing_settling_time = t + dt;
    }
    result.max_swing = std::max(result.max_swing, std::abs(s[2]));
    result.overshoot = std::max(result.overshoot, s[0] - step);
    est.trolley_position = s[0];
    est.trolley_velocity = s[1];
    est.swing_in_plane = s[2];
    est.swing_in_plane_rate = s[3];
    EXPECT_EQ(controller.step(est, ref, cmd), StepStatus::ok);
    const double V = cmd.trolley_voltage;
    result.max_voltage = std::max(result.max_voltage, std::abs(V));
    auto add = [](const State& a, const State& b, double h) {
      return State{a[0] + h * b[0], a[1] + h * b[1], a[2] + h * b[2], a[3] + h * b[3]};
    };
    const State k1 = f(s, V);
    const State k2 = f(add(s, k1, dt / 2), V);
    const State k3 = f(add(s, k2, dt / 2), V);
    const State k4 = f(add(s, k3, dt), V);
    for (std::size_t j = 0; j < 4; ++j) {
      s[j] += dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j]);
    }
  }
  EXPECT_NEAR(s[0], step, 1e-4);  // K_x = 1: zero steady-state error
  return result;
}

}  // namespace

// Settling-time criterion (3.21): "settling time = one swing period T = 2 pi sqrt(L/g)" with 4/a = T.
// 4/a is the 2 % rule of a SINGLE real pole; (3.20) puts a DOUBLE pole at -a, whose step response
// 1 - (1 + a t) e^{-a t} reaches 1 % only at a t = 6.64 (1.66 T) and 2 % at a t = 5.83 (1.46 T); with
// the load pair and the transmission zeros +-j sqrt(g/L) the measured 1 % settling is 1.86-1.92 T and
// the 2 % settling 1.66-1.73 T, for every L (the design is scale invariant in t/T). The gains match
// (4.18) to 3 digits, so this is a property of the published design, not of this code: a 1.5 T bound
// at 1 % is NOT met; we assert 2 T at 1 % and 1.75 T at 2 %, no overshoot above 1 %.
TEST(ClosedLoop, PartialStepSettlesInAboutOneSwingPeriod) {
  for (const double L : {0.5, 1.0, 3.0}) {
    const double T = 2.0 * kPi * std::sqrt(L / kG);
    const auto r = simulate_trolley_step(gs::FeedbackKind::partial, L, 0.09);
    EXPECT_LT(r.settling_time, 2.0 * T) << "L=" << L << " T=" << T;
    EXPECT_LT(r.position_settling_time_2, 1.75 * T) << "L=" << L << " T=" << T;
    EXPECT_LT(r.overshoot, 0.01 * 0.5) << "L=" << L;
    EXPECT_LE(r.max_voltage, 10.0);
    std::printf("partial L=%.1f: settle/T %.3f (x 1%%: %.3f, x 2%%: %.3f, swing: %.3f), overshoot %.2e m, "
                "max swing %.2f deg, max V %.2f\n", L, r.settling_time / T, r.position_settling_time / T,
                r.position_settling_time_2 / T, r.swing_settling_time / T, r.overshoot, r.max_swing * 180 / kPi,
                r.max_voltage);
  }
}

TEST(ClosedLoop, FullStepSettlesInAboutOneSwingPeriod) {
  for (const double L : {0.5, 1.0, 3.0}) {
    const double T = 2.0 * kPi * std::sqrt(L / kG);
    const auto r = simulate_trolley_step(gs::FeedbackKind::full, L, 0.09, 2.0);
    std::printf("full K=2 L=%.1f: settle/T %.3f (x 1%%: %.3f, x 2%%: %.3f, swing: %.3f), overshoot %.2e m, "
                "max swing %.2f deg, max V %.2f\n", L, r.settling_time / T, r.position_settling_time / T,
                r.position_settling_time_2 / T, r.swing_settling_time / T, r.overshoot, r.max_swing * 180 / kPi,
                r.max_voltage);
    EXPECT_LT(r.settling_time, 2.0 * T) << "L=" << L << " T=" << T;
    EXPECT_LT(r.position_settling_time_2, 1.75 * T) << "L=" << L << " T=" << T;
    EXPECT_LT(r.overshoot, 0.01 * 0.5) << "L=" << L;
  }
}

// Gains follow the measured cable length every step (scheduling), no state kept between steps.
TEST(Controller, ReschedulesFromMeasuredCableLengthAndTrolleyPosition) {
  gs::GainSchedulingController controller(gs::GainSchedulingParams{});
  crane::common::CraneStateEstimate est;
  crane::common::MotionReference ref;
  crane::common::DriveCommand cmd;
  for (const double L : {0.5, 2.0, 4.0}) {
    est.cable_length = L;
    est.trolley_position = 0.9;
    ASSERT_EQ(controller.step(est, ref, cmd), StepStatus::ok);
    const auto expected = gs::partial_state_gains(L, 0.09, 2.0, std::nullopt);
    EXPECT_NEAR(controller.trolley_gains().forward_gain, expected.forward_gain, 1e-12);
    EXPECT_NEAR(controller.trolley_gains().swing_gain, expected.swing_gain, 1e-12);
    const auto slew = gs::slew_partial_state_gains(L, 0.9, gs::SlewModel{}, std::nullopt);
    EXPECT_NEAR(controller.slew_gains().forward_gain, slew.forward_gain, 1e-12);
    EXPECT_NEAR(controller.slew_gains().swing_gain, slew.swing_gain, 1e-12);
  }
  // Sign check, tower convention: a positive in-plane swing phi with K_phi < 0 pushes V_x negative.
  est = {};
  est.swing_in_plane = 0.1;
  ASSERT_EQ(controller.step(est, ref, cmd), StepStatus::ok);
  EXPECT_LT(cmd.trolley_voltage, 0.0);
  // Voltage clamp.
  ref.trolley.position = 100.0;
  est = {};
  ASSERT_EQ(controller.step(est, ref, cmd), StepStatus::ok);
  EXPECT_DOUBLE_EQ(cmd.trolley_voltage, 10.0);
}

TEST(Controller, RejectsNonFiniteInputWithZeroOutput) {
  gs::GainSchedulingController controller(gs::GainSchedulingParams{});
  crane::common::MotionReference ref;
  ref.trolley.position = 1.0;
  ref.slew.position = 1.0;
  crane::common::DriveCommand cmd{3.0, 4.0, 0.1};
  crane::common::CraneStateEstimate est;
  est.swing_in_plane = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(controller.step(est, ref, cmd), StepStatus::rejected_nonfinite);
  EXPECT_EQ(cmd.trolley_voltage, 0.0);
  EXPECT_EQ(cmd.slew_voltage, 0.0);
  EXPECT_EQ(cmd.hoist_speed, 0.0);
  est = {};
  est.cable_length = std::numeric_limits<double>::infinity();
  cmd = {3.0, 4.0, 0.1};
  EXPECT_EQ(controller.step(est, ref, cmd), StepStatus::rejected_nonfinite);
  EXPECT_EQ(cmd.trolley_voltage, 0.0);
  est = {};
  ref.slew.position = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(controller.step(est, ref, cmd), StepStatus::rejected_nonfinite);
  EXPECT_EQ(cmd.slew_voltage, 0.0);
}

namespace {
template <typename F>
void expect_config_error(F&& f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "no ConfigError, expected one naming " << needle;
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}
}  // namespace

TEST(Validation, BadParametersThrowNamingTheField) {
  expect_config_error([] { (void)gs::partial_state_gains(0.0, 0.09, 2.0, std::nullopt); },
                      "cable_length = 0 is out of range: must be > 0");
  expect_config_error([] { (void)gs::partial_state_gains(std::nan(""), 0.09, 2.0, std::nullopt); },
                      "cable_length");
  expect_config_error([] { (void)gs::partial_state_gains(1.0, -0.1, 2.0, std::nullopt); },
                      "mass_ratio = -0.1");
  expect_config_error([] { (void)gs::partial_state_gains(1.0, 0.1, 2.0, -1.0); }, "forward_gain = -1");
  expect_config_error([] { (void)gs::full_state_gains(1.0, 0.1, 0.0, 2.0); }, "trolley_drive_gain = 0");
  expect_config_error([] { (void)gs::slew_partial_state_gains(1.0, 0.0, gs::SlewModel{}, std::nullopt); },
                      "trolley_position = 0 is out of range: must be != 0");
  expect_config_error(
      [] {
        gs::GainSchedulingParams p;
        p.voltage_limit = -1.0;
        gs::GainSchedulingController c(p);
      },
      "gain_scheduling.voltage_limit = -1");
  expect_config_error(
      [] {
        gs::GainSchedulingParams p;
        p.min_cable_length = 0.0;
        gs::GainSchedulingController c(p);
      },
      "gain_scheduling.min_cable_length = 0");
  expect_config_error(
      [] {
        gs::GainSchedulingParams p;
        p.damping_ratio = 1.5;
        gs::GainSchedulingController c(p);
      },
      "gain_scheduling.damping_ratio = 1.5");
}
