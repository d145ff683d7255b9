// fieldrigd end to end, through the real daemon process: a synthetic field (`fieldrig simulate`:
// serpentine drive NMEA, map, a session of rendered plots, truth; made once by the
// daemon_field CTest fixture) replayed in virtual time with the sim cameras replaying the
// rendered session. Every location is triggered once, every set recorded (naming its location,
// fix and trigger times) and processed, traits are held against the rendered truth, and a second
// run gives byte-identical results.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>

#include "fieldrig/recording/session_reader.h"
#include "support/cli_run.h"
#include "support/daemon_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

using testing_support::readWholeFile;
using testing_support::ScopedTempDir;
using Json = nlohmann::json;
namespace fs = std::filesystem;

TEST(DaemonReplay, EveryLocationTriggeredRecordedAndProcessedOnceCloseToTruthAndRepeatable) {
  const fs::path field = testing_support::daemonField();
  ASSERT_TRUE(fs::exists(field / "truth.jsonl")) << "the daemon_field fixture did not run";
  ScopedTempDir dir("daemon_replay");
  std::map<std::string, Json> truth;
  {
    std::ifstream in(field / "truth.jsonl");
    for (std::string line; std::getline(in, line);) {
      const Json j = Json::parse(line);
      truth[j.at("plot").get<std::string>()] = j;
    }
  }
  ASSERT_GE(truth.size(), 12U);

  std::string first_results;
  for (const char* name : {"run1", "run2"}) {
    SCOPED_TRACE(name);
    const fs::path config = testing_support::writeReplayConfig(dir.path(), name, field);
    const auto run =
        testing_support::runDaemon({"replay", "--config", config.string()}, dir.path());
    ASSERT_EQ(run.exit_code, 0) << run.err;
    ASSERT_EQ(run.out_lines.size(), truth.size() + 1) << run.err;  // plots, then the summary
    const Json summary = Json::parse(run.out_lines.back()).at("summary");
    EXPECT_EQ(summary.at("triggers"), truth.size());
    EXPECT_EQ(summary.at("sets_recorded"), truth.size());
    EXPECT_EQ(summary.at("sets_processed"), truth.size());
    EXPECT_EQ(summary.at("sets_skipped_for_processing"), 0);
    EXPECT_EQ(summary.at("sets_incomplete"), 0);
    EXPECT_EQ(summary.at("missed"), 0);

    // Every location of the map once, each plot close to the truth of its rendered plants.
    std::set<std::string> plots;
    double height_error_sum = 0;
    int heights_over_5cm = 0;
    for (std::size_t i = 0; i + 1 < run.out_lines.size(); ++i) {
      const Json line = Json::parse(run.out_lines[i]);
      const std::string plot = line.at("location").get<std::string>();
      SCOPED_TRACE(plot + ": " + line.dump());
      EXPECT_TRUE(plots.insert(plot).second) << "triggered twice";
      ASSERT_TRUE(truth.count(plot));
      // The first plot of the drive can be noticed just after its crossing (flagged late).
      EXPECT_NE(line.at("trigger_status"), "");
      EXPECT_FALSE(line.at("partial").get<bool>());
      const Json& traits = line.at("traits");
      ASSERT_EQ(traits.at("status"), "ok");
      // Height through stereo, measured on this field: -4.7 to -1.8 cm on 10 plots, +2.6 cm on
      // one, and +10.5 cm on R01P06, a plot with one abnormally tall plant (mean |error| 3.2 cm;
      // the ground registration fell back to the data pose on every plot). Issue 11 is to bring
      // every plot within 3 cm. Held here: every plot within 12 cm, all but one within 5 cm (the
      // tolerance of tests/tools/process_cli_test.cpp), the mean within 4 cm. Width through
      // stereo is issue 18's and not held against truth here.
      const double height_error = std::abs(traits.at("height_m").get<double>() -
                                           truth.at(plot).at("height_m").get<double>());
      EXPECT_LT(height_error, 0.12);
      height_error_sum += height_error;
      heights_over_5cm += height_error > 0.05 ? 1 : 0;
      EXPECT_GT(traits.at("width_m").get<double>(), 0.3);
    }
    EXPECT_EQ(plots.size(), truth.size());
    EXPECT_LT(height_error_sum / static_cast<double>(truth.size()), 0.04);
    EXPECT_LE(heights_over_5cm, 1);

    // The recording: whole, and every set names its location, fix and trigger times.
    const fs::path session = dir.path() / name / "session";
    const auto verify =
        testing_support::runFieldrig({"session", "info", session.string(), "--verify"}, dir.path());
    EXPECT_EQ(verify.exit_code, 0) << verify.err;
    const auto reader = recording::SessionReader::open(session);
    ASSERT_TRUE(reader.ok()) << reader.error().message;
    ASSERT_EQ(reader->sets().size(), truth.size());
    for (const recording::IndexedSet& set : reader->sets()) {
      ASSERT_TRUE(set.location_id.has_value());
      EXPECT_TRUE(truth.count(*set.location_id));
      ASSERT_TRUE(set.fix.has_value()) << *set.location_id;
      EXPECT_TRUE(set.fix->valid);
      EXPECT_LT(set.fix->time, set.trigger_time);  // causal: planned on an earlier fix
      ASSERT_TRUE(set.planned_time.has_value());
      EXPECT_TRUE(set.sent_time.has_value());
      EXPECT_TRUE(set.complete);
    }

    const std::string results = readWholeFile(session / "results" / "plots.jsonl");
    const std::string csv = readWholeFile(session / "results" / "plots.csv");
    EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), static_cast<long>(truth.size() + 1));
    const Json geojson = Json::parse(readWholeFile(session / "results" / "plots.geojson"));
    EXPECT_EQ(geojson.at("features").size(), truth.size());
    if (first_results.empty()) {
      first_results = results;
      // Live and offline are one processor: `fieldrig process` on the recording gives the traits
      // the daemon gave while recording it.
      const fs::path offline = dir.path() / "offline";
      const auto processed =
          testing_support::runFieldrig({"process", session.string(), "--out", offline.string(),
                                        "--map", (field / "map.csv").string()},
                                       dir.path());
      ASSERT_EQ(processed.exit_code, 0) << processed.err;
      std::map<std::uint64_t, Json> live;
      for (std::size_t i = 0; i + 1 < run.out_lines.size(); ++i) {
        const Json line = Json::parse(run.out_lines[i]);
        live[line.at("trigger_id").get<std::uint64_t>()] = line;
      }
      ASSERT_EQ(processed.out_lines.size(), truth.size() + 1);
      for (std::size_t i = 0; i + 1 < processed.out_lines.size(); ++i) {
        const Json line = Json::parse(processed.out_lines[i]);
        const Json& daemon_line = live.at(line.at("trigger_id").get<std::uint64_t>());
        EXPECT_EQ(line.at("location"), daemon_line.at("location"));
        EXPECT_EQ(line.at("traits"), daemon_line.at("traits"));
        EXPECT_EQ(line.at("lat"), daemon_line.at("lat"));
      }
    } else {
      EXPECT_EQ(results, first_results) << "the same inputs gave different results";
    }
  }
}

TEST(DaemonReplay, CheckConfigValidatesWithoutStarting) {
  const fs::path field = testing_support::daemonField();
  ScopedTempDir dir("daemon_check");
  const fs::path config = testing_support::writeReplayConfig(dir.path(), "run", field);
  const auto ok = testing_support::runDaemon({"--check-config", config.string()}, dir.path());
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
  EXPECT_FALSE(fs::exists(dir.path() / "run" / "session")) << "--check-config wrote a session";
}

}  // namespace
}  // namespace fieldrig
