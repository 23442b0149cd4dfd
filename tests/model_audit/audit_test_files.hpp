#pragma once
// Helpers of the model-audit tests: CSV files in the temporary directory, a refusal check for
// read_audit_data(), and crane_audit runs (CRANE_AUDIT_EXECUTABLE).
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>

#include "crane/model_audit/model_audit.hpp"
#include "crane/testing/scratch_directory.hpp"

namespace crane::model_audit::test {

/// The running test's scratch directory (crane::testing::scratch_directory "audit_test": its own
/// per process, removed when the test ends unless it failed), made at the test's first call.
inline const std::filesystem::path& test_directory() {
  static std::string test;
  static std::filesystem::path path;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string name = info != nullptr ? std::string(info->test_suite_name()) + "." + info->name() : std::string();
  if (path.empty() || name != test) {
    test = name;
    path = crane::testing::scratch_directory("audit_test");
  }
  return path;
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
