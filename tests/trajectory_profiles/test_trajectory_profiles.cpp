// Input-shaped and time-optimal swing-free profiles.
//
// Swing model (tower convention, linearized): L phi'' + g phi = u with u = x'' for the trolley and
// u = -x gamma'' for the slew (theta), w = sqrt(g/L), g = 9.8. The pendulum is simulated with the
// exact zero-order-hold discretization at 1 ms, the input over each step being the step-averaged
// acceleration (v(t + dt) - v(t))/dt, so the simulation only uses the profile's velocity samples.
// The time-optimal solver is cross-checked against an independent linear program (GLPK) on a 5 ms
// grid: acceleration samples as variables, |u| <= a_max, |v_k| <= v_max, final position, velocity
// and swing (phi, phi') exactly as required, bisection on the horizon N for feasibility.

#include <glpk.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/trajectory_planner/input_shaper.hpp"
#include "crane/trajectory_planner/shaped_profile.hpp"
#include "crane/trajectory_planner/time_optimal_profile.hpp"
#include "crane/trajectory_planner/trapezoid_profile.hpp"

namespace tp = crane::trajectory_planner;

namespace {

constexpr double kGravity = 9.8;
constexpr double kCable = 1.0;                          // [m] (3.53)
const double kW = std::sqrt(kGravity / kCable);         // 3.1305 rad/s
const double kPeriod = 2.0 * std::numbers::pi / kW;     // 2.0071 s
constexpr tp::AxisLimits kTrolleyLimits{0.4982, 0.9929};  // (3.54)
constexpr tp::AxisLimits kSlewLimits{1.0435, 2.0796};     // (3.55)
constexpr double kTrolleyStart = 0.25, kTrolleyTarget = 1.0;  // [m] (3.54)
constexpr double kSlewTarget = std::numbers::pi / 2.0;        // [rad] (3.55)
constexpr double kSlewRadius = 0.9;                           // [m] trolley at x = 0.9 m
constexpr double kSimStep = 1e-3;                             // [s]
constexpr double kLpStep = 5e-3;                              // [s]

tp::ShaperParams shaper(tp::ShaperKind kind, double zeta = 0.0, double tolerance = 0.05) {
  tp::ShaperParams p;
  p.kind = kind;
  p.natural_frequency = kW;
  p.damping_ratio = zeta;
  p.vibration_tolerance = tolerance;
  return p;
}

/// Residual swing amplitude sqrt(phi^2 + (phi'/w)^2) [rad] after the profile, for the pendulum
/// L phi'' + g phi = gain * x'' of frequency `w` (cable L = g/w^2).
double residual_swing(const tp::AxisProfile& profile, double w, double gain = 1.0) {
  const double length = kGravity / (w * w);
  const double c = std::cos(w * kSimStep), s = std::sin(w * kSimStep);
  double phi = 0.0, rate = 0.0;
  const int steps = static_cast<int>(std::ceil(profile.duration() / kSimStep)) + 2;
  double v_prev = profile.sample(0.0).velocity;
  for (int k = 0; k < steps; ++k) {
    const double v_next = profile.sample((k + 1) * kSimStep).velocity;
    const double u = gain * (v_next - v_prev) / kSimStep / length;  // phi'' = -w^2 phi + u/L
    v_prev = v_next;
    // Exact ZOH: phi+ = c phi + s/w rate + u/w^2 (1 - c), rate+ = -w s phi + c rate + u/w s.
    const double next_phi = c * phi + s / w * rate + u / (w * w) * (1.0 - c);
    const double next_rate = -w * s * phi + c * rate + u / w * s;
    phi = next_phi;
    rate = next_rate;
  }
  return std::hypot(phi, rate / w);
}

/// Checks |v| <= v_max, |a| <= a_max, continuity of position and velocity, arrival at rest.
void expect_admissible(const tp::AxisProfile& profile, double start, double target,
                       const tp::AxisLimits& limits) {
  const double dt = 1e-4;
  const int steps = static_cast<int>(profile.duration() / dt) + 10;
  crane::common::AxisReference prev = profile.sample(0.0);
  EXPECT_DOUBLE_EQ(prev.position, start);
  double worst_jump_position = 0.0, worst_jump_velocity = 0.0;
  for (int k = 1; k <= steps; ++k) {
    const crane::common::AxisReference r = profile.sample(k * dt);
    ASSERT_LE(std::abs(r.velocity), limits.max_velocity * (1.0 + 1e-12)) << "t = " << k * dt;
    ASSERT_LE(std::abs(r.acceleration), limits.max_acceleration * (1.0 + 1e-12)) << "t = " << k * dt;
    // Continuity: |dx| <= v_max dt, |dv| <= a_max dt (plus rounding).
    worst_jump_position = std::max(worst_jump_position, std::abs(r.position - prev.position) / (limits.max_velocity * dt));
    worst_jump_velocity = std::max(worst_jump_velocity, std::abs(r.velocity - prev.velocity) / (limits.max_acceleration * dt));
    prev = r;
  }
  EXPECT_LE(worst_jump_position, 1.0 + 1e-6);
  EXPECT_LE(worst_jump_velocity, 1.0 + 1e-6);
  const crane::common::AxisReference end = profile.sample(profile.duration());
  EXPECT_NEAR(end.position, target, 1e-12);
  EXPECT_EQ(end.velocity, 0.0);
  // Just before the end the profile is already (nearly) there: no jump at t_f.
  const crane::common::AxisReference before = profile.sample(profile.duration() - 1e-7);
  EXPECT_NEAR(before.position, target, 1e-9);
  EXPECT_NEAR(before.velocity, 0.0, limits.max_acceleration * 1e-7 * 1.01);
}

// ---- Independent LP: minimum horizon N dt for a swing-free rest-to-rest move ----
bool lp_feasible(int n, double dt, double distance, const tp::AxisLimits& limits, double w) {
  glp_prob* lp = glp_create_prob();
  glp_set_obj_dir(lp, GLP_MIN);  // feasibility: zero objective
  // Columns: u_0..u_{n-1} (acceleration), v_1..v_{n-1} (velocity at the grid points).
  glp_add_cols(lp, 2 * n - 1);
  for (int k = 0; k < n; ++k) glp_set_col_bnds(lp, k + 1, GLP_DB, -limits.max_acceleration, limits.max_acceleration);
  for (int k = 1; k < n; ++k) glp_set_col_bnds(lp, n + k, GLP_DB, -limits.max_velocity, limits.max_velocity);
  // Rows 1..n: v_{k+1} - v_k - dt u_k = 0 with v_0 = v_n = 0; n+1: position; n+2, n+3: swing.
  glp_add_rows(lp, n + 3);
  std::vector<int> ia{0}, ja{0};
  std::vector<double> ar{0.0};
  auto put = [&](int r, int col, double value) { ia.push_back(r); ja.push_back(col); ar.push_back(value); };
  for (int k = 0; k < n; ++k) {
    glp_set_row_bnds(lp, k + 1, GLP_FX, 0.0, 0.0);
    put(k + 1, k + 1, -dt);
    if (k + 1 < n) put(k + 1, n + k + 1, 1.0);
    if (k >= 1) put(k + 1, n + k, -1.0);
  }
  glp_set_row_bnds(lp, n + 1, GLP_FX, distance, distance);
  glp_set_row_bnds(lp, n + 2, GLP_FX, 0.0, 0.0);
  glp_set_row_bnds(lp, n + 3, GLP_FX, 0.0, 0.0);
  // Final swing (phi_n, phi'_n/w) = sum_k M^(n-1-k) b u_k, M the rotation by w dt, b the ZOH
  // response to a unit input (L = 1 scaling is irrelevant for = 0).
  const double c = std::cos(w * dt), s = std::sin(w * dt);
  double p = (1.0 - c) / (w * w), q = s / w;  // (phi, phi') after one step of u = 1
  for (int k = n - 1; k >= 0; --k) {
    put(n + 1, k + 1, dt * dt * (n - k - 0.5));  // x_n = sum u_k dt^2 (n - k - 1/2)
    put(n + 2, k + 1, p * w * w);
    put(n + 3, k + 1, q * w);
    const double next_p = c * p + s / w * q;
    const double next_q = -w * s * p + c * q;
    p = next_p;
    q = next_q;
  }
  glp_load_matrix(lp, static_cast<int>(ia.size()) - 1, ia.data(), ja.data(), ar.data());
  glp_smcp parm;
  glp_init_smcp(&parm);
  parm.msg_lev = GLP_MSG_OFF;
  parm.presolve = GLP_ON;
  const int rc = glp_simplex(lp, &parm);
  const bool ok = rc == 0 && glp_get_status(lp) == GLP_OPT;
  glp_delete_prob(lp);
  return ok;
}

/// Smallest N dt [s] with a feasible LP (bisection on N).
double lp_minimum_duration(double distance, const tp::AxisLimits& limits, double w, double dt = kLpStep) {
  int hi = 64;
  while (!lp_feasible(hi, dt, distance, limits, w)) hi *= 2;
  int lo = hi / 2;  // infeasible or trivially small
  if (lo < 2) lo = 1;
  while (hi - lo > 1) {
    const int mid = (lo + hi) / 2;
    if (lp_feasible(mid, dt, distance, limits, w)) hi = mid; else lo = mid;
  }
  return hi * dt;
}

}  // namespace

// ---------------------------------------------------------------- shapers
TEST(InputShaper, ZvAndZvdMatchClosedFormsAndSumToOne) {
  for (const double zeta : {0.0, 0.05, 0.2}) {
    // K = exp(-zeta pi / sqrt(1 - zeta^2)); T_d = 2 pi / (w sqrt(1 - zeta^2)).
    const double root = std::sqrt(1.0 - zeta * zeta);
    const double k = std::exp(-zeta * std::numbers::pi / root);
    const double td = 2.0 * std::numbers::pi / (kW * root);
    const tp::InputShaper zv(shaper(tp::ShaperKind::zv, zeta));
    ASSERT_EQ(zv.impulse_count(), 2u);
    EXPECT_NEAR(zv.amplitude(0), 1.0 / (1.0 + k), 1e-15);
    EXPECT_NEAR(zv.amplitude(1), k / (1.0 + k), 1e-15);
    EXPECT_EQ(zv.time(0), 0.0);
    EXPECT_NEAR(zv.time(1), td / 2.0, 1e-15);
    EXPECT_NEAR(zv.amplitude(0) + zv.amplitude(1), 1.0, 1e-15);
    const tp::InputShaper zvd(shaper(tp::ShaperKind::zvd, zeta));
    ASSERT_EQ(zvd.impulse_count(), 3u);
    const double d = (1.0 + k) * (1.0 + k);
    EXPECT_NEAR(zvd.amplitude(0), 1.0 / d, 1e-15);
    EXPECT_NEAR(zvd.amplitude(1), 2.0 * k / d, 1e-15);
    EXPECT_NEAR(zvd.amplitude(2), k * k / d, 1e-15);
    EXPECT_NEAR(zvd.time(1), td / 2.0, 1e-15);
    EXPECT_NEAR(zvd.time(2), td, 1e-15);
    EXPECT_NEAR(zvd.amplitude(0) + zvd.amplitude(1) + zvd.amplitude(2), 1.0, 1e-15);
    // Zero vibration at the design point, including damping.
    EXPECT_LT(zv.residual_vibration(kW, zeta), 1e-12);
    EXPECT_LT(zvd.residual_vibration(kW, zeta), 1e-12);
  }
  // Undamped: ZV = [1/2, 1/2] at [0, T/2], ZVD = [1/4, 1/2, 1/4] at [0, T/2, T].
  const tp::InputShaper zvd(shaper(tp::ShaperKind::zvd));
  EXPECT_DOUBLE_EQ(zvd.amplitude(1), 0.5);
  EXPECT_NEAR(zvd.length(), kPeriod, 1e-15);
}

TEST(InputShaper, EiHasToleranceAtDesignAndZerosAroundIt) {
  // Undamped EI: [(1+V)/4, (1-V)/2, (1+V)/4] at [0, T/2, T]; V(r) = |(1-V)/2 + (1+V)/2 cos(pi r)|
  // with r = w'/w: V at r = 1, zero where cos(pi r) = -(1-V)/(1+V) (r = 0.860, 1.140 for V = 5 %),
  // <= V for 0.8003 <= r <= 1.1997 (cos(pi r) >= (3V-1)/(1+V)).
  const double v = 0.05;
  const tp::InputShaper ei(shaper(tp::ShaperKind::ei, 0.0, v));
  EXPECT_DOUBLE_EQ(ei.amplitude(0), 0.2625);
  EXPECT_DOUBLE_EQ(ei.amplitude(1), 0.475);
  EXPECT_DOUBLE_EQ(ei.amplitude(2), 0.2625);
  EXPECT_NEAR(ei.residual_vibration(kW), v, 1e-12);
  const double r_zero = std::acos(-(1.0 - v) / (1.0 + v)) / std::numbers::pi;
  EXPECT_LT(ei.residual_vibration(r_zero * kW), 1e-12);
  EXPECT_LT(ei.residual_vibration((2.0 - r_zero) * kW), 1e-12);
  // Damped EI (curve fit): a tolerance of about V at the design point, far below ZV's sensitivity
  // off it. Fit accuracy: within 0.01 of V.
  for (const double zeta : {0.05, 0.1, 0.2}) {
    const tp::InputShaper damped(shaper(tp::ShaperKind::ei, zeta, v));
    const double sum = damped.amplitude(0) + damped.amplitude(1) + damped.amplitude(2);
    EXPECT_NEAR(sum, 1.0, 1e-15);
    EXPECT_NEAR(damped.residual_vibration(kW, zeta), v, 0.01) << "zeta " << zeta;
    EXPECT_LT(damped.residual_vibration(0.9 * kW, zeta), v + 0.01) << "zeta " << zeta;
    EXPECT_LT(damped.residual_vibration(1.1 * kW, zeta), v + 0.01) << "zeta " << zeta;
  }
}

TEST(InputShaper, MzvCancelsAtDesignAndLiesBetweenZvAndZvd) {
  // Undamped MZV: [1 - 1/sqrt(2), sqrt(2) - 1, 1 - 1/sqrt(2)] at [0, 3T/8, 3T/4]: the vectors at 0,
  // 135 and 270 deg cancel. Its residual at 10 % off (r = 0.9, 1.1) lies between ZV's and ZVD's, and
  // so does its length (T/2 < 3T/4 < T).
  const tp::InputShaper mzv(shaper(tp::ShaperKind::mzv));
  ASSERT_EQ(mzv.impulse_count(), 3u);
  EXPECT_NEAR(mzv.amplitude(0), 1.0 - 1.0 / std::sqrt(2.0), 1e-15);
  EXPECT_NEAR(mzv.amplitude(1), std::sqrt(2.0) - 1.0, 1e-15);
  EXPECT_NEAR(mzv.time(2), 0.75 * kPeriod, 1e-15);
  EXPECT_LT(mzv.residual_vibration(kW), 1e-12);
  const tp::InputShaper zv(shaper(tp::ShaperKind::zv)), zvd(shaper(tp::ShaperKind::zvd));
  for (const double r : {0.9, 1.1}) {
    EXPECT_LT(mzv.residual_vibration(r * kW), zv.residual_vibration(r * kW));
    EXPECT_GT(mzv.residual_vibration(r * kW), zvd.residual_vibration(r * kW));
  }
  for (const double zeta : {0.05, 0.2}) {  // damped: still zero at the design point, sum 1
    const tp::InputShaper damped(shaper(tp::ShaperKind::mzv, zeta));
    EXPECT_NEAR(damped.amplitude(0) + damped.amplitude(1) + damped.amplitude(2), 1.0, 1e-15);
    EXPECT_LT(damped.residual_vibration(kW, zeta), 1e-12) << "zeta " << zeta;
  }
}

TEST(InputShaper, TwoHumpEiStaysBelowToleranceOverItsWideBand) {
  // Undamped two-hump EI (Singhose, Porter, Tuttle, Singer 1997): 4 impulses at 0, T/2, T, 3T/2,
  // zero at r = 1 (the vectors alternate in sign), two humps of height V around it, <= V over
  // r in about [0.6, 1.4] for V = 5 %, where EI exceeds V beyond about +-20 %.
  const double v = 0.05;
  const tp::InputShaper ei2(shaper(tp::ShaperKind::two_hump_ei, 0.0, v));
  ASSERT_EQ(ei2.impulse_count(), 4u);
  EXPECT_NEAR(ei2.length(), 1.5 * kPeriod, 1e-15);
  EXPECT_NEAR(ei2.amplitude(0) + ei2.amplitude(1) + ei2.amplitude(2) + ei2.amplitude(3), 1.0, 1e-15);
  EXPECT_LT(ei2.residual_vibration(kW), 1e-12);
  double worst = 0.0;
  for (double r = 0.7; r <= 1.3; r += 0.001) worst = std::max(worst, ei2.residual_vibration(r * kW));
  EXPECT_NEAR(worst, v, 1e-3);  // the humps reach the tolerance
  const tp::InputShaper ei(shaper(tp::ShaperKind::ei, 0.0, v));
  EXPECT_GT(ei.residual_vibration(0.7 * kW), 2.0 * v);
  EXPECT_LE(ei2.residual_vibration(0.7 * kW), v + 1e-3);
  const tp::InputShaper damped(shaper(tp::ShaperKind::two_hump_ei, 0.1, v));
  EXPECT_LT(damped.residual_vibration(kW, 0.1), 1e-12);  // the damped weights keep the zero at r = 1
}

TEST(InputShaper, RejectsInvalidParametersNamingTheField) {
  tp::ShaperParams bad = shaper(tp::ShaperKind::zv);
  bad.natural_frequency = -1.0;
  try {
    const tp::InputShaper s(bad);
    FAIL() << "no throw";
  } catch (const crane::common::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("input_shaper.natural_frequency"), std::string::npos) << e.what();
  }
  bad = shaper(tp::ShaperKind::ei, 0.0, 0.0);
  EXPECT_THROW(tp::InputShaper{bad}, crane::common::ConfigError);
  bad = shaper(tp::ShaperKind::zvd, 1.0);
  EXPECT_THROW(tp::InputShaper{bad}, crane::common::ConfigError);
  tp::InputShaper s;
  EXPECT_EQ(s.design(bad), tp::ProfileStatus::invalid_parameters);
  EXPECT_EQ(s.impulse_count(), 1u);  // unchanged identity
  EXPECT_THROW(tp::ShapedProfile(0.0, 1.0, tp::AxisLimits{0.0, 1.0}, shaper(tp::ShaperKind::zv)),
               crane::common::ConfigError);
  EXPECT_THROW(tp::TimeOptimalProfile(0.0, 1.0, kTrolleyLimits, 0.0), crane::common::ConfigError);
  EXPECT_THROW(tp::TimeOptimalProfile(0.0, NAN, kTrolleyLimits, kW), crane::common::ConfigError);
  tp::TimeOptimalProfile p;
  EXPECT_EQ(p.plan(0.0, 1.0, tp::AxisLimits{1.0, INFINITY}, kW), tp::ProfileStatus::invalid_parameters);
}

// ---------------------------------------------------------------- shaped profiles
TEST(ShapedProfile, ResidualSwingAtDesignPeriodIsBelowOnePermilleOfTheTrapezoid) {
  const tp::TrapezoidProfile trapezoid(kTrolleyStart, kTrolleyTarget, kTrolleyLimits);
  const double unshaped = residual_swing(trapezoid, kW);
  EXPECT_GT(unshaped, 0.01);  // (3.54) with t_f = T leaves a visible swing
  for (const tp::ShaperKind kind : {tp::ShaperKind::zv, tp::ShaperKind::zvd}) {
    const tp::ShapedProfile shaped(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(kind));
    EXPECT_LT(residual_swing(shaped, kW), 1e-3 * unshaped) << static_cast<int>(kind);
  }
  const tp::ShapedProfile ei(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(tp::ShaperKind::ei));
  EXPECT_LT(residual_swing(ei, kW), (0.05 + 1e-3) * unshaped);
}

TEST(ShapedProfile, ZvdAndEiStaySmallForTwentyPercentPeriodError) {
  // True period T' = (1 +- 0.2) T, i.e. w' = w/(1 +- 0.2). By linearity the residual ratio is the
  // shaper's V(w'/w): ZVD cos^2(pi r/2) <= 0.147 at r = 1.25; EI <= 0.105; ZV reaches 0.38.
  for (const double error : {-0.2, -0.1, 0.1, 0.2}) {
    const double w_true = kW / (1.0 + error);
    const tp::TrapezoidProfile trapezoid(kTrolleyStart, kTrolleyTarget, kTrolleyLimits);
    const double unshaped = residual_swing(trapezoid, w_true);
    const tp::ShapedProfile zvd(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(tp::ShaperKind::zvd));
    const tp::ShapedProfile ei(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(tp::ShaperKind::ei));
    const double r = w_true / kW;
    EXPECT_LT(residual_swing(zvd, w_true), 0.15 * unshaped) << error;
    EXPECT_LT(residual_swing(ei, w_true), 0.11 * unshaped) << error;
    EXPECT_NEAR(residual_swing(zvd, w_true) / unshaped, std::pow(std::cos(std::numbers::pi * r / 2.0), 2), 1e-3) << error;
  }
  // EI over its design band 0.81 <= w'/w <= 1.19: residual <= V = 5 % of the unshaped one.
  for (double r = 0.81; r <= 1.19 + 1e-9; r += 0.02) {
    const double w_true = r * kW;
    const tp::TrapezoidProfile trapezoid(kTrolleyStart, kTrolleyTarget, kTrolleyLimits);
    const tp::ShapedProfile ei(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(tp::ShaperKind::ei));
    EXPECT_LE(residual_swing(ei, w_true), (0.05 + 1e-3) * residual_swing(trapezoid, w_true)) << r;
  }
}

TEST(ShapedProfile, RespectsLimitsReachesTargetAtRestAndLastsBasePlusShaper) {
  for (const tp::ShaperKind kind : {tp::ShaperKind::zv, tp::ShaperKind::zvd, tp::ShaperKind::ei}) {
    const tp::ShapedProfile trolley(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(kind));
    expect_admissible(trolley, kTrolleyStart, kTrolleyTarget, kTrolleyLimits);
    EXPECT_NEAR(trolley.duration(), trolley.base().duration() + trolley.shaper().length(), 1e-15);
    const tp::ShapedProfile slew(kSlewTarget, 0.0, kSlewLimits, shaper(kind));  // backwards too
    expect_admissible(slew, kSlewTarget, 0.0, kSlewLimits);
  }
  // ZV adds T/2, ZVD and EI add T: 2.0072 + 1.0035 and 2.0072 + 2.0071.
  const tp::ShapedProfile zv(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(tp::ShaperKind::zv));
  EXPECT_NEAR(zv.duration(), 0.75 / 0.4982 + 0.4982 / 0.9929 + kPeriod / 2.0, 1e-12);
}

// ---------------------------------------------------------------- time-optimal
struct Move {
  const char* name;
  double start;
  double target;
  tp::AxisLimits limits;
  double swing_gain;  // u = gain * axis acceleration
};

class TimeOptimal : public ::testing::TestWithParam<Move> {};

TEST_P(TimeOptimal, SwingFreeAdmissibleAndAgreesWithTheLp) {
  const Move m = GetParam();
  const tp::TimeOptimalProfile profile(m.start, m.target, m.limits, kW);
  expect_admissible(profile, m.start, m.target, m.limits);
  // Zero residual swing [rad] (the simulation error itself is ~1e-6).
  EXPECT_LT(residual_swing(profile, kW, m.swing_gain), 1e-4);
  const double lp = lp_minimum_duration(std::abs(m.target - m.start), m.limits, kW);
  // Every LP solution is an admissible continuous profile, so lp >= optimum; rounding the
  // optimum's switching times to the grid costs at most about one step.
  EXPECT_GE(lp, profile.duration() - 1e-9) << m.name;
  EXPECT_LE(lp - profile.duration(), kLpStep) << m.name;
  const tp::ShapedProfile zv(m.start, m.target, m.limits, shaper(tp::ShaperKind::zv));
  EXPECT_LT(profile.duration(), zv.duration());
  const tp::TrapezoidProfile trapezoid(m.start, m.target, m.limits);
  EXPECT_GE(profile.duration(), trapezoid.duration());
  std::printf("[ %-14s] trapezoid %.4f  ZV %.4f  ZVD %.4f  EI %.4f  time-optimal %.4f (family %d, "
              "%zu segments)  LP %.4f  LP-opt %+.4f s\n",
              m.name, trapezoid.duration(), zv.duration(),
              tp::ShapedProfile(m.start, m.target, m.limits, shaper(tp::ShaperKind::zvd)).duration(),
              tp::ShapedProfile(m.start, m.target, m.limits, shaper(tp::ShaperKind::ei)).duration(),
              profile.duration(), static_cast<int>(profile.family()), profile.segment_count(), lp,
              lp - profile.duration());
}

INSTANTIATE_TEST_SUITE_P(
    Moves, TimeOptimal,
    ::testing::Values(Move{"trolley_3_54", kTrolleyStart, kTrolleyTarget, kTrolleyLimits, 1.0},
                      Move{"slew_3_55", 0.0, kSlewTarget, kSlewLimits, -kSlewRadius},
                      Move{"trolley_short", 0.3, 0.4, kTrolleyLimits, 1.0},
                      Move{"trolley_back", 1.0, 0.2, kTrolleyLimits, 1.0},
                      Move{"slew_long", 0.0, 2.0 * std::numbers::pi, kSlewLimits, -kSlewRadius},
                      Move{"slew_4_rad", -2.0, 2.0, kSlewLimits, -kSlewRadius}),
    [](const ::testing::TestParamInfo<Move>& move_info) { return std::string(move_info.param.name); });

TEST(TimeOptimalProfile, ZeroDistanceHoldsTheStart) {
  const tp::TimeOptimalProfile p(0.5, 0.5, kTrolleyLimits, kW);
  EXPECT_EQ(p.duration(), 0.0);
  EXPECT_EQ(p.sample(1.0).position, 0.5);
}

TEST(TimeOptimalProfile, PlanIsFastEnoughForAMoveStartWorstCase) {
  // Reports the worst plan() time over a sweep of distances (not a hard real-time bound).
  tp::TimeOptimalProfile p;
  double worst = 0.0;
  for (int i = 1; i <= 40; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    ASSERT_EQ(p.plan(0.0, 0.1 * i, kSlewLimits, kW), tp::ProfileStatus::ok);
    worst = std::max(worst, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    EXPECT_LT(residual_swing(p, kW), 1e-4) << 0.1 * i;
  }
  std::printf("[ plan() worst ] %.3f ms\n", worst * 1e3);
}

// ---- Hoisting during the move: shapers rescheduled with L(t) ----

namespace {

/// Residual swing [rad] of the variable-length pendulum (linearized, Lagrangian of a point mass on
/// a cable of length L(t)): L phi'' + 2 L' phi' + g phi = x'' (trolley), integrated by RK4 at 1 ms
/// with the profile's acceleration, until `end` [s]; amplitude sqrt(phi^2 + (phi'/w_end)^2).
double residual_swing_hoisting(const tp::AxisProfile& profile, const tp::TrapezoidProfile& cable, double end) {
  auto derivative = [&](double t, double phi, double rate) {
    const auto c = cable.sample(t);
    const double u = profile.sample(t).acceleration;
    return std::pair{rate, (u - kGravity * phi - 2.0 * c.velocity * rate) / c.position};
  };
  double phi = 0.0, rate = 0.0;
  const int steps = static_cast<int>(std::ceil(end / kSimStep));
  for (int k = 0; k < steps; ++k) {
    const double t = k * kSimStep, h = kSimStep;
    const auto [k1p, k1r] = derivative(t, phi, rate);
    const auto [k2p, k2r] = derivative(t + h / 2, phi + h / 2 * k1p, rate + h / 2 * k1r);
    const auto [k3p, k3r] = derivative(t + h / 2, phi + h / 2 * k2p, rate + h / 2 * k2r);
    const auto [k4p, k4r] = derivative(t + h, phi + h * k3p, rate + h * k3r);
    phi += h / 6 * (k1p + 2 * k2p + 2 * k3p + k4p);
    rate += h / 6 * (k1r + 2 * k2r + 2 * k3r + k4r);
  }
  const double w_end = std::sqrt(kGravity / cable.sample(end).position);
  return std::hypot(phi, rate / w_end);
}

}  // namespace

TEST(ShapedProfile, HoistingReschedulesTheImpulsesAndLeavesLessSwingThanAFixedShaper) {
  // The trolley move of (3.54) while the load is lowered from 1.0 to 1.6 m at 0.2 m/s, 0.5 m/s^2.
  const tp::TrapezoidProfile cable(1.0, 1.6, {0.2, 0.5});
  const tp::TrapezoidProfile trapezoid(kTrolleyStart, kTrolleyTarget, kTrolleyLimits);
  for (const auto kind : {tp::ShaperKind::zv, tp::ShaperKind::zvd}) {
    tp::ShapedProfile fixed(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(kind));
    tp::ShapedProfile rescheduled = fixed;
    ASSERT_EQ(rescheduled.reschedule_for_hoisting(cable, kGravity), tp::ProfileStatus::ok);
    EXPECT_TRUE(rescheduled.hoisting());
    const double end = std::max(rescheduled.duration(), cable.duration()) + 0.5;
    const double none = residual_swing_hoisting(trapezoid, cable, end);
    const double with_fixed = residual_swing_hoisting(fixed, cable, end);
    const double with_rescheduled = residual_swing_hoisting(rescheduled, cable, end);
    std::printf("[ figure   ] %s, lowering 1.0 -> 1.6 m during the move: residual swing %.3f deg (trapezoid), "
                "%.3f deg (shaper for L = 1 m), %.3f deg (rescheduled with L(t))\n",
                kind == tp::ShaperKind::zv ? "ZV" : "ZVD", none * 180 / std::numbers::pi,
                with_fixed * 180 / std::numbers::pi, with_rescheduled * 180 / std::numbers::pi);
    EXPECT_LT(with_rescheduled, with_fixed);
    EXPECT_LT(with_rescheduled, 0.25 * none);
    // Still a rest-to-rest move within the limits' spirit: ends at the target at rest.
    const auto last = rescheduled.sample(rescheduled.duration());
    EXPECT_NEAR(last.position, kTrolleyTarget, 1e-12);
    EXPECT_EQ(last.velocity, 0.0);
  }
}

TEST(ShapedProfile, HoistingVelocityAndAccelerationAreTheDerivativesOfThePosition) {
  const tp::TrapezoidProfile cable(1.5, 0.8, {0.25, 0.5});  // hoisting up
  tp::ShapedProfile p(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(tp::ShaperKind::zvd));
  ASSERT_EQ(p.reschedule_for_hoisting(cable, kGravity), tp::ProfileStatus::ok);
  const double h = 1e-5;
  double worst_v = 0.0, worst_a = 0.0;
  for (double t = 0.05; t < p.duration() - 0.05; t += 0.0137) {
    const auto r = p.sample(t);
    const double v = (p.sample(t + h).position - p.sample(t - h).position) / (2 * h);
    const double a = (p.sample(t + h).velocity - p.sample(t - h).velocity) / (2 * h);
    worst_v = std::max(worst_v, std::abs(v - r.velocity));
    // The trapezoid's acceleration jumps: skip samples straddling a jump.
    if (std::abs(p.sample(t + h).acceleration - p.sample(t - h).acceleration) < 1e-3) {
      worst_a = std::max(worst_a, std::abs(a - r.acceleration));
    }
  }
  EXPECT_LT(worst_v, 1e-6);
  EXPECT_LT(worst_a, 1e-4);
  // Invalid schedules are refused and change nothing.
  tp::ShapedProfile q(kTrolleyStart, kTrolleyTarget, kTrolleyLimits, shaper(tp::ShaperKind::zv));
  EXPECT_EQ(q.reschedule_for_hoisting(cable, 0.0), tp::ProfileStatus::invalid_parameters);
  EXPECT_FALSE(q.hoisting());
}
