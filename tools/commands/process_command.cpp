// `fieldrig process SESSION [--calib DIR] [--map MAP.csv] [--config FILE] [--traits-config FILE]
//  [--out DIR] [--shard K/N] [--force] [--clouds] [--depth-source stereo|truth] [--score-stereo]`:
//  every FrameSet of a recorded session through
// the plot processor, the daemon's own (daemon/session_processing.h), into the results folder
// (plots.jsonl, plots.csv, plots.geojson; daemon/results_writer.h), one JSON line per set on stdout
// and a summary line last. It resumes: sets already in the folder's plots.jsonl (by trigger id) are
// skipped unless --force. On a session rendered by `fieldrig simulate` (mesh renderer), the depth
// may come from the rendered truth instead of stereo (--depth-source truth), and stereo may be
// scored against that truth per head (--score-stereo): bench/attribution_bench.py.
#include <charconv>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands/command_helpers.h"
#include "fieldrig/config/config.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/daemon/results_writer.h"
#include "fieldrig/daemon/session_processing.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/pipeline/plot_processor.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct ProcessArgs {
  std::string session, calib, map, config, traits_config, out, shard;
  std::string depth_source = "stereo";
  bool score_stereo = false;
  bool clouds = false;
  bool force = false;
};

// "K/N" with 0 ≤ K < N into the run's shard.
bool parseShard(const std::string& text, daemon::SessionProcessingOptions& run) {
  const auto slash = text.find('/');
  if (slash == std::string::npos)
    return false;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto k = std::from_chars(begin, begin + slash, run.shard_index);
  const auto n = std::from_chars(begin + slash + 1, end, run.shard_count);
  return k.ec == std::errc{} && k.ptr == begin + slash && n.ec == std::errc{} && n.ptr == end &&
         run.shard_count != 0 && run.shard_index < run.shard_count;
}

int runProcess(const ProcessArgs& args) {
  const char* who = "fieldrig process: ";
  daemon::SessionProcessingOptions run;
  if (!args.shard.empty() && !parseShard(args.shard, run)) {
    std::cerr << who << "--shard '" << args.shard << "': expected K/N with 0 <= K < N\n";
    return kExitBadInput;
  }
  auto opened = recording::SessionReader::open(args.session);
  if (!opened)
    return fail(who, opened.error().message);
  const recording::SessionReader& reader = *opened;
  // A crash while a set was being indexed leaves a torn last line: that set is left out, and
  // said so here rather than vanishing from the results.
  if (const auto& torn = reader.tornLine()) {
    std::cerr << who << (reader.dir() / recording::kIndexFile).string() << ":" << torn->line
              << ": a torn last line (" << torn->bytes
              << " bytes, a write cut short): its set is left out\n";
  }
  auto rig = daemon::loadRigFor(args.calib, &reader);
  if (!rig)
    return fail(who, rig.error().message);
  pipeline::ProcessorOptions options;
  options.keep_cloud = args.clouds;
  if (!args.config.empty()) {  // the daemon's file: its processing options, nothing else
    auto loaded = config::loadConfig(args.config);
    if (!loaded)
      return fail(who, loaded.error().message);
    options.cloud = loaded->pipeline.cloud;
    options.traits = loaded->pipeline.traits;
  }
  if (!args.traits_config.empty()) {  // overrides the configuration's traits
    auto loaded = config::loadTraitsOptions(args.traits_config);
    if (!loaded)
      return fail(who, loaded.error().message);
    options.traits = *loaded;
  }
  if (args.depth_source == "truth") {
    options.cloud.depth_source = cloud::DepthSource::kTruth;
    run.truth_maps = daemon::TruthMaps::kDepth;
  } else if (args.depth_source == "truth-where-matched") {
    options.cloud.depth_source = cloud::DepthSource::kTruthWhereMatched;
    run.truth_maps = daemon::TruthMaps::kDepth;
  }
  if (args.score_stereo)
    run.truth_maps = daemon::TruthMaps::kDepthAndVegetation;
  if (args.depth_source == "truth" && args.score_stereo) {
    std::cerr << who << "--score-stereo scores stereo, which --depth-source truth does not run\n";
    return kExitBadInput;
  }
  // Every truth map is checked before anything is written: a session without them is refused
  // whole, naming the first missing file, rather than failing part-way.
  if (run.truth_maps != daemon::TruthMaps::kNone) {
    if (auto present = daemon::checkTruthMaps(reader, *rig, run.truth_maps); !present)
      return fail(who, present.error().message);
  }
  std::optional<gps::LocationMap> map;
  if (!args.map.empty()) {
    auto loaded = gps::LocationMap::load(args.map);
    if (!loaded)
      return fail(who, loaded.error().message);
    if (auto matches = daemon::checkMapMatchesSession(reader, *loaded, args.map); !matches)
      return fail(who, matches.error().message);
    map = std::move(*loaded);
  }
  auto processor = pipeline::PlotProcessor::create(*rig, options);
  if (!processor)
    return fail(who, processor.error().message);
  const fs::path out_dir =
      args.out.empty() ? daemon::defaultResultsDir(reader.dir(), run) : fs::path(args.out);
  if (args.force)
    daemon::removeResults(out_dir);
  auto results = daemon::ResultsWriter::open(out_dir);
  if (!results)
    return fail(who, results.error().message);
  if (auto matches = daemon::checkResultsMatchSession(reader, **results); !matches)
    return fail(who, matches.error().message);
  if (auto claimed = daemon::claimResultsFor(reader, out_dir); !claimed)
    return fail(who, claimed.error().message);
  if (args.clouds)
    run.clouds_dir = out_dir;
  auto done = daemon::processSession(
      reader, *processor, map ? &*map : nullptr, **results, run,
      [](const Json& line) { std::cout << line.dump() << std::endl; },
      [who](const std::string& problem) { std::cerr << who << problem << '\n'; });
  if (!done)
    return fail(who, done.error().message, kExitRuntime);
  Json summary;
  summary["sets"] = done->sets;
  summary["ok"] = done->ok;
  summary["partial_clouds"] = done->partial_clouds;
  summary["unplaced"] = done->unplaced;
  summary["placement_problems"] = done->placement_problems;
  summary["already_done"] = done->already_done;
  summary["torn_index_line"] = reader.tornLine() ? Json(reader.tornLine()->line) : Json(nullptr);
  summary["plots_in_results"] = (*results)->plots();
  const daemon::ResultsFiles files = daemon::resultsFiles(out_dir);
  summary["csv"] = files.csv.string();
  summary["geojson"] = files.geojson.string();
  summary["jsonl"] = files.jsonl.string();
  std::cout << Json{{"summary", summary}}.dump() << std::endl;
  return kExitOk;
}

}  // namespace

void registerProcessCommand(CLI::App& app, int& exit_code) {
  const auto [process, args] = addSubcommand(
      app, "process", "Every FrameSet of a session → fused cloud → plot traits (CSV and GeoJSON)",
      exit_code, runProcess);
  process->add_option("session", args->session, "Session folder")->required();
  process->add_option("--calib", args->calib,
                      "Calibration folder (rig.yml + one folder per head); default: the "
                      "session's calib_dir reference");
  process->add_option("--map", args->map, "Location map: plots placed at their map location");
  process->add_option("--config", args->config,
                      "fieldrigd configuration (YAML) whose pipeline.cloud, pipeline.matcher and "
                      "pipeline.traits are used, so that a session is processed as the daemon "
                      "processed it");
  process->add_option("--traits-config", args->traits_config,
                      "Traits options (YAML or JSON: the keys of pipeline.traits); override "
                      "--config's");
  process->add_option("--out", args->out,
                      "Output folder (default SESSION/results, or SESSION/results/shard-K-of-N)");
  process->add_option("--shard", args->shard,
                      "Process every N-th set starting at the K-th (0 <= K < N), e.g. "
                      "$SLURM_ARRAY_TASK_ID/N");
  process->add_flag("--force", args->force,
                    "Process every set again (default: resume, skipping the sets already in the "
                    "results)");
  process->add_flag("--clouds", args->clouds, "Also write each set's fused cloud as PLY");
  process
      ->add_option("--depth-source", args->depth_source,
                   "Where each head's depth comes from: stereo (matching, the default), truth "
                   "(the left camera's rendered depth map that `fieldrig simulate` writes beside "
                   "each frame, through the same fusion, crop and traits; result lines say "
                   "\"depth_source\": \"truth\") or truth-where-matched (stereo runs, then its "
                   "matched pixels take the truth's depth and the others none: what the pixels "
                   "stereo leaves out cost, apart from its depth errors)")
      ->check(CLI::IsMember({"stereo", "truth", "truth-where-matched"}));
  process->add_flag("--score-stereo", args->score_stereo,
                    "Score each head's stereo against the rendered truth depth (sessions of "
                    "`fieldrig simulate`): heads[].stereo_vs_truth in each result line, over "
                    "vegetation pixels within the depth crop; bad = disparity error > 2 px");
}

}  // namespace fieldrig::tools
