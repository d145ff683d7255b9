// fieldrigd: parses flags (CLI11), loads the configuration and calls runDaemon (daemon.h).
//   fieldrigd run    --config FILE                 the field run
//   fieldrigd replay --config FILE [--nmea F] …    hardware-free replay
//   fieldrigd --check-config FILE                  validate without starting
#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include <exception>
#include <filesystem>
#include <iostream>
#include <new>
#include <string>

#include "fieldrig/config/config.h"
#include "fieldrig/core/command_line.h"
#include "fieldrig/core/exception_message.h"
#include "fieldrig/core/logging.h"
#include "fieldrig/daemon/daemon.h"

namespace {

using fieldrig::daemon::kExitBadInput;
using fieldrig::daemon::kExitInternal;
using fieldrig::daemon::kExitOk;

// log.file must be a file the log can be opened in: spdlog's exception from a folder there was
// an internal error (exit 4) naming no key, and --check-config said ok. Empty when it can be.
std::string logFileProblem(const std::string& config_path, const fieldrig::config::Config& config) {
  const std::filesystem::path& file = config.log.file;
  if (file.empty())
    return {};
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec))
    return config_path + ": log.file: " + file.string() + ": a folder, not a file";
  const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : ".";
  if (!std::filesystem::is_directory(folder, ec))
    return config_path + ": log.file: " + file.string() + ": its folder " + folder.string() +
           " does not exist";
  return {};
}

// The configuration and the files it names, by the start's own checks (runDaemon with
// check_only): what --check-config passes, the start does not refuse for the configuration.
int checkConfig(const std::string& path) {
  auto loaded = fieldrig::config::loadConfig(path);
  if (!loaded) {
    std::cerr << "fieldrigd: " << loaded.error().message << '\n';
    return kExitBadInput;
  }
  fieldrig::daemon::DaemonOptions options;
  options.config = std::move(*loaded);
  options.check_only = true;
  if (const std::string problem = logFileProblem(path, options.config); !problem.empty()) {
    std::cerr << "fieldrigd: " << problem << '\n';
    return kExitBadInput;
  }
  // To stderr only: a check before the start (systemd's ExecStartPre) is not the run's log.
  fieldrig::core::setupLogging(options.config.log.level, "");
  return fieldrig::daemon::runDaemon(options);
}

// `logging_ready` is set once the log (stderr and the configured file) is set up.
int runMain(int argc, char** argv, bool& logging_ready) {
  CLI::App app{"fieldrigd: GPS-triggered stereo capture, recording and plot traits on the tractor"};
  app.footer(
      "Exit codes: 0 done (signal or end of replay); 2 bad configuration, option or input at "
      "start (nothing written), or a replayed NMEA input with no valid fix (its empty session "
      "stays); 3 a failure while running; 4 internal error (an unexpected "
      "exception, out of memory; the session is closed first).");
  std::string check_config;
  app.add_option("--check-config", check_config,
                 "Validate a configuration (and the map and calibration it names), then exit");

  fieldrig::daemon::DaemonOptions options;
  std::string config_path, log_level, nmea, session, recording, status_address, map, calibration;
  int status_port = -1;
  bool realtime = false, quiet = false, no_status = false;
  auto add_common = [&](CLI::App* mode) {
    mode->add_option("--config", config_path, "The YAML configuration")->required();
    fieldrig::core::addLogLevelOption(*mode, log_level,
                                      "trace, debug, info, warn, error (overrides log.level)");
    mode->add_option("--recording", recording, "Session folder (overrides recording.dir)");
    mode->add_option("--map", map, "Imaging-location map (overrides map)");
    mode->add_option("--calibration", calibration, "Calibration folder (overrides calibration)");
    mode->add_option("--status-port", status_port, "Status port (overrides status.port; 0: any)")
        ->check(CLI::Range(0, 65535));
    mode->add_option("--status-address", status_address,
                     "Status address (overrides status.address)");
    mode->add_flag("--no-status", no_status, "Serve no status");
    mode->add_flag("--quiet", quiet, "No per-plot lines on stdout (the summary line stays)");
  };
  CLI::App* run = app.add_subcommand("run", "The field run: serial NMEA, the configured cameras");
  add_common(run);
  CLI::App* replay =
      app.add_subcommand("replay",
                         "Replay: the sim cameras on a recorded session, NMEA from a file "
                         "(virtual time) or a pty (real time)");
  add_common(replay);
  replay->add_option("--nmea", nmea, "NMEA file or device (overrides replay.nmea)");
  replay->add_option("--session", session,
                     "Recorded session the sim cameras replay (overrides replay.session)");
  replay->add_flag("--realtime", realtime,
                   "Play a file at its own pace (overrides replay.realtime)");
  app.require_subcommand(0, 1);
  try {
    fieldrig::core::refuseEmptyValues(app);
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    // --help is a ParseError with exit code 0; every other one is an option that cannot be used,
    // said on one line that names the command.
    if (error.get_exit_code() == 0)
      return app.exit(error);
    std::string command = "fieldrigd";
    if (!app.get_subcommands().empty())
      command += " " + app.get_subcommands().front()->get_name();
    std::cerr << command << ": " << error.what() << " (" << command
              << " --help lists the options)\n";
    return kExitBadInput;
  }

  if (!check_config.empty())
    return checkConfig(check_config);
  if (app.get_subcommands().empty()) {
    std::cerr << app.help();
    return kExitBadInput;
  }
  options.mode = run->parsed() ? fieldrig::daemon::Mode::kRun : fieldrig::daemon::Mode::kReplay;
  auto loaded = fieldrig::config::loadConfig(config_path);
  if (!loaded) {
    std::cerr << "fieldrigd: " << loaded.error().message << '\n';
    return kExitBadInput;
  }
  fieldrig::config::Config& config = *loaded;
  auto& flags = options.flags_for_keys;
  if (!log_level.empty())
    config.log.level = log_level;
  if (!recording.empty()) {
    config.recording.dir = recording;
    flags["recording.dir"] = "--recording";
  }
  if (!map.empty())
    config.map = map;  // its loader's errors name the file itself
  if (!calibration.empty())
    config.calibration = calibration;
  if (status_port >= 0) {
    config.status.port = static_cast<std::uint16_t>(status_port);
    flags["status.port"] = "--status-port";
  }
  if (!status_address.empty()) {
    config.status.address = status_address;
    flags["status.address"] = "--status-address";
  }
  if (no_status)
    config.status.enabled = false;
  if (!nmea.empty()) {
    config.replay.nmea = nmea;
    flags["replay.nmea"] = "--nmea";
  }
  if (!session.empty()) {
    config.replay.session = session;
    flags["replay.session"] = "--session";
  }
  if (realtime)
    config.replay.realtime = true;
  options.print_results = !quiet;
  if (const std::string problem = logFileProblem(config_path, config); !problem.empty()) {
    std::cerr << "fieldrigd: " << problem << '\n';
    return kExitBadInput;
  }
  options.config = std::move(config);
  try {
    fieldrig::core::setupLogging(options.config.log.level, options.config.log.file.string());
  } catch (const std::exception& e) {  // spdlog cannot open the file (permissions, a full disk)
    std::cerr << "fieldrigd: " << config_path << ": log.file: " << e.what() << '\n';
    return kExitBadInput;
  }
  logging_ready = true;
  return fieldrig::daemon::runDaemon(options);
}

}  // namespace

// An exception that escapes runDaemon has unwound it: the Acquisition's destructor finished the
// recording and closed the session on the way. What is left is to say so and exit non-zero.
int main(int argc, char** argv) {
  bool logging_ready = false;
  try {
    return runMain(argc, argv, logging_ready);
  } catch (...) {
    const std::string message = fieldrig::core::currentExceptionMessage();
    // The log writes to stderr too: one line either way, and in the log file when there is one.
    try {
      if (logging_ready) {
        spdlog::critical("fieldrigd: internal error: {}", message);
        spdlog::shutdown();
        return kExitInternal;
      }
    } catch (...) {  // a failing log must not turn a clean exit into an abort
    }
    std::cerr << "fieldrigd: internal error: " << message << '\n';
    return kExitInternal;
  }
}
