// crane_frequency_response: frequency responses of the state estimator's differentiators
// (4.8)-(4.10) and Butterworth low-pass (section 4.3, figure 4.5 of H. M. Omar, "Control of Gantry
// and Tower Cranes", Virginia Tech 2003), evaluated from the exact coefficients run in the loop.
//
//   crane_frequency_response --out DIR [--fs 100] [--cutoff 5] [--plot-script PY]
//                            [--python /usr/bin/python3]
//
// Writes DIR/frequency_response.json (log-spaced grid from 0.01 Hz to fs/2) and prints, at a few
// frequencies, each differentiator's magnitude ratio to the ideal s and its phase lag behind the
// ideal +90 deg, and the same for the cascade low-pass + (4.10) that the estimator applies. With
// --plot-script, runs `PYTHON PY JSON PNG` to draw DIR/frequency_response.png.
// Exit 0 on success, 2 on a bad option (the message names it), 1 on a failure to write or plot.
#include <CLI/CLI.hpp>
#include <array>
#include <cmath>
#include <complex>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "crane/state_estimator/discrete_filter.hpp"
#include "crane/state_estimator/filter_design.hpp"

namespace se = crane::state_estimator;

namespace {

constexpr double kLowestFrequency = 0.01;  // [Hz]
constexpr int kPoints = 400;
// Below this |H| / |ideal| the response sits on a transmission zero (z = -1 at fs/2) and its
// phase is numerically undefined: written as null.
constexpr double kZeroRatio = 1e-9;

double degrees(double radians) { return radians * 180.0 / std::numbers::pi; }

std::string shell_quote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

nlohmann::json number_or_null(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

/// One response on the grid. `reference_phase_deg` is the phase of the ideal element (+90 for a
/// differentiator, 0 for a low-pass); lag = reference - phase, unwrapped along frequency starting
/// near 0 at the lowest frequency.
struct Response {
  std::string key;
  std::string label;
  se::DiscreteTransferFunction coefficients;
  bool differentiator{true};
  std::vector<double> magnitude;
  std::vector<double> magnitude_ratio;  // |H| / |ideal| (ideal = 2 pi f, or 1 for the low-pass)
  std::vector<double> phase_deg;        // NaN on a transmission zero
  std::vector<double> lag_deg;          // NaN on a transmission zero

  void evaluate(const std::vector<double>& frequencies, double sample_rate) {
    const double reference_phase = differentiator ? 90.0 : 0.0;
    double previous_lag = 0.0;
    for (double f : frequencies) {
      const std::complex<double> h = coefficients.frequency_response(f, sample_rate);
      const double ideal = differentiator ? 2.0 * std::numbers::pi * f : 1.0;
      const double mag = std::abs(h);
      magnitude.push_back(mag);
      magnitude_ratio.push_back(mag / ideal);
      if (mag / ideal < kZeroRatio) {
        phase_deg.push_back(std::nan(""));
        lag_deg.push_back(std::nan(""));
        continue;
      }
      double lag = reference_phase - degrees(std::arg(h));
      lag -= 360.0 * std::round((lag - previous_lag) / 360.0);
      previous_lag = lag;
      lag_deg.push_back(lag);
      phase_deg.push_back(reference_phase - lag);
    }
  }
};

nlohmann::json array_of(const std::vector<double>& values) {
  nlohmann::json out = nlohmann::json::array();
  for (double v : values) out.push_back(number_or_null(v));
  return out;
}

nlohmann::json coefficients_json(const se::DiscreteTransferFunction& c) {
  return {{"b0", c.b0}, {"b1", c.b1}, {"b2", c.b2}, {"a1", c.a1}, {"a2", c.a2}};
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Frequency responses of the state estimator's differentiators and low-pass (figure 4.5)"};
  std::string out_dir;
  double sample_rate = 100.0;
  double cutoff = 5.0;
  std::string plot_script;
  std::string python = "/usr/bin/python3";
  app.add_option("--out", out_dir, "output directory (created if missing)")->required();
  app.add_option("--fs", sample_rate, "sample rate [Hz], > 0");
  app.add_option("--cutoff", cutoff, "Butterworth cut-off [Hz], 0 < cutoff < fs/2 (thesis: 0.05 fs)")
;
  app.add_option("--plot-script", plot_script, "plot_frequency_response.py; empty = no plot");
  app.add_option("--python", python, "python interpreter with matplotlib");
  try {
    app.parse(argc, argv);
    if (!(std::isfinite(sample_rate) && sample_rate > 0.0)) {
      throw CLI::ValidationError("--fs", "must be a positive finite number of Hz");
    }
    if (!(std::isfinite(cutoff) && cutoff > 0.0 && cutoff < sample_rate / 2.0)) {
      throw CLI::ValidationError(
          "--cutoff", "must satisfy 0 < cutoff < fs/2 = " + CLI::detail::to_string(sample_rate / 2.0) + " Hz");
    }
    if (!(kLowestFrequency < sample_rate / 2.0)) {
      throw CLI::ValidationError("--fs", "fs/2 must exceed the lowest plotted frequency 0.01 Hz");
    }
  } catch (const CLI::CallForHelp& help) {
    return app.exit(help);
  } catch (const CLI::ParseError& error) {
    std::cerr << "crane_frequency_response: " << error.what() << "\n";
    return 2;
  }

  const double nyquist = sample_rate / 2.0;
  std::vector<double> frequencies;
  frequencies.reserve(kPoints);
  const double log_low = std::log10(kLowestFrequency);
  const double log_high = std::log10(nyquist);
  for (int i = 0; i < kPoints; ++i) {
    frequencies.push_back(i + 1 == kPoints ? nyquist
                                           : std::pow(10.0, log_low + (log_high - log_low) * i / (kPoints - 1)));
  }

  const se::DiscreteTransferFunction low_pass = se::butterworth_low_pass(cutoff, sample_rate);
  std::vector<Response> differentiators{
      {"backward", "backward (4.8)",
       se::differentiator_coefficients(se::DifferentiatorKind::backward, sample_rate), true, {}, {}, {}, {}},
      {"al_alaoui_first_order", "Al-Alaoui first order (4.9)",
       se::differentiator_coefficients(se::DifferentiatorKind::al_alaoui_first_order, sample_rate), true, {}, {}, {},
       {}},
      {"al_alaoui_second_order", "Al-Alaoui second order (4.10)",
       se::differentiator_coefficients(se::DifferentiatorKind::al_alaoui_second_order, sample_rate), true, {}, {}, {},
       {}}};
  for (Response& r : differentiators) r.evaluate(frequencies, sample_rate);
  Response butterworth{"butterworth_low_pass", "Butterworth low-pass", low_pass, false, {}, {}, {}, {}};
  butterworth.evaluate(frequencies, sample_rate);

  // Cascade low-pass then (4.10): H = H_lp * H_d; magnitudes multiply, lags add (both unwrapped).
  const Response& second_order = differentiators[2];
  Response cascade{"cascade", "Butterworth low-pass + (4.10)", {}, true, {}, {}, {}, {}};
  for (std::size_t i = 0; i < frequencies.size(); ++i) {
    const double mag = butterworth.magnitude[i] * second_order.magnitude[i];
    cascade.magnitude.push_back(mag);
    cascade.magnitude_ratio.push_back(butterworth.magnitude_ratio[i] * second_order.magnitude_ratio[i]);
    const double lag = butterworth.lag_deg[i] + second_order.lag_deg[i];  // NaN propagates
    cascade.lag_deg.push_back(lag);
    cascade.phase_deg.push_back(90.0 - lag);
  }

  // Table.
  std::printf("fs = %g Hz, Butterworth cut-off = %g Hz (%.3f fs); ratio = |H| / (2 pi f), lag = 90 deg - arg H\n",
              sample_rate, cutoff, cutoff / sample_rate);
  std::printf("%8s | %-17s | %-17s | %-17s | %-17s\n", "f [Hz]", "backward (4.8)", "Al-Alaoui 1 (4.9)",
              "Al-Alaoui 2 (4.10)", "low-pass + (4.10)");
  std::printf("%8s | %7s %9s | %7s %9s | %7s %9s | %7s %9s\n", "", "ratio", "lag[deg]", "ratio", "lag[deg]", "ratio",
              "lag[deg]", "ratio", "lag[deg]");
  nlohmann::json table = nlohmann::json::array();
  for (double f : std::array<double, 5>{0.5, 1.0, 2.0, 5.0, 10.0}) {
    if (!(f < nyquist)) continue;
    const double ideal = 2.0 * std::numbers::pi * f;
    std::printf("%8.2f |", f);
    nlohmann::json row{{"frequency_hz", f}};
    // Lags wrapped to (-180, 180]; below fs/2 each biquad's true lag lies there (a second-order
    // low-pass lags by 0..180 deg), so the cascade's lag is the sum of the two wrapped lags.
    auto wrapped_lag = [](double reference_deg, std::complex<double> h) {
      const double lag = reference_deg - degrees(std::arg(h));
      return lag - 360.0 * std::ceil((lag - 180.0) / 360.0);
    };
    auto cell = [&](const std::string& key, double ratio, double lag) {
      std::printf(" %7.4f %9.3f |", ratio, lag);
      row[key] = {{"magnitude_ratio", ratio}, {"phase_lag_deg", lag}};
    };
    for (const Response& r : differentiators) {
      const std::complex<double> h = r.coefficients.frequency_response(f, sample_rate);
      cell(r.key, std::abs(h) / ideal, wrapped_lag(90.0, h));
    }
    const std::complex<double> h_lp = low_pass.frequency_response(f, sample_rate);
    const std::complex<double> h_d = second_order.coefficients.frequency_response(f, sample_rate);
    cell("cascade", std::abs(h_lp * h_d) / ideal, wrapped_lag(0.0, h_lp) + wrapped_lag(90.0, h_d));
    std::printf("\n");
    table.push_back(std::move(row));
  }

  nlohmann::json document;
  document["sample_rate_hz"] = sample_rate;
  document["cutoff_hz"] = cutoff;
  document["source"] = "Omar 2003, section 4.3, equations (4.8)-(4.10), figure 4.5";
  document["conventions"] = {
      {"magnitude_ratio", "differentiators and cascade: |H| / (2 pi f); low-pass: |H|"},
      {"phase_deg", "arg H unwrapped along frequency; null on a transmission zero (z = -1 at fs/2)"},
      {"phase_lag_deg", "reference phase - phase_deg: +90 deg for differentiators/cascade, 0 for the low-pass"}};
  document["frequency_hz"] = frequencies;
  nlohmann::json ideal_magnitude = nlohmann::json::array();
  for (double f : frequencies) ideal_magnitude.push_back(2.0 * std::numbers::pi * f);
  document["ideal"] = {{"label", "ideal s"},
                       {"magnitude", std::move(ideal_magnitude)},
                       {"phase_deg", 90.0}};
  auto response_json = [](const Response& r) {
    nlohmann::json j{{"label", r.label},
                     {"magnitude", array_of(r.magnitude)},
                     {"magnitude_ratio", array_of(r.magnitude_ratio)},
                     {"phase_deg", array_of(r.phase_deg)},
                     {"phase_lag_deg", array_of(r.lag_deg)}};
    return j;
  };
  nlohmann::json diffs = nlohmann::json::object();
  for (const Response& r : differentiators) {
    diffs[r.key] = response_json(r);
    diffs[r.key]["coefficients"] = coefficients_json(r.coefficients);
  }
  document["differentiators"] = std::move(diffs);
  document["butterworth_low_pass"] = response_json(butterworth);
  document["butterworth_low_pass"]["coefficients"] = coefficients_json(low_pass);
  document["cascade"] = response_json(cascade);
  document["cascade"]["description"] = "Butterworth low-pass followed by (4.10), as run by the estimator";
  document["table"] = std::move(table);

  std::error_code error;
  std::filesystem::create_directories(out_dir, error);
  const std::filesystem::path json_path = std::filesystem::path(out_dir) / "frequency_response.json";
  {
    std::ofstream file(json_path);
    if (!file) {
      std::cerr << "crane_frequency_response: cannot write " << json_path << "\n";
      return 1;
    }
    file << document.dump(1) << "\n";
  }
  std::printf("wrote %s\n", json_path.c_str());
  if (!plot_script.empty()) {
    const std::filesystem::path png_path = std::filesystem::path(out_dir) / "frequency_response.png";
    const std::string command = shell_quote(python) + " " + shell_quote(plot_script) + " " +
                                shell_quote(json_path.string()) + " " + shell_quote(png_path.string());
    if (std::system(command.c_str()) != 0) {
      std::cerr << "crane_frequency_response: plot failed: " << command << "\n";
      return 1;
    }
    std::printf("wrote %s\n", png_path.c_str());
  }
  return 0;
}
