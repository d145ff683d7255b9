#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/trigger_replay.h"
#include "fieldrig/sim/drive_simulator.h"
#include "fieldrig/sim/synthetic_field.h"

namespace fieldrig::sim {
namespace {
namespace fs = std::filesystem;
}  // namespace

PlotSeries fieldPlotSeries(const FieldSpec& spec, int plots) {
  PlotSeries series;
  series.count = plots;
  series.seed = spec.seed;
  series.height_min_m = spec.height_min_m;
  series.height_max_m = spec.height_max_m;
  series.renderer = spec.renderer;
  series.stages = spec.stages;
  series.stage_heights = spec.stage_heights;
  series.truth_maps = spec.truth_maps;
  series.truth_traits = spec.truth_traits;
  return series;
}

std::optional<std::string> checkFieldFolder(const fs::path& dir) {
  if (dir.empty())
    return "an empty path";
  std::error_code ec;
  const fs::file_status status = fs::status(dir, ec);
  if (!fs::exists(status))
    return std::nullopt;
  if (!fs::is_directory(status))
    return dir.string() + ": exists and is not a folder";
  if (!fs::is_empty(dir, ec) || ec) {
    return dir.string() +
           ": already holds files (a field is written whole into a new or empty folder: remove "
           "it or give another)";
  }
  return std::nullopt;
}

namespace {

// Where a field's files are in folder `dir`.
void placeFieldFiles(const fs::path& dir, FieldFiles& files) {
  files.nmea = dir / "drive.nmea";
  files.map = dir / "map.csv";
  files.session = dir / "source-session";
  files.calibration = files.session / "calib";
  files.truth = dir / "truth.jsonl";
}

// The field's files in `dir` (which exists); `writeSyntheticField` puts them in place.
core::Result<FieldFiles> writeFieldInto(const fs::path& dir, const FieldSpec& spec,
                                        const std::function<void(const RecordedPlot&)>& progress) {
  std::error_code ec;
  // Rows running north near Ames, Iowa: 3 m plots with 1 m alleys, 90-inch row spacing.
  gps::FieldPlan plan;
  plan.rows = spec.rows;
  plan.plots_per_row = (spec.plots + spec.rows - 1) / spec.rows;
  plan.plot_length_m = 3.0;
  plan.alley_length_m = 1.0;
  plan.row_spacing_m = 2.286;
  plan.start_offset_m = 1.0;
  plan.row_start_latitude_deg = 42.0106;
  plan.row_start_longitude_deg = -93.7385;
  const double row_length_m = 1.0 + plan.plots_per_row * 4.0 + 1.0;
  plan.row_end_latitude_deg = plan.row_start_latitude_deg + row_length_m / 111'132.0;
  plan.row_end_longitude_deg = plan.row_start_longitude_deg;
  auto map = gps::generateLocations(plan);
  if (!map)
    return map.error();

  DriveOptions drive_options;
  drive_options.speed_mps = spec.speed_mps;
  drive_options.position_noise_m = spec.position_noise_m;
  drive_options.seed = spec.seed;
  const DriveSimulator drive(plan, drive_options);
  FieldFiles files;
  placeFieldFiles(dir, files);
  files.locations = map->size();
  const std::string nmea = drive.nmea();
  {
    std::ofstream out(files.nmea, std::ios::binary);
    out << nmea;
    if (!out.flush())
      return core::Error{files.nmea.string() + ": cannot write"};
  }
  // The order in which the replay will trigger the locations: the same planner on the same drive.
  std::vector<std::string> order;
  std::istringstream stream(nmea);
  gps::ReplayHandlers handlers;
  handlers.on_trigger = [&](const core::TriggerEvent& event) {
    order.push_back(event.location_id);
  };
  if (auto replayed = gps::replayTriggers(stream, *map, spec.triggers, handlers); !replayed)
    return replayed.error();
  if (order.size() > static_cast<std::size_t>(spec.plots))
    order.resize(static_cast<std::size_t>(spec.plots));
  // The map keeps the locations that get a plot: the others (the last row's tail when plots do
  // not fill it) would trigger sets with nothing rendered for them.
  gps::LocationMap kept(map->metadataColumns());
  for (const gps::ImagingLocation& location : map->locations()) {
    if (std::find(order.begin(), order.end(), location.id) != order.end()) {
      if (auto added = kept.add(location); !added)
        return added.error();
    }
  }
  files.locations = kept.size();
  if (auto saved = kept.save(files.map); !saved)
    return saved.error();

  const PlotSeries series = fieldPlotSeries(spec, static_cast<int>(order.size()));
  auto recorded = recordSyntheticPlots(files.session, files.calibration, series, order, progress);
  if (!recorded)
    return recorded.error();
  files.plots = recorded->size();
  fs::copy_file(files.session / "truth.jsonl", files.truth, fs::copy_options::overwrite_existing,
                ec);
  if (ec)
    return core::Error{files.truth.string() + ": cannot write: " + ec.message()};
  return files;
}

}  // namespace

core::Result<FieldFiles> writeSyntheticField(
    const fs::path& dir, const FieldSpec& spec,
    const std::function<void(const RecordedPlot&)>& progress) {
  if (spec.plots < 1 || spec.rows < 1 || spec.rows > spec.plots) {
    return core::Error{"synthetic field: need 1 <= rows <= plots (got " +
                       std::to_string(spec.rows) + " rows, " + std::to_string(spec.plots) +
                       " plots)"};
  }
  if (auto error = validatePlotSeries(fieldPlotSeries(spec, spec.plots)))
    return core::Error{"synthetic field: " + *error};
  if (auto error = checkFieldFolder(dir))
    return core::Error{*error};
  // "out/" names the folder "out"; the hidden staging folder sits beside it, on the same file
  // system, so that the final rename is atomic.
  fs::path target = dir.lexically_normal();
  if (target.filename().empty())
    target = target.parent_path();
  const fs::path staging =
      target.parent_path() / ("." + target.filename().string() + ".simulate-partial");
  std::error_code ec;
  fs::remove_all(staging, ec);  // what a killed run left
  fs::create_directories(staging, ec);
  if (ec)
    return core::Error{staging.string() + ": cannot create folder: " + ec.message()};
  auto written = writeFieldInto(staging, spec, progress);
  if (written) {
    fs::remove(target, ec);  // an empty folder the caller made (rename cannot replace it)
    ec.clear();
    fs::rename(staging, target, ec);
    if (ec)
      written = core::Error{target.string() + ": cannot move the field in place from " +
                            staging.string() + ": " + ec.message()};
  }
  if (!written) {
    fs::remove_all(staging, ec);
    return written.error();
  }
  FieldFiles files = *written;
  placeFieldFiles(dir, files);
  return files;
}

}  // namespace fieldrig::sim
