// libFuzzer harness: the audit's strict CSV reader (crane::model_audit::parse_time_series_csv).
// Contract (measured_data.hpp): any text either gives a TimeSeries whose columns all have the same
// length, or throws DataError; nothing else escapes. The first byte chooses the options: the
// friction identification's (t, u, x, time column t) or none required. Seeds: heads of the files of
// /work/shared/data.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <sstream>
#include <string>

#include "crane/model_audit/measured_data.hpp"

namespace ma = crane::model_audit;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  ma::CsvReadOptions options;
  if (data[0] & 1) {
    options.required_columns = {"t", "u", "x"};
    options.mapping = ma::parse_column_mapping("t=t_s, u=vir_V, x=qm_m");
    options.time_column = "t";
  }
  options.minimum_samples = static_cast<std::size_t>(data[0] >> 1) % 4;
  std::istringstream text(std::string(reinterpret_cast<const char*>(data + 1), size - 1));
  try {
    const auto series = ma::parse_time_series_csv(text, "fuzz.csv", options);
    for (const auto& name : series.file_column_names()) {
      if (series.column(name).size() != series.sample_count()) std::abort();  // columns of one length
    }
  } catch (const ma::DataError&) {
  }
  return 0;
}
