// Rectification of one head's pair with maps computed once (cv::initUndistortRectifyMap) and
// applied per frame (cv::remap), so that a FrameSet costs two remaps and no map building.
#pragma once

#include <opencv2/core.hpp>

#include "fieldrig/core/result.h"
#include "fieldrig/stereo/calibration.h"

namespace fieldrig::stereo {

// Thread contract: thread-compatible; rectify() is const and may run from several threads.
class Rectifier {
 public:
  // Maps for images of `calibration.image_size` (the calibration must carry its size).
  static core::Result<Rectifier> create(const StereoCalibration& calibration);

  // Remaps both images (any type remap accepts); their size must be size().
  void rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_out,
               cv::Mat& right_out) const;
  // The left image only (its depth comes from elsewhere: truth_depth.h).
  void rectifyLeft(const cv::Mat& left, cv::Mat& left_out) const;
  cv::Size size() const { return size_; }

 private:
  cv::Size size_;
  cv::Mat left_map1_, left_map2_, right_map1_, right_map2_;
};

}  // namespace fieldrig::stereo
