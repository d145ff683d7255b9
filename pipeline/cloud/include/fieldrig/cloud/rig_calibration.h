// The three-head rig's calibration, as `fieldrig calibrate` writes it: each head's stereo
// calibration, its transform into the bottom head's frame, the rotation into the plot frame and
// the cameras' pixel format. Processing choices (matching resolution, disparity range, depth
// crop) are not calibration: they are cloud::CloudOptions, set in the configuration.
//
// Read from a calibration folder (layout in pipeline/cloud/README.md):
//   DIR/rig.yml                       heads, transforms, plot rotation, pixel format
//   DIR/<head>/intrinsics.yml, DIR/<head>/extrinsics.yml    each head (OpenCV stereo_calib layout)
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/result.h"
#include "fieldrig/stereo/calibration.h"

namespace fieldrig::cloud {

struct HeadCalibration {
  std::string name;  // "bottom", "middle", "top"; its cameras are NAME_left and NAME_right
  // Head frame (its rectified left camera, the frame Q reprojects into) → bottom head's frame.
  cv::Matx44d to_bottom = cv::Matx44d::eye();
  stereo::StereoCalibration stereo;  // at camera resolution, with its image size
  std::string leftCamera() const { return name + "_left"; }
  std::string rightCamera() const { return name + "_right"; }
};

struct RigCalibration {
  std::vector<HeadCalibration> heads;
  // Bottom head frame (x right, y down, z forward) → plot frame (x up, y along the row, z away
  // from the camera). The default is a camera whose image rows run along the row, upright.
  cv::Matx33d plot_rotation{0, -1, 0, 1, 0, 0, 0, 0, 1};
  core::PixelFormat pixel_format = core::PixelFormat::kBayerRG8;
};

// Reads DIR/rig.yml and each head's DIR/<name>/{intrinsics,extrinsics}.yml. The error names the
// file and the field. Calibrations written before the processing options left rig.yml still
// carry them (max_depth_m, min_depth_m, scale, min_disparity, num_disparities, edge_max_jump_px):
// at the values they were written with they are ignored; any other value is an error saying
// where the option lives now, so that a changed value is never dropped without a word.
core::Result<RigCalibration> loadRigCalibration(const std::filesystem::path& directory);
// Writes DIR/rig.yml and each head's calibration below DIR. The error names the file.
core::Result<std::filesystem::path> saveRigCalibration(const RigCalibration& rig,
                                                       const std::filesystem::path& directory);

}  // namespace fieldrig::cloud
