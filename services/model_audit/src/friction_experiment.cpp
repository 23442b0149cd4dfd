#include "crane/model_audit/friction_experiment.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <string>

#include "crane/common/validation.hpp"

namespace crane::model_audit {

void validate(const FrictionExperimentParams& params) {
  using common::require_at_least;
  using common::require_greater;
  require_greater("motor_constant", params.motor_constant, 0.0);
  require_greater("viscous_positive", params.viscous_positive, 0.0);
  require_greater("viscous_negative", params.viscous_negative, 0.0);
  require_at_least("coulomb_positive", params.coulomb_positive, 0.0);
  require_at_least("coulomb_negative", params.coulomb_negative, 0.0);
  require_greater("proportional_gain", params.proportional_gain, 0.0);
  require_at_least("derivative_time", params.derivative_time, 0.0);
  if (params.reference.empty()) throw common::ConfigError("reference: needs at least one sinusoid");
  for (std::size_t i = 0; i < params.reference.size(); ++i) {
    const std::string prefix = "reference[" + std::to_string(i) + "].";
    common::require_finite(prefix + "amplitude", params.reference[i].amplitude);
    require_at_least(prefix + "frequency", params.reference[i].frequency, 0.0);
    common::require_finite(prefix + "phase", params.reference[i].phase);
  }
  require_greater("sample_time", params.sample_time, 0.0);
  require_greater("duration", params.duration, 2.0 * params.sample_time);
  common::require_finite("initial_position", params.initial_position);
  require_at_least("noise_standard_deviation", params.noise_standard_deviation, 0.0);
  require_at_least("encoder_quantum", params.encoder_quantum, 0.0);
}

void advance_friction_axis(const FrictionExperimentParams& params, double input, double duration, double& position,
                           double& velocity) noexcept {
  // Paper notation (3.6): x'' = K_m u - b_s x' - c_s s; b_s, c_s in physical units here.
  const double k_m = params.motor_constant;
  const double drive = k_m * input;                        // K_m u [m/s^2]
  const double b_plus = params.viscous_positive * k_m;     // [1/s]
  const double b_minus = params.viscous_negative * k_m;
  const double c_plus = params.coulomb_positive * k_m;     // [m/s^2]
  const double c_minus = params.coulomb_negative * k_m;
  double remaining = duration;
  // At most three phases per call: slide to zero, rest decision, slide the other way.
  for (int phase = 0; phase < 4 && remaining > 0.0; ++phase) {
    int direction = velocity > 0.0 ? 1 : (velocity < 0.0 ? -1 : 0);
    if (direction == 0) {
      if (drive > c_plus) {
        direction = 1;
      } else if (drive < -c_minus) {
        direction = -1;
      } else {
        return;  // held by Coulomb friction for the rest of the interval (velocity stays 0)
      }
    }
    const double b = direction > 0 ? b_plus : b_minus;
    const double acceleration_constant = drive - (direction > 0 ? c_plus : c_minus) * direction;
    const double v_inf = acceleration_constant / b;  // [m/s] the velocity this regime tends to
    // v(t) = v_inf + (v0 - v_inf) e^{-b t}; it reaches zero iff v_inf has the opposite sign, at
    // e^{-b t*} = -v_inf / (v0 - v_inf), i.e. t* = log1p(-v0 / v_inf) / b.
    double step = remaining;
    bool stops = false;
    if (v_inf * direction < 0.0) {
      const double t_stop = std::log1p(-velocity / v_inf) / b;
      if (t_stop <= remaining) {
        step = t_stop;
        stops = true;
      }
    }
    const double decayed = -std::expm1(-b * step);  // 1 - e^{-b step}
    position += v_inf * step + (velocity - v_inf) * decayed / b;
    velocity = stops ? 0.0 : v_inf + (velocity - v_inf) * (1.0 - decayed);
    remaining -= step;
  }
}

FrictionExperimentRecord simulate_friction_experiment(const FrictionExperimentParams& params) {
  validate(params);
  const auto samples = static_cast<std::size_t>(std::floor(params.duration / params.sample_time + 0.5)) + 1;
  FrictionExperimentRecord record;
  for (auto* column : {&record.time, &record.input, &record.position, &record.true_position, &record.true_velocity,
                       &record.reference}) {
    column->reserve(samples);
  }

  std::mt19937_64 generator(params.seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const auto measure = [&](double true_position) {
    double measured = true_position;
    if (params.noise_standard_deviation > 0.0) measured += params.noise_standard_deviation * noise(generator);
    if (params.encoder_quantum > 0.0) measured = params.encoder_quantum * std::round(measured / params.encoder_quantum);
    return measured;
  };
  const auto reference = [&](double t) {
    double value = 0.0;
    for (const auto& sinusoid : params.reference) {
      value += sinusoid.amplitude * std::sin(2.0 * std::numbers::pi * sinusoid.frequency * t + sinusoid.phase);
    }
    return value;
  };

  double position = params.initial_position;
  double velocity = 0.0;
  double previous_measurement = std::numeric_limits<double>::quiet_NaN();
  for (std::size_t k = 0; k < samples; ++k) {
    const double t = static_cast<double>(k) * params.sample_time;
    const double measured = measure(position);
    double velocity_feedback = velocity;
    if (params.velocity_feedback == VelocityFeedback::backward_difference) {
      velocity_feedback = k == 0 ? 0.0 : (measured - previous_measurement) / params.sample_time;
    }
    previous_measurement = measured;
    const double x_ref = reference(t);
    // (3.17): V = K (X_ref - x - K_d x')
    const double input = params.proportional_gain * (x_ref - measured - params.derivative_time * velocity_feedback);

    record.time.push_back(t);
    record.input.push_back(input);
    record.position.push_back(measured);
    record.true_position.push_back(position);
    record.true_velocity.push_back(velocity);
    record.reference.push_back(x_ref);
    advance_friction_axis(params, input, params.sample_time, position, velocity);
  }
  return record;
}

}  // namespace crane::model_audit
