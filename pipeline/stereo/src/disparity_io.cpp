#include "fieldrig/stereo/disparity_io.h"

#include <bit>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>

#include "fieldrig/core/durable_file.h"

namespace fieldrig::stereo {

core::Result<std::filesystem::path> writePfm(const std::filesystem::path& file,
                                             const cv::Mat& disparity) {
  if (disparity.type() != CV_32FC1) {
    return core::Error{file.string() + ": disparity to write is not single-channel float"};
  }
  // Written here, not by cv::imwrite / cv::imencode: OpenCV's PFM encoder cannot write to
  // memory (imencode goes through a temporary file), and its file writer reports success after a
  // short write (a full disk, a file size limit), which would leave a cut map behind a run that
  // said it was fine. The format is three text lines and the rows bottom to top; a negative scale
  // says little-endian.
  const std::string header = "Pf\n" + std::to_string(disparity.cols) + " " +
                             std::to_string(disparity.rows) + "\n" +
                             (std::endian::native == std::endian::little ? "-1" : "1") + "\n";
  std::string bytes = header;
  const std::size_t row_bytes = static_cast<std::size_t>(disparity.cols) * sizeof(float);
  bytes.resize(header.size() + row_bytes * static_cast<std::size_t>(disparity.rows));
  for (int row = 0; row < disparity.rows; ++row) {
    std::memcpy(bytes.data() + header.size() +
                    row_bytes * static_cast<std::size_t>(disparity.rows - 1 - row),
                disparity.ptr<float>(row), row_bytes);
  }
  if (std::string failed = core::writeWholeFile(file, bytes); !failed.empty())
    return core::Error{std::move(failed)};
  return file;
}

core::Result<cv::Mat> readPfm(const std::filesystem::path& file) {
  // The header's size checked against the file's before OpenCV allocates what the header asks
  // for: a damaged 1 KB file saying 30000 × 30000 would otherwise take 3.6 GB.
  {
    std::ifstream in(file, std::ios::binary);
    std::string magic;
    long long width = 0;
    long long height = 0;
    double scale = 0.0;
    if (!in)
      return core::Error{file.string() + ": cannot open PFM: " + std::strerror(errno)};
    if (!(in >> magic >> width >> height >> scale) || (magic != "Pf" && magic != "PF"))
      return core::Error{file.string() + ": not a PFM file (no \"Pf\"/\"PF\" header)"};
    in.get();  // the single whitespace byte before the data
    const long long channels = magic == "PF" ? 3 : 1;
    std::error_code error;
    const auto size = static_cast<long long>(std::filesystem::file_size(file, error));
    const long long data = static_cast<long long>(in.tellg());
    if (error || width <= 0 || height <= 0 || width > (1 << 16) || height > (1 << 16) || data < 0 ||
        size - data < width * height * channels * 4) {
      return core::Error{file.string() + ": PFM header says " + std::to_string(width) + " x " +
                         std::to_string(height) + " x " + std::to_string(channels) +
                         " floats, more than the file holds (" + std::to_string(size) + " bytes)"};
    }
  }
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
