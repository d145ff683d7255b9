// A rendered truth depth map in place of matching: the simulator writes, beside each raw frame, the
// z of the surface in that camera's own unrectified frame through each raw pixel's centre
// (sim/field's SSSSSS_C_NAME.depth.pfm; 0 = sky). This turns the left camera's map into the
// disparity map the matcher would give at best — rectified, at matching resolution, in Q's
// convention — so that everything after matching (edge filter, reprojection, fusion, crop,
// traits) runs unchanged on it. It also scores a matched disparity map against that truth.
#pragma once

#include <opencv2/core.hpp>

#include "fieldrig/core/result.h"
#include "fieldrig/stereo/calibration.h"

namespace fieldrig::stereo {

// How far a head's matched disparity is from the truth, over the truth's vegetation pixels whose
// rectified depth lies in (min_depth, max_depth].
struct DisparityTruthScore {
  std::size_t pixels = 0;       // vegetation pixels with a truth depth in range
  double matched_fraction = 0;  // of those, with a disparity
  // Of the matched ones, |disparity error| > bad_threshold_px (matching resolution).
  double bad_fraction = 0;
  double median_abs_depth_error_m = 0;  // of the matched ones
  double median_depth_error_m = 0;      // signed: measured − truth (> 0: too far)
};

// What reaches the cloud: of the pixels with a disparity whose depth lies in (min_depth,
// max_depth] (after every filter; depth along the head's rectified axis, where the cloud crops
// along the plot's, the same for a level head), how many sit off the surface the truth has on
// their ray.
struct CloudTruthScore {
  std::size_t points = 0;           // pixels that become points
  double off_surface_fraction = 0;  // depth more than tolerance from the truth's, or on sky
  double on_sky_fraction = 0;       // the truth has nothing on that ray
  // The off-surface points by which side of the truth on their own ray they lie (those with no
  // truth on it are on sky or beside a rim): nearer (a background pulled forward, a near-range
  // mismatch) or farther (a leaf pushed back). Fractions of `points`.
  double off_nearer_fraction = 0;
  double off_farther_fraction = 0;
  // Of the nearer ones, those whose truth lies beyond max_depth_m: something the depth crop
  // would have removed (the next row, the far soil) matched into it.
  double from_beyond_crop_fraction = 0;
};

// Thread contract: thread-compatible; disparity(), rectifyMask() and score() are const.
class TruthDepthRectifier {
 public:
  // `scaled`: the head's calibration at matching resolution (HeadPipeline::matchingCalibration);
  // `camera_size`: the raw frames' size; `scale`: matching / camera resolution.
  static core::Result<TruthDepthRectifier> create(const StereoCalibration& scaled,
                                                  cv::Size camera_size, double scale);

  // `raw_depth` (CV_32F, camera size; z in metres, ≤ 0 or non-finite = none) → disparity (CV_32F,
  // matching size, kInvalidDisparity = none). Each rectified pixel takes the depth of the raw pixel
  // nearest to where its ray leaves the lens (no blending across depth edges) and turns it into
  // the rectified frame's depth along its own ray, then into disparity by inverting Q.
  core::Result<cv::Mat> disparity(const cv::Mat& raw_depth) const;

  // An 8-bit raw-left mask (camera size) onto the rectified grid, nearest pixel.
  core::Result<cv::Mat> rectifyMask(const cv::Mat& raw_mask) const;

  // `measured` against `truth` (both CV_32F disparities at matching size) where `mask` (8-bit,
  // matching size) is set and the truth depth is in (min_depth_m, max_depth_m].
  DisparityTruthScore score(const cv::Mat& measured, const cv::Mat& truth, const cv::Mat& mask,
                            double min_depth_m, double max_depth_m,
                            double bad_threshold_px = 2.0) const;

  // The pixels of `measured` that become points against the truth on their rays: a point is off
  // the surface when its depth differs by more than `tolerance_m` from the truth's on its own ray
  // and on every ray up to 2 pixels away (a few mm across at the plants' range: a leaf's rim
  // pixel may match the leaf while its centre ray passes beside it). Along rays, which can only
  // overstate the distance to the nearest surface. On sky: no surface on any of those rays.
  CloudTruthScore scoreCloud(const cv::Mat& measured, const cv::Mat& truth, double min_depth_m,
                             double max_depth_m, double tolerance_m = 0.03) const;

 private:
  cv::Size camera_size_;
  cv::Mat map_x_, map_y_;  // rectified pixel → raw pixel (camera resolution), CV_32F
  cv::Mat depth_factor_;   // rectified z / raw-camera z along each rectified ray, CV_32F
  cv::Matx44d q_;
};

// The truth's disparity on exactly the pixels where `measured` has one (both CV_32F disparities
// at matching size), kInvalidDisparity elsewhere and where the truth has none: a matcher's
// coverage without its depth errors.
cv::Mat truthWhereMatched(const cv::Mat& measured, const cv::Mat& truth);

}  // namespace fieldrig::stereo
