#include "crane/anti_swing_analysis/characteristic_equation.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace crane::anti_swing_analysis {
namespace {

using Complex = std::complex<double>;
using Poly = std::vector<double>;  // ascending powers

Poly multiply(const Poly& lhs, const Poly& rhs) {
  Poly product(lhs.size() + rhs.size() - 1, 0.0);
  for (std::size_t i = 0; i < lhs.size(); ++i)
    for (std::size_t j = 0; j < rhs.size(); ++j) product[i + j] += lhs[i] * rhs[j];
  return product;
}

Poly add(Poly lhs, const Poly& rhs) {
  if (lhs.size() < rhs.size()) lhs.resize(rhs.size(), 0.0);
  for (std::size_t i = 0; i < rhs.size(); ++i) lhs[i] += rhs[i];
  return lhs;
}

// Roots of the polynomial p (ascending powers, nonzero leading coefficient) as companion-matrix
// eigenvalues.
std::vector<Complex> polynomial_roots(const Poly& p) {
  const int n = static_cast<int>(p.size()) - 1;
  Eigen::MatrixXd companion = Eigen::MatrixXd::Zero(n, n);
  for (int i = 1; i < n; ++i) companion(i, i - 1) = 1.0;
  for (int i = 0; i < n; ++i) companion(i, n - 1) = -p[static_cast<std::size_t>(i)] / p.back();
  const Eigen::VectorXcd eigenvalues = Eigen::EigenSolver<Eigen::MatrixXd>(companion, false).eigenvalues();
  std::vector<Complex> roots(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) roots[static_cast<std::size_t>(i)] = eigenvalues[i];
  return roots;
}

bool has_delay(const LawPoint& point) { return point.law != AntiSwingLaw::pd && point.second > 0.0; }

bool has_filter(const TrackingLoop& loop) { return loop.swing_filter_cutoff > 0.0; }

void check_filter(const TrackingLoop& loop) {
  if (!(loop.swing_filter_cutoff >= 0.0) || !std::isfinite(loop.swing_filter_cutoff))
    throw std::invalid_argument("swing_filter_cutoff must be finite and >= 0");
}

// The filter's denominator over w_c^2, in ascending powers of s: 1 + sqrt(2) s/w_c + s^2/w_c^2.
Poly filter_denominator(const TrackingLoop& loop) {
  if (!has_filter(loop)) return {1.0};
  const double w = loop.swing_filter_cutoff;
  return {1.0, std::sqrt(2.0) / w, 1.0 / (w * w)};
}

// Feedback numerator N(s) in "- s^2 N(s) e^{-tau s}" (ascending powers, in s).
Poly feedback_numerator(const LawPoint& point, const TrackingLoop& loop) {
  switch (point.law) {
    case AntiSwingLaw::pd:
      return {point.first, point.second};  // K_ps + K_ds s (3.46)
    case AntiSwingLaw::delayed_feedback:
      return {point.first};  // K_del (3.47)
    case AntiSwingLaw::delayed_trajectory_correction:
      return {point.first * loop.proportional_gain, point.first * loop.derivative_gain};  // (3.50)
  }
  return {0.0};
}

}  // namespace

std::string_view law_name(AntiSwingLaw law) noexcept {
  switch (law) {
    case AntiSwingLaw::pd: return "pd";
    case AntiSwingLaw::delayed_feedback: return "delay1";
    case AntiSwingLaw::delayed_trajectory_correction: return "delay2";
  }
  return "?";
}

std::string_view first_parameter_name(AntiSwingLaw law) noexcept {
  return law == AntiSwingLaw::pd ? "K_ps" : "K_del";
}

std::string_view second_parameter_name(AntiSwingLaw law) noexcept {
  return law == AntiSwingLaw::pd ? "K_ds" : "tau_del";
}

std::vector<Complex> pade_roots(const LawPoint& point, const TrackingLoop& loop, int pade_order) {
  if (pade_order < 1) throw std::invalid_argument("pade_order must be >= 1");
  if (point.law != AntiSwingLaw::pd && !(point.second >= 0.0))
    throw std::invalid_argument("tau_del must be >= 0");
  check_filter(loop);
  // State-space realization whose characteristic polynomial is the Pade form: states
  // [x_bar, x_bar', phi, phi', (p, p'), z_1..z_l]; p is the filtered swing when the loop has a
  // filter (p'' = w_c^2 (phi - p) - sqrt(2) w_c p'); the delay is a cascade of l all-pass sections
  // (1 - c s)/(1 + c s) = -1 + 2/(1 + c s): c z_k' = -z_k + v_{k-1}, v_k = 2 z_k - v_{k-1}, v_0 = p
  // (phi without a filter). Rows are linear forms in the states; v_k' is tracked too for (3.50),
  // which feeds the derivative of the delayed swing through K_dx.
  const bool delayed = has_delay(point);
  const bool filtered = has_filter(loop);
  const int l = delayed ? pade_order : 0;
  const int f = filtered ? 2 : 0;
  const int n = 4 + f + l;
  const double a = loop.swing_stiffness;
  const double k_px = loop.proportional_gain;
  const double k_dx = loop.derivative_gain;
  Eigen::MatrixXd system = Eigen::MatrixXd::Zero(n, n);
  auto unit = [n](int index) {
    Eigen::RowVectorXd row = Eigen::RowVectorXd::Zero(n);
    row(index) = 1.0;
    return row;
  };
  Eigen::RowVectorXd measured_value = unit(2);       // what the law sees: phi, or p when filtered
  Eigen::RowVectorXd measured_derivative = unit(3);
  if (filtered) {
    const double w = loop.swing_filter_cutoff;
    system(4, 5) = 1.0;
    system.row(5) = w * w * (unit(2) - unit(4)) - std::sqrt(2.0) * w * unit(5);
    measured_value = unit(4);
    measured_derivative = unit(5);
  }
  Eigen::RowVectorXd delayed_value = measured_value;            // v_0
  Eigen::RowVectorXd delayed_derivative = measured_derivative;  // v_0'
  if (delayed) {
    const double c = point.second / (2.0 * pade_order);
    for (int k = 0; k < l; ++k) {
      const int state = 4 + f + k;
      const Eigen::RowVectorXd z_rate = (delayed_value - unit(state)) / c;
      system.row(state) = z_rate;
      delayed_value = 2.0 * unit(state) - delayed_value;
      delayed_derivative = 2.0 * z_rate - delayed_derivative;
    }
  }
  Eigen::RowVectorXd acceleration = -k_px * unit(0) - k_dx * unit(1);  // tracking PD (3.40)
  switch (point.law) {
    case AntiSwingLaw::pd:
      acceleration += point.first * measured_value + point.second * measured_derivative;  // (3.45)
      break;
    case AntiSwingLaw::delayed_feedback:
      acceleration += point.first * delayed_value;  // (3.47)
      break;
    case AntiSwingLaw::delayed_trajectory_correction:
      acceleration += point.first * (k_px * delayed_value + k_dx * delayed_derivative);  // (3.50)
      break;
  }
  system(0, 1) = 1.0;
  system.row(1) = acceleration;
  system(2, 3) = 1.0;
  system.row(3) = acceleration - a * unit(2);  // phi'' = x_bar'' - a phi (our convention)
  const Eigen::VectorXcd eigenvalues = Eigen::EigenSolver<Eigen::MatrixXd>(system, false).eigenvalues();
  std::vector<Complex> roots(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) roots[static_cast<std::size_t>(i)] = eigenvalues[i];
  return roots;
}

std::vector<Complex> pade_roots_companion(const LawPoint& point, const TrackingLoop& loop, int pade_order) {
  if (pade_order < 1) throw std::invalid_argument("pade_order must be >= 1");
  if (point.law != AntiSwingLaw::pd && !(point.second >= 0.0))
    throw std::invalid_argument("tau_del must be >= 0");
  check_filter(loop);
  const double a = loop.swing_stiffness;
  const double k_px = loop.proportional_gain;
  const double k_dx = loop.derivative_gain;
  const Poly numerator = feedback_numerator(point, loop);
  const Poly filter = filter_denominator(loop);  // D(s), 1 without a filter
  if (!has_delay(point)) {
    // (s^2 + a)(s^2 + K_dx s + K_px) D(s) - s^2 N(s)
    const Poly open = multiply(multiply(Poly{a, 0.0, 1.0}, Poly{k_px, k_dx, 1.0}), filter);
    return polynomial_roots(add(open, multiply(Poly{0.0, 0.0, -1.0}, numerator)));
  }
  // Pade (3.49), c = tau/(2l), in w = c s, times c^4:
  //   (w^2 + a c^2)(w^2 + K_dx c w + K_px c^2) D(w/c) (1 + w)^l - w^2 c^2 N(w/c) (1 - w)^l = 0.
  const double c = point.second / (2.0 * pade_order);
  Poly scaled_filter(filter.size());  // D(w/c)
  for (std::size_t i = 0; i < filter.size(); ++i) scaled_filter[i] = filter[i] / std::pow(c, static_cast<double>(i));
  Poly lead{1.0};
  Poly lag{1.0};
  for (int i = 0; i < pade_order; ++i) {
    lead = multiply(lead, Poly{1.0, 1.0});
    lag = multiply(lag, Poly{1.0, -1.0});
  }
  const Poly open =
      multiply(multiply(multiply(Poly{a * c * c, 0.0, 1.0}, Poly{k_px * c * c, k_dx * c, 1.0}), scaled_filter), lead);
  Poly scaled_numerator(numerator.size());  // c^2 N(w/c)
  for (std::size_t i = 0; i < numerator.size(); ++i)
    scaled_numerator[i] = numerator[i] * std::pow(c, 2.0 - static_cast<double>(i));
  const Poly feedback = multiply(multiply(Poly{0.0, 0.0, -1.0}, scaled_numerator), lag);
  std::vector<Complex> roots = polynomial_roots(add(open, feedback));
  for (Complex& root : roots) root /= c;
  return roots;
}

CharacteristicValue characteristic_function(const LawPoint& point, const TrackingLoop& loop,
                                            Complex s) noexcept {
  const double a = loop.swing_stiffness;
  const double k_px = loop.proportional_gain;
  const double k_dx = loop.derivative_gain;
  const Complex swing = s * s + a;
  const Complex tracking = s * s + k_dx * s + k_px;
  Complex numerator{0.0};
  Complex numerator_derivative{0.0};
  double tau = 0.0;
  switch (point.law) {
    case AntiSwingLaw::pd:
      numerator = point.first + point.second * s;
      numerator_derivative = point.second;
      break;
    case AntiSwingLaw::delayed_feedback:
      numerator = point.first;
      tau = point.second;
      break;
    case AntiSwingLaw::delayed_trajectory_correction:
      numerator = point.first * (k_dx * s + k_px);
      numerator_derivative = point.first * k_dx;
      tau = point.second;
      break;
  }
  // D(s) = 1 + sqrt(2) s/w_c + s^2/w_c^2 (1 without a filter; a negative or NaN cut-off gives NaN).
  Complex filter{1.0};
  Complex filter_derivative{0.0};
  if (loop.swing_filter_cutoff != 0.0) {
    const double w = loop.swing_filter_cutoff;
    filter = 1.0 + std::sqrt(2.0) * s / w + s * s / (w * w);
    filter_derivative = std::sqrt(2.0) / w + 2.0 * s / (w * w);
    if (!(w > 0.0)) filter = filter_derivative = {std::numeric_limits<double>::quiet_NaN(), 0.0};
  }
  const Complex delay = std::exp(-tau * s);
  const Complex open = swing * tracking;
  const Complex open_derivative = 2.0 * s * tracking + swing * (2.0 * s + k_dx);
  CharacteristicValue result;
  result.value = open * filter - s * s * numerator * delay;
  result.derivative = open_derivative * filter + open * filter_derivative -
                      (2.0 * s * numerator + s * s * numerator_derivative - tau * s * s * numerator) * delay;
  return result;
}

Complex newton_root(const LawPoint& point, const TrackingLoop& loop, Complex seed) noexcept {
  Complex s = seed;
  for (int iteration = 0; iteration < 60; ++iteration) {
    const CharacteristicValue f = characteristic_function(point, loop, s);
    if (!(std::abs(f.derivative) > 0.0)) break;
    const Complex step = f.value / f.derivative;
    s -= step;
    if (std::abs(step) <= 1e-13 * std::max(1.0, std::abs(s))) {
      const double scale = std::pow(std::max(1.0, std::abs(s)), 4.0);
      if (std::abs(characteristic_function(point, loop, s).value) <= 1e-9 * scale) return s;
      break;
    }
  }
  const double nan = std::numeric_limits<double>::quiet_NaN();
  return {nan, nan};
}

DominantPair dominant_pair(const std::vector<Complex>& roots) noexcept {
  DominantPair pair;
  pair.damping = std::numeric_limits<double>::quiet_NaN();
  pair.stable = true;
  double best_real = -std::numeric_limits<double>::infinity();
  for (const Complex& root : roots) {
    if (!std::isfinite(root.real()) || !std::isfinite(root.imag())) continue;
    if (root.real() > 1e-9) pair.stable = false;
    const bool complex_root = std::abs(root.imag()) > 1e-6 * std::max(1.0, std::abs(root));
    if (complex_root && root.real() > best_real) {
      best_real = root.real();
      pair.pole = {root.real(), std::abs(root.imag())};
      pair.found = true;
    }
  }
  if (pair.found) pair.damping = -pair.pole.real() / std::abs(pair.pole);
  return pair;
}

DampingEvaluation evaluate_damping(const LawPoint& point, const TrackingLoop& loop, int pade_order) {
  DampingEvaluation evaluation;
  std::vector<Complex> roots = pade_roots(point, loop, pade_order);
  evaluation.pade = dominant_pair(roots);
  // Seeds: the upper-half-plane and real Pade roots, rightmost first; refine the 8 rightmost
  // (the far-left ones are the Pade chain, which the exact equation continues to -infinity).
  std::vector<Complex> seeds;
  for (const Complex& root : roots)
    if (root.imag() >= 0.0) seeds.push_back(root);
  std::sort(seeds.begin(), seeds.end(), [](Complex lhs, Complex rhs) { return lhs.real() > rhs.real(); });
  if (seeds.size() > 8) seeds.resize(8);
  std::vector<Complex> refined;
  refined.reserve(seeds.size());
  for (const Complex& seed : seeds) refined.push_back(newton_root(point, loop, seed));
  evaluation.direct_independent = dominant_pair(refined);
  evaluation.direct = evaluation.pade;
  if (evaluation.pade.found) {
    const Complex exact = newton_root(point, loop, evaluation.pade.pole);
    evaluation.direct.pole = {exact.real(), std::abs(exact.imag())};
    evaluation.direct.damping = -exact.real() / std::abs(exact);  // NaN if Newton failed
    evaluation.direct.stable = evaluation.direct_independent.stable;
  }
  return evaluation;
}

}  // namespace crane::anti_swing_analysis
