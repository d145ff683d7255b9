// The in-cab page's data for a recorded session (`fieldrig view SESSION`): the same /map the
// daemon serves, a status built once from the session's index and results ("mode": "session"),
// and the per-plot results the page lists, each with a link to the stem tool.
//
// A location's state comes from what the session holds: processed (a result, not partial),
// incomplete (a partial result, or a set without all its frames), recorded (a set, no result),
// missed (no set, but a location after it in the map's order has one: the tractor passed it) or
// pending (no set and nothing after it: never reached). The session does not record the
// planner's alarms, so "missed" is read from the map's order, which is the driving order.
#pragma once

#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/gps/location_map.h"

namespace fieldrig::daemon {

// A location's state on the page: one character each in the status's locations.states.
inline constexpr char kLocationPending = '.', kLocationTriggered = 't', kLocationRecorded = 'r',
                      kLocationProcessed = 'p', kLocationMissed = 'm', kLocationIncomplete = 'i';

// Each location's row (the map's "row" column; "all" when it has none), in the map's order.
std::vector<std::string> locationRows(const gps::LocationMap& map);

// The map's static part for the page (/map): each location's id, row and place in metres east
// and north of the map's first location, in the map's order (that of locations.states).
nlohmann::ordered_json cabMapJson(const gps::LocationMap& map, const std::string& map_name);

struct SessionViewOptions {
  std::filesystem::path session;
  std::optional<std::filesystem::path> map;         // default: the map session.json names
  std::optional<std::filesystem::path> results;     // default: SESSION/results (may be absent)
  std::string stem_url = "http://127.0.0.1:8765/";  // where `fieldrig stem-ui` serves
};

struct SessionView {
  std::string map_json;           // /map
  nlohmann::ordered_json status;  // /status and /events
  std::string plots_json;         // /plots: one entry per result line
  std::vector<std::string> warnings;
};

// Reads the session, its map and its results; an error names the file (and line) that cannot be
// used.
core::Result<SessionView> buildSessionView(const SessionViewOptions& options);

}  // namespace fieldrig::daemon
