#include "fieldrig/daemon/session_view.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "fieldrig/daemon/results_writer.h"
#include "fieldrig/gps/local_frame.h"
#include "fieldrig/recording/session_reader.h"

namespace fieldrig::daemon {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// The name the stem tool gives a session folder (tools/stem_page: its folder's name).
std::string stemSessionName(const fs::path& dir) {
  const fs::path normal = dir.lexically_normal();
  const std::string name = normal.filename().string();
  return name.empty() ? normal.parent_path().filename().string() : name;
}

// A query parameter's value, percent-encoded (RFC 3986 unreserved characters kept).
std::string percentEncoded(const std::string& text) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  std::string out;
  for (const char c : text) {
    const auto byte = static_cast<unsigned char>(c);
    if (std::isalnum(byte) || c == '-' || c == '_' || c == '.' || c == '~') {
      out += c;
    } else {
      out += '%';
      out += kHex[byte >> 4];
      out += kHex[byte & 15];
    }
  }
  return out;
}

// The map a session was recorded with: session.json names it as the configuration gave it, so a
// relative path is tried from here, then from the session's parent folder.
core::Result<fs::path> sessionMapPath(const recording::SessionReader& session) {
  const fs::path session_json = session.dir() / recording::kSessionFile;
  if (!session.metadata().map_path)
    return core::Error{session_json.string() +
                       ": names no map (recorded without one): give the map with --map"};
  const fs::path named = *session.metadata().map_path;
  std::vector<fs::path> tried = {named};
  if (named.is_relative())
    tried.push_back(session.dir().parent_path() / named);
  for (const fs::path& path : tried) {
    std::error_code ec;
    if (fs::is_regular_file(path, ec))
      return path;
  }
  return core::Error{session_json.string() + ": its map '" + named.string() +
                     "' is not there any more: give the map with --map"};
}

// The result lines of plots.jsonl; a torn last line (a write cut short) is left out with a
// warning, a damaged line before it is an error naming the line.
core::Result<std::vector<Json>> readResultLines(const fs::path& path,
                                                std::vector<std::string>& warnings) {
  std::ifstream in(path, std::ios::binary);
  if (!in)
    return core::Error{path.string() + ": cannot be read"};
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string text = buffer.str();
  std::vector<Json> lines;
  std::size_t start = 0;
  for (std::uint64_t number = 1; start < text.size(); ++number) {
    const std::size_t end = text.find('\n', start);
    const std::string line =
        text.substr(start, end == std::string::npos ? std::string::npos : end - start);
    start = end == std::string::npos ? text.size() : end + 1;
    if (line.find_first_not_of(" \t\r") == std::string::npos)
      continue;
    Json parsed = Json::parse(line, nullptr, false);
    const bool usable = !parsed.is_discarded() && parsed.is_object() &&
                        parsed.contains("trigger_id") && parsed["trigger_id"].is_number_unsigned();
    if (!usable) {
      if (end == std::string::npos) {
        warnings.push_back(path.string() + ":" + std::to_string(number) +
                           ": a torn last line (a write cut short) is left out");
        break;
      }
      return core::Error{path.string() + ":" + std::to_string(number) +
                         ": not a result line (JSON with a trigger_id)"};
    }
    lines.push_back(std::move(parsed));
  }
  return lines;
}

Json traitOr(const Json& line, const char* name) {
  const auto traits = line.find("traits");
  if (traits == line.end() || !traits->is_object() || !traits->contains(name))
    return nullptr;
  return traits->at(name);
}

// How good a state is, to keep the best of a location's passes.
int rank(char state) {
  switch (state) {
    case kLocationProcessed:
      return 3;
    case kLocationRecorded:
      return 2;
    case kLocationIncomplete:
      return 1;
    default:
      return 0;
  }
}

}  // namespace

std::vector<std::string> locationRows(const gps::LocationMap& map) {
  const auto& columns = map.metadataColumns();
  const auto row_column = std::find(columns.begin(), columns.end(), "row");
  std::vector<std::string> rows;
  rows.reserve(map.size());
  for (const auto& location : map.locations()) {
    std::string row = "all";
    if (row_column != columns.end()) {
      const auto c = static_cast<std::size_t>(row_column - columns.begin());
      if (c < location.metadata.size())
        row = location.metadata[c];
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

Json cabMapJson(const gps::LocationMap& map, const std::string& map_name) {
  Json locations = Json::array();
  if (!map.empty()) {
    const gps::LocalFrame frame(map.locations().front().latitude_deg,
                                map.locations().front().longitude_deg);
    const std::vector<std::string> rows = locationRows(map);
    for (std::size_t i = 0; i < map.size(); ++i) {
      const auto& location = map.locations()[i];
      const gps::EnuPoint p = frame.toLocal(location.latitude_deg, location.longitude_deg);
      locations.push_back({location.id, rows[i], std::round(p.east_m * 100) / 100,
                           std::round(p.north_m * 100) / 100});
    }
  }
  Json origin = nullptr;
  if (!map.empty())
    origin = {{"lat", map.locations().front().latitude_deg},
              {"lon", map.locations().front().longitude_deg}};
  return Json{{"map", map_name},
              {"origin", origin},
              {"fields", {"id", "row", "east_m", "north_m"}},
              {"locations", locations},
              {"states",
               {{std::string(1, kLocationPending), "pending"},
                {std::string(1, kLocationTriggered), "triggered"},
                {std::string(1, kLocationRecorded), "recorded"},
                {std::string(1, kLocationProcessed), "processed"},
                {std::string(1, kLocationMissed), "missed"},
                {std::string(1, kLocationIncomplete), "incomplete"}}}};
}

core::Result<SessionView> buildSessionView(const SessionViewOptions& options) {
  SessionView view;
  auto session = recording::SessionReader::open(options.session);
  if (!session)
    return core::Error{session.error().message};
  if (session->tornLine())
    view.warnings.push_back((options.session / recording::kIndexFile).string() + ":" +
                            std::to_string(session->tornLine()->line) +
                            ": a torn last line (a write cut short) is left out");

  fs::path map_path;
  if (options.map) {
    map_path = *options.map;
  } else {
    auto found = sessionMapPath(*session);
    if (!found)
      return core::Error{found.error().message};
    map_path = *found;
  }
  auto map = gps::LocationMap::load(map_path);
  if (!map)
    return core::Error{map.error().message};
  if (map->empty())
    return core::Error{map_path.string() + ": the map has no locations"};

  // The results: those of `fieldrig process` or of the daemon, when there are any.
  const fs::path results_dir = options.results.value_or(options.session / "results");
  const fs::path jsonl = resultsFiles(results_dir).jsonl;
  std::vector<Json> lines;
  std::error_code ec;
  if (fs::exists(jsonl, ec)) {
    auto read = readResultLines(jsonl, view.warnings);
    if (!read)
      return core::Error{read.error().message};
    lines = std::move(*read);
  } else if (options.results) {
    return core::Error{jsonl.string() + ": no results there (run `fieldrig process` first)"};
  }

  // Each set's state, then each location's: the best of its passes.
  std::map<std::uint64_t, const Json*> result_of_trigger;
  for (const Json& line : lines)
    result_of_trigger[line["trigger_id"].get<std::uint64_t>()] = &line;
  std::map<std::string, char, std::less<>> best;
  std::uint64_t incomplete_sets = 0, late = 0, unknown_sets = 0;
  std::vector<std::string> unknown_ids;
  for (const recording::IndexedSet& set : session->sets()) {
    if (!set.complete)
      ++incomplete_sets;
    if (set.trigger_status == "late")
      ++late;
    if (!set.location_id)
      continue;  // a manual trigger: no dot on the map
    if (map->find(*set.location_id) == nullptr) {
      ++unknown_sets;
      if (unknown_ids.size() < 5)
        unknown_ids.push_back(*set.location_id);
      continue;
    }
    char state = set.complete ? kLocationRecorded : kLocationIncomplete;
    if (const auto it = result_of_trigger.find(set.trigger_id); it != result_of_trigger.end())
      state = it->second->value("partial", false) ? kLocationIncomplete : kLocationProcessed;
    char& kept = best.try_emplace(*set.location_id, kLocationPending).first->second;
    if (rank(state) > rank(kept))
      kept = state;
  }
  if (unknown_sets > 0) {
    std::string ids;
    for (const std::string& id : unknown_ids)
      ids += (ids.empty() ? "" : ", ") + id;
    view.warnings.push_back(std::to_string(unknown_sets) + " sets are at locations that " +
                            map_path.string() + " does not have (" + ids +
                            "): is it the map the session was recorded with?");
  }

  std::string states(map->size(), kLocationPending);
  std::size_t reached_end = 0;  // one past the last location with a set, in the map's order
  for (std::size_t i = 0; i < map->size(); ++i) {
    if (const auto it = best.find(map->locations()[i].id); it != best.end()) {
      states[i] = it->second;
      reached_end = i + 1;
    }
  }
  std::uint64_t missed = 0;
  for (std::size_t i = 0; i < reached_end; ++i) {
    if (states[i] == kLocationPending) {
      states[i] = kLocationMissed;
      ++missed;
    }
  }

  const std::string name = stemSessionName(options.session);
  Json plots = Json::array();
  for (const Json& line : lines) {
    const std::uint64_t trigger_id = line["trigger_id"].get<std::uint64_t>();
    Json set_index = line.value("set", Json(nullptr));
    if (!set_index.is_number_unsigned()) {
      const recording::IndexedSet* set = session->byTriggerId(trigger_id);
      set_index = set ? Json(set->set_index) : Json(nullptr);
    }
    Json stem = nullptr;
    if (set_index.is_number_unsigned())
      stem = options.stem_url + "?session=" + percentEncoded(name) +
             "&set=" + std::to_string(set_index.get<std::uint64_t>());
    plots.push_back({{"set", set_index},
                     {"trigger_id", trigger_id},
                     {"plot", line.value("plot", Json(nullptr))},
                     {"location", line.value("location", Json(nullptr))},
                     {"time", line.value("time", Json(nullptr))},
                     {"status", traitOr(line, "status")},
                     {"height_m", traitOr(line, "height_m")},
                     {"width_m", traitOr(line, "width_m")},
                     {"vvi", traitOr(line, "vvi")},
                     {"vai", traitOr(line, "vai")},
                     {"partial", line.value("partial", false)},
                     {"problems", line.value("problems", Json::array())},
                     {"stem_url", stem}});
  }

  view.map_json = cabMapJson(*map, map_path.string()).dump();
  view.plots_json = plots.dump();
  const auto counts = session->counts();
  view.status = Json{
      {"mode", "session"},
      {"session", name},
      {"session_dir", options.session.string()},
      {"start_time", session->metadata().start_time},
      {"map", map_path.string()},
      {"results", jsonl.string()},
      {"locations", {{"states", states}, {"current_row", ""}}},
      {"triggers",
       {{"fired", counts.sets}, {"locations", map->size()}, {"late", late}, {"missed", missed}}},
      {"sets",
       {{"recorded", counts.sets},
        {"processed", lines.size()},
        {"incomplete", incomplete_sets},
        {"skipped_for_processing", 0}}},
      {"plots", {{"count", plots.size()}, {"url", "/plots"}}},
      {"stem",
       {{"url", options.stem_url},
        {"session", name},
        {"command", "fieldrig stem-ui " + options.session.string()}}},
      {"warnings", view.warnings}};
  return view;
}

}  // namespace fieldrig::daemon
