// fieldrig: the command users type. It only picks the program that runs the subcommand and
// replaces itself with it (execv: the same process, arguments, streams and signals):
//   fieldrig-traits    `fieldrig traits --cloud …`, which links the traits and their options file
//                      only: 38 shared libraries at start instead of 219 (OpenCV's codecs alone
//                      pull in GDAL and ~140 others), 0.04 CPU s instead of 0.2.
//   fieldrig-commands  every other subcommand, `traits synth`, and the help (fieldrig_main.cpp);
//                      it also runs `traits`, so a misrouted call costs time, never a result.
// The two sit in FIELDRIG_LIBEXEC_FROM_BIN beside an installed fieldrig, or in the same folder in
// the build tree. Separate programs rather than dlopen(): each is an ordinary executable that can
// be run and tested on its own, and nothing here needs more than the C library.
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <string>
#include <string_view>
#include <system_error>

namespace {

namespace fs = std::filesystem;

// As kExitInternal of the subcommands (commands.h): an installation missing a part is not bad
// input.
constexpr int kExitInternal = 4;

// The helper that runs argv's subcommand.
std::string_view helperFor(int argc, char** argv) {
  int i = 1;
  // Top-level options come before the subcommand (`fieldrig --log-level debug traits …`).
  while (i < argc) {
    const std::string_view arg = argv[i];
    if (arg == "--log-level")
      i += 2;
    else if (arg.starts_with('-'))
      ++i;
    else
      break;
  }
  if (i >= argc || std::string_view(argv[i]) != "traits")
    return "fieldrig-commands";
  for (int j = i + 1; j < argc; ++j) {
    if (std::string_view(argv[j]) == "synth")
      return "fieldrig-commands";
  }
  return "fieldrig-traits";
}

}  // namespace

int main(int argc, char** argv) {
  const std::string_view helper = helperFor(argc, argv);
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) {
    std::cerr << "fieldrig: cannot find its own executable (/proc/self/exe): " << ec.message()
              << '\n';
    return kExitInternal;
  }
  const fs::path here = self.parent_path();
  const fs::path candidates[] = {(here / FIELDRIG_LIBEXEC_FROM_BIN / helper).lexically_normal(),
                                 here / helper};
  for (const fs::path& candidate : candidates) {
    if (::access(candidate.c_str(), X_OK) != 0)
      continue;
    ::execv(candidate.c_str(), argv);
    const int error = errno;
    std::cerr << "fieldrig: cannot run " << candidate.string() << ": " << std::strerror(error)
              << '\n';
    return kExitInternal;
  }
  std::cerr << "fieldrig: " << helper << " is missing (looked in " << candidates[0].parent_path()
            << " and " << here << "): the installation is incomplete\n";
  return kExitInternal;
}
