#pragma once
// The friction one drive meets along a move, from the balance of the crane's generalized momentum
// (docs/optimal_control.md, "The friction factor under delay1"): the PD law's rows for
// FrictionFactorEstimate.
//
// Lagrange's equation of the drive's coordinate, integrated over a stretch of cycles k0 < k <= k1 on
// which the drive slides, in volt-seconds (TrackingOutput's momenta: p over the drive's force per
// volt):
//   p(k1) - p(k0) = T sum_k [u(k) + c(k) + (s(k) - theta_0) F(k)] + e
// with u the law's voltage, c dT/dx over the force per volt (the trolley's; 0 on the slew), F the
// model's sliding friction (3.1) at the reference speed [V], s the share of it the compensation added
// beyond the model's because of the factor it was handed (friction_factor_estimate.hpp) and f =
// 1 + theta_0 the plant's friction over the model's. The compensation adds the model's F on the
// measured speed, so u carries only what the model gets wrong. One row per block of
// `block_cycles` cycles (and one for a stretch's rest):
//   y = T sum_k H[u + c + s F](k) - (p(k1) - p(k0)),   phi = T sum_k H[F](k),   y = theta_0 phi + e.
// H is why the balance closes on the estimate's momenta: the estimate's rates are the true ones
// through the estimator's low-pass B(z) and its differentiator's lag G(z)
// (state_estimator::differentiator_lag), one and a half cycles late (the command of cycle k drives the
// plant through the next cycle; the rate of two samples a cycle apart is the rate half a cycle
// before the later one). So the voltage side runs through the same H(z) = B(z) G(z) (z^-1 + z^-2)/2
// before it is summed, and both sides lag alike. On the simulated site's nominal moves (docs) the
// rows without H gave f 0.86-1.01 (median 0.98) where the plant's is 1; with it 0.99-1.02.
//
// Real-time: step() is noexcept and allocates nothing. Errors: the constructor throws
// common::ConfigError naming the field, the value and the bound.

#include <optional>

#include "crane/state_estimator/discrete_filter.hpp"

namespace crane::tracking {

class FrictionMomentumBalance {
 public:
  struct Row {
    double balance;   // [V s] y
    double friction;  // [V s] phi
  };

  /// `low_pass` B and `differentiator_lag` G of the estimator whose rates the momenta come from,
  /// `sample_period` T [s] > 0, `block_cycles` [-] in [1, 100000].
  FrictionMomentumBalance(const state_estimator::DiscreteTransferFunction& low_pass,
                          const state_estimator::DiscreteTransferFunction& differentiator_lag, double sample_period,
                          int block_cycles);

  /// One cycle, every cycle (the filters run on): `voltage` u + c + s F [V], `friction` F [V] (0 where
  /// the reference rests), `momentum` p [V s] of this cycle's estimate, `sliding` whether the cycle
  /// belongs to a stretch. Returns a row when a block closes: `block_cycles` sliding cycles, or the
  /// first cycle that does not slide after some. A non-finite input drops the open block (and
  /// restarts the filters on the next finite one).
  [[nodiscard]] std::optional<Row> step(double voltage, double friction, double momentum, bool sliding) noexcept;

  /// Drops the open block (a new move: its rows start afresh).
  void drop_block() noexcept { open_ = false; }

 private:
  struct Chain {  // H(z) on one signal
    state_estimator::DiscreteFilter low_pass;
    state_estimator::DiscreteFilter lag;
    double last{0.0};
    double before_last{0.0};
    void initialize(double value) noexcept;
    double update(double value) noexcept;
  };
  Chain voltage_;
  Chain friction_;
  double sample_period_;
  int block_cycles_;
  bool started_{false};
  bool open_{false};
  int cycles_{0};
  double start_momentum_{0.0};
  double last_momentum_{0.0};
  double voltage_sum_{0.0};
  double friction_sum_{0.0};
};

}  // namespace crane::tracking
