#include <array>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "fieldrig/recording/session_writer.h"
#include "fieldrig/sim/plot_truth.h"
#include "fieldrig/sim/plot_view_renderer.h"
#include "fieldrig/sim/synthetic_field.h"
#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::sim {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

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

core::Result<std::vector<RecordedPlot>> recordSyntheticPlots(
    const fs::path& session_dir, const fs::path& calib_dir, const PlotSeries& series,
    const std::vector<std::string>& locations,
    const std::function<void(const RecordedPlot&)>& progress) {
  const cloud::RigCalibration rig = idealRig();
  const core::RigLayout layout;
  if (auto saved = cloud::saveRigCalibration(rig, calib_dir); !saved)
    return saved.error();
  recording::SessionInfo info;
  info.configuration = {{"source", "fieldrig synthetic plots"},
                        {"count", series.count},
                        {"seed", series.seed},
                        {"height_min_m", series.height_min_m},
                        {"height_max_m", series.height_max_m}};
  std::error_code ec;
  const fs::path absolute_calib = fs::absolute(calib_dir, ec);
  const fs::path absolute_session = fs::absolute(session_dir, ec);
  info.calibration.push_back(
      {"calib_dir", absolute_calib.lexically_relative(absolute_session).string()});
  recording::SessionWriter writer;
  if (auto opened = writer.open(session_dir, info); !opened)
    return opened.error();
  const fs::path truth_path = session_dir / "truth.jsonl";
  std::ofstream truth_file(truth_path);
  const core::UtcTime start = core::UtcTime{} + std::chrono::hours{24 * 20600};

  const IdealRigGeometry geometry;  // the rig saved above
  std::vector<RecordedPlot> recorded;
  for (int index = 0; index < static_cast<int>(locations.size()); ++index) {
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
    recording::FrameSetRecord record;
    record.trigger_id = static_cast<std::uint64_t>(index) + 1;
    record.location_id = plot_info.location_id;
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
      frame.pixel_format = core::PixelFormat::kBayerRG8;
      frame.pixels = {raw[camera].data, raw[camera].total()};
      frame.sequence = record.trigger_id;
      record.frames.push_back(std::move(frame));
    }
    const recording::WriteOutcome written = writer.write(record);
    if (!written.ok())
      return core::Error{written.message};
    plot_info.set_index = written.set_index;
    const traits::TraitsResult truth = plotTruth(plot, traits::TraitsOptions{}).definitions;
    Json line;
    line["plot"] = plot_info.location_id;
    line["set"] = written.set_index;
    line["plant_height_m"] = plot_info.spec.plant_height_m;
    line["height_m"] = truth.height_m;
    line["width_m"] = truth.width_m;
    line["vvi"] = truth.vvi;
    line["z_min_m"] = truth.z_min;  // the refined box, camera at z = 0
    line["z_max_m"] = truth.z_max;
    line["visible_plant_area_m2"] = plot.truth.visible_plant_area_m2;
    truth_file << line.dump() << '\n';
    recorded.push_back(plot_info);
    if (progress)
      progress(plot_info);
  }
  writer.close();
  truth_file.close();
  if (!truth_file)
    return core::Error{truth_path.string() + ": cannot write"};
  return recorded;
}

}  // namespace fieldrig::sim
