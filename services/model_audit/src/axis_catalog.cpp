// The axis catalog: every candidate cause of the axis model in one table (axis_audit.hpp). The
// model terms are those of audit_models.hpp; each entry's parameters are reported under their
// ParameterSpec names. Grids and bounds scale with the record (AxisScales).
#include <algorithm>
#include <cmath>

#include "axis_audit.hpp"

namespace crane::model_audit::detail {

const std::vector<AxisCause>& axis_catalog() {
  using S = AxisScales;
  using T = AxisTerms;
  using R = AxisRegressorSample;
  static const std::vector<AxisCause> catalog{
      {.name = "coulomb_friction_asymmetry",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"coulomb_asymmetry", "m/s^2", s.c_scale, -10 * s.c_scale, 10 * s.c_scale,
                  linspace(-s.c_scale, s.c_scale, 41)}};
       },
       .apply = [](const double* p, T& t) { t.model.coulomb_asymmetry += p[0]; },
       .regressor = [](const R&) { return 1.0; }},
      {.name = "viscous_friction_asymmetry",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"viscous_asymmetry", "1/s", s.b_scale, -s.b_scale, s.b_scale,
                  linspace(-0.6 * s.b_scale, 0.6 * s.b_scale, 41)}};
       },
       .apply = [](const double* p, T& t) { t.model.viscous_asymmetry += p[0]; },
       .regressor = [](const R& r) { return std::abs(r.velocity); }},
      {.name = "stiction",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"stiction", "m/s^2", s.c_scale, 0.0, 20 * s.c_scale, linspace(0.05 * s.c_scale, 2.5 * s.c_scale, 120)}};
       },
       .apply = [](const double* p, T& t) { t.model.stiction += std::max(p[0], 0.0); },
       .breakaway_threshold = true},
      {.name = "stribeck",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"stribeck_level", "m/s^2", s.c_scale, 0.0, 20 * s.c_scale, linspace(0.1 * s.c_scale, 2.0 * s.c_scale, 20)},
                 {"stribeck_velocity", "m/s", 0.05, 0.002, 0.5, {0.005, 0.01, 0.015, 0.02, 0.03, 0.045, 0.07, 0.1, 0.15}}};
       },
       .apply =
           [](const double* p, T& t) {
             t.model.stribeck_level = std::max(p[0], 0.0);
             t.model.stribeck_velocity = std::max(p[1], 1e-6);
           },
       .substeps = true,
       // v_s at or below half the speed that the Coulomb level's acceleration gives in one sample
       // (c T / 2): the drop is over within the first sample after a breakaway, so the sampled
       // record sees a breakaway excess, the stiction signature.
       .limit_of = "stiction",
       .limit_parameter = 1,
       .limit_value = [](const S& s) { return 0.5 * s.c_scale * s.sample_time; }},
      {.name = "deadzone",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"deadzone", "V", s.volt, 0.0, s.max_input, linspace(0.05 * s.volt, 2.0 * s.volt, 80)}};
       },
       .apply = [](const double* p, T& t) { t.model.deadzone = std::max(p[0], 0.0); }},
      {.name = "saturation",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"saturation", "V", s.max_input, 0.02 * s.max_input, s.max_input,
                  linspace(0.2 * s.max_input, 0.99 * s.max_input, 80)}};
       },
       .apply = [](const double* p, T& t) { t.model.saturation = std::max(p[0], 1e-9); }},
      {.name = "backlash",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"backlash", "m", 0.005 * s.range, 0.0, 0.2 * s.range, linspace(0.0005 * s.range, 0.02 * s.range, 80)}};
       },
       .apply = [](const double* p, T& t) { t.model.backlash = std::max(p[0], 0.0); },
       .gap_state = true,
       .effort_channel = false},
      {.name = "input_delay",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         return {{"input_delay", "s", s.sample_time, 0.0, 30 * s.sample_time,
                  linspace(0.1 * s.sample_time, 5 * s.sample_time, 80)}};
       },
       .apply = [](const double* p, T& t) { t.model.input_delay = std::max(p[0], 0.0); }},
      // Regressor -K_m u against K_m (1 + g) u - ...: residual(g) = y + g K_m u, so theta = -g.
      {.name = "gain_error",
       .parameters = [](const S&) -> std::vector<ParameterSpec> {
         return {{"gain_error", "-", 0.1, -0.9, 3.0, linspace(-0.5, 0.5, 41)}};
       },
       .apply = [](const double* p, T& t) { t.model.gain_error = std::max(p[0], -0.99); },
       .regressor = [](const R& r) { return -r.drive; },
       .regressor_factor = -1.0,
       .calibration_note = "absorbed by the calibrated K_m"},
      {.name = "position_dependent_friction",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         const double slope = s.c_scale / s.half_range;
         return {{"position_friction_slope", "m/s^2/m", slope, -10 * s.c_scale / s.half_range,
                  10 * s.c_scale / s.half_range, linspace(-slope, slope, 41)}};
       },
       .apply = [](const double* p, T& t) { t.model.position_friction = p[0]; },
       .regressor = [](const R& r) { return r.sign * r.position; },
       .substeps = true},
      // The load mass of a crane drive: I and C of the row are affine in it (model_audit.hpp).
      {.name = "payload_mass_error",
       .parameters = [](const S& s) -> std::vector<ParameterSpec> {
         const double m = std::max(s.load_mass, 0.1);
         return {{"load_mass_error", "kg", 0.2 * m, -0.95 * s.load_mass, 5.0 * m, linspace(-0.6 * m, 0.6 * m, 49)}};
       },
       .apply = [](const double* p, T& t) { t.load_mass_error = p[0]; },
       .regressor = [](const R& r) { return r.mass_term; },
       .crane_drive_only = true},
  };
  return catalog;
}

}  // namespace crane::model_audit::detail
