#include "crane/tracking/friction_momentum_balance.hpp"

#include <cmath>

#include "crane/common/validation.hpp"

namespace crane::tracking {

void FrictionMomentumBalance::Chain::initialize(double value) noexcept {
  low_pass.initialize(value, value * low_pass.coefficients().dc_gain());
  lag.initialize(value, value * lag.coefficients().dc_gain());
  last = before_last = value * low_pass.coefficients().dc_gain() * lag.coefficients().dc_gain();
}

double FrictionMomentumBalance::Chain::update(double value) noexcept {
  const double filtered = lag.update(low_pass.update(value));
  const double delayed = 0.5 * (last + before_last);  // (z^-1 + z^-2) / 2
  before_last = last;
  last = filtered;
  return delayed;
}

FrictionMomentumBalance::FrictionMomentumBalance(const state_estimator::DiscreteTransferFunction& low_pass,
                                                 const state_estimator::DiscreteTransferFunction& differentiator_lag,
                                                 double sample_period, int block_cycles)
    : voltage_{state_estimator::DiscreteFilter(low_pass), state_estimator::DiscreteFilter(differentiator_lag)},
      friction_{state_estimator::DiscreteFilter(low_pass), state_estimator::DiscreteFilter(differentiator_lag)},
      sample_period_(sample_period),
      block_cycles_(block_cycles) {
  common::require_greater("friction_momentum_balance.sample_period", sample_period, 0.0);
  common::require_finite("friction_momentum_balance.sample_period", sample_period);
  common::require_in_range("friction_momentum_balance.block_cycles", block_cycles, 1, 100000);
  for (const auto* tf : {&low_pass, &differentiator_lag}) {
    const double coefficients[] = {tf->b0, tf->b1, tf->b2, tf->a1, tf->a2, tf->dc_gain()};
    for (const double c : coefficients) common::require_finite("friction_momentum_balance.filter coefficient", c);
  }
}

std::optional<FrictionMomentumBalance::Row> FrictionMomentumBalance::step(double voltage, double friction,
                                                                          double momentum, bool sliding) noexcept {
  if (!std::isfinite(voltage) || !std::isfinite(friction) || !std::isfinite(momentum)) {
    started_ = false;
    open_ = false;
    return std::nullopt;
  }
  if (!started_) {
    voltage_.initialize(voltage);
    friction_.initialize(friction);
    last_momentum_ = momentum;
    started_ = true;
  }
  const double u = voltage_.update(voltage);
  const double f = friction_.update(friction);
  std::optional<Row> row;
  if (sliding) {
    if (!open_) {  // from the cycle before the stretch's first
      open_ = true;
      start_momentum_ = last_momentum_;
      voltage_sum_ = friction_sum_ = 0.0;
      cycles_ = 0;
    }
    voltage_sum_ += u * sample_period_;
    friction_sum_ += f * sample_period_;
    if (++cycles_ >= block_cycles_) {
      row = Row{voltage_sum_ - (momentum - start_momentum_), friction_sum_};
      start_momentum_ = momentum;
      voltage_sum_ = friction_sum_ = 0.0;
      cycles_ = 0;
    }
  } else if (open_) {  // the stretch ended with the last cycle
    if (cycles_ > 0) row = Row{voltage_sum_ - (last_momentum_ - start_momentum_), friction_sum_};
    open_ = false;
  }
  last_momentum_ = momentum;
  return row;
}

}  // namespace crane::tracking
