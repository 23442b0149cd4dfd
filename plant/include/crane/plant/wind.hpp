#pragma once
// Wind as a horizontal force on the load (config plant.wind; beyond the dissertation): a mean force
// plus gusts, each horizontal component of the gusts a first-order Gauss-Markov (Ornstein-Uhlenbeck)
// process with standard deviation gust_force_std and correlation time gust_time_constant, sampled
// exactly at the sample period and held over each sample (the plant's zero-order hold):
//   g[k+1] = a g[k] + sqrt(1 - a^2) sigma n[k],  a = exp(-T_s / tau),  n[k] ~ N(0, 1)
// (the exact discretization of dg = -g/tau dt + sigma sqrt(2/tau) dW; e.g. Gillespie, "Exact numerical
// simulation of the Ornstein-Uhlenbeck process", Phys. Rev. E 54, 1996), started at g[0] = 0. The
// random numbers come from std::mt19937_64 seeded with `seed`: the same seed gives the same forces
// (on one standard library: std::normal_distribution is implementation-defined across libraries).
//
// The force acts on the load's centre of mass, in the inertial frame (x along the jib at slew 0,
// y to its left, as common::Site); CraneDynamics::load_force turns it into generalized forces.

#include <cstdint>
#include <random>
#include <string>

namespace crane::plant {

struct WindParameters {
  bool enabled{false};
  double mean_force_x{0.0};        // [N] inertial x, |.| <= 1e4
  double mean_force_y{0.0};        // [N] inertial y, |.| <= 1e4
  double gust_force_std{0.0};      // [N] per component, in [0, 1e4]
  double gust_time_constant{2.0};  // [s] in [0.01, 1e4]
  std::uint64_t seed{1};           // random stream of the gusts
};
/// Throws common::ConfigError naming `prefix` + field, the value and the bound (checked when enabled).
void validate(const WindParameters& wind, const std::string& prefix);

/// The force sequence. Constructed from validated parameters; force() and advance() are noexcept and
/// allocation-free.
class WindForce {
 public:
  /// `sample_period` [s] > 0. Throws common::ConfigError (validate()).
  WindForce(const WindParameters& wind, double sample_period);
  /// Back to sample 0 (gusts 0, the random stream restarted from the seed).
  void reset() noexcept;
  /// Force of the current sample [N], inertial frame; (0, 0) when disabled.
  [[nodiscard]] double force_x() const noexcept { return wind_.enabled ? wind_.mean_force_x + gust_x_ : 0.0; }
  [[nodiscard]] double force_y() const noexcept { return wind_.enabled ? wind_.mean_force_y + gust_y_ : 0.0; }
  /// To the next sample.
  void advance() noexcept;

 private:
  WindParameters wind_;
  double decay_{0.0};       // a [-]
  double innovation_{0.0};  // sqrt(1 - a^2) sigma [N]
  std::mt19937_64 random_;
  std::normal_distribution<double> normal_{0.0, 1.0};
  double gust_x_{0.0};
  double gust_y_{0.0};
};

}  // namespace crane::plant
