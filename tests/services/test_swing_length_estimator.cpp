// The online equivalent-pendulum estimator (services/adaptation/swing_length_estimator.hpp) on
// swing simulated here by an independent integrator: RK4 at 1 ms of the linear pendulum
//   (a L + c) s'' + 2 a L' s' + g s = drive
// with drive x'' in plane and -x gamma'' (tower) or -y'' (overhead) out of plane, sampled at 100 Hz
// through encoders that quantize (the lab crane's 0.26 mrad swing count, 0.01 mm trolley, 0.1 mrad
// slew).
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <vector>

#include "crane/adaptation/swing_length_estimator.hpp"
#include "crane/common/crane_parameters.hpp"
#include "crane/common/validation.hpp"

namespace {

using crane::adaptation::SwingLengthEstimate;
using crane::adaptation::SwingLengthEstimator;
using crane::adaptation::SwingLengthInput;
using crane::adaptation::SwingLengthParams;
using crane::common::CraneKind;

constexpr double kGravity = 9.8;
// [rad] one count of the lab crane's swing encoder: 6000 lines read in quadrature.
constexpr double kSwingCount = 2.0 * std::numbers::pi / 24000.0;

struct Pendulum {
  double scale{1.0};   // a of the truth
  double offset{0.0};  // c [m]
};

// Piecewise-constant acceleration: +amplitude on [start, start + width), -amplitude on
// [start + width + gap, start + 2 width + gap): a move from rest to rest.
struct Pulse {
  double start, width, gap, amplitude;
  [[nodiscard]] double at(double t) const {
    if (t >= start && t < start + width) return amplitude;
    if (t >= start + width + gap && t < start + 2.0 * width + gap) return -amplitude;
    return 0.0;
  }
};

struct Motion {
  std::vector<Pulse> trolley;  // x''
  std::vector<Pulse> second;   // gamma'' [rad/s^2] or y'' [m/s^2]
  double x0{0.5};              // [m]
  std::function<double(double)> length = [](double) { return 1.0; };
  std::function<double(double)> length_rate = [](double) { return 0.0; };
  bool brakes_engaged{false};
};

double sum_at(const std::vector<Pulse>& pulses, double t) {
  double a = 0.0;
  for (const Pulse& p : pulses) a += p.at(t);
  return a;
}

double quantize(double v, double step) { return step * std::round(v / step); }

// Simulates `duration` s of `motion` on `truth` and feeds the estimator every 10 ms; returns the
// last estimate.
SwingLengthEstimate run(SwingLengthEstimator& estimator, const Motion& motion, const Pendulum& truth, double duration,
                        CraneKind drive) {
  // state: x, x', q, q' (q: gamma or y), phi, phi', theta, theta'
  std::array<double, 8> s{motion.x0, 0, 0, 0, 0, 0, 0, 0};
  const auto derivative = [&](double t, const std::array<double, 8>& z) {
    const double xdd = sum_at(motion.trolley, t);
    const double qdd = sum_at(motion.second, t);
    const double l = motion.length(t);
    const double ld = motion.length_rate(t);
    const double le = truth.scale * l + truth.offset;
    const double out_drive = drive == CraneKind::tower ? -z[0] * qdd : drive == CraneKind::overhead ? -qdd : 0.0;
    std::array<double, 8> d{};
    d[0] = z[1];
    d[1] = xdd;
    d[2] = z[3];
    d[3] = qdd;
    d[4] = z[5];
    d[5] = (xdd - kGravity * z[4] - 2.0 * truth.scale * ld * z[5]) / le;
    d[6] = z[7];
    d[7] = (out_drive - kGravity * z[6] - 2.0 * truth.scale * ld * z[7]) / le;
    return d;
  };
  const double h = 1e-3;
  SwingLengthEstimate out;
  const int steps = static_cast<int>(std::lround(duration / h));
  for (int k = 0; k <= steps; ++k) {
    const double t = k * h;
    if (k % 10 == 0) {
      SwingLengthInput in;
      in.trolley_position = quantize(s[0], 1e-5);
      in.second_axis = quantize(s[2], 1e-4);
      in.swing_in_plane = quantize(s[4], kSwingCount);
      in.swing_out_of_plane = quantize(s[6], kSwingCount);
      in.cable_length = quantize(motion.length(t), 1e-4);
      in.brakes_engaged = motion.brakes_engaged;
      estimator.step(in, out);
    }
    auto add = [](const std::array<double, 8>& a, const std::array<double, 8>& b, double f) {
      std::array<double, 8> r{};
      for (std::size_t i = 0; i < 8; ++i) r[i] = a[i] + f * b[i];
      return r;
    };
    // Accelerations are constant over each 1 ms step (the pulses' edges lie on the grid): the
    // pulses are sampled at the step's middle.
    const double tm = t + 0.5 * h;
    const auto k1 = derivative(tm, s);
    const auto k2 = derivative(tm, add(s, k1, 0.5 * h));
    const auto k3 = derivative(tm, add(s, k2, 0.5 * h));
    const auto k4 = derivative(tm, add(s, k3, h));
    for (std::size_t i = 0; i < 8; ++i) s[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
  }
  return out;
}

SwingLengthParams params(CraneKind kind) {
  SwingLengthParams p;
  p.enabled = true;
  p.crane_kind = kind;
  p.crane.gravity = kGravity;
  return p;
}

// Two trolley moves out and back (0.3 m/s^2 for 1 s each way), then 6 s of free swing.
Motion trolley_moves() {
  Motion m;
  m.trolley = {{1.0, 1.0, 0.5, 0.3}, {8.0, 1.0, 0.5, -0.3}};
  return m;
}

TEST(SwingLengthEstimator, AtOneCableLengthFindsTheOffsetAndHoldsTheScale) {
  // The corners' longer and shorter pendulums: the hoist says 1.0 m, the pendulum is 1.2 or 0.8 m.
  // Each crane kind's own model rows (the tower's and the overhead crane's are L_e times an affine
  // function of it, the gantry's affine itself: the normalization must serve both).
  for (const CraneKind kind : {CraneKind::tower, CraneKind::gantry, CraneKind::overhead}) {
    for (const double offset : {0.2, -0.2}) {
      SwingLengthEstimator estimator(params(kind));
      const SwingLengthEstimate e = run(estimator, trolley_moves(), {1.0, offset}, 20.0, kind);
      const auto& s = estimator.solution();
      std::printf("%s: c = %.4f m (truth %.1f), 2 sigma %.4f m, rows %llu, residual %.2e m/s^2\n",
                  crane::common::to_string(kind), e.offset, offset, e.length_bound,
                  static_cast<unsigned long long>(s.rows), s.residual_rms);
      ASSERT_TRUE(e.confident) << crane::common::to_string(kind);
      EXPECT_FALSE(s.scale_solved);  // one length: a L and c are one number
      EXPECT_EQ(e.scale, 1.0);       // held
      EXPECT_NEAR(e.offset, offset, 0.01) << crane::common::to_string(kind);
      EXPECT_LE(e.length_bound, 0.02);
      EXPECT_GT(e.length_bound, 0.0);
    }
  }
}

TEST(SwingLengthEstimator, HoistingAcrossLengthsSeparatesTheScaleFromTheOffset) {
  // The lab crane's hook on rigging: 0.995 L + 0.257 m (swing_calibration.hpp); here 1.1 L + 0.1 m.
  Motion m;
  m.trolley = {{1.0, 1.0, 0.5, 0.3}, {6.0, 1.0, 0.5, -0.3}, {11.0, 1.0, 0.5, 0.3}, {16.0, 1.0, 0.5, -0.3}};
  // The hoist pays out from 0.6 m to 1.6 m over 20 s (a cosine ramp).
  m.length = [](double t) { return 1.1 - 0.5 * std::cos(std::numbers::pi * std::min(t, 20.0) / 20.0); };
  m.length_rate = [](double t) {
    return t < 20.0 ? 0.5 * std::numbers::pi / 20.0 * std::sin(std::numbers::pi * t / 20.0) : 0.0;
  };
  SwingLengthEstimator estimator(params(CraneKind::tower));
  const SwingLengthEstimate e = run(estimator, m, {1.1, 0.1}, 24.0, CraneKind::tower);
  const auto& s = estimator.solution();
  std::printf("a = %.4f (2 sigma %.4f), c = %.4f m (2 sigma %.4f); solved a = %.4f (sigma %.4f), c = %.4f (sigma %.4f)\n",
              e.scale, e.scale_bound, e.offset, e.length_bound, s.scale, s.scale_deviation, s.offset,
              s.offset_deviation);
  ASSERT_TRUE(e.confident);
  EXPECT_TRUE(s.scale_solved);
  EXPECT_NEAR(e.scale, 1.1, 0.03);
  EXPECT_NEAR(e.offset, 0.1, 0.03);
}

TEST(SwingLengthEstimator, TheSlewAloneDrivesTheOutOfPlaneRowsOfATower) {
  Motion m;
  m.x0 = 0.6;
  m.second = {{1.0, 1.0, 0.5, 0.4}, {8.0, 1.0, 0.5, -0.4}};  // gamma'' [rad/s^2]: 0.24 m/s^2 at the trolley
  SwingLengthEstimator tower(params(CraneKind::tower));
  const SwingLengthEstimate e = run(tower, m, {1.0, -0.2}, 20.0, CraneKind::tower);
  ASSERT_TRUE(e.confident);
  EXPECT_NEAR(e.offset, -0.2, 0.01);
  // A gantry crane has no out-of-plane drive: the same swing is not taken as rows.
  SwingLengthEstimator gantry(params(CraneKind::gantry));
  const SwingLengthEstimate none = run(gantry, m, {1.0, -0.2}, 20.0, CraneKind::tower);
  EXPECT_EQ(gantry.solution().rows, 0U);
  EXPECT_FALSE(none.confident);
  EXPECT_EQ(none.offset, 0.0);
}

TEST(SwingLengthEstimator, TheBridgeDrivesTheOutOfPlaneRowsOfAnOverheadCrane) {
  Motion m;
  m.second = {{1.0, 1.0, 0.5, 0.3}, {8.0, 1.0, 0.5, -0.3}};  // y'' [m/s^2]
  SwingLengthEstimator estimator(params(CraneKind::overhead));
  const SwingLengthEstimate e = run(estimator, m, {1.0, 0.15}, 20.0, CraneKind::overhead);
  ASSERT_TRUE(e.confident);
  EXPECT_NEAR(e.offset, 0.15, 0.01);
  // Read as a tower's slew (x gamma''), the same record is a different drive: not this pendulum.
  SwingLengthEstimator wrong(params(CraneKind::tower));
  const SwingLengthEstimate w = run(wrong, m, {1.0, 0.15}, 20.0, CraneKind::overhead);
  EXPECT_FALSE(w.confident && std::abs(w.offset - 0.15) < 0.01);
}

TEST(SwingLengthEstimator, NoRowsAtRestWithTheBrakesOnOrDisabled) {
  Motion still;  // no drive, no swing: every row below min_swing
  SwingLengthEstimator rest(params(CraneKind::tower));
  (void)run(rest, still, {1.0, 0.2}, 5.0, CraneKind::tower);
  EXPECT_EQ(rest.solution().rows, 0U);

  Motion braked = trolley_moves();
  braked.brakes_engaged = true;
  SwingLengthEstimator held(params(CraneKind::tower));
  const SwingLengthEstimate b = run(held, braked, {1.0, 0.2}, 20.0, CraneKind::tower);
  EXPECT_EQ(held.solution().rows, 0U);
  EXPECT_FALSE(b.confident);

  SwingLengthParams off = params(CraneKind::tower);
  off.enabled = false;
  SwingLengthEstimator disabled(off);
  const SwingLengthEstimate d = run(disabled, trolley_moves(), {1.0, 0.2}, 20.0, CraneKind::tower);
  EXPECT_FALSE(d.confident);
  EXPECT_EQ(d.scale, 1.0);
  EXPECT_EQ(d.offset, 0.0);
  EXPECT_EQ(disabled.solution().rows, 0U);
}

TEST(SwingLengthEstimator, ANonFiniteSampleIsSkippedAndTheEstimateKept) {
  SwingLengthEstimator estimator(params(CraneKind::tower));
  const SwingLengthEstimate learnt = run(estimator, trolley_moves(), {1.0, 0.2}, 20.0, CraneKind::tower);
  ASSERT_TRUE(learnt.confident);
  const auto rows = estimator.solution().rows;
  SwingLengthEstimate after;
  for (const double bad : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
    SwingLengthInput in;
    in.swing_in_plane = bad;
    in.brakes_engaged = false;
    estimator.step(in, after);
    EXPECT_EQ(after.offset, learnt.offset);
    SwingLengthInput zero_cable;
    zero_cable.cable_length = 0.0;
    zero_cable.brakes_engaged = false;
    estimator.step(zero_cable, after);
    EXPECT_EQ(after.offset, learnt.offset);
  }
  EXPECT_EQ(estimator.solution().rows, rows);
}

TEST(SwingLengthEstimator, InvalidParamsNameTheField) {
  SwingLengthParams p = params(CraneKind::tower);
  p.length_bound = 0.0;
  try {
    SwingLengthEstimator e(p);
    FAIL() << "accepted length_bound 0";
  } catch (const crane::common::ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("state_estimator.swing_length.length_bound"), std::string::npos)
        << error.what();
  }
  p = params(CraneKind::tower);
  p.filter_cutoff = 60.0;  // above 0.45 / T
  EXPECT_THROW(SwingLengthEstimator{p}, crane::common::ConfigError);
}

}  // namespace
