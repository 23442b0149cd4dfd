#include "crane/model_audit/model_audit.hpp"

#include <algorithm>
#include <cmath>

#include "audit_fit.hpp"
#include "axis_audit.hpp"
#include "crane/common/validation.hpp"
#include "pendulum_audit.hpp"

namespace crane::model_audit {

const std::vector<std::string>& audit_catalog(AuditPlant plant) {
  static const std::vector<std::string> axis = [] {
    std::vector<std::string> list;
    for (const auto& cause : detail::axis_catalog()) {
      if (!cause.crane_drive_only) list.emplace_back(cause.name);
    }
    return list;
  }();
  static const std::vector<std::string> pendulum = [] {
    std::vector<std::string> list;
    for (const auto& cause : detail::pendulum_catalog()) {
      if (!cause.crane_only) list.emplace_back(cause.name);
    }
    return list;
  }();
  static const std::vector<std::string> swing = [] {
    std::vector<std::string> list;
    for (const auto& cause : detail::pendulum_catalog()) list.emplace_back(cause.name);
    return list;
  }();
  // Every axis entry once per drive, then the swing's, then the entries of the drives' coupling.
  static const std::vector<std::string> crane = [] {
    std::vector<std::string> list;
    for (const char* prefix : {"trolley_", "slew_"}) {
      for (const auto& name : axis) list.push_back(prefix + name);
    }
    list.insert(list.end(), swing.begin(), swing.end());
    for (const auto& cause : detail::axis_catalog()) {
      if (cause.crane_drive_only) list.emplace_back(cause.name);
    }
    return list;
  }();
  return plant == AuditPlant::axis ? axis : plant == AuditPlant::pendulum ? pendulum : crane;
}

void validate(const AuditOptions& options) {
  const AuditPlant plant = audit_plant(options.nominal);
  validate(options.nominal);
  const auto& catalog = audit_catalog(plant);
  for (const auto& cause : options.causes) {
    // Entries that need the crane's coupling are fitted on an axis only as a drive of the crane.
    const auto& axis = detail::axis_catalog();
    if (plant == AuditPlant::axis && std::any_of(axis.begin(), axis.end(), [&](const auto& c) {
          return c.crane_drive_only && cause == c.name;
        })) {
      continue;
    }
    // Likewise the swing entries of the crane only (wind, hook) on the pendulum: the crane's swing channel.
    const auto& swing = detail::pendulum_catalog();
    if (plant == AuditPlant::pendulum && std::any_of(swing.begin(), swing.end(), [&](const auto& c) {
          return c.crane_only && cause == c.name;
        })) {
      continue;
    }
    if (std::find(catalog.begin(), catalog.end(), cause) == catalog.end()) {
      throw common::ConfigError("cause: '" + cause + "' is not in the " + std::string(plant_name(plant)) +
                                " catalog (valid: " + detail::join(catalog) + ")");
    }
  }
  if (plant == AuditPlant::pendulum && options.channel == AuditChannel::effort) {
    throw common::ConfigError("channel: effort is defined for the axis model only");
  }
  common::require_in_range("holdout_fraction", options.holdout_fraction, 0.1, 0.6);
  common::require_greater("window_duration", options.window_duration, 0.0);
  common::require_at_least("dead_band", options.dead_band, 0.0);
  common::require_at_least("bic_threshold", options.bic_threshold, 0.0);
  common::require_at_least("min_holdout_gain_percent", options.min_holdout_gain_percent, 0.0);
  common::require_at_least("min_holdout_gain_quanta", options.min_holdout_gain_quanta, 0.0);
  common::require_at_least("min_holdout_gain_resolutions", options.min_holdout_gain_resolutions, 0.0);
  if (options.max_causes < 1 || options.max_causes > 2) {
    throw common::ConfigError("max_causes = " + std::to_string(options.max_causes) + " must be 1 or 2");
  }
  if (options.substeps < 1) throw common::ConfigError("substeps = " + std::to_string(options.substeps) + " must be >= 1");
}

namespace {

// The crane's CSV columns (read_audit_data, write_audit_data), in file order.
const std::vector<std::string>& crane_columns() {
  static const std::vector<std::string> columns{"t", "u_x", "u_gamma", "x", "gamma", "phi", "theta", "L"};
  return columns;
}

}  // namespace

void write_audit_data(std::ostream& out, const AuditData& data, AuditPlant plant,
                      const std::vector<std::string>& comment_lines) {
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  const auto add = [&](const std::string& name, const std::vector<double>& column) {
    if (column.size() != data.time.size()) {
      throw DataError("write_audit_data: column '" + name + "' has " + std::to_string(column.size()) +
                      " samples, the time " + std::to_string(data.time.size()));
    }
    names.push_back(name);
    columns.push_back(column);
  };
  add("t", data.time);
  if (plant == AuditPlant::axis) {
    add("u", data.input);
    add("x", data.output);
  } else if (plant == AuditPlant::crane) {
    const std::vector<const std::vector<double>*> crane{&data.input,          &data.slew_input,         &data.output,
                                                        &data.slew_angle,     &data.swing_in_plane,     &data.swing_out_of_plane,
                                                        &data.cable_length};
    for (std::size_t i = 0; i < crane.size(); ++i) add(crane_columns()[i + 1], *crane[i]);
  } else {
    add("theta", data.output);
    if (!data.segment.empty()) add("segment", data.segment);
  }
  write_time_series_csv(out, comment_lines, names, columns);
}

AuditData read_audit_data(const std::filesystem::path& file, AuditPlant plant, const std::string& columns,
                          double max_rate, std::size_t minimum_samples) {
  CsvReadOptions read;
  read.mapping = parse_column_mapping(columns);
  const std::vector<std::string> allowed = plant == AuditPlant::axis       ? std::vector<std::string>{"t", "u", "x"}
                                           : plant == AuditPlant::pendulum ? std::vector<std::string>{"t", "theta", "x", "segment"}
                                                                           : crane_columns();
  for (const auto& [canonical, file_column] : read.mapping.entries) {
    if (std::find(allowed.begin(), allowed.end(), canonical) == allowed.end()) {
      throw common::ConfigError("columns: unknown canonical name '" + canonical + "' (expected " + detail::join(allowed) + ")");
    }
  }
  read.required_columns = plant == AuditPlant::axis       ? std::vector<std::string>{"t", "u", "x"}
                          : plant == AuditPlant::pendulum ? std::vector<std::string>{"t", "theta"}
                                                          : crane_columns();
  read.time_column = "t";
  read.minimum_samples = minimum_samples;
  const TimeSeries series = read_time_series_csv(file, read);
  const auto& t = series.column("t");
  const std::size_t n = t.size();
  const double dt = (t.back() - t.front()) / static_cast<double>(n - 1);
  for (std::size_t k = 1; k < n; ++k) {
    const double step = t[k] - t[k - 1];
    if (std::abs(step - dt) > 0.01 * dt) {
      // Data rows start after the comment lines and the header; the reader's rows are 1-based file
      // lines, which we do not have here, so name the sample and the time.
      throw DataError(file.string() + ": column '" + read.mapping.file_column("t") + "': sampling not uniform at data row " +
                      std::to_string(k + 1) + " (t = " + common::format_value(t[k]) + " s, step " +
                      common::format_value(step) + " s, mean step " + common::format_value(dt) + " s, tolerance 1 %)");
    }
  }
  std::size_t factor = 1;
  if (max_rate > 0.0 && 1.0 / dt > max_rate) factor = static_cast<std::size_t>(std::ceil((1.0 / dt) / max_rate));
  AuditData data;
  data.source = file.string();
  const auto take = [&](const std::vector<double>& column) {
    std::vector<double> out;
    for (std::size_t k = 0; k < n; k += factor) out.push_back(column[k]);
    return out;
  };
  data.time = take(t);
  if (plant == AuditPlant::axis) {
    data.input = take(series.column("u"));
    data.output = take(series.column("x"));
  } else if (plant == AuditPlant::crane) {
    data.input = take(series.column("u_x"));
    data.output = take(series.column("x"));
    data.slew_input = take(series.column("u_gamma"));
    data.slew_angle = take(series.column("gamma"));
    data.swing_in_plane = take(series.column("phi"));
    data.swing_out_of_plane = take(series.column("theta"));
    data.cable_length = take(series.column("L"));
    for (std::size_t k = 0; k < data.cable_length.size(); ++k) {
      if (data.cable_length[k] <= 0.0) {
        throw DataError(file.string() + ": column '" + read.mapping.file_column("L") + "': cable length " +
                        common::format_value(data.cable_length[k]) + " m at data row " + std::to_string(k * factor + 1) +
                        " must be > 0");
      }
    }
  } else {
    data.output = take(series.column("theta"));
    if (series.has_column("x") && (read.mapping.file_column("x") != "x" || series.has_column("x"))) {
      bool mapped = false;
      for (const auto& e : read.mapping.entries) mapped |= e.first == "x";
      if (mapped || series.has_column("x")) data.trolley_position = take(series.column("x"));
    }
    if (series.has_column("segment")) data.segment = take(series.column("segment"));
  }
  if (data.time.size() < minimum_samples) {
    throw DataError(file.string() + ": only " + std::to_string(data.time.size()) + " samples after decimation by " +
                    std::to_string(factor) + " (minimum " + std::to_string(minimum_samples) + ")");
  }
  return data;
}

AuditReport run_audit(const AuditData& data, const AuditOptions& options) {
  validate(options);
  if (const auto* axis = std::get_if<AxisAuditParameters>(&options.nominal)) {
    return detail::run_channel_audit(detail::AxisAudit(data, *axis, options), options);
  }
  if (const auto* pendulum = std::get_if<PendulumAuditParameters>(&options.nominal)) {
    return detail::run_channel_audit(detail::PendulumAudit(data, *pendulum, options), options);
  }
  return detail::run_crane_audit(data, options);
}

}  // namespace crane::model_audit
