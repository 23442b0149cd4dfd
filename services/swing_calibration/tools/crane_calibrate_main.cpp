// crane_calibrate swing (deploy/crane calibrate swing, docs/calibration.md): fits the swing against
// cable length from a recording and recommends a shaper for the planner. Parsing and printing only:
// the work is crane::swing_calibration.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <vector>

#include "crane/common/validation.hpp"
#include "crane/model_audit/measured_data.hpp"
#include "crane/swing_calibration/swing_calibration.hpp"

namespace sc = crane::swing_calibration;
namespace ma = crane::model_audit;

namespace {

void write_outputs(const std::filesystem::path& dir, const sc::SwingRecord& record, const sc::SwingFit& fit,
                   const sc::ShaperRecommendation& rec, const std::string& report, const std::string& yaml) {
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "report.txt") << report;
  std::ofstream(dir / "calibration.yaml") << yaml;
  // fit.csv: every fitted segment, measured and modelled angle.
  std::vector<double> segment, time, measured, model;
  for (std::size_t k = 0; k < fit.segments.size(); ++k) {
    const sc::SwingSegment& s = fit.segments[k];
    const std::vector<double> replayed = sc::replay_segment(record, fit, k);
    const std::vector<double>& v = s.in_plane ? record.swing_in_plane : record.swing_out_of_plane;
    for (std::size_t i = s.begin; i < s.end; ++i) {
      segment.push_back(static_cast<double>(k));
      time.push_back(record.time[i]);
      measured.push_back(v[i]);
      model.push_back(replayed[i - s.begin]);
    }
  }
  std::ofstream fit_csv(dir / "fit.csv");
  ma::write_time_series_csv(fit_csv, {"crane_calibrate swing: measured and modelled swing of each segment [rad]"},
                            {"segment", "t", "measured", "model"}, {segment, time, measured, model});
  // shapers.csv: residual swing against frequency ratio, one column per shaper.
  std::vector<double> ratios;
  for (int i = 0; i <= 200; ++i) ratios.push_back(0.5 + 0.005 * i);
  std::vector<std::string> names{"ratio"};
  std::vector<std::vector<double>> columns{ratios};
  for (std::size_t r = 0; r < rec.rows.size(); ++r) {
    names.push_back(rec.rows[r].name + (r == rec.recommended ? " (recommended)" : ""));
    columns.push_back(rec.residual_curve(r, ratios, fit.damping_ratio));
  }
  std::ofstream shapers_csv(dir / "shapers.csv");
  char comment[256];
  std::snprintf(comment, sizeof comment, "residual swing (1 = unshaped) against w / w_fit, w_fit = %.6f rad/s at L = %.4f m",
                rec.fitted_frequency, rec.cable_length);
  ma::write_time_series_csv(shapers_csv, {comment}, names, columns);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"crane_calibrate: shaper calibration from a recording (docs/calibration.md)"};
  app.require_subcommand(1);
  auto* swing = app.add_subcommand("swing", "fit the swing frequency and damping against cable length, rank the shapers");
  std::string data, mapping, out, source;
  double cable_length = 0.0;
  sc::CalibrationOptions options;
  swing->add_option("--data", data, "recording: CSV with t,x,gamma,phi,theta,L (crane_demo, crane_sim, crane_topic convert)")
      ->required();
  swing->add_option("--map", mapping, "column names: t=COL,x=COL,... (model_audit::parse_column_mapping)");
  swing->add_option("--cable-length", cable_length, "[m] design the shapers here (default: the fitted segments' middle)");
  swing->add_flag("--whole-record", options.whole_record,
                  "fit the whole record with the trolley and slew accelerations as input (default: free-swing segments)");
  swing->add_option("--band", options.frequency_band, "+- relative frequency error the shaper must cover")
      ->capture_default_str();
  swing->add_option("--tolerance", options.vibration_tolerance, "residual swing allowed over the band (1 = unshaped)")
      ->capture_default_str();
  swing->add_option("--min-periods", options.min_segment_periods, "free-swing segments last at least this many periods")
      ->capture_default_str();
  swing->add_option("--gravity", options.gravity, "[m/s^2]")->capture_default_str();
  swing->add_option("--source", source, "the recording's name in calibration.yaml (default: --data; deploy/crane "
                                        "passes the .mcap it converted)");
  swing->add_option("--out", out, "folder for calibration.yaml, report.txt, fit.csv, shapers.csv");
  CLI11_PARSE(app, argc, argv);
  try {
    const sc::SwingRecord record = sc::read_swing_record(data, ma::parse_column_mapping(mapping));
    const sc::SwingFit fit = sc::fit_swing(record, options);
    const double design_length =
        cable_length > 0.0 ? cable_length : 0.5 * (fit.min_cable_length + fit.max_cable_length);
    const sc::ShaperRecommendation rec = sc::recommend_shaper(fit, design_length, options);
    const std::string report = sc::format_report(fit, rec, options);
    const std::string planner = sc::planner_manual_yaml(fit, rec, source.empty() ? data : source);
    const std::string supervisor = sc::supervisor_yaml(fit, rec);
    // The pendulum is known now: its minimum-time plans need no robustness to its length (a robust
    // plan near the mast costs 20 %; docs/optimal_control.md, "Robust near the mast").
    const std::string known = "  robust_length_range: 0.0  # the pendulum is calibrated: its plans need no robustness\n";
    std::printf("%s\nfor the planner (trajectory_planner.manual in the config):\n%s"
                "in trajectory_planner itself:\n%s"
                "and for the supervisor (supervisor in the config: its model of the same soft stop):\n%s",
                report.c_str(), planner.c_str(), known.c_str(), supervisor.c_str());
    const std::string yaml =
        "# trajectory_planner.manual:\n" + planner + "# trajectory_planner:\n" + known + "# supervisor:\n" + supervisor;
    if (!out.empty()) {
      write_outputs(out, record, fit, rec, report, yaml);
      std::printf("wrote %s/{report.txt,calibration.yaml,fit.csv,shapers.csv}\n", out.c_str());
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crane_calibrate: %s\n", e.what());
    return 1;
  }
}
