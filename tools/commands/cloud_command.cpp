// `fieldrig cloud --pairs L1,R1,L2,R2,L3,R3 --calib DIR --out plot.ply` or
// `fieldrig cloud SESSION --set ID [--calib DIR] --out plot.ply`: one FrameSet's three heads fused
// into a plot-frame cloud (binary PLY). Prints one JSON line on success; bad input exits 2 with a
// message naming the file.
#include <chrono>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>

#include "commands/command_helpers.h"
#include "fieldrig/cloud/fusion.h"
#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/core/time.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct CloudArgs {
  std::string session, pairs, calib, out;
  std::int64_t set = -1;
  bool wls = false;
};

std::vector<std::string> splitCommas(const std::string& text) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, ','))
    parts.push_back(part);
  return parts;
}

int runCloud(const CloudArgs& args) {
  const char* who = "fieldrig cloud: ";
  const auto start = std::chrono::steady_clock::now();
  if (args.session.empty() == args.pairs.empty())
    return fail(who, "give either a SESSION (with --set) or --pairs");
  std::optional<recording::SessionReader> reader;
  if (!args.session.empty()) {
    if (args.set < 0)
      return fail(who, "--set is required with a SESSION");
    auto opened = recording::SessionReader::open(args.session);
    if (!opened)
      return fail(who, opened.error().message);
    reader = std::move(*opened);
  }
  auto rig = daemon::loadRigFor(args.calib, reader ? &*reader : nullptr);
  if (!rig)
    return fail(who, rig.error().message);
  const std::vector<std::string> files = splitCommas(args.pairs);
  if (!reader && files.size() != 2 * rig->heads.size()) {
    std::cerr << who << "--pairs names " << files.size() << " files; the rig in "
              << (std::filesystem::path(args.calib) / "rig.yml").string() << " has "
              << rig->heads.size() << " heads, so " << 2 * rig->heads.size()
              << " are needed (L1,R1,L2,R2,…)\n";
    return kExitBadInput;
  }
  std::vector<std::string> problems;
  const auto frames = reader ? daemon::headFramesFromRecording(
                                   *reader, static_cast<std::uint64_t>(args.set), *rig, problems)
                             : daemon::headFramesFromImageFiles(files, *rig);
  if (!frames)
    return fail(who, frames.error().message);
  cloud::CloudOptions options;
  options.matcher.wls = args.wls;
  auto builder = cloud::CloudBuilder::create(*rig, options);
  if (!builder)
    return fail(who, builder.error().message);
  const cloud::FusionResult result = builder->build(*frames);
  Json heads = Json::array();
  for (const cloud::HeadStatus& head : result.heads) {
    Json h;
    h["name"] = head.name;
    h["ok"] = head.ok;
    h["points"] = head.points;
    if (!head.ok) {
      h["problem"] = head.problem;
      std::cerr << who << "head left out: " << head.problem << '\n';
    }
    heads.push_back(std::move(h));
  }
  for (const std::string& problem : problems)
    std::cerr << who << problem << '\n';
  if (result.cloud.empty())
    return fail(who, "no head gave any point; nothing written");
  if (auto written = cloud::writePly(result.cloud, args.out); !written)
    return fail(who, written.error().message);
  Json out;
  out["out"] = args.out;
  out["points"] = result.cloud.size();
  out["partial"] = result.partial();
  out["heads"] = std::move(heads);
  out["problems"] = problems;
  out["ms"] = core::millisecondsSince(start);
  return printJsonLine(out);
}

}  // namespace

void registerCloudCommand(CLI::App& app, int& exit_code) {
  const auto [cmd, args] = addSubcommand(
      app, "cloud", "Fused three-head point cloud of one FrameSet in the plot frame (binary PLY)",
      exit_code, runCloud);
  cmd->add_option("session", args->session, "Recorded session folder");
  cmd->add_option("--set", args->set, "Set index in the session")
      ->check(finiteRange<std::int64_t>(0, std::numeric_limits<std::int64_t>::max()));
  cmd->add_option("--pairs", args->pairs, "L1,R1,L2,R2,L3,R3 image files, heads in rig order");
  cmd->add_option("--calib", args->calib,
                  "Calibration folder (rig.yml + one folder per head); for a session, "
                  "defaults to its calibration reference named calib_dir");
  cmd->add_flag("--wls", args->wls, "Apply the WLS disparity filter");
  cmd->add_option("--out", args->out, "Output .ply")->required();
}

}  // namespace fieldrig::tools
