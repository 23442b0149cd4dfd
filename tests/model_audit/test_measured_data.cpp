// Strict CSV time-series reader: accepted forms, and every error path with the row/column it must
// name (row = 1-based file line, comment and header lines included).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "crane/common/validation.hpp"
#include "crane/model_audit/measured_data.hpp"

namespace ma = crane::model_audit;

namespace {

ma::CsvReadOptions tux_options(std::size_t minimum_samples = 2) {
  ma::CsvReadOptions options;
  options.required_columns = {"t", "u", "x"};
  options.time_column = "t";
  options.minimum_samples = minimum_samples;
  return options;
}

ma::TimeSeries parse(const std::string& text, const ma::CsvReadOptions& options) {
  std::istringstream stream(text);
  return ma::parse_time_series_csv(stream, "run.csv", options);
}

// Returns the DataError message, or "" (and a test failure) when nothing is thrown.
std::string data_error(const std::string& text, const ma::CsvReadOptions& options) {
  try {
    (void)parse(text, options);
  } catch (const ma::DataError& error) {
    return error.what();
  }
  ADD_FAILURE() << "no DataError for:\n" << text;
  return {};
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

}  // namespace

TEST(MeasuredData, ReadsCommentsHeaderAndRows) {
  const auto series = parse(
      "# source: test\r\n#   constants k=1\n t , u,x ,extra\n0.0, 1.5 ,-2e-3,+7\n0.01,2,3,4\n\n\n",
      tux_options());
  EXPECT_EQ(series.source(), "run.csv");
  ASSERT_EQ(series.sample_count(), 2u);
  EXPECT_EQ(series.file_column_names(), (std::vector<std::string>{"t", "u", "x", "extra"}));
  EXPECT_EQ(series.column("t"), (std::vector<double>{0.0, 0.01}));
  EXPECT_EQ(series.column("u"), (std::vector<double>{1.5, 2.0}));
  EXPECT_EQ(series.column("x"), (std::vector<double>{-2e-3, 3.0}));
  EXPECT_EQ(series.column("extra"), (std::vector<double>{7.0, 4.0}));
}

TEST(MeasuredData, MappingSelectsFileColumns) {
  auto options = tux_options();
  options.mapping = ma::parse_column_mapping("t=t_s, u=vir_V ,x=qm_m");
  const auto series = parse("t_s,qm_m,vir_V,x\n0,1,2,9\n1,3,4,9\n", options);
  EXPECT_EQ(series.column("t"), (std::vector<double>{0.0, 1.0}));
  EXPECT_EQ(series.column("u"), (std::vector<double>{2.0, 4.0}));
  // x is mapped to qm_m: the file's own "x" column must not stand in for it.
  EXPECT_EQ(series.column("x"), (std::vector<double>{1.0, 3.0}));
  EXPECT_EQ(series.column("qm_m"), (std::vector<double>{1.0, 3.0}));
}

TEST(MeasuredData, ColumnMappingParsing) {
  EXPECT_TRUE(ma::parse_column_mapping("").entries.empty());
  const auto mapping = ma::parse_column_mapping("t=a,x=b");
  EXPECT_EQ(mapping.file_column("t"), "a");
  EXPECT_EQ(mapping.file_column("x"), "b");
  EXPECT_EQ(mapping.file_column("u"), "u");
  const auto config_error = [](const std::string& spec) -> std::string {
    try {
      (void)ma::parse_column_mapping(spec);
    } catch (const crane::common::ConfigError& error) {
      return error.what();
    }
    ADD_FAILURE() << "no ConfigError for " << spec;
    return {};
  };
  EXPECT_TRUE(contains(config_error("t=a,xb"), "'xb'"));
  EXPECT_TRUE(contains(config_error("t=,x=b"), "'t='"));
  EXPECT_TRUE(contains(config_error("=a"), "empty name"));
  EXPECT_TRUE(contains(config_error("t=a,t=b"), "'t' is mapped twice"));
}

TEST(MeasuredData, WriterRoundTripsExactly) {
  const std::vector<double> t{0.0, 0.1, 0.30000000000000004};
  const std::vector<double> u{1.0 / 3.0, -2.5e-300, std::numeric_limits<double>::max()};
  const std::vector<double> x{std::nextafter(1.0, 2.0), -0.0, 123456789.123456789};
  std::ostringstream out;
  ma::write_time_series_csv(out, {"made by a test"}, {"t", "u", "x"}, {t, u, x});
  EXPECT_TRUE(contains(out.str(), "# made by a test\nt,u,x\n"));
  const auto series = parse(out.str(), tux_options());
  EXPECT_EQ(series.column("t"), t);
  EXPECT_EQ(series.column("u"), u);
  EXPECT_EQ(series.column("x"), x);
}

TEST(MeasuredData, FileErrors) {
  const auto path = std::filesystem::temp_directory_path() / "crane_model_audit_no_such_file.csv";
  std::filesystem::remove(path);
  try {
    (void)ma::read_time_series_csv(path, tux_options());
    ADD_FAILURE() << "missing file accepted";
  } catch (const ma::DataError& error) {
    EXPECT_TRUE(contains(error.what(), path.string())) << error.what();
    EXPECT_TRUE(contains(error.what(), "cannot open")) << error.what();
  }
  EXPECT_TRUE(contains(data_error("", tux_options()), "no header row"));
  EXPECT_TRUE(contains(data_error("# only\n# comments\n", tux_options()), "no header row"));
}

TEST(MeasuredData, HeaderErrors) {
  const auto options = tux_options();
  std::string message = data_error("# c\nt,,x\n", options);
  EXPECT_TRUE(contains(message, "run.csv: row 2")) << message;
  EXPECT_TRUE(contains(message, "empty column name")) << message;
  message = data_error("t,u,x,u\n", options);
  EXPECT_TRUE(contains(message, "row 1")) << message;
  EXPECT_TRUE(contains(message, "'u' twice")) << message;
  message = data_error("\nt,u,x\n", options);
  EXPECT_TRUE(contains(message, "row 1: empty line before the header")) << message;
}

TEST(MeasuredData, StructureErrorsNameTheRow) {
  const auto options = tux_options();
  std::string message = data_error("t,u,x\n0,1,2\n# late comment\n1,2,3\n", options);
  EXPECT_TRUE(contains(message, "run.csv: row 3: comment lines are only allowed before the header")) << message;
  message = data_error("t,u,x\n0,1,2\n\n1,2,3\n", options);
  EXPECT_TRUE(contains(message, "row 3: empty line between data rows")) << message;
  message = data_error("# c\nt,u,x\n0,1,2\n1,2\n", options);
  EXPECT_TRUE(contains(message, "row 4: too few cells: 2, the header has 3 columns")) << message;
  message = data_error("t,u,x\n0,1,2,3\n", options);
  EXPECT_TRUE(contains(message, "row 2: too many cells: 4, the header has 3 columns")) << message;
}

TEST(MeasuredData, CellErrorsNameRowColumnAndText) {
  const auto options = tux_options();
  struct Case {
    std::string cell;
    std::string expected;
  };
  const Case cases[] = {
      {"abc", "column 'u': cannot parse 'abc' as a number"},
      {"1.2.3", "column 'u': cannot parse '1.2.3' as a number"},
      {"1e", "column 'u': cannot parse '1e' as a number"},
      {"0x10", "column 'u': cannot parse '0x10' as a number"},
      {"--1", "column 'u': cannot parse '--1' as a number"},
      {"\"1\"", "column 'u': cannot parse '\"1\"' as a number"},
      {"", "column 'u': empty cell"},
      {"nan", "column 'u': non-finite value 'nan'"},
      {"NaN", "column 'u': non-finite value 'NaN'"},
      {"-inf", "column 'u': non-finite value '-inf'"},
      {"Infinity", "column 'u': non-finite value 'Infinity'"},
      {"1e999", "column 'u': value '1e999' is out of the double range"},
  };
  for (const auto& c : cases) {
    const std::string message = data_error("# c\n# c\nt,u,x\n0,1,2\n0.5," + c.cell + ",2\n", options);
    EXPECT_TRUE(contains(message, "run.csv: row 5: " + c.expected)) << c.cell << " -> " << message;
  }
  // Strict: a damaged column nobody asked for still refuses the file.
  const std::string message = data_error("t,u,x,spare\n0,1,2,3\n1,1,2,nan\n", options);
  EXPECT_TRUE(contains(message, "row 3: column 'spare': non-finite value 'nan'")) << message;
}

TEST(MeasuredData, TimeMustIncreaseStrictly) {
  const auto options = tux_options();
  std::string message = data_error("t,u,x\n0,0,0\n0.01,0,0\n0.01,0,0\n", options);
  EXPECT_TRUE(contains(message, "row 4: time column 't' is not strictly increasing: 0.01 at row 3, then 0.01"))
      << message;
  auto mapped = options;
  mapped.mapping = ma::parse_column_mapping("t=time_s");
  message = data_error("# c\ntime_s,u,x\n0,0,0\n0.02,0,0\n0.015,0,0\n", mapped);
  EXPECT_TRUE(contains(message, "row 5: time column 'time_s' is not strictly increasing: 0.02 at row 4, then 0.015"))
      << message;
}

TEST(MeasuredData, TooFewSamples) {
  const std::string message = data_error("t,u,x\n0,0,0\n1,0,0\n2,0,0\n", tux_options(10));
  EXPECT_TRUE(contains(message, "run.csv: too few samples: 3 data rows, at least 10 required")) << message;
  EXPECT_TRUE(contains(data_error("t,u,x\n", tux_options(1)), "0 data rows, at least 1 required"));
}

TEST(MeasuredData, MissingColumnsAreNamedWithThePresentOnes) {
  std::string message = data_error("time,u,pos\n0,0,0\n1,0,0\n", tux_options());
  EXPECT_TRUE(contains(message, "missing required column(s) 't', 'x'")) << message;
  EXPECT_TRUE(contains(message, "columns present: 'time', 'u', 'pos'")) << message;
  auto mapped = tux_options();
  mapped.mapping = ma::parse_column_mapping("x=qm_m");
  message = data_error("t,u,x\n0,0,0\n1,0,0\n", mapped);
  EXPECT_TRUE(contains(message, "missing required column(s) 'qm_m' (for x)")) << message;
  // column() on an absent name names the source and what is there.
  const auto series = parse("t,u,x\n0,0,0\n1,0,0\n", tux_options());
  try {
    (void)series.column("gamma");
    ADD_FAILURE() << "absent column returned";
  } catch (const ma::DataError& error) {
    EXPECT_TRUE(contains(error.what(), "run.csv: no column 'gamma'; columns present: 't', 'u', 'x'")) << error.what();
  }
}
