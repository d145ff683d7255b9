// `fieldrig process SESSION [--calib DIR] [--map MAP.csv] [--traits-config FILE] [--out DIR]`:
// every FrameSet of a recorded session through the whole pipeline (three heads → fused cloud →
// plot traits), written as OUT/plots.csv and OUT/plots.geojson (one feature per plot, QGIS opens
// both) and one JSON line per set on stdout. A set that cannot be processed is reported with its
// status and kept in the outputs; it never stops the run.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "commands/commands.h"
#include "commands/session_frames.h"
#include "fieldrig/cloud/fusion.h"
#include "fieldrig/core/time.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/recording/session_reader.h"
#include "fieldrig/traits/plot_report.h"
#include "fieldrig/traits/traits_config.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

struct ProcessArgs {
  std::string session, calib, map, traits_config, out;
  bool clouds = false;
};

// Where a set's plot is: its map location when the map knows it, else the fix at the trigger.
std::optional<std::pair<double, double>> plotPosition(const recording::IndexedSet& set,
                                                      const gps::LocationMap* map) {
  if (map && set.location_id) {
    if (const gps::ImagingLocation* location = map->find(*set.location_id)) {
      return std::pair{location->latitude_deg, location->longitude_deg};
    }
  }
  if (set.fix)
    return std::pair{set.fix->latitude_deg, set.fix->longitude_deg};
  return std::nullopt;
}

int runProcess(const ProcessArgs& args) {
  const char* who = "fieldrig process: ";
  auto opened = recording::SessionReader::open(args.session);
  if (!opened) {
    std::cerr << who << opened.error().message << '\n';
    return kExitBadInput;
  }
  const recording::SessionReader& reader = *opened;
  auto rig = loadRigFor(args.calib, &reader);
  if (!rig) {
    std::cerr << who << rig.error().message << '\n';
    return kExitBadInput;
  }
  traits::TraitsOptions options;
  if (!args.traits_config.empty()) {
    auto loaded = traits::loadTraitsOptions(args.traits_config);
    if (!loaded) {
      std::cerr << who << loaded.error().message << '\n';
      return kExitBadInput;
    }
    options = *loaded;
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
  auto builder = cloud::CloudBuilder::create(*rig);
  if (!builder) {
    std::cerr << who << builder.error().message << '\n';
    return kExitBadInput;
  }
  const fs::path out_dir = args.out.empty() ? reader.dir() / "results" : fs::path(args.out);
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec) {
    std::cerr << who << out_dir.string() << ": cannot create folder: " << ec.message() << '\n';
    return kExitBadInput;
  }

  std::vector<traits::PlotRecord> records;
  std::size_t ok_sets = 0;
  std::size_t partial_clouds = 0;
  std::size_t unplaced = 0;
  for (const recording::IndexedSet& set : reader.sets()) {
    std::vector<std::string> problems;
    Json line;
    line["set"] = set.set_index;
    line["location"] = set.location_id ? Json(*set.location_id) : Json(nullptr);
    auto frames = framesFromSession(reader, set.set_index, *rig, problems);
    traits::PlotRecord record;
    record.plot_id = set.location_id.value_or("set-" + std::to_string(set.set_index));
    record.time = core::formatIso8601(set.trigger_time, 6);
    if (const auto position = plotPosition(set, map ? &*map : nullptr)) {
      std::tie(record.lat_deg, record.lon_deg) = *position;
    } else {
      ++unplaced;
      problems.push_back("no map location and no fix: placed at 0,0");
    }
    if (frames) {
      const cloud::FusionResult fused = builder->build(*frames);
      partial_clouds += fused.partial() ? 1 : 0;
      for (const cloud::HeadStatus& head : fused.heads) {
        if (!head.ok)
          problems.push_back("head " + head.name + " left out: " + head.problem);
      }
      std::vector<Eigen::Vector3f> points;
      points.reserve(fused.cloud.size());
      for (const auto& point : fused.cloud)
        points.emplace_back(point.x, point.y, point.z);
      if (args.clouds) {
        const fs::path ply =
            out_dir / (record.plot_id + "_set" + std::to_string(set.set_index) + ".ply");
        if (auto written = cloud::writePly(fused.cloud, ply); !written) {
          problems.push_back(written.error().message);
        }
      }
      record.traits = traits::computeTraits(points, traits::InputFrame::kPlot, options);
      line["cloud_points"] = fused.cloud.size();
      line["partial"] = fused.partial();
    } else {
      problems.push_back(frames.error().message);
      record.traits.status = traits::TraitsStatus::kEmptyCloud;
      record.traits.message = frames.error().message;
    }
    ok_sets += record.traits.status == traits::TraitsStatus::kOk ? 1 : 0;
    line["traits"] = traits::traitsToJson(record.traits, /*with_slices=*/false);
    line["problems"] = problems;
    std::cout << line.dump() << std::endl;
    records.push_back(std::move(record));
  }

  const fs::path csv = out_dir / "plots.csv";
  const fs::path geojson = out_dir / "plots.geojson";
  for (const auto& [path, text] : {std::pair{csv, traits::formatCsv(records)},
                                   std::pair{geojson, traits::formatGeoJson(records)}}) {
    if (auto written = traits::writeText(path.string(), text); !written) {
      std::cerr << who << written.error().message << '\n';
      return kExitRuntime;
    }
  }
  Json summary;
  summary["sets"] = records.size();
  summary["ok"] = ok_sets;
  summary["partial_clouds"] = partial_clouds;
  summary["unplaced"] = unplaced;
  summary["csv"] = csv.string();
  summary["geojson"] = geojson.string();
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
  process->add_option("--traits-config", args->traits_config, "Traits options (JSON)");
  process->add_option("--out", args->out, "Output folder (default SESSION/results)");
  process->add_flag("--clouds", args->clouds, "Also write each set's fused cloud as PLY");
  process->callback([args, &exit_code] { exit_code = runProcess(*args); });
}

}  // namespace fieldrig::tools
