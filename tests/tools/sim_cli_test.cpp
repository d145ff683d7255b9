// `fieldrig sim drive`: reproduces the bundled demo data, and refuses bad plans.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "fieldrig/gps/location_map.h"
#include "support/cli_run.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using testing_support::readWholeFile;
using testing_support::runFieldrig;

class SimCliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(::testing::TempDir()) / ("sim_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

TEST_F(SimCliTest, ReproducesTheBundledDemoData) {
  const fs::path demo = fs::path(FIELDRIG_SOURCE_DIR) / "sim" / "data";
  const auto run = runFieldrig({"sim",
                                "drive",
                                "--row-start",
                                "42.0106,-93.7385",
                                "--row-end",
                                "42.0112,-93.7385",
                                "--rows",
                                "8",
                                "--plot-length",
                                "3",
                                "--alley-length",
                                "1",
                                "--row-spacing",
                                "2.286",
                                "--start-offset",
                                "1",
                                "--speed",
                                "2",
                                "--seed",
                                "2026",
                                "--start",
                                "2026-07-14T15:30:00Z",
                                "--out-nmea",
                                (dir_ / "drive.nmea").string(),
                                "--out-map",
                                (dir_ / "map.csv").string()},
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

}  // namespace
}  // namespace fieldrig
