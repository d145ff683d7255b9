// One FrameSet (three heads, raw Bayer 1624×1224, matched at 812×612) to the fused, cropped
// cloud, split per stage, for fieldrig's CloudBuilder (maps and matchers built once) in several
// configurations, next to a straightforward per-head pipeline measured in the same run: default
// SGBM (create(0, 128, 3), MODE_SGBM), rectification maps recomputed for every FrameSet,
// reprojectImageTo3D and a loop over all pixels. Frames come from tests/support/plane_rig_scene.h.
// Usage: stereo_pipeline_bench [ITERATIONS]   (default 10; the first run of each is a warm-up)
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "fieldrig/cloud/fusion.h"
#include "fieldrig/core/time.h"
#include "support/plane_rig_scene.h"

#include "process_cpu.h"

namespace {

using namespace fieldrig;
using Clock = std::chrono::steady_clock;

double processCpuMs() {
  return 1e3 * fieldrig::bench::processCpuSeconds();
}

struct StageTimes {
  double debayer = 0, rectify = 0, sgbm = 0, filter = 0, reproject = 0, fuse = 0, total = 0;
  double cpu = 0;
  std::size_t points = 0;
  StageTimes& operator+=(const StageTimes& o) {
    debayer += o.debayer;
    rectify += o.rectify;
    sgbm += o.sgbm;
    filter += o.filter;
    reproject += o.reproject;
    fuse += o.fuse;
    total += o.total;
    cpu += o.cpu;
    points = o.points;
    return *this;
  }
};

void printRow(const std::string& name, const StageTimes& t, int n, double baseline_total) {
  std::printf("| %s | %.1f | %.1f | %.1f | %.1f | %.1f | %.1f | **%.1f** | %.2f× | %.1f | %zu |\n",
              name.c_str(), t.debayer / n, t.rectify / n, t.sgbm / n, t.filter / n, t.reproject / n,
              t.fuse / n, t.total / n, baseline_total > 0 ? baseline_total / (t.total / n) : 1.0,
              t.cpu / n, t.points);
}

StageTimes runBuilder(cloud::CloudBuilder& builder, const std::vector<cloud::HeadFrames>& frames,
                      bool parallel) {
  const auto start = Clock::now();
  const double cpu_start = processCpuMs();
  const cloud::FusionResult result = builder.build(frames, parallel);
  StageTimes t;
  t.total = fieldrig::core::millisecondsSince(start);
  t.cpu = processCpuMs() - cpu_start;
  for (const cloud::HeadStatus& head : result.heads) {
    t.debayer += head.timings.debayer_ms;
    t.rectify += head.timings.rectify_ms;
    t.sgbm += head.timings.match.sgbm_ms;
    t.filter += head.timings.match.filter_ms;
    t.reproject += head.reproject_ms;
  }
  t.fuse = result.fuse_ms;
  t.points = result.cloud.size();
  return t;
}

// The straightforward pipeline: everything per FrameSet, default SGBM.
StageTimes runStraightforward(const cloud::RigCalibration& rig, const cloud::CloudOptions& options,
                              const std::vector<cloud::HeadFrames>& frames) {
  StageTimes t;
  const auto all = Clock::now();
  const double cpu_start = processCpuMs();
  cloud::Cloud fused;
  for (std::size_t i = 0; i < rig.heads.size(); ++i) {
    const stereo::StereoCalibration c = rig.heads[i].stereo.scaled(options.scale);
    auto start = Clock::now();
    cv::Mat left_full, right_full, left, right;
    cv::cvtColor(frames[i].left, left_full, cv::COLOR_BayerRGGB2BGR);
    cv::cvtColor(frames[i].right, right_full, cv::COLOR_BayerRGGB2BGR);
    cv::resize(left_full, left, cv::Size(), options.scale, options.scale, cv::INTER_AREA);
    cv::resize(right_full, right, cv::Size(), options.scale, options.scale, cv::INTER_AREA);
    t.debayer += fieldrig::core::millisecondsSince(start);
    start = Clock::now();
    cv::Mat m1x, m1y, m2x, m2y, left_rect, right_rect;
    cv::initUndistortRectifyMap(c.M1, c.D1, c.R1, c.P1, left.size(), CV_32FC1, m1x, m1y);
    cv::initUndistortRectifyMap(c.M2, c.D2, c.R2, c.P2, left.size(), CV_32FC1, m2x, m2y);
    cv::remap(left, left_rect, m1x, m1y, cv::INTER_LINEAR);
    cv::remap(right, right_rect, m2x, m2y, cv::INTER_LINEAR);
    t.rectify += fieldrig::core::millisecondsSince(start);
    start = Clock::now();
    cv::Mat left_grey, right_grey, fixed, disparity;
    cv::cvtColor(left_rect, left_grey, cv::COLOR_BGR2GRAY);
    cv::cvtColor(right_rect, right_grey, cv::COLOR_BGR2GRAY);
    cv::StereoSGBM::create(0, options.matcher.num_disparities, 3)
        ->compute(left_grey, right_grey, fixed);
    t.sgbm += fieldrig::core::millisecondsSince(start);
    start = Clock::now();
    fixed.convertTo(disparity, CV_32F, 1.0 / 16);
    cv::Mat xyz;
    cv::reprojectImageTo3D(disparity, xyz, c.Q, true);
    t.reproject += fieldrig::core::millisecondsSince(start);
    start = Clock::now();
    cv::Matx44d plot = cv::Matx44d::eye();
    for (int r = 0; r < 3; ++r) {
      for (int col = 0; col < 3; ++col)
        plot(r, col) = rig.plot_rotation(r, col);
    }
    const cv::Matx44d to_plot = plot * rig.heads[i].to_bottom;
    for (int y = 0; y < xyz.rows; ++y) {
      for (int x = 0; x < xyz.cols; ++x) {
        const cv::Vec3f v = xyz.at<cv::Vec3f>(y, x);
        const cv::Vec4d p = to_plot * cv::Vec4d(v[0], v[1], v[2], 1);
        if (!(p[2] > options.min_depth_m && p[2] <= options.max_depth_m))
          continue;
        const cv::Vec3b colour = left_rect.at<cv::Vec3b>(y, x);
        pcl::PointXYZRGB point;
        point.x = static_cast<float>(p[0]);
        point.y = static_cast<float>(p[1]);
        point.z = static_cast<float>(p[2]);
        point.b = colour[0];
        point.g = colour[1];
        point.r = colour[2];
        fused.push_back(point);
      }
    }
    t.fuse += fieldrig::core::millisecondsSince(start);
  }
  t.total = fieldrig::core::millisecondsSince(all);
  t.cpu = processCpuMs() - cpu_start;
  t.points = fused.size();
  return t;
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::atoi(argv[1]) : 10;
  const cloud::RigCalibration rig = testing_support::syntheticRig();
  std::vector<cloud::HeadFrames> frames;
  for (int i = 0; i < 3; ++i) {
    testing_support::RenderedHead head = testing_support::renderHead(i);
    frames.push_back({head.left_raw, head.right_raw, core::PixelFormat::kBayerRG8, {}, {}});
  }
  std::printf("OpenCV %s, %d threads; %d FrameSets each (after one warm-up), ms per FrameSet\n\n",
              CV_VERSION, cv::getNumThreads(), iterations);
  std::printf(
      "| pipeline | debayer+downsample | rectify | SGBM | LR/filter | reproject | "
      "join | total | speed-up | CPU ms | points "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|\n");

  const cloud::CloudOptions defaults;
  runStraightforward(rig, defaults, frames);
  StageTimes baseline;
  for (int i = 0; i < iterations; ++i)
    baseline += runStraightforward(rig, defaults, frames);
  const double baseline_ms = baseline.total / iterations;
  printRow("straightforward (default SGBM, maps per set)", baseline, iterations, 0);

  struct Config {
    std::string name;
    stereo::MatcherOptions matcher;
    bool parallel;
  };
  stereo::MatcherOptions tuned;
  stereo::MatcherOptions lr = tuned;
  lr.lr_check = true;
  stereo::MatcherOptions wls = tuned;
  wls.wls = true;
  stereo::MatcherOptions one_way = tuned;
  one_way.mode = cv::StereoSGBM::MODE_SGBM;
  const std::vector<Config> configs{
      {"fieldrig SGBM_3WAY, heads in turn", tuned, false},
      {"fieldrig SGBM_3WAY, heads in parallel", tuned, true},
      {"fieldrig SGBM_3WAY, disparities [32, 112), heads in turn", tuned, false},
      {"fieldrig SGBM_3WAY, disparities [32, 112), heads in parallel", tuned, true},
      {"fieldrig MODE_SGBM, heads in parallel", one_way, true},
      {"fieldrig + LR check, heads in parallel", lr, true},
      {"fieldrig + WLS, heads in parallel", wls, true},
  };
  // The plants' range only (0.8–1.7 m is 101–48 px): disparities [32, 112).
  for (const Config& config : configs) {
    cloud::CloudOptions options;
    options.matcher = config.matcher;
    if (config.name.find("[32, 112)") != std::string::npos) {
      options.matcher.min_disparity = 32;
      options.matcher.num_disparities = 80;
    }
    auto builder = cloud::CloudBuilder::create(rig, options);
    if (!builder) {
      std::fprintf(stderr, "%s\n", builder.error().message.c_str());
      return 1;
    }
    runBuilder(*builder, frames, config.parallel);
    StageTimes sum;
    for (int i = 0; i < iterations; ++i)
      sum += runBuilder(*builder, frames, config.parallel);
    printRow(config.name, sum, iterations, baseline_ms);
  }
  std::printf(
      "\nStage columns are wall times summed over the three heads (with heads in parallel "
      "they overlap and add up to more than the total). fieldrig's reproject column is "
      "reprojection + plot-frame transform + crop + colour in one pass; join is the "
      "heads' clouds joined. The straightforward pipeline's reproject is "
      "reprojectImageTo3D and its join column its transform/crop/colour loop. CPU ms: "
      "process CPU time per FrameSet, all threads.\n");
  return 0;
}
