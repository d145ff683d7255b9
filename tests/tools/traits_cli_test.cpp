// `fieldrig traits` contract: the real binary on a synthetic plot written by `traits synth`.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "support/cli_run.h"
#include "support/temp_dir.h"

namespace fieldrig::testing_support {
namespace {

TEST(TraitsCli, SynthThenTraitsPrintsOneJsonObjectNearTheTruth) {
  ScopedTempDir dir("traits_cli_synth");
  const auto cloud = dir / "plot.ply";
  const auto truth_file = dir / "truth.json";
  const CliRun synth = runFieldrig({"traits", "synth", "--out", cloud.string(), "--truth",
                                    truth_file.string(), "--height", "1.6", "--seed", "3"},
                                   dir.path());
  ASSERT_EQ(synth.exit_code, 0) << synth.err;
  const nlohmann::json truth = nlohmann::json::parse(readWholeFile(truth_file));

  const CliRun run = runFieldrig({"traits", "--cloud", cloud.string(), "--json"}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  ASSERT_EQ(run.out_lines.size(), 1U);
  const nlohmann::json out = nlohmann::json::parse(run.out_lines[0]);
  EXPECT_EQ(out.at("status"), "ok");
  for (const char* key : {"height_m", "width_m", "vvi", "vai", "total_volume_m3", "total_area_m2",
                          "ega_m2", "valid_slices", "slices", "quality"})
    EXPECT_TRUE(out.contains(key)) << key;
  EXPECT_EQ(out["slices"].size(), 20U);
  EXPECT_NEAR(out["height_m"].get<double>(), truth["height_m"].get<double>(), 0.03);
  EXPECT_NEAR(out["width_m"].get<double>(), truth["width_m"].get<double>(), 0.03);
  EXPECT_TRUE(out["quality"].contains("icp_fitness_fine"));
  EXPECT_TRUE(out["quality"].contains("points_ground"));
}

TEST(TraitsCli, CameraFrameCloudWithCameraFlag) {
  ScopedTempDir dir("traits_cli_camera");
  const auto cloud = dir / "camera.ply";
  ASSERT_EQ(runFieldrig({"traits", "synth", "--out", cloud.string(), "--frame", "camera",
                         "--height", "1.2", "--seed", "4"},
                        dir.path())
                .exit_code,
            0);
  const CliRun as_camera =
      runFieldrig({"traits", "--cloud", cloud.string(), "--frame", "camera", "--json"}, dir.path());
  ASSERT_EQ(as_camera.exit_code, 0) << as_camera.err;
  const nlohmann::json out = nlohmann::json::parse(as_camera.out_lines.at(0));
  EXPECT_EQ(out.at("status"), "ok");
  EXPECT_NEAR(out.at("height_m").get<double>(), 1.2, 0.1);
}

TEST(TraitsCli, UnreadableInputIsBadInputNamingTheFile) {
  ScopedTempDir dir("traits_cli_bad");
  const auto text = dir / "notes.txt";
  std::ofstream(text) << "not a cloud\n";
  const CliRun wrong_kind = runFieldrig({"traits", "--cloud", text.string(), "--json"}, dir.path());
  EXPECT_EQ(wrong_kind.exit_code, 2);
  EXPECT_NE(wrong_kind.err.find("notes.txt"), std::string::npos);

  const auto broken = dir / "broken.ply";
  std::ofstream(broken)
      << "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nend_header\n1\n";
  const CliRun bad_ply = runFieldrig({"traits", "--cloud", broken.string(), "--json"}, dir.path());
  EXPECT_NE(bad_ply.exit_code, 0);

  const auto config = dir / "config.json";
  std::ofstream(config) << R"({"slices": 20, "no_such_key": 1})";
  const auto cloud = dir / "plot.ply";
  ASSERT_EQ(runFieldrig({"traits", "synth", "--out", cloud.string(), "--height", "1.0"}, dir.path())
                .exit_code,
            0);
  const CliRun bad_config = runFieldrig(
      {"traits", "--cloud", cloud.string(), "--config", config.string(), "--json"}, dir.path());
  EXPECT_EQ(bad_config.exit_code, 2);
  EXPECT_NE(bad_config.err.find("no_such_key"), std::string::npos);
}

TEST(TraitsCli, EmptyCloudIsAResultWithAStatus) {
  ScopedTempDir dir("traits_cli_empty");
  const auto empty = dir / "empty.ply";
  std::ofstream(empty) << "ply\nformat ascii 1.0\nelement vertex 0\nproperty float x\n"
                          "property float y\nproperty float z\nend_header\n";
  const CliRun run = runFieldrig({"traits", "--cloud", empty.string(), "--json"}, dir.path());
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const nlohmann::json out = nlohmann::json::parse(run.out_lines.at(0));
  EXPECT_EQ(out.at("status"), "empty_cloud");
  EXPECT_TRUE(out.at("height_m").is_null());
}

}  // namespace
}  // namespace fieldrig::testing_support
