// fieldrig-traits: `fieldrig traits --cloud …` alone, which the fieldrig launcher runs
// (fieldrig_launcher.cpp). It links the traits, their options file and the command line only, and
// with --as-needed (tools/CMakeLists.txt), so it starts without the camera, OpenCV and GDAL
// libraries that fieldrig-commands loads.
#include <CLI/CLI.hpp>
#include <string>

#include "commands/command_helpers.h"
#include "commands/commands.h"

int main(int argc, char** argv) {
  using namespace fieldrig::tools;
  CLI::App app{"fieldrig: GPS-triggered stereo phenotyping of row plots (traits of a plot cloud)"};
  app.footer(std::string(kExitCodesHelp) +
             "\nThe other subcommands, and `traits synth`: fieldrig --help.");
  app.require_subcommand(1);
  std::string log_level = "warn";
  addLogLevelOption(app, log_level);
  int exit_code = kExitOk;
  registerTraitsCommand(app, exit_code);
  return runCommandLine(app, "fieldrig", argc, argv, exit_code);
}
