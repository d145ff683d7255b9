// Replays every gpsd regression log (../shared/data/nmea/gpsd/*.log) through NmeaParser and
// compares the decode of each RMC/GGA with what gpsd printed for the same sentence (*.log.chk).
//
// The .chk echoes each sentence gpsd read, followed by the JSON reports it produced. gpsd merges
// the sentences of a cycle, so only fields that come from the echoed sentence itself are
// compared: lat/lon after either, speed/track/time after RMC, altMSL after GGA. Numbers are
// compared to the precision gpsd printed them with (half a unit of the last printed digit).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "fieldrig/core/time.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::gps {
namespace {

namespace fs = std::filesystem;

const fs::path kGpsdDir = fs::path(FIELDRIG_SHARED_DATA_DIR) / "nmea" / "gpsd";

// gpsd corrects these logs' dates by 1024 GPS weeks (see the data README's caveats).
std::chrono::days gpsdDateOffset(const std::string& name) {
  if (name == "neo-m8n.log" || name == "rst39.log" || name == "tcp-torture.log") {
    return std::chrono::days{7168};
  }
  return std::chrono::days{0};
}

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

// What we decoded for one sentence text (the last outcome if the same text occurs twice; the
// parser is pure, so identical text has an identical decode).
struct Decode {
  SentenceKind kind = SentenceKind::kRejected;
  RejectReason reason = RejectReason::kGarbage;
  RmcData rmc;
  GgaData gga;
};

// The printed text of a number field in one JSON line, to learn gpsd's printed precision.
std::optional<std::string> rawNumber(const std::string& json_line, const std::string& key) {
  const std::string needle = "\"" + key + "\":";
  const std::size_t at = json_line.find(needle);
  if (at == std::string::npos)
    return std::nullopt;
  const std::size_t begin = at + needle.size();
  const std::size_t end = json_line.find_first_of(",}", begin);
  return json_line.substr(begin, end - begin);
}

// Half a unit in the last printed digit: the largest honest difference between a value and its
// printed rounding. The tiny extra absorbs binary representation of both sides.
double printedTolerance(const std::string& text) {
  const std::size_t dot = text.find('.');
  const int decimals = dot == std::string::npos ? 0 : static_cast<int>(text.size() - dot - 1);
  return 0.5 * std::pow(10.0, -decimals) * (1 + 1e-9) + 1e-12;
}

bool hasValidChecksum(const std::string& sentence) {
  const std::size_t star = sentence.rfind('*');
  if (star == std::string::npos || star + 3 != sentence.size())
    return false;
  unsigned sum = 0;
  for (std::size_t i = 1; i < star; ++i)
    sum ^= static_cast<unsigned char>(sentence[i]);
  unsigned expected = 0;
  std::istringstream(sentence.substr(star + 1)) >> std::hex >> expected;
  return sum == expected;
}

std::string typeOf(const std::string& sentence) {
  return sentence.size() >= 6 && sentence[1] != 'P' ? sentence.substr(3, 3) : std::string{};
}

struct FileReport {
  std::string name;
  int echoed_fixes = 0;  // RMC/GGA echoes followed by a TPV with lat/lon
  int lat_lon = 0;
  int speed = 0;
  int track = 0;
  int time = 0;
  int altitude = 0;
  int bad_checksum_rejected = 0;  // RMC/GGA lines with a wrong/missing checksum, rejected by us
  int not_from_sentence = 0;
  int missing = 0;  // gpsd had a fix, we had no decode  // TPV position stale: the echoed sentence
                    // had none (e.g. status V)
  std::vector<std::string> failures;
};

FileReport compareFile(const fs::path& log_path) {
  FileReport report;
  report.name = log_path.filename().string();
  const auto fail = [&report](const std::string& sentence, const std::string& what) {
    report.failures.push_back(report.name + ": " + what + "\n  sentence: " + sentence);
  };

  // gpsfake removes the "Delay-Cookie" character and writes at each one: do the same, which also
  // exercises lines split across feed() calls.
  std::string bytes = readFile(log_path);
  std::optional<char> cookie;
  if (const std::size_t at = bytes.find("# Delay-Cookie: "); at != std::string::npos) {
    cookie = bytes[at + 16];
  }
  std::map<std::string, Decode> decodes;
  NmeaParser parser(
      [&decodes](const Sentence& s) {
        Decode& d = decodes[std::string(s.text)];
        d.kind = s.kind;
        d.reason = s.reason;
        d.rmc = s.rmc;
        d.gga = s.gga;
      },
      NmeaParserOptions{.max_line_length = 200, .comment_lines = true});
  if (cookie) {
    std::size_t begin = 0;
    const std::size_t body = bytes.find('\n', bytes.find("# Delay-Cookie: "));
    parser.feed(std::string_view(bytes).substr(0, body));
    begin = body;
    for (std::size_t at = bytes.find(*cookie, begin); at != std::string::npos;
         at = bytes.find(*cookie, begin)) {
      parser.feed(std::string_view(bytes).substr(begin, at - begin));
      begin = at + 1;
    }
    parser.feed(std::string_view(bytes).substr(begin));
  } else {
    parser.feed(bytes);
  }
  parser.flush();

  const auto offset = gpsdDateOffset(report.name);
  std::ifstream chk(log_path.string() + ".chk");
  std::vector<std::string> lines;
  for (std::string line; std::getline(chk, line);) {
    while (!line.empty() && line.back() == '\r')
      line.pop_back();  // some end in CR CR LF
    lines.push_back(line);
  }
  if (lines.empty())
    fail("", "no .chk file");

  std::set<std::string> echoes_with_fix;
  // The GGA echoed since the last TPV: a TPV that ends the cycle at the RMC carries its altitude.
  std::optional<std::string> cycle_gga;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const std::string& echo = lines[i];
    if (echo.find("\"class\":\"TPV\"") != std::string::npos)
      cycle_gga.reset();
    if (echo.empty() || (echo[0] != '$' && echo[0] != '!'))
      continue;
    const std::string type = typeOf(echo);
    if (type != "RMC" && type != "GGA")
      continue;
    // The first TPV among this sentence's reports.
    std::optional<std::string> tpv_line;
    for (std::size_t j = i + 1; j < lines.size() && !lines[j].empty() && lines[j][0] == '{'; ++j) {
      if (lines[j].find("\"class\":\"TPV\"") != std::string::npos) {
        tpv_line = lines[j];
        break;
      }
    }
    const auto found = decodes.find(echo);
    const bool decoded = found != decodes.end() && found->second.kind != SentenceKind::kRejected;

    const std::optional<std::string> gga_of_cycle = cycle_gga;
    if (type == "GGA")
      cycle_gga = echo;
    if (!hasValidChecksum(echo)) {
      if (decoded)
        fail(echo, "gpsd echoed it with a bad checksum, but we decoded it");
      if (found != decodes.end() && !decoded)
        ++report.bad_checksum_rejected;
      continue;
    }
    if (!tpv_line)
      continue;
    const nlohmann::json tpv = nlohmann::json::parse(*tpv_line);
    if (!tpv.contains("lat") || !tpv.contains("lon"))
      continue;
    ++report.echoed_fixes;
    echoes_with_fix.insert(echo);
    if (!decoded) {
      fail(echo, "gpsd reported a fix after it, we have no decode");
      ++report.missing;
      continue;
    }
    const Decode& ours = found->second;
    const bool is_rmc = ours.kind == SentenceKind::kRmc;
    const std::optional<double> lat = is_rmc ? ours.rmc.latitude_deg : ours.gga.latitude_deg;
    const std::optional<double> lon = is_rmc ? ours.rmc.longitude_deg : ours.gga.longitude_deg;
    // gpsd takes no position from an RMC with status V or a GGA with quality 0; the TPV then
    // repeats an older position, which is not this sentence's to match.
    const bool position_used = is_rmc ? ours.rmc.status_active : ours.gga.quality > 0;
    if (!lat || !lon || !position_used) {
      ++report.not_from_sentence;
      continue;
    }

    const auto compare = [&](const std::string& key, double value, int& counter) {
      const std::optional<std::string> raw = rawNumber(*tpv_line, key);
      if (!raw)
        return;
      const double printed = tpv[key].get<double>();
      const double tolerance = printedTolerance(*raw);
      if (std::fabs(value - printed) > tolerance) {
        std::ostringstream what;
        what << std::setprecision(15) << key << ": ours " << value << ", gpsd " << *raw
             << " (tolerance " << tolerance << ")";
        fail(echo, what.str());
      }
      ++counter;
    };
    int lat_lon_fields = 0;
    compare("lat", *lat, lat_lon_fields);
    compare("lon", *lon, lat_lon_fields);
    if (lat_lon_fields == 2)
      ++report.lat_lon;

    if (is_rmc) {
      if (ours.rmc.speed_mps)
        compare("speed", *ours.rmc.speed_mps, report.speed);
      if (ours.rmc.course_deg)
        compare("track", *ours.rmc.course_deg, report.track);
      if (ours.rmc.time && tpv.contains("time")) {
        const std::string printed = tpv["time"].get<std::string>();
        const std::size_t dot = printed.find('.');
        const int digits =
            dot == std::string::npos ? 0 : static_cast<int>(printed.size() - dot - 2);
        const std::string mine = core::formatIso8601(*ours.rmc.time + offset, digits);
        if (mine != printed)
          fail(echo, "time: ours " + mine + ", gpsd " + printed);
        ++report.time;
      }
      // The altitude of a TPV at an RMC comes from the GGA of the same epoch, when there is one.
      if (gga_of_cycle) {
        const auto gga = decodes.find(*gga_of_cycle);
        if (gga != decodes.end() && gga->second.kind == SentenceKind::kGga &&
            gga->second.gga.altitude_m && gga->second.gga.quality > 0 &&
            gga->second.gga.time_of_day == ours.rmc.time_of_day) {
          compare("altMSL", *gga->second.gga.altitude_m, report.altitude);
        }
      }
    } else if (ours.gga.altitude_m) {
      compare("altMSL", *ours.gga.altitude_m, report.altitude);
    }
  }

  // Every RMC/GGA in the log with a wrong or missing checksum, for which gpsd therefore reported
  // no fix, must be rejected by us (or never seen whole, when garbage cut into it).
  if (cookie) {
    bytes.erase(std::remove(bytes.begin() + static_cast<std::ptrdiff_t>(
                                                bytes.find('\n', bytes.find("# Delay-Cookie: "))),
                            bytes.end(), *cookie),
                bytes.end());
  }
  std::istringstream data(bytes);
  for (std::string line; std::getline(data, line);) {
    while (!line.empty() && line.back() == '\r')
      line.pop_back();
    if (line.empty() || line[0] == '#')
      continue;
    for (std::size_t start = line.find('$'); start != std::string::npos;) {
      const std::size_t next = line.find('$', start + 1);
      std::string fragment = line.substr(start, next == std::string::npos ? next : next - start);
      while (!fragment.empty() && fragment.back() == ' ')
        fragment.pop_back();
      start = next;
      const std::string type = typeOf(fragment);
      if ((type != "RMC" && type != "GGA") || hasValidChecksum(fragment))
        continue;
      if (echoes_with_fix.count(fragment) != 0) {
        fail(fragment, "gpsd reported a fix for a sentence with a bad checksum (test data?)");
        continue;
      }
      const auto found = decodes.find(fragment);
      if (found != decodes.end() && found->second.kind != SentenceKind::kRejected) {
        fail(fragment, "bad checksum, but we decoded it");
      } else {
        ++report.bad_checksum_rejected;
      }
    }
  }
  return report;
}

std::vector<std::string> logNames() {
  std::vector<std::string> names;
  if (!fs::is_directory(kGpsdDir))
    return names;
  for (const auto& entry : fs::directory_iterator(kGpsdDir)) {
    if (entry.path().extension() == ".log")
      names.push_back(entry.path().filename().string());
  }
  std::sort(names.begin(), names.end());
  return names;
}

class GpsdRegression : public testing::TestWithParam<std::string> {};

TEST_P(GpsdRegression, MatchesGpsdExpectedOutput) {
  const FileReport report = compareFile(kGpsdDir / GetParam());
  for (const std::string& failure : report.failures)
    ADD_FAILURE() << failure;
  RecordProperty("lat_lon", report.lat_lon);
  RecordProperty("speed", report.speed);
  RecordProperty("track", report.track);
  RecordProperty("time_fields", report.time);
  RecordProperty("altitude", report.altitude);
  RecordProperty("bad_checksum_rejected", report.bad_checksum_rejected);
  std::cout << report.name << ": lat/lon " << report.lat_lon << ", speed " << report.speed
            << ", track " << report.track << ", time " << report.time << ", altMSL "
            << report.altitude << ", bad-checksum rejected " << report.bad_checksum_rejected
            << ", stale TPV skipped " << report.not_from_sentence << "\n";
  // Every gpsd fix that is this sentence's own must have been compared, not skipped.
  EXPECT_EQ(report.echoed_fixes, report.lat_lon + report.not_from_sentence + report.missing);
}

std::string testName(const testing::TestParamInfo<std::string>& info) {
  std::string name = info.param.substr(0, info.param.size() - 4);
  std::replace_if(
      name.begin(), name.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); },
      '_');
  return name;
}

INSTANTIATE_TEST_SUITE_P(Logs, GpsdRegression, testing::ValuesIn(logNames()), testName);

// The whole corpus at once: prints the table of compared fields and makes sure the comparison
// cannot pass by comparing nothing.
TEST(GpsdRegressionCorpus, ComparesASubstantialNumberOfFields) {
  const std::vector<std::string> names = logNames();
  ASSERT_GE(names.size(), 23u) << "gpsd logs missing under " << kGpsdDir;
  FileReport total;
  std::cout << std::left << std::setw(36) << "file" << std::right << std::setw(8) << "lat/lon"
            << std::setw(7) << "speed" << std::setw(7) << "track" << std::setw(6) << "time"
            << std::setw(8) << "altMSL" << std::setw(9) << "badsum"
            << "\n";
  for (const std::string& name : names) {
    const FileReport r = compareFile(kGpsdDir / name);
    std::cout << std::left << std::setw(36) << name << std::right << std::setw(8) << r.lat_lon
              << std::setw(7) << r.speed << std::setw(7) << r.track << std::setw(6) << r.time
              << std::setw(8) << r.altitude << std::setw(9) << r.bad_checksum_rejected << "\n";
    total.lat_lon += r.lat_lon;
    total.speed += r.speed;
    total.track += r.track;
    total.time += r.time;
    total.altitude += r.altitude;
    total.bad_checksum_rejected += r.bad_checksum_rejected;
    EXPECT_TRUE(r.failures.empty()) << name << ": " << r.failures.size() << " mismatches";
  }
  std::cout << std::left << std::setw(36) << "total" << std::right << std::setw(8) << total.lat_lon
            << std::setw(7) << total.speed << std::setw(7) << total.track << std::setw(6)
            << total.time << std::setw(8) << total.altitude << std::setw(9)
            << total.bad_checksum_rejected << "\n";
  RecordProperty("lat_lon", total.lat_lon);
  RecordProperty("speed", total.speed);
  RecordProperty("time_fields", total.time);
  RecordProperty("altitude", total.altitude);
  // gpsd prints a TPV directly after about 370 of the logs' RMC/GGA sentences (most receivers
  // end their cycle with the RMC); the floors below sit a little under what the logs offer.
  EXPECT_GE(total.lat_lon, 350);
  EXPECT_GE(total.speed, 250);
  EXPECT_GE(total.track, 230);
  EXPECT_GE(total.time, 250);
  EXPECT_GE(total.altitude, 280);
  // firefly-II alone has 23 GGAs with a wrong checksum; gp-320fw and others add more.
  EXPECT_GE(total.bad_checksum_rejected, 30);
}

}  // namespace
}  // namespace fieldrig::gps
