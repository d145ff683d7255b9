#include "fieldrig/config/config.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string_view>
#include <system_error>
#include <utility>

#include "fieldrig/core/frame.h"
#include "fieldrig/core/pixel_format.h"
#include "traits_reader.h"
#include "yaml_reader.h"

namespace fieldrig::config {
namespace {

using namespace detail;  // NOLINT(google-build-using-namespace): the reader machinery

// --- Sections ---------------------------------------------------------------------------------

constexpr unsigned kStandardBaudRates[] = {4800, 9600, 19200, 38400, 57600, 115200};

// Ceilings shared by several keys: an hour between serial retries, a minute for anything the
// trigger chain or a camera waits for, a second of lead or latency (a plot is passed in ~2 s).
constexpr std::int64_t kMaxRetryMs = 3'600'000;
constexpr std::int64_t kMaxFrameTimeoutMs = 60'000;
constexpr double kMaxWaitS = 60;
constexpr double kMaxLeadS = 1;
// As `fieldrig acquire`: the largest machine-vision sensors are ~14k pixels wide, and the frame
// pool's own budget check refuses what does not fit in memory.
constexpr int kMaxFrameSide = 16384;
constexpr std::int64_t kMaxPoolSets = 1024;

void readSerial(const Value& section, gps::SerialOptions& serial) {
  const Entries entries = readMap(
      section,
      {
          {"device", [&](const Value& v) { serial.device = v.text(); }},
          {"baud",
           [&](const Value& v) {
             const std::int64_t baud = v.integer();
             const bool standard = std::any_of(
                 std::begin(kStandardBaudRates), std::end(kStandardBaudRates),
                 [baud](unsigned rate) { return static_cast<std::int64_t>(rate) == baud; });
             if (!standard) {
               v.fail(v.node().Scalar() +
                      " is not a standard baud rate (4800, 9600, 19200, 38400, 57600 or 115200)");
             }
             serial.baud = static_cast<unsigned>(baud);
           }},
          {"reopen_initial_ms",
           [&](const Value& v) {
             serial.reopen_initial_delay =
                 std::chrono::milliseconds{readIntegerIn(v, 1, kMaxRetryMs)};
           }},
          {"reopen_max_ms",
           [&](const Value& v) {
             serial.reopen_max_delay = std::chrono::milliseconds{readIntegerIn(v, 1, kMaxRetryMs)};
           }},
      });
  if (serial.reopen_max_delay < serial.reopen_initial_delay) {
    const Value& at = entries.contains("reopen_max_ms")
                          ? entries.at("reopen_max_ms")
                          : entryOr(entries, "reopen_initial_ms", section);
    at.fail("the reopen delays must satisfy reopen_initial_ms (" +
            std::to_string(serial.reopen_initial_delay.count()) + ") <= reopen_max_ms (" +
            std::to_string(serial.reopen_max_delay.count()) + ")");
  }
}

void readPlanner(const Value& section, gps::TriggerOptions& o) {
  readMap(section,
          {
              {"cross_track_tolerance_m", positive(o.cross_track_tolerance_m, 100)},
              {"heading_tolerance_deg", numberIn(o.heading_tolerance_deg, 0, 180)},
              {"min_speed_mps", nonNegative(o.min_speed_mps, 50)},
              {"max_fix_age_s", positive(o.max_fix_age_s, kMaxWaitS)},
              {"max_fix_gap_s", positive(o.max_fix_gap_s, kMaxWaitS)},
              {"min_trigger_interval_s", nonNegative(o.min_trigger_interval_s, kMaxWaitS)},
              {"late_tolerance_m", nonNegative(o.late_tolerance_m, 100)},
              {"rearm_distance_m", nonNegative(o.rearm_distance_m, 1000)},
              {"fit_window_s", positive(o.fit_window_s, kMaxWaitS)},
              {"fit_residual_limit_m", positive(o.fit_residual_limit_m, 100)},
              {"trigger_lead_s", nonNegative(o.trigger_lead_s, kMaxLeadS)},
              {"motion_model",
               choice(o.motion_model,
                      Names<gps::MotionModel>{
                          {"kalman", gps::MotionModel::kKalman},
                          {"constant_velocity_fit", gps::MotionModel::kConstantVelocityFit},
                      })},
              {"kalman_jerk_density", positive(o.kalman_jerk_density, 1000)},
              {"kalman_position_sd_m", positive(o.kalman_position_sd_m, 100)},
              {"kalman_velocity_sd_mps", positive(o.kalman_velocity_sd_mps, 100)},
          });
}

void readGps(const Value& section, GpsConfig& gps) {
  readMap(section, {
                       {"serial", [&](const Value& v) { readSerial(v, gps.serial); }},
                       {"latency_s", nonNegative(gps.triggers.latency_s, kMaxLeadS)},
                       {"planner", [&](const Value& v) { readPlanner(v, gps.triggers.planner); }},
                   });
}

// Head names become camera names ("bottom_left") and calibration folder names.
std::vector<std::string> readHeads(const Value& v) {
  const std::vector<Value> items = v.list();
  constexpr std::size_t kMaxHeads = core::FrameSet::kMaxCameras / 2;
  if (items.empty() || items.size() > kMaxHeads) {
    v.fail(std::to_string(items.size()) + " heads; a rig has 1 to " + std::to_string(kMaxHeads));
  }
  std::vector<std::string> heads;
  for (const Value& item : items) {
    const std::string name = readNonEmptyText(item);
    const bool usable = std::all_of(name.begin(), name.end(), [](unsigned char c) {
      return std::isalnum(c) || c == '_' || c == '-';
    });
    if (!usable) {
      item.fail("'" + name +
                "' is not a usable head name (letters, digits, '_' and '-'; it names folders)");
    }
    if (std::find(heads.begin(), heads.end(), name) != heads.end())
      item.fail("head '" + name + "' is named twice");
    heads.push_back(name);
  }
  return heads;
}

std::map<std::string, std::string> readCameraOptions(const Value& section) {
  std::map<std::string, std::string> options;
  const YAML::Node& node = section.node();
  if (node.IsNull())
    return options;
  if (!node.IsMap())
    section.fail("expected a map of driver options, got " + section.describe());
  for (auto it = node.begin(); it != node.end(); ++it) {
    const Value key(section.source(), it->first, section.keyPath(), it->first.Mark());
    const std::string name = readNonEmptyText(key);
    const YAML::Node value_node = it->second;
    const Value value(section.source(), value_node, section.childPath(name),
                      value_node.IsNull() ? it->first.Mark() : value_node.Mark());
    if (options.contains(name))
      value.fail("given twice");
    if (!value_node.IsScalar())
      value.fail("expected a single value, got " + value.describe());
    options[name] = value_node.Scalar();
  }
  return options;
}

void readCameras(const Value& section, CamerasConfig& cameras) {
  drivers::RigOptions& rig = cameras.rig;
  drivers::CameraConfig shared;  // what every camera is configured with, but its id
  std::optional<Value> ids_value;
  std::vector<std::string> ids;
  readMap(section,
          {
              {"driver", [&](const Value& v) { rig.driver = readNonEmptyText(v); }},
              {"heads", [&](const Value& v) { cameras.layout.heads = readHeads(v); }},
              {"ids",
               [&](const Value& v) {
                 ids_value = v;
                 for (const Value& item : v.list()) {
                   const std::string id = readNonEmptyText(item);
                   if (std::find(ids.begin(), ids.end(), id) != ids.end())
                     item.fail("camera id '" + id + "' is given twice");
                   ids.push_back(id);
                 }
               }},
              {"width",
               [&](const Value& v) {
                 shared.width = static_cast<std::uint32_t>(readInt(v, 1, kMaxFrameSide));
               }},
              {"height",
               [&](const Value& v) {
                 shared.height = static_cast<std::uint32_t>(readInt(v, 1, kMaxFrameSide));
               }},
              {"pixel_format",
               [&](const Value& v) {
                 const std::string& name = v.text();
                 const auto format = core::parsePixelFormat(name);
                 if (!format) {
                   v.fail("'" + name +
                          "' is not one of Mono8, BayerRG8, BayerGR8, BayerGB8 or BayerBG8");
                 }
                 shared.format = *format;
               }},
              {"exposure_us", positive(shared.exposure_us, 10'000'000)},
              {"gain_db", numberIn(shared.gain_db, -100, 100)},
              {"white_balance",
               [&](const Value& v) {
                 const std::vector<Value> gains = v.list();
                 if (gains.size() != 2)
                   v.fail("expected two gains [blue, red], got " + std::to_string(gains.size()));
                 shared.white_balance =
                     std::make_pair(readPositive(gains[0], 100), readPositive(gains[1], 100));
               }},
              {"trigger", choice(shared.trigger,
                                 Names<drivers::TriggerSource>{
                                     {"software", drivers::TriggerSource::kSoftware},
                                     {"external", drivers::TriggerSource::kExternal},
                                 })},
              {"frame_timeout_ms",
               [&](const Value& v) {
                 rig.frame_timeout =
                     std::chrono::milliseconds{readIntegerIn(v, 1, kMaxFrameTimeoutMs)};
               }},
              {"max_skew_us",
               [&](const Value& v) {
                 rig.max_skew = std::chrono::microseconds{readIntegerIn(v, 0, 1'000'000)};
               }},
              {"pool_sets",
               [&](const Value& v) {
                 rig.pool_sets = static_cast<std::size_t>(readIntegerIn(v, 1, kMaxPoolSets));
               }},
              {"options", [&](const Value& v) { shared.options = readCameraOptions(v); }},
          });

  const std::size_t count = cameras.layout.cameraCount();
  if (ids_value) {
    if (ids.size() != count) {
      ids_value->fail(std::to_string(ids.size()) + " ids for " + std::to_string(count) +
                      " cameras: one id per camera, in rig order (" +
                      joinNames(cameras.layout.cameraNames(), ", ") + ")");
    }
  } else {
    // The sim driver's ids are camera indices; a hardware driver without ids gets empty ones,
    // which it refuses naming the camera.
    for (std::size_t i = 0; i < count; ++i)
      ids.push_back(rig.driver == "sim" ? std::to_string(i) : std::string());
  }
  rig.cameras.clear();
  for (std::size_t i = 0; i < count; ++i) {
    drivers::CameraConfig camera = shared;
    camera.id = ids[i];
    rig.cameras.push_back(std::move(camera));
  }
}

void readRecording(const Value& section, RecordingConfig& recording) {
  readMap(section, {
                       {"dir", location(recording.dir)},
                       {"fsync",
                        [&](const Value& v) {
                          const std::string& name = v.text();
                          const auto policy = recording::parseFsyncPolicy(name);
                          if (!policy)
                            v.fail("'" + name + "' is not one of none, per_set or per_frame");
                          recording.writer.fsync = *policy;
                        }},
                   });
}

void readMatcher(const Value& section, stereo::MatcherOptions& o) {
  readMap(section,
          {
              {"num_disparities",
               [&](const Value& v) {
                 const int n = readInt(v);
                 if (n <= 0 || n % 16 != 0)
                   v.fail(v.node().Scalar() + " is not a positive multiple of 16");
                 o.num_disparities = n;
               }},
              {"min_disparity", integer(o.min_disparity)},
              {"block_size",
               [&](const Value& v) {
                 const int size = readInt(v, 1);
                 if (size % 2 == 0)
                   v.fail(v.node().Scalar() + " is even; the block size must be odd");
                 o.block_size = size;
               }},
              {"p1_per_pixel", integer(o.p1_per_pixel, 0)},
              {"p2_per_pixel", integer(o.p2_per_pixel, 0)},
              {"pre_filter_cap", integer(o.pre_filter_cap, 0)},
              {"uniqueness_ratio", integer(o.uniqueness_ratio, 0, 100)},
              {"speckle_window", integer(o.speckle_window, 0)},
              {"speckle_range", integer(o.speckle_range, 0)},
              {"disp12_max_diff", integer(o.disp12_max_diff, -1)},
              {"lr_check", flag(o.lr_check)},
              {"lr_max_diff",
               [&](const Value& v) { o.lr_max_diff = static_cast<float>(readNonNegative(v)); }},
              {"wls", flag(o.wls)},
              {"wls_lambda", nonNegative(o.wls_lambda)},
              {"wls_sigma", positive(o.wls_sigma)},
              {"mode", choice(o.mode,
                              Names<int>{
                                  {"sgbm", cv::StereoSGBM::MODE_SGBM},
                                  {"hh", cv::StereoSGBM::MODE_HH},
                                  {"sgbm_3way", cv::StereoSGBM::MODE_SGBM_3WAY},
                                  {"hh4", cv::StereoSGBM::MODE_HH4},
                              })},
              {"match_colour", flag(o.match_colour)},
              {"full_width", flag(o.full_width)},
              {"min_texture", numberIn(o.min_texture, 0, stereo::kMaxMinTexture)},
              {"grow_uniqueness_ratio", integer(o.grow_uniqueness_ratio, -1, 100)},
              {"grow_confirmed_fraction", numberIn(o.grow_confirmed_fraction, 0, 1)},
          });
  // The library's own ranges (and those across keys), so the file and the command line agree.
  if (auto valid = stereo::validate(o); !valid)
    section.fail(valid.error().message);
}
void readCloud(const Value& section, cloud::CloudOptions& o) {
  const Entries entries =
      readMap(section, {
                           {"scale",
                            [&](const Value& v) {
                              const double scale = v.number();
                              if (!(scale > 0 && scale <= 1))
                                v.fail(v.node().Scalar() + " is out of range (0, 1]");
                              o.scale = scale;
                            }},
                           {"min_depth_m", nonNegative(o.min_depth_m)},
                           {"max_depth_m", positive(o.max_depth_m)},
                           {"edge_max_jump_px", nonNegative(o.edge_max_jump_px)},
                           {"edge_keep_near_side", flag(o.edge_keep_near_side)},
                       });
  if (!(o.min_depth_m < o.max_depth_m)) {
    const Value& at = entries.contains("min_depth_m") ? entries.at("min_depth_m")
                                                      : entryOr(entries, "max_depth_m", section);
    at.fail("the depth crop must satisfy min_depth_m (" + formatNumber(o.min_depth_m) +
            ") < max_depth_m (" + formatNumber(o.max_depth_m) + ")");
  }
}

void readPipeline(const Value& section, PipelineConfig& pipeline) {
  readMap(section, {
                       {"enabled", flag(pipeline.enabled)},
                       {"queue_sets",
                        [&](const Value& v) {
                          pipeline.queue_sets =
                              static_cast<std::size_t>(readIntegerIn(v, 1, kMaxPoolSets));
                        }},
                       {"cloud", [&](const Value& v) { readCloud(v, pipeline.cloud); }},
                       {"matcher", [&](const Value& v) { readMatcher(v, pipeline.cloud.matcher); }},
                       {"traits", [&](const Value& v) { readTraits(v, pipeline.traits); }},
                   });
}

void readOutputs(const Value& section, OutputsConfig& outputs) {
  readMap(section, {
                       {"dir", location(outputs.dir)},
                       {"csv", flag(outputs.csv)},
                       {"geojson", flag(outputs.geojson)},
                       {"jsonl", flag(outputs.jsonl)},
                   });
}

void readStatus(const Value& section, StatusConfig& status) {
  readMap(
      section,
      {
          {"enabled", flag(status.enabled)},
          {"address", [&](const Value& v) { status.address = readNonEmptyText(v); }},
          {"port",
           [&](const Value& v) { status.port = static_cast<std::uint16_t>(readInt(v, 0, 65535)); }},
      });
}

void readReplay(const Value& section, ReplayConfig& replay) {
  readMap(section, {
                       {"nmea", location(replay.nmea)},
                       {"realtime", flag(replay.realtime)},
                       {"session", location(replay.session)},
                   });
}

void readLog(const Value& section, LogConfig& log) {
  readMap(section, {
                       {"level",
                        [&](const Value& v) {
                          log.level = std::string(readChoice(v, Names<std::string_view>{
                                                                    {"trace", "trace"},
                                                                    {"debug", "debug"},
                                                                    {"info", "info"},
                                                                    {"warn", "warn"},
                                                                    {"error", "error"},
                                                                }));
                        }},
                       {"file", location(log.file)},
                   });
}

Config readConfig(const Value& root) {
  Config config;
  bool cameras_seen = false;
  readMap(root, {
                    {"gps", [&](const Value& v) { readGps(v, config.gps); }},
                    {"map", location(config.map)},
                    {"cameras",
                     [&](const Value& v) {
                       readCameras(v, config.cameras);
                       cameras_seen = true;
                     }},
                    {"calibration", location(config.calibration)},
                    {"recording", [&](const Value& v) { readRecording(v, config.recording); }},
                    {"pipeline", [&](const Value& v) { readPipeline(v, config.pipeline); }},
                    {"outputs", [&](const Value& v) { readOutputs(v, config.outputs); }},
                    {"status", [&](const Value& v) { readStatus(v, config.status); }},
                    {"replay", [&](const Value& v) { readReplay(v, config.replay); }},
                    {"log", [&](const Value& v) { readLog(v, config.log); }},
                });
  // The rig's cameras are filled from the defaults when the file has no cameras section.
  if (!cameras_seen)
    readCameras(Value(root.source(), YAML::Node(), "cameras", root.mark()), config.cameras);
  return config;
}

}  // namespace

core::Result<Config> parseConfig(const std::string& text, const std::string& origin,
                                 const std::filesystem::path& base_dir) {
  const Source source{origin, base_dir};
  return guarded<Config>(origin, [&] {
    Config config = readConfig(rootValue(source, parseDocument(source, text)));
    config.source = origin;
    return config;
  });
}

core::Result<Config> loadConfig(const std::filesystem::path& file) {
  core::Result<std::string> text = readFile(file);
  if (!text)
    return text.error();
  core::Result<Config> config = parseConfig(*text, file.string(), folderOf(file));
  if (config)
    config->source = file;
  return config;
}

}  // namespace fieldrig::config
