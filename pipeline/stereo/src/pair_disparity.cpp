#include "fieldrig/stereo/pair_disparity.h"

#include <chrono>

#include "fieldrig/core/time.h"
#include "fieldrig/stereo/rectifier.h"

namespace fieldrig::stereo {

core::Result<PairDisparity> computePairDisparity(const cv::Mat& left, const cv::Mat& right,
                                                 const StereoCalibration* calibration,
                                                 const MatcherOptions& options) {
  CV_Assert(left.size() == right.size());
  if (auto valid = validate(options, left.size()); !valid)
    return valid.error();
  cv::Mat left_matched = left, right_matched = right;
  if (calibration != nullptr) {
    CV_Assert(calibration->image_size == left.size());
    core::Result<Rectifier> rectifier = Rectifier::create(*calibration);
    if (!rectifier)
      return rectifier.error();
    rectifier->rectify(left, right, left_matched, right_matched);
  }
  DisparityMatcher matcher(options);
  PairDisparity out;
  const auto start = std::chrono::steady_clock::now();
  out.disparity = matcher.compute(left_matched, right_matched);
  out.match_ms = core::millisecondsSince(start);
  out.valid_fraction = static_cast<double>(cv::countNonZero(out.disparity >= 0)) /
                       static_cast<double>(out.disparity.total());
  return out;
}

}  // namespace fieldrig::stereo
