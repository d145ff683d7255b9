// Disparity maps on disk (PFM, float pixels, through OpenCV's own PFM codec) and their scoring
// against ground truth.
#pragma once

#include <filesystem>
#include <opencv2/core.hpp>

#include "fieldrig/core/result.h"

namespace fieldrig::stereo {

// Writes a CV_32F map as PFM; the error names the file.
core::Result<std::filesystem::path> writePfm(const std::filesystem::path& file,
                                             const cv::Mat& disparity);
// Reads a single-channel PFM; the error names the file.
core::Result<cv::Mat> readPfm(const std::filesystem::path& file);

// Bad-pixel rates of an estimated disparity against ground truth (both CV_32F pixels). Ground
// truth <= 0 or NaN is unknown and not counted; an estimate < 0 or NaN is invalid.
struct DisparityScores {
  double known_pixels = 0;    // pixels with known ground truth
  double valid_fraction = 0;  // of known pixels, those with a valid estimate
  double bad1_valid = 0;      // |error| > 1 px, over known pixels with a valid estimate
  double bad2_valid = 0;      // |error| > 2 px, same
  double bad1_all = 0;        // |error| > 1 px or invalid, over all known pixels
  double bad2_all = 0;
};
DisparityScores scoreDisparity(const cv::Mat& estimate, const cv::Mat& ground_truth);

}  // namespace fieldrig::stereo
