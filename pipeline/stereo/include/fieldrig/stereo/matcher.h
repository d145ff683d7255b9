// Semi-global matching of a rectified pair (OpenCV's StereoSGBM) with the post-processing the
// field images need: a left–right consistency check with a real right-view matcher, speckle
// removal, and optionally opencv_contrib's weighted-least-squares (WLS) filter.
#pragma once

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/ximgproc/disparity_filter.hpp>

#include "fieldrig/core/result.h"

namespace fieldrig::stereo {

// Disparities below this value mark invalid pixels in every float map this library returns.
inline constexpr float kInvalidDisparity = -1.0f;

struct MatcherOptions {
  int num_disparities = 128;  // multiple of 16
  int min_disparity = 0;
  int block_size = 5;  // odd
  // P1 = p1_per_pixel · channels · block², P2 likewise (OpenCV's own suggestion is 8 and 32).
  int p1_per_pixel = 8;
  int p2_per_pixel = 32;
  int pre_filter_cap = 63;
  int uniqueness_ratio = 10;
  // SGBM's speckle filter: connected pieces of disparity (neighbours within speckle_range px)
  // smaller than speckle_window pixels are made invalid. On five 24-plot rendered fields (75
  // plots in view, scale 0.5) it is what keeps mismatches out: window 50 put heights 4.6 cm off
  // on average and 25 cm at worst (100: 2.0 and 11.9), the filter off 41 cm on average; 200 cut
  // thin leaves (widths 14 cm narrow). Range 3 instead of 2 kept more leaf tips (width's mean error
  // against everything a camera sees 7.8 to 7.1 cm, 16 to 19 plots within 3 cm) and left every
  // worst case as it was; 4 and 6 raised the worst width from 18 to 21 cm.
  int speckle_window = 100;  // pixels; 0 disables speckle filtering
  int speckle_range = 3;     // pixels of disparity within one speckle
  // SGBM's own left–right check from the left cost volume (cheap); -1 disables it.
  int disp12_max_diff = 1;
  // Match the right view as well and keep left pixels whose right match points back within
  // lr_max_diff pixels (doubles the matching time).
  bool lr_check = false;
  float lr_max_diff = 1.0f;
  // opencv_contrib WLS filter (needs the right view; it fills invalid pixels).
  bool wls = false;
  double wls_lambda = 8000.0;
  double wls_sigma = 1.5;
  int mode = cv::StereoSGBM::MODE_SGBM_3WAY;
  bool match_colour = false;  // true: SGBM on BGR (3 channels), false: on grey
  // SGBM leaves the leftmost min_disparity + num_disparities columns of the left view without
  // disparity (a sixth of an 812-pixel image at 128), though most of them see what the right
  // camera sees too. true: the pair is padded by that many columns before matching, and a pixel
  // keeps its disparity only when its match lies inside the right image.
  bool full_width = true;
  // Pixels whose grey level varies less than this (standard deviation over a window of
  // block_size + 2, in 8-bit grey levels) have nothing to match on — sky, saturated highlights —
  // and SGBM's smoothness term fills them from their neighbours: they are made invalid. 0 keeps
  // them. 2 measured best on the rendered mesh field (24 plots, three stages): sky points had
  // put plots' heights up to 67 cm high; 4 kept less of the plants.
  double min_texture = 2.0;
  // -1: off. Otherwise a second matching at this uniqueness ratio (below uniqueness_ratio: more
  // matches, some ambiguous) adds the pixels the first left without disparity, but only those
  // in a piece of the second's disparity (neighbours within speckle_range) that the first
  // confirms: at least grow_confirmed_fraction of the piece's pixels match the first within
  // 1 px. Far-side leaves seen through gaps are ambiguous at the shipped ratio yet lie in pieces
  // the first partly matches; mismatched blobs do not.
  int grow_uniqueness_ratio = -1;
  double grow_confirmed_fraction = 0.0;
};

// The ranges validate() enforces, each with its reason:
// - disparities: SGBM returns 16-bit fixed point (×16), so min + num must stay below 2048; a range
//   of 1024 pixels is beyond any pair at field resolution, and the cost volume grows with it.
inline constexpr int kMaxNumDisparities = 1024;
inline constexpr int kMinMinDisparity = -1024;
inline constexpr int kMaxMinDisparity = 1023;
// - block: OpenCV suggests 3..11; matching time grows with the block (9999 ran for hours), and
//   P1/P2 = per_pixel · channels · block² must not overflow an int.
inline constexpr int kMaxBlockSize = 31;
inline constexpr int kMaxPenaltyPerPixel = 1000;
// - pre_filter_cap: OpenCV's own limit (StereoBM's; SGBM keeps the clipped values in 8 bits).
inline constexpr int kMaxPreFilterCap = 63;
// - min_texture: a standard deviation of 8-bit grey levels cannot exceed 127.5.
inline constexpr double kMaxMinTexture = 127.5;

// How validate() names an option in its errors: the configuration key ("num_disparities") or the
// `fieldrig disparity` flag ("--num-disparities").
enum class OptionNames { kConfigKeys, kCommandLineFlags };

// Every option finite and inside its range (above), checked before OpenCV sees it: out of range,
// OpenCV throws (num_disparities 100000), runs for hours (block_size 9999) or silently clamps.
// The error names the option and the allowed range.
core::Result<void> validate(const MatcherOptions& options,
                            OptionNames names = OptionNames::kConfigKeys);
// The same, and the disparity range leaves columns of an image of `matched_size` to match:
// min_disparity + num_disparities < width (+ min_disparity when negative). Beyond it OpenCV's
// SGBM aborts on an empty buffer (num_disparities 464 on a 450-pixel-wide pair).
core::Result<void> validate(const MatcherOptions& options, cv::Size matched_size,
                            OptionNames names = OptionNames::kConfigKeys);

// Per-call timings of DisparityMatcher::compute, milliseconds.
struct MatchTimings {
  double sgbm_ms = 0;    // left (and right) matcher
  double filter_ms = 0;  // LR check, WLS, conversion to float
};

// Thread contract: thread-compatible; one instance per thread (StereoSGBM keeps buffers).
class DisparityMatcher {
 public:
  explicit DisparityMatcher(const MatcherOptions& options);

  // Left-view disparity in pixels (CV_32F), kInvalidDisparity where no reliable match. Inputs:
  // rectified, same size; BGR or grey (converted as match_colour says).
  cv::Mat compute(const cv::Mat& left, const cv::Mat& right, MatchTimings* timings = nullptr);

  const MatcherOptions& options() const { return options_; }

 private:
  MatcherOptions options_;
  cv::Ptr<cv::StereoSGBM> left_matcher_;
  cv::Ptr<cv::StereoMatcher> right_matcher_;
  // grow_uniqueness_ratio's second matcher (and its right view for lr_check), else null.
  cv::Ptr<cv::StereoSGBM> grow_left_matcher_;
  cv::Ptr<cv::StereoMatcher> grow_right_matcher_;
  cv::Ptr<cv::ximgproc::DisparityWLSFilter> wls_;
};

// The baseline of the issue: plain OpenCV SGBM "with default parameters", i.e.
// cv::StereoSGBM::create(0, num_disparities, 3) and nothing else set (P1 = P2 = 0,
// disp12MaxDiff = 0, preFilterCap = 0, uniquenessRatio = 0, no speckle filter, MODE_SGBM), on
// grey images. Returns the left disparity in pixels, kInvalidDisparity where SGBM gave none.
cv::Mat computeDefaultSgbm(const cv::Mat& left, const cv::Mat& right, int num_disparities);

// Keeps pixels of `left_disparity` whose match in `right_disparity` (right view, positive
// pixels, kInvalidDisparity = none) lies within `max_diff`; the others become invalid.
// The disparity of `confident` where valid; elsewhere that of `ambiguous` where the pixel belongs
// to a piece of `ambiguous` (4-connected pixels whose disparities differ by at most
// `piece_range`) of which more than `min_confirmed_fraction` of the pixels (and at least one)
// have a valid `confident` disparity within 1 px of their own. Both CV_32F, same size.
cv::Mat growConfirmedPieces(const cv::Mat& confident, const cv::Mat& ambiguous, float piece_range,
                            double min_confirmed_fraction);

void leftRightCheck(cv::Mat& left_disparity, const cv::Mat& right_disparity, float max_diff);

// Makes invalid the pixels of `disparity` whose grey level in `image` (same size, grey or BGR)
// has a standard deviation below `min_std` over a `window` × `window` neighbourhood.
void dropTexturelessPixels(cv::Mat& disparity, const cv::Mat& image, int window, double min_std);

// Fixed-point SGBM output (CV_16S, ×16) → float pixels with kInvalidDisparity below min_disparity.
cv::Mat toFloatDisparity(const cv::Mat& fixed_point, int min_disparity);

}  // namespace fieldrig::stereo
