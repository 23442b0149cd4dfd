#pragma once
// Strict reader (and writer) of measured time series in CSV form, for the offline model-audit and
// identification tools (section 3.1 friction identification of H. M. Omar, "Control of Gantry and
// Tower Cranes", Virginia Tech 2003, and later model audits).
//
// Accepted format (the one of /work/shared/data/*/*.csv):
//   # any number of comment lines, only before the header
//   t_s,qm_m,vir_V            <- header: unique, non-empty column names separated by ','
//   0.0,7.45e-06,2.538        <- one row per sample, every cell a finite decimal number
//   ...
// Cells may be surrounded by blanks; '\r' line ends are accepted; empty lines are accepted only
// after the last data row. Every cell of every column is checked (strict: a NaN in a column nobody
// asked for still refuses the file), because a file that is partly damaged is not to be trusted.
//
// Canonical names: a caller asks for columns by canonical name ("t", "u", "x", ...). A ColumnMapping
// says which file column plays each canonical role; an unmapped canonical name means the file column
// of the same name.
//
// Errors: every problem with the file's content throws DataError whose message starts with the
// file name and names the 1-based file line ("row N", comment and header lines count) and/or the
// column, plus the offending text or values. A malformed mapping specification throws
// common::ConfigError. Nothing here is real-time: functions allocate and do I/O.

#include <cstddef>
#include <filesystem>
#include <iosfwd>
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace crane::model_audit {

/// Thrown for any content problem in a measured-data file (see the header comment for the format
/// of the message).
class DataError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// Which file column plays which canonical role: ordered (canonical name, file column name) pairs.
struct ColumnMapping {
  std::vector<std::pair<std::string, std::string>> entries;

  /// File column name for `canonical_name`: the mapped one, else `canonical_name` itself.
  [[nodiscard]] std::string file_column(std::string_view canonical_name) const;
};

/// Parses "t=COL,u=COL,x=COL" (any number of comma-separated CANONICAL=FILE_COLUMN entries, blanks
/// around names ignored; an empty string gives an empty mapping). Throws common::ConfigError naming
/// the entry when an entry has no '=', an empty side, or a canonical name given twice.
[[nodiscard]] ColumnMapping parse_column_mapping(std::string_view specification);

/// What the reader must find in the file.
struct CsvReadOptions {
  std::vector<std::string> required_columns;  // canonical names that must be present
  ColumnMapping mapping;                      // canonical -> file column
  std::string time_column;                    // canonical name whose values must be strictly
                                              // increasing; "" = no check. Implicitly required.
  std::size_t minimum_samples{2};             // [samples] fewer data rows are refused
};

/// Columns of one file, all of the same length (the number of data rows).
class TimeSeries {
 public:
  TimeSeries() = default;
  TimeSeries(std::string source, std::vector<std::string> file_column_names,
             std::vector<std::vector<double>> columns, ColumnMapping mapping);

  /// The file name (or stream label) the data came from; used in messages.
  [[nodiscard]] const std::string& source() const noexcept { return source_; }
  /// Number of data rows.
  [[nodiscard]] std::size_t sample_count() const noexcept;
  /// Header names in file order.
  [[nodiscard]] const std::vector<std::string>& file_column_names() const noexcept { return names_; }
  /// True if `name` resolves: a mapped canonical name to its mapped file column, any other name to
  /// the file column of that name.
  [[nodiscard]] bool has_column(std::string_view name) const noexcept;
  /// The values of column `name` (resolved as in has_column()). Throws DataError naming the source,
  /// the name and the columns present when it does not resolve.
  [[nodiscard]] const std::vector<double>& column(std::string_view name) const;

 private:
  [[nodiscard]] std::ptrdiff_t find(std::string_view name) const noexcept;

  std::string source_;
  std::vector<std::string> names_;
  std::vector<std::vector<double>> columns_;
  ColumnMapping mapping_;
};

/// Reads `file` (format above). Throws DataError when the file cannot be opened, has no header, a
/// duplicate or empty column name, a comment line after the header, an empty line between rows, a
/// row with too few or too many cells (row, counts), an empty, unparsable or non-finite cell (row,
/// column, text), a time column that is not strictly increasing (row, both values), fewer than
/// options.minimum_samples rows (count and minimum), or when a required column is missing (names the
/// missing ones with their mapped file names and lists the columns present).
[[nodiscard]] TimeSeries read_time_series_csv(const std::filesystem::path& file, const CsvReadOptions& options);

/// As read_time_series_csv() but from a stream; `source_name` labels the messages.
[[nodiscard]] TimeSeries parse_time_series_csv(std::istream& text, std::string_view source_name,
                                               const CsvReadOptions& options);

/// Writes `comment_lines` (each prefixed with "# "), the header and the rows, values in shortest
/// round-trip form. Preconditions (asserted): names.size() == columns.size(), equal column lengths.
/// Throws DataError if the stream fails.
void write_time_series_csv(std::ostream& out, const std::vector<std::string>& comment_lines,
                           const std::vector<std::string>& names, const std::vector<std::vector<double>>& columns);

}  // namespace crane::model_audit
