// `fieldrig process --depth-source truth|truth-where-matched` and `--score-stereo` on sessions of
// `fieldrig sim plots`: a rendered mesh plot processed from its truth depth maps goes through the
// same fusion, crop and traits as stereo, with every left pixel measured, or only stereo's matched
// pixels; stereo is scored per head against the same truth; a session without the truth maps is
// refused before anything is written, naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

using testing_support::readWholeFile;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;
using Json = nlohmann::json;
namespace fs = std::filesystem;

// The one result line of a one-set run (the summary comes last).
Json plotLine(const testing_support::CliRun& run) {
  EXPECT_EQ(run.out_lines.size(), 2U) << run.err;
  return run.out_lines.empty() ? Json() : Json::parse(run.out_lines.front());
}

const Json& head(const Json& line, const std::string& name) {
  for (const Json& h : line.at("heads")) {
    if (h.at("name") == name)
      return h;
  }
  ADD_FAILURE() << "no head " << name << " in " << line.dump();
  static const Json none;
  return none;
}

// A rendered one-plot session (mesh renderer, so with truth maps) in DIR/session.
fs::path renderedSession(const ScopedTempDir& dir) {
  const fs::path session = dir / "session";
  const auto made = runFieldrig(
      {"sim", "plots", "--out", session.string(), "--count", "1", "--stage", "mid"}, dir.path());
  EXPECT_EQ(made.exit_code, 0) << made.err;
  return session;
}

// `fieldrig process SESSION --out DIR/NAME EXTRA...`: its one result line (null when it failed).
Json processedLine(const ScopedTempDir& dir, const fs::path& session, const std::string& name,
                   const std::vector<std::string>& extra) {
  std::vector<std::string> args = {"process", session.string(), "--out", (dir / name).string()};
  args.insert(args.end(), extra.begin(), extra.end());
  const auto run = runFieldrig(args, dir.path());
  EXPECT_EQ(run.exit_code, 0) << name << ": " << run.err;
  return run.exit_code == 0 ? plotLine(run) : Json();
}

TEST(ProcessTruthDepthCli, TruthDepthGoesThroughTheSameChainAndStereoIsScoredAgainstIt) {
  ScopedTempDir dir("process_truth_depth");
  const fs::path session = renderedSession(dir);
  ASSERT_FALSE(HasFailure());
  const Json truth = Json::parse(readWholeFile(session / "truth.jsonl"));

  const Json s = processedLine(dir, session, "stereo", {"--score-stereo"});
  const Json t = processedLine(dir, session, "truth", {"--depth-source", "truth"});
  ASSERT_FALSE(s.is_null());
  ASSERT_FALSE(t.is_null());
  EXPECT_FALSE(s.contains("depth_source")) << "a stereo line stays as the rig writes it";
  EXPECT_EQ(t.at("depth_source"), "truth");
  EXPECT_EQ(t.at("traits").at("status"), "ok") << t.dump();
  EXPECT_EQ(t.at("problems"), Json::array()) << t.dump();

  // Perfect depth: every plant pixel of the bottom head has a disparity, so its share of the left
  // image and its cloud exceed what matching (left–right check, speckle filter) keeps.
  const Json& stereo_bottom = head(s, "bottom");
  const Json& truth_bottom = head(t, "bottom");
  EXPECT_GT(truth_bottom.at("valid_pixel_fraction").get<double>(),
            stereo_bottom.at("valid_pixel_fraction").get<double>());
  EXPECT_GT(truth_bottom.at("points").get<std::size_t>(),
            stereo_bottom.at("points").get<std::size_t>());
  EXPECT_FALSE(truth_bottom.contains("stereo_vs_truth"));

  // The truth-depth height is as close to the mesh truth as stereo's, give or take the slicing
  // (1 cm voxels): it has the same crop and slices and no matching error.
  const double truth_height = truth.at("height_m").get<double>();
  const double error_truth_depth =
      std::abs(t.at("traits").at("height_m").get<double>() - truth_height);
  const double error_stereo = std::abs(s.at("traits").at("height_m").get<double>() - truth_height);
  EXPECT_LE(error_truth_depth, error_stereo + 0.02)
      << "truth depth " << error_truth_depth << " m, stereo " << error_stereo << " m";
  EXPECT_LT(error_truth_depth, 0.05);

  // Stereo scored on the plot's vegetation: a matched share, a bad-pixel rate, and a depth error of
  // millimetres (the rig's SGBM at 0.8-1.7 m), not of the metre a wrong convention would give.
  const Json& score = stereo_bottom.at("stereo_vs_truth");
  EXPECT_GT(score.at("vegetation_pixels").get<std::size_t>(), 10000U) << score.dump();
  const double matched = score.at("matched_fraction").get<double>();
  const double bad = score.at("bad_fraction").get<double>();
  EXPECT_GT(matched, 0.2) << score.dump();
  EXPECT_LE(matched, 1.0);
  EXPECT_GE(bad, 0.0);
  EXPECT_LT(bad, 0.5) << score.dump();
  EXPECT_LT(score.at("median_abs_depth_error_m").get<double>(), 0.02) << score.dump();
  EXPECT_LT(std::abs(score.at("median_depth_error_m").get<double>()), 0.02) << score.dump();

  // The head's points against the truth on their rays: every point counted, most of them on the
  // surface (the sky mask and the edge filter have done their part), and the truth depth's own
  // head has no such score.
  const Json& points = stereo_bottom.at("points_vs_truth");
  // (The score's depth range is along the head's axis, the cloud's crop along the plot's; the
  // bottom head looks level, so they agree.)
  EXPECT_NEAR(points.at("points").get<double>(), stereo_bottom.at("points").get<double>(),
              0.02 * stereo_bottom.at("points").get<double>())
      << points.dump();
  const double off = points.at("off_surface_3cm_fraction").get<double>();
  EXPECT_GE(off, points.at("on_sky_fraction").get<double>()) << points.dump();
  EXPECT_LT(off, 0.25) << points.dump();
  // The off points by side: those with a side and those on sky are apart, and none is counted
  // twice; the ones from beyond the crop are some of the nearer ones.
  const double nearer = points.at("off_nearer_fraction").get<double>();
  const double farther = points.at("off_farther_fraction").get<double>();
  EXPECT_LE(nearer + farther + points.at("on_sky_fraction").get<double>(), off + 1e-9)
      << points.dump();
  EXPECT_GT(nearer + farther, 0.0) << points.dump();
  EXPECT_LE(points.at("from_beyond_crop_fraction").get<double>(), nearer) << points.dump();
  EXPECT_FALSE(truth_bottom.contains("points_vs_truth"));
}

TEST(ProcessTruthDepthCli, TruthWhereMatchedKeepsStereosPixelsWithTheTruthsDepth) {
  ScopedTempDir dir("process_truth_where_matched");
  const fs::path session = renderedSession(dir);
  ASSERT_FALSE(HasFailure());
  const Json s = processedLine(dir, session, "stereo", {"--score-stereo"});
  const Json m = processedLine(dir, session, "matched",
                               {"--depth-source", "truth-where-matched", "--score-stereo"});
  const Json t = processedLine(dir, session, "truth", {"--depth-source", "truth"});
  ASSERT_FALSE(s.is_null() || m.is_null() || t.is_null());
  EXPECT_EQ(m.at("depth_source"), "truth-where-matched");
  EXPECT_EQ(m.at("traits").at("status"), "ok") << m.dump();

  const Json& stereo_bottom = head(s, "bottom");
  const Json& matched_bottom = head(m, "bottom");
  // The same matching ran: the same pixels matched, the same score against the truth.
  EXPECT_EQ(matched_bottom.at("valid_pixel_fraction"), stereo_bottom.at("valid_pixel_fraction"));
  EXPECT_EQ(matched_bottom.at("stereo_vs_truth"), stereo_bottom.at("stereo_vs_truth"));
  // Its cloud has those pixels' points (less those on sky, which the truth has no depth for), all
  // of them on the surfaces; the full truth depth has more.
  const auto points = matched_bottom.at("points").get<double>();
  EXPECT_LE(points, stereo_bottom.at("points").get<double>() * 1.01);
  EXPECT_GT(points, stereo_bottom.at("points").get<double>() * 0.8);
  EXPECT_LT(points, head(t, "bottom").at("points").get<double>());
  const Json& on_surface = matched_bottom.at("points_vs_truth");
  EXPECT_LT(on_surface.at("off_surface_3cm_fraction").get<double>(), 0.01) << on_surface.dump();
  EXPECT_EQ(on_surface.at("on_sky_fraction").get<double>(), 0.0) << on_surface.dump();
  EXPECT_GT(stereo_bottom.at("points_vs_truth").at("off_surface_3cm_fraction").get<double>(),
            on_surface.at("off_surface_3cm_fraction").get<double>());
}

// A truth map damaged after the session was checked, or of another rig's size, costs its head
// (its truth, not its stereo), not the run: the set's line names the file among its problems, and
// the other heads are processed and scored.
TEST(ProcessTruthDepthCli, ADamagedTruthMapIsNamedOnItsSetAndTheRunGoesOn) {
  ScopedTempDir dir("process_truth_depth_damaged");
  const fs::path session = renderedSession(dir);
  ASSERT_FALSE(HasFailure());
  const fs::path depth = session / "frames" / "000000_2_middle_left.depth.pfm";
  fs::resize_file(depth, fs::file_size(depth) / 2);
  { std::ofstream(session / "frames" / "000000_4_top_left.veg.png") << "not a PNG"; }
  {  // a whole, readable map of another size: of another rig
    std::ofstream small(session / "frames" / "000000_4_top_left.depth.pfm", std::ios::binary);
    small << "Pf\n4 4\n-1\n" << std::string(4 * 4 * sizeof(float), '\0');
  }

  auto problemNaming = [](const Json& line, const std::string& file) {
    for (const Json& problem : line.at("problems")) {
      if (problem.get<std::string>().find(file) != std::string::npos)
        return true;
    }
    return false;
  };
  const Json t = processedLine(dir, session, "truth", {"--depth-source", "truth"});
  ASSERT_FALSE(t.is_null());
  EXPECT_TRUE(problemNaming(t, "000000_2_middle_left.depth.pfm: PFM header says")) << t.dump();
  EXPECT_EQ(head(t, "middle").at("points"), 0) << t.dump();
  EXPECT_TRUE(problemNaming(t, "000000_4_top_left.depth.pfm: truth map is 4x4")) << t.dump();
  EXPECT_EQ(head(t, "top").at("points"), 0) << t.dump();
  EXPECT_GT(head(t, "bottom").at("points").get<double>(), 0.0);

  const Json s = processedLine(dir, session, "stereo", {"--score-stereo"});
  ASSERT_FALSE(s.is_null());
  EXPECT_TRUE(problemNaming(s, "000000_4_top_left.veg.png")) << s.dump();
  EXPECT_TRUE(problemNaming(s, "000000_4_top_left.depth.pfm: truth map is 4x4")) << s.dump();
  EXPECT_GT(head(s, "top").at("points").get<double>(), 0.0) << "stereo needs no truth";
  EXPECT_TRUE(head(s, "bottom").contains("stereo_vs_truth")) << s.dump();
  EXPECT_FALSE(head(s, "top").contains("stereo_vs_truth")) << s.dump();
}

TEST(ProcessTruthDepthCli, ASessionWithoutTruthMapsIsRefusedNamingTheMissingFile) {
  ScopedTempDir dir("process_truth_depth_missing");
  const fs::path session = dir / "session";
  // The splat renderer writes no truth maps.
  const auto made =
      runFieldrig({"sim", "plots", "--out", session.string(), "--count", "1"}, dir.path());
  ASSERT_EQ(made.exit_code, 0) << made.err;
  for (const auto& extra : {std::vector<std::string>{"--depth-source", "truth"},
                            std::vector<std::string>{"--depth-source", "truth-where-matched"},
                            std::vector<std::string>{"--score-stereo"}}) {
    std::vector<std::string> args = {"process", session.string(), "--out",
                                     (dir / "results").string()};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto run = runFieldrig(args, dir.path());
    SCOPED_TRACE(extra.front());
    EXPECT_EQ(run.exit_code, 2) << run.err;
    EXPECT_NE(run.err.find("frames/000000_0_bottom_left.depth.pfm"), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(dir / "results")) << "something was written";
  }
  const auto both = runFieldrig(
      {"process", session.string(), "--depth-source", "truth", "--score-stereo"}, dir.path());
  EXPECT_EQ(both.exit_code, 2);
  EXPECT_NE(both.err.find("--score-stereo"), std::string::npos) << both.err;
  const auto bogus =
      runFieldrig({"process", session.string(), "--depth-source", "lidar"}, dir.path());
  EXPECT_EQ(bogus.exit_code, 2);
  EXPECT_NE(bogus.err.find("--depth-source"), std::string::npos) << bogus.err;
}

}  // namespace
}  // namespace fieldrig
