#include "crane/model_audit/measured_data.hpp"

#include <cassert>
#include <charconv>
#include <cmath>
#include <fstream>
#include <istream>
#include <ostream>
#include <system_error>

#include "crane/common/validation.hpp"

namespace crane::model_audit {

namespace {

std::string_view trim(std::string_view text) noexcept {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return text.substr(first, last - first + 1);
}

std::vector<std::string_view> split_cells(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const auto comma = line.find(',', start);
    if (comma == std::string_view::npos) {
      cells.push_back(trim(line.substr(start)));
      return cells;
    }
    cells.push_back(trim(line.substr(start, comma - start)));
    start = comma + 1;
  }
}

std::string join_names(const std::vector<std::string>& names) {
  std::string joined;
  for (const auto& name : names) {
    if (!joined.empty()) joined += ", ";
    joined += "'" + name + "'";
  }
  return joined.empty() ? std::string("(none)") : joined;
}

std::string shortest(double value) {
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof(buffer), value);
  return std::string(buffer, result.ptr);
}

[[noreturn]] void fail_at(std::string_view source, std::size_t row, const std::string& what) {
  throw DataError(std::string(source) + ": row " + std::to_string(row) + ": " + what);
}

// Parses one cell strictly: the whole cell must be a finite decimal number (optional leading '+').
double parse_cell(std::string_view source, std::size_t row, const std::string& column, std::string_view cell) {
  const std::string quoted = "'" + std::string(cell) + "'";
  if (cell.empty()) fail_at(source, row, "column '" + column + "': empty cell");
  std::string_view digits = cell;
  if (digits.front() == '+') digits.remove_prefix(1);
  double value = 0.0;
  const auto result = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (result.ec == std::errc::result_out_of_range) {
    fail_at(source, row, "column '" + column + "': value " + quoted + " is out of the double range");
  }
  if (result.ec != std::errc() || result.ptr != digits.data() + digits.size() || digits.empty()) {
    fail_at(source, row, "column '" + column + "': cannot parse " + quoted + " as a number");
  }
  if (!std::isfinite(value)) fail_at(source, row, "column '" + column + "': non-finite value " + quoted);
  return value;
}

}  // namespace

std::string ColumnMapping::file_column(std::string_view canonical_name) const {
  for (const auto& [canonical, file] : entries) {
    if (canonical == canonical_name) return file;
  }
  return std::string(canonical_name);
}

ColumnMapping parse_column_mapping(std::string_view specification) {
  ColumnMapping mapping;
  if (trim(specification).empty()) return mapping;
  for (const std::string_view entry : split_cells(specification)) {
    const auto equals = entry.find('=');
    const std::string text(entry);
    if (equals == std::string_view::npos) {
      throw common::ConfigError("columns: entry '" + text + "' is not of the form CANONICAL=FILE_COLUMN");
    }
    const std::string canonical(trim(entry.substr(0, equals)));
    const std::string file(trim(entry.substr(equals + 1)));
    if (canonical.empty() || file.empty()) {
      throw common::ConfigError("columns: entry '" + text + "' has an empty name (form CANONICAL=FILE_COLUMN)");
    }
    for (const auto& existing : mapping.entries) {
      if (existing.first == canonical) {
        throw common::ConfigError("columns: canonical name '" + canonical + "' is mapped twice");
      }
    }
    mapping.entries.emplace_back(canonical, file);
  }
  return mapping;
}

TimeSeries::TimeSeries(std::string source, std::vector<std::string> file_column_names,
                       std::vector<std::vector<double>> columns, ColumnMapping mapping)
    : source_(std::move(source)),
      names_(std::move(file_column_names)),
      columns_(std::move(columns)),
      mapping_(std::move(mapping)) {
  assert(names_.size() == columns_.size());
}

std::size_t TimeSeries::sample_count() const noexcept { return columns_.empty() ? 0 : columns_.front().size(); }

std::ptrdiff_t TimeSeries::find(std::string_view name) const noexcept {
  // A mapped canonical name resolves only through its mapping (a file column that happens to carry
  // the canonical name must not stand in for the column the user named).
  std::string_view file_name = name;
  for (const auto& [canonical, file] : mapping_.entries) {
    if (canonical == name) {
      file_name = file;
      break;
    }
  }
  for (std::size_t i = 0; i < names_.size(); ++i) {
    if (names_[i] == file_name) return static_cast<std::ptrdiff_t>(i);
  }
  return -1;
}

bool TimeSeries::has_column(std::string_view name) const noexcept { return find(name) >= 0; }

const std::vector<double>& TimeSeries::column(std::string_view name) const {
  const auto index = find(name);
  if (index < 0) {
    const std::string file_name = mapping_.file_column(name);
    std::string what = source_ + ": no column '" + std::string(name) + "'";
    if (file_name != name) what += " (mapped to file column '" + file_name + "')";
    throw DataError(what + "; columns present: " + join_names(names_));
  }
  return columns_[static_cast<std::size_t>(index)];
}

TimeSeries parse_time_series_csv(std::istream& text, std::string_view source_name, const CsvReadOptions& options) {
  const std::string source(source_name);
  std::vector<std::string> names;
  std::vector<std::vector<double>> columns;
  std::string line;
  std::size_t row = 0;
  std::size_t header_row = 0;
  std::size_t first_empty_row = 0;  // an empty line seen after the header (0 = none yet)

  while (std::getline(text, line)) {
    ++row;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    const std::string_view content = trim(line);
    if (header_row == 0) {
      if (content.empty()) fail_at(source, row, "empty line before the header");
      if (content.front() == '#') continue;
      header_row = row;
      for (const std::string_view cell : split_cells(content)) {
        const std::string name(cell);
        if (name.empty()) fail_at(source, row, "header has an empty column name");
        for (const auto& existing : names) {
          if (existing == name) fail_at(source, row, "header names column '" + name + "' twice");
        }
        names.push_back(name);
      }
      columns.resize(names.size());
      continue;
    }
    if (content.empty()) {
      if (first_empty_row == 0) first_empty_row = row;
      continue;
    }
    if (first_empty_row != 0) fail_at(source, first_empty_row, "empty line between data rows");
    if (content.front() == '#') fail_at(source, row, "comment lines are only allowed before the header");
    const auto cells = split_cells(content);
    if (cells.size() != names.size()) {
      fail_at(source, row,
              std::string(cells.size() < names.size() ? "too few" : "too many") + " cells: " +
                  std::to_string(cells.size()) + ", the header has " + std::to_string(names.size()) + " columns");
    }
    for (std::size_t i = 0; i < cells.size(); ++i) columns[i].push_back(parse_cell(source, row, names[i], cells[i]));
  }
  if (text.bad()) throw DataError(source + ": read error after row " + std::to_string(row));
  if (header_row == 0) throw DataError(source + ": no header row (the file is empty or only comments)");

  TimeSeries series(source, names, std::move(columns), options.mapping);

  std::vector<std::string> required = options.required_columns;
  if (!options.time_column.empty()) {
    bool listed = false;
    for (const auto& name : required) listed = listed || name == options.time_column;
    if (!listed) required.insert(required.begin(), options.time_column);
  }
  std::string missing;
  for (const auto& canonical : required) {
    if (series.has_column(canonical)) continue;
    const std::string file_name = options.mapping.file_column(canonical);
    if (!missing.empty()) missing += ", ";
    missing += "'" + file_name + "'";
    if (file_name != canonical) missing += " (for " + canonical + ")";
  }
  if (!missing.empty()) {
    throw DataError(source + ": missing required column(s) " + missing + "; columns present: " + join_names(names));
  }

  const std::size_t samples = series.sample_count();
  if (samples < options.minimum_samples) {
    throw DataError(source + ": too few samples: " + std::to_string(samples) + " data rows, at least " +
                    std::to_string(options.minimum_samples) + " required");
  }

  if (!options.time_column.empty()) {
    const auto& time = series.column(options.time_column);
    const std::size_t first_data_row = header_row + 1;
    for (std::size_t i = 1; i < time.size(); ++i) {
      if (!(time[i] > time[i - 1])) {
        fail_at(source, first_data_row + i,
                "time column '" + options.mapping.file_column(options.time_column) +
                    "' is not strictly increasing: " + shortest(time[i - 1]) + " at row " +
                    std::to_string(first_data_row + i - 1) + ", then " + shortest(time[i]));
      }
    }
  }
  return series;
}

TimeSeries read_time_series_csv(const std::filesystem::path& file, const CsvReadOptions& options) {
  std::ifstream stream(file);
  if (!stream) throw DataError(file.string() + ": cannot open the file for reading");
  return parse_time_series_csv(stream, file.string(), options);
}

void write_time_series_csv(std::ostream& out, const std::vector<std::string>& comment_lines,
                           const std::vector<std::string>& names, const std::vector<std::vector<double>>& columns) {
  assert(names.size() == columns.size());
  for (const auto& comment : comment_lines) out << "# " << comment << '\n';
  for (std::size_t i = 0; i < names.size(); ++i) out << (i == 0 ? "" : ",") << names[i];
  out << '\n';
  const std::size_t rows = columns.empty() ? 0 : columns.front().size();
  std::string line;
  for (std::size_t r = 0; r < rows; ++r) {
    line.clear();
    for (std::size_t c = 0; c < columns.size(); ++c) {
      assert(columns[c].size() == rows);
      if (c != 0) line += ',';
      line += shortest(columns[c][r]);
    }
    out << line << '\n';
  }
  out.flush();
  if (!out) throw DataError("write_time_series_csv: the output stream failed");
}

}  // namespace crane::model_audit
