// One image pair's disparity, as `fieldrig disparity` computes it: rectified first when a
// calibration is given (at the images' own resolution, no downsampling), then matched.
#pragma once

#include <opencv2/core.hpp>

#include "fieldrig/core/result.h"
#include "fieldrig/stereo/calibration.h"
#include "fieldrig/stereo/matcher.h"

namespace fieldrig::stereo {

struct PairDisparity {
  cv::Mat disparity;          // CV_32F pixels of the left view, kInvalidDisparity = none
  double valid_fraction = 0;  // of all pixels
  double match_ms = 0;
};

// `left` and `right` must have one size, and `calibration` (when not null) must be for that size
// and carry it; callers check this against their files, so that the error can name them. The
// error says why the rectification cannot be built.
core::Result<PairDisparity> computePairDisparity(const cv::Mat& left, const cv::Mat& right,
                                                 const StereoCalibration* calibration,
                                                 const MatcherOptions& options);

}  // namespace fieldrig::stereo
