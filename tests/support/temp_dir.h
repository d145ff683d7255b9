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

// The temporary files the durable writers (core/durable_file.h) leave beside `path`: names
// starting with "FILE.tmp" in its folder. A writer that finished, or failed cleanly, leaves none.
inline std::size_t tempFilesBeside(const std::filesystem::path& path) {
  const std::string prefix = path.filename().string() + ".tmp";
  std::size_t count = 0;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(path.parent_path(), ec))
    count += entry.path().filename().string().starts_with(prefix) ? 1 : 0;
  if (ec)  // a folder that cannot be listed must not pass for one without temporary files
    ADD_FAILURE() << path.parent_path() << ": cannot list: " << ec.message();
  return count;
}

}  // namespace fieldrig::testing_support
