// One stereo head's calibration, in the file layout of OpenCV's stereo_calib sample so that the
// files interoperate with OpenCV's own tools:
//   intrinsics.yml  M1 D1 M2 D2            (camera matrices and distortion, left and right)
//   extrinsics.yml  R T R1 R2 P1 P2 Q      (right camera pose, rectification, reprojection)
// Translation is in metres, so the baseline is |T| m and Q reprojects disparities to metres.
// image_width/image_height are an addition of ours (OpenCV's readers ignore unknown keys); files
// without them (OpenCV's own) load with an empty image_size, and users take the images' size.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "fieldrig/core/result.h"

namespace fieldrig::stereo {

struct StereoCalibration {
  cv::Mat M1, D1, M2, D2;     // CV_64F 3×3 and 1×N (N = 4, 5, 8, 12 or 14)
  cv::Mat R, T;               // right camera w.r.t. left: 3×3, 3×1 (metres)
  cv::Mat R1, R2, P1, P2, Q;  // stereoRectify's output: 3×3, 3×3, 3×4, 3×4, 4×4
  cv::Size image_size;        // of the calibration images; empty when the files lack it

  // |T| in metres.
  double baseline() const;
  // Focal length of the rectified pair in pixels (P1(0,0)).
  double rectifiedFocalPx() const;
  // The same calibration for images scaled by `factor` (0.5 for the paper's 812×612): camera
  // and projection matrices scaled, Q recomputed; distortion and rotations unchanged.
  StereoCalibration scaled(double factor) const;
};

// A distortion-free pair of identical pinhole cameras (principal point at the image centre), the
// right one `baseline_m` along the left one's x, rectified with stereoRectify: the calibration of
// rendered scenes and synthetic rigs.
StereoCalibration idealStereoCalibration(double focal_px, cv::Size image_size, double baseline_m);

// Reads the two files; the error names the file and the missing or malformed field.
core::Result<StereoCalibration> loadStereoCalibration(const std::filesystem::path& intrinsics,
                                                      const std::filesystem::path& extrinsics);
// Reads DIR/intrinsics.yml and DIR/extrinsics.yml.
core::Result<StereoCalibration> loadStereoCalibration(const std::filesystem::path& directory);

// Writes DIR/intrinsics.yml and DIR/extrinsics.yml (creating DIR). The error names the file.
core::Result<std::filesystem::path> saveStereoCalibration(const StereoCalibration& calibration,
                                                          const std::filesystem::path& directory);

}  // namespace fieldrig::stereo
