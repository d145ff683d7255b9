// `fieldrig triggers --map MAP.csv --nmea FILE`: the CLI contract on a simulated drive whose
// truth is known, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/nmea_parser.h"
#include "fieldrig/sim/drive_simulator.h"
#include "fieldrig/sim/trigger_accuracy.h"
#include "support/cli_run.h"
#include "support/field_plans.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;
using testing_support::runFieldrig;

class TriggersCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto map = gps::generateLocations(plan_);
    ASSERT_TRUE(map.ok()) << map.error().message;
    map_ = *map;
    ASSERT_TRUE(map_.save(dir_ / "map.csv").ok());
  }
  void write(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
  }

  const testing_support::ScopedTempDir temp_{"triggers_cli"};
  const fs::path dir_ = temp_.path();
  // Four rows of about 35 m, north-north-east.
  const gps::FieldPlan plan_ =
      testing_support::fieldPlan({41.99, -93.64}, {41.9903, -93.6399}, 4, 3.0, 0.5);
  gps::LocationMap map_;
};

TEST_F(TriggersCliTest, PrintsOneJsonLinePerTriggerWithLocationAndIsoTime) {
  const sim::DriveSimulator drive(plan_, sim::DriveOptions{});
  write(dir_ / "drive.nmea", drive.nmea());
  const auto run = runFieldrig(
      {"triggers", "--map", (dir_ / "map.csv").string(), "--nmea", (dir_ / "drive.nmea").string()},
      dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), map_.size());
  std::vector<core::TriggerEvent> events;
  core::UtcTime previous{};
  for (const std::string& text : run.out_lines) {
    const Json line = Json::parse(text);
    ASSERT_TRUE(line.contains("location"));
    ASSERT_TRUE(line.contains("time"));
    const std::string time = line["time"];
    // ISO-8601 UTC with at least millisecond precision.
    ASSERT_GE(time.size(), std::string("2026-07-14T15:30:00.000Z").size()) << time;
    const auto parsed = core::parseIso8601(time);
    ASSERT_TRUE(parsed) << time;
    EXPECT_GE(*parsed, previous) << "triggers in time order";
    previous = *parsed;
    const auto last_fix = core::parseIso8601(line["last_fix_time"].get<std::string>());
    ASSERT_TRUE(last_fix);
    EXPECT_LT(*last_fix, *parsed) << "causal: the trigger rests on earlier fixes";
    core::TriggerEvent event;
    event.location_id = line["location"];
    event.time = *parsed;
    events.push_back(event);
  }
  const sim::TriggerAccuracy accuracy = sim::scoreTriggers(drive, map_, events);
  EXPECT_EQ(accuracy.fired_once, map_.size());
  EXPECT_LT(accuracy.max_abs_m, 0.04);
  // The summary goes to stderr, stdout holds triggers only.
  ASSERT_FALSE(run.err_lines.empty());
  const Json summary = Json::parse(run.err_lines.back());
  EXPECT_EQ(summary["summary"]["triggers"], map_.size());
  EXPECT_EQ(summary["summary"]["missed"], 0);
}

// A drive breathing ±15 % replayed with ±10 ms of latency jitter, by both motion models: every
// location once, causal, and each trigger says its own uncertainty.
TEST_F(TriggersCliTest, JitteredReplayOfABreathingDriveWithEitherMotionModel) {
  sim::DriveOptions options;
  options.speed_slow_amplitude = 0.15;
  options.speed_fast_amplitude = 0.05;
  options.velocity_noise_mps = 0.02;
  const sim::DriveSimulator drive(plan_, options);
  write(dir_ / "drive.nmea", drive.nmea());
  for (const char* model : {"kalman", "constant_velocity_fit"}) {
    const auto run = runFieldrig(
        {"triggers", "--map", (dir_ / "map.csv").string(), "--nmea", (dir_ / "drive.nmea").string(),
         "--latency-jitter", "0.01", "--motion-model", model},
        dir_);
    ASSERT_EQ(run.exit_code, 0) << model << ": " << run.err;
    ASSERT_EQ(run.out_lines.size(), map_.size()) << model;
    for (const std::string& text : run.out_lines) {
      const Json line = Json::parse(text);
      const auto time = core::parseIso8601(line["time"].get<std::string>());
      const auto last_fix = core::parseIso8601(line["last_fix_time"].get<std::string>());
      ASSERT_TRUE(time && last_fix);
      EXPECT_LT(*last_fix, *time) << model;
      EXPECT_GT(line["along_track_sigma_m"].get<double>(), 0.0) << model;
      EXPECT_GT(line["timing_sigma_s"].get<double>(), 0.0) << model;
    }
  }
}

TEST_F(TriggersCliTest, BadJitterAndMotionModelAreErrorsNamingTheOption) {
  const sim::DriveSimulator drive(plan_, sim::DriveOptions{});
  write(dir_ / "drive.nmea", drive.nmea());
  const std::vector<std::string> base = {"triggers", "--map", (dir_ / "map.csv").string(), "--nmea",
                                         (dir_ / "drive.nmea").string()};
  const struct {
    std::vector<std::string> extra;
    std::string named;
  } cases[] = {
      {{"--latency-jitter", "nan"}, "--latency-jitter"},
      {{"--latency-jitter", "-0.01"}, "--latency-jitter"},
      // Within the option's own range but more than the latency itself.
      {{"--latency", "0.02", "--latency-jitter", "0.03"}, "latency_jitter_s"},
      {{"--motion-model", "magic"}, "--motion-model"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> args = base;
    args.insert(args.end(), c.extra.begin(), c.extra.end());
    const auto run = runFieldrig(args, dir_);
    EXPECT_NE(run.exit_code, 0) << c.extra.back();
    EXPECT_NE(run.err.find(c.named), std::string::npos) << run.err;
    EXPECT_TRUE(run.out_lines.empty()) << c.extra.back();
  }
}

TEST_F(TriggersCliTest, InvalidFixesYieldNoTriggers) {
  sim::DriveOptions options;
  const sim::DriveSimulator drive(plan_, options);
  // Status V in every RMC and quality 0 in every GGA: the receiver has no fix.
  std::string nmea;
  for (const std::string& line : testing_support::splitLines(drive.nmea())) {
    std::string body = line.substr(1, line.find('*') - 1);
    if (body.find("RMC,") != std::string::npos) {
      body.replace(body.find(",A,"), 3, ",V,");
    } else {
      body.replace(body.find(",4,14,"), 6, ",0,14,");
    }
    nmea += gps::withChecksum(body) + "\r\n";
  }
  write(dir_ / "nofix.nmea", nmea);
  const auto run = runFieldrig(
      {"triggers", "--map", (dir_ / "map.csv").string(), "--nmea", (dir_ / "nofix.nmea").string()},
      dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_TRUE(run.out_lines.empty());
  const Json summary = Json::parse(run.err_lines.back());
  EXPECT_GT(summary["summary"]["fixes_invalid"].get<int>(), 100);
}

TEST_F(TriggersCliTest, CorruptSentencesAreSkippedAndCounted) {
  const sim::DriveSimulator drive(plan_, sim::DriveOptions{});
  std::string nmea;
  int n = 0;
  for (const std::string& line : testing_support::splitLines(drive.nmea())) {
    std::string corrupted = line;
    // Every 7th sentence gets a flipped digit: its checksum no longer matches.
    if (++n % 7 == 0)
      corrupted[20] = corrupted[20] == '1' ? '2' : '1';
    nmea += corrupted + "\n";
  }
  write(dir_ / "corrupt.nmea", nmea);
  const auto run = runFieldrig({"triggers", "--map", (dir_ / "map.csv").string(), "--nmea",
                                (dir_ / "corrupt.nmea").string()},
                               dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.out_lines.size(), map_.size());
  const Json summary = Json::parse(run.err_lines.back());
  EXPECT_EQ(summary["summary"]["rejected_lines"].get<int>(), n / 7);
}

TEST_F(TriggersCliTest, BadMapIsAnErrorNamingFileAndLine) {
  write(dir_ / "bad.csv", "id,lat,lon\nA,41.99,-93.64\nB,north,-93.64\n");
  write(dir_ / "empty.nmea", "");
  const auto run = runFieldrig(
      {"triggers", "--map", (dir_ / "bad.csv").string(), "--nmea", (dir_ / "empty.nmea").string()},
      dir_);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("bad.csv:3"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("lat"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out_lines.empty());
}

TEST_F(TriggersCliTest, MissingNmeaFileIsAnErrorNamingIt) {
  const auto run = runFieldrig({"triggers", "--map", (dir_ / "map.csv").string(), "--nmea",
                                (dir_ / "nowhere.nmea").string()},
                               dir_);
  EXPECT_NE(run.exit_code, 0);
  EXPECT_NE(run.err.find("nowhere.nmea"), std::string::npos) << run.err;
}

// A character device that is no serial port was opened again and again until killed.
TEST_F(TriggersCliTest, ADeviceThatIsNoSerialPortIsAnErrorNamingIt) {
  const auto run =
      runFieldrig({"triggers", "--map", (dir_ / "map.csv").string(), "--nmea", "/dev/null"}, dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("/dev/null: a character device but not a serial port"), std::string::npos)
      << run.err;
}

}  // namespace
}  // namespace fieldrig
