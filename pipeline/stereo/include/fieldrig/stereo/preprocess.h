// From a camera's raw frame to the image the matcher works on: debayer (GenICam pattern names,
// as the drivers and the recording use them) and downsample (the paper matches at 812×612, half
// of the Grasshoppers' 1624×1224).
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "fieldrig/core/pixel_format.h"
#include "fieldrig/core/result.h"

namespace fieldrig::stereo {

// The cv::cvtColor code that turns a raw frame of `format` into BGR (for kMono8: GRAY2BGR).
int bgrConversionCode(core::PixelFormat format);

// Raw 8-bit frame (CV_8UC1, debayered as `format` says) or an image already in BGR (CV_8UC3,
// `format` ignored) → BGR scaled by `scale` (INTER_AREA; 1 = no resize). The error names the
// problem (empty frame, wrong type, odd Bayer size).
core::Result<cv::Mat> debayerAndScale(const cv::Mat& raw, core::PixelFormat format, double scale);

// An image file as the head pipeline takes a frame: 8-bit raw (one channel) or BGR (three), read
// unchanged. The error names the file.
core::Result<cv::Mat> readFrameImage(const std::filesystem::path& file);

// Raw 8-bit frame (CV_8UC1 of `format`) → 8-bit grey, debayered first; a kMono8 frame is
// returned as it is (not copied).
cv::Mat toGrey(const cv::Mat& raw, core::PixelFormat format);

// Mosaics a BGR image into a raw Bayer frame of `format` (the inverse of debayering, which OpenCV
// does not offer): each pixel keeps the one channel the sensor's filter passes there. Used to
// make synthetic raw frames for tests and benchmarks.
cv::Mat mosaicBayer(const cv::Mat& bgr, core::PixelFormat format);

}  // namespace fieldrig::stereo
