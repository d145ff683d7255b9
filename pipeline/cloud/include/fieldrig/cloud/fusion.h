// One FrameSet's three heads to one point cloud in the plot frame: each head's disparity
// reprojected with its Q, moved into the bottom head's frame (rig.yml), rotated into the plot
// frame and cropped by depth. A head that cannot be used (missing or blank frame, wrong size)
// is flagged and the cloud is built from the others.
#pragma once

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/cloud/cloud_options.h"
#include "fieldrig/cloud/rig_calibration.h"
#include "fieldrig/core/result.h"
#include "fieldrig/stereo/head.h"

namespace fieldrig::cloud {

using Cloud = pcl::PointCloud<pcl::PointXYZRGB>;

// One head's frames: raw Bayer (CV_8UC1, of `pixel_format`) or BGR images; empty = missing.
// The simulator's truth of the left camera may come along (sim/field's maps, camera size):
// `left_truth_depth` (CV_32F, z in metres) is the depth with DepthSource::kTruth and, on the
// pixels stereo matched, with kTruthWhereMatched; with stereo running, it and
// `left_truth_vegetation` (8-bit mask) score the matched disparity (HeadStatus::stereo_score).
struct HeadFrames {
  cv::Mat left, right;
  core::PixelFormat pixel_format = core::PixelFormat::kBayerRG8;
  cv::Mat left_truth_depth, left_truth_vegetation;
};

struct HeadStatus {
  std::string name;
  bool ok = false;
  std::string problem;  // why the head was left out, when not ok
  std::size_t points = 0;
  std::size_t edge_pixels = 0;  // dropped as depth edges (dropDepthEdges)
  // How much of the left image stereo measured (before the edge filter and the depth crop): the
  // fraction of pixels with a disparity, and of columns with at least one — a head that matched
  // only part of the row shows here, not as a narrower plant.
  double valid_pixel_fraction = 0;
  double matched_column_fraction = 0;
  // Stereo against the truth, when the truth came with kStereo: over vegetation pixels whose
  // rectified truth depth lies in (min_depth_m, max_depth_m] (about the plot frame's depth crop),
  // before the edge filter; bad = |disparity error| > 2 px at matching resolution.
  std::optional<stereo::DisparityTruthScore> stereo_score;
  // Why a head that had truth maps was not scored against them (a map of another size than the
  // calibration's): the head itself is in the cloud; only stereo_score or cloud_score is missing.
  std::string truth_problem;
  // The same head's points (after the edge filter, in the depth range) against the truth.
  std::optional<stereo::CloudTruthScore> cloud_score;
  stereo::HeadTimings timings;
  double reproject_ms = 0;  // reprojection, transform into the plot frame, crop, colour
};

struct FusionResult {
  Cloud cloud;  // plot frame, metres
  std::vector<HeadStatus> heads;
  bool partial() const;  // some head was left out
  double fuse_ms = 0;    // the heads' clouds joined into one
};

// Appends the valid pixels of `disparity` (CV_32F, stereo::kInvalidDisparity = none), coloured
// from `left_bgr`, reprojected with `Q` and moved by `to_output` (4×4), keeping points whose
// output z lies in (min_z, max_z]. Returns the number of points appended.
std::size_t appendReprojected(const cv::Mat& disparity, const cv::Mat& left_bgr, const cv::Mat& Q,
                              const cv::Matx44d& to_output, double min_z, double max_z, Cloud& out,
                              double* reproject_ms = nullptr);

// Sets `status`'s valid_pixel_fraction and matched_column_fraction from `disparity` (CV_32F).
void measureCoverage(const cv::Mat& disparity, HeadStatus& status);

// Marks as invalid (stereo::kInvalidDisparity) every pixel of `disparity` (CV_32F) whose valid
// 3×3 neighbours, itself included, differ by more than `max_jump` pixels of disparity; with
// `keep_near_side`, only those with a neighbour more than `max_jump` above their own disparity
// (the far side of the jump, and the blend between). Returns how many pixels it invalidated.
std::size_t dropDepthEdges(cv::Mat& disparity, double max_jump, bool keep_near_side = false);

// Thread contract: thread-compatible; one instance per thread.
class CloudBuilder {
 public:
  // Builds each head's pipeline (maps, matchers) once. The error names a bad option or head.
  static core::Result<CloudBuilder> create(const RigCalibration& rig, CloudOptions options = {});

  // `frames` in the order of rig.heads. Never fails for bad frames: the head is flagged.
  // parallel_heads runs the heads on OpenCV's thread pool at once (each head's SGBM then runs
  // single-threaded inside it, as OpenCV does not nest parallel loops).
  FusionResult build(const std::vector<HeadFrames>& frames, bool parallel_heads = false);

  const RigCalibration& rig() const { return rig_; }
  const CloudOptions& options() const { return options_; }

 private:
  RigCalibration rig_;
  CloudOptions options_;
  std::vector<stereo::HeadPipeline> heads_;
  std::vector<cv::Matx44d> to_plot_;  // head frame → plot frame
};

// The cloud as binary little-endian PLY (x y z float, red green blue uchar, metres), which
// CloudCompare, MeshLab and PCL read.
std::string plyBytes(const Cloud& cloud);
// Writes plyBytes() whole or not at all (core::writeWholeFile); an empty cloud is an error.
core::Result<std::filesystem::path> writePly(const Cloud& cloud, const std::filesystem::path& file);

}  // namespace fieldrig::cloud
