#include "fieldrig/stereo/preprocess.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace fieldrig::stereo {

int bgrConversionCode(core::PixelFormat format) {
  switch (format) {
    case core::PixelFormat::kBayerRG8:
      return cv::COLOR_BayerRGGB2BGR;
    case core::PixelFormat::kBayerGR8:
      return cv::COLOR_BayerGRBG2BGR;
    case core::PixelFormat::kBayerGB8:
      return cv::COLOR_BayerGBRG2BGR;
    case core::PixelFormat::kBayerBG8:
      return cv::COLOR_BayerBGGR2BGR;
    case core::PixelFormat::kMono8:
      return cv::COLOR_GRAY2BGR;
  }
  return cv::COLOR_GRAY2BGR;
}

core::Result<cv::Mat> debayerAndScale(const cv::Mat& raw, core::PixelFormat format, double scale) {
  if (raw.empty()) {
    return core::Error{"raw frame is empty"};
  }
  if (raw.type() != CV_8UC1 && raw.type() != CV_8UC3) {
    return core::Error{"frame is neither 8-bit raw nor 8-bit BGR"};
  }
  if (raw.type() == CV_8UC1 && format != core::PixelFormat::kMono8 &&
      (raw.cols % 2 != 0 || raw.rows % 2 != 0)) {
    return core::Error{"Bayer frame " + std::to_string(raw.cols) + "x" + std::to_string(raw.rows) +
                       " has an odd size"};
  }
  if (!(scale > 0 && scale <= 1)) {
    return core::Error{"scale " + std::to_string(scale) + " is not in (0, 1]"};
  }
  cv::Mat bgr = raw;
  if (raw.type() == CV_8UC1) {
    cv::cvtColor(raw, bgr, bgrConversionCode(format));
  }
  if (scale == 1) {
    return bgr;
  }
  cv::Mat scaled;
  cv::resize(bgr, scaled, cv::Size(), scale, scale, cv::INTER_AREA);
  return scaled;
}

core::Result<cv::Mat> readFrameImage(const std::filesystem::path& file) {
  cv::Mat image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  if (image.empty())
    return core::Error{file.string() + ": cannot read the image"};
  if (image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    return core::Error{file.string() + ": not an 8-bit raw or colour image"};
  return image;
}

cv::Mat toGrey(const cv::Mat& raw, core::PixelFormat format) {
  if (format == core::PixelFormat::kMono8)
    return raw;
  cv::Mat bgr;
  cv::cvtColor(raw, bgr, bgrConversionCode(format));
  cv::Mat grey;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  return grey;
}

cv::Mat mosaicBayer(const cv::Mat& bgr, core::PixelFormat format) {
  CV_Assert(bgr.type() == CV_8UC3);
  if (format == core::PixelFormat::kMono8) {
    cv::Mat grey;
    cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
    return grey;
  }
  // Colour (BGR channel index) of the filter at (row parity, column parity), GenICam naming: the
  // name gives the first two pixels of the first row.
  const char* pattern = "RGGB";
  switch (format) {
    case core::PixelFormat::kBayerRG8:
      pattern = "RGGB";
      break;
    case core::PixelFormat::kBayerGR8:
      pattern = "GRBG";
      break;
    case core::PixelFormat::kBayerGB8:
      pattern = "GBRG";
      break;
    case core::PixelFormat::kBayerBG8:
      pattern = "BGGR";
      break;
    case core::PixelFormat::kMono8:
      break;
  }
  auto channelOf = [](char colour) { return colour == 'B' ? 0 : colour == 'G' ? 1 : 2; };
  const int channel[2][2] = {{channelOf(pattern[0]), channelOf(pattern[1])},
                             {channelOf(pattern[2]), channelOf(pattern[3])}};
  cv::Mat raw(bgr.size(), CV_8UC1);
  for (int y = 0; y < bgr.rows; ++y) {
    const cv::Vec3b* in = bgr.ptr<cv::Vec3b>(y);
    std::uint8_t* out = raw.ptr<std::uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x) {
      out[x] = in[x][channel[y % 2][x % 2]];
    }
  }
  return raw;
}

}  // namespace fieldrig::stereo
