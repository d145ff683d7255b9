#include <opencv2/calib3d.hpp>
#include <opencv2/imgcodecs.hpp>

#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string_view>
#include <vector>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/recording/session_format.h"
#include "fieldrig/recording/session_writer.h"
#include "fieldrig/sim/mesh_renderer.h"
#include "fieldrig/sim/mesh_truth.h"
#include "fieldrig/sim/plot_truth.h"
#include "fieldrig/sim/plot_view_renderer.h"
#include "fieldrig/sim/synthetic_field.h"
#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/disparity_io.h"
#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::sim {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

// Each camera as a calibration finds it: (fx, fy, cx, cy, k1, k2, p1, p2, k3), rig order.
struct Optics {
  double fx, fy, cx, cy, k1, k2, p1, p2, k3;
};
constexpr std::array<Optics, 6> kCalibratedOptics{{
    {1352.4, 1351.1, 815.2, 609.3, -0.1182, 0.0874, 0.00041, -0.00027, -0.0105},
    {1348.7, 1349.5, 808.6, 614.9, -0.1231, 0.0921, -0.00018, 0.00052, -0.0121},
    {1349.8, 1350.6, 813.1, 616.0, -0.1204, 0.0897, 0.00022, 0.00035, -0.0098},
    {1353.5, 1352.2, 809.9, 607.8, -0.1167, 0.0853, -0.00039, -0.00011, -0.0131},
    {1350.9, 1349.2, 806.4, 611.7, -0.1219, 0.0915, 0.00033, -0.00046, -0.0112},
    {1347.6, 1348.8, 816.7, 613.2, -0.1195, 0.0889, -0.00025, 0.00029, -0.0089},
}};
// The right camera of each head: rotation (Rodrigues, rad) and translation (m) from the left.
constexpr std::array<std::array<double, 6>, 3> kCalibratedPairs{{
    {0.0021, -0.0034, 0.0012, -0.1203, 0.0007, -0.0005},
    {-0.0016, 0.0027, -0.0009, -0.1196, -0.0006, 0.0009},
    {0.0012, 0.0019, 0.0015, -0.1201, 0.0004, 0.0003},
}};
// Gains of the six cameras relative to each other, as unmatched sensors have them.
constexpr std::array<double, 6> kCameraGains{1.0, 0.97, 1.02, 0.99, 1.03, 0.98};

cv::Mat cameraMatrix(const Optics& o) {
  return (cv::Mat_<double>(3, 3) << o.fx, 0, o.cx, 0, o.fy, o.cy, 0, 0, 1);
}
cv::Mat distortion(const Optics& o) {
  return (cv::Mat_<double>(1, 5) << o.k1, o.k2, o.p1, o.p2, o.k3);
}

// The rig's session folder and truth file, and writing one set of six frames.
class SyntheticSession {
 public:
  core::Result<void> open(const fs::path& session_dir, const fs::path& calib_dir,
                          const cloud::RigCalibration& rig, const PlotSeries& series) {
    session_dir_ = session_dir;
    if (auto saved = cloud::saveRigCalibration(rig, calib_dir); !saved)
      return saved.error();
    recording::SessionInfo info;
    info.configuration = {{"source", "fieldrig synthetic plots"},
                          {"renderer", std::string(rendererName(series.renderer))},
                          {"count", series.count},
                          {"seed", series.seed},
                          {"height_min_m", series.height_min_m},
                          {"height_max_m", series.height_max_m}};
    if (series.renderer == SceneRenderer::kMesh) {
      Json stages = Json::array();
      for (GrowthStage stage : series.stages)
        stages.push_back(std::string(stageName(stage)));
      info.configuration["stages"] = stages;
      info.configuration["stage_heights"] = series.stage_heights;
    }
    std::error_code ec;
    const fs::path absolute_calib = fs::absolute(calib_dir, ec);
    const fs::path absolute_session = fs::absolute(session_dir, ec);
    info.calibration.push_back(
        {"calib_dir", absolute_calib.lexically_relative(absolute_session).string()});
    if (auto opened = writer_.open(session_dir, info); !opened)
      return opened.error();
    truth_path_ = session_dir / "truth.jsonl";
    truth_file_.open(truth_path_);
    if (!truth_file_)
      return core::Error{truth_path_.string() + ": cannot write"};
    return {};
  }

  core::Result<std::uint64_t> writeSet(int index, const std::string& location,
                                       const std::array<cv::Mat, 6>& raw,
                                       core::PixelFormat format) {
    const core::RigLayout layout;
    const core::UtcTime start = core::UtcTime{} + std::chrono::hours{24 * 20600};
    recording::FrameSetRecord record;
    record.trigger_id = static_cast<std::uint64_t>(index) + 1;
    record.location_id = location;
    record.trigger_time = start + std::chrono::seconds{2 * index};
    core::GpsFix fix;
    fix.time = record.trigger_time;
    fix.has_date = true;
    fix.valid = true;
    // Plots 3.05 m apart (10 ft) along a row running north.
    fix.latitude_deg = 42.0 + 3.05 * index / 111'320.0;
    fix.longitude_deg = -93.6;
    record.fix = fix;
    for (std::size_t camera = 0; camera < raw.size(); ++camera) {
      recording::FrameView frame;
      frame.camera_index = static_cast<int>(camera);
      frame.camera_name = layout.cameraName(camera);
      frame.width = raw[camera].cols;
      frame.height = raw[camera].rows;
      frame.pixel_format = format;
      frame.pixels = {raw[camera].data, raw[camera].total()};
      frame.sequence = record.trigger_id;
      record.frames.push_back(std::move(frame));
    }
    const recording::WriteOutcome written = writer_.write(record);
    if (!written.ok())
      return core::Error{written.message};
    return written.set_index;
  }

  void writeTruth(const Json& line) { truth_file_ << line.dump() << '\n'; }

  core::Result<void> close() {
    writer_.close();
    truth_file_.close();
    if (!truth_file_)
      return core::Error{truth_path_.string() + ": cannot write"};
    return {};
  }

  const fs::path& dir() const { return session_dir_; }

 private:
  recording::SessionWriter writer_;
  fs::path session_dir_;
  fs::path truth_path_;
  std::ofstream truth_file_;
};

Json splatTruthLine(const RecordedPlot& plot_info, const PlotCloud& plot,
                    const traits::TraitsOptions& definitions) {
  const traits::TraitsResult truth = plotTruth(plot, definitions).definitions;
  Json line;
  line["plot"] = plot_info.location_id;
  line["set"] = plot_info.set_index;
  line["plant_height_m"] = plot_info.spec.plant_height_m;
  line["height_m"] = truth.height_m;
  line["width_m"] = truth.width_m;
  line["vvi"] = truth.vvi;
  line["z_min_m"] = truth.z_min;  // the refined box, camera at z = 0
  line["z_max_m"] = truth.z_max;
  line["visible_plant_area_m2"] = plot.truth.visible_plant_area_m2;
  return line;
}

core::Result<std::vector<RecordedPlot>> recordSplatPlots(
    const fs::path& session_dir, const fs::path& calib_dir, const PlotSeries& series,
    const std::vector<std::string>& locations,
    const std::function<void(const RecordedPlot&)>& progress) {
  const cloud::RigCalibration rig = idealRig();
  const core::RigLayout layout;
  SyntheticSession session;
  if (auto opened = session.open(session_dir, calib_dir, rig, series); !opened)
    return opened.error();
  const IdealRigGeometry geometry;  // the rig saved above
  std::vector<RecordedPlot> recorded;
  for (int index = 0; index < static_cast<int>(locations.size()); ++index) {
    const auto start = std::chrono::steady_clock::now();
    RecordedPlot plot_info;
    plot_info.location_id = locations[static_cast<std::size_t>(index)];
    plot_info.spec = plotSpec(series, index);
    const PlotCloud plot = generatePlot(plot_info.spec);
    std::array<cv::Mat, 6> raw;
    for (std::size_t head = 0; head < layout.heads.size(); ++head) {
      for (int side = 0; side < 2; ++side) {
        PinholeView view;
        view.focal_px = kIdealFocalPx;
        view.size = cv::Size(kIdealImageWidth, kIdealImageHeight);
        // The right camera sits one baseline along the left camera's x, which is the row (+y).
        view.position = Eigen::Vector3d(geometry.head_heights_m[head], side * kIdealBaselineM, 0.0);
        raw[2 * head + static_cast<std::size_t>(side)] =
            stereo::mosaicBayer(renderPlotView(plot, view), core::PixelFormat::kBayerRG8);
      }
    }
    auto written =
        session.writeSet(index, plot_info.location_id, raw, core::PixelFormat::kBayerRG8);
    if (!written)
      return written.error();
    plot_info.set_index = *written;
    plot_info.render_seconds = secondsSince(start);
    const auto truth_start = std::chrono::steady_clock::now();
    session.writeTruth(splatTruthLine(plot_info, plot, series.truth_traits));
    plot_info.truth_seconds = secondsSince(truth_start);
    recorded.push_back(plot_info);
    if (progress)
      progress(plot_info);
  }
  if (auto closed = session.close(); !closed)
    return closed.error();
  return recorded;
}

// Writes the truth maps of one frame beside it (file names: synthetic_field.h).
core::Result<Json> writeTruthMaps(const fs::path& session_dir, std::uint64_t set_index,
                                  int camera_index, const std::string& camera_name,
                                  const MeshFrame& frame) {
  std::string stem = recording::frameFileName(set_index, camera_index, camera_name);
  stem.resize(stem.size() - 4);  // ".pgm"
  const fs::path base = session_dir / stem;
  Json names;
  if (auto depth = stereo::writePfm(fs::path(base.string() + ".depth.pfm"), frame.depth); !depth)
    return depth.error();
  names["depth"] = stem + ".depth.pfm";
  for (const auto& [suffix, image] :
       {std::pair{".plot.png", &frame.plot}, std::pair{".plant.png", &frame.plant},
        std::pair{".veg.png", &frame.vegetation}}) {
    const std::string file = base.string() + suffix;
    // Encoded in memory and written by us: cv::imwrite says true after a short write.
    std::vector<std::uint8_t> encoded;
    try {
      if (!cv::imencode(".png", *image, encoded))
        return core::Error{file + ": cannot encode PNG"};
    } catch (const cv::Exception& e) {
      return core::Error{file + ": cannot encode PNG: " + e.what()};
    }
    if (std::string failed = core::writeWholeFile(
            file, std::string_view(reinterpret_cast<const char*>(encoded.data()), encoded.size()));
        !failed.empty())
      return core::Error{std::move(failed)};
  }
  names["plot"] = stem + ".plot.png";
  names["plant"] = stem + ".plant.png";
  names["vegetation"] = stem + ".veg.png";
  return names;
}

// The sun over the session: one time of day per seed (elevation 35–65°, any azimuth), moving a
// little from plot to plot.
Eigen::Vector3d sunDirection(std::uint32_t seed, int index) {
  std::mt19937 rng(seed * 2654435761U + 17U);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double elevation = (35.0 + 30.0 * uni(rng)) * std::numbers::pi / 180.0;
  const double azimuth = 2.0 * std::numbers::pi * uni(rng) + 0.004 * index;
  return {std::sin(elevation), std::cos(elevation) * std::cos(azimuth),
          std::cos(elevation) * std::sin(azimuth)};
}

core::Result<std::vector<RecordedPlot>> recordMeshPlots(
    const fs::path& session_dir, const fs::path& calib_dir, const PlotSeries& series,
    const std::vector<std::string>& locations,
    const std::function<void(const RecordedPlot&)>& progress) {
  const cloud::RigCalibration rig = calibratedRig();
  const IdealRigGeometry geometry;
  auto device = MeshRenderDevice::create();
  if (!device)
    return device.error();
  SyntheticSession session;
  if (auto opened = session.open(session_dir, calib_dir, rig, series); !opened)
    return opened.error();
  // The bottom head's rectified left camera at its height above the soil, at the plot centre.
  const std::vector<MeshCamera> cameras =
      rigCameras(rig, Eigen::Vector3d(geometry.head_heights_m.front(), 0.0, 0.0));
  std::vector<cv::Mat> rays;
  for (const MeshCamera& camera : cameras)
    rays.push_back(pixelRayMap(camera));

  std::vector<RecordedPlot> recorded;
  for (int index = 0; index < static_cast<int>(locations.size()); ++index) {
    const auto start = std::chrono::steady_clock::now();
    RecordedPlot plot_info;
    plot_info.location_id = locations[static_cast<std::size_t>(index)];
    plot_info.spec = plotSpec(series, index);
    const MeshPlotSpec spec = meshPlotSpec(series, index);
    if (auto error = validateMeshPlotSpec(spec))
      return core::Error{"synthetic plots: plot " + plot_info.location_id + ": " + *error};
    plot_info.spec.plant_height_m = spec.plot.height_m;
    plot_info.mesh = spec;
    auto scene = MeshRenderScene::build(*device, buildMeshScene(spec));
    if (!scene)
      return scene.error();
    MeshRenderOptions options;
    options.sun_direction = sunDirection(series.seed, index);
    options.pixel_format = rig.pixel_format;
    options.truth_maps = series.truth_maps;
    std::array<cv::Mat, 6> raw;
    std::array<MeshFrame, 6> frames;
    for (std::size_t camera = 0; camera < cameras.size() && camera < raw.size(); ++camera) {
      options.exposure_gain = kCameraGains[camera];
      options.noise_key = (static_cast<std::uint64_t>(series.seed) << 32) ^
                          (static_cast<std::uint64_t>(index) << 8) ^ camera;
      frames[camera] = renderMeshFrame(**scene, cameras[camera], rays[camera], options);
      raw[camera] = frames[camera].raw;
    }
    auto written = session.writeSet(index, plot_info.location_id, raw, rig.pixel_format);
    if (!written)
      return written.error();
    plot_info.set_index = *written;
    Json maps = Json::object();
    if (series.truth_maps) {
      for (std::size_t camera = 0; camera < cameras.size() && camera < frames.size(); ++camera) {
        auto names = writeTruthMaps(session_dir, plot_info.set_index, static_cast<int>(camera),
                                    cameras[camera].name, frames[camera]);
        if (!names)
          return names.error();
        maps[cameras[camera].name] = *names;
      }
    }
    plot_info.render_seconds = secondsSince(start);

    const auto truth_start = std::chrono::steady_clock::now();
    MeshTruthOptions truth_options;
    truth_options.seed = spec.plot.seed;
    truth_options.traits = series.truth_traits;
    const MeshPlotTruth truth = meshPlotTruth(**scene, cameras, truth_options);
    const traits::TraitsResult& d = truth.traits.definitions;
    Json line;
    line["plot"] = plot_info.location_id;
    line["set"] = plot_info.set_index;
    line["plant_height_m"] = spec.plot.height_m;
    line["height_m"] = d.height_m;
    line["width_m"] = d.width_m;
    line["vvi"] = d.vvi;
    line["z_min_m"] = d.z_min;  // the refined box, camera at z = 0
    line["z_max_m"] = d.z_max;
    line["visible_plant_area_m2"] = truth.visible.truth.visible_plant_area_m2;
    line["renderer"] = "mesh";
    line["stage"] = std::string(stageName(spec.plot.stage));
    // The soil plane's slopes, and the angle between its normal and the vertical (the rig is level
    // here): what the traits' ground fit (quality.ground_tilt_deg) should find.
    line["soil_slope_along_deg"] = spec.slope_along_deg;
    line["soil_slope_across_deg"] = spec.slope_across_deg;
    line["soil_tilt_deg"] =
        std::atan(std::hypot(std::tan(spec.slope_along_deg * std::numbers::pi / 180.0),
                             std::tan(spec.slope_across_deg * std::numbers::pi / 180.0))) *
        180.0 / std::numbers::pi;
    const Json mesh_fields = meshTruthJson(truth, (*scene)->scene());
    for (const auto& [key, value] : mesh_fields.items())
      line[key] = value;
    line["plot_codes"] = {{"1", plot_info.location_id},
                          {"2", plot_info.location_id + ":previous"},
                          {"3", plot_info.location_id + ":next"},
                          {"4", "background"}};
    line["sun_direction"] = {options.sun_direction.x(), options.sun_direction.y(),
                             options.sun_direction.z()};
    line["truth_maps"] = maps;
    session.writeTruth(line);
    plot_info.truth_seconds = secondsSince(truth_start);
    recorded.push_back(plot_info);
    if (progress)
      progress(plot_info);
  }
  if (auto closed = session.close(); !closed)
    return closed.error();
  return recorded;
}

}  // namespace

cloud::RigCalibration idealRig(const IdealRigGeometry& geometry) {
  const core::RigLayout layout;
  const cv::Size image_size(kIdealImageWidth, kIdealImageHeight);
  // A head the geometry leaves out sits at 0 m, level: never an empty vector's front().
  const double bottom_height =
      geometry.head_heights_m.empty() ? 0.0 : geometry.head_heights_m.front();
  cloud::RigCalibration rig;
  for (std::size_t i = 0; i < layout.heads.size(); ++i) {
    cloud::HeadCalibration head;
    head.name = layout.heads[i];
    head.stereo = stereo::idealStereoCalibration(kIdealFocalPx, image_size, kIdealBaselineM);
    // Head frame → bottom head's frame: straight above it (camera y points down), its z axis
    // turned towards +y (down) by the tilt.
    const double height = i < geometry.head_heights_m.size() ? geometry.head_heights_m[i] : 0;
    const double tilt_deg =
        i < geometry.head_tilts_down_deg.size() ? geometry.head_tilts_down_deg[i] : 0;
    const double tilt = tilt_deg * CV_PI / 180.0;
    head.to_bottom(1, 3) = -(height - bottom_height);
    head.to_bottom(1, 1) = std::cos(tilt);
    head.to_bottom(1, 2) = std::sin(tilt);
    head.to_bottom(2, 1) = -std::sin(tilt);
    head.to_bottom(2, 2) = std::cos(tilt);
    rig.heads.push_back(std::move(head));
  }
  rig.pixel_format = core::PixelFormat::kBayerRG8;
  return rig;
}

cloud::RigCalibration calibratedRig(const IdealRigGeometry& geometry) {
  cloud::RigCalibration rig = idealRig(geometry);
  const cv::Size image_size(kIdealImageWidth, kIdealImageHeight);
  for (std::size_t i = 0; i < rig.heads.size() && i < kCalibratedPairs.size(); ++i) {
    stereo::StereoCalibration& c = rig.heads[i].stereo;
    c.image_size = image_size;
    c.M1 = cameraMatrix(kCalibratedOptics[2 * i]);
    c.D1 = distortion(kCalibratedOptics[2 * i]);
    c.M2 = cameraMatrix(kCalibratedOptics[2 * i + 1]);
    c.D2 = distortion(kCalibratedOptics[2 * i + 1]);
    const auto& pair = kCalibratedPairs[i];
    cv::Rodrigues(cv::Vec3d(pair[0], pair[1], pair[2]), c.R);
    c.T = (cv::Mat_<double>(3, 1) << pair[3], pair[4], pair[5]);
    cv::stereoRectify(c.M1, c.D1, c.M2, c.D2, image_size, c.R, c.T, c.R1, c.R2, c.P1, c.P2, c.Q,
                      cv::CALIB_ZERO_DISPARITY, 0);
  }
  return rig;
}

std::string_view rendererName(SceneRenderer renderer) {
  return renderer == SceneRenderer::kMesh ? "mesh" : "splat";
}

std::optional<SceneRenderer> parseRenderer(std::string_view name) {
  if (name == "mesh")
    return SceneRenderer::kMesh;
  if (name == "splat")
    return SceneRenderer::kSplat;
  return std::nullopt;
}

PlotSpec plotSpec(const PlotSeries& series, int index) {
  PlotSpec spec;
  const double t = series.count > 1 ? static_cast<double>(index) / (series.count - 1) : 0.5;
  spec.plant_height_m = series.height_min_m + t * (series.height_max_m - series.height_min_m);
  spec.seed = series.seed * 1000 + static_cast<std::uint32_t>(index);
  spec.depth_noise_m = 0;  // the cameras and the matcher make the noise here
  spec.outlier_fraction = 0;
  spec.camera_heads = 6;  // keep the samples any of the (slightly offset) real cameras sees
  if (index % 3 == 1)
    spec.missing_plants = {3};
  if (index % 3 == 2)
    spec.tall_plant = 6;
  return spec;
}

MeshPlotSpec meshPlotSpec(const PlotSeries& series, int index) {
  const int count = std::max(series.count, 1);
  const auto stages = static_cast<int>(std::max<std::size_t>(series.stages.size(), 1));
  // Consecutive blocks of (nearly) equal size, one per stage.
  auto blockOf = [&](int i) { return static_cast<int>(static_cast<long>(i) * stages / count); };
  const int block = blockOf(index);
  int first = index;
  while (first > 0 && blockOf(first - 1) == block)
    --first;
  int last = index;
  while (last + 1 < count && blockOf(last + 1) == block)
    ++last;
  const GrowthStage stage =
      series.stages.empty() ? GrowthStage::kMid : series.stages[static_cast<std::size_t>(block)];
  const HeightRange range = series.stage_heights
                                ? stageHeights(stage)
                                : HeightRange{series.height_min_m, series.height_max_m};
  const double t = last > first ? static_cast<double>(index - first) / (last - first) : 0.5;

  std::mt19937 rng(series.seed * 7919U + static_cast<std::uint32_t>(index) * 104729U + 3U);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  MeshPlotSpec spec;
  spec.plot.stage = stage;
  spec.plot.height_m = range.min_m + t * (range.max_m - range.min_m);
  spec.plot.seed = series.seed * 1000 + static_cast<std::uint32_t>(index);
  // Positions 8 and 11 of 20 sit 0.22 m either side of the plot centre, in every camera's view.
  if (index % 3 == 1)
    spec.plot.missing = {8};
  if (index % 3 == 2)
    spec.plot.tall_plant = 11;
  const HeightRange stage_range = stageHeights(stage);
  for (auto* neighbour : {&spec.previous, &spec.next}) {
    PlotPlanting other;
    other.stage = stage;
    other.height_m = stage_range.min_m + (stage_range.max_m - stage_range.min_m) * uni(rng);
    other.centre_y_m = neighbour == &spec.previous ? -4.0 : 4.0;
    other.seed = series.seed * 1000 + 500 + static_cast<std::uint32_t>(index) * 2 +
                 (neighbour == &spec.previous ? 0U : 1U);
    *neighbour = other;
  }
  spec.row_depth_m = 1.15 + 0.1 * uni(rng);
  spec.slope_along_deg = -2.0 + 4.0 * uni(rng);
  spec.slope_across_deg = -2.0 + 4.0 * uni(rng);
  spec.seed = series.seed * 1000 + 700 + static_cast<std::uint32_t>(index);
  return spec;
}

std::optional<std::string> validatePlotSeries(const PlotSeries& series) {
  if (series.count < 1)
    return "count " + std::to_string(series.count) + " below 1";
  if (!(series.height_min_m > 0.0) || !(series.height_max_m > 0.0) ||
      !std::isfinite(series.height_min_m) || !std::isfinite(series.height_max_m))
    return "height range must be finite and positive";
  const double limit = series.renderer == SceneRenderer::kMesh ? 5.0 : 2.8;
  if (series.height_min_m > limit || series.height_max_m > limit) {
    return "plant height above " + std::to_string(limit).substr(0, 3) + " m needs " +
           (series.renderer == SceneRenderer::kMesh ? "a smaller value"
                                                    : "the mesh renderer (--renderer mesh)");
  }
  if (series.renderer == SceneRenderer::kMesh) {
    if (series.stages.empty())
      return "no growth stage given";
    if (series.stages.size() > static_cast<std::size_t>(series.count))
      return std::to_string(series.stages.size()) + " growth stages for " +
             std::to_string(series.count) + " plot(s): need a plot per stage";
  }
  return std::nullopt;
}

core::Result<std::vector<RecordedPlot>> recordSyntheticPlots(
    const fs::path& session_dir, const fs::path& calib_dir, const PlotSeries& series,
    const std::vector<std::string>& locations,
    const std::function<void(const RecordedPlot&)>& progress) {
  PlotSeries checked = series;
  checked.count = std::max(series.count, static_cast<int>(locations.size()));
  if (auto error = validatePlotSeries(checked))
    return core::Error{"synthetic plots: " + *error};
  if (series.renderer == SceneRenderer::kMesh)
    return recordMeshPlots(session_dir, calib_dir, series, locations, progress);
  return recordSplatPlots(session_dir, calib_dir, series, locations, progress);
}

}  // namespace fieldrig::sim
