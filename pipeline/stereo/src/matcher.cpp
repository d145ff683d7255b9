#include "fieldrig/stereo/matcher.h"
#include "fieldrig/core/time.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

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

std::string optionName(std::string_view key, OptionNames names) {
  if (names == OptionNames::kConfigKeys)
    return std::string(key);
  std::string flag = "--" + std::string(key);
  std::replace(flag.begin(), flag.end(), '_', '-');
  return flag;
}

}  // namespace

core::Result<void> validate(const MatcherOptions& options, OptionNames names) {
  using core::Error;
  const auto outside = [&](std::string_view key, auto value, const std::string& allowed) {
    std::ostringstream text;
    text << optionName(key, names) << ' ' << value << " is outside the allowed range " << allowed;
    return Error{text.str()};
  };
  const auto range = [](auto lo, auto hi) {
    std::ostringstream text;
    text << '[' << lo << ", " << hi << ']';
    return text.str();
  };
  if (options.num_disparities < 16 || options.num_disparities > kMaxNumDisparities ||
      options.num_disparities % 16 != 0) {
    return outside("num_disparities", options.num_disparities,
                   range(16, kMaxNumDisparities) + " (a multiple of 16)");
  }
  if (options.min_disparity < kMinMinDisparity || options.min_disparity > kMaxMinDisparity) {
    return outside("min_disparity", options.min_disparity,
                   range(kMinMinDisparity, kMaxMinDisparity));
  }
  if (options.block_size < 1 || options.block_size > kMaxBlockSize || options.block_size % 2 == 0) {
    return outside("block_size", options.block_size, range(1, kMaxBlockSize) + " (odd)");
  }
  for (const auto& [key, value] :
       {std::pair{"p1_per_pixel", options.p1_per_pixel}, {"p2_per_pixel", options.p2_per_pixel}}) {
    if (value < 0 || value > kMaxPenaltyPerPixel)
      return outside(key, value, range(0, kMaxPenaltyPerPixel));
  }
  if (options.pre_filter_cap < 0 || options.pre_filter_cap > kMaxPreFilterCap)
    return outside("pre_filter_cap", options.pre_filter_cap, range(0, kMaxPreFilterCap));
  if (options.uniqueness_ratio < 0 || options.uniqueness_ratio > 100)
    return outside("uniqueness_ratio", options.uniqueness_ratio, range(0, 100));
  if (options.speckle_window < 0)
    return outside("speckle_window", options.speckle_window, "[0, ...) pixels");
  // SGBM multiplies the range by 16 (its fixed point); beyond the disparity range it means nothing.
  if (options.speckle_range < 0 || options.speckle_range > kMaxNumDisparities)
    return outside("speckle_range", options.speckle_range, range(0, kMaxNumDisparities));
  if (options.disp12_max_diff < -1 || options.disp12_max_diff > kMaxNumDisparities) {
    return outside("disp12_max_diff", options.disp12_max_diff,
                   range(-1, kMaxNumDisparities) + " (-1 disables it)");
  }
  // Written as negations so that NaN fails them.
  if (!(options.lr_max_diff >= 0 && std::isfinite(options.lr_max_diff)))
    return outside("lr_max_diff", options.lr_max_diff, "[0, ...) pixels, finite");
  if (!(options.wls_lambda >= 0 && std::isfinite(options.wls_lambda)))
    return outside("wls_lambda", options.wls_lambda, "[0, ...), finite");
  if (!(options.wls_sigma > 0 && std::isfinite(options.wls_sigma)))
    return outside("wls_sigma", options.wls_sigma, "(0, ...), finite");
  if (options.grow_uniqueness_ratio < -1 || options.grow_uniqueness_ratio > 100) {
    return outside("grow_uniqueness_ratio", options.grow_uniqueness_ratio,
                   range(-1, 100) + " (-1 disables it)");
  }
  if (!(options.grow_confirmed_fraction >= 0 && options.grow_confirmed_fraction < 1))
    return outside("grow_confirmed_fraction", options.grow_confirmed_fraction, "[0, 1)");
  if (options.grow_uniqueness_ratio >= 0 && options.wls) {
    return Error{optionName("grow_uniqueness_ratio", names) +
                 " needs wls off (WLS fills every pixel, so there is nothing to grow into)"};
  }
  if (!(options.min_texture >= 0 && options.min_texture <= kMaxMinTexture))
    return outside("min_texture", options.min_texture, range(0, kMaxMinTexture));
  if (options.mode != cv::StereoSGBM::MODE_SGBM && options.mode != cv::StereoSGBM::MODE_HH &&
      options.mode != cv::StereoSGBM::MODE_SGBM_3WAY && options.mode != cv::StereoSGBM::MODE_HH4) {
    return outside("mode", options.mode, "(sgbm, hh, sgbm_3way or hh4)");
  }
  return {};
}

core::Result<void> validate(const MatcherOptions& options, cv::Size matched_size,
                            OptionNames names) {
  if (auto valid = validate(options, names); !valid)
    return valid;
  // SGBM matches columns [max(maxD, 0), width + min(minD, 0)), maxD = minD + num.
  const int limit = matched_size.width - std::max(options.min_disparity, 0);
  if (options.num_disparities < limit)
    return {};
  std::ostringstream text;
  text << optionName("num_disparities", names) << ' ' << options.num_disparities;
  if (options.min_disparity != 0)
    text << " (from " << optionName("min_disparity", names) << ' ' << options.min_disparity << ')';
  text << " leaves no column of the " << matched_size.width << "-pixel-wide images to match";
  const int largest = (limit - 1) / 16 * 16;
  if (largest >= 16)
    text << ": at most " << largest;
  return core::Error{text.str()};
}

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

cv::Mat growConfirmedPieces(const cv::Mat& confident, const cv::Mat& ambiguous, float piece_range,
                            double min_confirmed_fraction) {
  CV_Assert(confident.type() == CV_32F && ambiguous.type() == CV_32F &&
            confident.size() == ambiguous.size());
  constexpr float kConfirmedWithin = 1.0f;
  const int width = ambiguous.cols;
  const int height = ambiguous.rows;
  // Pieces are found by a flood fill: OpenCV's connectedComponents joins pixels by a binary
  // mask only, and filterSpeckles (the same pieces) removes them without saying which is which.
  std::vector<char> visited(static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
  std::vector<int> stack;
  cv::Mat out = confident.clone();
  std::vector<int> members;
  for (int start = 0; start < width * height; ++start) {
    const int start_x = start % width;
    const int start_y = start / width;
    if (visited[static_cast<std::size_t>(start)] || ambiguous.at<float>(start_y, start_x) < 0)
      continue;
    members.clear();
    stack.assign(1, start);
    visited[static_cast<std::size_t>(start)] = 1;
    std::size_t confirmed = 0;
    while (!stack.empty()) {
      const int index = stack.back();
      stack.pop_back();
      members.push_back(index);
      const int x = index % width;
      const int y = index / width;
      const float d = ambiguous.at<float>(y, x);
      const float c = confident.at<float>(y, x);
      if (c >= 0 && std::fabs(c - d) <= kConfirmedWithin)
        ++confirmed;
      const auto visit = [&](int nx, int ny) {
        if (nx < 0 || ny < 0 || nx >= width || ny >= height)
          return;
        const int next = ny * width + nx;
        const float nd = ambiguous.at<float>(ny, nx);
        if (visited[static_cast<std::size_t>(next)] || nd < 0 || std::fabs(nd - d) > piece_range)
          return;
        visited[static_cast<std::size_t>(next)] = 1;
        stack.push_back(next);
      };
      visit(x - 1, y);
      visit(x + 1, y);
      visit(x, y - 1);
      visit(x, y + 1);
    }
    const bool kept =
        confirmed > 0 && static_cast<double>(confirmed) >
                             min_confirmed_fraction * static_cast<double>(members.size());
    if (!kept)
      continue;
    for (const int index : members) {
      float& o = out.at<float>(index / width, index % width);
      if (o < 0)
        o = ambiguous.at<float>(index / width, index % width);
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
  const auto sgbm = [&](int uniqueness_ratio) {
    return cv::StereoSGBM::create(options_.min_disparity, options_.num_disparities,
                                  options_.block_size, options_.p1_per_pixel * channels * area,
                                  options_.p2_per_pixel * channels * area, options_.disp12_max_diff,
                                  options_.pre_filter_cap, uniqueness_ratio,
                                  options_.speckle_window, options_.speckle_range, options_.mode);
  };
  left_matcher_ = sgbm(options_.uniqueness_ratio);
  if (options_.lr_check || options_.wls) {
    right_matcher_ = cv::ximgproc::createRightMatcher(left_matcher_);
  }
  if (options_.grow_uniqueness_ratio >= 0) {
    grow_left_matcher_ = sgbm(options_.grow_uniqueness_ratio);
    if (options_.lr_check)
      grow_right_matcher_ = cv::ximgproc::createRightMatcher(grow_left_matcher_);
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
  cv::Mat left_in = toChannels(left, options_.match_colour);
  cv::Mat right_in = toChannels(right, options_.match_colour);
  cv::Mat guide = left;  // WLS's edge-aware guide: the left view as given
  // Full width: the left view's unmatched band (SGBM's [0, maxD)) moves into padding on the left;
  // the right view's (the right matcher's last maxD columns) into padding on the right.
  const int band = std::max(options_.min_disparity + options_.num_disparities, 0);
  const int pad_left = options_.full_width ? band : 0;
  const int pad_right = options_.full_width && right_matcher_ ? band : 0;
  if (pad_left > 0 || pad_right > 0) {
    for (cv::Mat* image : {&left_in, &right_in, &guide}) {
      cv::Mat padded;
      cv::copyMakeBorder(*image, padded, 0, 0, pad_left, pad_right, cv::BORDER_REPLICATE);
      *image = padded;
    }
  }
  auto start = Clock::now();
  cv::Mat left_fixed;
  cv::Mat right_fixed;
  left_matcher_->compute(left_in, right_in, left_fixed);
  if (right_matcher_) {
    right_matcher_->compute(right_in, left_in, right_fixed);
  }
  cv::Mat grow_left_fixed;
  cv::Mat grow_right_fixed;
  if (grow_left_matcher_) {
    grow_left_matcher_->compute(left_in, right_in, grow_left_fixed);
    if (grow_right_matcher_)
      grow_right_matcher_->compute(right_in, left_in, grow_right_fixed);
  }
  if (timings)
    timings->sgbm_ms = core::millisecondsSince(start);
  start = Clock::now();
  cv::Mat disparity;
  if (wls_) {
    cv::Mat filtered;
    wls_->filter(left_fixed, guide, filtered, right_fixed);
    disparity = toFloatDisparity(filtered, options_.min_disparity);
  } else {
    disparity = toFloatDisparity(left_fixed, options_.min_disparity);
    if (options_.lr_check) {
      leftRightCheck(disparity, rightViewToFloat(right_fixed, options_), options_.lr_max_diff);
    }
    if (grow_left_matcher_) {
      cv::Mat ambiguous = toFloatDisparity(grow_left_fixed, options_.min_disparity);
      if (grow_right_matcher_) {
        leftRightCheck(ambiguous, rightViewToFloat(grow_right_fixed, options_),
                       options_.lr_max_diff);
      }
      disparity =
          growConfirmedPieces(disparity, ambiguous, static_cast<float>(options_.speckle_range),
                              options_.grow_confirmed_fraction);
    }
  }
  if (pad_left > 0 || pad_right > 0) {
    disparity = disparity(cv::Rect(pad_left, 0, left.cols, left.rows)).clone();
    // A match in the padding is a match with nothing: the right camera does not see that pixel.
    for (int y = 0; y < disparity.rows; ++y) {
      float* row = disparity.ptr<float>(y);
      for (int x = 0; x < disparity.cols; ++x) {
        if (row[x] >= 0 && static_cast<float>(x) - row[x] < 0.0f)
          row[x] = kInvalidDisparity;
      }
    }
  }
  if (options_.min_texture > 0)
    dropTexturelessPixels(disparity, left, options_.block_size + 2, options_.min_texture);
  if (timings)
    timings->filter_ms = core::millisecondsSince(start);
  return disparity;
}

void dropTexturelessPixels(cv::Mat& disparity, const cv::Mat& image, int window, double min_std) {
  CV_Assert(disparity.type() == CV_32F && disparity.size() == image.size());
  cv::Mat grey;
  toChannels(image, false).convertTo(grey, CV_32F);
  cv::Mat mean;
  cv::Mat mean_of_squares;
  const cv::Size box(window, window);
  cv::boxFilter(grey, mean, CV_32F, box, cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  cv::boxFilter(grey.mul(grey), mean_of_squares, CV_32F, box, cv::Point(-1, -1), true,
                cv::BORDER_REFLECT);
  const float min_variance = static_cast<float>(min_std * min_std);
  for (int y = 0; y < disparity.rows; ++y) {
    float* row = disparity.ptr<float>(y);
    const float* m = mean.ptr<float>(y);
    const float* m2 = mean_of_squares.ptr<float>(y);
    for (int x = 0; x < disparity.cols; ++x) {
      if (m2[x] - m[x] * m[x] < min_variance)
        row[x] = kInvalidDisparity;
    }
  }
}

cv::Mat computeDefaultSgbm(const cv::Mat& left, const cv::Mat& right, int num_disparities) {
  cv::Ptr<cv::StereoSGBM> sgbm = cv::StereoSGBM::create(0, num_disparities, 3);
  cv::Mat fixed;
  sgbm->compute(toChannels(left, false), toChannels(right, false), fixed);
  return toFloatDisparity(fixed, 0);
}

}  // namespace fieldrig::stereo
