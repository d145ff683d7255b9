#include "fieldrig/cloud/fusion.h"

#include <bit>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <limits>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "fieldrig/core/durable_file.h"
#include "fieldrig/core/time.h"

namespace fieldrig::cloud {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

bool FusionResult::partial() const {
  for (const HeadStatus& head : heads) {
    if (!head.ok)
      return true;
  }
  return false;
}

std::size_t appendReprojected(const cv::Mat& disparity, const cv::Mat& left_bgr, const cv::Mat& Q,
                              const cv::Matx44d& to_output, double min_z, double max_z, Cloud& out,
                              double* reproject_ms) {
  CV_Assert(disparity.type() == CV_32F && left_bgr.type() == CV_8UC3 &&
            disparity.size() == left_bgr.size() && Q.type() == CV_64F &&
            Q.size() == cv::Size(4, 4));
  const auto start = Clock::now();
  // cv::reprojectImageTo3D would fill a 3-channel float image for every pixel (invalid ones
  // included) that is then read again to transform and crop. Here Q and the transform are one
  // 4×4 matrix applied to the valid pixels only, in the same pass that crops and colours:
  // (X, Y, Z, W) = (to_output · Q) · (x, y, d, 1), as reprojectImageTo3D computes Q · (x, y, d, 1).
  const cv::Matx44d a = to_output * cv::Matx44d(Q);
  cv::Matx44f m;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c)
      m(r, c) = static_cast<float>(a(r, c));
  }
  const auto min_zf = static_cast<float>(min_z);
  const auto max_zf = static_cast<float>(max_z);
  const std::size_t before = out.size();
  out.reserve(before + static_cast<std::size_t>(cv::countNonZero(disparity > 0)));
  for (int y = 0; y < disparity.rows; ++y) {
    const float* d = disparity.ptr<float>(y);
    const cv::Vec3b* colour = left_bgr.ptr<cv::Vec3b>(y);
    const auto yf = static_cast<float>(y);
    // The row's contribution is constant along it.
    const float row[4] = {m(0, 1) * yf + m(0, 3), m(1, 1) * yf + m(1, 3), m(2, 1) * yf + m(2, 3),
                          m(3, 1) * yf + m(3, 3)};
    for (int x = 0; x < disparity.cols; ++x) {
      // Zero disparity is a point at infinity; negative or NaN is no match.
      if (!(d[x] > 0))
        continue;
      const auto xf = static_cast<float>(x);
      const float w = m(3, 0) * xf + m(3, 2) * d[x] + row[3];
      const float z = (m(2, 0) * xf + m(2, 2) * d[x] + row[2]) / w;
      if (!(z > min_zf && z <= max_zf))
        continue;
      pcl::PointXYZRGB point;
      point.x = (m(0, 0) * xf + m(0, 2) * d[x] + row[0]) / w;
      point.y = (m(1, 0) * xf + m(1, 2) * d[x] + row[1]) / w;
      point.z = z;
      point.b = colour[x][0];
      point.g = colour[x][1];
      point.r = colour[x][2];
      out.push_back(point);
    }
  }
  if (reproject_ms)
    *reproject_ms = core::millisecondsSince(start);
  return out.size() - before;
}

void measureCoverage(const cv::Mat& disparity, HeadStatus& status) {
  CV_Assert(disparity.type() == CV_32F);
  if (disparity.empty())
    return;
  const cv::Mat valid = disparity >= 0;
  status.valid_pixel_fraction =
      static_cast<double>(cv::countNonZero(valid)) / static_cast<double>(disparity.total());
  cv::Mat column_max;
  cv::reduce(valid, column_max, 0, cv::REDUCE_MAX);
  status.matched_column_fraction =
      static_cast<double>(cv::countNonZero(column_max)) / static_cast<double>(disparity.cols);
}

std::size_t dropDepthEdges(cv::Mat& disparity, double max_jump, bool keep_near_side) {
  CV_Assert(disparity.type() == CV_32F);
  // Neighbourhood maximum and minimum by grey dilation and erosion; invalid pixels must not
  // count, so they are below every disparity for the maximum and above for the minimum.
  const cv::Mat invalid = ~(disparity > 0);
  cv::Mat highest;
  const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3));
  cv::dilate(disparity, highest, kernel);
  cv::Mat lowest;
  if (keep_near_side) {
    lowest = disparity;  // the far-side test compares with the pixel itself
  } else {
    cv::Mat for_min = disparity.clone();
    for_min.setTo(std::numeric_limits<float>::max(), invalid);
    cv::erode(for_min, lowest, kernel);
  }
  const cv::Mat edge = (highest - lowest > max_jump) & ~invalid;
  const auto dropped = static_cast<std::size_t>(cv::countNonZero(edge));
  disparity.setTo(stereo::kInvalidDisparity, edge);
  return dropped;
}

core::Result<CloudBuilder> CloudBuilder::create(const RigCalibration& rig, CloudOptions options) {
  if (rig.heads.empty()) {
    return core::Error{"the rig has no heads"};
  }
  if (auto valid = validate(options); !valid)
    return core::Error{"cloud options: " + valid.error().message};
  CloudBuilder builder;
  builder.rig_ = rig;
  builder.options_ = options;
  stereo::HeadOptions head_options;
  head_options.scale = options.scale;
  head_options.matcher = options.matcher;
  cv::Matx44d plot = cv::Matx44d::eye();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c)
      plot(r, c) = rig.plot_rotation(r, c);
  }
  for (const HeadCalibration& head : rig.heads) {
    core::Result<stereo::HeadPipeline> pipeline =
        stereo::HeadPipeline::create(head.stereo, head_options);
    if (!pipeline)
      return core::Error{head.name + " head: " + pipeline.error().message};
    builder.heads_.push_back(std::move(*pipeline));
    builder.to_plot_.push_back(plot * head.to_bottom);
  }
  return builder;
}

FusionResult CloudBuilder::build(const std::vector<HeadFrames>& frames, bool parallel_heads) {
  FusionResult result;
  result.heads.resize(heads_.size());
  std::vector<Cloud> head_clouds(heads_.size());
  auto runHead = [&](std::size_t i) {
    HeadStatus& status = result.heads[i];
    status.name = rig_.heads[i].name;
    if (i >= frames.size()) {
      status.problem = status.name + ": no frames given";
      return;
    }
    // The head checks its input first; an OpenCV failure past those checks still only costs
    // this head, never the FrameSet.
    try {
      const HeadFrames& head = frames[i];
      const bool truth_depth = options_.depth_source == DepthSource::kTruth;
      const bool truth_where_matched = options_.depth_source == DepthSource::kTruthWhereMatched;
      if ((truth_depth || truth_where_matched) && head.left_truth_depth.empty()) {
        status.problem = status.name + ": no truth depth map for the left camera";
        return;
      }
      core::Result<stereo::HeadOutput> output =
          truth_depth ? heads_[i].processTruthDepth(head.left, head.left_truth_depth,
                                                    head.pixel_format, status.name, &status.timings)
                      : heads_[i].process(head.left, head.right, head.pixel_format, status.name,
                                          &status.timings);
      if (!output) {
        status.problem = output.error().message;
        return;
      }
      measureCoverage(output->disparity, status);
      std::optional<cv::Mat> truth_disparity;
      if (!truth_depth && !head.left_truth_depth.empty()) {
        const stereo::TruthDepthRectifier& truth = heads_[i].truthDepth();
        core::Result<cv::Mat> disparity = truth.disparity(head.left_truth_depth);
        if (disparity && !head.left_truth_vegetation.empty()) {
          core::Result<cv::Mat> vegetation = truth.rectifyMask(head.left_truth_vegetation);
          if (vegetation) {
            status.stereo_score = truth.score(output->disparity, *disparity, *vegetation,
                                              options_.min_depth_m, options_.max_depth_m);
          } else {
            status.truth_problem = vegetation.error().message;
          }
        }
        if (disparity) {
          truth_disparity = std::move(*disparity);
        } else if (truth_where_matched) {
          status.problem = disparity.error().message;
          return;
        } else {
          status.truth_problem = disparity.error().message;
        }
      }
      // The stereo score above stays the matcher's; everything after sees the truth's depth.
      if (truth_where_matched)
        output->disparity = stereo::truthWhereMatched(output->disparity, *truth_disparity);
      if (options_.edge_max_jump_px > 0)
        status.edge_pixels = dropDepthEdges(output->disparity, options_.edge_max_jump_px,
                                            options_.edge_keep_near_side);
      if (truth_disparity) {
        status.cloud_score = heads_[i].truthDepth().scoreCloud(
            output->disparity, *truth_disparity, options_.min_depth_m, options_.max_depth_m);
      }
      status.points = appendReprojected(
          output->disparity, output->left_bgr, heads_[i].matchingCalibration().Q, to_plot_[i],
          options_.min_depth_m, options_.max_depth_m, head_clouds[i], &status.reproject_ms);
      status.ok = true;
    } catch (const cv::Exception& e) {
      status.problem = status.name + ": OpenCV failed: " + e.what();
      head_clouds[i].clear();
      status.points = 0;
    }
  };
  if (parallel_heads) {
    cv::parallel_for_(cv::Range(0, static_cast<int>(heads_.size())), [&](const cv::Range& range) {
      for (int i = range.start; i < range.end; ++i)
        runHead(static_cast<std::size_t>(i));
    });
  } else {
    for (std::size_t i = 0; i < heads_.size(); ++i)
      runHead(i);
  }
  const auto start = Clock::now();
  std::size_t total = 0;
  for (const Cloud& cloud : head_clouds)
    total += cloud.size();
  result.cloud.reserve(total);
  for (const Cloud& cloud : head_clouds)
    result.cloud += cloud;
  result.cloud.width = static_cast<std::uint32_t>(result.cloud.size());
  result.cloud.height = 1;
  result.cloud.is_dense = true;
  result.fuse_ms = core::millisecondsSince(start);
  return result;
}

std::string plyBytes(const Cloud& cloud) {
  // Built here, not by pcl::PLYWriter: PCL's writer truncates the file in place and reports
  // success after a short write (a full disk), which left a cut cloud where the old one was. The
  // format is PCL's own for this point type without its "camera" element: a plain vertex list
  // with red/green/blue that every PLY reader takes.
  static_assert(std::endian::native == std::endian::little, "binary_little_endian is written");
  std::string bytes =
      "ply\nformat binary_little_endian 1.0\ncomment fieldrig cloud, metres\n"
      "element vertex " +
      std::to_string(cloud.size()) +
      "\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nproperty uchar green\nproperty uchar blue\n"
      "end_header\n";
  constexpr std::size_t kVertexBytes = 3 * sizeof(float) + 3;
  std::size_t at = bytes.size();
  bytes.resize(at + cloud.size() * kVertexBytes);
  for (const pcl::PointXYZRGB& point : cloud) {
    const float xyz[3] = {point.x, point.y, point.z};
    const std::uint8_t rgb[3] = {point.r, point.g, point.b};
    std::memcpy(&bytes[at], xyz, sizeof xyz);
    std::memcpy(&bytes[at + sizeof xyz], rgb, sizeof rgb);
    at += kVertexBytes;
  }
  return bytes;
}

core::Result<std::filesystem::path> writePly(const Cloud& cloud,
                                             const std::filesystem::path& file) {
  if (cloud.empty()) {
    return core::Error{file.string() + ": the cloud is empty; nothing to write"};
  }
  if (std::string failed = core::writeWholeFile(file, plyBytes(cloud)); !failed.empty())
    return core::Error{std::move(failed)};
  return file;
}

}  // namespace fieldrig::cloud
