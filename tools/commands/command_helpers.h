// What the subcommands share beyond their exit codes: a subcommand added with the arguments its
// options are bound to and the run function that sets the exit code, a command that only groups
// subcommands, a failure reported on stderr, and the one JSON line most of them print.
#pragma once

#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <utility>

#include "commands/commands.h"

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

// Prints `line` as one line of JSON on stdout and gives the exit code back.
inline int printJsonLine(const nlohmann::ordered_json& line, int exit_code = kExitOk) {
  std::cout << line.dump() << '\n';
  return exit_code;
}

}  // namespace fieldrig::tools
