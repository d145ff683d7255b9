// `fieldrig sim plots --out SESSION [--calib-out DIR] [--count N] [--seed S]`: a recorded session
// of synthetic row plots, as the tractor would record it — six raw Bayer frames per plot from an
// ideal three-head rig — with the rig's calibration and each plot's truth (SESSION/truth.jsonl:
// the trait definitions applied to the noise-free visible plant geometry). `fieldrig process`
// then runs the whole pipeline on it, hardware-free, and its results can be held against truth.
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "commands/commands.h"
#include "fieldrig/cloud/rig.h"
#include "fieldrig/recording/session_writer.h"
#include "fieldrig/sim/plot_generator.h"
#include "fieldrig/sim/plot_truth.h"
#include "fieldrig/sim/plot_view_renderer.h"
#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::tools {
namespace {

namespace fs = std::filesystem;
using Json = nlohmann::ordered_json;

// The rig: Grasshopper-like heads (1624×1224, f 1350 px, 0.12 m baseline), stacked at these
// heights above the soil, all looking level at the row 1.2 m away (vertical field ±0.54 m there).
constexpr double kFocalPx = 1350.0;
constexpr double kBaselineM = 0.12;
constexpr std::array<double, 3> kHeadHeightM{0.55, 1.45, 2.35};
const std::array<std::string, 3> kHeadNames{"bottom", "middle", "top"};
const cv::Size kCameraSize(1624, 1224);

struct PlotsArgs {
  std::string out, calib_out;
  int count = 3;
  std::uint32_t seed = 1;
  double height_min_m = 1.4;
  double height_max_m = 2.4;
};

cloud::RigConfig idealRig() {
  cloud::RigConfig rig;
  for (std::size_t i = 0; i < kHeadNames.size(); ++i) {
    cloud::HeadConfig head;
    head.name = kHeadNames[i];
    head.calibration = stereo::idealStereoCalibration(kFocalPx, kCameraSize, kBaselineM);
    // Head frame → bottom head's frame: straight above it, and camera y points down.
    head.to_bottom(1, 3) = -(kHeadHeightM[i] - kHeadHeightM[0]);
    rig.heads.push_back(std::move(head));
  }
  rig.pixel_format = core::PixelFormat::kBayerRG8;
  return rig;
}

// Plot `index` of the session: heights spread over the range, with the paper's irregularities
// (a missing plant, an abnormally tall one) on some plots.
sim::PlotSpec plotSpec(const PlotsArgs& args, int index) {
  sim::PlotSpec spec;
  const double t = args.count > 1 ? static_cast<double>(index) / (args.count - 1) : 0.5;
  spec.plant_height_m = args.height_min_m + t * (args.height_max_m - args.height_min_m);
  spec.seed = args.seed * 1000 + static_cast<std::uint32_t>(index);
  spec.depth_noise_m = 0;  // the cameras and the matcher make the noise here
  spec.outlier_fraction = 0;
  spec.camera_heads = 6;  // keep the samples any of the (slightly offset) real cameras sees
  if (index % 3 == 1)
    spec.missing_plants = {3};
  if (index % 3 == 2)
    spec.tall_plant = 6;
  return spec;
}

int runPlots(const PlotsArgs& args) {
  const char* who = "fieldrig sim plots: ";
  const fs::path session_dir(args.out);
  const fs::path calib_dir =
      args.calib_out.empty() ? session_dir / "calib" : fs::path(args.calib_out);
  const cloud::RigConfig rig = idealRig();
  if (auto saved = cloud::saveRig(rig, calib_dir); !saved) {
    std::cerr << who << saved.error().message << '\n';
    return kExitBadInput;
  }
  recording::SessionInfo info;
  info.configuration = {
      {"source", "fieldrig sim plots"}, {"count", args.count}, {"seed", args.seed}};
  std::error_code ec;
  const fs::path absolute_calib = fs::absolute(calib_dir, ec);
  const fs::path absolute_session = fs::absolute(session_dir, ec);
  info.calibration.push_back(
      {"calib_dir", absolute_calib.lexically_relative(absolute_session).string()});
  recording::SessionWriter writer;
  if (auto opened = writer.open(session_dir, info); !opened) {
    std::cerr << who << opened.error().message << '\n';
    return kExitBadInput;
  }
  std::ofstream truth_file(session_dir / "truth.jsonl");
  const core::UtcTime start = core::UtcTime{} + std::chrono::hours{24 * 20600};

  for (int index = 0; index < args.count; ++index) {
    const sim::PlotSpec spec = plotSpec(args, index);
    const sim::PlotCloud plot = sim::generatePlot(spec);
    std::array<cv::Mat, 6> raw;
    for (std::size_t head = 0; head < kHeadNames.size(); ++head) {
      for (int side = 0; side < 2; ++side) {
        sim::PinholeView view;
        view.focal_px = kFocalPx;
        view.size = kCameraSize;
        // The right camera sits one baseline along the left camera's x, which is the row (+y).
        view.position = Eigen::Vector3d(kHeadHeightM[head], side * kBaselineM, 0.0);
        raw[2 * head + static_cast<std::size_t>(side)] =
            stereo::mosaicBayer(sim::renderPlotView(plot, view), core::PixelFormat::kBayerRG8);
      }
    }
    recording::FrameSetRecord record;
    record.trigger_id = static_cast<std::uint64_t>(index) + 1;
    record.location_id = "plot-" + std::to_string(index + 1);
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
      frame.camera_name = kHeadNames[camera / 2] + (camera % 2 ? "_right" : "_left");
      frame.width = raw[camera].cols;
      frame.height = raw[camera].rows;
      frame.pixel_format = core::PixelFormat::kBayerRG8;
      frame.pixels = {raw[camera].data, raw[camera].total()};
      frame.sequence = record.trigger_id;
      record.frames.push_back(std::move(frame));
    }
    const recording::WriteOutcome written = writer.write(record);
    if (!written.ok()) {
      std::cerr << who << written.message << '\n';
      return kExitRuntime;
    }
    const traits::TraitsResult truth = sim::plotTruth(plot, traits::TraitsOptions{}).definitions;
    Json line;
    line["plot"] = *record.location_id;
    line["set"] = written.set_index;
    line["plant_height_m"] = spec.plant_height_m;
    line["height_m"] = truth.height_m;
    line["width_m"] = truth.width_m;
    line["vvi"] = truth.vvi;
    line["z_min_m"] = truth.z_min;  // the refined box, camera at z = 0
    line["z_max_m"] = truth.z_max;
    line["visible_plant_area_m2"] = plot.truth.visible_plant_area_m2;
    truth_file << line.dump() << '\n';
  }
  writer.close();
  truth_file.close();
  if (!truth_file) {
    std::cerr << who << (session_dir / "truth.jsonl").string() << ": cannot write\n";
    return kExitRuntime;
  }
  Json summary;
  summary["session"] = session_dir.string();
  summary["calib"] = calib_dir.string();
  summary["plots"] = args.count;
  summary["truth"] = (session_dir / "truth.jsonl").string();
  std::cout << summary.dump() << '\n';
  return kExitOk;
}

}  // namespace

void registerSimPlotsSubcommand(CLI::App& sim, int& exit_code) {
  auto args = std::make_shared<PlotsArgs>();
  CLI::App* plots = sim.add_subcommand(
      "plots", "Record a session of synthetic row plots (six raw frames each) with its truth");
  plots->add_option("--out", args->out, "Session folder to write")->required();
  plots->add_option("--calib-out", args->calib_out,
                    "Calibration folder to write (default SESSION/calib)");
  plots->add_option("--count", args->count, "Number of plots")
      ->capture_default_str()
      ->check(CLI::Range(1, 1000));
  plots->add_option("--seed", args->seed, "Scene seed")->capture_default_str();
  plots->add_option("--height-min", args->height_min_m, "Plant height of the first plot, m")
      ->capture_default_str()
      ->check(CLI::Range(0.3, 2.8));
  plots->add_option("--height-max", args->height_max_m, "Plant height of the last plot, m")
      ->capture_default_str()
      ->check(CLI::Range(0.3, 2.8));
  plots->callback([args, &exit_code] { exit_code = runPlots(*args); });
}

}  // namespace fieldrig::tools
