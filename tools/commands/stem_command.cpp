// `fieldrig stem`: the four-click stem diameter of one stereo pair, from the command line.
//   fieldrig stem --left L --right R --intrinsics I.yml --extrinsics E.yml
//                 --points x1,y1,x2,y2,x3,y3,x4,y4 [--json] [--bayer RG|GR|GB|BG]
// Points are pixels of the raw left image, any order. Exit codes: 0 measured; 2 bad input
// (files, calibration, points that are not a convex quadrangle); 3 no reliable measurement
// (weak NCC match, no disparity range in the image).
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <optional>
#include <sstream>
#include <vector>

#include "commands/command_helpers.h"
#include "fieldrig/core/pixel_format.h"
#include "fieldrig/stem/measurement_json.h"
#include "fieldrig/stem/stem_measurer.h"
#include "fieldrig/stereo/preprocess.h"

namespace fieldrig::tools {
namespace {

struct StemArgs {
  std::string left, right, intrinsics, extrinsics, points, bayer;
  bool json = false;
  bool face_value = false;
  bool plane = false;
};

// "x1,y1,…,x4,y4": eight finite numbers.
core::Result<stem::Points4> parseStemPoints(const std::string& text) {
  std::vector<double> values;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    char* end = nullptr;
    errno = 0;
    const double value = std::strtod(item.c_str(), &end);
    if (item.empty() || errno != 0 || end != item.c_str() + item.size() || !std::isfinite(value))
      return core::Error{"'" + item + "' is not a number"};
    values.push_back(value);
  }
  if (values.size() != 8) {
    return core::Error{"expected 8 numbers (x1,y1,…,x4,y4), got " + std::to_string(values.size())};
  }
  stem::Points4 points;
  for (std::size_t i = 0; i < 4; ++i)
    points[i] = cv::Point2d(values[2 * i], values[2 * i + 1]);
  return points;
}

// An image file as 8-bit grey; `bayer` ("", "RG", "GR", "GB", "BG") demosaics raw Bayer.
core::Result<cv::Mat> loadGreyImage(const std::filesystem::path& file, const std::string& bayer) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    return core::Error{file.string() + ": no such image file"};
  cv::Mat image =
      cv::imread(file.string(), bayer.empty() ? cv::IMREAD_GRAYSCALE : cv::IMREAD_UNCHANGED);
  if (image.empty())
    return core::Error{file.string() + ": not an image OpenCV can read"};
  if (bayer.empty())
    return image;
  const std::optional<core::PixelFormat> format = core::parsePixelFormat("Bayer" + bayer + "8");
  if (!format)
    return core::Error{"--bayer: '" + bayer + "' is not one of RG, GR, GB, BG"};
  if (image.type() != CV_8UC1)
    return core::Error{file.string() + ": raw Bayer must be one 8-bit channel"};
  return stereo::toGrey(image, *format);
}

int runStem(const StemArgs& args) {
  constexpr std::string_view kName = "fieldrig stem: ";
  core::Result<stem::Points4> points = parseStemPoints(args.points);
  if (!points)
    return fail(kName, "--points: " + points.error().message);
  core::Result<stereo::StereoCalibration> calibration =
      stereo::loadStereoCalibration(args.intrinsics, args.extrinsics);
  if (!calibration)
    return fail(kName, calibration.error().message);
  core::Result<cv::Mat> left = loadGreyImage(args.left, args.bayer);
  if (!left)
    return fail(kName, left.error().message);
  core::Result<cv::Mat> right = loadGreyImage(args.right, args.bayer);
  if (!right)
    return fail(kName, right.error().message);
  core::Result<stem::StemMeasurer> measurer =
      stem::StemMeasurer::create(*calibration, *left, *right);
  if (!measurer)
    return fail(kName, measurer.error().message);
  stem::MeasureOptions options;
  options.refine_edges = !args.face_value;
  options.cylinder_model = !args.plane;
  const stem::StemMeasurement m = measurer->measure(*points, options);
  if (args.json) {
    std::cout << stem::toJson(m).dump() << '\n';
  } else if (m.ok()) {
    std::cout << "diameter " << m.diameter_mm << " mm  (disparity " << m.disparity_px << " px, NCC "
              << m.ncc << ", width " << m.width.d << " px)\n";
  }
  if (m.ok())
    return kExitOk;
  return fail(kName, m.message,
              m.status == stem::MeasureStatus::kBadPoints ? kExitBadInput : kExitRuntime);
}

}  // namespace

void registerStemCommand(CLI::App& app, int& exit_code) {
  const auto [command, args] = addSubcommand(
      app, "stem",
      "Stem diameter from four clicks on its edges in the raw left image of a stereo pair",
      exit_code, runStem);
  command->add_option("--left", args->left, "Left image (raw, as recorded)")->required();
  command->add_option("--right", args->right, "Right image (raw, as recorded)")->required();
  command->add_option("--intrinsics", args->intrinsics, "intrinsics.yml (M1 D1 M2 D2)")->required();
  command->add_option("--extrinsics", args->extrinsics, "extrinsics.yml (R T R1 R2 P1 P2 Q)")
      ->required();
  command
      ->add_option("--points", args->points,
                   "x1,y1,x2,y2,x3,y3,x4,y4: two points on each stem edge, any order")
      ->required();
  command->add_option("--bayer", args->bayer,
                      "The images are raw Bayer with this first row pattern (RG, GR, GB, BG)");
  command->add_flag("--json", args->json, "Print one JSON object");
  command->add_flag("--face-value", args->face_value,
                    "Take the clicks as the edges (no sub-pixel edge search), as the paper did");
  command->add_flag("--plane", args->plane,
                    "Diameter by eq. 13 (fronto-parallel patch) instead of the cylinder model");
}

}  // namespace fieldrig::tools
