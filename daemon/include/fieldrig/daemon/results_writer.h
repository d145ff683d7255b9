// The per-plot results of a session, as the daemon and `fieldrig process` both write them, in one
// folder (default SESSION/results):
//   plots.jsonl    one JSON line per plot, appended durably as each plot is done (fdatasync);
//                  the line printed on stdout, and what a later run reads back to resume
//   plots.csv      the table (QGIS, spreadsheets): rewritten atomically from all plots
//   plots.geojson  one Point feature per plot: rewritten atomically likewise
// The tables are rewritten at most every `table_interval` while plots arrive, and at flush(), so
// a long day does not rewrite a growing file for every plot.
//
// Thread contract: thread-compatible; the daemon's processing thread owns it.
#pragma once

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "fieldrig/core/gps_fix.h"
#include "fieldrig/core/result.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/pipeline/plot_processor.h"
#include "fieldrig/traits/plot_report.h"

namespace fieldrig::daemon {

// Which set a result belongs to, and where and when it was taken.
struct PlotIdentity {
  std::optional<std::uint64_t> set_index;  // the session's set index, when known
  std::uint64_t trigger_id = 0;            // unique within a session: the key of a result
  std::optional<std::string> location_id;  // the map's imaging location
  std::string time;                        // ISO 8601, GPS time of the trigger
  std::optional<std::pair<double, double>> position;  // lat, lon
  std::string trigger_status;                         // "on_time", "late"; empty for manual
  // Why the position may not be the plot's: listed among the line's problems.
  std::optional<std::string> placement_problem;
};

// How far a map location may lie from the fix at its trigger before the line says so. A trigger
// fires within centimetres of its location with RTK and within a few metres without; tens of
// metres means a map of another field, or a fix that jumped.
inline constexpr double kMapToFixToleranceM = 10.0;

// The geodesic distance, m, between a map location and the fix at its trigger: what is held
// against kMapToFixToleranceM, for one plot (placePlot) and for a whole session's map
// (session_processing.h: checkMapMatchesSession).
double mapToFixMetres(const gps::ImagingLocation& location, const core::GpsFix& fix);

// Sets identity.position: the map location of identity.location_id when the map knows it, else
// the fix at the trigger (none without either). With a map, a location it lacks, or one farther
// than kMapToFixToleranceM from the fix, is said in identity.placement_problem: a map of another
// field must not place plots unseen.
void placePlot(PlotIdentity& identity, const std::optional<core::GpsFix>& fix,
               const gps::LocationMap* map);

// The result line: set, trigger_id, plot, location, time, lat, lon, trigger_status, cloud_points,
// partial, traits (traits::traitsToJson without slices and timings), problems.
nlohmann::ordered_json plotLine(const PlotIdentity& identity, const pipeline::PlotResult& result);

// The files of a results folder. `source` (source.json) names the session the results are of,
// once `fieldrig process` has written into the folder (session_processing.h: claimResultsFor).
struct ResultsFiles {
  std::filesystem::path jsonl, csv, geojson, source;
};
ResultsFiles resultsFiles(const std::filesystem::path& dir);

// Removes the results files from `dir` (nothing else in it), so that the next run does every set
// again instead of resuming.
void removeResults(const std::filesystem::path& dir);

struct ResultsOptions {
  bool csv = true;
  bool geojson = true;
  bool jsonl = true;
  std::chrono::milliseconds table_interval{5000};
};

class ResultsWriter {
 public:
  // Creates the folder, or reads back the plots.jsonl already there (a torn last line, from a
  // crash, is ignored and rewritten). The error names the file and line.
  static core::Result<std::unique_ptr<ResultsWriter>> open(const std::filesystem::path& dir,
                                                           ResultsOptions options = {});
  ~ResultsWriter();

  // What a result line says of its set, to tell a resumed session from another one.
  struct DoneSet {
    std::string location;  // empty: none
    std::string time;      // the trigger time as the line has it
  };
  bool contains(std::uint64_t trigger_id) const { return done_.count(trigger_id) > 0; }
  const std::map<std::uint64_t, DoneSet>& done() const { return done_; }
  std::size_t plots() const { return rows_.size(); }
  const std::filesystem::path& dir() const { return dir_; }

  // Appends one plotLine(); empty on success, else what failed, naming the file.
  std::string add(const nlohmann::ordered_json& line);
  // Rewrites the tables now; empty on success.
  std::string flush();

 private:
  ResultsWriter(std::filesystem::path dir, ResultsOptions options)
      : dir_(std::move(dir)), options_(options) {}
  std::string writeTables();

  std::filesystem::path dir_;
  ResultsOptions options_;
  std::vector<traits::PlotRow> rows_;
  std::map<std::uint64_t, DoneSet> done_;
  bool tables_stale_ = false;
  std::chrono::steady_clock::time_point tables_written_{};
};

}  // namespace fieldrig::daemon
