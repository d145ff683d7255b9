#include "fieldrig/stereo/disparity_io.h"

#include <cmath>
#include <opencv2/imgcodecs.hpp>

namespace fieldrig::stereo {

core::Result<std::filesystem::path> writePfm(const std::filesystem::path& file,
                                             const cv::Mat& disparity) {
  if (disparity.type() != CV_32FC1) {
    return core::Error{file.string() + ": disparity to write is not single-channel float"};
  }
  try {
    if (!cv::imwrite(file.string(), disparity)) {
      return core::Error{file.string() + ": cannot write PFM"};
    }
  } catch (const cv::Exception& e) {
    return core::Error{file.string() + ": cannot write PFM: " + e.what()};
  }
  return file;
}

core::Result<cv::Mat> readPfm(const std::filesystem::path& file) {
  cv::Mat image;
  try {
    image = cv::imread(file.string(), cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    return core::Error{file.string() + ": cannot read PFM: " + e.what()};
  }
  if (image.empty() || image.type() != CV_32FC1) {
    return core::Error{file.string() + ": not a single-channel PFM"};
  }
  return image;
}

DisparityScores scoreDisparity(const cv::Mat& estimate, const cv::Mat& ground_truth) {
  CV_Assert(estimate.type() == CV_32F && ground_truth.type() == CV_32F &&
            estimate.size() == ground_truth.size());
  std::uint64_t known = 0, valid = 0, bad1 = 0, bad2 = 0;
  for (int y = 0; y < estimate.rows; ++y) {
    const float* e = estimate.ptr<float>(y);
    const float* g = ground_truth.ptr<float>(y);
    for (int x = 0; x < estimate.cols; ++x) {
      if (!(g[x] > 0))
        continue;
      ++known;
      if (!(e[x] >= 0))
        continue;
      ++valid;
      const float error = std::fabs(e[x] - g[x]);
      bad1 += error > 1.0f ? 1 : 0;
      bad2 += error > 2.0f ? 1 : 0;
    }
  }
  DisparityScores scores;
  scores.known_pixels = static_cast<double>(known);
  if (known == 0)
    return scores;
  const double k = static_cast<double>(known);
  const double v = static_cast<double>(valid);
  scores.valid_fraction = v / k;
  scores.bad1_valid = valid ? static_cast<double>(bad1) / v : 0;
  scores.bad2_valid = valid ? static_cast<double>(bad2) / v : 0;
  scores.bad1_all = (static_cast<double>(bad1) + (k - v)) / k;
  scores.bad2_all = (static_cast<double>(bad2) + (k - v)) / k;
  return scores;
}

}  // namespace fieldrig::stereo
