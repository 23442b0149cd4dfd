// crane_audit: model audit of measured data against a nominal model (model_audit.hpp).
//
//   crane_audit --model crane|axis|pendulum --data measured.csv [--config nominal.yaml]
//               [--param NAME=VALUE ...] [--calibrate] [--columns t=COL,u=COL,x=COL ...] [--cause NAME ...]
//               [--channel position|effort] [--holdout F] [--window S] [--dead-band V] [--max-rate HZ]
//               [--t-min S] [--t-max S] [--plot] --out DIR
//   crane_audit generate --model crane|axis|pendulum --effect NAME|none|random|NAME+NAME --seed N --out FILE.csv
//     Writes a hidden-effect test case (hidden_effect_generator.hpp); the nominal parameters and
//     the truth go into the comment line.
//
// Axis: x'' = K_m u - b x' - c sign(x') (3.6), params K_m [m/s^2/V], b [1/s], c [m/s^2]; columns
// t [s], u [V], x [m]. Pendulum: params L [m], damping [1/s], theta_zero [rad] (the measured angle
// of hanging straight down, e.g. --param theta_zero=3.14159; omitted = estimated), gravity;
// columns t, theta [rad], optional x [m] (trolley) and segment (maneuver id). Crane: columns t, u_x,
// u_gamma [V], x [m], gamma, phi, theta [rad], L [m]; nominal parameters from --config (the stack's
// YAML, crane section, loaded by crane::config) and --param (names: audit_parameter_names(crane),
// e.g. --param load_mass=2.4); every parameter is required, so give --config or all of them.
// --config for axis: the trolley drive (K_m, b, c and the nominal asymmetries). --calibrate for
// the crane fits each drive's gain, viscous and Coulomb friction first (report.json "nominal" gives
// them in the configuration's terms).
// Exit codes: 0 success; 2 input refused (message names the file, row, column, option or cause);
// 1 anything else.
#include <CLI/CLI.hpp>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/config/config_document.hpp"
#include "crane/model_audit/audit_report.hpp"
#include "crane/model_audit/hidden_effect_generator.hpp"
#include "crane/model_audit/measured_data.hpp"
#include "crane/model_audit/model_audit.hpp"

namespace ma = crane::model_audit;

namespace {

constexpr int kExitInputRefused = 2;

ma::AuditPlant parse_plant(const std::string& name) {
  if (name == "axis") return ma::AuditPlant::axis;
  if (name == "pendulum") return ma::AuditPlant::pendulum;
  if (name == "crane") return ma::AuditPlant::crane;
  throw crane::common::ConfigError("model: '" + name + "' is not a model (valid: crane, axis, pendulum)");
}

std::map<std::string, double> parse_parameters(const std::vector<std::string>& entries) {
  std::map<std::string, double> out;
  for (const auto& entry : entries) {
    const auto eq = entry.find('=');
    if (eq == std::string::npos || eq == 0 || eq + 1 == entry.size()) {
      throw crane::common::ConfigError("param: '" + entry + "' is not NAME=VALUE");
    }
    const std::string name = entry.substr(0, eq);
    const std::string text = entry.substr(eq + 1);
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (end == text.c_str() || *end != '\0') {
      throw crane::common::ConfigError("param " + name + ": cannot parse '" + text + "' as a number");
    }
    if (out.contains(name)) throw crane::common::ConfigError("param: '" + name + "' given twice");
    out[name] = value;
  }
  return out;
}

// Nominal model of `plant` from the stack configuration `path` (empty: none).
std::optional<ma::AuditNominal> config_nominal(const std::string& path, ma::AuditPlant plant) {
  if (path.empty()) return std::nullopt;
  const crane::common::CraneParameters crane = crane::config::ConfigDocument::load(path).facts().crane;
  if (plant == ma::AuditPlant::crane) return ma::AuditNominal{crane};
  if (plant == ma::AuditPlant::axis) {
    return ma::AuditNominal{ma::drive_axis_parameters(crane.trolley_friction, crane.trolley_drive_gain)};
  }
  throw crane::common::ConfigError("config: --config gives crane or trolley-axis parameters, not the pendulum's "
                                   "(give --param L=VALUE)");
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_audit: model audit of measured data (catalog of candidate causes, BIC + held-out selection)"};
  std::string model_name;
  std::string data_path;
  std::vector<std::string> params;
  std::string config_path;
  bool calibrate = false;
  std::string columns;
  std::vector<std::string> causes;
  std::string channel = "position";
  std::string out_dir;
  bool plot = false;
  double max_rate = -1.0;
  double t_min = -1e300;
  double t_max = 1e300;
  ma::AuditOptions options;
  app.add_option("--model", model_name, "crane | axis | pendulum");
  app.add_option("--data", data_path, "measured CSV");
  app.add_option("--config", config_path, "nominal parameters from the stack YAML (crane; axis: the trolley drive)");
  app.add_option("--param", params, "nominal parameter NAME=VALUE (repeatable)");
  app.add_flag("--calibrate", calibrate, "fit the nominal parameters first");
  app.add_option("--columns", columns, "canonical=file column mapping, e.g. t=t_s,u=vir_V,x=qm_m");
  app.add_option("--cause", causes, "restrict the audit to these catalog entries (repeatable)");
  app.add_option("--channel", channel, "position (default) | effort (axis inverse dynamics)");
  app.add_option("--holdout", options.holdout_fraction, "held-out fraction (0.1..0.6)");
  app.add_option("--window", options.window_duration, "axis replay window [s]");
  app.add_option("--dead-band", options.dead_band, "axis effort-channel rest band [m/s]");
  app.add_option("--bic-threshold", options.bic_threshold, "required delta-BIC drop");
  app.add_option("--max-rate", max_rate, "decimate to at most this rate [Hz] (default: pendulum 200, axis none)");
  app.add_option("--t-min", t_min, "use only samples with t >= this [s]");
  app.add_option("--t-max", t_max, "use only samples with t <= this [s]");
  app.add_option("--substeps", options.substeps, "integration substeps per sample");
  app.add_option("--out", out_dir, "output directory (report.json, report.md, series.csv, PNGs)");
  app.add_flag("--plot", plot, "render PNG plots with " CRANE_AUDIT_PLOT_SCRIPT);

  auto* generate = app.add_subcommand("generate", "write a hidden-effect test case as CSV");
  std::string effect = "random";
  std::uint64_t seed = 1;
  std::string generate_out;
  generate->add_option("--model", model_name, "crane | axis | pendulum");
  generate->add_option("--effect", effect, "catalog name, none, random, or (crane) a pair NAME+NAME");
  generate->add_option("--seed", seed, "seed");
  generate->add_option("--out", generate_out, "CSV file")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error) == 0 ? 0 : kExitInputRefused;
  }
  std::string command_line;
  for (int i = 0; i < argc; ++i) command_line += (i ? " " : "") + std::string(argv[i]);
  try {
    if (model_name.empty()) throw crane::common::ConfigError("model: --model is required (crane, axis or pendulum)");
    const ma::AuditPlant plant = parse_plant(model_name);
    if (generate->parsed()) {
      const auto c = ma::generate_hidden_effect_case(plant, effect, seed);
      std::string comment = "hidden-effect case: effect " + c.effect + " " + c.main_parameter + "=" +
                            crane::common::format_value(c.main_value) +
                            (c.second_effect == "none" ? std::string()
                                                       : " + " + c.second_effect + " " + c.second_main_parameter + "=" +
                                                             crane::common::format_value(c.second_main_value)) +
                            "; nominal";
      for (const auto& [k, v] : ma::parameter_values(c.nominal)) comment += " " + k + "=" + crane::common::format_value(v);
      std::ofstream out(generate_out);
      ma::write_audit_data(out, c.data, plant, {comment});
      std::cout << comment << '\n';
      return 0;
    }
    if (data_path.empty()) throw crane::common::ConfigError("data: --data is required");
    if (out_dir.empty()) throw crane::common::ConfigError("out: --out is required");
    const auto named = parse_parameters(params);
    const auto from_config = config_nominal(config_path, plant);
    options.nominal = from_config ? ma::override_values(*from_config, named) : ma::nominal_from_values(plant, named);
    options.calibrate = calibrate;
    options.causes = causes;
    if (channel == "effort") options.channel = ma::AuditChannel::effort;
    else if (channel != "position") throw crane::common::ConfigError("channel: '" + channel + "' (valid: position, effort)");
    ma::validate(options);  // refuse bad options before reading a large file
    if (max_rate < 0.0) max_rate = plant == ma::AuditPlant::pendulum ? 200.0 : 0.0;
    ma::AuditData data = ma::read_audit_data(data_path, plant, columns, max_rate);
    if (t_min > -1e300 || t_max < 1e300) {  // crop to [t_min, t_max]
      ma::AuditData cropped;
      cropped.source = data.source;
      const std::pair<const std::vector<double>*, std::vector<double>*> columns_of[] = {
          {&data.time, &cropped.time},
          {&data.output, &cropped.output},
          {&data.input, &cropped.input},
          {&data.trolley_position, &cropped.trolley_position},
          {&data.segment, &cropped.segment},
          {&data.slew_input, &cropped.slew_input},
          {&data.slew_angle, &cropped.slew_angle},
          {&data.swing_in_plane, &cropped.swing_in_plane},
          {&data.swing_out_of_plane, &cropped.swing_out_of_plane},
          {&data.cable_length, &cropped.cable_length}};
      for (std::size_t k = 0; k < data.time.size(); ++k) {
        if (data.time[k] < t_min || data.time[k] > t_max) continue;
        for (const auto& [from, to] : columns_of) {
          if (!from->empty()) to->push_back((*from)[k]);
        }
      }
      data = std::move(cropped);
    }
    const ma::AuditReport report = ma::run_audit(data, options);
    ma::write_audit_report(report, out_dir, command_line);
    std::cout << "cause: " << report.cause << "  (" << report.stop_reason << ")\n";
    for (const auto& p : report.parameters) {
      std::cout << "  " << p.name << " = " << p.value << " +- " << p.standard_error << " " << p.unit << '\n';
    }
    if (report.second_cause != "none") {
      std::cout << "second cause: " << report.second_cause
                << (report.second_channel.empty() ? "" : " (on the " + report.second_channel + " channel)") << '\n';
      for (const auto& p : report.second_parameters) {
        std::cout << "  " << p.name << " = " << p.value << " +- " << p.standard_error << " " << p.unit << '\n';
      }
    }
    std::cout << "held-out RMS " << report.holdout_before << " -> " << report.holdout_after << " " << report.unit
              << " (" << report.holdout_percent << " %)\n";
    std::cout << "wrote " << out_dir << "/report.json, report.md, series.csv\n";
    if (plot) {
      const std::string command = std::string("/usr/bin/python3 '") + CRANE_AUDIT_PLOT_SCRIPT + "' '" + out_dir + "'";
      if (std::system(command.c_str()) != 0) {
        std::cerr << "crane_audit: plotting failed (" << command << ")\n";
        return 1;
      }
    }
    return 0;
  } catch (const crane::common::ConfigError& error) {
    std::cerr << "crane_audit: " << error.what() << '\n';
    return kExitInputRefused;
  } catch (const ma::DataError& error) {
    std::cerr << "crane_audit: " << error.what() << '\n';
    return kExitInputRefused;
  } catch (const std::exception& error) {
    std::cerr << "crane_audit: " << error.what() << '\n';
    return 1;
  }
}
