#include "fieldrig/daemon/results_writer.h"

#include <cmath>
#include <sstream>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/gps/local_frame.h"

namespace fieldrig::daemon {
namespace {

using Json = nlohmann::ordered_json;

Json optionalJson(const std::optional<std::string>& value) {
  return value ? Json(*value) : Json(nullptr);
}

}  // namespace

ResultsFiles resultsFiles(const std::filesystem::path& dir) {
  return {dir / "plots.jsonl", dir / "plots.csv", dir / "plots.geojson", dir / "source.json"};
}

void removeResults(const std::filesystem::path& dir) {
  const ResultsFiles files = resultsFiles(dir);
  std::error_code ec;  // a file that is not there is already removed
  for (const std::filesystem::path& file : {files.jsonl, files.csv, files.geojson, files.source})
    std::filesystem::remove(file, ec);
}

double mapToFixMetres(const gps::ImagingLocation& location, const core::GpsFix& fix) {
  return gps::geodesicDistanceMetres({location.latitude_deg, location.longitude_deg},
                                     {fix.latitude_deg, fix.longitude_deg});
}

void placePlot(PlotIdentity& identity, const std::optional<core::GpsFix>& fix,
               const gps::LocationMap* map) {
  identity.position.reset();
  identity.placement_problem.reset();
  const std::optional<std::string>& id = identity.location_id;
  const gps::ImagingLocation* location = map && id ? map->find(*id) : nullptr;
  if (location) {
    identity.position = std::pair{location->latitude_deg, location->longitude_deg};
    if (fix) {
      const double metres = mapToFixMetres(*location, *fix);
      if (metres > kMapToFixToleranceM) {
        identity.placement_problem = "map location " + *id + " is " +
                                     std::to_string(static_cast<long long>(std::lround(metres))) +
                                     " m from the fix at the trigger: placed at the map's "
                                     "location (a map of another field?)";
      }
    }
    return;
  }
  if (fix)
    identity.position = std::pair{fix->latitude_deg, fix->longitude_deg};
  if (map && id) {
    // Without a fix the line says, too, that it was placed at 0,0 (plotLine).
    identity.placement_problem = "location " + *id + " is not in the map" +
                                 (fix ? ": placed at the fix at the trigger" : "");
  }
}

nlohmann::ordered_json plotLine(const PlotIdentity& identity, const pipeline::PlotResult& result) {
  Json line;
  line["set"] = identity.set_index ? Json(*identity.set_index) : Json(nullptr);
  line["trigger_id"] = identity.trigger_id;
  line["plot"] = identity.location_id.value_or(
      identity.set_index ? "set-" + std::to_string(*identity.set_index)
                         : "trigger-" + std::to_string(identity.trigger_id));
  line["location"] = optionalJson(identity.location_id);
  line["time"] = identity.time;
  std::vector<std::string> problems = result.problems;
  if (identity.placement_problem)
    problems.push_back(*identity.placement_problem);
  if (identity.position) {
    line["lat"] = identity.position->first;
    line["lon"] = identity.position->second;
  } else {
    line["lat"] = 0.0;
    line["lon"] = 0.0;
    problems.push_back("no map location and no fix: placed at 0,0");
  }
  line["trigger_status"] = identity.trigger_status;
  line["cloud_points"] = result.cloud_points;
  line["partial"] = result.partial;
  // Only a line whose depth did not come from stereo says so: the rig's lines stay as they were.
  if (result.depth_source != cloud::DepthSource::kStereo)
    line["depth_source"] = cloud::toString(result.depth_source);
  Json heads = Json::array();
  for (const cloud::HeadStatus& head : result.heads) {
    Json head_json = {{"name", head.name},
                      {"ok", head.ok},
                      {"points", head.points},
                      {"valid_pixel_fraction", head.valid_pixel_fraction},
                      {"matched_column_fraction", head.matched_column_fraction}};
    if (head.stereo_score) {
      const stereo::DisparityTruthScore& score = *head.stereo_score;
      head_json["stereo_vs_truth"] = {{"vegetation_pixels", score.pixels},
                                      {"matched_fraction", score.matched_fraction},
                                      {"bad_fraction", score.bad_fraction},
                                      {"median_abs_depth_error_m", score.median_abs_depth_error_m},
                                      {"median_depth_error_m", score.median_depth_error_m}};
    }
    if (!head.truth_problem.empty())
      head_json["truth_problem"] = head.truth_problem;
    if (head.cloud_score) {
      head_json["points_vs_truth"] = {
          {"points", head.cloud_score->points},
          {"off_surface_3cm_fraction", head.cloud_score->off_surface_fraction},
          {"on_sky_fraction", head.cloud_score->on_sky_fraction},
          {"off_nearer_fraction", head.cloud_score->off_nearer_fraction},
          {"off_farther_fraction", head.cloud_score->off_farther_fraction},
          {"from_beyond_crop_fraction", head.cloud_score->from_beyond_crop_fraction}};
    }
    heads.push_back(std::move(head_json));
  }
  line["heads"] = std::move(heads);
  Json traits_json = traits::traitsToJson(result.traits, /*with_slices=*/false);
  // Timings are how long this machine took, not what the plot is: they stay out of the results,
  // so that the same inputs give byte-identical files (benchmarks and the status report them).
  traits_json.erase("timings_ms");
  line["traits"] = std::move(traits_json);
  line["problems"] = problems;
  return line;
}

namespace {

template <typename Line>
ResultsWriter::DoneSet doneSet(const Line& line) {
  ResultsWriter::DoneSet done;
  if (const auto location = line.find("location"); location != line.end() && location->is_string())
    done.location = location->template get<std::string>();
  done.time = line.at("time").template get<std::string>();
  return done;
}

}  // namespace

core::Result<std::unique_ptr<ResultsWriter>> ResultsWriter::open(const std::filesystem::path& dir,
                                                                 ResultsOptions options) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    return core::Error{dir.string() + ": cannot create folder: " + ec.message()};
  std::unique_ptr<ResultsWriter> writer(new ResultsWriter(dir, options));
  const std::filesystem::path lines_path = resultsFiles(dir).jsonl;
  if (!std::filesystem::exists(lines_path))
    return writer;
  std::string error;
  const std::optional<std::string> content = core::readWholeFile(lines_path, error);
  if (!content)
    return core::Error{error};
  std::istringstream in(*content);
  std::string text;
  std::size_t line_number = 0;
  std::size_t whole_bytes = 0;
  while (std::getline(in, text)) {
    ++line_number;
    if (in.eof())  // no newline: an append cut short by a crash; the plot is processed again
      break;
    whole_bytes += text.size() + 1;
    try {
      const Json line = Json::parse(text);
      auto row = traits::plotRowFromJson(
          line.at("plot").get<std::string>(), line.at("time").get<std::string>(),
          line.at("lat").get<double>(), line.at("lon").get<double>(), line.at("traits"));
      if (!row)
        throw std::runtime_error(row.error().message);
      writer->rows_.push_back(std::move(*row));
      writer->done_[line.at("trigger_id").get<std::uint64_t>()] = doneSet(line);
    } catch (const std::exception& e) {
      return core::Error{lines_path.string() + ":" + std::to_string(line_number) +
                         ": not a result line: " + e.what()};
    }
  }
  if (whole_bytes < content->size()) {
    if (const std::string failed =
            core::replaceFileAtomically(lines_path, content->substr(0, whole_bytes));
        !failed.empty()) {
      return core::Error{failed};
    }
  }
  return writer;
}

ResultsWriter::~ResultsWriter() {
  flush();
}

std::string ResultsWriter::add(const nlohmann::ordered_json& line) {
  if (options_.jsonl) {
    if (std::string failed = core::appendDurably(resultsFiles(dir_).jsonl, line.dump() + "\n");
        !failed.empty()) {
      return failed;
    }
  }
  auto row = traits::plotRowFromJson(
      line.at("plot").get<std::string>(), line.at("time").get<std::string>(),
      line.at("lat").get<double>(), line.at("lon").get<double>(), line.at("traits"));
  if (!row)
    return row.error().message;
  rows_.push_back(std::move(*row));
  done_[line.at("trigger_id").get<std::uint64_t>()] = doneSet(line);
  tables_stale_ = true;
  if (std::chrono::steady_clock::now() - tables_written_ >= options_.table_interval)
    return writeTables();
  return {};
}

std::string ResultsWriter::flush() {
  return tables_stale_ ? writeTables() : std::string();
}

std::string ResultsWriter::writeTables() {
  tables_written_ = std::chrono::steady_clock::now();
  tables_stale_ = false;
  if (options_.csv) {
    if (std::string failed =
            core::replaceFileAtomically(resultsFiles(dir_).csv, traits::formatCsv(rows_));
        !failed.empty()) {
      return failed;
    }
  }
  if (options_.geojson) {
    if (std::string failed =
            core::replaceFileAtomically(resultsFiles(dir_).geojson, traits::formatGeoJson(rows_));
        !failed.empty()) {
      return failed;
    }
  }
  return {};
}

}  // namespace fieldrig::daemon
