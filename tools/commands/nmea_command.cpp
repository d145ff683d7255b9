// `fieldrig nmea decode FILE`: one JSON object per intact RMC/GGA sentence, then a summary.
#include <array>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>

#include "commands/command_helpers.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::tools {
namespace {

using Json = nlohmann::ordered_json;

Json optionalNumber(const std::optional<double>& value) {
  return value ? Json(*value) : Json(nullptr);
}

// Digits after the seconds' point: at least 2 (NMEA's usual hhmmss.ss), more when the receiver
// sent them (hhmmss.sss), so no precision is lost.
int fractionDigits(core::Nanoseconds time_of_day) {
  const std::int64_t nanos = time_of_day.count() % 1'000'000'000;
  int digits = 2;
  for (std::int64_t unit = 10'000'000; digits < 9 && nanos % unit != 0; unit /= 10)
    ++digits;
  return digits;
}

// The fields every sentence's object starts with.
Json sentenceJson(const gps::Sentence& s, const char* kind) {
  Json out;
  out["sentence"] = kind;
  out["talker"] = s.talker;
  return out;
}

Json rmcJson(const gps::Sentence& s) {
  const gps::RmcData& rmc = s.rmc;
  Json out = sentenceJson(s, "RMC");
  out["time"] = rmc.time ? Json(core::formatIso8601(*rmc.time, fractionDigits(*rmc.time_of_day)))
                         : Json(nullptr);
  out["valid"] = rmc.status_active;  // the contract: status A (mode N is in "mode")
  out["lat"] = optionalNumber(rmc.latitude_deg);
  out["lon"] = optionalNumber(rmc.longitude_deg);
  out["speed_mps"] = optionalNumber(rmc.speed_mps);
  out["course_deg"] = optionalNumber(rmc.course_deg);
  out["magvar_deg"] = optionalNumber(rmc.magnetic_variation_deg);
  out["mode"] = rmc.mode ? Json(std::string(1, rmc.mode)) : Json(nullptr);
  return out;
}

Json ggaJson(const gps::Sentence& s) {
  const gps::GgaData& gga = s.gga;
  Json out = sentenceJson(s, "GGA");
  out["time_of_day"] =
      gga.time_of_day
          ? Json(core::formatTimeOfDay(*gga.time_of_day, fractionDigits(*gga.time_of_day)))
          : Json(nullptr);
  out["lat"] = optionalNumber(gga.latitude_deg);
  out["lon"] = optionalNumber(gga.longitude_deg);
  out["quality"] = gga.quality;
  out["satellites"] = gga.satellites ? Json(*gga.satellites) : Json(nullptr);
  out["hdop"] = optionalNumber(gga.hdop);
  out["altitude_m"] = optionalNumber(gga.altitude_m);
  out["geoid_separation_m"] = optionalNumber(gga.geoid_separation_m);
  return out;
}

int runDecode(const std::string& path) {
  std::ifstream in;
  if (const std::string problem = openInputFile(path, in); !problem.empty())
    return fail("fieldrig nmea decode: ", problem);
  // A file is a capture: its '#' header lines (gpsd logs, recordings) are comments, not noise.
  gps::NmeaParserOptions options;
  options.comment_lines = true;
  gps::NmeaParser parser(
      [](const gps::Sentence& s) {
        if (s.kind == gps::SentenceKind::kRmc) {
          std::cout << rmcJson(s).dump() << '\n';
        } else if (s.kind == gps::SentenceKind::kGga) {
          std::cout << ggaJson(s).dump() << '\n';
        }
      },
      options);
  std::array<char, 65536> chunk{};
  while (in.read(chunk.data(), chunk.size()) || in.gcount() > 0) {
    parser.feed(std::string_view(chunk.data(), static_cast<std::size_t>(in.gcount())));
  }
  parser.flush();

  const gps::NmeaStats& stats = parser.stats();
  Json rejected = Json::object();
  for (std::size_t i = 0; i < gps::kRejectReasonCount; ++i) {
    rejected[std::string(gps::toString(static_cast<gps::RejectReason>(i)))] = stats.rejected[i];
  }
  Json summary;
  summary["file"] = path;
  summary["lines"] = stats.lines;
  summary["comments"] = stats.comments;
  summary["sentences"] = stats.sentences;
  summary["rmc"] = stats.rmc;
  summary["gga"] = stats.gga;
  summary["other"] = stats.other;
  summary["rejected_total"] = stats.rejectedTotal();
  summary["rejected"] = rejected;
  std::cout << Json{{"summary", summary}}.dump() << '\n';
  return kExitOk;
}

}  // namespace

void registerNmeaCommand(CLI::App& app, int& exit_code) {
  CLI::App* nmea = addCommandGroup(app, "nmea", "NMEA 0183 tools");
  CLI::App* decode =
      nmea->add_subcommand("decode", "Print every intact RMC/GGA sentence of FILE as JSON lines");
  auto path = std::make_shared<std::string>();
  decode->add_option("FILE", *path, "NMEA log (raw bytes as captured)")->required();
  decode->callback([path, &exit_code] { exit_code = runDecode(*path); });
}

}  // namespace fieldrig::tools
