#include "commands/stem_support.h"

#include "fieldrig/stereo/preprocess.h"

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <vector>

namespace fieldrig::tools {
namespace {

nlohmann::ordered_json pointsJson(const stem::Points4& points) {
  nlohmann::ordered_json out = nlohmann::ordered_json::array();
  for (const cv::Point2d& p : points)
    out.push_back({p.x, p.y});
  return out;
}

}  // namespace

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

cv::Mat toGrey(const cv::Mat& raw, core::PixelFormat format) {
  if (format == core::PixelFormat::kMono8)
    return raw;
  // The pipeline's debayering (GenICam pattern names), then grey.
  cv::Mat bgr;
  cv::cvtColor(raw, bgr, stereo::bgrConversionCode(format));
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

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
  return toGrey(image, *format);
}

nlohmann::ordered_json measurementJson(const stem::StemMeasurement& m) {
  nlohmann::ordered_json out;
  out["status"] = std::string(stem::toString(m.status));
  if (!m.ok())
    out["message"] = m.message;
  const bool matched = m.ok() || m.status == stem::MeasureStatus::kWeakMatch;
  out["diameter_mm"] = m.ok() ? nlohmann::ordered_json(m.diameter_mm) : nullptr;
  out["disparity_px"] = matched ? nlohmann::ordered_json(m.disparity_px) : nullptr;
  out["ncc"] = matched ? nlohmann::ordered_json(m.ncc) : nullptr;
  out["ncc_second"] = matched ? nlohmann::ordered_json(m.ncc_second) : nullptr;
  out["distinctness"] = matched ? nlohmann::ordered_json(m.distinctness) : nullptr;
  out["diameter_plane_mm"] = m.ok() ? nlohmann::ordered_json(m.diameter_plane_mm) : nullptr;
  out["patch_depth_m"] = m.ok() ? nlohmann::ordered_json(m.patch_depth_m) : nullptr;
  out["width_px"] = {{"d12", m.width.d12}, {"d34", m.width.d34}, {"d", m.width.d}};
  out["edges_refined"] = m.edges_refined;
  out["edge_samples"] = {m.edge_samples_left, m.edge_samples_right};
  out["quadrangle_rectified"] = pointsJson(stem::toPoints(m.refined));
  out["clicked_rectified"] = pointsJson(stem::toPoints(m.clicked));
  out["right_patch_raw"] = matched ? pointsJson(m.right_patch_raw) : nullptr;
  out["elapsed_ms"] = m.elapsed_ms;
  return out;
}

}  // namespace fieldrig::tools
