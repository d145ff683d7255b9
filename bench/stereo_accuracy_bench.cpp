// Disparity accuracy on real ground truth (Middlebury Teddy, Cones, Aloe from the shared data):
// bad-pixel rates and valid fraction of plain default OpenCV SGBM and of fieldrig's matcher
// variants, measured in the same run, with their matching times. Prints a Markdown table.
#include <chrono>
#include <cstdio>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "fieldrig/stereo/disparity_io.h"
#include "fieldrig/stereo/matcher.h"

namespace {

using namespace fieldrig::stereo;
using Clock = std::chrono::steady_clock;

struct Scene {
  std::string name;
  cv::Mat left, right, truth;
  int num_disparities;
};

Scene middlebury2003(const std::string& name) {
  const std::string dir = std::string(FIELDRIG_SHARED_DATA_DIR) + "/stereo/middlebury2003/" + name;
  Scene scene{name, cv::imread(dir + "/im2.png"), cv::imread(dir + "/im6.png"), {}, 64};
  cv::imread(dir + "/disp2.pgm", cv::IMREAD_GRAYSCALE).convertTo(scene.truth, CV_32F, 0.25);
  return scene;
}

Scene aloe() {
  const std::string dir = std::string(FIELDRIG_SHARED_DATA_DIR) + "/stereo/opencv_aloe";
  Scene scene{"aloe", cv::imread(dir + "/aloeL.jpg"), cv::imread(dir + "/aloeR.jpg"), {}, 224};
  cv::imread(dir + "/aloeGT.png", cv::IMREAD_GRAYSCALE).convertTo(scene.truth, CV_32F);
  return scene;
}

// The numbers in the shipped matcher's row are read from its options, so they follow the defaults.
std::string shippedName(const MatcherOptions& o) {
  return "fieldrig (grey, 3WAY, P1/P2 " + std::to_string(o.p1_per_pixel) + "/" +
         std::to_string(o.p2_per_pixel) + ", uniq " + std::to_string(o.uniqueness_ratio) +
         ", speckle " + std::to_string(o.speckle_window) + "/" + std::to_string(o.speckle_range) +
         ", disp12 " + std::to_string(o.disp12_max_diff) + ")";
}

}  // namespace

int main() {
  std::vector<Scene> scenes{middlebury2003("teddy"), middlebury2003("cones"), aloe()};
  struct Variant {
    std::string name;
    std::function<cv::Mat(const Scene&)> run;
  };
  auto ours = [](MatcherOptions options) {
    return [options](const Scene& scene) mutable {
      options.num_disparities = scene.num_disparities;
      DisparityMatcher matcher(options);
      return matcher.compute(scene.left, scene.right);
    };
  };
  MatcherOptions base;
  MatcherOptions lr = base;
  lr.lr_check = true;
  MatcherOptions wls = base;
  wls.wls = true;
  MatcherOptions colour = base;
  colour.match_colour = true;
  MatcherOptions colour_lr = colour;
  colour_lr.lr_check = true;
  std::vector<Variant> variants{
      {"default SGBM create(0,N,3)",
       [](const Scene& s) { return computeDefaultSgbm(s.left, s.right, s.num_disparities); }},
      {shippedName(base), ours(base)},
      {"fieldrig + LR check (right matcher)", ours(lr)},
      {"fieldrig + WLS", ours(wls)},
      {"fieldrig colour", ours(colour)},
      {"fieldrig colour + LR check", ours(colour_lr)},
  };
  std::printf(
      "| scene | matcher | bad>1 (valid) | bad>2 (valid) | bad>1 (invalid=bad) | "
      "bad>2 (invalid=bad) | valid | ms |\n|---|---|---|---|---|---|---|---|\n");
  for (const Scene& scene : scenes) {
    for (const Variant& variant : variants) {
      const auto start = Clock::now();
      const cv::Mat disparity = variant.run(scene);
      const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
      const DisparityScores s = scoreDisparity(disparity, scene.truth);
      std::printf("| %s | %s | %.2f %% | %.2f %% | %.2f %% | %.2f %% | %.1f %% | %.0f |\n",
                  scene.name.c_str(), variant.name.c_str(), 100 * s.bad1_valid, 100 * s.bad2_valid,
                  100 * s.bad1_all, 100 * s.bad2_all, 100 * s.valid_fraction, ms);
    }
  }
  return 0;
}
