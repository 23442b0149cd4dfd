#pragma once
// Helpers of the model-audit tests: CSV files in the temporary directory, a refusal check for
// read_audit_data(), and crane_audit runs (CRANE_AUDIT_EXECUTABLE).
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <system_error>

#include "crane/model_audit/model_audit.hpp"

namespace crane::model_audit::test {

/// This test process's own folder, TMP/crane_audit_test_PID (two test processes that run side by
/// side write files of the same names), removed when the process exits.
inline const std::filesystem::path& test_directory() {
  struct Directory {
    std::filesystem::path path;
    Directory() : path(std::filesystem::temp_directory_path() / ("crane_audit_test_" + std::to_string(getpid()))) {
      std::filesystem::create_directories(path);
    }
    ~Directory() {
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
  };
  static const Directory directory;
  return directory.path;
}

/// Writes `text` to test_directory()/NAME and returns the path.
inline std::filesystem::path write_file(const std::string& name, const std::string& text) {
  const std::filesystem::path path = test_directory() / name;
  std::ofstream(path) << text;
  return path;
}

/// A comment line, `header`, and n rows row(k); data row `bad_at` (0-based) replaced by `bad_row`
/// when that is not empty. Data row k is file line k + 3 ("row k + 3").
inline std::string rows(std::size_t n, const std::string& header, const std::function<std::string(std::size_t)>& row,
                        const std::string& bad_row = "", std::size_t bad_at = 0) {
  std::ostringstream out;
  out << "# test\n" << header << "\n";
  for (std::size_t k = 0; k < n; ++k) out << (!bad_row.empty() && k == bad_at ? bad_row : row(k)) << "\n";
  return out.str();
}

/// read_audit_data(path, plant) must throw DataError with `needle` in the message.
inline void expect_refused(const std::filesystem::path& path, AuditPlant plant, const std::string& needle) {
  try {
    (void)read_audit_data(path, plant, "", 0.0);
    ADD_FAILURE() << "accepted " << path;
  } catch (const DataError& e) {
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

/// Exit code of `crane_audit ARGUMENTS` (output discarded); -1 if it did not exit.
inline int run_tool(const std::string& arguments) {
  const std::string command = std::string(CRANE_AUDIT_EXECUTABLE) + " " + arguments + " > /dev/null 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace crane::model_audit::test
