// The three-head rig as the cloud needs it: each head's calibration, its transform into the
// bottom head's frame, the rotation into the plot frame and the depth crop. Read from a
// calibration folder (layout in pipeline/cloud/README.md):
//   DIR/rig.yml                       heads, transforms, plot rotation, crop, pixel format, scale
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

struct HeadConfig {
  std::string name;  // "bottom", "middle", "top"; its cameras are NAME_left and NAME_right
  // Head frame (its rectified left camera, the frame Q reprojects into) → bottom head's frame.
  cv::Matx44d to_bottom = cv::Matx44d::eye();
  stereo::StereoCalibration calibration;  // at camera resolution, with its image size
  std::string leftCamera() const { return name + "_left"; }
  std::string rightCamera() const { return name + "_right"; }
};

struct RigConfig {
  std::vector<HeadConfig> heads;
  // Bottom head frame (x right, y down, z forward) → plot frame (x up, y along the row, z away
  // from the camera). The default is a camera whose image rows run along the row, upright.
  cv::Matx33d plot_rotation{0, -1, 0, 1, 0, 0, 0, 0, 1};
  double max_depth_m = 1.7;  // plot-frame z beyond this is a background row: cropped
  double min_depth_m = 0.2;  // closer than this is not a plant (mismatches near the lens)
  core::PixelFormat pixel_format = core::PixelFormat::kBayerRG8;
  double scale = 0.5;  // matching resolution / camera resolution
  // Disparity search range at matching resolution, [min_disparity, min + num). With f ≈ 675 px
  // and B = 0.12 m at 812×612, 0.8–1.7 m plants are 101–48 px.
  int min_disparity = 0;
  int num_disparities = 128;
  // Pixels on a depth edge — whose 3×3 neighbourhood spans more than this many pixels of
  // disparity — are not reprojected: SGBM blends foreground and background there, and the
  // blend lands as "flying" points between a leaf and what is behind it. 0 keeps them.
  double edge_max_jump_px = 2.0;
};

// Reads DIR/rig.yml and each head's DIR/<name>/{intrinsics,extrinsics}.yml. The error names the
// file and the field.
core::Result<RigConfig> loadRig(const std::filesystem::path& directory);
// Writes DIR/rig.yml and each head's calibration below DIR. The error names the file.
core::Result<std::filesystem::path> saveRig(const RigConfig& rig,
                                            const std::filesystem::path& directory);

}  // namespace fieldrig::cloud
