// The YAML configuration: every shipped file loads and says what it should; errors name the file,
// the line and the key path; relative paths follow the file; an empty file gives the option
// structs' own defaults; traits options load from YAML and from the JSON of earlier versions.
#include "fieldrig/config/config.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "support/temp_dir.h"

namespace fieldrig::config {
namespace {

namespace fs = std::filesystem;
using testing_support::ScopedTempDir;

std::string currentTestName() {
  return ::testing::UnitTest::GetInstance()->current_test_info()->name();
}

fs::path writeFile(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
  return file;
}

// --- Field-by-field comparisons (the option structs have no operator==) ------------------------

#define EXPECT_FIELD(field) EXPECT_EQ(actual.field, expected.field) << #field

void expectSame(const gps::SerialOptions& actual, const gps::SerialOptions& expected) {
  EXPECT_FIELD(device);
  EXPECT_FIELD(baud);
  EXPECT_FIELD(reopen_initial_delay);
  EXPECT_FIELD(reopen_max_delay);
}

void expectSame(const gps::TriggerChainOptions& actual, const gps::TriggerChainOptions& expected) {
  EXPECT_FIELD(latency_s);
  EXPECT_FIELD(planner.cross_track_tolerance_m);
  EXPECT_FIELD(planner.heading_tolerance_deg);
  EXPECT_FIELD(planner.min_speed_mps);
  EXPECT_FIELD(planner.max_fix_age_s);
  EXPECT_FIELD(planner.max_fix_gap_s);
  EXPECT_FIELD(planner.min_trigger_interval_s);
  EXPECT_FIELD(planner.late_tolerance_m);
  EXPECT_FIELD(planner.rearm_distance_m);
  EXPECT_FIELD(planner.fit_window_s);
  EXPECT_FIELD(planner.fit_residual_limit_m);
  EXPECT_FIELD(planner.trigger_lead_s);
  EXPECT_FIELD(planner.motion_model);
  EXPECT_FIELD(planner.kalman_jerk_density);
  EXPECT_FIELD(planner.kalman_position_sd_m);
  EXPECT_FIELD(planner.kalman_velocity_sd_mps);
}

void expectSame(const drivers::CameraConfig& actual, const drivers::CameraConfig& expected) {
  EXPECT_FIELD(id);
  EXPECT_FIELD(format);
  EXPECT_FIELD(width);
  EXPECT_FIELD(height);
  EXPECT_FIELD(exposure_us);
  EXPECT_FIELD(gain_db);
  EXPECT_FIELD(white_balance);
  EXPECT_FIELD(trigger);
  EXPECT_FIELD(options);
}

void expectSame(const stereo::MatcherOptions& actual, const stereo::MatcherOptions& expected) {
  EXPECT_FIELD(num_disparities);
  EXPECT_FIELD(min_disparity);
  EXPECT_FIELD(block_size);
  EXPECT_FIELD(p1_per_pixel);
  EXPECT_FIELD(p2_per_pixel);
  EXPECT_FIELD(pre_filter_cap);
  EXPECT_FIELD(uniqueness_ratio);
  EXPECT_FIELD(speckle_window);
  EXPECT_FIELD(speckle_range);
  EXPECT_FIELD(disp12_max_diff);
  EXPECT_FIELD(lr_check);
  EXPECT_FIELD(lr_max_diff);
  EXPECT_FIELD(wls);
  EXPECT_FIELD(wls_lambda);
  EXPECT_FIELD(wls_sigma);
  EXPECT_FIELD(mode);
  EXPECT_FIELD(match_colour);
  EXPECT_FIELD(full_width);
  EXPECT_FIELD(min_texture);
  EXPECT_FIELD(grow_uniqueness_ratio);
  EXPECT_FIELD(grow_confirmed_fraction);
}

void expectSame(const cloud::CloudOptions& actual, const cloud::CloudOptions& expected) {
  EXPECT_FIELD(scale);
  EXPECT_FIELD(min_depth_m);
  EXPECT_FIELD(max_depth_m);
  EXPECT_FIELD(edge_max_jump_px);
  EXPECT_FIELD(edge_keep_near_side);
  expectSame(actual.matcher, expected.matcher);
}

void expectSame(const traits::TraitsOptions& actual, const traits::TraitsOptions& expected) {
  EXPECT_TRUE(actual.camera_to_plot == expected.camera_to_plot)
      << "camera_to_plot\n"
      << actual.camera_to_plot << "\nexpected\n"
      << expected.camera_to_plot;
  EXPECT_FIELD(voxel_leaf_m);
  EXPECT_FIELD(outlier_method);
  EXPECT_FIELD(outlier_mean_k);
  EXPECT_FIELD(outlier_stddev_mul);
  EXPECT_FIELD(outlier_min_neighbours);
  EXPECT_FIELD(min_piece_voxels);
  EXPECT_FIELD(crop_z_max_m);
  EXPECT_FIELD(crop_z_min_m);
  EXPECT_FIELD(max_abs_coordinate_m);
  EXPECT_FIELD(template_strip_m);
  EXPECT_FIELD(template_step_m);
  EXPECT_FIELD(icp_target_leaf_m);
  EXPECT_FIELD(icp_coarse_distance_m);
  EXPECT_FIELD(icp_fine_distance_m);
  EXPECT_FIELD(icp_iterations);
  EXPECT_FIELD(max_ground_tilt_deg);
  EXPECT_FIELD(ground_tilt_limit_deg);
  EXPECT_FIELD(max_ground_shift_m);
  EXPECT_FIELD(ground_margin_m);
  EXPECT_FIELD(row_base_band_m);
  EXPECT_FIELD(ground_tilt_deg);
  EXPECT_FIELD(row_length_m);
  EXPECT_FIELD(crop_to_row_length);
  EXPECT_FIELD(intra_row_spacing_m);
  EXPECT_FIELD(slices);
  EXPECT_FIELD(slice_width_quantile);
  EXPECT_FIELD(width_band_m);
  EXPECT_FIELD(min_row_extent_m);
  EXPECT_FIELD(min_plant_points);
  EXPECT_FIELD(alpha);
  EXPECT_FIELD(alpha_near_margin);
  EXPECT_FIELD(area_method);
  EXPECT_FIELD(depth_map_cell_m);
  EXPECT_FIELD(depth_map_max_step_m);
  EXPECT_FIELD(depth_map_min_fill);
  EXPECT_FIELD(mls_radius_m);
  EXPECT_FIELD(gpt_radius_m);
  EXPECT_FIELD(gpt_mu);
  EXPECT_FIELD(gpt_max_neighbors);
}

#undef EXPECT_FIELD

// Everything but the rig's cameras (which the loader always fills) against the structs' defaults.
void expectDefaults(const Config& config) {
  const Config defaults;
  expectSame(config.gps.serial, defaults.gps.serial);
  expectSame(config.gps.triggers, defaults.gps.triggers);
  EXPECT_EQ(config.map, fs::path());
  EXPECT_EQ(config.cameras.layout.heads, core::RigLayout().heads);
  EXPECT_EQ(config.cameras.rig.driver, drivers::RigOptions().driver);
  EXPECT_EQ(config.cameras.rig.frame_timeout, drivers::RigOptions().frame_timeout);
  EXPECT_EQ(config.cameras.rig.max_skew, drivers::RigOptions().max_skew);
  EXPECT_EQ(config.cameras.rig.pool_sets, drivers::RigOptions().pool_sets);
  EXPECT_EQ(config.calibration, fs::path());
  EXPECT_EQ(config.recording.dir, fs::path());
  EXPECT_EQ(config.recording.writer.fsync, recording::WriterOptions().fsync);
  EXPECT_EQ(config.pipeline.enabled, defaults.pipeline.enabled);
  EXPECT_EQ(config.pipeline.queue_sets, defaults.pipeline.queue_sets);
  expectSame(config.pipeline.cloud, cloud::CloudOptions());
  expectSame(config.pipeline.traits, traits::TraitsOptions());
  EXPECT_EQ(config.outputs.dir, fs::path());
  EXPECT_EQ(config.outputs.csv, defaults.outputs.csv);
  EXPECT_EQ(config.outputs.geojson, defaults.outputs.geojson);
  EXPECT_EQ(config.outputs.jsonl, defaults.outputs.jsonl);
  EXPECT_EQ(config.status.enabled, defaults.status.enabled);
  EXPECT_EQ(config.status.address, defaults.status.address);
  EXPECT_EQ(config.status.port, defaults.status.port);
  EXPECT_EQ(config.replay.nmea, fs::path());
  EXPECT_EQ(config.replay.realtime, defaults.replay.realtime);
  EXPECT_EQ(config.replay.session, fs::path());
  EXPECT_EQ(config.log.level, defaults.log.level);
  EXPECT_EQ(config.log.file, fs::path());
}

// --- (a) Every shipped configuration file
// ---------------------------------------------------------

const fs::path kShippedFolder = fs::path(FIELDRIG_SOURCE_DIR) / "config";

// What each shipped file says, checked on what it loads to.
const std::map<std::string, std::function<void(const Config&)>>& shippedFileChecks() {
  static const std::map<std::string, std::function<void(const Config&)>> checks = {
      {"fieldrigd.yaml",
       [](const Config& c) {
         EXPECT_EQ(c.gps.serial.device, "/dev/ttyUSB0");
         EXPECT_EQ(c.gps.serial.baud, 115200U);
         EXPECT_DOUBLE_EQ(c.gps.triggers.latency_s, 0.05);
         EXPECT_EQ(c.cameras.rig.driver, "dc1394");
         EXPECT_EQ(c.cameras.layout.heads, (std::vector<std::string>{"bottom", "middle", "top"}));
         ASSERT_EQ(c.cameras.rig.cameras.size(), 6U);
         EXPECT_EQ(c.cameras.rig.cameras.front().id, "00b09d0100000001");
         EXPECT_EQ(c.cameras.rig.cameras.back().id, "00b09d0100000006");
         for (const drivers::CameraConfig& camera : c.cameras.rig.cameras) {
           EXPECT_EQ(camera.width, 1624U);
           EXPECT_EQ(camera.height, 1224U);
           EXPECT_EQ(camera.format, core::PixelFormat::kBayerRG8);
           EXPECT_EQ(camera.options.at("iso_speed"), "800");
         }
         EXPECT_EQ(c.calibration, fs::path("/etc/fieldrig/calib"));
         EXPECT_EQ(c.recording.dir, fs::path("/var/lib/fieldrig/sessions/today"));
         EXPECT_EQ(c.recording.writer.fsync, recording::FsyncPolicy::kPerSet);
         EXPECT_EQ(c.pipeline.cloud.matcher.mode, cv::StereoSGBM::MODE_SGBM_3WAY);
         EXPECT_EQ(c.pipeline.cloud.scale, 0.5);
         EXPECT_EQ(c.pipeline.cloud.max_depth_m, 1.7);
         EXPECT_EQ(c.status.address, "127.0.0.1");
         EXPECT_EQ(c.status.port, 8470);
         EXPECT_TRUE(c.replay.nmea.empty());
       }},
      {"replay.yaml",
       [](const Config& c) {
         EXPECT_EQ(c.cameras.rig.driver, "sim");
         ASSERT_EQ(c.cameras.rig.cameras.size(), 6U);
         for (std::size_t i = 0; i < 6; ++i)
           EXPECT_EQ(c.cameras.rig.cameras[i].id, std::to_string(i));
         // The synthetic field scripts/demo.sh makes in the build folder, beside config/.
         const auto shipped = [](const char* relative) {
           return (kShippedFolder / relative).lexically_normal();
         };
         EXPECT_EQ(c.replay.nmea, shipped("../build/demo/field/drive.nmea"));
         EXPECT_EQ(c.replay.session, shipped("../build/demo/field/source-session"));
         EXPECT_FALSE(c.replay.realtime);
         EXPECT_EQ(c.map, shipped("../build/demo/field/map.csv"));
         EXPECT_EQ(c.calibration, shipped("../build/demo/field/source-session/calib"));
         EXPECT_EQ(c.recording.dir, shipped("../build/demo/run"));
         EXPECT_EQ(c.recording.writer.fsync, recording::FsyncPolicy::kNone);
         EXPECT_EQ(c.status.port, 0);
         EXPECT_TRUE(c.pipeline.enabled);
         EXPECT_EQ(c.pipeline.queue_sets, 2U);
         EXPECT_TRUE(c.gps.serial.device.empty());
       }},
  };
  return checks;
}

TEST(ShippedConfigFiles, EveryYamlFileLoadsAndSaysWhatItShould) {
  std::vector<std::string> loaded;
  for (const fs::directory_entry& entry : fs::directory_iterator(kShippedFolder)) {
    if (!entry.is_regular_file() || entry.path().extension() != ".yaml")
      continue;
    const std::string name = entry.path().filename().string();
    SCOPED_TRACE(name);
    const core::Result<Config> config = loadConfig(entry.path());
    ASSERT_TRUE(config.ok()) << config.error().message;
    EXPECT_EQ(config->source, entry.path());
    EXPECT_EQ(config->cameras.rig.cameras.size(), config->cameras.layout.cameraCount());
    if (const auto check = shippedFileChecks().find(name); check != shippedFileChecks().end())
      check->second(*config);
    loaded.push_back(name);
  }
  // The files this test knows were there (an empty folder must not pass).
  for (const auto& [name, _] : shippedFileChecks()) {
    EXPECT_NE(std::find(loaded.begin(), loaded.end(), name), loaded.end())
        << name << " is not in " << kShippedFolder;
  }
}

// --- (b) Errors name the file, the line and the key path
// ------------------------------------------

class ConfigErrors : public ::testing::Test {
 protected:
  ScopedTempDir dir_{"config_" + currentTestName()};

  // Loads `text` from bad.yaml and expects an error starting "…/bad.yaml:LINE: KEY_PATH: " and
  // holding `what`.
  void expectError(const std::string& text, int line, const std::string& key_path,
                   const std::string& what) {
    const fs::path file = writeFile(dir_ / "bad.yaml", text);
    const core::Result<Config> config = loadConfig(file);
    ASSERT_FALSE(config.ok()) << "loaded:\n" << text;
    const std::string& message = config.error().message;
    const std::string prefix = file.string() + ":" + std::to_string(line) + ": " +
                               (key_path.empty() ? "" : key_path + ": ");
    EXPECT_EQ(message.substr(0, prefix.size()), prefix) << message;
    EXPECT_NE(message.find(what), std::string::npos) << message << "\ndoes not say: " << what;
  }
};

TEST_F(ConfigErrors, UnknownKeyNamesItsPathAndLine) {
  expectError(
      "gps:\n"
      "  serial:\n"
      "    device: /dev/ttyUSB0\n"
      "    bad_key: 1\n",
      4, "gps.serial.bad_key", "unknown key (known here: device, baud,");
  expectError("gps:\n  serial:\n    buad: 9600\n", 3, "gps.serial.buad",
              "unknown key (did you mean 'baud'?)");
  expectError("# a comment\ncamera:\n  driver: sim\n", 2, "camera",
              "unknown key (did you mean 'cameras'?)");
  expectError("pipeline:\n  traits:\n    alhpa: 0.3\n", 3, "pipeline.traits.alhpa",
              "did you mean 'alpha'?");
}

TEST_F(ConfigErrors, WrongTypeNamesWhatWasExpectedAndFound) {
  expectError("gps:\n  serial:\n    baud: fast\n", 3, "gps.serial.baud",
              "expected an integer, got 'fast'");
  expectError("gps:\n  latency_s: \"0.05\"\n", 2, "gps.latency_s",
              "expected a number, got the string \"0.05\"");
  expectError("cameras: [a, b]\n", 1, "cameras", "expected a map of keys, got a list");
  expectError("cameras:\n  heads: {bottom: 1}\n", 2, "cameras.heads", "expected a list, got a map");
  expectError("pipeline:\n  enabled: maybe\n", 2, "pipeline.enabled",
              "expected true or false, got 'maybe'");
  expectError("cameras:\n  width: 1624.5\n", 2, "cameras.width", "expected an integer");
  expectError("status:\n  port:\n", 2, "status.port", "expected an integer, got nothing");
  expectError("cameras:\n  options:\n    delay_ms: [1, 2]\n", 3, "cameras.options.delay_ms",
              "expected a single value, got a list");
  expectError("- gps\n- cameras\n", 1, "", "expected a map of sections");
}

TEST_F(ConfigErrors, OutOfRangeValuesAreRefused) {
  expectError(
      "# field run\n"
      "gps:\n"
      "  serial:\n"
      "    baud: 1234\n",
      4, "gps.serial.baud",
      "1234 is not a standard baud rate (4800, 9600, 19200, 38400, 57600 or 115200)");
  expectError("pipeline:\n  matcher:\n    block_size: 5\n    num_disparities: 100\n", 4,
              "pipeline.matcher.num_disparities", "100 is not a positive multiple of 16");
  expectError("pipeline:\n  matcher:\n    num_disparities: -16\n", 3,
              "pipeline.matcher.num_disparities", "not a positive multiple of 16");
  expectError("pipeline:\n  matcher:\n    block_size: 4\n", 3, "pipeline.matcher.block_size",
              "4 is even");
  expectError("pipeline:\n  cloud:\n    scale: 1.5\n", 3, "pipeline.cloud.scale",
              "1.5 is out of range (0, 1]");
  expectError("pipeline:\n  cloud:\n    scale: 0\n", 3, "pipeline.cloud.scale",
              "0 is out of range (0, 1]");
  expectError("pipeline:\n  cloud:\n    min_depth_m: 2\n    max_depth_m: 1.5\n", 3,
              "pipeline.cloud.min_depth_m",
              "the depth crop must satisfy min_depth_m (2) < max_depth_m (1.5)");
  expectError("pipeline:\n  cloud:\n    edge_max_jump_px: -1\n", 3,
              "pipeline.cloud.edge_max_jump_px", "must not be negative");
  expectError("status:\n  port: 65536\n", 2, "status.port", "65536 is out of range (0 … 65535)");
  expectError("gps:\n  planner:\n    late_tolerance_m: -0.1\n", 3, "gps.planner.late_tolerance_m",
              "-0.1 must not be negative");
  expectError("gps:\n  planner:\n    cross_track_tolerance_m: 0\n", 3,
              "gps.planner.cross_track_tolerance_m", "must be positive");
  expectError("gps:\n  serial:\n    reopen_initial_ms: 500\n    reopen_max_ms: 100\n", 4,
              "gps.serial.reopen_max_ms", "reopen_initial_ms (500) <= reopen_max_ms (100)");
  expectError("pipeline:\n  traits:\n    alpha: 1.5\n", 3, "pipeline.traits.alpha",
              "1.5 is out of range [0, 1)");
  expectError("pipeline:\n  traits:\n    crop_z_min_m: 2\n", 3, "pipeline.traits.crop_z_min_m",
              "crop_z_min_m (2) < crop_z_max_m (1.7)");
  expectError("cameras:\n  pixel_format: RGB8\n", 2, "cameras.pixel_format",
              "'RGB8' is not one of Mono8, BayerRG8");
  expectError("cameras:\n  trigger: hardware\n", 2, "cameras.trigger",
              "'hardware' is not one of software or external");
  expectError("recording:\n  fsync: always\n", 2, "recording.fsync",
              "'always' is not one of none, per_set or per_frame");
  expectError("pipeline:\n  matcher:\n    mode: bm\n", 3, "pipeline.matcher.mode",
              "'bm' is not one of sgbm, hh, sgbm_3way or hh4");
  expectError("log:\n  level: verbose\n", 2, "log.level", "'verbose' is not one of trace");
  expectError("pipeline:\n  matcher:\n    wls: true\n    grow_uniqueness_ratio: 0\n", 3,
              "pipeline.matcher", "grow_uniqueness_ratio needs wls off");
}

// The grow keys cannot join EveryKeyReachesItsField's matcher: it turns WLS on, which they refuse.
TEST(ConfigSections, MatcherGrowKeysReachTheirFields) {
  const core::Result<Config> config = parseConfig(
      "pipeline:\n  matcher: {grow_uniqueness_ratio: 3, grow_confirmed_fraction: 0.25}\n", "inline",
      "/");
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->pipeline.cloud.matcher.grow_uniqueness_ratio, 3);
  EXPECT_DOUBLE_EQ(config->pipeline.cloud.matcher.grow_confirmed_fraction, 0.25);
}

// One policy for numbers (issue 17): finite, and bounded above as well as below, so that a typo
// or a unit mistake is refused at start instead of making the daemon wait, allocate or miss.
TEST_F(ConfigErrors, NumbersBeyondTheirCeilingOrNotFiniteAreRefusedWithTheRange) {
  expectError("gps:\n  latency_s: nan\n", 2, "gps.latency_s", "nan is not a finite number");
  expectError("gps:\n  latency_s: .nan\n", 2, "gps.latency_s", "expected a number, got '.nan'");
  expectError("gps:\n  latency_s: 5\n", 2, "gps.latency_s", "5 is out of range [0, 1]");
  expectError("gps:\n  planner:\n    trigger_lead_s: 1e9\n", 3, "gps.planner.trigger_lead_s",
              "1e9 is out of range [0, 1]");
  expectError("gps:\n  planner:\n    trigger_lead_s: .inf\n", 3, "gps.planner.trigger_lead_s",
              "expected a number, got '.inf'");
  expectError("gps:\n  planner:\n    cross_track_tolerance_m: 1e6\n", 3,
              "gps.planner.cross_track_tolerance_m", "1e6 is out of range (0, 100]");
  expectError("gps:\n  planner:\n    max_fix_age_s: 3600\n", 3, "gps.planner.max_fix_age_s",
              "3600 is out of range (0, 60]");
  expectError("gps:\n  serial:\n    reopen_max_ms: 99999999999\n", 3, "gps.serial.reopen_max_ms",
              "99999999999 is out of range (1 … 3600000)");
  expectError("cameras:\n  pool_sets: 70000\n", 2, "cameras.pool_sets",
              "70000 is out of range (1 … 1024)");
  expectError("cameras:\n  width: 100000\n", 2, "cameras.width",
              "100000 is out of range (1 … 16384)");
  expectError("cameras:\n  frame_timeout_ms: -1\n", 2, "cameras.frame_timeout_ms",
              "-1 is out of range (1 … 60000)");
  expectError("cameras:\n  gain_db: 1e300\n", 2, "cameras.gain_db",
              "1e300 is out of range [-100, 100]");
  expectError("pipeline:\n  queue_sets: 1000000\n", 2, "pipeline.queue_sets",
              "1000000 is out of range (1 … 1024)");
}

// The traits options' own ranges (TraitsOptions::validate) reach the configuration with the key
// and line of the value.
TEST_F(ConfigErrors, TraitsOptionsOutsideTheirRangeNameTheKey) {
  expectError("pipeline:\n  traits:\n    slice_width_quantile: 0.5\n", 3,
              "pipeline.traits.slice_width_quantile", "0.5 is out of range [0, 0.25]");
  expectError("pipeline:\n  traits:\n    slices: 2000000000\n", 3, "pipeline.traits.slices",
              "2000000000 is out of range [0, 1000]");
  expectError("pipeline:\n  traits:\n    depth_map_cell_m: 1e-9\n", 3,
              "pipeline.traits.depth_map_cell_m", "1e-09 is out of range [0.001, 1]");
  expectError("pipeline:\n  traits:\n    icp_iterations: 100000000\n", 3,
              "pipeline.traits.icp_iterations", "is out of range [1, 1000]");
  expectError("pipeline:\n  traits:\n    outlier_stddev_mul: 1e9\n", 3,
              "pipeline.traits.outlier_stddev_mul", "is out of range [0, 100]");
  expectError("pipeline:\n  traits:\n    row_length_m: 1e6\n", 3, "pipeline.traits.row_length_m",
              "is out of range [0.01, 100]");
  expectError("pipeline:\n  traits:\n    row_length_m: -1\n", 3, "pipeline.traits.row_length_m",
              "must be positive");
}

TEST_F(ConfigErrors, WrongNumberOfCameraIds) {
  expectError(
      "cameras:\n"
      "  driver: dc1394\n"
      "  ids: [a1, a2, a3, a4]\n",
      3, "cameras.ids",
      "4 ids for 6 cameras: one id per camera, in rig order (bottom_left, bottom_right, "
      "middle_left, middle_right, top_left, top_right)");
  // The count follows the heads, whichever comes first in the file.
  expectError(
      "cameras:\n"
      "  ids: ['0', '1', '2', '3', '4', '5']\n"
      "  heads: [low, high]\n",
      2, "cameras.ids", "6 ids for 4 cameras");
  expectError("cameras:\n  ids:\n    - a\n    - b\n    - a\n", 5, "cameras.ids[2]",
              "camera id 'a' is given twice");
  expectError("cameras:\n  heads: [low, low]\n", 2, "cameras.heads[1]", "named twice");
  expectError("cameras:\n  heads: []\n", 2, "cameras.heads", "0 heads; a rig has 1 to 4");
}

TEST_F(ConfigErrors, RepeatedKeyAndSecondDocument) {
  expectError("status:\n  port: 1\n  port: 2\n", 3, "status.port", "given twice (first on line 2)");
  expectError("status:\n  port: 1\n---\nlog:\n  level: info\n", 4, "", "a second YAML document");
}

TEST_F(ConfigErrors, YamlSyntaxErrorNamesFileAndLine) {
  expectError(
      "gps:\n"
      "  serial:\n"
      "    baud: 9600\n"
      "   device: /dev/ttyUSB0\n",
      4, "", "YAML syntax error: ");
  expectError(
      "status:\n"
      "  port: 8470\n"
      "cameras:\n"
      "  ids: [a, b\n",
      5, "", "YAML syntax error: end of sequence flow not found");
}

TEST_F(ConfigErrors, MissingFileSaysItCannotBeOpened) {
  const fs::path missing = dir_ / "nowhere.yaml";
  const core::Result<Config> config = loadConfig(missing);
  ASSERT_FALSE(config.ok());
  EXPECT_EQ(config.error().message,
            missing.string() + ": cannot open: " + std::generic_category().message(ENOENT));

  const core::Result<Config> folder = loadConfig(dir_.path());
  ASSERT_FALSE(folder.ok());
  EXPECT_EQ(folder.error().message, dir_.path().string() + ": cannot open: it is a folder");
}

// --- (c) Relative paths follow the file
// ------------------------------------------------------------

TEST(ConfigPaths, RelativePathsResolveAgainstTheFilesFolder) {
  ScopedTempDir dir("config_paths");
  const fs::path file = writeFile(dir / "site/run.yaml",
                                  "map: field/map.csv\n"
                                  "calibration: ../calib\n"
                                  "recording: {dir: sessions/today}\n"
                                  "outputs: {dir: ./results}\n"
                                  "replay:\n"
                                  "  nmea: /dev/pts/3\n"
                                  "  session: field/source-session\n"
                                  "log: {file: log/fieldrigd.log}\n");
  const core::Result<Config> config = loadConfig(file);
  ASSERT_TRUE(config.ok()) << config.error().message;
  const fs::path site = dir.path() / "site";
  EXPECT_EQ(config->map, (site / "field/map.csv").lexically_normal());
  EXPECT_EQ(config->calibration, (dir.path() / "calib").lexically_normal());
  EXPECT_EQ(config->recording.dir, (site / "sessions/today").lexically_normal());
  EXPECT_EQ(config->outputs.dir, (site / "results").lexically_normal());
  EXPECT_EQ(config->replay.nmea, fs::path("/dev/pts/3"));  // a device stays where it is
  EXPECT_EQ(config->replay.session, (site / "field/source-session").lexically_normal());
  EXPECT_EQ(config->log.file, (site / "log/fieldrigd.log").lexically_normal());
}

TEST(ConfigPaths, ParsedTextResolvesAgainstTheGivenFolderAndEmptyStaysEmpty) {
  const core::Result<Config> config =
      parseConfig("map: maps/field.csv\ncalibration: /etc/fieldrig/calib\noutputs: {dir: ''}\n",
                  "inline", "/srv/fieldrig");
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->map, fs::path("/srv/fieldrig/maps/field.csv"));
  EXPECT_EQ(config->calibration, fs::path("/etc/fieldrig/calib"));
  EXPECT_TRUE(config->outputs.dir.empty());

  const core::Result<Config> bad = parseConfig("map: [a]\n", "inline", "/srv/fieldrig");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message.rfind("inline:1: map: expected a text value, got a list", 0), 0U)
      << bad.error().message;
}

// Found by the config fuzzer: yaml-cpp 0.7 never returned from a NUL byte inside a flow map.
// Control characters are refused before yaml-cpp sees the text, naming the line and the byte.
TEST(ConfigText, ControlCharactersAreRefusedNamingTheLine) {
  const std::string with_nul = std::string("pipeline:\n  matcher: {mode: sg") + '\0' + "bm}\n";
  const core::Result<Config> nul = parseConfig(with_nul, "inline", "/srv/fieldrig");
  ASSERT_FALSE(nul.ok());
  EXPECT_EQ(nul.error().message,
            "inline:2: a control character (0x00) in the text; YAML allows none but tab and line "
            "breaks");
  const core::Result<Config> escape = parseConfig("log: {level: \x1b[31m}\n", "inline", "/srv");
  ASSERT_FALSE(escape.ok());
  EXPECT_EQ(escape.error().message.rfind("inline:1: a control character (0x1b)", 0), 0U)
      << escape.error().message;
  // Tabs in comments and CRLF line ends are text.
  EXPECT_TRUE(parseConfig("# a\tcomment\r\nlog: {level: info}\r\n", "inline", "/srv").ok());
}

// Found by the traits options fuzzer: yaml-cpp 0.7's LoadAll never returned from a ',' outside a
// flow collection. Such text is a syntax error naming its line.
TEST(ConfigText, AStrayCommaIsASyntaxErrorNamingTheLine) {
  for (const auto& [text, line] : {std::pair<std::string, int>{",", 1}, {"- a\n,\n", 2}}) {
    const core::Result<Config> config = parseConfig(text, "inline", "/srv");
    ASSERT_FALSE(config.ok()) << text;
    EXPECT_EQ(config.error().message,
              "inline:" + std::to_string(line) +
                  ": YAML syntax error: text outside any value (a stray ',')")
        << text;
  }
}

// --- (d) Defaults
// ------------------------------------------------------------------------------------

TEST(ConfigDefaults, AnEmptyFileGivesTheStructsDefaults) {
  ScopedTempDir dir("config_defaults");
  for (const std::string& text : {std::string(), std::string("# nothing set\n"),
                                  std::string("gps:\n  # serial:\n  #   device: /dev/ttyUSB0\n"
                                              "cameras:\nreplay:\n")}) {
    SCOPED_TRACE(text);
    const core::Result<Config> config = loadConfig(writeFile(dir / "empty.yaml", text));
    ASSERT_TRUE(config.ok()) << config.error().message;
    expectDefaults(*config);
    // The rig's cameras are filled even so: the default (sim) rig, with its camera indices.
    ASSERT_EQ(config->cameras.rig.cameras.size(), 6U);
    for (std::size_t i = 0; i < 6; ++i) {
      drivers::CameraConfig expected;
      expected.id = std::to_string(i);
      expectSame(config->cameras.rig.cameras[i], expected);
    }
  }
}

// --- Cameras
// ------------------------------------------------------------------------------------------

TEST(ConfigCameras, EveryCameraGetsTheSharedSettingsAndItsId) {
  const core::Result<Config> config = parseConfig(
      "cameras:\n"
      "  driver: sim\n"
      "  heads: [low, high]\n"
      "  width: 812\n"
      "  height: 612\n"
      "  pixel_format: BayerGB8\n"
      "  exposure_us: 1500\n"
      "  gain_db: 3.5\n"
      "  white_balance: [1.25, 1.5]\n"
      "  trigger: external\n"
      "  frame_timeout_ms: 250\n"
      "  max_skew_us: 500\n"
      "  pool_sets: 4\n"
      "  options: {delay_ms: 5, session: 'runs/a b'}\n",
      "inline", "/data");
  ASSERT_TRUE(config.ok()) << config.error().message;
  const drivers::RigOptions& rig = config->cameras.rig;
  EXPECT_EQ(config->cameras.layout.cameraNames(),
            (std::vector<std::string>{"low_left", "low_right", "high_left", "high_right"}));
  EXPECT_EQ(rig.frame_timeout, std::chrono::milliseconds{250});
  EXPECT_EQ(rig.max_skew, std::chrono::microseconds{500});
  EXPECT_EQ(rig.pool_sets, 4U);
  ASSERT_EQ(rig.cameras.size(), 4U);
  for (std::size_t i = 0; i < rig.cameras.size(); ++i) {
    drivers::CameraConfig expected;
    expected.id = std::to_string(i);
    expected.width = 812;
    expected.height = 612;
    expected.format = core::PixelFormat::kBayerGB8;
    expected.exposure_us = 1500;
    expected.gain_db = 3.5;
    expected.white_balance = std::make_pair(1.25, 1.5);
    expected.trigger = drivers::TriggerSource::kExternal;
    expected.options = {{"delay_ms", "5"}, {"session", "runs/a b"}};
    expectSame(rig.cameras[i], expected);
  }
}

TEST(ConfigCameras, HardwareDriverIdsInRigOrder) {
  const core::Result<Config> config = parseConfig(
      "cameras:\n  driver: dc1394\n  ids: [0800461000821fa2, b, c, d, e, '0x00b09d01']\n", "inline",
      "/");
  ASSERT_TRUE(config.ok()) << config.error().message;
  const std::vector<drivers::CameraConfig>& cameras = config->cameras.rig.cameras;
  ASSERT_EQ(cameras.size(), 6U);
  EXPECT_EQ(cameras[0].id, "0800461000821fa2");  // a GUID stays text, leading zero and all
  EXPECT_EQ(cameras[3].id, "d");
  EXPECT_EQ(cameras[5].id, "0x00b09d01");

  // Without ids a hardware driver's cameras are there, unnamed: the driver refuses them.
  const core::Result<Config> unnamed = parseConfig("cameras: {driver: aravis}\n", "inline", "/");
  ASSERT_TRUE(unnamed.ok()) << unnamed.error().message;
  ASSERT_EQ(unnamed->cameras.rig.cameras.size(), 6U);
  for (const drivers::CameraConfig& camera : unnamed->cameras.rig.cameras)
    EXPECT_TRUE(camera.id.empty());
}

// --- Every section's keys reach their fields
// -----------------------------------------------------------

TEST(ConfigSections, EveryKeyReachesItsField) {
  const core::Result<Config> config = parseConfig(
      "gps:\n"
      "  serial: {device: /dev/ttyS1, baud: 9600, reopen_initial_ms: 50, reopen_max_ms: 800}\n"
      "  latency_s: 0.03\n"
      "  planner:\n"
      "    cross_track_tolerance_m: 0.4\n"
      "    heading_tolerance_deg: 45\n"
      "    min_speed_mps: 0.5\n"
      "    max_fix_age_s: 0.4\n"
      "    max_fix_gap_s: 0.6\n"
      "    min_trigger_interval_s: 0.2\n"
      "    late_tolerance_m: 0.25\n"
      "    rearm_distance_m: 4\n"
      "    fit_window_s: 1.5\n"
      "    fit_residual_limit_m: 0.04\n"
      "    trigger_lead_s: 0.01\n"
      "    motion_model: constant_velocity_fit\n"
      "    kalman_jerk_density: 0.25\n"
      "    kalman_position_sd_m: 0.02\n"
      "    kalman_velocity_sd_mps: 0.03\n"
      "recording: {dir: /rec, fsync: per_frame}\n"
      "pipeline:\n"
      "  enabled: false\n"
      "  queue_sets: 3\n"
      "  cloud: {scale: 0.25, min_depth_m: 0.3, max_depth_m: 2.5, edge_max_jump_px: 3.5,\n"
      "          edge_keep_near_side: true}\n"
      "  matcher:\n"
      "    num_disparities: 64\n"
      "    min_disparity: -8\n"
      "    block_size: 7\n"
      "    p1_per_pixel: 4\n"
      "    p2_per_pixel: 16\n"
      "    pre_filter_cap: 31\n"
      "    uniqueness_ratio: 5\n"
      "    speckle_window: 50\n"
      "    speckle_range: 1\n"
      "    disp12_max_diff: -1\n"
      "    lr_check: true\n"
      "    lr_max_diff: 1.5\n"
      "    wls: yes\n"
      "    wls_lambda: 4000\n"
      "    wls_sigma: 1.2\n"
      "    mode: hh4\n"
      "    match_colour: true\n"
      "    full_width: false\n"
      "    min_texture: 3.5\n"
      "outputs: {csv: false, geojson: false, jsonl: false}\n"
      "status: {enabled: false, address: 0.0.0.0, port: 9000}\n"
      "replay: {realtime: true}\n"
      "log: {level: debug}\n",
      "inline", "/");
  ASSERT_TRUE(config.ok()) << config.error().message;
  const Config& c = *config;
  EXPECT_EQ(c.gps.serial.device, "/dev/ttyS1");
  EXPECT_EQ(c.gps.serial.baud, 9600U);
  EXPECT_EQ(c.gps.serial.reopen_initial_delay, std::chrono::milliseconds{50});
  EXPECT_EQ(c.gps.serial.reopen_max_delay, std::chrono::milliseconds{800});
  gps::TriggerChainOptions triggers;
  triggers.latency_s = 0.03;
  triggers.planner.cross_track_tolerance_m = 0.4;
  triggers.planner.heading_tolerance_deg = 45;
  triggers.planner.min_speed_mps = 0.5;
  triggers.planner.max_fix_age_s = 0.4;
  triggers.planner.max_fix_gap_s = 0.6;
  triggers.planner.min_trigger_interval_s = 0.2;
  triggers.planner.late_tolerance_m = 0.25;
  triggers.planner.rearm_distance_m = 4;
  triggers.planner.fit_window_s = 1.5;
  triggers.planner.fit_residual_limit_m = 0.04;
  triggers.planner.trigger_lead_s = 0.01;
  triggers.planner.motion_model = gps::MotionModel::kConstantVelocityFit;
  triggers.planner.kalman_jerk_density = 0.25;
  triggers.planner.kalman_position_sd_m = 0.02;
  triggers.planner.kalman_velocity_sd_mps = 0.03;
  expectSame(c.gps.triggers, triggers);
  EXPECT_EQ(c.recording.dir, fs::path("/rec"));
  EXPECT_EQ(c.recording.writer.fsync, recording::FsyncPolicy::kPerFrame);
  EXPECT_FALSE(c.pipeline.enabled);
  EXPECT_EQ(c.pipeline.queue_sets, 3U);
  stereo::MatcherOptions matcher;
  matcher.num_disparities = 64;
  matcher.min_disparity = -8;
  matcher.block_size = 7;
  matcher.p1_per_pixel = 4;
  matcher.p2_per_pixel = 16;
  matcher.pre_filter_cap = 31;
  matcher.uniqueness_ratio = 5;
  matcher.speckle_window = 50;
  matcher.speckle_range = 1;
  matcher.disp12_max_diff = -1;
  matcher.lr_check = true;
  matcher.lr_max_diff = 1.5f;
  matcher.wls = true;
  matcher.wls_lambda = 4000;
  matcher.wls_sigma = 1.2;
  matcher.mode = cv::StereoSGBM::MODE_HH4;
  matcher.match_colour = true;
  matcher.full_width = false;
  matcher.min_texture = 3.5;
  cloud::CloudOptions cloud_options;
  cloud_options.scale = 0.25;
  cloud_options.min_depth_m = 0.3;
  cloud_options.max_depth_m = 2.5;
  cloud_options.edge_max_jump_px = 3.5;
  cloud_options.edge_keep_near_side = true;
  cloud_options.matcher = matcher;
  expectSame(c.pipeline.cloud, cloud_options);
  EXPECT_FALSE(c.outputs.csv);
  EXPECT_FALSE(c.outputs.geojson);
  EXPECT_FALSE(c.outputs.jsonl);
  EXPECT_FALSE(c.status.enabled);
  EXPECT_EQ(c.status.address, "0.0.0.0");
  EXPECT_EQ(c.status.port, 9000);
  EXPECT_TRUE(c.replay.realtime);
  EXPECT_EQ(c.log.level, "debug");
}

// --- (e) Traits options files
// ---------------------------------------------------------------------

// Every key the JSON loader of earlier versions (traits::traitsOptionsFromJson) reads.
constexpr const char* kEarlierJson = R"({
  "voxel_leaf_m": 0.02,
  "outlier_mean_k": 30,
  "outlier_stddev_mul": 1.5,
  "outlier_min_neighbours": 3,
  "outlier_method": "statistical",
  "crop_z_max_m": 2.0,
  "crop_z_min_m": 0.2,
  "template_strip_m": 0.25,
  "template_step_m": 0.02,
  "icp_coarse_distance_m": 0.35,
  "icp_fine_distance_m": 0.02,
  "icp_iterations": 12,
  "max_ground_tilt_deg": 12.5,
  "ground_margin_m": 0.015,
  "ground_tilt_deg": 8,
  "row_length_m": 3.0,
  "intra_row_spacing_m": 0.2,
  "slices": 24,
  "alpha": 0.25,
  "area_method": "paper_mls_gpt",
  "depth_map_cell_m": 0.015,
  "camera_to_plot": [[0, -1, 0], [1, 0, 0], [0, 0, -1]]
}
)";

TEST(TraitsOptionsFile, JsonOfEarlierVersionsLoadsAsTheJsonLoaderReadsIt) {
  ScopedTempDir dir("config_traits_json");
  const fs::path file = writeFile(dir / "traits.json", kEarlierJson);
  const core::Result<traits::TraitsOptions> loaded = loadTraitsOptions(file);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  EXPECT_DOUBLE_EQ(loaded->voxel_leaf_m, 0.02);
  EXPECT_EQ(loaded->outlier_mean_k, 30);
  EXPECT_DOUBLE_EQ(loaded->outlier_stddev_mul, 1.5);
  EXPECT_EQ(loaded->outlier_min_neighbours, 3);
  EXPECT_DOUBLE_EQ(loaded->crop_z_max_m, 2.0);
  EXPECT_DOUBLE_EQ(loaded->crop_z_min_m, 0.2);
  EXPECT_DOUBLE_EQ(loaded->template_strip_m, 0.25);
  EXPECT_DOUBLE_EQ(loaded->template_step_m, 0.02);
  EXPECT_DOUBLE_EQ(loaded->icp_coarse_distance_m, 0.35);
  EXPECT_DOUBLE_EQ(loaded->icp_fine_distance_m, 0.02);
  EXPECT_EQ(loaded->icp_iterations, 12);
  EXPECT_DOUBLE_EQ(loaded->max_ground_tilt_deg, 12.5);
  EXPECT_DOUBLE_EQ(loaded->ground_margin_m, 0.015);
  EXPECT_DOUBLE_EQ(loaded->ground_tilt_deg, 8.0);
  EXPECT_DOUBLE_EQ(loaded->row_length_m, 3.0);
  EXPECT_DOUBLE_EQ(loaded->intra_row_spacing_m, 0.2);
  EXPECT_DOUBLE_EQ(loaded->alpha, 0.25);
  EXPECT_DOUBLE_EQ(loaded->depth_map_cell_m, 0.015);
  EXPECT_EQ(loaded->area_method, traits::AreaMethod::kPaperMlsGpt);
  EXPECT_EQ(loaded->outlier_method, traits::OutlierMethod::kStatistical);
  EXPECT_EQ(loaded->camera_to_plot(2, 2), -1.0);
  EXPECT_EQ(loaded->slices, 24);

  // Errors in the same form: file, line, key.
  const fs::path typo = writeFile(dir / "typo.json", "{\n  \"slices\": 12,\n  \"alhpa\": 0.2\n}\n");
  const core::Result<traits::TraitsOptions> bad = loadTraitsOptions(typo);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, typo.string() + ":3: alhpa: unknown key (did you mean 'alpha'?)");
  const fs::path typed = writeFile(dir / "typed.json", "{\"slices\": \"twenty\"}");
  const core::Result<traits::TraitsOptions> ill = loadTraitsOptions(typed);
  ASSERT_FALSE(ill.ok());
  EXPECT_EQ(ill.error().message,
            typed.string() + ":1: slices: expected an integer, got the string \"twenty\"");
}

TEST(TraitsOptionsFile, YamlFileLoadsEveryField) {
  ScopedTempDir dir("config_traits_yaml");
  const fs::path file = writeFile(dir / "tall-sorghum.yaml",
                                  "# traits for tall sorghum\n"
                                  "camera_to_plot:\n"
                                  "  - [1, 0, 0]\n"
                                  "  - [0, 1, 0]\n"
                                  "  - [0, 0, 1]\n"
                                  "voxel_leaf_m: 0.015\n"
                                  "outlier_method: statistical\n"
                                  "outlier_mean_k: 40\n"
                                  "outlier_stddev_mul: 2\n"
                                  "outlier_min_neighbours: 4\n"
                                  "min_piece_voxels: 40\n"
                                  "crop_z_max_m: 2.2\n"
                                  "crop_z_min_m: 0.1\n"
                                  "max_abs_coordinate_m: 500\n"
                                  "template_strip_m: 0.35\n"
                                  "template_step_m: 0.01\n"
                                  "icp_target_leaf_m: 0.03\n"
                                  "icp_coarse_distance_m: 0.4\n"
                                  "icp_fine_distance_m: 0\n"
                                  "icp_iterations: 20\n"
                                  "max_ground_tilt_deg: 20\n"
                                  "ground_tilt_limit_deg: 6\n"
                                  "ground_margin_m: 0.02\n"
                                  "row_base_band_m: 0.1\n"
                                  "ground_tilt_deg: 12\n"
                                  "row_length_m: 3\n"
                                  "intra_row_spacing_m: 0.1\n"
                                  "slices: 30\n"
                                  "slice_width_quantile: 0.03\n"
                                  "width_band_m: 0.6\n"
                                  "min_row_extent_m: 0.1\n"
                                  "min_plant_points: 80\n"
                                  "alpha: 0.35\n"
                                  "alpha_near_margin: 0.02\n"
                                  "area_method: paper\n"
                                  "depth_map_cell_m: 0.02\n"
                                  "depth_map_max_step_m: 0.03\n"
                                  "depth_map_min_fill: 0.5\n"
                                  "mls_radius_m: 0.04\n"
                                  "gpt_radius_m: 0.06\n"
                                  "gpt_mu: 3\n"
                                  "gpt_max_neighbors: 150\n");
  const core::Result<traits::TraitsOptions> loaded = loadTraitsOptions(file);
  ASSERT_TRUE(loaded.ok()) << loaded.error().message;
  traits::TraitsOptions expected;
  expected.camera_to_plot.setIdentity();
  expected.voxel_leaf_m = 0.015;
  expected.outlier_method = traits::OutlierMethod::kStatistical;
  expected.outlier_mean_k = 40;
  expected.outlier_stddev_mul = 2;
  expected.outlier_min_neighbours = 4;
  expected.min_piece_voxels = 40;
  expected.crop_z_max_m = 2.2;
  expected.crop_z_min_m = 0.1;
  expected.max_abs_coordinate_m = 500;
  expected.template_strip_m = 0.35;
  expected.template_step_m = 0.01;
  expected.icp_target_leaf_m = 0.03;
  expected.icp_coarse_distance_m = 0.4;
  expected.icp_fine_distance_m = 0;
  expected.icp_iterations = 20;
  expected.max_ground_tilt_deg = 20;
  expected.ground_tilt_limit_deg = 6;
  expected.ground_margin_m = 0.02;
  expected.row_base_band_m = 0.1;
  expected.ground_tilt_deg = 12;
  expected.row_length_m = 3;
  expected.intra_row_spacing_m = 0.1;
  expected.slices = 30;
  expected.slice_width_quantile = 0.03;
  expected.width_band_m = 0.6;
  expected.min_row_extent_m = 0.1;
  expected.min_plant_points = 80;
  expected.alpha = 0.35;
  expected.alpha_near_margin = 0.02;
  expected.area_method = traits::AreaMethod::kPaperMlsGpt;
  expected.depth_map_cell_m = 0.02;
  expected.depth_map_max_step_m = 0.03;
  expected.depth_map_min_fill = 0.5;
  expected.mls_radius_m = 0.04;
  expected.gpt_radius_m = 0.06;
  expected.gpt_mu = 3;
  expected.gpt_max_neighbors = 150;
  expectSame(*loaded, expected);

  // The same keys under pipeline.traits of the main file.
  const core::Result<Config> config =
      parseConfig("pipeline:\n  traits:\n    area_method: none\n    slices: 6\n", "inline", "/");
  ASSERT_TRUE(config.ok()) << config.error().message;
  EXPECT_EQ(config->pipeline.traits.area_method, traits::AreaMethod::kNone);
  EXPECT_EQ(config->pipeline.traits.slices, 6);

  const fs::path bad = writeFile(dir / "bad.yaml", "slices: 6\ncamera_to_plot: [[1, 0], [0, 1]]\n");
  const core::Result<traits::TraitsOptions> not_3x3 = loadTraitsOptions(bad);
  ASSERT_FALSE(not_3x3.ok());
  EXPECT_EQ(not_3x3.error().message.rfind(bad.string() + ":2: camera_to_plot: expected 3 rows", 0),
            0U)
      << not_3x3.error().message;

  // A traits file alone gets the same ranges, named by key and line.
  const fs::path huge = writeFile(dir / "huge.yaml", "alpha: 0.3\nslices: 2000000000\n");
  const core::Result<traits::TraitsOptions> too_many = loadTraitsOptions(huge);
  ASSERT_FALSE(too_many.ok());
  EXPECT_EQ(too_many.error().message,
            huge.string() + ":2: slices: 2000000000 is out of range [0, 1000]");

  const core::Result<traits::TraitsOptions> missing = loadTraitsOptions(dir / "none.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("none.yaml: cannot open: "), std::string::npos);
}

}  // namespace
}  // namespace fieldrig::config
