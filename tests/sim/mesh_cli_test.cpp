// `fieldrig sim plots` and `fieldrig simulate` with the mesh renderer, through the built binary:
// --stage alone selects it and its summary says so; the frames get their truth maps unless
// --no-truth-maps; --traits-config sets the truth's trait definitions; options that do not fit the
// renderer or a bad traits file are refused before anything is written, naming the flag or file.
#include <gtest/gtest.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig {
namespace {

namespace fs = std::filesystem;
using testing_support::runFieldrig;
using testing_support::ScopedTempDir;

std::size_t countFiles(const fs::path& dir, const std::string& suffix) {
  std::size_t count = 0;
  for (const auto& entry : fs::directory_iterator(dir))
    count += entry.path().filename().string().ends_with(suffix) ? 1 : 0;
  return count;
}

TEST(MeshCli, StageAloneSelectsTheMeshRendererAndTruthMapsCanBeLeftOut) {
  ScopedTempDir dir("mesh_cli_plots");
  const fs::path session = dir / "session";
  const auto run = runFieldrig({"sim", "plots", "--out", session.string(), "--count", "1",
                                "--stage", "early", "--no-truth-maps"},
                               dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1U);
  const auto summary = nlohmann::json::parse(run.out_lines[0]);
  EXPECT_EQ(summary.at("renderer"), "mesh");
  EXPECT_EQ(summary.at("stages"), nlohmann::json::array({"early"}));
  EXPECT_EQ(summary.at("plots"), 1);
  EXPECT_EQ(countFiles(session / "frames", ".pgm"), 6U);
  EXPECT_EQ(countFiles(session / "frames", ".depth.pfm"), 0U);
  const auto truth = nlohmann::json::parse(testing_support::readWholeFile(session / "truth.jsonl"));
  EXPECT_EQ(truth.at("renderer"), "mesh");
  EXPECT_EQ(truth.at("stage"), "early");
  EXPECT_TRUE(truth.at("truth_maps").empty());
  // The calibrated rig: distorted lenses.
  EXPECT_NE(
      testing_support::readWholeFile(session / "calib" / "bottom" / "intrinsics.yml").find("-1.18"),
      std::string::npos);
}

// --traits-config: the truth lines take the definitions the session will be processed with.
TEST(MeshCli, TraitsConfigSetsTheDefinitionsOfTheTruth) {
  ScopedTempDir dir("mesh_cli_truth_definitions");
  const fs::path definitions = dir / "quantile.yaml";
  { std::ofstream(definitions) << "slice_width_quantile: 0.05\n"; }
  auto truthLine = [&](const std::string& name, const std::vector<std::string>& extra) {
    std::vector<std::string> args = {"sim", "plots",   "--out", (dir / name).string(), "--count",
                                     "1",   "--stage", "mid",   "--no-truth-maps"};
    args.insert(args.end(), extra.begin(), extra.end());
    const auto run = runFieldrig(args, dir.path());
    EXPECT_EQ(run.exit_code, 0) << run.err;
    return nlohmann::json::parse(testing_support::readWholeFile(dir / name / "truth.jsonl"));
  };
  const auto extreme = truthLine("extreme", {});
  const auto quantile = truthLine("quantile", {"--traits-config", definitions.string()});
  // The same plot: the 5 % of each slice's voxels nearest and furthest no longer set its width.
  EXPECT_EQ(quantile.at("visible_plant_area_m2"), extreme.at("visible_plant_area_m2"));
  EXPECT_LT(quantile.at("width_m").get<double>(), extreme.at("width_m").get<double>() - 0.01);
  EXPECT_EQ(quantile.at("height_m"), extreme.at("height_m"));  // the top is not a quantile
  EXPECT_LT(quantile.at("stereo_view").at("width_m").get<double>(),
            extreme.at("stereo_view").at("width_m").get<double>());
}

TEST(MeshCli, OptionsThatDoNotFitTheRendererAreRefusedBeforeAnythingIsWritten) {
  ScopedTempDir dir("mesh_cli_refusals");
  const std::string out = (dir / "out").string();
  const fs::path bad_traits = dir / "bad-traits.yaml";
  { std::ofstream(bad_traits) << "slice_width_quantile: 0.4\n"; }
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"sim", "plots", "--out", out, "--stage", "late"}, "--stage"},
      {{"sim", "plots", "--out", out, "--renderer", "raster"}, "--renderer"},
      {{"sim", "plots", "--out", out, "--renderer", "splat", "--stage", "mid"}, "--stage"},
      {{"sim", "plots", "--out", out, "--no-truth-maps"}, "--no-truth-maps"},
      {{"sim", "plots", "--out", out, "--height-max", "3.5"}, "--renderer mesh"},
      {{"sim", "plots", "--out", out, "--renderer", "mesh", "--height-max", "9"}, "--height-max"},
      {{"sim", "plots", "--out", out, "--count", "2", "--stage", "early,mid,mature"}, "stages"},
      {{"simulate", "--out", out, "--plots", "2", "--stage", "early,mid,mature"}, "stages"},
      {{"simulate", "--out", out, "--renderer", "splat", "--stage", "mature"}, "--stage"},
      {{"simulate", "--out", out, "--traits-config", bad_traits.string()},
       bad_traits.string() + ":1: slice_width_quantile"},
      {{"sim", "plots", "--out", out, "--traits-config", (dir / "absent.yaml").string()},
       "absent.yaml"},
  };
  for (const auto& [args, named] : cases) {
    std::string joined;
    for (const auto& a : args)
      joined += a + " ";
    SCOPED_TRACE(joined);
    const auto run = runFieldrig(args, dir.path());
    EXPECT_EQ(run.exit_code, 2) << run.err;
    EXPECT_NE(run.err.find(named), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(out)) << "something was written";
  }
}

// A field is written whole into a new or empty folder: an earlier field, a file or a row count
// the plots cannot fill are refused as bad input, naming the option, and nothing is touched.
TEST(MeshCli, SimulateRefusesAFolderThatHoldsFilesAndRowsThePlotsCannotFill) {
  ScopedTempDir dir("mesh_cli_out_folder");
  const fs::path earlier = dir / "earlier";
  fs::create_directories(earlier / "source-session");
  { std::ofstream(earlier / "truth.jsonl") << "{\"plot\":\"R01P01\"}\n"; }
  const fs::path file = dir / "a-file";
  { std::ofstream(file) << "x"; }
  const std::vector<std::pair<std::vector<std::string>, std::string>> cases = {
      {{"simulate", "--out", earlier.string(), "--plots", "1", "--rows", "1"},
       "--out: " + earlier.string() + ": already holds files"},
      {{"simulate", "--out", file.string(), "--plots", "1", "--rows", "1"},
       "--out: " + file.string() + ": exists and is not a folder"},
      {{"simulate", "--out", "", "--plots", "1", "--rows", "1"}, "--out: must not be empty"},
      {{"simulate", "--out", (dir / "new").string(), "--plots", "1", "--rows", "2"},
       "--rows 2 is more than --plots 1"},
  };
  for (const auto& [args, named] : cases) {
    SCOPED_TRACE(named);
    const auto run = runFieldrig(args, dir.path());
    EXPECT_EQ(run.exit_code, 2) << run.err;
    EXPECT_NE(run.err.find(named), std::string::npos) << run.err;
  }
  EXPECT_EQ(testing_support::readWholeFile(earlier / "truth.jsonl"), "{\"plot\":\"R01P01\"}\n");
  EXPECT_TRUE(fs::is_empty(earlier / "source-session"));
  EXPECT_FALSE(fs::exists(dir / "new"));
}

// A write that fails half-way (here the file size limit, as a full disk would) fails the run
// with the file named, and leaves neither the field's folder nor its hidden staging folder.
TEST(MeshCli, SimulateThatCannotWriteLeavesNothingHalfWritten) {
  ScopedTempDir dir("mesh_cli_short_write");
  const fs::path out = dir / "field";
  // 4 MiB: the drive, map and frames fit, a 1624 × 1224 float depth map (7.9 MB) does not.
  const auto run = testing_support::runProgram(
      "bash",
      {"-c", "trap '' XFSZ; ulimit -f 4096; exec \"$0\" \"$@\"", testing_support::kFieldrigBinary,
       "simulate", "--out", out.string(), "--plots", "1", "--rows", "1", "--stage", "early"},
      dir.path());
  EXPECT_EQ(run.exit_code, 3) << run.err;
  EXPECT_NE(run.err.find(".depth.pfm: cannot write: " + std::string(std::strerror(EFBIG))),
            std::string::npos)
      << run.err;
  EXPECT_FALSE(fs::exists(out));
  EXPECT_FALSE(fs::exists(dir / ".field.simulate-partial"));
}

}  // namespace
}  // namespace fieldrig
