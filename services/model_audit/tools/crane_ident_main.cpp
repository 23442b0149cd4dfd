// crane_ident: offline identification tools (section 3.1 of H. M. Omar, "Control of Gantry and
// Tower Cranes", Virginia Tech 2003).
//
//   crane_ident friction --data run.csv --axis x|gamma [--dead-band D] [--cutoff-hz F]
//                        [--filter-input] [--km K] [--columns t=COL,u=COL,x=COL]
//                        [--scheme centered|dissertation] [--min-samples N] [--json]
//     Identifies b+/K_m, b-/K_m, c+/K_m, c-/K_m (and K_m unless --km is given) by the least squares
//     of (3.10)-(3.14). Column defaults: t, u, x (axis x) or t, u, gamma (axis gamma).
//
//   crane_ident simulate-friction --out run.csv [--axis x|gamma] [--seed N] [--noise SIGMA]
//                        [--quantum Q] [--duration S] [--sample-time TS] [--km K] [--b-plus B]
//                        [--b-minus B] [--c-plus C] [--c-minus C] [--kp K] [--kd KD]
//                        [--exact-velocity-feedback]
//     Writes a section-3.1-like experiment (PD loop (3.17) tracking (3.18), exact integration of
//     (3.6)) as CSV: columns t, u, x (or gamma), and the simulation truth x_true, v_true, x_ref.
//
// Exit codes: 0 success; 2 input refused (unreadable or malformed data file, bad option; the
// message names the file, row and column); 3 the data cannot identify the model (too few moving
// samples, rank deficiency, non-uniform sampling); 1 anything else (e.g. a failed write).
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/model_audit/friction_experiment.hpp"
#include "crane/model_audit/friction_identification.hpp"
#include "crane/model_audit/measured_data.hpp"

namespace ma = crane::model_audit;

namespace {

constexpr int kExitInputRefused = 2;
constexpr int kExitNotIdentifiable = 3;

struct FrictionCommand {
  std::string data;
  std::string axis{"x"};
  double dead_band{0.05};
  double cutoff_hz{0.0};
  bool filter_input{false};
  std::optional<double> km;
  std::string columns;
  std::string scheme{"centered"};
  std::size_t min_samples{20};
  bool json{false};
};

struct SimulateCommand {
  std::string out;
  std::string axis{"x"};
  ma::FrictionExperimentParams params;
  bool exact_velocity_feedback{false};
};

nlohmann::json ratios_json(const ma::FrictionRatios& ratios) {
  return {{"b_plus", ratios.viscous_positive},
          {"b_minus", ratios.viscous_negative},
          {"c_plus", ratios.coulomb_positive},
          {"c_minus", ratios.coulomb_negative}};
}

int run_friction(const FrictionCommand& command) {
  const std::string position_name = command.axis;  // canonical "x" or "gamma"
  ma::CsvReadOptions read_options;
  read_options.mapping = ma::parse_column_mapping(command.columns);
  for (const auto& [canonical, file] : read_options.mapping.entries) {
    if (canonical != "t" && canonical != "u" && canonical != position_name) {
      throw crane::common::ConfigError("columns: unknown canonical name '" + canonical + "' for axis " +
                                       command.axis + " (expected t, u, " + position_name + ")");
    }
  }
  read_options.required_columns = {"t", "u", position_name};
  read_options.time_column = "t";
  read_options.minimum_samples = 3;
  const ma::TimeSeries series = ma::read_time_series_csv(command.data, read_options);

  ma::FrictionIdentificationOptions options;
  options.dead_band = command.dead_band;
  options.cutoff_frequency = command.cutoff_hz;
  options.filter_input = command.filter_input;
  options.motor_constant = command.km;
  options.scheme = command.scheme == "dissertation" ? ma::DifferenceScheme::dissertation
                                                    : ma::DifferenceScheme::centered;
  options.minimum_samples_per_direction = command.min_samples;
  const auto result = ma::identify_friction(series.column("t"), series.column("u"), series.column(position_name),
                                            options);

  if (command.json) {
    nlohmann::json out = ratios_json(result.estimate);
    out["axis"] = command.axis;
    nlohmann::json errors = ratios_json(result.standard_error);
    if (result.motor_constant) {
      out["K_m"] = *result.motor_constant;
      errors["K_m"] = *result.motor_constant_standard_error;
    }
    out["standard_errors"] = errors;
    out["samples_used"] = {{"positive", result.samples_positive},
                           {"negative", result.samples_negative},
                           {"total", result.samples_positive + result.samples_negative},
                           {"excluded", result.samples_excluded}};
    out["dead_band"] = command.dead_band;
    out["cutoff_hz"] = command.cutoff_hz;
    out["filter_input"] = command.filter_input;
    out["scheme"] = command.scheme;
    out["sample_time"] = result.sample_time;
    out["residual_rms"] = result.residual_rms;
    out["data"] = command.data;
    std::cout << out.dump(2) << '\n';
    return 0;
  }

  const bool slew = command.axis == "gamma";
  const char* velocity_unit = slew ? "rad/s" : "m/s";
  std::printf("friction identification (section 3.1), axis %s, data %s\n", command.axis.c_str(),
              command.data.c_str());
  const std::string prefilter =
      command.cutoff_hz > 0.0
          ? crane::common::format_value(command.cutoff_hz) + " Hz zero-phase Butterworth" +
                (command.filter_input ? " on x and u" : " on x")
          : std::string("none");
  std::printf("  T_s %.6g s, dead band d_s %.6g %s, prefilter %s, scheme %s\n", result.sample_time,
              command.dead_band, velocity_unit, prefilter.c_str(), command.scheme.c_str());
  std::printf("  %-22s %14s %14s\n", "parameter", "estimate", "std. error");
  const auto line = [](const char* name, double value, double error) {
    std::printf("  %-22s %14.6f %14.6f\n", name, value, error);
  };
  line(slew ? "b+/K_m [V s/rad]" : "b+/K_m [V s/m]", result.estimate.viscous_positive,
       result.standard_error.viscous_positive);
  line(slew ? "b-/K_m [V s/rad]" : "b-/K_m [V s/m]", result.estimate.viscous_negative,
       result.standard_error.viscous_negative);
  line("c+/K_m [V]", result.estimate.coulomb_positive, result.standard_error.coulomb_positive);
  line("c-/K_m [V]", result.estimate.coulomb_negative, result.standard_error.coulomb_negative);
  if (result.motor_constant) {
    line(slew ? "K_m [rad/s^2/V]" : "K_m [m/s^2/V]", *result.motor_constant, *result.motor_constant_standard_error);
  } else {
    std::printf("  %-22s %14.6f %14s\n", "K_m (given)", *command.km, "-");
  }
  std::printf("  samples used: %zu positive, %zu negative; %zu in the dead band; residual rms %.6g\n",
              result.samples_positive, result.samples_negative, result.samples_excluded, result.residual_rms);
  return 0;
}

int run_simulate(SimulateCommand command) {
  command.params.velocity_feedback =
      command.exact_velocity_feedback ? ma::VelocityFeedback::exact : ma::VelocityFeedback::backward_difference;
  const auto record = ma::simulate_friction_experiment(command.params);
  const auto& p = command.params;
  const std::string q = command.axis;
  std::vector<std::string> comments{
      "crane_ident simulate-friction: section 3.1 experiment, x'' = K_m u - b_s x' - c_s sign(x') (3.6), "
      "PD (3.17) tracking (3.18), exact integration, u held over [t_k, t_k+1)",
      "K_m=" + crane::common::format_value(p.motor_constant) +
          " b_plus=" + crane::common::format_value(p.viscous_positive) +
          " b_minus=" + crane::common::format_value(p.viscous_negative) +
          " c_plus=" + crane::common::format_value(p.coulomb_positive) +
          " c_minus=" + crane::common::format_value(p.coulomb_negative) + " (ratios to K_m, volt-equivalents)",
      "K=" + crane::common::format_value(p.proportional_gain) + " K_d=" + crane::common::format_value(p.derivative_time) +
          " T_s=" + crane::common::format_value(p.sample_time) + " noise=" +
          crane::common::format_value(p.noise_standard_deviation) + " quantum=" +
          crane::common::format_value(p.encoder_quantum) + " seed=" + std::to_string(p.seed) +
          (command.exact_velocity_feedback ? " velocity feedback exact" : " velocity feedback backward difference")};
  std::ofstream out(command.out);
  if (!out) {
    std::cerr << "crane_ident: cannot open " << command.out << " for writing\n";
    return 1;
  }
  ma::write_time_series_csv(out, comments, {"t", "u", q, q + "_true", (q == "x" ? "v" : "gamma_rate") + std::string("_true"), q + "_ref"},
                            {record.time, record.input, record.position, record.true_position, record.true_velocity,
                             record.reference});
  std::fprintf(stderr, "crane_ident: wrote %zu samples to %s\n", record.time.size(), command.out.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Offline identification (friction, section 3.1)"};
  app.require_subcommand(1);

  FrictionCommand friction;
  auto* friction_app = app.add_subcommand("friction", "identify direction-dependent viscous + Coulomb friction");
  friction_app->add_option("--data", friction.data, "CSV file: header row, numeric rows, '#' comments on top")
      ->required();
  friction_app->add_option("--axis", friction.axis, "x (trolley, [m]) | gamma (slew, [rad])")
      ->required()
      ->check(CLI::IsMember({"x", "gamma"}));
  friction_app->add_option("--dead-band", friction.dead_band, "zero-velocity band d_s [m/s] or [rad/s] (default 0.05)");
  friction_app->add_option("--cutoff-hz", friction.cutoff_hz, "zero-phase Butterworth prefilter cutoff [Hz]; 0 = none");
  friction_app->add_flag("--filter-input", friction.filter_input, "prefilter u with the same filter");
  friction_app->add_option("--km", friction.km, "known motor constant K_m; if absent K_m is identified");
  friction_app->add_option("--columns", friction.columns, "canonical=file column map, e.g. t=t_s,u=vir_V,x=qm_m");
  friction_app->add_option("--scheme", friction.scheme, "centered (default) | dissertation (3.10)-(3.11) as printed")
      ->check(CLI::IsMember({"centered", "dissertation"}));
  friction_app->add_option("--min-samples", friction.min_samples, "minimum regression rows per direction (default 20)");
  friction_app->add_flag("--json", friction.json, "print JSON instead of a table");

  SimulateCommand simulate;
  auto& p = simulate.params;
  auto* simulate_app = app.add_subcommand("simulate-friction", "write a section-3.1-like experiment as CSV");
  simulate_app->add_option("--out", simulate.out, "output CSV file")->required();
  simulate_app->add_option("--axis", simulate.axis, "name of the position column: x | gamma")
      ->check(CLI::IsMember({"x", "gamma"}));
  simulate_app->add_option("--seed", p.seed, "noise seed");
  simulate_app->add_option("--noise", p.noise_standard_deviation, "position noise standard deviation [m]");
  simulate_app->add_option("--quantum", p.encoder_quantum, "encoder quantum [m]; 0 = none");
  simulate_app->add_option("--duration", p.duration, "[s] (default 24)");
  simulate_app->add_option("--sample-time", p.sample_time, "T_s [s] (default 0.01)");
  simulate_app->add_option("--km", p.motor_constant, "K_m (default 1.7)");
  simulate_app->add_option("--b-plus", p.viscous_positive, "b+/K_m (default 2.8)");
  simulate_app->add_option("--b-minus", p.viscous_negative, "b-/K_m (default 5.5)");
  simulate_app->add_option("--c-plus", p.coulomb_positive, "c+/K_m (default 1.0)");
  simulate_app->add_option("--c-minus", p.coulomb_negative, "c-/K_m (default 1.2)");
  simulate_app->add_option("--kp", p.proportional_gain, "PD gain K (default 100)");
  simulate_app->add_option("--kd", p.derivative_time, "PD derivative time K_d (default 0.2)");
  simulate_app->add_flag("--exact-velocity-feedback", simulate.exact_velocity_feedback,
                         "PD uses the true velocity instead of a backward difference");

  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    std::cerr << "crane_ident: " << error.what() << "\n";
    return kExitInputRefused;
  }

  try {
    if (friction_app->parsed()) return run_friction(friction);
    return run_simulate(simulate);
  } catch (const ma::DataError& error) {
    std::cerr << "crane_ident: " << error.what() << "\n";
    return kExitInputRefused;
  } catch (const crane::common::ConfigError& error) {
    std::cerr << "crane_ident: " << error.what() << "\n";
    return kExitInputRefused;
  } catch (const ma::IdentificationError& error) {
    std::cerr << "crane_ident: " << error.what() << "\n";
    return kExitNotIdentifiable;
  } catch (const std::exception& error) {
    std::cerr << "crane_ident: " << error.what() << "\n";
    return 1;
  }
}
