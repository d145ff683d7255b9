// The four-click stem diameter of one stereo pair (paper §2.4), improved:
//   1. the clicks (raw left image) are mapped through the rectification and sorted into the
//      convex quadrangle q1..q4;
//   2. each clicked edge is refined to the image's true silhouette: the strongest gradient along
//      the edge's normal within a few pixels of the click, located to sub-pixel, then a robust
//      line fit; the width d follows eq. (10)–(12) on the refined quadrangle;
//   3. the shared disparity is the NCC peak (eq. 14–15) of the quadrangle patch over the right
//      image's rows in the disparity range the calibration allows, refined by a parabola; a weak
//      (NCC ≤ 0.5) match is refused;
//   4. the diameter comes from a cylinder model instead of eq. (13)'s fronto-parallel plane: the
//      patch's depth is that of the stem's near surface, the edges are the tangent rays.
#pragma once

#include <array>
#include <opencv2/core.hpp>
#include <string>
#include <string_view>

#include "fieldrig/core/result.h"
#include "fieldrig/stem/quadrangle.h"
#include "fieldrig/stereo/calibration.h"

namespace fieldrig::stem {

struct MeasureOptions {
  // Find the true edges near the clicks (sub-pixel); false takes the clicks at face value.
  bool refine_edges = true;
  double edge_search_px = 3.0;  // how far from the clicked edge the silhouette is looked for
  // Diameter from the cylinder model; false uses eq. (13), D = b·d/d_shared, as the paper did.
  bool cylinder_model = true;
  // Where the matched patch's depth lies between the stem's nearest point (1) and its axis (0),
  // in radii: the NCC peak is a texture-weighted mean over the visible surface, measured at
  // 0.61-0.67 on rendered cylinders (bench/stem_accuracy_bench, last column).
  double near_surface_radii = 0.65;
  // Depth range the head is used at; it bounds the disparity search (eq. 14's ε).
  double min_depth_m = 0.4;
  double max_depth_m = 6.0;
  double min_ncc = 0.5;  // a peak at or below this is refused (the paper's threshold)
};

enum class MeasureStatus {
  kOk,
  kBadPoints,      // not a convex quadrangle, degenerate, outside the image
  kNoSearchRange,  // the disparity range leaves no room in the right image
  kWeakMatch,      // NCC peak ≤ min_ncc
};

std::string_view toString(MeasureStatus status);

struct StemMeasurement {
  MeasureStatus status = MeasureStatus::kBadPoints;
  std::string message;  // why, when not kOk
  Quadrangle clicked;   // rectified left image, as clicked
  Quadrangle refined;   // rectified left image, on the found edges (= clicked without refinement)
  bool edges_refined = false;
  int edge_samples_left = 0;  // edge points found along each side
  int edge_samples_right = 0;
  QuadrangleWidth width;           // of `refined`, rectified pixels
  double disparity_px = 0.0;       // shared disparity, sub-pixel
  double ncc = 0.0;                // NCC peak
  double ncc_second = 0.0;         // best NCC away from the peak's lobe
  double distinctness = 0.0;       // ncc − ncc_second
  double patch_depth_m = 0.0;      // depth of the matched patch
  double diameter_mm = 0.0;        // the answer (cylinder model or eq. 13, per the options)
  double diameter_plane_mm = 0.0;  // eq. (13), for comparison
  Points4 right_patch_raw{};       // the matched quadrangle in the raw right image (q1..q4)
  double elapsed_ms = 0.0;
  bool ok() const { return status == MeasureStatus::kOk; }
};

// One stereo pair with its calibration. Thread contract: thread-compatible; measure() is const
// and may run concurrently on one instance.
class StemMeasurer {
 public:
  // The images are 8-bit grey, raw (as the cameras saw them, lens distortion included). The
  // error names what does not fit: image sizes, calibration, rectification direction.
  static core::Result<StemMeasurer> create(const stereo::StereoCalibration& calibration,
                                           const cv::Mat& left, const cv::Mat& right);

  // `points`: four clicks in the raw left image, any order.
  StemMeasurement measure(const Points4& points, const MeasureOptions& options = {}) const;

  // Raw left pixel coordinates → rectified left, and rectified right → raw right.
  Points4 rectifyLeft(const Points4& raw) const;
  Points4 unrectifyRight(const Points4& rectified) const;

  const stereo::StereoCalibration& calibration() const { return calibration_; }

 private:
  StemMeasurer() = default;
  // The rectified view of `rect` (rectified pixel coordinates) of one camera, float, remapped
  // from the raw image: only the region is computed, never the whole image.
  cv::Mat rectifiedRegion(bool left_camera, const cv::Rect& rect) const;

  stereo::StereoCalibration calibration_;
  cv::Mat left_, right_;
  double focal_px_ = 0.0;
  double baseline_m_ = 0.0;
  double disparity_offset_px_ = 0.0;  // cx1 − cx2 of the rectified pair
};

}  // namespace fieldrig::stem
