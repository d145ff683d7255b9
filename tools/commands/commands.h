// The `fieldrig` CLI's subcommands. Each register function adds its subcommand (and options) to
// the app and binds a run function; run functions return the process exit code.
#pragma once

#include <CLI/CLI.hpp>

namespace fieldrig::tools {

// Exit codes shared by all subcommands (and listed in `fieldrig --help`: kExitCodesHelp).
inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;  // a file or option that cannot be used
inline constexpr int kExitRuntime = 3;   // a failure while running (device lost for good…)
inline constexpr int kExitInternal = 4;  // an exception nothing handled: a bug, or out of memory

inline constexpr const char* kExitCodesHelp =
    "Exit codes: 0 ok; 2 bad input (an option out of range, a file that cannot be used); "
    "3 a failure while running; 4 internal error (an unexpected exception, out of memory).";

void registerNmeaCommand(CLI::App& app, int& exit_code);
void registerMapCommand(CLI::App& app, int& exit_code);
void registerTriggersCommand(CLI::App& app, int& exit_code);
void registerSimCommand(CLI::App& app, int& exit_code);
void registerAcquireCommand(CLI::App& app, int& exit_code);
void registerSessionCommand(CLI::App& app, int& exit_code);
void registerCalibrateCommand(CLI::App& app, int& exit_code);
void registerDisparityCommand(CLI::App& app, int& exit_code);
void registerCloudCommand(CLI::App& app, int& exit_code);
void registerTraitsCommand(CLI::App& app, int& exit_code);
// `traits synth`, added to the `traits` subcommand (registerTraitsCommand first).
void registerTraitsSynthCommand(CLI::App& app, int& exit_code);
void registerStemCommand(CLI::App& app, int& exit_code);
void registerStemUiCommand(CLI::App& app, int& exit_code);
void registerViewCommand(CLI::App& app, int& exit_code);
void registerProcessCommand(CLI::App& app, int& exit_code);
// `sim plots`, added to the `sim` subcommand by registerSimCommand.
void registerSimPlotsSubcommand(CLI::App& sim, int& exit_code);
// `simulate`: a synthetic field (drive, map, session, truth) to replay through fieldrigd.
void registerSimulateCommand(CLI::App& app, int& exit_code);
// `batch plan|submit|status|merge|run|task`: sessions reprocessed as a Slurm array job.
void registerBatchCommand(CLI::App& app, int& exit_code);
// `evaluate`: plot traits against a synthetic field's truth.
void registerEvaluateCommand(CLI::App& app, int& exit_code);

}  // namespace fieldrig::tools
