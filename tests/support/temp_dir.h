// A fresh, empty folder for one test's files, removed with everything in it when the test ends
// (also when it fails). The process id in the name keeps concurrent test processes apart.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

#include <gtest/gtest.h>

namespace fieldrig::testing_support {

class ScopedTempDir {
 public:
  // `name` should be unique among the tests of one executable, e.g. "map_cli_record".
  explicit ScopedTempDir(const std::string& name)
      : path_(std::filesystem::path(::testing::TempDir()) /
              ("fieldrig_" + name + "_" + std::to_string(::getpid()))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScopedTempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  ScopedTempDir(const ScopedTempDir&) = delete;
  ScopedTempDir& operator=(const ScopedTempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& file) const { return path_ / file; }

 private:
  std::filesystem::path path_;
};

}  // namespace fieldrig::testing_support
