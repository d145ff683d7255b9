#include "fieldrig/stereo/matcher.h"
#include "fieldrig/core/time.h"

#include <chrono>
#include <cmath>
#include <opencv2/imgproc.hpp>

namespace fieldrig::stereo {
namespace {

using Clock = std::chrono::steady_clock;

cv::Mat toChannels(const cv::Mat& image, bool colour) {
  if (colour) {
    if (image.channels() == 3)
      return image;
    cv::Mat bgr;
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
    return bgr;
  }
  if (image.channels() == 1)
    return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

// The right matcher reports right-view disparities as negative values in
// [-(min + num) + 1, -min], and invalid pixels one step below that range.
cv::Mat rightViewToFloat(const cv::Mat& fixed_point, const MatcherOptions& options) {
  cv::Mat out(fixed_point.size(), CV_32F);
  const int lowest_valid =
      (-(options.min_disparity + options.num_disparities) + 1) * cv::StereoMatcher::DISP_SCALE;
  for (int y = 0; y < fixed_point.rows; ++y) {
    const std::int16_t* in = fixed_point.ptr<std::int16_t>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < fixed_point.cols; ++x) {
      o[x] = in[x] < lowest_valid
                 ? kInvalidDisparity
                 : -static_cast<float>(in[x]) / static_cast<float>(cv::StereoMatcher::DISP_SCALE);
    }
  }
  return out;
}

}  // namespace

cv::Mat toFloatDisparity(const cv::Mat& fixed_point, int min_disparity) {
  cv::Mat out(fixed_point.size(), CV_32F);
  const int invalid_below = min_disparity * cv::StereoMatcher::DISP_SCALE;
  for (int y = 0; y < fixed_point.rows; ++y) {
    const std::int16_t* in = fixed_point.ptr<std::int16_t>(y);
    float* o = out.ptr<float>(y);
    for (int x = 0; x < fixed_point.cols; ++x) {
      o[x] = in[x] < invalid_below
                 ? kInvalidDisparity
                 : static_cast<float>(in[x]) / static_cast<float>(cv::StereoMatcher::DISP_SCALE);
    }
  }
  return out;
}

void leftRightCheck(cv::Mat& left_disparity, const cv::Mat& right_disparity, float max_diff) {
  CV_Assert(left_disparity.type() == CV_32F && right_disparity.type() == CV_32F &&
            left_disparity.size() == right_disparity.size());
  for (int y = 0; y < left_disparity.rows; ++y) {
    float* left = left_disparity.ptr<float>(y);
    const float* right = right_disparity.ptr<float>(y);
    for (int x = 0; x < left_disparity.cols; ++x) {
      if (left[x] < 0)
        continue;
      const int xr = static_cast<int>(std::lround(static_cast<float>(x) - left[x]));
      if (xr < 0 || right[xr] < 0 || std::fabs(right[xr] - left[x]) > max_diff) {
        left[x] = kInvalidDisparity;
      }
    }
  }
}

DisparityMatcher::DisparityMatcher(const MatcherOptions& options) : options_(options) {
  const int channels = options_.match_colour ? 3 : 1;
  const int area = options_.block_size * options_.block_size;
  left_matcher_ = cv::StereoSGBM::create(
      options_.min_disparity, options_.num_disparities, options_.block_size,
      options_.p1_per_pixel * channels * area, options_.p2_per_pixel * channels * area,
      options_.disp12_max_diff, options_.pre_filter_cap, options_.uniqueness_ratio,
      options_.speckle_window, options_.speckle_range, options_.mode);
  if (options_.lr_check || options_.wls) {
    right_matcher_ = cv::ximgproc::createRightMatcher(left_matcher_);
  }
  if (options_.wls) {
    wls_ = cv::ximgproc::createDisparityWLSFilter(left_matcher_);
    wls_->setLambda(options_.wls_lambda);
    wls_->setSigmaColor(options_.wls_sigma);
  }
}

cv::Mat DisparityMatcher::compute(const cv::Mat& left, const cv::Mat& right,
                                  MatchTimings* timings) {
  CV_Assert(left.size() == right.size() && !left.empty());
  const cv::Mat left_in = toChannels(left, options_.match_colour);
  const cv::Mat right_in = toChannels(right, options_.match_colour);
  auto start = Clock::now();
  cv::Mat left_fixed;
  cv::Mat right_fixed;
  left_matcher_->compute(left_in, right_in, left_fixed);
  if (right_matcher_) {
    right_matcher_->compute(right_in, left_in, right_fixed);
  }
  if (timings)
    timings->sgbm_ms = core::millisecondsSince(start);
  start = Clock::now();
  cv::Mat disparity;
  if (wls_) {
    cv::Mat filtered;
    wls_->filter(left_fixed, left, filtered, right_fixed);
    disparity = toFloatDisparity(filtered, options_.min_disparity);
  } else {
    disparity = toFloatDisparity(left_fixed, options_.min_disparity);
    if (options_.lr_check) {
      leftRightCheck(disparity, rightViewToFloat(right_fixed, options_), options_.lr_max_diff);
    }
  }
  if (timings)
    timings->filter_ms = core::millisecondsSince(start);
  return disparity;
}

cv::Mat computeDefaultSgbm(const cv::Mat& left, const cv::Mat& right, int num_disparities) {
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(0, num_disparities, 3);
  cv::Mat fixed;
  sgbm->compute(toChannels(left, false), toChannels(right, false), fixed);
  return toFloatDisparity(fixed, 0);
}

}  // namespace fieldrig::stereo
