#pragma once
// What the analysis tools (crane_damping_map, crane_filter_delay_map) do with their result: a JSON
// file in the output directory and, when a plot script is given, a PNG drawn from it by
// `/usr/bin/python3 SCRIPT JSON PNG` (matplotlib, Debian's python3-matplotlib).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>

namespace crane::anti_swing_analysis::tools {

/// `value`, or null when it is NaN/Inf (JSON has no NaN).
inline nlohmann::json number_or_null(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

/// `text` quoted for /bin/sh.
inline std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

/// Writes OUT_DIR/STEM.json (creating OUT_DIR) and, with `plot_script`, OUT_DIR/STEM.png; prints
/// what it wrote. Returns 0, or 1 after printing "TOOL: cannot write ..." or "TOOL: plot failed: ...".
inline int write_json_and_plot(const std::string& tool, const std::string& out_dir, const std::string& stem,
                               const nlohmann::json& document, const std::string& plot_script) {
  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  const std::filesystem::path json_path = std::filesystem::path(out_dir) / (stem + ".json");
  {
    std::ofstream file(json_path);
    if (!file) {
      std::cerr << tool << ": cannot write " << json_path << "\n";
      return 1;
    }
    file << document.dump(1) << "\n";
  }
  std::printf("wrote %s\n", json_path.c_str());
  if (plot_script.empty()) return 0;
  const std::filesystem::path png_path = std::filesystem::path(out_dir) / (stem + ".png");
  const std::string command = "/usr/bin/python3 " + shell_quote(plot_script) + " " + shell_quote(json_path.string()) +
                              " " + shell_quote(png_path.string());
  if (std::system(command.c_str()) != 0) {
    std::cerr << tool << ": plot failed: " << command << "\n";
    return 1;
  }
  std::printf("wrote %s\n", png_path.c_str());
  return 0;
}

}  // namespace crane::anti_swing_analysis::tools
