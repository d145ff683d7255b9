// What the subcommands share beyond their exit codes: a subcommand added with the arguments its
// options are bound to and the run function that sets the exit code, a command that only groups
// subcommands, a failure reported on stderr, the one JSON line most of them print, and main()'s
// parse-and-run that turns every failure into one line naming the command.
#pragma once

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <concepts>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>

#include "commands/commands.h"
#include "fieldrig/core/command_line.h"
#include "fieldrig/core/exception_message.h"
#include "fieldrig/core/logging.h"

namespace fieldrig::tools {

template <typename Args>
struct Subcommand {
  CLI::App* app;
  std::shared_ptr<Args> args;  // shared with the callback: it outlives the register function
};

// Adds `name` to `parent` with default Args; when it is given, `run(args)` becomes the exit code.
template <typename Args>
Subcommand<Args> addSubcommand(CLI::App& parent, std::string name, std::string description,
                               int& exit_code, int (*run)(const Args&)) {
  auto args = std::make_shared<Args>();
  CLI::App* app = parent.add_subcommand(std::move(name), std::move(description));
  app->callback([args, run, &exit_code] { exit_code = run(*args); });
  return {app, args};
}

// A command that only groups subcommands (`map generate`, `map record`): one of them is required.
inline CLI::App* addCommandGroup(CLI::App& parent, std::string name, std::string description) {
  CLI::App* group = parent.add_subcommand(std::move(name), std::move(description));
  group->require_subcommand(1);
  return group;
}

// Says on stderr what failed, after `who` ("fieldrig cloud: "), and gives the exit code back, so
// that a run function can `return fail(who, error.message);`.
inline int fail(std::string_view who, std::string_view message, int exit_code = kExitBadInput) {
  std::cerr << who << message << '\n';
  return exit_code;
}

// The one policy for numbers given on the command line: finite and inside [min, max], or an
// error that CLI11 prefixes with the option's name ("--rate: must be a finite number in [0.01,
// 1000], got nan"). CLI11's own Range, PositiveNumber and NonNegativeNumber compare with < and >,
// which are false for NaN, so they let NaN (and, with the double's full range, inf) through.
template <typename T>
requires std::integral<T> || std::floating_point<T> CLI::Validator finiteRange(T min, T max) {
  const auto text = [](T value) {
    if constexpr (std::floating_point<T>) {
      char buffer[32];
      const auto [end, ec] = std::to_chars(buffer, buffer + sizeof buffer, value);
      return ec == std::errc() ? std::string(buffer, end) : std::to_string(value);
    } else {
      return std::to_string(value);
    }
  };
  const std::string kind = std::floating_point<T> ? "a finite number" : "a whole number";
  const std::string range = "[" + text(min) + ", " + text(max) + "]";
  return CLI::Validator(
      [min, max, kind, range](std::string& input) {
        T value{};
        const bool converted = CLI::detail::lexical_cast(input, value);
        bool finite = converted;
        if constexpr (std::floating_point<T>)
          finite = converted && std::isfinite(value);
        if (!finite || value < min || value > max)
          return "must be " + kind + " in " + range + ", got " + input;
        return std::string{};
      },
      range);
}

// Opens a file given on the command line for reading; on failure, says why, naming the path. A
// folder must be refused here: it opens and then reads as empty, which would pass for an empty
// log. (fieldrigd reads its files through loaders that refuse folders themselves.)
inline std::string openInputFile(const std::string& path, std::ifstream& in) {
  if (std::error_code error; std::filesystem::is_directory(path, error))
    return "'" + path + "' is a directory, not a file";
  in.open(path, std::ios::binary);
  if (!in)
    return "cannot open '" + path + "'";
  return {};
}

// "fieldrig map generate": the program and the subcommands that were parsed, for the one line
// that says what failed. (Not the app's name: CLI11 names an unnamed app after argv[0], a path.)
inline std::string commandName(const CLI::App& app, const std::string& program) {
  std::string name = program;
  const CLI::App* at = &app;
  for (auto parsed = at->get_subcommands(); !parsed.empty(); parsed = at->get_subcommands()) {
    at = parsed.front();
    name += " " + at->get_name();
  }
  return name;
}

// The top-level --log-level option of every fieldrig program; logging is set up once the command
// line is parsed.
inline void addLogLevelOption(CLI::App& app, std::string& log_level) {
  core::addLogLevelOption(app, log_level, "trace, debug, info, warn, error")->capture_default_str();
  app.parse_complete_callback([&log_level] { core::setupLogging(log_level); });
}

// main(): parses the command line, whose subcommand callbacks run the command and set
// `exit_code`, and gives the process's exit code. Whatever fails says so in one stderr line that
// names the command: an option CLI11 refuses (exit 2; --help is exit 0), or an exception that
// nothing else handled (exit 4).
inline int runCommandLine(CLI::App& app, const std::string& program, int argc,
                          const char* const* argv, const int& exit_code) {
  try {
    core::refuseEmptyValues(app);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    if (error.get_exit_code() == 0)
      return app.exit(error);
    const std::string command = commandName(app, program);
    std::cerr << command << ": " << error.what() << " (" << command
              << " --help lists the options)\n";
    return kExitBadInput;
  } catch (...) {
    std::cerr << commandName(app, program)
              << ": internal error: " << core::currentExceptionMessage() << '\n';
    return kExitInternal;
  }
  return exit_code;
}

// Prints `line` as one line of JSON on stdout and gives the exit code back.
inline int printJsonLine(const nlohmann::ordered_json& line, int exit_code = kExitOk) {
  std::cout << line.dump() << '\n';
  return exit_code;
}

}  // namespace fieldrig::tools
