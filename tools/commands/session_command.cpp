// `fieldrig session info DIR [--verify]`: one JSON summary of a recorded session; with --verify
// every indexed frame is read back and checked, and damage makes the exit code non-zero.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/commands.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct InfoArgs {
  std::string dir;
  bool verify = false;
};

// Bytes of every regular file in the session folder, recursively.
std::uint64_t folderBytes(const fs::path& dir) {
  std::uint64_t bytes = 0;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    std::error_code size_ec;
    if (it->is_regular_file(size_ec)) {
      const std::uintmax_t size = it->file_size(size_ec);
      if (!size_ec)
        bytes += size;
    }
  }
  return bytes;
}

int runInfo(const InfoArgs& args) {
  core::Result<recording::SessionReader> opened = recording::SessionReader::open(args.dir);
  if (!opened) {
    std::cerr << "fieldrig session info: " << opened.error().message << '\n';
    return kExitBadInput;
  }
  const recording::SessionReader& reader = *opened;
  std::uint64_t frames = 0;
  std::uint64_t frames_not_ok = 0;
  std::uint64_t complete = 0;
  for (const recording::IndexedSet& set : reader.sets()) {
    complete += set.complete ? 1 : 0;
    for (const recording::IndexedFrame& frame : set.frames) {
      ++frames;
      frames_not_ok += frame.status == recording::FrameStatus::kOk ? 0 : 1;
    }
  }
  Json out;
  out["dir"] = args.dir;
  out["software_version"] = reader.metadata().software_version;
  out["start_time"] = reader.metadata().start_time;
  out["sets"] = reader.sets().size();
  out["frames"] = frames;
  out["frames_not_ok"] = frames_not_ok;
  out["complete"] = complete;
  out["incomplete"] = reader.sets().size() - complete;
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
  out["bytes"] = folderBytes(args.dir);

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
  CLI::App* session = app.add_subcommand("session", "Recorded sessions");
  session->require_subcommand(1);
  CLI::App* info = session->add_subcommand(
      "info", "Print a session's summary as one JSON line; --verify checks every frame");
  auto args = std::make_shared<InfoArgs>();
  info->add_option("dir", args->dir, "Session folder")->required();
  info->add_flag("--verify", args->verify,
                 "Read every indexed frame back: size, PGM header and CRC-32; exit 3 on damage");
  info->callback([args, &exit_code] { exit_code = runInfo(*args); });
}

}  // namespace fieldrig::tools
