// `fieldrig triggers --map MAP.csv --nmea FILE`: replays a capture in GPS time and prints one
// JSON line per trigger on stdout; alarms and the summary go to stderr as JSON lines.
#include <boost/asio/io_context.hpp>
#include <boost/asio/signal_set.hpp>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/command_helpers.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/gps/serial_nmea_source.h"
#include "fieldrig/gps/serial_trigger_chain.h"
#include "fieldrig/gps/trigger_replay.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

struct TriggersArgs {
  std::string map_path;
  std::string nmea_path;
  unsigned baud = 115200;
  gps::TriggerChainOptions replay;
};

Json triggerJson(const core::TriggerEvent& event) {
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
  line["timing_sigma_s"] = event.timing_sigma_s;
  line["along_track_sigma_m"] = event.along_track_sigma_m;
  return line;
}

void printAlarm(const gps::PlannerAlarm& alarm) {
  Json line;
  line["alarm"] = gps::toString(alarm.kind);
  line["location"] = alarm.location_id;
  line["time"] = core::formatIso8601(alarm.time, 6);
  line["message"] = alarm.message;
  std::cerr << line.dump() << std::endl;
}

Json summaryJson(const gps::LocationMap& map, const gps::NmeaStats& nmea,
                 const gps::TriggerStats& s) {
  Json out;
  out["locations"] = map.size();
  out["sentences"] = nmea.sentences;
  out["rejected_lines"] = nmea.rejectedTotal();
  out["fixes"] = s.fixes;
  out["fixes_invalid"] = s.fixes_invalid;
  out["fixes_too_slow"] = s.fixes_too_slow;
  out["track_restarts"] = s.track_restarts;
  out["filter_resets"] = s.filter_resets;
  out["position_jumps"] = s.position_jumps;
  out["time_jumps"] = s.time_jumps;
  out["triggers"] = s.triggers;
  out["triggers_late"] = s.triggers_late;
  out["missed"] = s.missed;
  out["too_fast"] = s.too_fast;
  out["stale_plans_dropped"] = s.stale_plans_dropped;
  return Json{{"summary", out}};
}

Json serialStatusJson(const gps::SerialStatus& status) {
  Json line;
  line["serial"] = gps::toString(status.event);
  line["device"] = status.device;
  line["message"] = status.message;
  return line;
}

// Live: the receiver on a serial device; triggers fire on a steady_timer until SIGINT/SIGTERM.
int runLive(const TriggersArgs& args, const gps::LocationMap& map) {
  boost::asio::io_context io;
  gps::SerialOptions serial;
  serial.device = args.nmea_path;
  serial.baud = args.baud;
  gps::LiveTriggerHandlers handlers;
  handlers.on_trigger = [](const core::TriggerEvent& event, core::SteadyTime) {
    Json line = triggerJson(event);
    line["host_time"] = core::formatIso8601(
        std::chrono::time_point_cast<core::Nanoseconds>(std::chrono::system_clock::now()), 6);
    std::cout << line.dump() << std::endl;
  };
  handlers.on_alarm = printAlarm;
  auto chain = gps::SerialTriggerChain::create(
      io, map, serial, args.replay, handlers, [](const gps::SerialStatus& status) {
        std::cerr << serialStatusJson(status).dump() << std::endl;
      });
  if (!chain)
    return fail("fieldrig triggers: ", chain.error().message);
  boost::asio::signal_set signals(io, SIGINT, SIGTERM);
  signals.async_wait([&](const boost::system::error_code&, int) { chain->stop(); });
  chain->start();
  io.run();
  std::cerr << summaryJson(map, chain->nmeaStats(), chain->plannerStats()).dump() << std::endl;
  return kExitOk;
}

int runTriggers(const TriggersArgs& args) {
  const auto map = gps::LocationMap::load(args.map_path);
  if (!map)
    return fail("fieldrig triggers: ", map.error().message);
  if (map->empty()) {
    std::cerr << "fieldrig triggers: " << args.map_path << ": the map has no locations\n";
    return kExitBadInput;
  }
  std::error_code type_error;  // an unreadable path is reported below as "cannot open"
  if (std::filesystem::is_character_file(args.nmea_path, type_error)) {
    // /dev/null is a character device too: opened as a port again and again for ever.
    if (auto serial = gps::checkSerialDevice(args.nmea_path); !serial)
      return fail("fieldrig triggers: --nmea: ", serial.error().message);
    return runLive(args, *map);
  }
  std::ifstream nmea;
  if (const std::string problem = openInputFile(args.nmea_path, nmea); !problem.empty())
    return fail("fieldrig triggers: NMEA file: ", problem);

  gps::ReplayHandlers handlers;
  handlers.on_trigger = [](const core::TriggerEvent& event) {
    std::cout << triggerJson(event).dump() << '\n';
  };
  handlers.on_alarm = printAlarm;
  const auto summary = gps::replayTriggers(nmea, *map, args.replay, handlers);
  std::cout.flush();
  if (!summary)
    return fail("fieldrig triggers: ", summary.error().message);
  std::cerr << summaryJson(*map, summary->nmea, summary->planner).dump() << '\n';
  return kExitOk;
}

}  // namespace

void registerTriggersCommand(CLI::App& app, int& exit_code) {
  const auto [cmd, args] =
      addSubcommand(app, "triggers",
                    "Replay an NMEA capture against an imaging-location map and print the triggers",
                    exit_code, runTriggers);
  gps::TriggerOptions& p = args->replay.planner;
  cmd->add_option("--map", args->map_path, "imaging-location map (CSV)")->required();
  cmd->add_option("--nmea", args->nmea_path,
                  "NMEA capture to replay in GPS time, or a serial device to run live")
      ->required();
  cmd->add_option("--baud", args->baud, "serial baud rate (live)")
      ->capture_default_str()
      ->check(finiteRange(300u, 4'000'000u));
  cmd->add_option("--latency", args->replay.latency_s, "receiver and serial latency, seconds")
      ->capture_default_str()
      ->check(finiteRange(0.0, 1.0));
  cmd->add_option("--latency-jitter", args->replay.latency_jitter_s,
                  "replay: vary each fix's latency uniformly by ± this many seconds (≤ --latency)")
      ->capture_default_str()
      ->check(finiteRange(0.0, 1.0));
  cmd->add_option("--latency-jitter-seed", args->replay.latency_jitter_seed,
                  "replay: seed of the latency jitter")
      ->capture_default_str();
  cmd->add_option("--motion-model", p.motion_model, "kalman or constant_velocity_fit")
      ->transform(CLI::CheckedTransformer(
          std::map<std::string, gps::MotionModel>{
              {"kalman", gps::MotionModel::kKalman},
              {"constant_velocity_fit", gps::MotionModel::kConstantVelocityFit}},
          CLI::ignore_case));
  cmd->add_option("--cross-track", p.cross_track_tolerance_m, "cross-track tolerance, metres")
      ->capture_default_str()
      ->check(finiteRange(0.01, 100.0));
  cmd->add_option("--heading-tolerance", p.heading_tolerance_deg, "degrees")
      ->capture_default_str()
      ->check(finiteRange(0.0, 180.0));
  cmd->add_option("--min-speed", p.min_speed_mps, "m/s")
      ->capture_default_str()
      ->check(finiteRange(0.01, 50.0));
  cmd->add_option("--min-interval", p.min_trigger_interval_s,
                  "minimum seconds between triggers (the cameras' rate)")
      ->capture_default_str()
      ->check(finiteRange(0.0, 60.0));
  // A camera's exposure delay is milliseconds; a second ahead is already 2-3 plots early.
  cmd->add_option("--lead", p.trigger_lead_s, "fire this many seconds before the crossing")
      ->capture_default_str()
      ->check(finiteRange(0.0, 1.0));
}

}  // namespace fieldrig::tools
