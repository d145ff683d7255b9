// `fieldrig process SESSION [--calib DIR] [--map MAP.csv] [--config FILE] [--traits-config FILE]
//  [--out DIR] [--shard K/N] [--force] [--clouds]`: every FrameSet of a recorded session through
//  the plot
// processor (three heads → fused cloud → plot traits), the daemon's own, into the results folder
// (plots.jsonl, plots.csv, plots.geojson; daemon/results_writer.h) and one JSON line per set on
// stdout. It resumes: sets already in the folder's plots.jsonl (by trigger id) are skipped unless
// --force. A set that cannot be processed is reported with its status and kept in the outputs;
// it never stops the run.
#include <charconv>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands/commands.h"
#include "fieldrig/cloud/fusion.h"
#include "fieldrig/config/config.h"
#include "fieldrig/core/time.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/daemon/results_writer.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/pipeline/plot_processor.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct ProcessArgs {
  std::string session, calib, map, config, traits_config, out, shard;
  bool clouds = false;
  bool force = false;
};

struct Shard {
  std::size_t index = 0;  // 0 … count-1
  std::size_t count = 1;
};

// "K/N" with 0 ≤ K < N: this run takes every N-th set starting at the K-th, so shards get the
// same number of sets (±1) whatever the sessions' lengths.
std::optional<Shard> parseShard(const std::string& text) {
  const auto slash = text.find('/');
  if (slash == std::string::npos)
    return std::nullopt;
  Shard shard;
  const char* begin = text.data();
  const char* end = begin + text.size();
  const auto k = std::from_chars(begin, begin + slash, shard.index);
  const auto n = std::from_chars(begin + slash + 1, end, shard.count);
  if (k.ec != std::errc{} || k.ptr != begin + slash || n.ec != std::errc{} || n.ptr != end ||
      shard.count == 0 || shard.index >= shard.count) {
    return std::nullopt;
  }
  return shard;
}

int runProcess(const ProcessArgs& args) {
  const char* who = "fieldrig process: ";
  Shard shard;
  if (!args.shard.empty()) {
    const auto parsed = parseShard(args.shard);
    if (!parsed) {
      std::cerr << who << "--shard '" << args.shard << "': expected K/N with 0 <= K < N\n";
      return kExitBadInput;
    }
    shard = *parsed;
  }
  auto opened = recording::SessionReader::open(args.session);
  if (!opened) {
    std::cerr << who << opened.error().message << '\n';
    return kExitBadInput;
  }
  const recording::SessionReader& reader = *opened;
  auto rig = daemon::loadRigFor(args.calib, &reader);
  if (!rig) {
    std::cerr << who << rig.error().message << '\n';
    return kExitBadInput;
  }
  pipeline::ProcessorOptions options;
  options.keep_cloud = args.clouds;
  if (!args.config.empty()) {  // the daemon's file: its processing options, nothing else
    auto loaded = config::loadConfig(args.config);
    if (!loaded) {
      std::cerr << who << loaded.error().message << '\n';
      return kExitBadInput;
    }
    options.cloud = loaded->pipeline.cloud;
    options.traits = loaded->pipeline.traits;
  }
  if (!args.traits_config.empty()) {  // overrides the configuration's traits
    auto loaded = config::loadTraitsOptions(args.traits_config);
    if (!loaded) {
      std::cerr << who << loaded.error().message << '\n';
      return kExitBadInput;
    }
    options.traits = *loaded;
  }
  std::optional<gps::LocationMap> map;
  if (!args.map.empty()) {
    auto loaded = gps::LocationMap::load(args.map);
    if (!loaded) {
      std::cerr << who << loaded.error().message << '\n';
      return kExitBadInput;
    }
    map = std::move(*loaded);
  }
  auto processor = pipeline::PlotProcessor::create(*rig, options);
  if (!processor) {
    std::cerr << who << processor.error().message << '\n';
    return kExitBadInput;
  }
  fs::path out_dir = args.out.empty() ? reader.dir() / "results" : fs::path(args.out);
  if (args.out.empty() && shard.count > 1) {  // shards never write the same file
    out_dir /= "shard-" + std::to_string(shard.index) + "-of-" + std::to_string(shard.count);
  }
  if (args.force) {
    std::error_code ec;
    for (const char* name : {"plots.jsonl", "plots.csv", "plots.geojson"})
      fs::remove(out_dir / name, ec);
  }
  auto results = daemon::ResultsWriter::open(out_dir);
  if (!results) {
    std::cerr << who << results.error().message << '\n';
    return kExitBadInput;
  }

  std::size_t sets = 0, ok_sets = 0, partial_clouds = 0, unplaced = 0, skipped = 0;
  for (std::size_t position = 0; position < reader.sets().size(); ++position) {
    const recording::IndexedSet& set = reader.sets()[position];
    if (position % shard.count != shard.index)
      continue;
    if ((*results)->contains(set.trigger_id)) {
      ++skipped;
      continue;
    }
    std::vector<std::string> problems;
    auto frames = daemon::headFramesFromRecording(reader, set.set_index, *rig, problems);
    pipeline::PlotResult result;
    if (frames) {
      result = processor->process(*frames, std::move(problems));
    } else {
      result.problems = std::move(problems);
      result.problems.push_back(frames.error().message);
      result.traits.status = traits::TraitsStatus::kEmptyCloud;
      result.traits.message = frames.error().message;
    }
    daemon::PlotIdentity identity;
    identity.set_index = set.set_index;
    identity.trigger_id = set.trigger_id;
    identity.location_id = set.location_id;
    identity.time = core::formatIso8601(set.trigger_time, 6);
    identity.position = daemon::plotPosition(set.location_id, set.fix, map ? &*map : nullptr);
    identity.trigger_status = set.trigger_status.value_or("");
    const Json line = daemon::plotLine(identity, result);
    if (args.clouds && frames) {
      const fs::path ply = out_dir / (line.at("plot").get<std::string>() + "_set" +
                                      std::to_string(set.set_index) + ".ply");
      if (auto written = cloud::writePly(result.cloud, ply); !written)
        std::cerr << who << written.error().message << '\n';
    }
    ++sets;
    ok_sets += result.traits.status == traits::TraitsStatus::kOk ? 1 : 0;
    partial_clouds += result.partial ? 1 : 0;
    unplaced += identity.position ? 0 : 1;
    std::cout << line.dump() << std::endl;
    if (const std::string failed = (*results)->add(line); !failed.empty()) {
      std::cerr << who << failed << '\n';
      return kExitRuntime;
    }
  }
  if (const std::string failed = (*results)->flush(); !failed.empty()) {
    std::cerr << who << failed << '\n';
    return kExitRuntime;
  }
  Json summary;
  summary["sets"] = sets;
  summary["ok"] = ok_sets;
  summary["partial_clouds"] = partial_clouds;
  summary["unplaced"] = unplaced;
  summary["already_done"] = skipped;
  summary["plots_in_results"] = (*results)->plots();
  summary["csv"] = (out_dir / "plots.csv").string();
  summary["geojson"] = (out_dir / "plots.geojson").string();
  summary["jsonl"] = (out_dir / "plots.jsonl").string();
  std::cout << Json{{"summary", summary}}.dump() << std::endl;
  return kExitOk;
}

}  // namespace

void registerProcessCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ProcessArgs>();
  CLI::App* process = app.add_subcommand(
      "process", "Every FrameSet of a session → fused cloud → plot traits (CSV and GeoJSON)");
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
  process->callback([args, &exit_code] { exit_code = runProcess(*args); });
}

}  // namespace fieldrig::tools
