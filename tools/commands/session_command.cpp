// `fieldrig session info DIR [--verify]`: one JSON summary of a recorded session; with --verify
// every indexed frame is read back and checked, and damage makes the exit code non-zero.
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/command_helpers.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct InfoArgs {
  std::string dir;
  bool verify = false;
};

int runInfo(const InfoArgs& args) {
  core::Result<recording::SessionReader> opened = recording::SessionReader::open(args.dir);
  if (!opened)
    return fail("fieldrig session info: ", opened.error().message);
  const recording::SessionReader& reader = *opened;
  const recording::SessionCounts counts = reader.counts();
  Json out;
  out["dir"] = args.dir;
  out["software_version"] = reader.metadata().software_version;
  out["start_time"] = reader.metadata().start_time;
  out["sets"] = counts.sets;
  out["frames"] = counts.frames;
  out["frames_not_ok"] = counts.frames_not_ok;
  out["complete"] = counts.complete_sets;
  out["incomplete"] = counts.sets - counts.complete_sets;
  out["first_trigger_time"] =
      reader.sets().empty() ? Json(nullptr)
                            : Json(core::formatIso8601(reader.sets().front().trigger_time, 3));
  out["last_trigger_time"] = reader.sets().empty()
                                 ? Json(nullptr)
                                 : Json(core::formatIso8601(reader.sets().back().trigger_time, 3));
  if (const auto& torn = reader.tornLine()) {
    out["torn_line"] = {{"line", torn->line}, {"bytes", torn->bytes}};
  } else {
    out["torn_line"] = nullptr;
  }
  out["bytes"] = reader.bytesOnDisk();

  int exit_code = kExitOk;
  if (args.verify) {
    const recording::VerifyReport report = reader.verify();
    out["verified"] = {{"ok", report.ok()},
                       {"frames_checked", report.frames_checked},
                       {"problems", report.problems}};
    if (!report.ok()) {
      for (const std::string& problem : report.problems)
        std::cerr << "fieldrig session info: damaged: " << problem << '\n';
      exit_code = kExitRuntime;
    }
  }
  std::cout << out.dump() << '\n';
  return exit_code;
}

}  // namespace

void registerSessionCommand(CLI::App& app, int& exit_code) {
  CLI::App* session = addCommandGroup(app, "session", "Recorded sessions");
  const auto [info, args] = addSubcommand(
      *session, "info", "Print a session's summary as one JSON line; --verify checks every frame",
      exit_code, runInfo);
  info->add_option("dir", args->dir, "Session folder")->required();
  info->add_flag("--verify", args->verify,
                 "Read every indexed frame back: size, PGM header and CRC-32; exit 3 on damage");
}

}  // namespace fieldrig::tools
