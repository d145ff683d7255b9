// Offline processing of a recorded session, as `fieldrig process` runs it: every set (or every
// N-th, for one shard of a batch job) through the plot processor into a results folder, by the
// same adapter, result line and results writer as fieldrigd's live processing. It resumes: a set
// whose trigger id the results already hold is skipped. A set that cannot be processed is kept in
// the results with its status; it never stops the run.
#pragma once

#include <cstddef>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "fieldrig/core/result.h"
#include "fieldrig/daemon/head_frames.h"
#include "fieldrig/daemon/results_writer.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/pipeline/plot_processor.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::daemon {

struct SessionProcessingOptions {
  // This run takes the sets at positions shard_index, shard_index + shard_count, …: shards of a
  // batch job get the same number of sets (±1) whatever the sessions' lengths.
  std::size_t shard_index = 0;
  std::size_t shard_count = 1;
  // Only the sets at positions [first_position, end_position) of the index: the contiguous part
  // of a session that one task of a batch plan (daemon/batch_job.h) owns.
  std::size_t first_position = 0;
  std::size_t end_position = static_cast<std::size_t>(-1);
  // Also write each set's fused cloud here as PLOT_setN.ply (the processor must keep_cloud).
  std::optional<std::filesystem::path> clouds_dir;
  // The simulator's truth maps to hand the processor with each set (head_frames.h): the depth for
  // cloud::DepthSource::kTruth, depth and vegetation to score stereo. A map that cannot be read
  // is named in its set's problems and its head goes without it (check first that they are
  // there: checkTruthMaps).
  TruthMaps truth_maps = TruthMaps::kNone;
};

// Where a run writes its results unless told: SESSION/results, and one shard of several
// SESSION/results/shard-K-of-N, so that shards never write the same file.
std::filesystem::path defaultResultsDir(const std::filesystem::path& session_dir,
                                        const SessionProcessingOptions& options);

struct SessionProcessingSummary {
  std::size_t sets = 0;  // processed by this run
  std::size_t ok = 0;    // of those, with traits status ok
  std::size_t partial_clouds = 0;
  std::size_t unplaced = 0;  // neither a map location nor a fix
  // Placed, but with a placement_problem on the line (results_writer.h): a location the map
  // lacks, or a map location far from the fix at the trigger.
  std::size_t placement_problems = 0;
  std::size_t already_done = 0;  // skipped: in the results before this run
};

// Resuming skips the sets whose trigger ids the results hold, which is only right for results of
// this session: the error names the results file and a trigger whose location or trigger time
// differs there (results of another session, e.g. the same --out given for two sessions).
core::Result<void> checkResultsMatchSession(const recording::SessionReader& reader,
                                            const ResultsWriter& results);

// The trigger check above cannot tell apart two sessions whose sets have the same locations and
// trigger times (two synthetic fields of one layout). So the results folder records the session it
// is of, by the start time in its session.json (which stays when a session is reopened or moved):
// the first run writes DIR/source.json, and a later one of a session started at another time is
// refused, naming both (removeResults, i.e. --force, clears it). A folder without the file (the
// daemon's live results) is claimed by the first run that writes into it after the trigger check.
core::Result<void> claimResultsFor(const recording::SessionReader& reader,
                                   const std::filesystem::path& results_dir);

// A map that places none of the session's located sets where they were taken is of another field:
// the error names `map_name` and the first set, when no located set's id is in the map, or when
// every one that has a fix lies farther than kMapToFixToleranceM from its map location. A map that
// misses or misplaces only some is taken, and each such line says so (placePlot).
core::Result<void> checkMapMatchesSession(const recording::SessionReader& reader,
                                          const gps::LocationMap& map, const std::string& map_name);

// `on_line` sees each set's result line before it is added to `results`; `on_problem` hears of a
// cloud that cannot be written, and of a set whose trigger id an earlier set of the index already
// has (a damaged index: only the first is processed). The error names a results file that cannot
// be written (the run stops there), or results of another session: a line whose trigger id is a
// set's here but whose location or trigger time is not (nothing is processed then). `map` may be
// null.
core::Result<SessionProcessingSummary> processSession(
    const recording::SessionReader& reader, pipeline::PlotProcessor& processor,
    const gps::LocationMap* map, ResultsWriter& results, const SessionProcessingOptions& options,
    const std::function<void(const nlohmann::ordered_json&)>& on_line,
    const std::function<void(const std::string&)>& on_problem);

}  // namespace fieldrig::daemon
