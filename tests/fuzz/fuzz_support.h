// What the libFuzzer targets of tests/fuzz share (built by scripts/fuzz.sh, never by CMake).
//
//   check(condition, what)  a broken invariant: prints what and aborts, so libFuzzer keeps the
//   input FuzzFolder              a fresh folder for the targets whose parser reads files
//   writeSeed(name, bytes)  a seed for the corpus, when scripts/fuzz.sh asks for seeds (the
//                           targets write their seeds with the project's own writers, so that
//                           the seeds follow the format as it changes)
#pragma once

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

namespace fieldrig::fuzz {

inline void check(bool condition, std::string_view what) {
  if (condition)
    return;
  std::fprintf(stderr, "fuzz invariant broken: %.*s\n", static_cast<int>(what.size()), what.data());
  std::abort();
}

inline bool startsWith(std::string_view text, std::string_view prefix) {
  return text.substr(0, prefix.size()) == prefix;
}

// One folder per process, in /dev/shm when there is one (file-reading targets write every input),
// removed when the process ends normally.
class FuzzFolder {
 public:
  explicit FuzzFolder(const std::string& name) {
    std::error_code ec;
    std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec)
                                     ? std::filesystem::path("/dev/shm")
                                     : std::filesystem::temp_directory_path();
    path_ = base / ("fieldrig-fuzz-" + name + "-" + std::to_string(::getpid()));
    std::filesystem::remove_all(path_, ec);
    std::filesystem::create_directories(path_);
  }
  ~FuzzFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  FuzzFolder(const FuzzFolder&) = delete;
  FuzzFolder& operator=(const FuzzFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }

  std::filesystem::path write(const std::string& name, std::string_view bytes) const {
    const std::filesystem::path file = path_ / name;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    check(static_cast<bool>(out), "the fuzz folder cannot be written");
    return file;
  }

 private:
  std::filesystem::path path_;
};

// Where scripts/fuzz.sh wants seeds (FIELDRIG_FUZZ_SEEDS), or nothing.
inline const char* seedFolder() {
  return std::getenv("FIELDRIG_FUZZ_SEEDS");
}

inline void writeSeed(const std::string& name, std::string_view bytes) {
  const char* folder = seedFolder();
  if (folder == nullptr)
    return;
  std::ofstream out(std::filesystem::path(folder) / ("seed-" + name),
                    std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The parts of an input that holds several files, cut at kFileSeparator lines.
inline constexpr std::string_view kFileSeparator = "\n=====\n";

inline std::string_view part(std::string_view data, int index) {
  for (int i = 0; i < index; ++i) {
    const std::size_t cut = data.find(kFileSeparator);
    if (cut == std::string_view::npos)
      return {};
    data.remove_prefix(cut + kFileSeparator.size());
  }
  return data.substr(0, data.find(kFileSeparator));
}

}  // namespace fieldrig::fuzz
