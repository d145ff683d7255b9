// `fieldrig triggers --map MAP.csv --nmea FILE`: replays a capture in GPS time and prints one
// JSON line per trigger on stdout; alarms and the summary go to stderr as JSON lines.
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/commands.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/gps/trigger_replay.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct TriggersArgs {
  std::string map_path;
  std::string nmea_path;
  gps::ReplayOptions replay;
};

std::string_view alarmName(gps::AlarmKind kind) {
  return kind == gps::AlarmKind::kTooFast ? "too_fast" : "missed";
}

int runTriggers(const TriggersArgs& args) {
  const auto map = gps::LocationMap::load(args.map_path);
  if (!map) {
    std::cerr << "fieldrig triggers: " << map.error().message << '\n';
    return kExitBadInput;
  }
  if (map->empty()) {
    std::cerr << "fieldrig triggers: " << args.map_path << ": the map has no locations\n";
    return kExitBadInput;
  }
  std::ifstream nmea(args.nmea_path, std::ios::binary);
  if (!nmea) {
    std::cerr << "fieldrig triggers: cannot open NMEA file '" << args.nmea_path << "'\n";
    return kExitBadInput;
  }

  gps::ReplayHandlers handlers;
  handlers.on_trigger = [&](const core::TriggerEvent& event) {
    Json line;
    line["trigger_id"] = event.trigger_id;
    line["location"] = event.location_id;
    line["time"] = core::formatIso8601(event.time, 6);
    line["status"] = core::toString(event.status);
    line["predicted_crossing"] = core::formatIso8601(event.planned_time, 6);
    line["last_fix_time"] = core::formatIso8601(event.last_fix_time, 6);
    line["speed_mps"] = event.speed_mps;
    line["course_deg"] = event.course_deg;
    line["cross_track_m"] = event.cross_track_m;
    std::cout << line.dump() << '\n';
  };
  handlers.on_alarm = [](const gps::PlannerAlarm& alarm) {
    Json line;
    line["alarm"] = alarmName(alarm.kind);
    line["location"] = alarm.location_id;
    line["time"] = core::formatIso8601(alarm.time, 6);
    line["message"] = alarm.message;
    std::cerr << line.dump() << '\n';
  };
  const gps::ReplaySummary summary = gps::replayTriggers(nmea, *map, args.replay, handlers);
  std::cout.flush();

  const gps::TriggerStats& s = summary.planner;
  Json out;
  out["locations"] = map->size();
  out["sentences"] = summary.nmea.sentences;
  out["rejected_lines"] = summary.nmea.rejectedTotal();
  out["fixes"] = s.fixes;
  out["fixes_invalid"] = s.fixes_invalid;
  out["fixes_too_slow"] = s.fixes_too_slow;
  out["track_restarts"] = s.track_restarts;
  out["triggers"] = s.triggers;
  out["triggers_late"] = s.triggers_late;
  out["missed"] = s.missed;
  out["too_fast"] = s.too_fast;
  out["stale_plans_dropped"] = s.stale_plans_dropped;
  std::cerr << Json{{"summary", out}}.dump() << '\n';
  return kExitOk;
}

}  // namespace

void registerTriggersCommand(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<TriggersArgs>();
  gps::TriggerOptions& p = args->replay.planner;
  CLI::App* cmd = app.add_subcommand(
      "triggers", "Replay an NMEA capture against an imaging-location map and print the triggers");
  cmd->add_option("--map", args->map_path, "imaging-location map (CSV)")->required();
  cmd->add_option("--nmea", args->nmea_path, "NMEA capture to replay in GPS time")->required();
  cmd->add_option("--latency", args->replay.latency_s, "receiver and serial latency, seconds")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1.0));
  cmd->add_option("--cross-track", p.cross_track_tolerance_m, "cross-track tolerance, metres")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  cmd->add_option("--heading-tolerance", p.heading_tolerance_deg, "degrees")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 180.0));
  cmd->add_option("--min-speed", p.min_speed_mps, "m/s")->capture_default_str();
  cmd->add_option("--min-interval", p.min_trigger_interval_s,
                  "minimum seconds between triggers (the cameras' rate)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--lead", p.trigger_lead_s, "fire this many seconds before the crossing")
      ->capture_default_str();
  cmd->callback([args, &exit_code] { exit_code = runTriggers(*args); });
}

}  // namespace fieldrig::tools
