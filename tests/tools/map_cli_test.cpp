// `fieldrig map generate` and `fieldrig map record`, run as the built binary.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>
#include <GeographicLib/Geodesic.hpp>
#include <GeographicLib/LocalCartesian.hpp>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/location_map.h"
#include "fieldrig/gps/nmea_parser.h"
#include "support/cli_process.h"
#include "support/cli_run.h"
#include "support/field_plans.h"
#include "support/socat_pty.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using Json = nlohmann::json;
using testing_support::FieldrigProcess;
using testing_support::readWholeFile;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;

// One JSON object per line of `lines` (a mark per line on stdout).
std::vector<Json> jsonLines(const std::vector<std::string>& lines) {
  std::vector<Json> objects;
  for (const std::string& line : lines)
    objects.push_back(Json::parse(line));
  return objects;
}

// ---------------------------------------------------------------------------------------------
// Synthetic NMEA.

// NMEA's dddmm.mmmmmmmm, rounded as a whole so that 41.99999999999 becomes 4200.00000000, not
// 4159.99999999 rounded to the invalid 4160.00000000.
std::string angle(double degrees, int degree_digits, char positive, char negative) {
  const auto units = static_cast<long long>(std::llround(std::fabs(degrees) * 60.0 * 1e8));
  const long long per_degree = 60LL * 100'000'000LL;
  const long long whole = units / per_degree;
  const long long minutes = (units % per_degree) / 100'000'000LL;
  const long long fraction = units % 100'000'000LL;
  char text[48];
  std::snprintf(text, sizeof text, "%0*lld%02lld.%08lld,%c", degree_digits, whole, minutes,
                fraction, degrees < 0 ? negative : positive);
  return text;
}

struct Epoch {
  double t = 0;  // seconds after 15:30:00 UTC, 2026-07-14
  double latitude = 0;
  double longitude = 0;
  bool valid = true;
  double speed_mps = 0;
  std::optional<double> course;
};

std::string timeOfDay(double t) {
  // Seconds below 60 only: the drives here are short.
  const int hundredths = static_cast<int>(std::lround(t * 100)) % 6000;
  char text[32];
  std::snprintf(text, sizeof text, "1530%02d.%02d", hundredths / 100, hundredths % 100);
  return text;
}

std::string nmeaFor(const Epoch& e) {
  char speed[32];
  std::snprintf(speed, sizeof speed, "%.4f", e.speed_mps / (1852.0 / 3600.0));
  char course[32] = "";
  if (e.course)
    std::snprintf(course, sizeof course, "%.2f", *e.course);
  const std::string position =
      angle(e.latitude, 2, 'N', 'S') + "," + angle(e.longitude, 3, 'E', 'W');
  const std::string rmc = "GPRMC," + timeOfDay(e.t) + "," + (e.valid ? "A" : "V") + "," + position +
                          "," + speed + "," + course + ",140726,,," + (e.valid ? "D" : "N");
  const std::string gga = "GPGGA," + timeOfDay(e.t) + "," + position + "," + (e.valid ? "4" : "0") +
                          ",12,0.8,300.0,M,-30.0,M,,";
  return gps::withChecksum(rmc) + "\r\n" + gps::withChecksum(gga) + "\r\n";
}

// The driven track in a local east/north frame near Ames, Iowa.
struct Track {
  GeographicLib::LocalCartesian frame{42.0, -93.6, 0.0};

  Epoch at(double t, double east, double north) const {
    Epoch e;
    e.t = t;
    double h = 0;
    frame.Reverse(east, north, 0.0, e.latitude, e.longitude, h);
    return e;
  }
  void local(double latitude, double longitude, double& east, double& north) const {
    double up = 0;
    frame.Forward(latitude, longitude, 0.0, east, north, up);
  }
};

// Distance along and across a leg from `start` on `heading_deg`.
void legCoordinates(double east, double north, double start_east, double start_north,
                    double heading_deg, double& along, double& across) {
  const double rad = heading_deg * std::numbers::pi / 180.0;
  const double ue = std::sin(rad), un = std::cos(rad);
  along = (east - start_east) * ue + (north - start_north) * un;
  across = (east - start_east) * un - (north - start_north) * ue;
}

void writeFile(const std::string& path, const std::string& text) {
  std::ofstream(path, std::ios::binary) << text;
}

// ---------------------------------------------------------------------------------------------
// map generate

TEST(MapCli, GenerateWritesTheFieldPlansMap) {
  const ScopedTempDir dir("map_cli_generate");
  // Three rows of four 10-foot plots, further rows to the left, ids T…: every option given.
  gps::FieldPlan plan =
      testing_support::fieldPlan({42.0105, -93.7452}, {42.0110, -93.7445}, 3, 3.048, 0.5);
  plan.plots_per_row = 4;
  plan.rows_to_the_right = false;
  plan.id_prefix = "T";
  const auto run = runFieldrig(
      testing_support::withFieldPlan({"map", "generate"}, plan, {"--out", dir / "map.csv"}),
      dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1u) << run.err;
  const Json summary = Json::parse(run.out_lines[0]);
  EXPECT_EQ(summary["locations"], 12);
  EXPECT_EQ(summary["rows"], 3);
  EXPECT_EQ(summary["plots_per_row"], 4);

  auto expected = gps::generateLocations(plan);
  ASSERT_TRUE(expected.ok()) << expected.error().message;
  auto written = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(written.ok()) << written.error().message;
  ASSERT_EQ(written->size(), 12u);
  EXPECT_EQ(written->metadataColumns(), expected->metadataColumns());
  for (std::size_t i = 0; i < written->size(); ++i) {
    const auto& a = written->locations()[i];
    const auto& b = expected->locations()[i];
    EXPECT_EQ(a.id, b.id);
    EXPECT_EQ(a.latitude_deg, b.latitude_deg);
    EXPECT_EQ(a.longitude_deg, b.longitude_deg);
    EXPECT_EQ(a.heading_deg, b.heading_deg);
    EXPECT_EQ(a.metadata, b.metadata);
  }
  EXPECT_EQ(written->locations()[4].id, "TR02P04");  // serpentine: row 2 starts at its far end
}

TEST(MapCli, GenerateRejectsABadPlan) {
  const ScopedTempDir dir("map_cli_generate_bad");
  auto run = runFieldrig({"map", "generate", "--row-start", "42.0105,-93.7452", "--row-end",
                          "42.0110,-93.7445", "--rows", "0", "--plot-length", "3", "--alley-length",
                          "1", "--row-spacing", "2", "--out", dir / "map.csv"},
                         dir.path());
  EXPECT_EQ(run.exit_code, 2);
  // Refused by the flag's own range, which the message states.
  EXPECT_NE(run.err.find("--rows: must be a whole number in [1, 1000], got 0"), std::string::npos)
      << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir / "map.csv"));
  run = runFieldrig({"map", "generate", "--row-start", "42.0105;-93.7452", "--row-end",
                     "42.0110,-93.7445", "--rows", "1", "--plot-length", "3", "--alley-length", "1",
                     "--row-spacing", "2", "--out", dir / "map.csv"},
                    dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--row-start"), std::string::npos) << run.err;
}

// An output that cannot be written is a file that cannot be used (exit 2, naming it), as in the
// other commands; it was exit 3, the code for a failure while running.
TEST(MapCli, GenerateIntoAnUnwritablePlaceIsBadInputNamingIt) {
  const ScopedTempDir dir("map_cli_generate_unwritable");
  const std::filesystem::path out = dir / "no-such-folder" / "map.csv";
  const auto run = runFieldrig({"map", "generate", "--row-start", "42.0105,-93.7452", "--row-end",
                                "42.0110,-93.7445", "--rows", "1", "--plot-length", "3",
                                "--alley-length", "1", "--row-spacing", "2", "--out", out},
                               dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find(out.string()), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(out.parent_path()));
}

// ---------------------------------------------------------------------------------------------
// map record

// Invalid fixes until 1.2 s; leg 1 north-east (45 degrees) at 2 m/s with RMC course until
// 3.5 s; leg 2 south-east (135 degrees) at 2 m/s without RMC course until 6 s.
constexpr double kLeg1Start = 1.2, kLeg2Start = 3.5, kEnd = 6.0;

std::string twoLegDrive(const Track& track, double& corner_east, double& corner_north) {
  const double rad45 = std::numbers::pi / 4;
  corner_east = 2.0 * (kLeg2Start - kLeg1Start) * std::sin(rad45);
  corner_north = 2.0 * (kLeg2Start - kLeg1Start) * std::cos(rad45);
  std::string nmea = "$GPGSV,garbage line the parser must survive\r\n";
  for (int i = 0; i <= static_cast<int>(kEnd * 10 + 0.5); ++i) {
    const double t = i / 10.0;
    Epoch e;
    if (t < kLeg1Start) {
      e = track.at(t, 0, 0);
      e.valid = false;
    } else if (t < kLeg2Start) {
      const double s = 2.0 * (t - kLeg1Start);
      e = track.at(t, s * std::sin(rad45), s * std::cos(rad45));
      e.speed_mps = 2.0;
      e.course = 45.0;
    } else {
      const double s = 2.0 * (t - kLeg2Start);
      e = track.at(t, corner_east + s * std::sin(3 * rad45),
                   corner_north + s * std::cos(3 * rad45));
      e.speed_mps = 2.0;
    }
    nmea += nmeaFor(e);
  }
  return nmea;
}

TEST(MapCli, RecordFromFileMarksByEnterAndSigusr1) {
  const ScopedTempDir dir("map_cli_record");
  Track track;
  double corner_east = 0, corner_north = 0;
  writeFile(dir / "drive.nmea", twoLegDrive(track, corner_east, corner_north));

  FieldrigProcess child(
      {"map", "record", "--nmea", dir / "drive.nmea", "--out", dir / "map.csv", "--realtime"},
      dir.path());
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err();
  const auto start = Clock::now();
  // Before any valid fix: refused, nothing written.
  std::this_thread::sleep_until(start + 400ms);
  ASSERT_TRUE(child.sendInput("\n"));
  ASSERT_TRUE(child.waitForStderr("refused")) << child.err();
  // On leg 1, by Enter.
  std::this_thread::sleep_until(start + 2300ms);
  ASSERT_TRUE(child.sendInput("\n"));
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err();
  // On leg 2, by SIGUSR1.
  std::this_thread::sleep_until(start + 5000ms);
  ASSERT_TRUE(child.signal(SIGUSR1));
  ASSERT_TRUE(child.waitForStdoutLines(2)) << child.err();
  // The file ends at 6 s, and so does the command.
  ASSERT_EQ(child.waitExit(), 0) << child.err();
  EXPECT_NE(child.err().find("2 marks written"), std::string::npos) << child.err();

  const std::vector<Json> marks = jsonLines(child.outLines());
  ASSERT_EQ(marks.size(), 2u) << child.out();
  EXPECT_EQ(marks[0]["id"], "P1");
  EXPECT_EQ(marks[0]["trigger"], "enter");
  EXPECT_EQ(marks[0]["heading_source"], "course");
  EXPECT_EQ(marks[1]["id"], "P2");
  EXPECT_EQ(marks[1]["trigger"], "sigusr1");
  EXPECT_EQ(marks[1]["heading_source"], "track");

  auto map = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 2u);
  EXPECT_EQ(map->metadataColumns(), (std::vector<std::string>{"time", "speed_mps", "quality"}));

  // P1 lies on leg 1 (within the 8-decimal NMEA rounding), heading its course.
  const gps::ImagingLocation& p1 = map->locations()[0];
  EXPECT_EQ(p1.latitude_deg, marks[0]["lat"].get<double>());
  double east = 0, north = 0, along = 0, across = 0;
  track.local(p1.latitude_deg, p1.longitude_deg, east, north);
  legCoordinates(east, north, 0, 0, 45.0, along, across);
  EXPECT_LT(std::fabs(across), 0.001);
  EXPECT_GT(along, 0.0);
  EXPECT_LT(along, 2.0 * (kLeg2Start - kLeg1Start));
  ASSERT_TRUE(p1.heading_deg.has_value());
  EXPECT_DOUBLE_EQ(*p1.heading_deg, 45.0);
  EXPECT_EQ(p1.metadata[1], "2.000");
  EXPECT_EQ(p1.metadata[2], "4");
  EXPECT_EQ(p1.metadata[0].rfind("2026-07-14T15:30:0", 0), 0u) << p1.metadata[0];

  // P2 lies on leg 2; its heading is the bearing of the track behind it (no RMC course).
  const gps::ImagingLocation& p2 = map->locations()[1];
  track.local(p2.latitude_deg, p2.longitude_deg, east, north);
  legCoordinates(east, north, corner_east, corner_north, 135.0, along, across);
  EXPECT_LT(std::fabs(across), 0.001);
  // Far enough into leg 2 that the 1 m bearing base is all on leg 2 (the mark came ~1.5 s in).
  EXPECT_GT(along, 1.2);
  EXPECT_LE(along, 2.0 * (kEnd - kLeg2Start) + 1e-3);
  ASSERT_TRUE(p2.heading_deg.has_value());
  EXPECT_NEAR(*p2.heading_deg, 135.0, 0.01);
}

TEST(MapCli, RecordContinuesAnExistingMapAndRefusesStaleFixes) {
  const ScopedTempDir dir("map_cli_record_continue");
  const std::string header = "id,lat,lon,heading,time,speed_mps,quality\n";
  const std::string existing = "# recorded yesterday\n" + header +
                               "P7,42.001,-93.601,10,2026-07-13T15:00:00.000Z,1.500,4\n"
                               "X1,42.002,-93.602,,2026-07-13T15:00:01.000Z,,";  // no final newline
  writeFile(dir / "map.csv", existing);

  // Valid fixes heading north for 1.5 s, then nothing until a last fix at 6 s.
  Track track;
  std::string nmea;
  for (int i = 0; i <= 15; ++i) {
    Epoch e = track.at(i / 10.0, 0, 1.5 * i / 10.0);
    e.speed_mps = 1.5;
    e.course = 0.0;
    nmea += nmeaFor(e);
  }
  Epoch last = track.at(6.0, 0, 10.0);
  last.speed_mps = 1.5;
  nmea += nmeaFor(last);
  writeFile(dir / "drive.nmea", nmea);

  FieldrigProcess child({"map", "record", "--nmea", dir / "drive.nmea", "--out", dir / "map.csv"},
                        dir.path());
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err();
  EXPECT_NE(child.err().find("2 locations already there"), std::string::npos) << child.err();
  const auto start = Clock::now();
  std::this_thread::sleep_until(start + 700ms);
  ASSERT_TRUE(child.sendInput("\n"));
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err();
  // 4.2 s: the latest fix (1.5 s) is 2.7 s old.
  std::this_thread::sleep_until(start + 4200ms);
  ASSERT_TRUE(child.sendInput("\n"));
  ASSERT_TRUE(child.waitForStderr("s old; nothing written")) << child.err();
  ASSERT_EQ(child.waitExit(), 0) << child.err();

  const std::vector<Json> marks = jsonLines(child.outLines());
  ASSERT_EQ(marks.size(), 1u) << child.out();
  EXPECT_EQ(marks[0]["id"], "P8");  // one past the highest P number

  const std::string text = readWholeFile(dir / "map.csv");
  // The old text is kept byte for byte, the missing newline added, the header not repeated.
  ASSERT_EQ(text.rfind(existing + "\n", 0), 0u) << text;
  EXPECT_EQ(text.find(header), text.rfind(header));
  auto map = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 3u);
  const gps::ImagingLocation& p8 = map->locations()[2];
  EXPECT_EQ(p8.id, "P8");
  double east = 0, north = 0;
  track.local(p8.latitude_deg, p8.longitude_deg, east, north);
  EXPECT_LT(std::fabs(east), 0.001);
  EXPECT_GT(north, 0.0);
  EXPECT_LE(north, 1.5 * 1.5 + 1e-3);
  EXPECT_EQ(p8.heading_deg, std::optional<double>(0.0));
}

TEST(MapCli, RecordRefusesAnIncompatibleExistingMap) {
  const ScopedTempDir dir("map_cli_record_incompatible");
  writeFile(dir / "drive.nmea", nmeaFor(Track{}.at(0, 0, 0)));
  const std::string other = "id,lat,lon,plot\nA,42,-93,1\n";
  writeFile(dir / "map.csv", other);
  const std::vector<std::string> record = {"map",   "record",       "--nmea", dir / "drive.nmea",
                                           "--out", dir / "map.csv"};
  auto run = runFieldrig(record, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("is not the recording header"), std::string::npos) << run.err;
  EXPECT_EQ(readWholeFile(dir / "map.csv"), other);

  // A broken map is reported with its line.
  writeFile(dir / "map.csv", "id,lat,lon,heading,time,speed_mps,quality\nA,95,-93,,,,\n");
  run = runFieldrig(record, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("map.csv:2: field 'lat': 95 is outside"), std::string::npos) << run.err;
}

TEST(MapCli, MarkAtAStandstillTakesTheHeadingFromTheTrackNotTheCourse) {
  // Operators stop on the spot to mark it; the receiver then reports course 0.0 at speed 0.
  const ScopedTempDir dir("map_cli_record_standstill");
  const std::string fifo = dir / "gps.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  FieldrigProcess child({"map", "record", "--nmea", fifo, "--out", dir / "map.csv"}, dir.path());
  const int writer = ::open(fifo.c_str(), O_WRONLY);
  ASSERT_GE(writer, 0);
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err();
  Track track;
  std::string nmea;
  for (int i = 0; i <= 30; ++i) {  // 3 s due south at 1 m/s, then 1 s standing
    const double t = i / 10.0;
    Epoch e = track.at(t, 0, -std::min(t, 2.0));
    e.speed_mps = t < 2.0 ? 1.0 : 0.0;
    e.course = t < 2.0 ? 180.0 : 0.0;
    nmea += nmeaFor(e);
  }
  ASSERT_EQ(::write(writer, nmea.data(), nmea.size()), static_cast<ssize_t>(nmea.size()));
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(child.sendInput("\n"));
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err();
  ::close(writer);
  ASSERT_EQ(child.waitExit(), 0) << child.err();
  const std::vector<Json> marks = jsonLines(child.outLines());
  ASSERT_EQ(marks.size(), 1u);
  EXPECT_NEAR(marks[0]["heading_deg"].get<double>(), 180.0, 0.5);
}

TEST(MapCli, RecordFromAFifo) {
  const ScopedTempDir dir("map_cli_record_fifo");
  const std::string fifo = dir / "gps.fifo";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  FieldrigProcess child({"map", "record", "--nmea", fifo, "--out", dir / "map.csv", "--id-prefix",
                         "F", "--start-id", "100"},
                        dir.path());
  const int writer = ::open(fifo.c_str(), O_WRONLY);  // meets the recorder's open
  ASSERT_GE(writer, 0);
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err();
  Track track;
  std::string nmea;
  for (int i = 0; i < 10; ++i) {
    Epoch e = track.at(i / 10.0, -0.5 * i / 10.0, 0);  // due west at 0.5 m/s
    e.speed_mps = 0.5;
    e.course = 270.0;
    nmea += nmeaFor(e);
  }
  ASSERT_EQ(::write(writer, nmea.data(), nmea.size()), static_cast<ssize_t>(nmea.size()));
  std::this_thread::sleep_for(300ms);
  ASSERT_TRUE(child.sendInput("\n"));
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err();
  ::close(writer);  // end of input ends the command
  ASSERT_EQ(child.waitExit(), 0) << child.err();
  const std::vector<Json> marks = jsonLines(child.outLines());
  ASSERT_EQ(marks.size(), 1u);
  EXPECT_EQ(marks[0]["id"], "F100");
  EXPECT_EQ(marks[0]["heading_deg"], 270.0);
  // The last fix written before the mark: 0.45 m west of the start.
  double east = 0, north = 0;
  track.local(marks[0]["lat"].get<double>(), marks[0]["lon"].get<double>(), east, north);
  EXPECT_NEAR(east, -0.45, 0.001);
  EXPECT_NEAR(north, 0.0, 0.001);
}

// Through a real pseudo-terminal pair, as from the receiver's serial port.
TEST(MapCli, RecordFromASerialPty) {
  const ScopedTempDir dir("map_cli_record_pty");
  // socat is required: the project's test command installs it, so its absence is a failure.
  testing_support::SocatPty pty(dir.path());
  const std::string started = pty.start();
  ASSERT_EQ(started, "") << started;

  FieldrigProcess child(
      {"map", "record", "--nmea", pty.device(), "--out", dir / "map.csv", "--baud", "38400"},
      dir.path());
  ASSERT_TRUE(child.waitForStderr("mark with Enter")) << child.err();
  testing_support::Feed feed(pty.feed());
  ASSERT_TRUE(feed.ok());
  Track track;
  const auto start = Clock::now();
  bool marked = false;
  for (int i = 0; i < 20; ++i) {
    std::this_thread::sleep_until(start + i * 100ms);
    Epoch e = track.at(i / 10.0, 0, -1.0 * i / 10.0);  // due south at 1 m/s
    e.speed_mps = 1.0;
    e.course = 180.0;
    const std::string text = nmeaFor(e);
    ASSERT_TRUE(feed.write(text));
    if (i == 12) {
      std::this_thread::sleep_for(30ms);  // let the epoch arrive before the mark
      ASSERT_TRUE(child.sendInput("\n"));
      marked = true;
    }
  }
  ASSERT_TRUE(marked);
  ASSERT_TRUE(child.waitForStdoutLines(1)) << child.err();
  ASSERT_TRUE(child.signal(SIGINT));
  ASSERT_EQ(child.waitExit(), 0) << child.err();

  const std::vector<Json> marks = jsonLines(child.outLines());
  ASSERT_EQ(marks.size(), 1u);
  EXPECT_EQ(marks[0]["id"], "P1");
  EXPECT_EQ(marks[0]["heading_deg"], 180.0);
  double east = 0, north = 0;
  track.local(marks[0]["lat"].get<double>(), marks[0]["lon"].get<double>(), east, north);
  EXPECT_NEAR(east, 0.0, 0.001);
  // Epoch 12 (1.2 m south), give or take one epoch of scheduling.
  EXPECT_NEAR(north, -1.2, 0.1 + 1e-3);
  auto map = gps::LocationMap::load(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->size(), 1u);
}

}  // namespace
}  // namespace fieldrig
