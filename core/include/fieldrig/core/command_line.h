// What every fieldrig program's command line shares (fieldrig, fieldrig-traits, fieldrigd): empty
// values refused, and --log-level restricted to the levels the configuration file takes. Header
// only, behind the fieldrig::command_line target, so that core itself does not need CLI11.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

namespace fieldrig::core {

// An empty value ("--shard ''", "--recording ''", an empty positional) is refused for every option
// that takes one, here and in the subcommands: the programs test their string options for
// emptiness to mean "not given", so an empty value would silently act as no option at all
// (`--shard ''` processed every set in every array task; `fieldrigd replay --recording ''` wrote
// into the configuration's folder).
inline CLI::Validator nonEmpty() {
  return CLI::Validator(
      [](std::string& input) {
        return input.empty() ? std::string("must not be empty") : std::string{};
      },
      "");
}

inline void refuseEmptyValues(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    if (option->get_type_size_max() > 0)
      option->check(nonEmpty());
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    refuseEmptyValues(*sub);
}

// The levels --log-level takes: the configuration's `log.level` choices. spdlog reads any other
// word as "off", so `--log-level loud` would have silenced the log without a word.
inline CLI::Option* addLogLevelOption(CLI::App& app, std::string& log_level,
                                      const std::string& description) {
  // Empty first, so that '' is said as for every other option (CLI11 stops at the first check
  // that fails).
  return app.add_option("--log-level", log_level, description)
      ->check(nonEmpty())
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error"}));
}

}  // namespace fieldrig::core
