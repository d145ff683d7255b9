// Runs the built `fieldrig` binary for CLI contract tests: the real process, real files.
#pragma once

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace fieldrig::testing_support {

inline const std::string kFieldrigBinary = FIELDRIG_BINARY_DIR "/tools/fieldrig";

struct CliRun {
  int exit_code = -1;
  std::vector<std::string> out_lines;  // stdout, one entry per line
  std::vector<std::string> err_lines;  // stderr, one entry per line
  std::string err;                     // stderr, whole
};

inline std::string readWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

inline std::vector<std::string> splitLines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

inline std::string shellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  return quoted + "'";
}

// Runs `PROGRAM ARGS…` to completion, capturing stdout and stderr through files in `work_dir`.
inline CliRun runProgram(const std::string& program, const std::vector<std::string>& args,
                         const std::filesystem::path& work_dir) {
  const auto out = work_dir / "cli.out";
  const auto err = work_dir / "cli.err";
  // append, not " " + std::string: GCC 12 -O3 gives a false-positive -Wrestrict on that insert.
  std::string command = shellQuote(program);
  for (const std::string& arg : args)
    command.append(" ").append(shellQuote(arg));
  command.append(" </dev/null >").append(shellQuote(out.string()));
  command.append(" 2>").append(shellQuote(err.string()));
  CliRun run;
  const int status = std::system(command.c_str());
  run.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out_lines = splitLines(readWholeFile(out));
  run.err = readWholeFile(err);
  run.err_lines = splitLines(run.err);
  return run;
}

// Runs `fieldrig ARGS…` to completion.
inline CliRun runFieldrig(const std::vector<std::string>& args,
                          const std::filesystem::path& work_dir) {
  return runProgram(kFieldrigBinary, args, work_dir);
}

}  // namespace fieldrig::testing_support
