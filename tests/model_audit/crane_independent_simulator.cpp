// The test's own tower-crane simulator (crane_independent_simulator.hpp). Shares no code with the
// audit, the hidden-effect generator or the plant: its own chart of the cable, its own Lagrangian
// (point masses differentiated by hyper-dual numbers), integrator, stick-slip rule, injections,
// maneuver and sensors.
#include "crane_independent_simulator.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>

namespace crane::model_audit::test {

namespace {

constexpr double kSampleTime = 0.01;  // [s] 100 Hz
constexpr int kSubsteps = 100;        // RK4 steps per sample
constexpr double kDuration = 18.0;    // [s]
constexpr double kNoiseCounts = 0.3;  // Gaussian sensor noise [counts] before the reading
constexpr double kDacRange = 10.0;    // [V]
constexpr double kDacStep = 2.0 * kDacRange / 8192.0;  // 13 bit
constexpr double kTrolleyGain = 70.0;   // [V/m]
constexpr double kSlewGain = 30.0;      // [V/rad]
constexpr double kDerivativeTime = 0.25;  // [s]
constexpr double kTrolleyStart = 0.6;   // [m]
constexpr double kCreepSpeed = 0.025;   // [m/s] and [rad/s]
constexpr double kCreepEnd = 4.5;       // [s]
constexpr double kSwingCoulombWidth = 5e-4;  // [rad/s] regularization of the swing's Coulomb sign
constexpr double kRopeDampingRatio = 0.02;   // [-]
constexpr int kMaxCoordinates = 6;

// ---------------------------------------------------------------------------------------------
// Hyper-dual numbers a + b e1 + c e2 + d e1 e2 (e1^2 = e2^2 = 0): f(q + e1 u + e2 w) carries the
// directional derivatives f'(q) u, f'(q) w and the second derivative u^T f''(q) w, exactly.
struct HD {
  double a{0.0}, b{0.0}, c{0.0}, d{0.0};
};
HD operator+(HD x, HD y) { return {x.a + y.a, x.b + y.b, x.c + y.c, x.d + y.d}; }
HD operator-(HD x, HD y) { return {x.a - y.a, x.b - y.b, x.c - y.c, x.d - y.d}; }
HD operator*(HD x, HD y) { return {x.a * y.a, x.a * y.b + x.b * y.a, x.a * y.c + x.c * y.a, x.a * y.d + x.b * y.c + x.c * y.b + x.d * y.a}; }
HD operator*(double s, HD x) { return {s * x.a, s * x.b, s * x.c, s * x.d}; }
HD lift(HD x, double f, double f1, double f2) { return {f, f1 * x.b, f1 * x.c, f1 * x.d + f2 * x.b * x.c}; }
HD sin(HD x) { return lift(x, std::sin(x.a), std::cos(x.a), -std::sin(x.a)); }
HD cos(HD x) { return lift(x, std::cos(x.a), -std::sin(x.a), -std::cos(x.a)); }

struct V3 {
  HD x, y, z;
};
V3 operator+(const V3& p, const V3& q) { return {p.x + q.x, p.y + q.y, p.z + q.z}; }
V3 scaled(HD s, const V3& p) { return {s * p.x, s * p.y, s * p.z}; }

// The cable's direction in the jib frame, this simulator's chart.
V3 direction(HD alpha, HD beta) {
  const HD ca = cos(alpha);
  return {-1.0 * sin(alpha), ca * sin(beta), -1.0 * (ca * cos(beta))};
}

enum class Rigging { single, hook, rope };

struct Geometry {
  Rigging rigging{Rigging::single};
  double length{1.0};   // true cable length [m]
  double rigging_length{0.0};  // [m] hook to load
  int coordinates{4};
  int points{2};
};

// Point positions in the inertial frame: 0 trolley, 1 load (hook with a hook), 2 load (hook only).
void positions(const Geometry& g, const HD* q, V3* out) {
  const HD cg = cos(q[1]);
  const HD sg = sin(q[1]);
  const auto inertial = [&](const V3& r) { return V3{cg * r.x - sg * r.y, sg * r.x + cg * r.y, r.z}; };
  const V3 trolley{q[0], HD{}, HD{}};
  out[0] = inertial(trolley);
  HD cable{g.length, 0.0, 0.0, 0.0};
  if (g.rigging == Rigging::rope) cable = cable + q[4];
  const V3 first = trolley + scaled(cable, direction(q[2], q[3]));
  out[1] = inertial(first);
  if (g.rigging == Rigging::hook) {
    out[2] = inertial(first + scaled(HD{g.rigging_length, 0.0, 0.0, 0.0}, direction(q[4], q[5])));
  }
}

// ---------------------------------------------------------------------------------------------
// Drives, in volt equivalents (a force is volts * M_drive K_mx, a torque volts * J_o K_mgamma).
struct DriveTruth {
  double gain{1.0};  // K_m [m/s^2/V] or [rad/s^2/V]
  double inertia{1.0};  // M_drive [kg] or J_o [kg m^2]: force per volt = inertia * gain
  double viscous_positive{0.0}, viscous_negative{0.0};  // [V s/m]
  double coulomb_positive{0.0}, coulomb_negative{0.0};  // [V]
  // Breakaway excess over the Coulomb level [V] per direction, from the configuration (max(static,
  // Coulomb) - Coulomb): the catalog's nominal Delta_s +- dDelta_s, kept when an entry moves the
  // Coulomb level (audit_models.hpp).
  double static_excess_positive{0.0}, static_excess_negative{0.0};
  double stiction{0.0};           // [V] added breakaway level
  double stribeck_level{0.0};     // [V]
  double stribeck_velocity{0.03};  // [m/s]
  double slope{0.0};              // [V/m] position-dependent Coulomb level
  double deadzone{0.0};           // [V]
  double saturation{0.0};         // [V], 0 = none
  double backlash{0.0};           // [m] total play
  double delay{0.0};              // [s]
  double gain_error{0.0};         // [-]

  [[nodiscard]] double per_volt() const { return inertia * gain; }
  [[nodiscard]] double coulomb(int s, double x) const {
    return std::max(0.0, (s > 0 ? coulomb_positive : coulomb_negative) + slope * x);
  }
  // Friction level [V] (magnitude) while sliding toward s.
  [[nodiscard]] double sliding(int s, double x, double v) const {
    const double b = std::max(0.0, s > 0 ? viscous_positive : viscous_negative);
    const double r = v / stribeck_velocity;
    return coulomb(s, x) + (stribeck_level > 0.0 ? stribeck_level * std::exp(-r * r) : 0.0) + b * std::abs(v);
  }
  // Largest drive [V] held at rest toward s.
  [[nodiscard]] double breakaway(int s, double x) const {
    return coulomb(s, x) + (s > 0 ? static_excess_positive : static_excess_negative) + stribeck_level + stiction;
  }
  // Effective drive [V] of the command u [V].
  [[nodiscard]] double drive(double u) const {
    double v = deadzone > 0.0 ? u - std::clamp(u, -deadzone, deadzone) : u;
    if (saturation > 0.0) v = std::clamp(v, -saturation, saturation);
    return (1.0 + gain_error) * v;
  }
};

struct SwingTruth {
  double viscous{0.0};    // [1/s] on phi'' and theta''
  double coulomb{0.0};    // [rad/s^2]
  double quadratic{0.0};  // [1/rad]
  double offset{0.0};     // [rad] phi encoder
  double wind_x{0.0}, wind_y{0.0};  // [N] inertial
};

struct Truth {
  common::CraneParameters crane;  // true masses, gains; load_mass the suspended mass
  Geometry geometry;
  double point_mass[3]{0.0, 0.0, 0.0};
  double hook_share{0.0};
  double rope_stiffness{0.0};  // [N/m]
  double rope_damping{0.0};    // [N s/m]
  DriveTruth drive[2];         // trolley, slew
  SwingTruth swing;
};

// ---------------------------------------------------------------------------------------------
// Dense solve (Gaussian elimination with partial pivoting), n <= kMaxCoordinates.
using Mat = std::array<std::array<double, kMaxCoordinates>, kMaxCoordinates>;
using Vec = std::array<double, kMaxCoordinates>;

Vec solve(Mat a, Vec b, int n) {
  for (int k = 0; k < n; ++k) {
    int p = k;
    for (int i = k + 1; i < n; ++i) {
      if (std::abs(a[i][k]) > std::abs(a[p][k])) p = i;
    }
    std::swap(a[k], a[p]);
    std::swap(b[k], b[p]);
    for (int i = k + 1; i < n; ++i) {
      const double f = a[i][k] / a[k][k];
      for (int j = k; j < n; ++j) a[i][j] -= f * a[k][j];
      b[i] -= f * b[k];
    }
  }
  Vec x{};
  for (int k = n - 1; k >= 0; --k) {
    double s = b[k];
    for (int j = k + 1; j < n; ++j) s -= a[k][j] * x[j];
    x[k] = s / a[k][k];
  }
  return x;
}

// The audit's swing angles (phi, theta) of the cable direction in this chart, and their Jacobian
// d(phi, theta)/d(alpha, beta) (phi = atan2(sin a, cos a cos b), theta = asin(cos a sin b)).
struct SwingReading {
  double phi, theta;
  double dphi_da, dphi_db, dtheta_da, dtheta_db;
};
SwingReading swing_reading(double a, double b) {
  const double ca = std::cos(a), sa = std::sin(a), cb = std::cos(b), sb = std::sin(b);
  SwingReading r{};
  r.phi = std::atan2(sa, ca * cb);
  r.theta = std::asin(std::clamp(ca * sb, -1.0, 1.0));
  const double c2 = std::max(1e-12, 1.0 - ca * ca * sb * sb);  // cos^2 theta
  const double ct = std::sqrt(c2);
  r.dphi_da = cb / c2;
  r.dphi_db = sa * ca * sb / c2;
  r.dtheta_da = -sa * sb / ct;
  r.dtheta_db = ca * cb / ct;
  return r;
}

struct State {
  Vec q{};
  Vec v{};
};

class Crane {
 public:
  explicit Crane(const Truth& truth) : t_(truth), n_(truth.geometry.coordinates) {}

  // Mass matrix, bias (convective, gravity, rope) and the non-friction generalized force.
  void assemble(const State& s, const double drive_volts[2], Mat& mass, Vec& bias, Vec& force) const {
    const Geometry& g = t_.geometry;
    for (auto& row : mass) row.fill(0.0);
    bias.fill(0.0);
    force.fill(0.0);
    std::array<std::array<V3, 3>, kMaxCoordinates> column{};  // column[j][point] = dp/dq_j
    std::array<HD, kMaxCoordinates> hq{};
    for (int j = 0; j < n_; ++j) {
      for (int i = 0; i < n_; ++i) hq[i] = HD{s.q[i], i == j ? 1.0 : 0.0, 0.0, 0.0};
      positions(g, hq.data(), column[j].data());
    }
    V3 path[3];
    for (int i = 0; i < n_; ++i) hq[i] = HD{s.q[i], s.v[i], s.v[i], 0.0};
    positions(g, hq.data(), path);  // .d = q'^T H q' (the convective acceleration)
    const double gravity = t_.crane.gravity;
    for (int p = 0; p < g.points; ++p) {
      const double m = t_.point_mass[p];
      for (int j = 0; j < n_; ++j) {
        const V3& cj = column[j][p];
        for (int k = 0; k < n_; ++k) {
          const V3& ck = column[k][p];
          mass[j][k] += m * (cj.x.b * ck.x.b + cj.y.b * ck.y.b + cj.z.b * ck.z.b);
        }
        bias[j] += m * (cj.x.b * path[p].x.d + cj.y.b * path[p].y.d + cj.z.b * (path[p].z.d + gravity));
      }
    }
    mass[0][0] += t_.crane.trolley_drive_mass - t_.crane.trolley_mass;
    mass[1][1] += t_.crane.jib_inertia;
    if (g.rigging == Rigging::rope) bias[4] += t_.rope_stiffness * s.q[4] + t_.rope_damping * s.v[4];
    for (int i = 0; i < 2; ++i) force[i] = t_.drive[i].per_volt() * drive_volts[i];
    const int load = g.points - 1;
    if (t_.swing.wind_x != 0.0 || t_.swing.wind_y != 0.0) {
      for (int j = 0; j < n_; ++j) {
        force[j] += column[j][load].x.b * t_.swing.wind_x + column[j][load].y.b * t_.swing.wind_y;
      }
    }
    const SwingTruth& w = t_.swing;
    if (w.viscous != 0.0 || w.coulomb != 0.0 || w.quadratic != 0.0) {
      // The catalog's terms on phi'' and theta'' as a generalized force: in the audit's chart the
      // cable's rows are m L^2 diag(cos^2 theta, 1), so Q_(phi, theta) = m L^2 (cos^2 theta a_phi,
      // a_theta); back to this chart by the transposed Jacobian.
      const SwingReading r = swing_reading(s.q[2], s.q[3]);
      const double rate_phi = r.dphi_da * s.v[2] + r.dphi_db * s.v[3];
      const double rate_theta = r.dtheta_da * s.v[2] + r.dtheta_db * s.v[3];
      const auto extra = [&](double rate) {
        return -w.viscous * rate - w.coulomb * std::tanh(rate / kSwingCoulombWidth) - w.quadratic * rate * std::abs(rate);
      };
      const double ml2 = t_.point_mass[1] * g.length * g.length;
      const double ct = std::cos(r.theta);
      const double q_phi = ml2 * ct * ct * extra(rate_phi);
      const double q_theta = ml2 * extra(rate_theta);
      force[2] += r.dphi_da * q_phi + r.dtheta_da * q_theta;
      force[3] += r.dphi_db * q_phi + r.dtheta_db * q_theta;
    }
  }

  // Accelerations with the drives in `held` at rest (q''_i = 0); `dir` the sliding directions.
  // `holding`: for a held drive, the drive [V] that its friction must hold.
  Vec acceleration(const State& s, const double drive_volts[2], const int dir[2], Vec* holding = nullptr) const {
    Mat mass;
    Vec bias, force;
    assemble(s, drive_volts, mass, bias, force);
    Vec rhs{};
    for (int j = 0; j < n_; ++j) rhs[j] = force[j] - bias[j];
    for (int i = 0; i < 2; ++i) {
      if (dir[i] != 0) rhs[i] -= dir[i] * t_.drive[i].per_volt() * t_.drive[i].sliding(dir[i], s.q[i], s.v[i]);
    }
    Mat reduced = mass;
    Vec r = rhs;
    for (int i = 0; i < 2; ++i) {
      if (dir[i] != 0) continue;
      reduced[i].fill(0.0);
      reduced[i][i] = 1.0;
      r[i] = 0.0;
    }
    const Vec a = solve(reduced, r, n_);
    if (holding != nullptr) {
      for (int i = 0; i < 2; ++i) {
        if (dir[i] != 0) continue;
        double inertial = 0.0;
        for (int k = 0; k < n_; ++k) inertial += mass[i][k] * a[k];
        (*holding)[i] = (rhs[i] - inertial) / t_.drive[i].per_volt();
      }
    }
    return a;
  }

  // The rest rule for the drives at rest: a drive breaks away toward the drive it must hold when
  // that exceeds its breakaway level.
  void decide_rest(const State& s, const double drive_volts[2], int dir[2]) const {
    for (int pass = 0; pass < 2; ++pass) {
      if (dir[0] != 0 && dir[1] != 0) return;
      Vec holding{};
      (void)acceleration(s, drive_volts, dir, &holding);
      bool changed = false;
      for (int i = 0; i < 2; ++i) {
        if (dir[i] != 0) continue;
        const double d = holding[i];
        const int toward = d > 0.0 ? 1 : -1;
        if (d != 0.0 && std::abs(d) > t_.drive[i].breakaway(toward, s.q[i])) {
          dir[i] = toward;
          changed = true;
        }
      }
      if (!changed) return;
    }
  }

  void rk4(State& s, const double drive_volts[2], const int dir[2], double h) const {
    const auto f = [&](const State& x, Vec& dq, Vec& dv) {
      dv = acceleration(x, drive_volts, dir);
      dq = x.v;
    };
    Vec k1q, k1v, k2q, k2v, k3q, k3v, k4q, k4v;
    State m = s;
    f(s, k1q, k1v);
    for (int j = 0; j < n_; ++j) {
      m.q[j] = s.q[j] + 0.5 * h * k1q[j];
      m.v[j] = s.v[j] + 0.5 * h * k1v[j];
    }
    f(m, k2q, k2v);
    for (int j = 0; j < n_; ++j) {
      m.q[j] = s.q[j] + 0.5 * h * k2q[j];
      m.v[j] = s.v[j] + 0.5 * h * k2v[j];
    }
    f(m, k3q, k3v);
    for (int j = 0; j < n_; ++j) {
      m.q[j] = s.q[j] + h * k3q[j];
      m.v[j] = s.v[j] + h * k3v[j];
    }
    f(m, k4q, k4v);
    for (int j = 0; j < n_; ++j) {
      s.q[j] += h / 6.0 * (k1q[j] + 2.0 * k2q[j] + 2.0 * k3q[j] + k4q[j]);
      s.v[j] += h / 6.0 * (k1v[j] + 2.0 * k2v[j] + 2.0 * k3v[j] + k4v[j]);
    }
    for (int i = 0; i < 2; ++i) {
      if (dir[i] == 0) s.v[i] = 0.0;
    }
  }

  // One step of h with the rest rule; a sliding drive whose rate changes sign stops at the
  // reversal (the step is cut there, linear in the rate) and the rest of the step follows.
  void step(State& s, const double drive_volts[2], int dir[2], double h, int depth = 0) const {
    decide_rest(s, drive_volts, dir);
    State trial = s;
    rk4(trial, drive_volts, dir, h);
    double first = 1.0;
    int which = -1;
    for (int i = 0; i < 2; ++i) {
      if (dir[i] != 0 && trial.v[i] * dir[i] < 0.0) {
        const double a = s.v[i] / (s.v[i] - trial.v[i]);
        if (a < first) {
          first = a;
          which = i;
        }
      }
    }
    if (which < 0 || depth > 3) {
      s = trial;
      for (int i = 0; i < 2; ++i) {
        if (dir[i] != 0 && s.v[i] * dir[i] < 0.0) {
          s.v[i] = 0.0;
          dir[i] = 0;
        }
      }
      return;
    }
    if (first > 0.0) rk4(s, drive_volts, dir, first * h);
    s.v[which] = 0.0;
    dir[which] = 0;
    if (first < 1.0) step(s, drive_volts, dir, (1.0 - first) * h, depth + 1);
  }

 private:
  const Truth& t_;
  int n_;
};

// ---------------------------------------------------------------------------------------------
double smooth_fade(double s) { return s < 1.0 ? s * s * (3.0 - 2.0 * s) : 1.0; }

double creep(double t) {
  const double leg = kCreepEnd / 3.0;
  if (t < leg) return kCreepSpeed * t;
  if (t < 2.0 * leg) return kCreepSpeed * (2.0 * leg - t);
  return kCreepSpeed * (t - 2.0 * leg);
}

double trolley_reference(double t) {
  if (t < kCreepEnd) return kTrolleyStart + creep(t);
  const double s = t - kCreepEnd;
  const double w = 2.0 * std::numbers::pi;
  return kTrolleyStart + creep(kCreepEnd) +
         smooth_fade(s) * (0.16 * std::sin(w * 0.22 * s) + 0.08 * std::sin(w * 0.47 * s + 0.8) -
                           0.05 * std::sin(w * 0.9 * s + 2.0));
}

double slew_reference(double t) {
  if (t < kCreepEnd) return -creep(t);
  const double s = t - kCreepEnd;
  const double w = 2.0 * std::numbers::pi;
  return -creep(kCreepEnd) + smooth_fade(s) * (0.22 * std::sin(w * 0.13 * s + 0.3) - 0.15 * std::sin(w * 0.37 * s) +
                                               0.06 * std::sin(w * 0.8 * s + 1.1));
}

struct Draw {
  std::mt19937_64 rng;
  double uniform(double a, double b) { return std::uniform_real_distribution<double>(a, b)(rng); }
  double signed_uniform(double a, double b) { return (uniform(0.0, 1.0) < 0.5 ? -1.0 : 1.0) * uniform(a, b); }
};

double read(double value, double quantum, std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, kNoiseCounts);
  return quantum * std::round(value / quantum + normal(rng));
}

double dac(double u) { return std::clamp(kDacStep * std::round(u / kDacStep), -kDacRange, kDacRange); }

// Closed-loop run; records into `data` when given; returns max |u| of each drive.
std::array<double, 2> run(const Truth& truth, std::uint64_t seed, AuditData* data) {
  const Crane crane(truth);
  const common::CraneParameters& p = truth.crane;
  const double quantum[2] = {p.leadscrew_pitch * 2.0 * std::numbers::pi / (4.0 * p.motor_encoder_lines),
                             2.0 * std::numbers::pi / (4.0 * p.motor_encoder_lines * p.slew_gear_ratio)};
  const double swing_quantum = 2.0 * std::numbers::pi / (4.0 * p.swing_encoder_lines);
  std::mt19937_64 rng(seed ^ 0x5eedcafeULL);
  State s;
  s.q[0] = kTrolleyStart;
  if (truth.geometry.rigging == Rigging::rope) s.q[4] = truth.point_mass[1] * p.gravity / truth.rope_stiffness;
  double measured_side[2] = {s.q[0], 0.0};  // the sensor's side of the backlash
  int dir[2] = {0, 0};
  std::vector<double> commands[2];
  double previous[2] = {0.0, 0.0};
  std::array<double, 2> largest{0.0, 0.0};
  const auto samples = static_cast<std::size_t>(std::llround(kDuration / kSampleTime)) + 1;
  const double h = kSampleTime / kSubsteps;
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * kSampleTime;
    double y[2];
    for (int i = 0; i < 2; ++i) y[i] = read(measured_side[i], quantum[i], rng);
    const double reference[2] = {trolley_reference(t), slew_reference(t)};
    const double gain[2] = {kTrolleyGain, kSlewGain};
    for (int i = 0; i < 2; ++i) {
      const double rate = k == 0 ? 0.0 : (y[i] - previous[i]) / kSampleTime;
      previous[i] = y[i];
      commands[i].push_back(dac(gain[i] * (reference[i] - y[i] - kDerivativeTime * rate)));
      largest[i] = std::max(largest[i], std::abs(commands[i].back()));
    }
    if (data != nullptr) {
      const SwingReading r = swing_reading(s.q[2], s.q[3]);
      data->time.push_back(t);
      data->input.push_back(commands[0].back());
      data->output.push_back(y[0]);
      data->slew_input.push_back(commands[1].back());
      data->slew_angle.push_back(y[1]);
      data->swing_in_plane.push_back(read(r.phi + truth.swing.offset, swing_quantum, rng));
      data->swing_out_of_plane.push_back(read(r.theta, swing_quantum, rng));
    }
    for (int j = 0; j < kSubsteps; ++j) {
      double volts[2];
      for (int i = 0; i < 2; ++i) {
        const double at = t + (j + 0.5) * h - truth.drive[i].delay;
        const auto index = at <= 0.0 ? std::size_t{0}
                                     : std::min(k, static_cast<std::size_t>(std::floor(at / kSampleTime + 1e-12)));
        volts[i] = truth.drive[i].drive(commands[i][index]);
      }
      crane.step(s, volts, dir, h);
      for (int i = 0; i < 2; ++i) {
        const double half = 0.5 * truth.drive[i].backlash;
        if (s.q[i] - measured_side[i] > half) measured_side[i] = s.q[i] - half;
        if (s.q[i] - measured_side[i] < -half) measured_side[i] = s.q[i] + half;
      }
    }
  }
  return largest;
}

void set_point_masses(Truth& t) {
  Geometry& g = t.geometry;
  t.point_mass[0] = t.crane.trolley_mass;
  if (g.rigging == Rigging::hook) {
    g.coordinates = 6;
    g.points = 3;
    t.point_mass[1] = t.hook_share * t.crane.load_mass;
    t.point_mass[2] = (1.0 - t.hook_share) * t.crane.load_mass;
  } else {
    g.coordinates = g.rigging == Rigging::rope ? 5 : 4;
    g.points = 2;
    t.point_mass[1] = t.crane.load_mass;
  }
}

DriveTruth drive_truth(const common::AxisFriction& f, double gain, double inertia) {
  DriveTruth d;
  d.gain = gain;
  d.inertia = inertia;
  d.viscous_positive = f.viscous_positive;
  d.viscous_negative = f.viscous_negative;
  d.coulomb_positive = f.coulomb_positive;
  d.coulomb_negative = f.coulomb_negative;
  d.static_excess_positive = std::max(0.0, f.static_positive - f.coulomb_positive);
  d.static_excess_negative = std::max(0.0, f.static_negative - f.coulomb_negative);
  return d;
}

// Draws the drive entry `entry` on drive `d` (volts inside, the main value in the audit's units).
void inject_drive(const std::string& entry, DriveTruth& d, bool trolley, Draw& draw, IndependentCraneCase& out) {
  const double c = 0.5 * (d.coulomb_positive + d.coulomb_negative);  // [V]
  const double b = 0.5 * (d.viscous_positive + d.viscous_negative);  // [V s/m]
  const double km = d.gain;
  if (entry == "coulomb_friction_asymmetry") {
    const double dc = draw.signed_uniform(0.2, 0.5) * c;
    d.coulomb_positive += dc;
    d.coulomb_negative -= dc;
    out.main_parameter = "coulomb_asymmetry";
    out.main_value = km * dc;
  } else if (entry == "viscous_friction_asymmetry") {
    const double db = draw.signed_uniform(0.15, 0.3) * b;
    d.viscous_positive += db;
    d.viscous_negative -= db;
    out.main_parameter = "viscous_asymmetry";
    out.main_value = km * db;
  } else if (entry == "stiction") {
    d.stiction = draw.uniform(0.4, 1.0) * c;
    out.main_parameter = "stiction";
    out.main_value = km * d.stiction;
  } else if (entry == "stribeck") {
    d.stribeck_level = draw.uniform(0.4, 1.0) * c;
    d.stribeck_velocity = draw.uniform(0.02, 0.06);
    out.main_parameter = "stribeck_level";
    out.main_value = km * d.stribeck_level;
  } else if (entry == "deadzone") {
    d.deadzone = draw.uniform(0.3, 0.8) * c;
    out.main_parameter = "deadzone";
    out.main_value = d.deadzone;
  } else if (entry == "saturation") {
    out.main_parameter = "saturation";
    out.main_value = draw.uniform(0.45, 0.75);  // fraction of the nominal run's max |u| (scaled by the caller)
  } else if (entry == "backlash") {
    d.backlash = draw.uniform(0.001, 0.004);
    out.main_parameter = "backlash";
    out.main_value = d.backlash;
  } else if (entry == "input_delay") {
    d.delay = draw.uniform(0.005, 0.025);
    out.main_parameter = "input_delay";
    out.main_value = d.delay;
  } else if (entry == "gain_error") {
    d.gain_error = draw.signed_uniform(0.1, 0.3);
    out.main_parameter = "gain_error";
    out.main_value = d.gain_error;
  } else if (entry == "position_dependent_friction") {
    d.slope = draw.signed_uniform(0.3, 0.7) * c / (trolley ? 0.6 : 0.5);
    out.main_parameter = "position_friction_slope";
    out.main_value = km * d.slope;
  } else {
    throw std::invalid_argument("independent crane: unknown drive entry " + entry);
  }
}

const std::vector<std::string> kDriveEntries = {"coulomb_friction_asymmetry", "viscous_friction_asymmetry", "stiction",
                                                "stribeck", "deadzone", "saturation", "backlash", "input_delay",
                                                "gain_error", "position_dependent_friction"};

}  // namespace

const std::vector<std::string>& independent_crane_entries() {
  static const std::vector<std::string> entries = [] {
    std::vector<std::string> e;
    for (const char* prefix : {"trolley_", "slew_"}) {
      for (const auto& name : kDriveEntries) e.push_back(prefix + name);
    }
    for (const char* name : {"pendulum_viscous_damping", "pendulum_coulomb_damping", "pendulum_quadratic_damping",
                             "cable_length_error", "encoder_offset", "wind_force", "hook_double_pendulum",
                             "elastic_rope", "payload_mass_error"}) {
      e.emplace_back(name);
    }
    return e;
  }();
  return entries;
}

IndependentCraneCase independent_crane_case(const std::string& cause, std::uint64_t seed) {
  Draw draw{std::mt19937_64(seed * 6364136223846793005ULL + 1442695040888963407ULL)};
  Truth truth;
  common::CraneParameters& p = truth.crane;
  p.load_mass = draw.uniform(1.0, 3.0);
  p.cable_length = draw.uniform(0.6, 1.6);
  for (common::AxisFriction* f : {&p.trolley_friction, &p.slew_friction}) {
    for (double* v : {&f->viscous_positive, &f->viscous_negative, &f->coulomb_positive, &f->coulomb_negative,
                      &f->static_positive, &f->static_negative}) {
      *v *= draw.uniform(0.85, 1.15);
    }
  }
  p.trolley_drive_gain *= draw.uniform(0.95, 1.05);
  p.slew_drive_gain *= draw.uniform(0.95, 1.05);
  IndependentCraneCase out;
  out.cause = cause;
  common::CraneParameters nominal = p;  // told to the audit
  truth.geometry.length = p.cable_length;
  truth.drive[0] = drive_truth(p.trolley_friction, p.trolley_drive_gain, p.trolley_drive_mass);
  truth.drive[1] = drive_truth(p.slew_friction, p.slew_drive_gain, p.jib_inertia);
  const double omega2 = p.gravity / p.cable_length;
  const bool on_trolley = cause.rfind("trolley_", 0) == 0;
  const bool on_slew = cause.rfind("slew_", 0) == 0;
  if (on_trolley || on_slew) {
    const std::string entry = cause.substr(on_trolley ? 8 : 5);
    inject_drive(entry, truth.drive[on_trolley ? 0 : 1], on_trolley, draw, out);
    if (entry == "saturation") {
      set_point_masses(truth);
      const auto largest = run(truth, seed, nullptr);
      truth.drive[on_trolley ? 0 : 1].saturation = out.main_value * largest[on_trolley ? 0 : 1];
      out.main_value = truth.drive[on_trolley ? 0 : 1].saturation;
    }
  } else if (cause == "payload_mass_error") {
    const double dm = draw.signed_uniform(0.15, 0.4) * p.load_mass;
    nominal.load_mass = p.load_mass - dm;
    out.main_parameter = "load_mass_error";
    out.main_value = dm;
  } else if (cause == "pendulum_viscous_damping") {
    truth.swing.viscous = draw.uniform(0.05, 0.3);
    out.main_parameter = "extra_viscous_damping";
    out.main_value = truth.swing.viscous;
  } else if (cause == "pendulum_coulomb_damping") {
    truth.swing.coulomb = draw.uniform(0.002, 0.006) * omega2;
    out.main_parameter = "coulomb_damping";
    out.main_value = truth.swing.coulomb;
  } else if (cause == "pendulum_quadratic_damping") {
    truth.swing.quadratic = draw.uniform(0.1, 0.5);
    out.main_parameter = "quadratic_damping";
    out.main_value = truth.swing.quadratic;
  } else if (cause == "cable_length_error") {
    const double e = draw.signed_uniform(0.05, 0.15);
    truth.geometry.length = p.cable_length * (1.0 + e);
    out.main_parameter = "length_error";
    out.main_value = e;
  } else if (cause == "encoder_offset") {
    truth.swing.offset = draw.signed_uniform(0.01, 0.05);
    out.main_parameter = "encoder_offset";
    out.main_value = truth.swing.offset;
  } else if (cause == "wind_force") {
    const double force = draw.uniform(0.01, 0.05) * p.load_mass * p.gravity;
    const double heading = draw.uniform(0.0, 2.0 * std::numbers::pi);
    truth.swing.wind_x = force * std::cos(heading);
    truth.swing.wind_y = force * std::sin(heading);
    const bool x_larger = std::abs(truth.swing.wind_x) >= std::abs(truth.swing.wind_y);
    out.main_parameter = x_larger ? "wind_force_x" : "wind_force_y";
    out.main_value = x_larger ? truth.swing.wind_x : truth.swing.wind_y;
  } else if (cause == "hook_double_pendulum") {
    truth.geometry.rigging = Rigging::hook;
    truth.geometry.rigging_length = draw.uniform(0.15, 0.5);
    truth.hook_share = draw.uniform(0.1, 0.4);
    out.main_parameter = "rigging_length";
    out.main_value = truth.geometry.rigging_length;
  } else if (cause == "elastic_rope") {
    truth.geometry.rigging = Rigging::rope;
    const double ratio = draw.uniform(0.01, 0.04);
    const double ea = p.load_mass * p.gravity / ratio;  // [N]
    truth.rope_stiffness = ea / p.cable_length;
    truth.rope_damping = 2.0 * kRopeDampingRatio * std::sqrt(truth.rope_stiffness * p.load_mass);
    out.main_parameter = "rope_stretch_ratio";
    out.main_value = ratio;
  } else if (cause != "none") {
    throw std::invalid_argument("independent crane: unknown cause " + cause);
  }
  set_point_masses(truth);
  out.nominal = nominal;
  out.data.source = "independent crane (seed " + std::to_string(seed) + ") " + cause;
  run(truth, seed, &out.data);
  out.data.cable_length.assign(out.data.time.size(), p.cable_length);
  return out;
}

}  // namespace crane::model_audit::test
