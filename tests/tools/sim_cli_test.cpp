// `fieldrig sim drive`: reproduces the bundled demo data, and refuses bad plans.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "fieldrig/gps/location_map.h"
#include "support/cli_run.h"
#include "support/field_plans.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using testing_support::readWholeFile;
using testing_support::runFieldrig;
using testing_support::withFieldPlan;

class SimCliTest : public ::testing::Test {
 protected:
  const testing_support::ScopedTempDir temp_{"sim_cli"};
  const fs::path dir_ = temp_.path();
};

TEST_F(SimCliTest, ReproducesTheBundledDemoData) {
  const fs::path demo = fs::path(FIELDRIG_SOURCE_DIR) / "sim" / "data";
  // Eight rows of about 67 m north, 3 m plots from 1 m after the row start: sim/data's field.
  const gps::FieldPlan demo_plan =
      testing_support::fieldPlan({42.0106, -93.7385}, {42.0112, -93.7385}, 8, 3.0, 1.0);
  const auto run = runFieldrig(
      withFieldPlan(
          {"sim", "drive"}, demo_plan,
          {"--speed", "2", "--seed", "2026", "--start", "2026-07-14T15:30:00Z", "--out-nmea",
           (dir_ / "drive.nmea").string(), "--out-map", (dir_ / "map.csv").string()}),
      dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(readWholeFile(dir_ / "drive.nmea"), readWholeFile(demo / "demo_drive.nmea"));
  EXPECT_EQ(readWholeFile(dir_ / "map.csv"), readWholeFile(demo / "demo_map.csv"));
  const auto summary = nlohmann::json::parse(run.out_lines.at(0));
  EXPECT_EQ(summary["locations"], 128);
  const auto map = gps::LocationMap::load(demo / "demo_map.csv");
  ASSERT_TRUE(map.ok()) << map.error().message;
  EXPECT_EQ(map->size(), 128u);
}

TEST_F(SimCliTest, BadRowEndIsAnErrorNamingTheOption) {
  const auto run = runFieldrig(
      {"sim", "drive", "--row-start", "42.0106,-93.7385", "--row-end", "42.0112;-93.7385", "--rows",
       "2", "--plot-length", "3", "--alley-length", "1", "--row-spacing", "2.286", "--out-nmea",
       (dir_ / "drive.nmea").string(), "--out-map", (dir_ / "map.csv").string()},
      dir_);
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("--row-end"), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(dir_ / "drive.nmea"));
}

// `sim drive` writes its two files once at the end: an output it cannot write is bad input (exit
// 2, as `map generate`), named, and neither file is left behind.
TEST_F(SimCliTest, AnOutputThatCannotBeWrittenIsBadInputNamingIt) {
  const fs::path unwritable = dir_ / "no-such-folder" / "map.csv";
  const auto run = runFieldrig(
      {"sim", "drive", "--row-start", "42.0106,-93.7385", "--row-end", "42.0112,-93.7385", "--rows",
       "2", "--plot-length", "3", "--alley-length", "1", "--row-spacing", "2.286", "--out-nmea",
       (dir_ / "drive.nmea").string(), "--out-map", unwritable.string()},
      dir_);
  EXPECT_EQ(run.exit_code, 2) << run.err;
  EXPECT_NE(run.err.find(unwritable.string()), std::string::npos) << run.err;
  EXPECT_FALSE(fs::exists(unwritable.parent_path()));
  EXPECT_FALSE(fs::exists(dir_ / "drive.nmea")) << "a drive was left without its map";

  // A folder as the map, or one file for both: refused before anything is written (the drive
  // was written beside no map, or the map overwrote it).
  fs::create_directories(dir_ / "a-folder");
  const std::vector<std::pair<std::string, std::string>> outputs = {
      {(dir_ / "drive.nmea").string(), (dir_ / "a-folder").string()},
      {(dir_ / "both").string(), (dir_ / "." / "both").string()}};
  for (const auto& [nmea, map] : outputs) {
    const auto refused =
        runFieldrig({"sim", "drive", "--row-start", "42.0106,-93.7385", "--row-end",
                     "42.0112,-93.7385", "--rows", "2", "--plot-length", "3", "--alley-length", "1",
                     "--row-spacing", "2.286", "--out-nmea", nmea, "--out-map", map},
                    dir_);
    EXPECT_EQ(refused.exit_code, 2) << map << "\n" << refused.err;
    EXPECT_NE(refused.err.find(map), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(dir_ / "drive.nmea")) << map;
    EXPECT_FALSE(fs::exists(dir_ / "both")) << map;
  }
}

// The speed profile, correlated noise and velocity noise reach the NMEA: RMC speeds breathe
// around the mean.
TEST_F(SimCliTest, BreathingDriveReportsTheChangingSpeed) {
  const gps::FieldPlan plan =
      testing_support::fieldPlan({42.0106, -93.7385}, {42.0112, -93.7385}, 2, 3.0, 1.0);
  const auto run = runFieldrig(withFieldPlan({"sim", "drive"}, plan,
                                             {"--speed",
                                              "2",
                                              "--speed-slow-amplitude",
                                              "0.15",
                                              "--speed-slow-period",
                                              "18",
                                              "--speed-fast-amplitude",
                                              "0.05",
                                              "--speed-fast-period",
                                              "5",
                                              "--correlated-noise",
                                              "0.01",
                                              "--correlated-noise-tau",
                                              "10",
                                              "--velocity-noise",
                                              "0.02",
                                              "--out-nmea",
                                              (dir_ / "drive.nmea").string(),
                                              "--out-map",
                                              (dir_ / "map.csv").string()}),
                               dir_);
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string nmea = readWholeFile(dir_ / "drive.nmea");
  double slowest = 1e9, fastest = 0;
  for (std::size_t at = nmea.find("RMC,"); at != std::string::npos;
       at = nmea.find("RMC,", at + 1)) {
    // $GNRMC,time,A,lat,N,lon,W,knots,...: the speed is the 7th field after "RMC".
    std::size_t field = at;
    for (int i = 0; i < 7; ++i)
      field = nmea.find(',', field) + 1;
    const double mps = std::stod(nmea.substr(field)) * 1852.0 / 3600.0;
    slowest = std::min(slowest, mps);
    fastest = std::max(fastest, mps);
  }
  EXPECT_LT(slowest, 1.85);
  EXPECT_GT(fastest, 2.15);
  EXPECT_GT(slowest, 1.5);
  EXPECT_LT(fastest, 2.5);
}

TEST_F(SimCliTest, BadDriveOptionsAreErrorsNamingTheOption) {
  const gps::FieldPlan plan =
      testing_support::fieldPlan({42.0106, -93.7385}, {42.0112, -93.7385}, 2, 3.0, 1.0);
  const struct {
    std::string option, value;
  } cases[] = {
      {"--speed-slow-amplitude", "0.7"}, {"--speed-fast-amplitude", "-0.1"},
      {"--speed-slow-period", "nan"},    {"--speed-fast-period", "0"},
      {"--correlated-noise", "inf"},     {"--correlated-noise-tau", "0"},
      {"--velocity-noise", "-1"},
  };
  for (const auto& c : cases) {
    const auto run =
        runFieldrig(withFieldPlan({"sim", "drive"}, plan,
                                  {c.option, c.value, "--out-nmea", (dir_ / "drive.nmea").string(),
                                   "--out-map", (dir_ / "map.csv").string()}),
                    dir_);
    EXPECT_EQ(run.exit_code, 2) << c.option << " " << c.value;
    EXPECT_NE(run.err.find(c.option), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(dir_ / "drive.nmea")) << c.option;
  }
}

}  // namespace
}  // namespace fieldrig
