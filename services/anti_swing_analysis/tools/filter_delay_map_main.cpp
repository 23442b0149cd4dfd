// crane_filter_delay_map: how the state estimator's low-pass cut-off (the delay it adds) changes the
// damping of each anti-swing law, section 5.1 of H. M. Omar, "Control of Gantry and Tower Cranes",
// Virginia Tech 2003 (filter_delay_sensitivity.hpp), for one crane configuration.
//
//   crane_filter_delay_map --config CONFIG --out DIR [--plot-script PY]
//
// For pd and delay1 at the configuration's gains and delay2 at its map maximum
// (DelayedTrajectoryAntiSwingParams), over cut-offs 1-45 Hz and the configuration's cable range:
// prints the damping ratio of the dominant closed-loop pair, the delay the filter adds at the swing
// frequency, and what the filter buys: the RMS noise of the swing and swing rate the estimator
// delivers from the swing encoders' quantization (its exact difference equations on a unit
// impulse). Writes DIR/filter_delay_map.json and, with --plot-script, DIR/filter_delay_map.png.
// Exit 0, 2 on a bad option or configuration (the message names it), 1 on a failure to write or plot.
#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "crane/anti_swing/anti_swing_stage.hpp"
#include "crane/anti_swing_analysis/delayed_trajectory_anti_swing.hpp"
#include "crane/anti_swing_analysis/filter_delay_sensitivity.hpp"
#include "crane/config/config_document.hpp"
#include "crane/state_estimator/state_estimator_stage.hpp"
#include "crane/tracking/tracking_stage.hpp"

#include "json_and_plot.hpp"

namespace asa = crane::anti_swing_analysis;
namespace tools = crane::anti_swing_analysis::tools;
using tools::number_or_null;
namespace se = crane::state_estimator;

namespace {

/// RMS noise gain sqrt(sum h_k^2) of the estimator's cascade (low-pass, then `second` when given)
/// from its exact difference equations, on a unit impulse.
double noise_gain(const se::DiscreteTransferFunction& low_pass, const se::DiscreteTransferFunction* second) {
  se::DiscreteFilter a(low_pass);
  se::DiscreteFilter b(second ? *second : se::DiscreteTransferFunction{});
  double sum = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const double y = b.update(a.update(k == 0 ? 1.0 : 0.0));
    sum += y * y;
  }
  return std::sqrt(sum);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Damping of the anti-swing laws against the state estimator's filter cut-off (section 5.1)"};
  std::string config_path;
  std::string out_dir;
  std::string plot_script;
  app.add_option("--config", config_path, "crane configuration (YAML)")->required()->check(CLI::ExistingFile);
  app.add_option("--out", out_dir, "output directory (created if missing)")->required();
  app.add_option("--plot-script", plot_script, "plot_filter_delay_map.py; empty = no plot");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    std::cerr << "crane_filter_delay_map: " << error.what() << "\n";
    return 2;
  }

  crane::anti_swing::AntiSwingStageParams anti_swing;
  crane::tracking::TrackingStageParams tracking;
  se::StateEstimatorParams estimator;
  crane::common::StackFacts facts;
  try {
    const auto cfg = crane::config::ConfigDocument::load(config_path);
    anti_swing = cfg.read("anti_swing", crane::anti_swing::read_params);
    tracking = cfg.read("tracking", crane::tracking::read_params);
    estimator = cfg.read("state_estimator", se::read_params).estimator;
    facts = cfg.facts();
  } catch (const std::exception& error) {
    std::cerr << "crane_filter_delay_map: " << error.what() << "\n";
    return 2;
  }

  const auto& crane = facts.crane;
  asa::TrackingLoop loop;
  loop.proportional_gain = tracking.tracking.proportional_gain;
  loop.derivative_gain = tracking.tracking.derivative_gain;
  const asa::DelayedTrajectoryAntiSwingParams delay2;
  const std::vector<std::pair<std::string, asa::LawPoint>> laws{
      {"pd", {asa::AntiSwingLaw::pd, anti_swing.anti_swing.pd_proportional_gain, anti_swing.anti_swing.pd_derivative_gain}},
      {"delay1",
       {asa::AntiSwingLaw::delayed_feedback, anti_swing.anti_swing.delay_gain, anti_swing.anti_swing.normalized_delay}},
      {"delay2", {asa::AntiSwingLaw::delayed_trajectory_correction, delay2.delay_gain, delay2.normalized_delay}}};
  std::vector<double> cutoffs;
  for (const double f : {1.0, 1.5, 2.0, 3.0, 4.0, 5.0, 7.5, 10.0, 15.0, 20.0, 30.0, 45.0})
    if (f < 0.5 * estimator.sample_rate) cutoffs.push_back(f);
  const double short_cable = crane.min_cable_length, long_cable = crane.max_cable_length;
  std::vector<double> cables{short_cable};
  for (const double l : {0.5, 1.0}) if (l > short_cable && l < long_cable) cables.push_back(l);
  cables.push_back(long_cable);

  // What the filter buys: the swing encoders' quantization noise (uniform, q^2/12 with q one count
  // of the quadrature-decoded encoder) through the estimator's own filters.
  const double count = 2.0 * std::numbers::pi / (4.0 * crane.swing_encoder_lines);  // [rad]
  const double quantization_rms = count / std::sqrt(12.0);
  const auto differentiator = se::differentiator_coefficients(estimator.differentiator, estimator.sample_rate);
  nlohmann::json noise = nlohmann::json::array();
  std::printf("swing encoder: one count %.3g deg, quantization RMS %.3g deg; estimator at %.0f Hz\n",
              count * 180.0 / std::numbers::pi, quantization_rms * 180.0 / std::numbers::pi, estimator.sample_rate);
  std::printf("%8s %16s %20s\n", "f_c [Hz]", "swing RMS [deg]", "swing rate RMS [deg/s]");
  for (const double f : cutoffs) {
    const auto low_pass = se::butterworth_low_pass(f, estimator.sample_rate);
    const double angle = quantization_rms * noise_gain(low_pass, nullptr) * 180.0 / std::numbers::pi;
    const double rate = quantization_rms * noise_gain(low_pass, &differentiator) * 180.0 / std::numbers::pi;
    std::printf("%8.1f %16.4f %20.4f%s\n", f, angle, rate, std::abs(f - estimator.cutoff_frequency) < 1e-9 ? "   <- the stack" : "");
    noise.push_back({{"cutoff_hz", f}, {"swing_rms_deg", angle}, {"swing_rate_rms_deg_s", rate}});
  }

  nlohmann::json document;
  document["config"] = config_path;
  document["stack_cutoff_hz"] = estimator.cutoff_frequency;
  document["sample_rate_hz"] = estimator.sample_rate;
  document["tracking"] = {{"K_px", loop.proportional_gain}, {"K_dx", loop.derivative_gain}};
  document["cutoffs_hz"] = cutoffs;
  document["cable_lengths_m"] = cables;
  document["noise"] = noise;
  document["values_layout"] = "laws[i].damping[j][k] at cable_lengths_m[j], cutoffs_hz[k]; null = no complex pair";
  document["laws"] = nlohmann::json::array();
  for (const auto& [name, point] : laws) {
    asa::FilterDelaySpec spec;
    spec.law = point;
    spec.loop = loop;
    spec.gravity = crane.gravity;
    spec.cutoffs = cutoffs;
    spec.cable_lengths = cables;
    const auto map = asa::compute_filter_delay_map(spec);
    std::printf("\n%s (%s = %g, %s = %g): damping %.3f without the filter\n", name.c_str(),
                std::string(asa::first_parameter_name(point.law)).c_str(), point.first,
                std::string(asa::second_parameter_name(point.law)).c_str(), point.second, map.unfiltered_damping);
    std::printf("%8s", "f_c [Hz]");
    for (const double l : cables) std::printf("   L=%4.2f m (delay ms)", l);
    std::printf("\n");
    nlohmann::json damping = nlohmann::json::array(), stable = nlohmann::json::array(), delay = nlohmann::json::array();
    for (std::size_t j = 0; j < cables.size(); ++j) {
      nlohmann::json d = nlohmann::json::array(), s = nlohmann::json::array(), t = nlohmann::json::array();
      for (std::size_t k = 0; k < cutoffs.size(); ++k) {
        const auto& p = map.points[j * cutoffs.size() + k];
        d.push_back(number_or_null(p.direct_damping));
        s.push_back(p.stable);
        t.push_back(p.added_delay);
      }
      damping.push_back(d);
      stable.push_back(s);
      delay.push_back(t);
    }
    for (std::size_t k = 0; k < cutoffs.size(); ++k) {
      std::printf("%8.1f", cutoffs[k]);
      for (std::size_t j = 0; j < cables.size(); ++j) {
        const auto& p = map.points[j * cutoffs.size() + k];
        std::printf("   %8.3f%s (%5.1f)  ", p.direct_damping, p.stable ? " " : "!", p.added_delay * 1e3);
      }
      std::printf("%s\n", std::abs(cutoffs[k] - estimator.cutoff_frequency) < 1e-9 ? "  <- the stack" : "");
    }
    // The verdict: the lowest cut-off of the grid from which on the law keeps 95 % of its unfiltered
    // damping at every cable length of the range.
    double lowest = std::nan("");
    for (std::size_t k = cutoffs.size(); k-- > 0;) {
      bool keeps = true;
      for (std::size_t j = 0; j < cables.size(); ++j) {
        const auto& p = map.points[j * cutoffs.size() + k];
        keeps = keeps && p.stable && p.direct_damping >= 0.95 * map.unfiltered_damping;
      }
      if (!keeps) break;
      lowest = cutoffs[k];
    }
    const double at_stack_worst = [&] {
      asa::FilterDelaySpec here = spec;
      here.cutoffs = {estimator.cutoff_frequency};
      double worst = std::numeric_limits<double>::infinity();
      for (const auto& p : asa::compute_filter_delay_map(here).points) worst = std::min(worst, p.direct_damping);
      return worst;
    }();
    if (std::isfinite(lowest)) {
      std::printf("%s keeps 95 %% of its damping over L in [%.2f, %.2f] m from f_c = %.1f Hz; at the stack's %.1f Hz "
                  "its worst damping is %.3f (%.0f %% of %.3f)\n",
                  name.c_str(), short_cable, long_cable, lowest, estimator.cutoff_frequency, at_stack_worst,
                  100.0 * at_stack_worst / map.unfiltered_damping, map.unfiltered_damping);
    } else {
      std::printf("%s does not keep 95 %% of its damping over L in [%.2f, %.2f] m at any cut-off up to %.1f Hz; at "
                  "the stack's %.1f Hz its worst damping is %.3f (%.0f %% of %.3f)\n",
                  name.c_str(), short_cable, long_cable, cutoffs.back(), estimator.cutoff_frequency, at_stack_worst,
                  100.0 * at_stack_worst / map.unfiltered_damping, map.unfiltered_damping);
    }
    document["laws"].push_back({{"name", name},
                                {"keeps_95_percent_from_hz", number_or_null(lowest)},
                                {"worst_damping_at_stack_cutoff", at_stack_worst},
                                {std::string(asa::first_parameter_name(point.law)), point.first},
                                {std::string(asa::second_parameter_name(point.law)), point.second},
                                {"unfiltered_damping", map.unfiltered_damping},
                                {"damping", damping},
                                {"stable", stable},
                                {"added_delay_s", delay}});
  }
  std::printf("(damping of the dominant closed-loop pair, exact equation; ! = unstable; in brackets the "
              "filter's delay at the swing frequency)\n");

  return tools::write_json_and_plot("crane_filter_delay_map", out_dir, "filter_delay_map", document, plot_script);
}
