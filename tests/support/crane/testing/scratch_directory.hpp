#pragma once
// A test's scratch directory: <the system's temporary directory>/crane_<name>_<pid>, created empty
// (what an earlier process of the same id left there is removed first). When the test that made
// it ends, it is removed with all it holds, unless the test failed: a failed test keeps what its
// processes wrote (logs, CSV, MCAP, fault logs) for the person who reads its message, which names
// the path, and the end of the test prints "kept: <path>". A directory made outside any test (a
// static) lasts until the end of the next test.
//
// Why: the suite's process tests wrote their logs under /tmp and left them there; 50 runs of
// .ci/run on one machine had left 2457 directories, 3.3 GB.
//
// Errors: throws std::filesystem::filesystem_error when the directory cannot be made; a directory
// that cannot be removed is left, with no error.

#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <mutex>
#include <string>
#include <system_error>
#include <vector>

namespace crane::testing {
namespace detail {

// Removes the directories made during a test when it ends, unless it failed.
class ScratchCleaner final : public ::testing::EmptyTestEventListener {
 public:
  void add(const std::filesystem::path& path) {
    const std::lock_guard lock(mutex_);
    paths_.push_back(path);
  }
  void OnTestEnd(const ::testing::TestInfo& info) override {
    const std::lock_guard lock(mutex_);
    for (const auto& path : paths_) {
      if (info.result()->Failed()) {
        std::printf("kept: %s\n", path.c_str());
        continue;
      }
      std::error_code ignored;
      std::filesystem::remove_all(path, ignored);
    }
    paths_.clear();
  }

 private:
  std::mutex mutex_;
  std::vector<std::filesystem::path> paths_;
};

// The one cleaner of the test binary, appended to GoogleTest's listeners (which own it) at first use.
inline ScratchCleaner& scratch_cleaner() {
  static ScratchCleaner* const cleaner = [] {
    auto* made = new ScratchCleaner;
    ::testing::UnitTest::GetInstance()->listeners().Append(made);
    return made;
  }();
  return *cleaner;
}

}  // namespace detail

/// Makes the test's scratch directory `crane_<name>_<pid>` (see the header) and returns its path.
inline std::filesystem::path scratch_directory(const std::string& name) {
  const std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("crane_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(path);
  std::filesystem::create_directories(path);
  detail::scratch_cleaner().add(path);
  return path;
}

}  // namespace crane::testing
