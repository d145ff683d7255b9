// fieldrig: the command-line tool. Parses flags and dispatches to a subcommand's run function.
#include <CLI/CLI.hpp>

#include "commands/commands.h"
#include "fieldrig/core/logging.h"

int main(int argc, char** argv) {
  CLI::App app{"fieldrig: GPS-triggered stereo phenotyping of row plots"};
  app.require_subcommand(1);
  std::string log_level = "warn";
  app.add_option("--log-level", log_level, "trace, debug, info, warn, error")
      ->capture_default_str();
  app.parse_complete_callback([&] { fieldrig::core::setupLogging(log_level); });

  int exit_code = fieldrig::tools::kExitOk;
  fieldrig::tools::registerNmeaCommand(app, exit_code);
  fieldrig::tools::registerMapCommand(app, exit_code);
  fieldrig::tools::registerTriggersCommand(app, exit_code);
  fieldrig::tools::registerSimCommand(app, exit_code);
  fieldrig::tools::registerAcquireCommand(app, exit_code);
  fieldrig::tools::registerSessionCommand(app, exit_code);
  fieldrig::tools::registerCalibrateCommand(app, exit_code);
  fieldrig::tools::registerDisparityCommand(app, exit_code);
  fieldrig::tools::registerCloudCommand(app, exit_code);
  fieldrig::tools::registerTraitsCommand(app, exit_code);
  fieldrig::tools::registerStemCommand(app, exit_code);
  fieldrig::tools::registerStemUiCommand(app, exit_code);
  fieldrig::tools::registerProcessCommand(app, exit_code);
  fieldrig::tools::registerSimulateCommand(app, exit_code);
  CLI11_PARSE(app, argc, argv);
  return exit_code;
}
