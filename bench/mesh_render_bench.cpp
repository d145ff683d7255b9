// The Embree mesh renderer's speed: seconds per FrameSet (six 1624×1224 RAW8 frames, four
// colour rays and one truth ray per pixel, sun shadows, truth maps) on one plot per growth stage,
// with the scene build and the truth by the definitions beside it, as a Markdown table. The
// ray maps (undistortPoints over each camera's pixel grid) are made once per session and timed
// apart. `mesh_render_bench [REPEATS] [--preview DIR]` also writes each stage's six frames,
// debayered, as PNG files into DIR.
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "fieldrig/sim/mesh_renderer.h"
#include "fieldrig/sim/mesh_truth.h"
#include "fieldrig/sim/synthetic_field.h"
#include "fieldrig/stereo/preprocess.h"
#include "process_cpu.h"

namespace {

using Clock = std::chrono::steady_clock;
double since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

}  // namespace

int main(int argc, char** argv) {
  using namespace fieldrig;
  int repeats = 3;
  std::string preview;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--preview" && i + 1 < argc)
      preview = argv[++i];
    else
      repeats = std::max(1, std::atoi(argv[i]));
  }
  auto device = sim::MeshRenderDevice::create();
  if (!device) {
    std::fprintf(stderr, "%s\n", device.error().message.c_str());
    return 1;
  }
  const cloud::RigCalibration rig = sim::calibratedRig();
  const sim::IdealRigGeometry geometry;
  const auto cameras =
      sim::rigCameras(rig, Eigen::Vector3d(geometry.head_heights_m.front(), 0.0, 0.0));
  auto start = Clock::now();
  std::vector<cv::Mat> rays;
  for (const auto& camera : cameras)
    rays.push_back(sim::pixelRayMap(camera));
  const double ray_maps = since(start);
  std::printf(
      "cv::getNumThreads() = %d; ray maps of the six cameras (once per session): %.2f s\n\n",
      cv::getNumThreads(), ray_maps);
  std::printf(
      "| stage | plant height m | triangles | scene build s | FrameSet s (6 frames) | "
      "FrameSet CPU s | per frame ms | without shadows s | truth s |\n");
  std::printf("| --- | --- | --- | --- | --- | --- | --- | --- | --- |\n");
  double worst = 0.0;
  double worst_cpu = 0.0;
  for (sim::GrowthStage stage :
       {sim::GrowthStage::kEarly, sim::GrowthStage::kMid, sim::GrowthStage::kMature}) {
    sim::PlotSeries series;
    series.count = 3;
    series.seed = 7;
    series.renderer = sim::SceneRenderer::kMesh;
    series.stages = {stage};
    const sim::MeshPlotSpec spec = sim::meshPlotSpec(series, 1);
    start = Clock::now();
    auto scene = sim::MeshRenderScene::build(*device, sim::buildMeshScene(spec));
    const double build = since(start);
    if (!scene) {
      std::fprintf(stderr, "%s\n", scene.error().message.c_str());
      return 1;
    }
    sim::MeshRenderOptions options;
    std::vector<double> times;
    std::vector<double> cpu_times;
    std::vector<sim::MeshFrame> frames(cameras.size());
    for (int r = 0; r < repeats; ++r) {
      start = Clock::now();
      const double cpu_start = bench::processCpuSeconds();
      for (std::size_t c = 0; c < cameras.size(); ++c)
        frames[c] = sim::renderMeshFrame(**scene, cameras[c], rays[c], options);
      times.push_back(since(start));
      cpu_times.push_back(bench::processCpuSeconds() - cpu_start);
    }
    std::sort(times.begin(), times.end());
    std::sort(cpu_times.begin(), cpu_times.end());
    const double median = times[times.size() / 2];
    const double cpu = cpu_times[cpu_times.size() / 2];
    worst = std::max(worst, median);
    sim::MeshRenderOptions no_shadows = options;
    no_shadows.shadows = false;
    start = Clock::now();
    for (std::size_t c = 0; c < cameras.size(); ++c)
      sim::renderMeshFrame(**scene, cameras[c], rays[c], no_shadows);
    const double unshadowed = since(start);
    start = Clock::now();
    const sim::MeshPlotTruth truth = sim::meshPlotTruth(**scene, cameras, {});
    const double truth_s = since(start);
    std::printf("| %s | %.2f | %zu | %.2f | %.2f | %.2f | %.0f | %.2f | %.2f |\n",
                std::string(sim::stageName(stage)).c_str(), spec.plot.height_m,
                (*scene)->scene().triangleCount(), build, median, cpu, 1000.0 * median / 6.0,
                unshadowed, truth_s);
    worst_cpu = std::max(worst_cpu, cpu);
    if (!preview.empty()) {
      std::filesystem::create_directories(preview);
      for (std::size_t c = 0; c < cameras.size(); ++c) {
        const auto bgr = stereo::debayerAndScale(frames[c].raw, rig.pixel_format, 1.0);
        cv::imwrite(
            preview + "/" + std::string(sim::stageName(stage)) + "_" + cameras[c].name + ".png",
            *bgr);
        cv::Mat depth8;
        frames[c].depth.convertTo(depth8, CV_8U, 40.0);
        cv::imwrite(preview + "/" + std::string(sim::stageName(stage)) + "_" + cameras[c].name +
                        "_depth.png",
                    depth8);
      }
      std::fprintf(stderr, "%s: truth height %.3f width %.3f vvi %.3f vai %.3f view top %.2f\n",
                   std::string(sim::stageName(stage)).c_str(), truth.traits.definitions.height_m,
                   truth.traits.definitions.width_m, truth.traits.definitions.vvi, truth.traits.vai,
                   truth.view_top_m);
    }
  }
  double load = 0.0;
  if (std::FILE* f = std::fopen("/proc/loadavg", "r")) {
    if (std::fscanf(f, "%lf", &load) != 1)
      load = 0.0;
    std::fclose(f);
  }
  std::printf(
      "\nworst FrameSet: %.2f s wall, %.2f s CPU over %d threads (target <= 2 s wall on "
      "2 cores); load average %.1f while it ran\n",
      worst, worst_cpu, cv::getNumThreads(), load);
  return 0;
}
