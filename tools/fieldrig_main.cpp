// fieldrig: the command-line tool. Parses flags and dispatches to a subcommand's run function.
#include <CLI/CLI.hpp>
#include <string>

#include "commands/command_helpers.h"
#include "commands/commands.h"

int main(int argc, char** argv) {
  using namespace fieldrig::tools;
  CLI::App app{"fieldrig: GPS-triggered stereo phenotyping of row plots"};
  app.footer(kExitCodesHelp);
  app.require_subcommand(1);
  std::string log_level = "warn";
  addLogLevelOption(app, log_level);

  int exit_code = kExitOk;
  registerNmeaCommand(app, exit_code);
  registerMapCommand(app, exit_code);
  registerTriggersCommand(app, exit_code);
  registerSimCommand(app, exit_code);
  registerAcquireCommand(app, exit_code);
  registerSessionCommand(app, exit_code);
  registerCalibrateCommand(app, exit_code);
  registerDisparityCommand(app, exit_code);
  registerCloudCommand(app, exit_code);
  registerTraitsCommand(app, exit_code);
  registerTraitsSynthCommand(app, exit_code);
  registerStemCommand(app, exit_code);
  registerStemUiCommand(app, exit_code);
  registerViewCommand(app, exit_code);
  registerProcessCommand(app, exit_code);
  registerSimulateCommand(app, exit_code);
  registerEvaluateCommand(app, exit_code);
  registerBatchCommand(app, exit_code);
  // The run functions are CLI11 callbacks, so whatever they let escape arrives there too.
  return runCommandLine(app, "fieldrig", argc, argv, exit_code);
}
