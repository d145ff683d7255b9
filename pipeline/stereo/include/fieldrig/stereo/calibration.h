// One stereo head's calibration, in the file layout of OpenCV's stereo_calib sample so that the
// files interoperate with OpenCV's own tools:
//   intrinsics.yml  M1 D1 M2 D2            (camera matrices and distortion, left and right)
//   extrinsics.yml  R T R1 R2 P1 P2 Q      (right camera pose, rectification, reprojection)
// Translation is in metres, so the baseline is |T| m and Q reprojects disparities to metres.
// image_width/image_height are an addition of ours (OpenCV's readers ignore unknown keys); files
// without them (OpenCV's own) load with an empty image_size, and users take the images' size.
#pragma once

#include <cstdint>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>

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

// "WIDTHxHEIGHT", as error messages about image sizes print it.
std::string sizeText(cv::Size size);

// Whether the values are usable, not only well-formed: OpenCV rectifies and reprojects with any
// finite matrix without complaint, so a singular camera matrix or a zeroed rotation would turn
// into empty disparity maps and wrong sizes far from the file that caused them. Each check's error
// names the field ("field 'M1': singular camera matrix (fx = 0)"); the loader adds the file.
//   checkIntrinsics: M1, M2 are [fx s cx; 0 fy cy; 0 0 1] with fx, fy > 0 (hence invertible),
//     fx/fy within [1/kMaxFocalAspect, kMaxFocalAspect], the principal point inside the image
//     (kPrincipalPointMargin of its size outside is tolerated) or, without an image size, at
//     positive coordinates; D1, D2 finite; the image size, when given, positive and within what
//     cv::remap addresses (kMaxImageSide).
//   checkExtrinsics: R, R1, R2 rotations (checkRotation); T a baseline in [kMinBaselineM,
//     kMaxBaselineM]; P1, P2 finite with a positive rectified focal length; Q reprojecting
//     (Q(2,3) = f != 0) with the baseline T gives.
core::Result<void> checkIntrinsics(const StereoCalibration& calibration);
core::Result<void> checkExtrinsics(const StereoCalibration& calibration);

// A rotation is orthonormal, ||R·Rᵀ − I|| (Frobenius) <= kRotationTolerance, with det +1 (not a
// reflection). The error says which, with the measured value.
core::Result<void> checkRotation(const cv::Matx33d& rotation);

// 1e-3: OpenCV writes 17 significant digits (errors ~1e-15), and rotations copied by hand with 4
// or more digits stay below 1e-3; a matrix further off is not a rotation but a mistake, and
// would skew geometry by more than a milliradian.
inline constexpr double kRotationTolerance = 1e-3;
// Square pixels give 1; anamorphic optics stay well inside 2. Beyond it a value was mistyped.
inline constexpr double kMaxFocalAspect = 2.0;
inline constexpr double kPrincipalPointMargin = 0.1;
// cv::remap takes the rectification maps as 16-bit coordinates.
inline constexpr int kMaxImageSide = 32767;
// |T| is in metres: a baseline over 10 m is a calibration in millimetres (a board square given
// in mm), one under 1 mm a zeroed or mistyped T.
inline constexpr double kMinBaselineM = 1e-3;
inline constexpr double kMaxBaselineM = 10.0;

// OpenCV YAML files as every calibration loader reads them (the project writes YAML; OpenCV's XML
// is not read). cv::FileStorage trusts what a file says: `node >> mat` allocates the declared
// rows x cols before reading the data (16 GiB for "cols: 2147483647"), open() hangs on control
// bytes and on some malformed YAML and throws std::length_error on some damaged files, and
// indexing a file whose top is not a map throws. These check first and turn every failure into an
// error naming the file (and the line or field).
//   openCalibrationFile: a regular file of at most kMaxCalibrationFileBytes, without control
//     characters other than tab and line breaks, that yaml-cpp reads as a map (so OpenCV's parser
//     only meets well-formed YAML) and OpenCV then opens as a map of fields.
//   readCalibrationMatrix: a 2-D matrix node of at most kMaxCalibrationMatrixSide rows and columns
//     whose data has rows x cols finite values, as CV_64F; the error says what is wrong with it.
inline constexpr std::uintmax_t kMaxCalibrationFileBytes = 1 << 20;
inline constexpr int kMaxCalibrationMatrixSide = 16;
core::Result<void> openCalibrationFile(const std::filesystem::path& file, cv::FileStorage& storage);
core::Result<cv::Mat> readCalibrationMatrix(const cv::FileNode& node);

// Reads the two files and checks them (checkIntrinsics, checkExtrinsics); the error names the
// file and the missing, malformed or implausible field.
core::Result<StereoCalibration> loadStereoCalibration(const std::filesystem::path& intrinsics,
                                                      const std::filesystem::path& extrinsics);
// Reads DIR/intrinsics.yml and DIR/extrinsics.yml.
core::Result<StereoCalibration> loadStereoCalibration(const std::filesystem::path& directory);

// Writes DIR/intrinsics.yml and DIR/extrinsics.yml (creating DIR). The error names the file.
core::Result<std::filesystem::path> saveStereoCalibration(const StereoCalibration& calibration,
                                                          const std::filesystem::path& directory);

}  // namespace fieldrig::stereo
