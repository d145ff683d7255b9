// The whole pipeline end to end through the CLI: `fieldrig sim plots` records a session of
// synthetic plots as the rig would (six raw Bayer frames per plot, with calibration and truth);
// `fieldrig process` turns it into per-plot traits, CSV and GeoJSON, which are held against the
// truth of the rendered geometry.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

using testing_support::readWholeFile;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;
using Json = nlohmann::json;
namespace fs = std::filesystem;

std::map<std::string, Json> readTruth(const fs::path& file) {
  std::map<std::string, Json> truth;
  std::ifstream in(file);
  for (std::string line; std::getline(in, line);) {
    const Json j = Json::parse(line);
    truth[j.at("plot").get<std::string>()] = j;
  }
  return truth;
}

// `fieldrig sim plots --out SESSION --count N`: whether it succeeded.
::testing::AssertionResult recordPlots(const ScopedTempDir& dir, const fs::path& session,
                                       int count) {
  const auto made = runFieldrig(
      {"sim", "plots", "--out", session.string(), "--count", std::to_string(count)}, dir.path());
  if (made.exit_code == 0)
    return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "sim plots: exit " << made.exit_code << ": " << made.err;
}

TEST(ProcessCli, SyntheticSessionGivesTraitsCloseToTruth) {
  ScopedTempDir dir("process_cli_truth");
  const fs::path session = dir.path() / "session";
  const auto made = runFieldrig({"sim", "plots", "--out", session.string(), "--count", "3",
                                 "--height-min", "1.3", "--height-max", "2.3"},
                                dir.path());
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const auto truth = readTruth(session / "truth.jsonl");
  ASSERT_EQ(truth.size(), 3U);

  const auto run = runFieldrig({"process", session.string()}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 4U) << run.err;  // three plots and the summary
  for (int i = 0; i < 3; ++i) {
    const Json line = Json::parse(run.out_lines[static_cast<std::size_t>(i)]);
    const std::string plot = line.at("location").get<std::string>();
    SCOPED_TRACE(plot + ": " + line.dump());
    EXPECT_FALSE(line.at("partial").get<bool>());
    // How much each head measured: full-width matching leaves at most the columns whose match
    // lies outside the right image (the nearest leaves: ~100 of 812) and the backdrop's edges.
    ASSERT_EQ(line.at("heads").size(), 3U);
    for (const Json& head : line.at("heads")) {
      EXPECT_TRUE(head.at("ok").get<bool>());
      EXPECT_GT(head.at("matched_column_fraction").get<double>(), 0.9);
      EXPECT_LE(head.at("matched_column_fraction").get<double>(), 1.0);
      EXPECT_GT(head.at("valid_pixel_fraction").get<double>(), 0.3);
      EXPECT_LE(head.at("valid_pixel_fraction").get<double>(),
                head.at("matched_column_fraction").get<double>());
    }
    const Json& traits = line.at("traits");
    ASSERT_EQ(traits.at("status"), "ok");
    const Json& expected = truth.at(plot);
    // Height through stereo: measured 1.4–4.1 cm low on these plots, most on the tallest (thin
    // leaf tips at the top head's edge of view are lost at 812×612); the 3 cm of the traits issue
    // holds on clouds without stereo (tests/pipeline/traits), not yet through it.
    EXPECT_NEAR(traits.at("height_m").get<double>(), expected.at("height_m").get<double>(), 0.05);
    // Width is not held against truth here: SGBM fills the small gaps between leaves, through
    // which the far backdrop shows, with disparities between the two, and those points (1.5–1.7 m
    // deep, inside the crop) raise the per-slice maxima: measured widths are 2–12 cm wide and
    // 9 cm narrow of the truth on these plots (closing note of issue 4). On the rendered
    // geometry itself, without stereo, the traits tests hold width within 3 cm.
    EXPECT_GT(traits.at("width_m").get<double>(), 0.3);
    EXPECT_GT(traits.at("vvi").get<double>(), 0.0);
  }
  const Json summary = Json::parse(run.out_lines.back()).at("summary");
  EXPECT_EQ(summary.at("sets"), 3);
  EXPECT_EQ(summary.at("ok"), 3);

  const Json geojson = Json::parse(readWholeFile(session / "results" / "plots.geojson"));
  ASSERT_EQ(geojson.at("features").size(), 3U);
  const Json& first = geojson.at("features").at(0);
  EXPECT_EQ(first.at("geometry").at("type"), "Point");
  EXPECT_NEAR(first.at("geometry").at("coordinates").at(0).get<double>(), -93.6, 1e-9);  // lon
  EXPECT_NEAR(first.at("geometry").at("coordinates").at(1).get<double>(), 42.0, 1e-9);   // lat
  const std::string csv = readWholeFile(session / "results" / "plots.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 4) << csv;  // header + three plots
}

TEST(ProcessCli, AMissingCameraGivesAFlaggedPartialPlotNotAFailure) {
  ScopedTempDir dir("process_cli_missing");
  const fs::path session = dir.path() / "session";
  ASSERT_TRUE(recordPlots(dir, session, 1));
  // The top head's right frame is lost (as a crash or a full disk would lose it).
  int removed = 0;
  for (const auto& entry : fs::directory_iterator(session / "frames")) {
    if (entry.path().filename().string().find("top_right") != std::string::npos) {
      fs::remove(entry.path());
      ++removed;
    }
  }
  ASSERT_EQ(removed, 1);
  const auto run = runFieldrig({"process", session.string()}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const Json line = Json::parse(run.out_lines.at(0));
  EXPECT_TRUE(line.at("partial").get<bool>());
  bool names_the_file = false;
  for (const Json& problem : line.at("problems")) {
    names_the_file |= problem.get<std::string>().find("top_right") != std::string::npos;
  }
  EXPECT_TRUE(names_the_file) << line.dump();
  EXPECT_EQ(line.at("traits").at("status"), "ok") << "two heads still see the plot's base";
  const Json& top = line.at("heads").at(2);
  EXPECT_EQ(top.at("name"), "top");
  EXPECT_FALSE(top.at("ok").get<bool>());
  EXPECT_EQ(top.at("matched_column_fraction").get<double>(), 0.0);
}

TEST(ProcessCli, ResumesSkipsWhatIsDoneRedoesWithForceAndSplitsIntoShards) {
  ScopedTempDir dir("process_cli_resume");
  const fs::path session = dir.path() / "session";
  ASSERT_TRUE(recordPlots(dir, session, 3));
  const auto first = runFieldrig({"process", session.string()}, dir.path());
  ASSERT_EQ(first.exit_code, 0) << first.err;
  const std::string results = readWholeFile(session / "results" / "plots.jsonl");
  // Again: every set is already in the results, nothing is processed, nothing changes.
  const auto again = runFieldrig({"process", session.string()}, dir.path());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  ASSERT_EQ(again.out_lines.size(), 1U);
  const Json resumed = Json::parse(again.out_lines.back()).at("summary");
  EXPECT_EQ(resumed.at("sets"), 0);
  EXPECT_EQ(resumed.at("already_done"), 3);
  EXPECT_EQ(resumed.at("plots_in_results"), 3);
  EXPECT_EQ(readWholeFile(session / "results" / "plots.jsonl"), results);
  // A run cut short leaves a torn last line: the plot is done again, the others are kept.
  const std::string torn = results.substr(0, results.size() - 40);
  std::ofstream(session / "results" / "plots.jsonl", std::ios::trunc) << torn;
  const auto after_crash = runFieldrig({"process", session.string()}, dir.path());
  ASSERT_EQ(after_crash.exit_code, 0) << after_crash.err;
  EXPECT_EQ(Json::parse(after_crash.out_lines.back()).at("summary").at("sets"), 1);
  EXPECT_EQ(readWholeFile(session / "results" / "plots.jsonl"), results);
  // --force processes every set again, into fresh files.
  const auto forced = runFieldrig({"process", session.string(), "--force"}, dir.path());
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_EQ(Json::parse(forced.out_lines.back()).at("summary").at("sets"), 3);
  EXPECT_EQ(readWholeFile(session / "results" / "plots.jsonl"), results);
  // Two shards: separate folders, every set in exactly one of them.
  std::set<std::uint64_t> sets;
  for (const char* shard : {"0/2", "1/2"}) {
    const auto part = runFieldrig({"process", session.string(), "--shard", shard}, dir.path());
    ASSERT_EQ(part.exit_code, 0) << part.err;
    for (std::size_t i = 0; i + 1 < part.out_lines.size(); ++i)
      EXPECT_TRUE(
          sets.insert(Json::parse(part.out_lines[i]).at("set").get<std::uint64_t>()).second);
  }
  EXPECT_EQ(sets, (std::set<std::uint64_t>{0, 1, 2}));
  EXPECT_TRUE(fs::exists(session / "results" / "shard-0-of-2" / "plots.jsonl"));
  EXPECT_TRUE(fs::exists(session / "results" / "shard-1-of-2" / "plots.jsonl"));
  // Results of another session in --out (here: a trigger at another time) are refused before
  // anything is processed; resuming into them would skip those sets unseen.
  const fs::path other = dir.path() / "other-results";
  fs::create_directories(other);
  {
    std::istringstream lines(results);
    std::ofstream out(other / "plots.jsonl");
    std::string text;
    std::getline(lines, text);
    Json changed = Json::parse(text);
    changed["time"] = "2001-01-01T00:00:00.000000Z";
    out << changed.dump() << '\n';
  }
  const std::string other_before = readWholeFile(other / "plots.jsonl");
  const auto mixed =
      runFieldrig({"process", session.string(), "--out", other.string()}, dir.path());
  EXPECT_EQ(mixed.exit_code, 2) << mixed.err;
  EXPECT_NE(mixed.err.find((other / "plots.jsonl").string() + ": trigger "), std::string::npos)
      << mixed.err;
  EXPECT_NE(mixed.err.find("results of another session"), std::string::npos) << mixed.err;
  EXPECT_TRUE(mixed.out_lines.empty());
  EXPECT_EQ(readWholeFile(other / "plots.jsonl"), other_before);
  const auto bad = runFieldrig({"process", session.string(), "--shard", "2/2"}, dir.path());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--shard"), std::string::npos) << bad.err;
}

// Two sessions of `sim plots` have the same plot ids and trigger times, which the trigger check
// cannot tell apart: the results folder names the session it is of (source.json), so results of
// the other are refused rather than every set skipped as already done.
TEST(ProcessCli, ResultsOfAnotherSessionWithTheSameTriggersAreRefused) {
  ScopedTempDir dir("process_cli_source");
  const fs::path first = dir.path() / "first";
  const fs::path second = dir.path() / "second";
  ASSERT_TRUE(recordPlots(dir, first, 1));
  ASSERT_TRUE(recordPlots(dir, second, 1));
  ASSERT_EQ(readWholeFile(first / "index.jsonl"), readWholeFile(second / "index.jsonl"));
  const fs::path out = dir.path() / "results";
  const auto made = runFieldrig({"process", first.string(), "--out", out.string()}, dir.path());
  ASSERT_EQ(made.exit_code, 0) << made.err;
  const Json source = Json::parse(readWholeFile(out / "source.json"));
  EXPECT_EQ(source.at("session"), fs::absolute(first).string());
  const std::string before = readWholeFile(out / "plots.jsonl");

  const auto again = runFieldrig({"process", first.string(), "--out", out.string()}, dir.path());
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_EQ(Json::parse(again.out_lines.back()).at("summary").at("already_done"), 1);
  const auto other = runFieldrig({"process", second.string(), "--out", out.string()}, dir.path());
  EXPECT_EQ(other.exit_code, 2) << other.err;
  EXPECT_NE(other.err.find((out / "source.json").string() +
                           ": the results are of the session "
                           "started at " +
                           source.at("start_time").get<std::string>() + " (" +
                           fs::absolute(first).string() + "), but " + second.string()),
            std::string::npos)
      << other.err;
  EXPECT_TRUE(other.out_lines.empty());
  EXPECT_EQ(readWholeFile(out / "plots.jsonl"), before);
  const auto forced =
      runFieldrig({"process", second.string(), "--out", out.string(), "--force"}, dir.path());
  ASSERT_EQ(forced.exit_code, 0) << forced.err;
  EXPECT_EQ(Json::parse(readWholeFile(out / "source.json")).at("session"),
            fs::absolute(second).string());
}

// A set whose index line a crash cut short is not in the session: the run says so, naming the
// line, instead of the set vanishing from the results unremarked.
TEST(ProcessCli, ATornLastIndexLineIsNamed) {
  ScopedTempDir dir("process_cli_torn_index");
  const fs::path session = dir.path() / "session";
  ASSERT_TRUE(recordPlots(dir, session, 2));
  fs::resize_file(session / "index.jsonl", fs::file_size(session / "index.jsonl") - 50);
  const auto run = runFieldrig({"process", session.string()}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find((session / "index.jsonl").string() + ":2: a torn last line"),
            std::string::npos)
      << run.err;
  const Json summary = Json::parse(run.out_lines.back()).at("summary");
  EXPECT_EQ(summary.at("sets"), 1);
  EXPECT_EQ(summary.at("torn_index_line"), 2);
}

// A map of another field (none of the session's locations, or all of them elsewhere) is refused
// before anything is written; a map that lacks or misplaces only some locations is used, and
// those plots' lines say so.
TEST(ProcessCli, AMapOfAnotherFieldIsRefusedAndAPlotItMisplacesIsSaid) {
  ScopedTempDir dir("process_cli_map");
  const fs::path session = dir.path() / "session";
  ASSERT_TRUE(recordPlots(dir, session, 3));
  std::map<std::string, std::pair<double, double>> fixes;  // where each plot was taken
  {
    std::ifstream index(session / "index.jsonl");
    for (std::string text; std::getline(index, text);) {
      const Json set = Json::parse(text);
      fixes[set.at("location_id").get<std::string>()] = {set.at("gps").at("lat").get<double>(),
                                                         set.at("gps").at("lon").get<double>()};
    }
  }
  ASSERT_EQ(fixes.size(), 3U);
  // A map row for `plot` at its fix moved `north_deg` degrees of latitude.
  auto row = [&](const std::string& id, const std::string& plot, double north_deg) {
    std::ostringstream out;
    out.precision(12);
    out << id << ',' << fixes.at(plot).first + north_deg << ',' << fixes.at(plot).second << ",0\n";
    return out.str();
  };
  auto writeMap = [&](const std::string& name, const std::string& rows) {
    const fs::path map = dir.path() / name;
    std::ofstream(map) << "id,lat,lon,heading\n" << rows;
    return map;
  };
  auto process = [&](const fs::path& map) {
    return runFieldrig({"process", session.string(), "--map", map.string(), "--out",
                        (dir.path() / ("results-" + map.stem().string())).string()},
                       dir.path());
  };
  const fs::path other_ids =
      writeMap("other-ids.csv", row("R1P1", "plot-1", 0) + row("R1P2", "plot-2", 0));
  const auto none = process(other_ids);
  EXPECT_EQ(none.exit_code, 2) << none.err;
  EXPECT_NE(none.err.find(other_ids.string() + ": holds none of the session's locations"),
            std::string::npos)
      << none.err;
  const fs::path elsewhere =
      writeMap("elsewhere.csv", row("plot-1", "plot-1", 0.5) + row("plot-2", "plot-2", 0.5) +
                                    row("plot-3", "plot-3", 0.5));
  const auto far = process(elsewhere);
  EXPECT_EQ(far.exit_code, 2) << far.err;
  EXPECT_NE(
      far.err.find(elsewhere.string() + ": every location of the session lies more than 10 m"),
      std::string::npos)
      << far.err;
  EXPECT_TRUE(none.out_lines.empty() && far.out_lines.empty());
  EXPECT_FALSE(fs::exists(dir.path() / "results-elsewhere" / "plots.jsonl"));

  // plot-1 where it was taken, plot-2 missing, plot-3 0.001° (111 m) north.
  const auto partly =
      process(writeMap("partly.csv", row("plot-1", "plot-1", 0) + row("plot-3", "plot-3", 0.001)));
  ASSERT_EQ(partly.exit_code, 0) << partly.err;
  ASSERT_EQ(partly.out_lines.size(), 4U) << partly.err;
  std::map<std::string, Json> lines;
  for (std::size_t i = 0; i < 3; ++i) {
    const Json line = Json::parse(partly.out_lines[i]);
    lines[line.at("plot").get<std::string>()] = line;
  }
  auto problems = [&](const std::string& plot) { return lines.at(plot).at("problems").dump(); };
  EXPECT_EQ(problems("plot-1").find("map"), std::string::npos) << problems("plot-1");
  EXPECT_NE(problems("plot-2").find("location plot-2 is not in the map: placed at the fix at the "
                                    "trigger"),
            std::string::npos)
      << problems("plot-2");
  EXPECT_NEAR(lines.at("plot-2").at("lat").get<double>(), fixes.at("plot-2").first, 1e-9);
  EXPECT_NE(problems("plot-3").find("map location plot-3 is 111 m from the fix at the trigger"),
            std::string::npos)
      << problems("plot-3");
  EXPECT_NEAR(lines.at("plot-3").at("lat").get<double>(), fixes.at("plot-3").first + 0.001, 1e-9);
  EXPECT_EQ(Json::parse(partly.out_lines.back()).at("summary").at("placement_problems"), 2);
}

TEST(ProcessCli, BadCalibrationIsAClearError) {
  ScopedTempDir dir("process_cli_badcal");
  const fs::path session = dir.path() / "session";
  ASSERT_TRUE(recordPlots(dir, session, 1));
  fs::remove(session / "calib" / "middle" / "extrinsics.yml");
  const auto run = runFieldrig({"process", session.string()}, dir.path());
  EXPECT_EQ(run.exit_code, 2);
  EXPECT_NE(run.err.find("extrinsics.yml"), std::string::npos) << run.err;
  EXPECT_TRUE(run.out_lines.empty());
}

// `--config` takes the daemon's processing options: a depth crop that ends before the plants
// (0.3–0.5 m from the camera; they stand 1.2 m away) leaves no points, and a bad key is an error
// naming the file's line and key.
TEST(ProcessCli, ConfigFileSetsTheProcessingOptions) {
  ScopedTempDir dir("process_cli_config");
  const fs::path session = dir.path() / "session";
  ASSERT_TRUE(recordPlots(dir, session, 1));
  const fs::path config = dir.path() / "near.yaml";
  std::ofstream(config) << "pipeline:\n  cloud:\n    min_depth_m: 0.3\n    max_depth_m: 0.5\n";
  const auto near = runFieldrig({"process", session.string(), "--config", config.string(), "--out",
                                 (dir.path() / "near").string()},
                                dir.path());
  ASSERT_EQ(near.exit_code, 0) << near.err;
  ASSERT_EQ(near.out_lines.size(), 2U) << near.err;
  const Json cropped = Json::parse(near.out_lines.front());
  EXPECT_EQ(cropped.at("cloud_points").get<std::size_t>(), 0U) << cropped.dump();
  EXPECT_NE(cropped.at("traits").at("status"), "ok") << cropped.dump();

  const auto defaults = runFieldrig(
      {"process", session.string(), "--out", (dir.path() / "default").string()}, dir.path());
  ASSERT_EQ(defaults.exit_code, 0) << defaults.err;
  EXPECT_GT(Json::parse(defaults.out_lines.front()).at("cloud_points").get<std::size_t>(), 1000U);

  std::ofstream(config, std::ios::trunc) << "pipeline:\n  cloud:\n    scale: 2\n";
  const auto bad =
      runFieldrig({"process", session.string(), "--config", config.string()}, dir.path());
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("near.yaml:3: pipeline.cloud.scale"), std::string::npos) << bad.err;
}

}  // namespace
}  // namespace fieldrig
