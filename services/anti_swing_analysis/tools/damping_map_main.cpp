// crane_damping_map: damping map of an anti-swing law (figures 3.16, 3.17, 3.19 of H. M. Omar,
// "Control of Gantry and Tower Cranes", Virginia Tech 2003) in this project's sign convention.
//
//   crane_damping_map --controller pd|delay1|delay2 --out DIR [--resolution N] [--plot-script PY]
//
// Prints the maximum damping ratio of the dominant complex pole pair and where it occurs, writes
// DIR/damping_map.json and, with --plot-script, runs `/usr/bin/python3 PY JSON PNG` to draw
// DIR/damping_map.png. Exit 0 on success, 2 on a bad option (the message names it), 1 on a
// failure to write or plot.
#include <CLI/CLI.hpp>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "crane/anti_swing_analysis/damping_map.hpp"

#include "json_and_plot.hpp"

namespace asa = crane::anti_swing_analysis;
namespace tools = crane::anti_swing_analysis::tools;
using tools::number_or_null;

int main(int argc, char** argv) {
  CLI::App app{"Damping map of an anti-swing law (dominant complex pole pair, Pade l = 20)"};
  std::string controller;
  std::string out_dir;
  int resolution = 81;
  std::string plot_script;
  const std::map<std::string, asa::AntiSwingLaw> laws{
      {"pd", asa::AntiSwingLaw::pd},
      {"delay1", asa::AntiSwingLaw::delayed_feedback},
      {"delay2", asa::AntiSwingLaw::delayed_trajectory_correction}};
  app.add_option("--controller", controller, "pd | delay1 | delay2")
      ->required()
      ->check(CLI::IsMember({"pd", "delay1", "delay2"}));
  app.add_option("--out", out_dir, "output directory (created if missing)")->required();
  app.add_option("--resolution", resolution, "grid points per axis")->check(CLI::Range(2, 1001));
  app.add_option("--plot-script", plot_script, "plot_damping_map.py; empty = no plot");
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    std::cerr << "crane_damping_map: " << error.what() << "\n";
    return 2;
  }

  const auto started = std::chrono::steady_clock::now();
  const asa::AntiSwingLaw law = laws.at(controller);
  const asa::DampingMap map = asa::compute_damping_map(asa::default_damping_map_spec(law, resolution));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  const std::string first_name{asa::first_parameter_name(law)};
  const std::string second_name{asa::second_parameter_name(law)};

  std::printf("controller %s: max damping %.4f at %s = %.4f, %s = %.4f (grid max %.4f at %.4f, %.4f)\n",
              controller.c_str(), map.max_damping, first_name.c_str(), map.max_first, second_name.c_str(),
              map.max_second, map.grid_max_damping, map.grid_max_first, map.grid_max_second);
  std::printf("method check: direct (Newton on e^{-tau s} from the Pade pole) damping at the max %.6f, "
              "|diff| %.2e; max |Pade - direct| over the stable grid %.2e at (%.4f, %.4f)\n",
              map.direct_damping_at_max, std::abs(map.direct_damping_at_max - map.max_damping),
              map.max_method_difference, map.max_method_difference_first, map.max_method_difference_second);
  std::printf("independent exact dominant pair: %.6f at the max; it differs from the Pade choice at %d grid "
              "points (near-ties of two pairs), largest jump %.3f; %dx%d grid in %.2f s\n",
              map.direct_independent_damping_at_max, map.dominant_selection_flips,
              map.max_selection_flip_difference, resolution, resolution, seconds);

  nlohmann::json document;
  document["controller"] = controller;
  document["convention"] = "(s^2+a)(s^2+K_dx s+K_px) - s^2 G_s(s) = 0 (phi'' + a phi = +x_bar''), a = 4 pi^2";
  document["tracking"] = {{"K_px", map.spec.loop.proportional_gain}, {"K_dx", map.spec.loop.derivative_gain}};
  document["pade_order"] = map.spec.pade_order;
  document["max_damping"] = map.max_damping;
  document["at"] = {{first_name, map.max_first}, {second_name, map.max_second}};
  document["grid_max"] = {{"damping", map.grid_max_damping},
                          {first_name, map.grid_max_first},
                          {second_name, map.grid_max_second}};
  document["method_check"] = {
      {"max_abs_difference", map.max_method_difference},
      {"at", {{first_name, map.max_method_difference_first}, {second_name, map.max_method_difference_second}}},
      {"direct_damping_at_max", map.direct_damping_at_max},
      {"abs_difference_at_max", std::abs(map.direct_damping_at_max - map.max_damping)},
      {"independent_dominant_damping_at_max", number_or_null(map.direct_independent_damping_at_max)},
      {"dominant_selection_flips", map.dominant_selection_flips},
      {"max_selection_flip_difference", map.max_selection_flip_difference},
      {"description", "Pade l=20 dominant pole vs the same pole refined by Newton on the exact delay equation, over stable points"}};
  document["parameters"] = nlohmann::json::array(
      {{{"name", first_name}, {"values", map.first_values}}, {{"name", second_name}, {"values", map.second_values}}});
  document["values_layout"] = "values[i][j] at parameters[0].values[i], parameters[1].values[j]; null = no complex pair";
  nlohmann::json values = nlohmann::json::array();
  nlohmann::json stable = nlohmann::json::array();
  const auto n = static_cast<std::size_t>(resolution);
  for (std::size_t i = 0; i < n; ++i) {
    nlohmann::json value_row = nlohmann::json::array();
    nlohmann::json stable_row = nlohmann::json::array();
    for (std::size_t j = 0; j < n; ++j) {
      value_row.push_back(number_or_null(map.damping[i * n + j]));
      stable_row.push_back(map.stable[i * n + j] != 0);
    }
    values.push_back(std::move(value_row));
    stable.push_back(std::move(stable_row));
  }
  document["values"] = std::move(values);
  document["stable"] = std::move(stable);

  return tools::write_json_and_plot("crane_damping_map", out_dir, "damping_map", document, plot_script);
}
