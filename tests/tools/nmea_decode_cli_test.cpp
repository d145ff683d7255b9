// Runs the built `fieldrig nmea decode` on gpsd logs and on a hand-made file with corrupt lines
// and checks the contract: one JSON object per intact RMC/GGA in input order with the required
// fields, a final {"summary": …} line with the counts, and nothing from a corrupt line.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "fieldrig/gps/nmea_parser.h"
#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using gps::withChecksum;
using namespace testing_support;

const fs::path kGpsdDir = fs::path(FIELDRIG_SHARED_DATA_DIR) / "nmea" / "gpsd";

// `fieldrig nmea decode FILE`, its outputs kept in `dir`.
CliRun decode(const fs::path& file, const ScopedTempDir& dir) {
  return testing_support::runFieldrig({"nmea", "decode", file.string()}, dir.path());
}

// Checked here without the library: the intact sentences of a gpsd log are found independently.
bool checksumOk(const std::string& sentence) {
  const std::size_t star = sentence.rfind('*');
  if (star == std::string::npos || star + 3 != sentence.size())
    return false;
  unsigned char sum = 0;
  for (std::size_t i = 1; i < star; ++i)
    sum ^= static_cast<unsigned char>(sentence[i]);
  return std::strtoul(sentence.substr(star + 1).c_str(), nullptr, 16) == sum;
}

// Checks every output line against the contract; returns the objects (summary excluded).
std::vector<Json> checkContract(const CliRun& run, Json& summary) {
  std::vector<Json> objects;
  EXPECT_FALSE(run.out_lines.empty());
  for (std::size_t i = 0; i < run.out_lines.size(); ++i) {
    Json line;
    try {
      line = Json::parse(run.out_lines[i]);
    } catch (const Json::parse_error& e) {
      ADD_FAILURE() << "line " << i + 1 << " is not JSON: " << run.out_lines[i];
      continue;
    }
    if (i + 1 == run.out_lines.size()) {
      EXPECT_TRUE(line.contains("summary")) << run.out_lines[i];
      summary = line["summary"];
      continue;
    }
    EXPECT_TRUE(line.is_object());
    const std::string kind = line.value("sentence", "");
    EXPECT_TRUE(kind == "RMC" || kind == "GGA") << run.out_lines[i];
    std::vector<std::string> required = {"sentence", "talker", "lat", "lon"};
    if (kind == "RMC") {
      required.insert(required.end(), {"time", "valid", "speed_mps", "course_deg"});
    } else {
      required.insert(required.end(),
                      {"time_of_day", "quality", "satellites", "hdop", "altitude_m"});
    }
    for (const std::string& field : required) {
      EXPECT_TRUE(line.contains(field)) << field << " missing: " << run.out_lines[i];
    }
    if (kind == "RMC") {
      EXPECT_TRUE(line["valid"].is_boolean());
      EXPECT_TRUE(line["time"].is_null() || line["time"].get<std::string>().back() == 'Z');
    } else {
      EXPECT_TRUE(line["quality"].is_number_integer());
      EXPECT_TRUE(line["satellites"].is_null() || line["satellites"].is_number_integer());
    }
    objects.push_back(line);
  }
  return objects;
}

// `text` as the file NAME.nmea in a fresh folder, decoded there: it must exit 0 with every line
// by the contract. The objects, and the summary in `summary`. Its fatal failures end only this
// call: call it through ASSERT_NO_FATAL_FAILURE.
void decodeText(const std::string& name, const std::string& text, std::vector<Json>& objects,
                Json& summary) {
  const ScopedTempDir dir("nmea_decode_cli_" + name);
  const fs::path file = dir / (name + ".nmea");
  std::ofstream(file, std::ios::binary) << text;
  const CliRun run = decode(file, dir);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  objects = checkContract(run, summary);
}

// hh:mm:ss of an output object, to compare order with the input.
std::string clockOf(const Json& object) {
  const std::string text = object["sentence"] == "RMC" ? object["time"].get<std::string>()
                                                       : object["time_of_day"].get<std::string>();
  return object["sentence"] == "RMC" ? text.substr(11, 8) : text.substr(0, 8);
}

TEST(NmeaDecodeCli, GpsdLogsFollowTheContractInInputOrder) {
  for (const std::string name :
       {"cat-ms352.log", "gp-320fw-2019-04-07-coldboot.log", "triton400.log", "nmea-rtk.log"}) {
    SCOPED_TRACE(name);
    const ScopedTempDir dir("nmea_decode_cli_gpsd");
    const CliRun run = decode(kGpsdDir / name, dir);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    Json summary;
    const std::vector<Json> objects = checkContract(run, summary);

    // The intact RMC/GGA of the file, found here independently: split lines at '$', check the
    // XOR checksum. Comment lines ('#') are not data.
    std::vector<std::pair<std::string, std::string>> expected;  // type, hh:mm:ss
    int comments = 0;
    std::istringstream data(readWholeFile(kGpsdDir / name));
    for (std::string line; std::getline(data, line);) {
      while (!line.empty() && (line.back() == '\r' || line.back() == ' '))
        line.pop_back();
      if (!line.empty() && line[0] == '#') {
        ++comments;
        continue;
      }
      for (std::size_t at = line.find('$'); at != std::string::npos;) {
        const std::size_t next = line.find('$', at + 1);
        const std::string sentence = line.substr(at, next == std::string::npos ? next : next - at);
        at = next;
        if (!checksumOk(sentence) || sentence.size() < 14)
          continue;
        const std::string type = sentence.substr(3, 3);
        if (type != "RMC" && type != "GGA")
          continue;
        const std::string hhmmss = sentence.substr(7, 6);
        expected.emplace_back(
            type, hhmmss.substr(0, 2) + ":" + hhmmss.substr(2, 2) + ":" + hhmmss.substr(4, 2));
      }
    }
    // gp-320fw has an intact RMC without a date: its time is null, so only its type is compared.
    ASSERT_EQ(objects.size(), expected.size());
    for (std::size_t i = 0; i < objects.size(); ++i) {
      EXPECT_EQ(objects[i]["sentence"], expected[i].first) << "object " << i;
      const bool timed = objects[i]["sentence"] == "GGA" ? !objects[i]["time_of_day"].is_null()
                                                         : !objects[i]["time"].is_null();
      if (timed) {
        EXPECT_EQ(clockOf(objects[i]), expected[i].second) << "object " << i;
      }
    }
    ASSERT_TRUE(summary.is_object());
    const auto rmc = std::count_if(expected.begin(), expected.end(),
                                   [](const auto& e) { return e.first == "RMC"; });
    EXPECT_EQ(summary["rmc"].get<long>(), rmc);
    EXPECT_EQ(summary["gga"].get<long>(), static_cast<long>(expected.size()) - rmc);
    EXPECT_EQ(summary["comments"].get<int>(), comments);
    EXPECT_GE(summary["lines"].get<long>(), summary["sentences"].get<long>() / 2);
  }
}

TEST(NmeaDecodeCli, CorruptLinesNeverYieldAnObject) {
  // Good sentences at latitude 40°, corrupt ones at 11°: no output may be near 11°.
  const std::string good_rmc =
      withChecksum("GNRMC,120000.10,A,4000.12345678,N,08800.12345678,W,1.944,45.0,140726,,,R");
  const std::string good_gga = withChecksum(
      "GNGGA,120000.10,4000.12345678,N,08800.12345678,W,4,17,0.7,221.5,M,-33.4,M,1.0,0000");
  const std::string bad_rmc =
      withChecksum("GNRMC,120000.20,A,1100.12345678,N,08800.12345678,W,1.944,45.0,140726,,,R");
  const std::string bad_gga = withChecksum(
      "GNGGA,120000.20,1100.12345678,N,08800.12345678,W,4,17,0.7,221.5,M,-33.4,M,1.0,0000");
  std::string wrong_checksum = bad_rmc;
  wrong_checksum.back() = wrong_checksum.back() == 'A' ? 'B' : 'A';
  std::string nul_inside = bad_gga;
  nul_inside[20] = '\0';
  std::string flipped = bad_gga;  // one digit changed, checksum no longer matches
  flipped[25] = flipped[25] == '9' ? '8' : '9';
  const std::string file_text =
      "# hand-made: two intact epochs around corrupt lines\r\n" + good_rmc + "\r\n" + good_gga +
      "\r\n" + wrong_checksum + "\r\n" + bad_gga.substr(0, 40) + "\r\n" + nul_inside + "\r\n" +
      "$GNGGA,120000" + good_rmc + "\r\n" + flipped + "\r\n" + "line noise \x01\x02\r\n" +
      "$GPTXT," + std::string(400, 'x') + "\r\n" + good_gga;  // no final terminator
  std::vector<Json> objects;
  Json summary;
  ASSERT_NO_FATAL_FAILURE(decodeText("corrupt", file_text, objects, summary));
  ASSERT_EQ(objects.size(), 4u);
  const std::vector<std::string> order = {"RMC", "GGA", "RMC", "GGA"};
  for (std::size_t i = 0; i < objects.size(); ++i) {
    EXPECT_EQ(objects[i]["sentence"], order[i]);
    // 40 + 0.12345678 / 60 = 40.002057613
    EXPECT_NEAR(objects[i]["lat"].get<double>(), 40.002057613, 1e-9);
    EXPECT_NEAR(objects[i]["lon"].get<double>(), -88.002057613, 1e-9);
    EXPECT_EQ(objects[i]["talker"], "GN");
  }
  EXPECT_EQ(objects[0]["time"], "2026-07-14T12:00:00.10Z");
  EXPECT_EQ(objects[0]["valid"], true);
  EXPECT_NEAR(objects[0]["speed_mps"].get<double>(), 1.944 * 1852 / 3600, 1e-12);
  EXPECT_EQ(objects[1]["quality"], 4);
  EXPECT_EQ(objects[1]["satellites"], 17);
  EXPECT_EQ(objects[1]["altitude_m"], 221.5);

  ASSERT_TRUE(summary.is_object());
  EXPECT_EQ(summary["comments"], 1);
  EXPECT_EQ(summary["lines"], 11);  // every non-blank line, the comment included
  EXPECT_EQ(summary["rmc"], 2);
  EXPECT_EQ(summary["gga"], 2);
  EXPECT_EQ(summary["sentences"], 4);
  const Json& rejected = summary["rejected"];
  EXPECT_EQ(rejected["bad_checksum"], 2);  // wrong_checksum, flipped
  EXPECT_EQ(rejected["no_checksum"], 2);   // the truncated GGA, "$GNGGA,120000"
  EXPECT_EQ(rejected["non_printable"], 1);
  EXPECT_EQ(rejected["garbage"], 1);
  EXPECT_EQ(rejected["too_long"], 1);
  EXPECT_EQ(summary["rejected_total"], 7);
}

TEST(NmeaDecodeCli, TimesKeepTheReceiversPrecisionAndValidIsStatusA) {
  // Millisecond times (hhmmss.sss) keep their third digit; status A with mode N (no fix) is
  // still "valid": the contract's valid is the status field.
  const std::string file_text =
      withChecksum("GPRMC,235959.125,A,4000.12345678,N,08800.12345678,W,0.0,0.0,311226,,,N") +
      "\r\n" +
      withChecksum("GPGGA,235959.125,4000.12345678,N,08800.12345678,W,1,08,1.0,10.0,M,0,M,,") +
      "\r\n" + withChecksum("GPRMC,000000.00,V,,,,,,,010127,,,N") + "\r\n";
  std::vector<Json> objects;
  Json summary;
  ASSERT_NO_FATAL_FAILURE(decodeText("precision", file_text, objects, summary));
  ASSERT_EQ(objects.size(), 3u);
  EXPECT_EQ(objects[0]["time"], "2026-12-31T23:59:59.125Z");
  EXPECT_EQ(objects[0]["valid"], true);
  EXPECT_EQ(objects[1]["time_of_day"], "23:59:59.125");
  EXPECT_EQ(objects[2]["time"], "2027-01-01T00:00:00.00Z");
  EXPECT_EQ(objects[2]["valid"], false);
  EXPECT_TRUE(objects[2]["lat"].is_null());
}

TEST(NmeaDecodeCli, MissingFileIsAnErrorNamingIt) {
  const std::string missing = "/nonexistent/fieldrig-no-such-file.nmea";
  const ScopedTempDir dir("nmea_decode_cli_missing");
  const CliRun run = decode(missing, dir);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find(missing), std::string::npos) << run.err;
  // No summary pretends the file was read.
  for (const std::string& line : run.out_lines)
    EXPECT_EQ(line.find("summary"), std::string::npos);
}

}  // namespace
}  // namespace fieldrig
