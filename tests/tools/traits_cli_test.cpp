// `fieldrig traits` contract: the real binary on a synthetic plot written by `traits synth`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

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

// Hostile cloud files: each exits 2 with the file named (before: abort on std::bad_alloc for a
// huge header count, a segfault inside PCL for an empty or garbage .pcd).
TEST(TraitsCli, HostileCloudFilesAreBadInputNamingTheFile) {
  ScopedTempDir dir("traits_cli_hostile");
  const std::string ply_head =
      "ply\nformat binary_little_endian 1.0\nelement vertex COUNT\nproperty float x\n"
      "property float y\nproperty float z\nend_header\n";
  const auto ply = [&](const std::string& count) {
    std::string head = ply_head;
    return head.replace(head.find("COUNT"), 5, count) + std::string(24, '\0');
  };
  const std::string pcd_head =
      "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2147483647\nHEIGHT 1\n"
      "POINTS 2147483647\nDATA ";
  const std::pair<std::string, std::string> cases[] = {
      {"huge31.ply", ply("2147483647")},
      {"huge32.ply", ply("4294967295")},
      {"truncated.ply", ply("1000")},
      {"huge.pcd", pcd_head + "binary\n" + std::string(24, '\0')},
      {"huge_ascii.pcd", pcd_head + "ascii\n1 2 3\n"},
      {"truncated.pcd",
       "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 3\nDATA ascii\n1 2 3\n4 5 6\n"},
      {"garbage.pcd", std::string("\x89\x01\xff garbage\n\x00\x13", 14)},
      {"garbage.ply", std::string("\x89\x01\xff garbage\n\x00\x13", 14)},
      {"empty.pcd", ""},
      {"empty.ply", ""},
  };
  for (const auto& [name, bytes] : cases) {
    const auto file = dir / name;
    std::ofstream(file, std::ios::binary) << bytes;
    const CliRun run = runFieldrig({"traits", "--cloud", file.string(), "--json"}, dir.path());
    EXPECT_EQ(run.exit_code, 2) << name << ": " << run.err;
    EXPECT_EQ(run.err.rfind("fieldrig traits: " + file.string() + ": ", 0), 0u) << run.err;
  }
  // A folder is refused by the option's own check (CLI11's ExistingFile, with CLI11's exit code)
  // before loadCloud sees it; loadCloud refuses it too, for library callers (cloud_io_test).
  std::filesystem::create_directory(dir / "folder.ply");
  const CliRun folder =
      runFieldrig({"traits", "--cloud", (dir / "folder.ply").string(), "--json"}, dir.path());
  EXPECT_NE(folder.exit_code, 0);
  EXPECT_NE(folder.err.find((dir / "folder.ply").string()), std::string::npos) << folder.err;
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

// A truth that cannot be written leaves no cloud behind without it.
TEST(TraitsCli, SynthWithAnUnwritableTruthWritesNoCloud) {
  ScopedTempDir dir("traits_cli_synth_truth");
  const auto cloud = dir / "plot.ply";
  const CliRun synth = runFieldrig(
      {"traits", "synth", "--out", cloud.string(), "--truth", "/proc/no-such/truth.json"},
      dir.path());
  EXPECT_EQ(synth.exit_code, 2);
  EXPECT_NE(synth.err.find("/proc/no-such/truth.json"), std::string::npos) << synth.err;
  EXPECT_FALSE(std::filesystem::exists(cloud));
}

// `fieldrig` is a launcher: `traits` runs the light fieldrig-traits, everything else (and
// `traits synth`) the full fieldrig-commands. The light program's help says where the rest is.
TEST(TraitsCli, TraitsRunsTheLightProgramAndEverythingElseTheFullOne) {
  ScopedTempDir dir("traits_cli_launcher");
  const std::string light_footer = "The other subcommands, and `traits synth`: fieldrig --help.";
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"traits", "--help"},
        std::vector<std::string>{"--log-level", "info", "traits", "--help"}}) {
    const CliRun help = runFieldrig(args, dir.path());
    EXPECT_EQ(help.exit_code, 0) << help.err;
    const std::string out = readWholeFile(dir / "cli.out");
    EXPECT_NE(out.find("--cloud"), std::string::npos) << out;
    EXPECT_NE(out.find(light_footer), std::string::npos) << out;
  }
  const CliRun synth = runFieldrig({"traits", "synth", "--help"}, dir.path());
  EXPECT_EQ(synth.exit_code, 0) << synth.err;
  const std::string synth_out = readWholeFile(dir / "cli.out");
  EXPECT_NE(synth_out.find("--no-plants"), std::string::npos) << synth_out;
  EXPECT_EQ(synth_out.find(light_footer), std::string::npos) << synth_out;

  // What makes it light: none of OpenCV (whose image codecs pull in GDAL and ~140 libraries) or
  // the camera libraries is loaded. VTK still is, through PCL's surface module (hulls, MLS).
  const std::filesystem::path light =
      std::filesystem::path(kFieldrigBinary).parent_path() / "fieldrig-traits";
  ASSERT_TRUE(std::filesystem::exists(light)) << light;
  const CliRun libraries = runProgram("ldd", {light.string()}, dir.path());
  ASSERT_EQ(libraries.exit_code, 0) << libraries.err;
  ASSERT_GT(libraries.out_lines.size(), 3U);
  // 38 on Debian 12 (fieldrig-commands: 219).
  EXPECT_LT(libraries.out_lines.size(), 80U);
  for (const std::string& line : libraries.out_lines) {
    for (const char* heavy : {"libopencv", "libgdal", "libaravis", "libdc1394"})
      EXPECT_EQ(line.find(heavy), std::string::npos) << light << " loads " << line;
  }
}

}  // namespace
}  // namespace fieldrig::testing_support
