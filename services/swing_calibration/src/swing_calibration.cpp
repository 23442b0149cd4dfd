#include "crane/swing_calibration/swing_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <sstream>

#include <ceres/ceres.h>

#include "crane/common/validation.hpp"

namespace crane::swing_calibration {

namespace tp = crane::trajectory_planner;

namespace {

// Central differences (one-sided at the ends) of `v` over `t`.
std::vector<double> derivative(const std::vector<double>& t, const std::vector<double>& v) {
  const std::size_t n = v.size();
  std::vector<double> d(n, 0.0);
  if (n < 2) return d;
  d[0] = (v[1] - v[0]) / (t[1] - t[0]);
  d[n - 1] = (v[n - 1] - v[n - 2]) / (t[n - 1] - t[n - 2]);
  for (std::size_t i = 1; i + 1 < n; ++i) d[i] = (v[i + 1] - v[i - 1]) / (t[i + 1] - t[i - 1]);
  return d;
}

// The record's derived signals, computed once.
struct Signals {
  std::vector<double> trolley_velocity, trolley_acceleration, slew_rate, slew_acceleration, cable_rate;
};

Signals derive(const SwingRecord& r) {
  Signals s;
  s.trolley_velocity = derivative(r.time, r.trolley_position);
  s.trolley_acceleration = derivative(r.time, s.trolley_velocity);
  s.slew_rate = derivative(r.time, r.slew_angle);
  s.slew_acceleration = derivative(r.time, s.slew_rate);
  s.cable_rate = derivative(r.time, r.cable_length);
  return s;
}

// Inputs of the swing model at one instant.
struct ModelInput {
  double cable_length;   // L [m]
  double cable_rate;     // L' [m/s]
  double drive;          // x'' (in plane) or -x gamma'' (out of plane) [m/s^2]
};

ModelInput input_at(const SwingRecord& r, const Signals& s, bool in_plane, bool with_drive, std::size_t i) {
  double drive = 0.0;
  if (with_drive) {
    drive = in_plane ? s.trolley_acceleration[i] : -r.trolley_position[i] * s.slew_acceleration[i];
  }
  return {r.cable_length[i], s.cable_rate[i], drive};
}

ModelInput midpoint(const ModelInput& a, const ModelInput& b) {
  return {0.5 * (a.cable_length + b.cable_length), 0.5 * (a.cable_rate + b.cable_rate), 0.5 * (a.drive + b.drive)};
}

// s'' of the header's model for the equivalent length L_e = a L + c.
double swing_acceleration(double angle, double rate, const ModelInput& in, double gravity, double scale, double offset,
                          double zeta) {
  const double length = scale * in.cable_length + offset;
  const double length_rate = scale * in.cable_rate;
  const double omega = std::sqrt(gravity / length);
  return (in.drive - gravity * angle - 2.0 * length_rate * rate) / length - 2.0 * zeta * omega * rate;
}

// The modelled measured angle over [begin, end): RK4 from (angle0, rate0), plus the bias.
void replay(const SwingRecord& r, const Signals& s, bool in_plane, bool with_drive, std::size_t begin, std::size_t end,
            double gravity, double scale, double offset, double zeta, const double* nuisance, double* out) {
  double angle = nuisance[0], rate = nuisance[1];
  const double bias = nuisance[2];
  const double min_length = scale * *std::min_element(r.cable_length.begin() + static_cast<std::ptrdiff_t>(begin),
                                                      r.cable_length.begin() + static_cast<std::ptrdiff_t>(end)) +
                            offset;
  if (!(min_length > 0.0)) {
    for (std::size_t i = begin; i < end; ++i) out[i - begin] = 1e3;  // outside the model's domain
    return;
  }
  out[0] = angle + bias;
  for (std::size_t i = begin; i + 1 < end; ++i) {
    const double h = r.time[i + 1] - r.time[i];
    const ModelInput a = input_at(r, s, in_plane, with_drive, i);
    const ModelInput b = input_at(r, s, in_plane, with_drive, i + 1);
    const ModelInput m = midpoint(a, b);
    const auto f = [&](double x, double v, const ModelInput& in) {
      return swing_acceleration(x, v, in, gravity, scale, offset, zeta);
    };
    const double k1x = rate, k1v = f(angle, rate, a);
    const double k2x = rate + 0.5 * h * k1v, k2v = f(angle + 0.5 * h * k1x, rate + 0.5 * h * k1v, m);
    const double k3x = rate + 0.5 * h * k2v, k3v = f(angle + 0.5 * h * k2x, rate + 0.5 * h * k2v, m);
    const double k4x = rate + h * k3v, k4v = f(angle + h * k3x, rate + h * k3v, b);
    angle += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
    rate += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
    out[i + 1 - begin] = angle + bias;
  }
}

const std::vector<double>& channel(const SwingRecord& r, bool in_plane) {
  return in_plane ? r.swing_in_plane : r.swing_out_of_plane;
}

// Ceres residual of one segment: parameters scale, offset, damping (one each) and the segment's
// nuisance (angle0, rate0, bias).
struct SegmentCost {
  const SwingRecord* record;
  const Signals* signals;
  SwingSegment segment;
  bool with_drive;
  double gravity;
  bool operator()(double const* const* p, double* residual) const {
    const std::size_t n = segment.end - segment.begin;
    replay(*record, *signals, segment.in_plane, with_drive, segment.begin, segment.end, gravity, p[0][0], p[1][0],
           p[2][0], p[3], residual);
    const std::vector<double>& measured = channel(*record, segment.in_plane);
    for (std::size_t i = 0; i < n; ++i) residual[i] -= measured[segment.begin + i];
    return true;
  }
};

// Mean angular frequency from the zero crossings of the angle about its mean [rad/s]; 0 if fewer
// than two crossings.
double zero_crossing_frequency(const SwingRecord& r, const std::vector<double>& v, std::size_t begin, std::size_t end,
                               double mean) {
  double first = -1.0, last = -1.0;
  int crossings = 0;
  for (std::size_t i = begin; i + 1 < end; ++i) {
    const double a = v[i] - mean, b = v[i + 1] - mean;
    if ((a < 0.0 && b >= 0.0) || (a > 0.0 && b <= 0.0)) {
      const double t = r.time[i] + (r.time[i + 1] - r.time[i]) * a / (a - b);
      if (first < 0.0) first = t;
      last = t;
      ++crossings;
    }
  }
  if (crossings < 2 || !(last > first)) return 0.0;
  return std::numbers::pi * static_cast<double>(crossings - 1) / (last - first);
}

std::vector<SwingSegment> choose_segments(const SwingRecord& r, const Signals& s, const CalibrationOptions& o) {
  const std::size_t n = r.time.size();
  std::vector<std::pair<std::size_t, std::size_t>> runs;
  if (o.whole_record) {
    runs.emplace_back(0, n);
  } else {
    std::size_t start = n;
    for (std::size_t i = 0; i <= n; ++i) {
      const bool still = i < n && std::abs(s.trolley_velocity[i]) < o.still_trolley_speed &&
                         std::abs(s.slew_rate[i]) < o.still_slew_rate;
      if (still && start == n) start = i;
      if (!still && start != n) {
        runs.emplace_back(start, i);
        start = n;
      }
    }
  }
  std::vector<SwingSegment> segments;
  for (const auto& [begin, end] : runs) {
    if (end - begin < 10) continue;
    double length_sum = 0.0;
    for (std::size_t i = begin; i < end; ++i) length_sum += r.cable_length[i];
    const double mean_length = length_sum / static_cast<double>(end - begin);
    const double period = 2.0 * std::numbers::pi * std::sqrt(mean_length / o.gravity);
    if (r.time[end - 1] - r.time[begin] < o.min_segment_periods * period) continue;
    for (const bool in_plane : {true, false}) {
      const std::vector<double>& v = channel(r, in_plane);
      double mean = 0.0;
      for (std::size_t i = begin; i < end; ++i) mean += v[i];
      mean /= static_cast<double>(end - begin);
      double amplitude = 0.0;
      for (std::size_t i = begin; i < end; ++i) amplitude = std::max(amplitude, std::abs(v[i] - mean));
      if (amplitude < o.min_swing_amplitude) continue;
      SwingSegment seg;
      seg.begin = begin;
      seg.end = end;
      seg.in_plane = in_plane;
      seg.driven = o.whole_record;
      seg.start_time = r.time[begin];
      seg.end_time = r.time[end - 1];
      seg.mean_cable_length = mean_length;
      seg.amplitude = amplitude;
      seg.zero_crossing_frequency = zero_crossing_frequency(r, v, begin, end, mean);
      if (seg.zero_crossing_frequency > 0.0) segments.push_back(seg);
    }
  }
  return segments;
}

void check_record(const SwingRecord& r) {
  const std::size_t n = r.time.size();
  if (n < 3 || r.trolley_position.size() != n || r.slew_angle.size() != n || r.swing_in_plane.size() != n ||
      r.swing_out_of_plane.size() != n || r.cable_length.size() != n) {
    throw CalibrationError(r.source + ": a swing record needs at least 3 samples and columns of equal length");
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!(r.cable_length[i] > 0.0)) {
      throw CalibrationError(r.source + ": cable length " + common::format_value(r.cable_length[i]) + " at t = " +
                             common::format_value(r.time[i]) + " s is not > 0");
    }
    if (i > 0 && !(r.time[i] > r.time[i - 1])) {
      throw CalibrationError(r.source + ": time is not increasing at sample " + std::to_string(i));
    }
  }
}

}  // namespace

SwingRecord read_swing_record(const std::filesystem::path& file, const model_audit::ColumnMapping& mapping) {
  model_audit::CsvReadOptions options;
  options.required_columns = {"t", "x", "gamma", "phi", "theta", "L"};
  options.mapping = mapping;
  options.time_column = "t";
  options.minimum_samples = 3;
  const model_audit::TimeSeries series = model_audit::read_time_series_csv(file, options);
  SwingRecord r;
  r.source = file.string();
  r.time = series.column("t");
  r.trolley_position = series.column("x");
  r.slew_angle = series.column("gamma");
  r.swing_in_plane = series.column("phi");
  r.swing_out_of_plane = series.column("theta");
  r.cable_length = series.column("L");
  return r;
}

void validate(const CalibrationOptions& o) {
  common::require_greater("calibration.gravity", o.gravity, 0.0);
  common::require_in_range("calibration.min_segment_periods", o.min_segment_periods, 1.0, 1e3);
  common::require_greater("calibration.still_trolley_speed", o.still_trolley_speed, 0.0);
  common::require_greater("calibration.still_slew_rate", o.still_slew_rate, 0.0);
  common::require_in_range("calibration.min_swing_amplitude", o.min_swing_amplitude, 0.0, 1.0);
  common::require_greater("calibration.frequency_band", o.frequency_band, 0.0);
  common::require_in_range("calibration.frequency_band", o.frequency_band, 0.0, 0.5);
  common::require_greater("calibration.vibration_tolerance", o.vibration_tolerance, 0.0);
  common::require_in_range("calibration.vibration_tolerance", o.vibration_tolerance, 0.0, 0.2);
}

double SwingFit::natural_frequency(double cable_length) const noexcept {
  const double length = length_scale * cable_length + length_offset;
  if (!(length > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return std::sqrt(gravity / length);
}

SwingFit fit_swing(const SwingRecord& record, const CalibrationOptions& options) {
  validate(options);
  check_record(record);
  const Signals signals = derive(record);
  SwingFit fit;
  fit.gravity = options.gravity;
  fit.segments = choose_segments(record, signals, options);
  if (fit.segments.empty()) {
    const std::string swing = "swings more than " + common::format_value(options.min_swing_amplitude) +
                              " rad with two zero crossings";
    throw CalibrationError(
        record.source + ": no swing to fit: " +
        (options.whole_record
             ? "the record never " + swing + " (record a move that lets the load swing)"
             : "no stretch with the trolley below " + common::format_value(options.still_trolley_speed) +
                   " m/s and the slew below " + common::format_value(options.still_slew_rate) + " rad/s for " +
                   common::format_value(options.min_segment_periods) + " periods " + swing +
                   " (record a move that stops, then lets the load swing; or --whole-record)"));
  }
  // Initial guesses: a = 1, c from the zero-crossing frequencies, small damping.
  double offset_sum = 0.0;
  fit.min_cable_length = std::numeric_limits<double>::infinity();
  fit.max_cable_length = 0.0;
  for (const SwingSegment& seg : fit.segments) {
    offset_sum += options.gravity / (seg.zero_crossing_frequency * seg.zero_crossing_frequency) - seg.mean_cable_length;
    for (std::size_t i = seg.begin; i < seg.end; ++i) {
      fit.min_cable_length = std::min(fit.min_cable_length, record.cable_length[i]);
      fit.max_cable_length = std::max(fit.max_cable_length, record.cable_length[i]);
    }
  }
  double scale = 1.0;
  double offset = offset_sum / static_cast<double>(fit.segments.size());
  // Ceres starts from a feasible point: an estimate outside the bounds below (zero crossings of a
  // closed-loop record can count a faster mode) starts from the single pendulum instead.
  const double lowest_offset = -0.5 * fit.min_cable_length;
  if (!(offset > lowest_offset && offset < 10.0)) offset = 0.0;
  double zeta = 0.005;
  const double mid_length = 0.5 * (fit.min_cable_length + fit.max_cable_length);
  fit.length_scale_fitted = fit.max_cable_length - fit.min_cable_length > 0.2 * mid_length;

  std::vector<std::vector<double>> nuisance;
  for (const SwingSegment& seg : fit.segments) {
    const std::vector<double>& v = channel(record, seg.in_plane);
    double mean = 0.0;
    for (std::size_t i = seg.begin; i < seg.end; ++i) mean += v[i];
    mean /= static_cast<double>(seg.end - seg.begin);
    const std::size_t b = seg.begin;
    const double rate = (v[b + 1] - v[b]) / (record.time[b + 1] - record.time[b]);
    nuisance.push_back({v[b] - mean, rate, mean});
  }

  ceres::Problem problem;
  for (std::size_t k = 0; k < fit.segments.size(); ++k) {
    auto* cost = new ceres::DynamicNumericDiffCostFunction<SegmentCost, ceres::CENTRAL>(
        new SegmentCost{&record, &signals, fit.segments[k], fit.segments[k].driven, options.gravity});
    cost->AddParameterBlock(1);
    cost->AddParameterBlock(1);
    cost->AddParameterBlock(1);
    cost->AddParameterBlock(3);
    cost->SetNumResiduals(static_cast<int>(fit.segments[k].end - fit.segments[k].begin));
    problem.AddResidualBlock(cost, nullptr, {&scale, &offset, &zeta, nuisance[k].data()});
  }
  problem.SetParameterLowerBound(&zeta, 0, 0.0);
  problem.SetParameterUpperBound(&zeta, 0, 0.3);
  problem.SetParameterLowerBound(&offset, 0, lowest_offset);
  problem.SetParameterUpperBound(&offset, 0, 10.0);
  if (fit.length_scale_fitted) {
    problem.SetParameterLowerBound(&scale, 0, 0.5);
    problem.SetParameterUpperBound(&scale, 0, 2.0);
  } else {
    problem.SetParameterBlockConstant(&scale);
  }
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.max_num_iterations = 200;
  solver.logging_type = ceres::SILENT;
  solver.function_tolerance = 1e-12;
  solver.parameter_tolerance = 1e-12;
  solver.gradient_tolerance = 1e-14;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  fit.length_scale = scale;
  fit.length_offset = offset;
  fit.damping_ratio = zeta;
  double total_ss = 0.0;
  std::size_t total_n = 0;
  for (std::size_t k = 0; k < fit.segments.size(); ++k) {
    SwingSegment& seg = fit.segments[k];
    std::vector<double> model(seg.end - seg.begin);
    replay(record, signals, seg.in_plane, seg.driven, seg.begin, seg.end, options.gravity, scale, offset, zeta,
           nuisance[k].data(), model.data());
    const std::vector<double>& v = channel(record, seg.in_plane);
    double ss = 0.0;
    for (std::size_t i = 0; i < model.size(); ++i) ss += (model[i] - v[seg.begin + i]) * (model[i] - v[seg.begin + i]);
    seg.rms_residual = std::sqrt(ss / static_cast<double>(model.size()));
    total_ss += ss;
    total_n += model.size();
  }
  fit.rms_residual = std::sqrt(total_ss / static_cast<double>(total_n));
  return fit;
}

std::vector<double> replay_segment(const SwingRecord& record, const SwingFit& fit, std::size_t index) {
  // The nuisance is fitted again with the global parameters held (cheap: three parameters).
  const Signals signals = derive(record);
  const SwingSegment& seg = fit.segments.at(index);
  const std::vector<double>& v = channel(record, seg.in_plane);
  double mean = 0.0;
  for (std::size_t i = seg.begin; i < seg.end; ++i) mean += v[i];
  mean /= static_cast<double>(seg.end - seg.begin);
  std::vector<double> nuisance{v[seg.begin] - mean,
                               (v[seg.begin + 1] - v[seg.begin]) / (record.time[seg.begin + 1] - record.time[seg.begin]),
                               mean};
  const bool drive = seg.driven;
  double scale = fit.length_scale, offset = fit.length_offset, zeta = fit.damping_ratio;
  ceres::Problem problem;
  auto* cost = new ceres::DynamicNumericDiffCostFunction<SegmentCost, ceres::CENTRAL>(
      new SegmentCost{&record, &signals, seg, drive, fit.gravity});
  cost->AddParameterBlock(1);
  cost->AddParameterBlock(1);
  cost->AddParameterBlock(1);
  cost->AddParameterBlock(3);
  cost->SetNumResiduals(static_cast<int>(seg.end - seg.begin));
  problem.AddResidualBlock(cost, nullptr, {&scale, &offset, &zeta, nuisance.data()});
  problem.SetParameterBlockConstant(&scale);
  problem.SetParameterBlockConstant(&offset);
  problem.SetParameterBlockConstant(&zeta);
  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_QR;
  solver.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);
  std::vector<double> model(seg.end - seg.begin);
  replay(record, signals, seg.in_plane, drive, seg.begin, seg.end, fit.gravity, scale, offset, zeta, nuisance.data(),
         model.data());
  return model;
}

tp::SpeedShaping speed_shaping(tp::ShaperKind kind) noexcept {
  switch (kind) {
    case tp::ShaperKind::zv: return tp::SpeedShaping::zv;
    case tp::ShaperKind::zvd: return tp::SpeedShaping::zvd;
    case tp::ShaperKind::ei: return tp::SpeedShaping::ei;
    case tp::ShaperKind::mzv: return tp::SpeedShaping::mzv;
    case tp::ShaperKind::two_hump_ei: return tp::SpeedShaping::two_hump_ei;
  }
  return tp::SpeedShaping::zvd;
}

namespace {

tp::InputShaper design(tp::ShaperKind kind, double frequency, double zeta, double tolerance) {
  tp::ShaperParams p;
  p.kind = kind;
  p.natural_frequency = frequency;
  p.damping_ratio = zeta;
  p.vibration_tolerance = tolerance;
  return tp::InputShaper(p);
}

constexpr int kBandPoints = 401;

}  // namespace

std::vector<double> ShaperRecommendation::residual_curve(std::size_t row, const std::vector<double>& ratios,
                                                         double damping_ratio) const {
  const ShaperRow& r = rows.at(row);
  const tp::InputShaper shaper = design(r.kind, r.design_frequency, r.name == "zv_nominal" ? 0.0 : damping_ratio,
                                        vibration_tolerance);
  std::vector<double> out;
  for (double ratio : ratios) out.push_back(shaper.residual_vibration(ratio * fitted_frequency, damping_ratio));
  return out;
}

ShaperRecommendation recommend_shaper(const SwingFit& fit, double cable_length, const CalibrationOptions& options) {
  validate(options);
  common::require_greater("calibration.cable_length", cable_length, 0.0);
  ShaperRecommendation rec;
  rec.cable_length = cable_length;
  rec.fitted_frequency = fit.natural_frequency(cable_length);
  if (!std::isfinite(rec.fitted_frequency)) {
    throw common::ConfigError("calibration.cable_length = " + common::format_value(cable_length) +
                              " gives no equivalent length (a L + c <= 0)");
  }
  rec.nominal_frequency = std::sqrt(options.gravity / cable_length);
  rec.vibration_tolerance = options.vibration_tolerance;
  const double zeta = fit.damping_ratio;
  const double fitted_period = 2.0 * std::numbers::pi / rec.fitted_frequency;
  const auto add_row = [&](const char* name, tp::ShaperKind kind, double frequency, double design_zeta) {
    const tp::InputShaper shaper = design(kind, frequency, design_zeta, options.vibration_tolerance);
    ShaperRow row;
    row.name = name;
    row.kind = kind;
    row.design_frequency = frequency;
    row.delay = shaper.length();
    row.delay_periods = shaper.length() / fitted_period;
    row.residual_at_fit = shaper.residual_vibration(rec.fitted_frequency, zeta);
    for (int i = 0; i < kBandPoints; ++i) {
      const double ratio = 1.0 - options.frequency_band + 2.0 * options.frequency_band * i / (kBandPoints - 1);
      row.worst_residual_in_band =
          std::max(row.worst_residual_in_band, shaper.residual_vibration(ratio * rec.fitted_frequency, zeta));
    }
    // 1e-9: EI's hump is V by design.
    row.meets_tolerance = row.worst_residual_in_band <= options.vibration_tolerance + 1e-9;
    rec.rows.push_back(row);
  };
  for (tp::ShaperKind kind : {tp::ShaperKind::zv, tp::ShaperKind::zvd, tp::ShaperKind::ei, tp::ShaperKind::mzv,
                              tp::ShaperKind::two_hump_ei}) {
    add_row(tp::to_string(kind), kind, rec.fitted_frequency, zeta);
  }
  add_row("zv_nominal", tp::ShaperKind::zv, rec.nominal_frequency, 0.0);
  const std::size_t candidates = rec.rows.size() - 1;  // not the nominal reference
  std::size_t best = candidates;
  for (std::size_t i = 0; i < candidates; ++i) {
    if (!rec.rows[i].meets_tolerance) continue;
    if (best == candidates || rec.rows[i].delay < rec.rows[best].delay) best = i;
  }
  if (best == candidates) {
    best = 0;
    for (std::size_t i = 1; i < candidates; ++i) {
      if (rec.rows[i].worst_residual_in_band < rec.rows[best].worst_residual_in_band) best = i;
    }
  }
  rec.recommended = best;
  return rec;
}

std::string planner_manual_yaml(const SwingFit& fit, const ShaperRecommendation& rec, const std::string& source) {
  char buffer[1024];
  std::snprintf(buffer, sizeof buffer,
                "    # deploy/crane calibrate swing --data %s: w = sqrt(g / (%.4f L + %.4f m)), zeta %.4f\n"
                "    shaping: %s\n"
                "    swing_length_scale: %.4f\n"
                "    swing_length_offset: %.4f\n"
                "    swing_damping_ratio: %.4f\n",
                source.c_str(), fit.length_scale, fit.length_offset, fit.damping_ratio,
                tp::to_string(rec.rows[rec.recommended].kind), fit.length_scale, fit.length_offset,
                std::min(fit.damping_ratio, 0.3));
  return buffer;
}

std::string supervisor_yaml(const SwingFit& fit, const ShaperRecommendation& rec) {
  const double delay = tp::shaper_delay_periods(speed_shaping(rec.rows[rec.recommended].kind),
                                                std::min(fit.damping_ratio, 0.3));
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "  zone_stop_delay_periods: %.6f  # the shaper's mean delay, sum A_i t_i\n", delay);
  return buffer;
}

std::string format_report(const SwingFit& fit, const ShaperRecommendation& rec, const CalibrationOptions& options) {
  std::ostringstream out;
  char line[512];
  std::snprintf(line, sizeof line,
                "swing fit: w(L) = sqrt(g / (a L + c)), a = %.4f%s, c = %.4f m, damping ratio %.4f, rms residual %.3g "
                "rad over %zu segment(s), L in [%.3f, %.3f] m\n",
                fit.length_scale, fit.length_scale_fitted ? "" : " (held: the record spans one length)",
                fit.length_offset, fit.damping_ratio, fit.rms_residual, fit.segments.size(), fit.min_cable_length,
                fit.max_cable_length);
  out << line;
  out << "segment  channel  t_start_s  t_end_s  L_mean_m  amplitude_deg  w_zero_cross  w_fit  rms_deg\n";
  for (std::size_t k = 0; k < fit.segments.size(); ++k) {
    const SwingSegment& s = fit.segments[k];
    std::snprintf(line, sizeof line, "%7zu  %-7s  %9.2f  %7.2f  %8.3f  %13.3f  %12.4f  %5.4f  %7.4f\n", k,
                  s.in_plane ? "phi" : "theta", s.start_time, s.end_time,
                  s.mean_cable_length, s.amplitude * 180.0 / std::numbers::pi, s.zero_crossing_frequency,
                  fit.natural_frequency(s.mean_cable_length), s.rms_residual * 180.0 / std::numbers::pi);
    out << line;
  }
  std::snprintf(line, sizeof line,
                "\nshapers at L = %.3f m: fitted w = %.4f rad/s (period %.3f s), nominal sqrt(g/L) = %.4f rad/s "
                "(%+.1f %%); band +-%.0f %%, tolerance %.1f %%\n",
                rec.cable_length, rec.fitted_frequency, 2.0 * std::numbers::pi / rec.fitted_frequency,
                rec.nominal_frequency, 100.0 * (rec.nominal_frequency / rec.fitted_frequency - 1.0),
                100.0 * options.frequency_band, 100.0 * options.vibration_tolerance);
  out << line;
  out << "shaper       design_w  delay_s  delay_periods  residual_at_fit_%  worst_in_band_%  meets\n";
  for (std::size_t i = 0; i < rec.rows.size(); ++i) {
    const ShaperRow& r = rec.rows[i];
    std::snprintf(line, sizeof line, "%-11s  %8.4f  %7.3f  %13.3f  %17.2f  %15.2f  %-5s%s\n", r.name.c_str(),
                  r.design_frequency, r.delay, r.delay_periods, 100.0 * r.residual_at_fit,
                  100.0 * r.worst_residual_in_band, r.meets_tolerance ? "yes" : "no",
                  i == rec.recommended ? "  <- recommended" : "");
    out << line;
  }
  return out.str();
}

}  // namespace crane::swing_calibration
