#include "fieldrig/cloud/rig_calibration.h"

#include <cctype>
#include <cmath>
#include <sstream>

#include "fieldrig/cloud/cloud_options.h"
#include "fieldrig/core/durable_file.h"

namespace fieldrig::cloud {
namespace {

namespace fs = std::filesystem;
using core::Error;

bool readMatx(const cv::FileNode& node, int rows, int cols, cv::Mat& out) {
  if (node.empty())
    return false;
  core::Result<cv::Mat> matrix = stereo::readCalibrationMatrix(node);
  if (!matrix || matrix->rows != rows || matrix->cols != cols)
    return false;
  out = std::move(*matrix);
  return true;
}

// A head's name is also its calibration folder beside rig.yml and its frames' folder in a
// session: a plain name, never a path.
core::Result<void> checkHeadName(const std::string& name) {
  if (name.empty() || name.size() > 64 || name == "." || name == "..")
    return Error{"'" + name + "' is not a head name"};
  for (const char c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') {
      return Error{"'" + name +
                   "' is not a head name (letters, digits, '_', '-' and '.' only: it names a "
                   "folder)"};
    }
  }
  return {};
}

// Heads ride on one rig: a head more than this far from the bottom one is a transform in
// millimetres or a typo, and would put its points metres off without any other sign.
constexpr double kMaxHeadOffsetM = 10.0;

// A head's transform: rotation (stereo::checkRotation), bottom row (0 0 0 1), plausible offset.
core::Result<void> checkHeadTransform(const cv::Matx44d& transform) {
  if (auto rotation = stereo::checkRotation(transform.get_minor<3, 3>(0, 0)); !rotation)
    return rotation;
  if (transform(3, 0) != 0 || transform(3, 1) != 0 || transform(3, 2) != 0 ||
      transform(3, 3) != 1) {
    return Error{"not a rigid transform: its bottom row is not (0 0 0 1)"};
  }
  const double offset = cv::norm(cv::Vec3d(transform(0, 3), transform(1, 3), transform(2, 3)));
  if (offset > kMaxHeadOffsetM) {
    std::ostringstream text;
    text << "the head is " << offset << " m from the bottom one (at most " << kMaxHeadOffsetM
         << " m on one rig; rig.yml translations are in metres)";
    return Error{text.str()};
  }
  return {};
}

core::Result<RigCalibration> loadCheckedRig(const fs::path& directory) {
  const fs::path file = directory / "rig.yml";
  cv::FileStorage storage;
  if (auto opened = stereo::openCalibrationFile(file, storage); !opened)
    return opened.error();
  RigCalibration rig;
  const cv::FileNode heads = storage["heads"];
  if (heads.empty() || !heads.isSeq()) {
    return Error{file.string() + ": field 'heads' is missing or not a list of head names"};
  }
  for (const cv::FileNode& head_node : heads) {
    HeadCalibration head;
    if (!head_node.isString()) {
      return Error{file.string() + ": field 'heads' holds something that is not a name"};
    }
    head.name = static_cast<std::string>(head_node);
    if (auto checked = checkHeadName(head.name); !checked)
      return Error{file.string() + ": field 'heads': " + checked.error().message};
    for (const HeadCalibration& earlier : rig.heads) {
      if (earlier.name == head.name)
        return Error{file.string() + ": field 'heads' names '" + head.name + "' twice"};
    }
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
      if (auto checked = checkHeadTransform(head.to_bottom); !checked) {
        return Error{file.string() + ": field '" + key + "': " + checked.error().message};
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
    head.stereo = std::move(*calibration);
    rig.heads.push_back(std::move(head));
  }
  if (!storage["plot_rotation"].empty()) {
    cv::Mat rotation;
    if (!readMatx(storage["plot_rotation"], 3, 3, rotation)) {
      return Error{file.string() + ": field 'plot_rotation' is not a finite 3x3 matrix"};
    }
    if (auto checked = stereo::checkRotation(cv::Matx33d(rotation)); !checked) {
      return Error{file.string() + ": field 'plot_rotation': " + checked.error().message};
    }
    rig.plot_rotation = cv::Matx33d(rotation);
  }
  // Processing options that earlier versions wrote here, each with the default they were written
  // with: such a file still loads; a changed value must move to the configuration, where it takes
  // effect, rather than be ignored here. The edge filter was written at 2 px, its default then.
  const CloudOptions defaults;
  constexpr double kWrittenEdgeMaxJumpPx = 2.0;
  const std::pair<const char*, double> legacy_options[] = {
      {"max_depth_m", defaults.max_depth_m},
      {"min_depth_m", defaults.min_depth_m},
      {"scale", defaults.scale},
      {"min_disparity", defaults.matcher.min_disparity},
      {"num_disparities", defaults.matcher.num_disparities},
      {"edge_max_jump_px", kWrittenEdgeMaxJumpPx},
  };
  for (const auto& [key, default_value] : legacy_options) {
    const cv::FileNode node = storage[key];
    if (node.empty())
      continue;
    const bool is_default =
        (node.isReal() || node.isInt()) && static_cast<double>(node) == default_value;
    if (!is_default) {
      return Error{file.string() + ": field '" + key +
                   "' is a processing option, no longer part of the calibration: set it as " +
                   (std::string(key).find("disparit") != std::string::npos ? "pipeline.matcher."
                                                                           : "pipeline.cloud.") +
                   key + " in the configuration and remove it here"};
    }
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

}  // namespace

core::Result<RigCalibration> loadRigCalibration(const fs::path& directory) {
  // A node of another type than the one asked for throws inside OpenCV; whatever escapes the
  // checks is still a damaged file, not a crash.
  try {
    return loadCheckedRig(directory);
  } catch (const std::exception& e) {
    return Error{(directory / "rig.yml").string() + ": not a readable rig calibration (" +
                 e.what() + ")"};
  }
}

core::Result<fs::path> saveRigCalibration(const RigCalibration& rig, const fs::path& directory) {
  const fs::path file = directory / "rig.yml";
  // Before anything is written: a name with a path in it would write outside `directory`.
  for (const HeadCalibration& head : rig.heads) {
    if (auto checked = checkHeadName(head.name); !checked)
      return Error{file.string() + ": " + checked.error().message};
  }
  for (const HeadCalibration& head : rig.heads) {
    core::Result<fs::path> saved =
        stereo::saveStereoCalibration(head.stereo, directory / head.name);
    if (!saved)
      return saved.error();
  }
  std::string text;
  try {
    cv::FileStorage storage(".yml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
    storage << "heads"
            << "[";
    for (const HeadCalibration& head : rig.heads)
      storage << head.name;
    storage << "]";
    for (const HeadCalibration& head : rig.heads) {
      storage << head.name + "_to_bottom" << cv::Mat(head.to_bottom);
    }
    storage << "plot_rotation" << cv::Mat(rig.plot_rotation) << "pixel_format"
            << std::string(core::toString(rig.pixel_format));
    text = storage.releaseAndGetString();
  } catch (const cv::Exception& e) {
    return Error{file.string() + ": cannot write: " + e.what()};
  }
  // Replaced whole, so that a crash leaves the old file or the new one.
  if (std::string failed = core::replaceFileAtomically(fs::absolute(file), text); !failed.empty())
    return Error{std::move(failed)};
  return directory;
}

}  // namespace fieldrig::cloud
