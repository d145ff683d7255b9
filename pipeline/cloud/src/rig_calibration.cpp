#include "fieldrig/cloud/rig.h"

#include <cmath>

namespace fieldrig::cloud {
namespace {

namespace fs = std::filesystem;
using core::Error;

bool readMatx(const cv::FileNode& node, int rows, int cols, cv::Mat& out) {
  if (node.empty())
    return false;
  try {
    node >> out;
  } catch (const cv::Exception&) {
    return false;
  }
  if (out.rows != rows || out.cols != cols)
    return false;
  out.convertTo(out, CV_64F);
  return cv::checkRange(out);
}

bool isRotation(const cv::Matx33d& r) {
  const cv::Matx33d should_be_identity = r * r.t();
  return cv::norm(should_be_identity - cv::Matx33d::eye()) < 1e-3 && cv::determinant(r) > 0;
}

}  // namespace

core::Result<RigConfig> loadRig(const fs::path& directory) {
  const fs::path file = directory / "rig.yml";
  // Checked first so that OpenCV does not log its own error for a missing file.
  std::error_code ec;
  if (!fs::is_regular_file(file, ec)) {
    return Error{file.string() + ": cannot open"};
  }
  cv::FileStorage storage;
  try {
    storage.open(file.string(), cv::FileStorage::READ);
  } catch (const cv::Exception&) {
    return Error{file.string() + ": not a readable OpenCV YAML file"};
  }
  if (!storage.isOpened()) {
    return Error{file.string() + ": cannot open"};
  }
  RigConfig rig;
  const cv::FileNode heads = storage["heads"];
  if (heads.empty() || !heads.isSeq()) {
    return Error{file.string() + ": field 'heads' is missing or not a list of head names"};
  }
  for (const cv::FileNode& head_node : heads) {
    HeadConfig head;
    if (!head_node.isString()) {
      return Error{file.string() + ": field 'heads' holds something that is not a name"};
    }
    head.name = static_cast<std::string>(head_node);
    const std::string key = head.name + "_to_bottom";
    cv::Mat transform;
    if (storage[key].empty()) {
      if (!rig.heads.empty()) {
        return Error{file.string() + ": field '" + key + "' is missing"};
      }
      // The first head is the reference; its transform defaults to identity.
    } else if (!readMatx(storage[key], 4, 4, transform)) {
      return Error{file.string() + ": field '" + key + "' is not a finite 4x4 matrix"};
    } else {
      head.to_bottom = cv::Matx44d(transform);
      const cv::Matx33d rotation = head.to_bottom.get_minor<3, 3>(0, 0);
      if (!isRotation(rotation)) {
        return Error{file.string() + ": field '" + key + "' does not hold a rotation"};
      }
    }
    core::Result<stereo::StereoCalibration> calibration =
        stereo::loadStereoCalibration(directory / head.name);
    if (!calibration)
      return calibration.error();
    if (calibration->image_size.empty()) {
      return Error{(directory / head.name / "intrinsics.yml").string() +
                   ": fields 'image_width'/'image_height' are missing (the cameras' size)"};
    }
    head.calibration = std::move(*calibration);
    rig.heads.push_back(std::move(head));
  }
  if (!storage["plot_rotation"].empty()) {
    cv::Mat rotation;
    if (!readMatx(storage["plot_rotation"], 3, 3, rotation) || !isRotation(cv::Matx33d(rotation))) {
      return Error{file.string() + ": field 'plot_rotation' is not a 3x3 rotation matrix"};
    }
    rig.plot_rotation = cv::Matx33d(rotation);
  }
  auto readNumber = [&](const char* key, double& value) -> bool {
    const cv::FileNode node = storage[key];
    if (node.empty())
      return true;
    if (!node.isReal() && !node.isInt())
      return false;
    value = static_cast<double>(node);
    return std::isfinite(value);
  };
  double num_disparities = rig.num_disparities;
  double min_disparity = rig.min_disparity;
  if (!readNumber("max_depth_m", rig.max_depth_m) || !readNumber("min_depth_m", rig.min_depth_m) ||
      !readNumber("scale", rig.scale) || !readNumber("num_disparities", num_disparities) ||
      !readNumber("min_disparity", min_disparity) ||
      !readNumber("edge_max_jump_px", rig.edge_max_jump_px)) {
    return Error{file.string() +
                 ": one of 'max_depth_m', 'min_depth_m', 'scale', 'num_disparities', "
                 "'min_disparity', 'edge_max_jump_px' is not a number"};
  }
  rig.num_disparities = static_cast<int>(num_disparities);
  rig.min_disparity = static_cast<int>(min_disparity);
  if (rig.num_disparities <= 0 || rig.num_disparities % 16 != 0 || rig.min_disparity < 0) {
    return Error{file.string() +
                 ": field 'num_disparities' must be a positive multiple of 16 and "
                 "'min_disparity' not negative"};
  }
  if (!(rig.scale > 0 && rig.scale <= 1)) {
    return Error{file.string() + ": field 'scale' must be in (0, 1]"};
  }
  if (!(rig.max_depth_m > rig.min_depth_m)) {
    return Error{file.string() + ": field 'max_depth_m' must exceed 'min_depth_m'"};
  }
  if (!storage["pixel_format"].empty()) {
    const std::string name = static_cast<std::string>(storage["pixel_format"]);
    const auto format = core::parsePixelFormat(name);
    if (!format) {
      return Error{file.string() + ": field 'pixel_format': '" + name + "' is not known"};
    }
    rig.pixel_format = *format;
  }
  return rig;
}

core::Result<fs::path> saveRig(const RigConfig& rig, const fs::path& directory) {
  for (const HeadConfig& head : rig.heads) {
    core::Result<fs::path> saved =
        stereo::saveStereoCalibration(head.calibration, directory / head.name);
    if (!saved)
      return saved.error();
  }
  const fs::path file = directory / "rig.yml";
  try {
    cv::FileStorage storage(file.string(), cv::FileStorage::WRITE);
    if (!storage.isOpened())
      return Error{file.string() + ": cannot write"};
    storage << "heads"
            << "[";
    for (const HeadConfig& head : rig.heads)
      storage << head.name;
    storage << "]";
    for (const HeadConfig& head : rig.heads) {
      storage << head.name + "_to_bottom" << cv::Mat(head.to_bottom);
    }
    storage << "plot_rotation" << cv::Mat(rig.plot_rotation) << "max_depth_m" << rig.max_depth_m
            << "min_depth_m" << rig.min_depth_m << "pixel_format"
            << std::string(core::toString(rig.pixel_format)) << "scale" << rig.scale
            << "min_disparity" << rig.min_disparity << "num_disparities" << rig.num_disparities
            << "edge_max_jump_px" << rig.edge_max_jump_px;
  } catch (const cv::Exception& e) {
    return Error{file.string() + ": cannot write: " + e.what()};
  }
  return directory;
}

}  // namespace fieldrig::cloud
