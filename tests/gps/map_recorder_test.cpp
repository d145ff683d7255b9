// MapRecorder: which fix a mark takes, its heading and its id, on hand-made fixes near the
// equator (where a metre east or north is a known fraction of a degree), and the recording file.
#include "fieldrig/gps/map_recorder.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>

#include "fieldrig/core/durable_file.h"
#include "support/temp_dir.h"

namespace fieldrig::gps {
namespace {

using namespace std::chrono_literals;
using testing_support::ScopedTempDir;

// WGS84 at the equator: a degree of latitude is 110 574.3 m, a degree of longitude 111 319.5 m.
constexpr double kMetresPerDegreeLatitude = 110574.2727;
constexpr double kMetresPerDegreeLongitude = 111319.4908;

const core::UtcTime kDay =
    core::UtcTime{std::chrono::sys_days{std::chrono::year{2026} / std::chrono::July / 14}};
const core::SteadyTime kBoot{};

// A valid RTK fix `t` seconds into the drive, `east`/`north` metres from (0°, 0°), received at
// steady time t (no latency: the recorder only compares reception times).
core::GpsFix fixAt(double t, double east, double north, std::optional<double> speed,
                   std::optional<double> course) {
  core::GpsFix fix;
  fix.time = kDay + std::chrono::hours{15} + core::fromSeconds(t);
  fix.has_date = true;
  fix.latitude_deg = north / kMetresPerDegreeLatitude;
  fix.longitude_deg = east / kMetresPerDegreeLongitude;
  fix.valid = true;
  fix.speed_mps = speed;
  fix.course_deg = course;
  fix.quality = core::FixQuality::kRtkFixed;
  fix.received.steady =
      kBoot + std::chrono::duration_cast<core::SteadyTime::duration>(core::fromSeconds(t));
  return fix;
}

core::SteadyTime at(double t) {
  return kBoot + std::chrono::duration_cast<core::SteadyTime::duration>(core::fromSeconds(t));
}

MapRecorder emptyRecorder(MapRecorderOptions options = {}) {
  return MapRecorder(LocationMap(recordingColumns()), std::move(options));
}

TEST(MapRecorderTest, RefusesAMarkWithoutAValidFix) {
  MapRecorder recorder = emptyRecorder();
  auto mark = recorder.mark(at(0));
  ASSERT_FALSE(mark.ok());
  EXPECT_EQ(mark.error().message, "no valid fix yet");

  core::GpsFix invalid = fixAt(1.0, 0, 0, 1.0, 90.0);
  invalid.valid = false;
  recorder.addFix(invalid);
  EXPECT_FALSE(recorder.mark(at(1.0)).ok());
  EXPECT_TRUE(recorder.map().empty());
}

TEST(MapRecorderTest, AMovingMarkTakesTheLatestFixAndItsCourse) {
  MapRecorder recorder = emptyRecorder();
  recorder.addFix(fixAt(10.0, 0, 0, 1.5, 90.0));
  recorder.addFix(fixAt(10.1, 0.15, 0, 1.5, 90.5));
  auto mark = recorder.mark(at(10.4));
  ASSERT_TRUE(mark.ok()) << mark.error().message;
  const ImagingLocation& location = mark->location;
  EXPECT_EQ(location.id, "P1");
  EXPECT_DOUBLE_EQ(location.latitude_deg, 0.0);
  EXPECT_DOUBLE_EQ(location.longitude_deg, 0.15 / kMetresPerDegreeLongitude);
  EXPECT_EQ(location.heading_deg, std::optional<double>(90.5));
  EXPECT_EQ(mark->heading_source, HeadingSource::kCourse);
  EXPECT_EQ(mark->fix_age, 300ms);
  EXPECT_EQ(location.metadata,
            (std::vector<std::string>{"2026-07-14T15:00:10.100Z", "1.500", "4"}));
  ASSERT_EQ(recorder.map().size(), 1u);
  EXPECT_EQ(recorder.map().locations()[0].id, "P1");
  EXPECT_EQ(recorder.map().locations()[0].longitude_deg, location.longitude_deg);
}

TEST(MapRecorderTest, AFixOlderThanTwoSecondsIsRefusedAndUsesNoNumber) {
  MapRecorder recorder = emptyRecorder();
  recorder.addFix(fixAt(0.0, 0, 0, 1.0, 0.0));
  auto stale = recorder.mark(at(2.5));
  ASSERT_FALSE(stale.ok());
  EXPECT_EQ(stale.error().message, "the latest valid fix is 2.50 s old");
  EXPECT_TRUE(recorder.map().empty());
  // Exactly kMaxMarkFixAge is still fresh.
  auto fresh = recorder.mark(at(2.0));
  ASSERT_TRUE(fresh.ok()) << fresh.error().message;
  EXPECT_EQ(fresh->location.id, "P1");
}

TEST(MapRecorderTest, AtAStandstillTheHeadingIsTheBearingFromAFixOneMetreBehind) {
  MapRecorder recorder = emptyRecorder();
  // Due south at 1 m/s, then stopped: the receiver says course 0 at speed 0.
  recorder.addFix(fixAt(0.0, 0, 0.0, 1.0, 180.0));
  recorder.addFix(fixAt(0.5, 0, -0.5, 1.0, 180.0));
  recorder.addFix(fixAt(1.0, 0, -1.0, 1.0, 180.0));
  recorder.addFix(fixAt(1.2, 0, -1.2, 0.0, 0.0));
  recorder.addFix(fixAt(1.3, 0, -1.2, 0.0, 0.0));
  auto mark = recorder.mark(at(1.3));
  ASSERT_TRUE(mark.ok()) << mark.error().message;
  EXPECT_EQ(mark->heading_source, HeadingSource::kTrack);
  ASSERT_TRUE(mark->location.heading_deg.has_value());
  // The nearest earlier fix at least 1 m away is the one at 0.0 s (0.5 s: 0.7 m; 1.0 s: 0.2 m).
  EXPECT_NEAR(*mark->location.heading_deg, 180.0, 1e-6);
}

TEST(MapRecorderTest, BearingFromTheTrackWhenTheReceiverSendsNoCourse) {
  MapRecorder recorder = emptyRecorder();
  recorder.addFix(fixAt(0.0, 0.0, 0, std::nullopt, std::nullopt));
  recorder.addFix(fixAt(1.0, 1.1, 0, std::nullopt, std::nullopt));
  auto mark = recorder.mark(at(1.0));
  ASSERT_TRUE(mark.ok()) << mark.error().message;
  EXPECT_EQ(mark->heading_source, HeadingSource::kTrack);
  EXPECT_NEAR(*mark->location.heading_deg, 90.0, 1e-6);
  EXPECT_EQ(mark->location.metadata[1], "");  // no speed
}

TEST(MapRecorderTest, NoHeadingWithoutACourseOrAFixOneMetreBehindWithinTenSeconds) {
  MapRecorder recorder = emptyRecorder();
  recorder.addFix(fixAt(0.0, 0, 0.0, 0.0, 0.0));   // 2 m behind, but 12 s earlier: forgotten
  recorder.addFix(fixAt(11.0, 0, 1.5, 0.0, 0.0));  // 0.5 m behind
  recorder.addFix(fixAt(12.0, 0, 2.0, 0.0, 0.0));
  auto mark = recorder.mark(at(12.0));
  ASSERT_TRUE(mark.ok()) << mark.error().message;
  EXPECT_EQ(mark->heading_source, HeadingSource::kNone);
  EXPECT_FALSE(mark->location.heading_deg.has_value());
  EXPECT_EQ(toString(mark->heading_source), "none");
}

TEST(MapRecorderTest, AnEpochRefinedToInvalidCannotBeMarked) {
  MapRecorder recorder = emptyRecorder();
  recorder.addFix(fixAt(0.0, 0, 0, 1.0, 0.0));
  recorder.addFix(fixAt(0.1, 0, 0.1, 1.0, 0.0));
  // The GGA of the 0.1 s epoch says quality 0: the epoch's fix is replaced, not kept.
  core::GpsFix vetoed = fixAt(0.1, 0, 0.1, 1.0, 0.0);
  vetoed.valid = false;
  recorder.addFix(vetoed);
  auto mark = recorder.mark(at(0.1));
  ASSERT_TRUE(mark.ok()) << mark.error().message;
  EXPECT_DOUBLE_EQ(mark->location.latitude_deg, 0.0);  // the 0.0 s fix
}

TEST(MapRecorderTest, NumbersContinueAfterTheHighestAndSkipUsedOnes) {
  LocationMap existing(recordingColumns());
  ImagingLocation p7;
  p7.id = "P7";
  p7.metadata = {"", "", ""};
  ASSERT_TRUE(existing.add(p7).ok());
  ImagingLocation x1 = p7;
  x1.id = "X12";
  ASSERT_TRUE(existing.add(x1).ok());
  ImagingLocation p7b = p7;
  p7b.id = "P7b";  // not <prefix><number>: ignored
  ASSERT_TRUE(existing.add(p7b).ok());

  MapRecorder continued(existing, {});
  continued.addFix(fixAt(0, 0, 0, 1.0, 0.0));
  EXPECT_EQ(continued.mark(at(0)).value().location.id, "P8");
  EXPECT_EQ(continued.mark(at(0)).value().location.id, "P9");

  MapRecorder restarted(existing, {.id_prefix = "P", .start_id = 6});
  restarted.addFix(fixAt(0, 0, 0, 1.0, 0.0));
  EXPECT_EQ(restarted.mark(at(0)).value().location.id, "P6");
  EXPECT_EQ(restarted.mark(at(0)).value().location.id, "P8");  // P7 is taken

  MapRecorder other_prefix(existing, {.id_prefix = "X", .start_id = std::nullopt});
  other_prefix.addFix(fixAt(0, 0, 0, 1.0, 0.0));
  EXPECT_EQ(other_prefix.mark(at(0)).value().location.id, "X13");
}

TEST(MapRecorderTest, NmeaBytesBecomeFixesWithTheirReceptionTime) {
  // 48°07.038' N, 11°31.000' E; 2.0 knots = 1.028889 m/s; course 84.4; GGA quality 4.
  MapRecorder recorder = emptyRecorder();
  const std::string rmc =
      withChecksum("GPRMC,123519.00,A,4807.038,N,01131.000,E,2.0,84.4,140726,,,D");
  const std::string gga =
      withChecksum("GPGGA,123519.00,4807.038,N,01131.000,E,4,12,0.8,500.0,M,47.0,M,,");
  core::ReceptionStamp stamp;
  stamp.steady = at(5.0);
  recorder.feed(rmc + "\r\n" + gga.substr(0, 20), stamp);
  recorder.feed(gga.substr(20), stamp);  // the last line arrives without its end: flush takes it
  recorder.flush();
  auto mark = recorder.mark(at(5.25));
  ASSERT_TRUE(mark.ok()) << mark.error().message;
  EXPECT_NEAR(mark->location.latitude_deg, 48.1173, 1e-12);
  EXPECT_NEAR(mark->location.longitude_deg, 11.0 + 31.0 / 60.0, 1e-12);
  EXPECT_EQ(mark->location.heading_deg, std::optional<double>(84.4));
  EXPECT_EQ(mark->location.metadata,
            (std::vector<std::string>{"2026-07-14T12:35:19.000Z", "1.029", "4"}));
  EXPECT_EQ(mark->fix_age, 250ms);
}

// ---- the recording file ----------------------------------------------------------------------

std::string readAll(const std::filesystem::path& path) {
  std::string error;
  return core::readWholeFile(path, error).value_or("");
}

TEST(RecordingMapFileTest, ANewFileGetsTheHeader) {
  const ScopedTempDir dir("map_recorder_new");
  auto map = openRecordingMap(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_TRUE(map->empty());
  EXPECT_EQ(readAll(dir / "map.csv"), "id,lat,lon,heading,time,speed_mps,quality\n");
  // Opened again: continued, the header not repeated.
  ASSERT_TRUE(openRecordingMap(dir / "map.csv").ok());
  EXPECT_EQ(readAll(dir / "map.csv"), "id,lat,lon,heading,time,speed_mps,quality\n");
}

TEST(RecordingMapFileTest, AnExistingMapIsLoadedAndItsLastLineEnded) {
  const ScopedTempDir dir("map_recorder_existing");
  const std::string text =
      "# yesterday\nid,lat,lon,heading,time,speed_mps,quality\nP7,42,-93,10,,1.500,4";
  std::ofstream(dir / "map.csv", std::ios::binary) << text;
  auto map = openRecordingMap(dir / "map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  ASSERT_EQ(map->size(), 1u);
  EXPECT_EQ(map->locations()[0].id, "P7");
  EXPECT_EQ(readAll(dir / "map.csv"), text + "\n");
}

TEST(RecordingMapFileTest, AnotherKindOfMapIsRefusedUntouched) {
  const ScopedTempDir dir("map_recorder_other");
  const std::string other = "id,lat,lon,plot\nA,42,-93,1\n";
  std::ofstream(dir / "map.csv", std::ios::binary) << other;
  auto map = openRecordingMap(dir / "map.csv");
  ASSERT_FALSE(map.ok());
  EXPECT_EQ(map.error().message, (dir / "map.csv").string() +
                                     ": its header 'id,lat,lon,plot' is not the recording header "
                                     "'id,lat,lon,heading,time,speed_mps,quality'; give another "
                                     "--out");
  EXPECT_EQ(readAll(dir / "map.csv"), other);
}

}  // namespace
}  // namespace fieldrig::gps
