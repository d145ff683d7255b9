#include "fieldrig/daemon/session_processing.h"

#include <algorithm>
#include <cmath>
#include <set>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/core/time.h"
#include "fieldrig/daemon/head_frames.h"

namespace fieldrig::daemon {

std::filesystem::path defaultResultsDir(const std::filesystem::path& session_dir,
                                        const SessionProcessingOptions& options) {
  std::filesystem::path dir = session_dir / "results";
  if (options.shard_count > 1) {
    dir /= "shard-" + std::to_string(options.shard_index) + "-of-" +
           std::to_string(options.shard_count);
  }
  return dir;
}

core::Result<void> checkResultsMatchSession(const recording::SessionReader& reader,
                                            const ResultsWriter& results) {
  // Resuming skips the sets whose trigger ids the results hold: only right when the results are
  // of this session. Results of another one (an --out given twice) would skip its sets unseen.
  for (const recording::IndexedSet& set : reader.sets()) {
    const auto done = results.done().find(set.trigger_id);
    if (done == results.done().end())
      continue;
    const std::string time = core::formatIso8601(set.trigger_time, 6);
    const std::string location = set.location_id.value_or("");
    // A manual trigger's line may carry the rig's send time where the index has the host's.
    const bool times_differ = !location.empty() && done->second.time != time;
    if (done->second.location != location || times_differ) {
      return core::Error{resultsFiles(results.dir()).jsonl.string() + ": trigger " +
                         std::to_string(set.trigger_id) + " is " +
                         (done->second.location.empty() ? "no location" : done->second.location) +
                         " at " + done->second.time + " there but " +
                         (location.empty() ? "no location" : location) + " at " + time + " in " +
                         reader.dir().string() +
                         ": results of another session (give another results folder, or --force)"};
    }
  }
  return {};
}

core::Result<void> claimResultsFor(const recording::SessionReader& reader,
                                   const std::filesystem::path& results_dir) {
  const std::string& start_time = reader.metadata().start_time;
  const std::filesystem::path source = resultsFiles(results_dir).source;
  std::error_code ec;
  if (std::filesystem::exists(source, ec)) {
    std::string error;
    const std::optional<std::string> text = core::readWholeFile(source, error);
    if (!text)
      return core::Error{error};
    std::string claimed_start, claimed_session;
    try {
      const nlohmann::json claimed = nlohmann::json::parse(*text);
      claimed_start = claimed.at("start_time").get<std::string>();
      claimed_session = claimed.at("session").get<std::string>();
    } catch (const std::exception& e) {
      return core::Error{source.string() + ": not a results source record (" + e.what() +
                         "); remove it, or give --force"};
    }
    if (claimed_start == start_time)
      return {};
    return core::Error{source.string() + ": the results are of the session started at " +
                       claimed_start + " (" + claimed_session + "), but " + reader.dir().string() +
                       " started at " + start_time +
                       ": results of another session (give another results folder, or --force)"};
  }
  const nlohmann::ordered_json record = {
      {"session", std::filesystem::absolute(reader.dir(), ec).string()},
      {"start_time", start_time}};
  if (std::string failed = core::replaceFileAtomically(source, record.dump(2) + "\n");
      !failed.empty())
    return core::Error{std::move(failed)};
  return {};
}

core::Result<void> checkMapMatchesSession(const recording::SessionReader& reader,
                                          const gps::LocationMap& map,
                                          const std::string& map_name) {
  const recording::IndexedSet* first_located = nullptr;
  const recording::IndexedSet* first_far = nullptr;
  double first_far_m = 0;
  std::size_t in_map = 0, near = 0;
  for (const recording::IndexedSet& set : reader.sets()) {
    if (!set.location_id)
      continue;
    if (!first_located)
      first_located = &set;
    const gps::ImagingLocation* location = map.find(*set.location_id);
    if (!location)
      continue;
    ++in_map;
    if (!set.fix) {
      ++near;  // nothing to hold it against: taken as the map says
      continue;
    }
    const double metres = mapToFixMetres(*location, *set.fix);
    if (metres <= kMapToFixToleranceM) {
      ++near;
    } else if (!first_far) {
      first_far = &set;
      first_far_m = metres;
    }
  }
  if (!first_located)
    return {};  // manual triggers only: the map places nothing
  const std::string advice =
      ": a map of another field? (without --map, plots are placed at the fix at their trigger)";
  if (in_map == 0) {
    return core::Error{map_name + ": holds none of the session's locations (the first, " +
                       *first_located->location_id + ", of set " +
                       std::to_string(first_located->set_index) + ", is not in it)" + advice};
  }
  if (near == 0) {
    return core::Error{
        map_name + ": every location of the session lies more than " +
        std::to_string(static_cast<int>(kMapToFixToleranceM)) + " m from the fix at its trigger (" +
        *first_far->location_id + " of set " + std::to_string(first_far->set_index) + ": " +
        std::to_string(static_cast<long long>(std::lround(first_far_m))) + " m)" + advice};
  }
  return {};
}

core::Result<SessionProcessingSummary> processSession(
    const recording::SessionReader& reader, pipeline::PlotProcessor& processor,
    const gps::LocationMap* map, ResultsWriter& results, const SessionProcessingOptions& options,
    const std::function<void(const nlohmann::ordered_json&)>& on_line,
    const std::function<void(const std::string&)>& on_problem) {
  SessionProcessingSummary summary;
  const std::size_t end = std::min(reader.sets().size(), options.end_position);
  if (auto matches = checkResultsMatchSession(reader, results); !matches)
    return matches.error();
  std::set<std::uint64_t> triggers_seen;
  for (std::size_t position = options.first_position; position < end; ++position) {
    const recording::IndexedSet& set = reader.sets()[position];
    if (position % options.shard_count != options.shard_index)
      continue;
    if (!triggers_seen.insert(set.trigger_id).second) {
      on_problem(reader.dir().string() + ": set " + std::to_string(set.set_index) +
                 " has trigger id " + std::to_string(set.trigger_id) +
                 ", as an earlier set has: a damaged index; not processed");
      continue;
    }
    if (results.contains(set.trigger_id)) {
      ++summary.already_done;
      continue;
    }
    std::vector<std::string> problems;
    auto frames = headFramesFromRecording(reader, set.set_index, processor.rig(), problems);
    if (frames && options.truth_maps != TruthMaps::kNone) {
      if (auto added = addTruthMaps(reader, set.set_index, processor.rig(), options.truth_maps,
                                    *frames, problems);
          !added)
        return added.error();
    }
    pipeline::PlotResult result;
    if (frames) {
      result = processor.process(*frames, std::move(problems));
    } else {
      result.problems = std::move(problems);
      result.problems.push_back(frames.error().message);
      result.traits.status = traits::TraitsStatus::kEmptyCloud;
      result.traits.message = frames.error().message;
    }
    PlotIdentity identity;
    identity.set_index = set.set_index;
    identity.trigger_id = set.trigger_id;
    identity.location_id = set.location_id;
    identity.time = core::formatIso8601(set.trigger_time, 6);
    placePlot(identity, set.fix, map);
    identity.trigger_status = set.trigger_status.value_or("");
    const nlohmann::ordered_json line = plotLine(identity, result);
    if (options.clouds_dir && frames) {
      const std::filesystem::path ply =
          *options.clouds_dir /
          (line.at("plot").get<std::string>() + "_set" + std::to_string(set.set_index) + ".ply");
      if (auto written = cloud::writePly(result.cloud, ply); !written)
        on_problem(written.error().message);
    }
    ++summary.sets;
    summary.ok += result.traits.status == traits::TraitsStatus::kOk ? 1 : 0;
    summary.partial_clouds += result.partial ? 1 : 0;
    summary.unplaced += identity.position ? 0 : 1;
    summary.placement_problems += identity.placement_problem ? 1 : 0;
    on_line(line);
    if (std::string failed = results.add(line); !failed.empty())
      return core::Error{std::move(failed)};
  }
  if (std::string failed = results.flush(); !failed.empty())
    return core::Error{std::move(failed)};
  return summary;
}

}  // namespace fieldrig::daemon
