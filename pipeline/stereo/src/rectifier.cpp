#include "fieldrig/stereo/rectifier.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>

namespace fieldrig::stereo {

core::Result<Rectifier> Rectifier::create(const StereoCalibration& calibration) {
  if (calibration.image_size.empty()) {
    return core::Error{"calibration has no image size (image_width/image_height)"};
  }
  Rectifier rectifier;
  rectifier.size_ = calibration.image_size;
  // Fixed-point maps (CV_16SC2 + CV_16UC1): remap runs about twice as fast as with float maps.
  cv::initUndistortRectifyMap(calibration.M1, calibration.D1, calibration.R1, calibration.P1,
                              rectifier.size_, CV_16SC2, rectifier.left_map1_,
                              rectifier.left_map2_);
  cv::initUndistortRectifyMap(calibration.M2, calibration.D2, calibration.R2, calibration.P2,
                              rectifier.size_, CV_16SC2, rectifier.right_map1_,
                              rectifier.right_map2_);
  return rectifier;
}

void Rectifier::rectify(const cv::Mat& left, const cv::Mat& right, cv::Mat& left_out,
                        cv::Mat& right_out) const {
  CV_Assert(left.size() == size_ && right.size() == size_);
  cv::remap(left, left_out, left_map1_, left_map2_, cv::INTER_LINEAR);
  cv::remap(right, right_out, right_map1_, right_map2_, cv::INTER_LINEAR);
}

void Rectifier::rectifyLeft(const cv::Mat& left, cv::Mat& left_out) const {
  CV_Assert(left.size() == size_);
  cv::remap(left, left_out, left_map1_, left_map2_, cv::INTER_LINEAR);
}

}  // namespace fieldrig::stereo
