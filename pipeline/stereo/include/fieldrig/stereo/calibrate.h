// Chessboard calibration of one stereo head (corners with sub-pixel refinement, each camera's
// intrinsics, cv::stereoCalibrate, cv::stereoRectify), the epipolar error OpenCV's stereo_calib
// sample reports, and the transform between two heads from a board both see at once.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/stereo/calibration.h"

namespace fieldrig::stereo {

struct BoardSpec {
  cv::Size inner_corners{9, 6};  // columns × rows of inner corners
  double square_m = 0.025;
};

// The board's inner corners in image pixels, refined to sub-pixel; nullopt when not all found.
std::optional<std::vector<cv::Point2f>> findBoardCorners(const cv::Mat& grey,
                                                         const BoardSpec& board);
// The board's corners in its own frame (z = 0), metres, in findBoardCorners' order.
std::vector<cv::Point3f> boardPoints(const BoardSpec& board);

// One pair's corners: empty vectors when the board was not found in that image.
struct PairCorners {
  std::string name;  // for reports: "left01.jpg/right01.jpg"
  std::vector<cv::Point2f> left, right;
  bool found() const { return !left.empty() && !right.empty(); }
};

struct BoardPairs {
  std::vector<PairCorners> pairs;  // one per image pair, in the given order
  cv::Size image_size;             // of every image
};

// Reads the images `left[i]`, `right[i]` (same count) and finds the board in each; a pair counts
// only when both images show it (its corners are cleared otherwise). The error names a file that
// cannot be read or whose size differs from the first image's.
core::Result<BoardPairs> findBoardInImagePairs(const std::vector<std::string>& left,
                                               const std::vector<std::string>& right,
                                               const BoardSpec& board);

struct CalibrateOptions {
  // A view whose per-view RMS error (the worse of its two cameras) exceeds drop_factor × the
  // median is dropped and the head recalibrated once without it; <= 0 keeps every view.
  double drop_factor = 2.5;
  int min_pairs = 3;
  double rectify_alpha = 0;  // stereoRectify's alpha: 0 keeps valid pixels only
};

struct ViewReport {
  std::string name;
  bool found = false;
  bool used = false;
  double error_left = 0;  // per-view RMS of the first calibration, pixels
  double error_right = 0;
  std::string dropped_because;  // empty when used or not found
};

struct HeadCalibrationReport {
  StereoCalibration calibration;
  double rms = 0;                // stereoCalibrate's RMS of the final calibration
  double epipolar_error_px = 0;  // stereo_calib sample's "average epipolar err"
  int pairs_used = 0;
  std::vector<ViewReport> views;
};

// Calibrates one head from corners found in `pairs` (images `image_size`). The error says why
// (too few boards found, a result that checkIntrinsics/checkExtrinsics refuse, …).
core::Result<HeadCalibrationReport> calibrateHead(const std::vector<PairCorners>& pairs,
                                                  const BoardSpec& board, cv::Size image_size,
                                                  const CalibrateOptions& options = {});

// The sample's metric: corners undistorted (P = camera matrix), each checked against the other
// image's epipolar line from F; the sum of both distances averaged over the points.
double epipolarError(const StereoCalibration& calibration, const cv::Mat& F,
                     const std::vector<PairCorners>& pairs);

// 4×4 transform from head B's frame into head A's frame, where a head's frame is its rectified
// left camera (the frame Q reprojects into). Boards seen at once by A's left camera (corners_a)
// and B's left camera (corners_b), one entry per view; uses cv::stereoCalibrate with the heads'
// intrinsics fixed. The error says why (too few views).
core::Result<cv::Matx44d> calibrateHeadToHead(
    const StereoCalibration& head_a, const StereoCalibration& head_b,
    const std::vector<std::vector<cv::Point2f>>& corners_a,
    const std::vector<std::vector<cv::Point2f>>& corners_b, const BoardSpec& board,
    double* rms = nullptr);

struct HeadToHeadReport {
  cv::Matx44d b_to_a = cv::Matx44d::eye();  // head B's frame → head A's frame
  double rms = 0;
  int views_used = 0;
};

// The same from image pairs whose left images are head A's left camera and right images head
// B's left camera, taken at once (findBoardInImagePairs); the views where both saw the board are
// used. A head calibration without an image size takes `pairs.image_size`.
core::Result<HeadToHeadReport> calibrateHeadToHead(StereoCalibration head_a,
                                                   const StereoCalibration& head_b,
                                                   const BoardPairs& pairs, const BoardSpec& board);

// Writes `b_to_a` (4×4, to copy into rig.yml) and `rms` to an OpenCV YAML file; the error names
// the file.
core::Result<std::filesystem::path> saveHeadToHead(const HeadToHeadReport& report,
                                                   const std::filesystem::path& file);

}  // namespace fieldrig::stereo
