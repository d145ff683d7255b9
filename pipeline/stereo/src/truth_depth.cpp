#include "fieldrig/stereo/truth_depth.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <string>
#include <vector>

#include "fieldrig/stereo/matcher.h"

namespace fieldrig::stereo {
namespace {

double median(std::vector<double>& values) {
  if (values.empty())
    return 0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// The depth Q gives rectified pixel (u, v) at disparity d.
double rectifiedDepth(const cv::Matx44d& q, int u, int v, double d) {
  return (q(2, 0) * u + q(2, 1) * v + q(2, 2) * d + q(2, 3)) /
         (q(3, 0) * u + q(3, 1) * v + q(3, 2) * d + q(3, 3));
}

}  // namespace

core::Result<TruthDepthRectifier> TruthDepthRectifier::create(const StereoCalibration& scaled,
                                                              cv::Size camera_size, double scale) {
  if (scaled.image_size.empty() || camera_size.empty() || !(scale > 0)) {
    return core::Error{"truth depth: the calibration needs its image size"};
  }
  TruthDepthRectifier rectifier;
  rectifier.camera_size_ = camera_size;
  cv::initUndistortRectifyMap(scaled.M1, scaled.D1, scaled.R1, scaled.P1, scaled.image_size,
                              CV_32FC1, rectifier.map_x_, rectifier.map_y_);
  // The maps address the raw image at matching resolution, whose pixel x is the camera's x·scale
  // (StereoCalibration::scaled scales the camera matrix, principal point included).
  rectifier.map_x_ *= 1.0 / scale;
  rectifier.map_y_ *= 1.0 / scale;
  const cv::Matx33d r1(scaled.R1);
  const double fx = scaled.P1.at<double>(0, 0), fy = scaled.P1.at<double>(1, 1);
  const double cx = scaled.P1.at<double>(0, 2), cy = scaled.P1.at<double>(1, 2);
  rectifier.depth_factor_.create(scaled.image_size, CV_32F);
  for (int v = 0; v < scaled.image_size.height; ++v) {
    auto* factor = rectifier.depth_factor_.ptr<float>(v);
    for (int u = 0; u < scaled.image_size.width; ++u) {
      // The rectified ray (x, y, 1) is R1 times the raw camera's ray: a point t·(x, y, 1) of the
      // rectified frame has raw-camera z = t·(R1ᵀ(x, y, 1))_z, and its rectified depth is t.
      const double x = (u - cx) / fx, y = (v - cy) / fy;
      const double raw_z = r1(0, 2) * x + r1(1, 2) * y + r1(2, 2);
      factor[u] = raw_z > 1e-6 ? static_cast<float>(1.0 / raw_z) : 0.0f;
    }
  }
  rectifier.q_ = cv::Matx44d(scaled.Q);
  return rectifier;
}

core::Result<cv::Mat> TruthDepthRectifier::disparity(const cv::Mat& raw_depth) const {
  if (raw_depth.type() != CV_32F || raw_depth.size() != camera_size_) {
    return core::Error{"truth depth map is " + sizeText(raw_depth.size()) +
                       (raw_depth.type() == CV_32F ? "" : " and not one float channel") +
                       " but the calibration is for " + sizeText(camera_size_) + " float"};
  }
  cv::Mat depth;
  // Nearest: a blend of a leaf's depth and the soil's behind it is a surface nobody rendered.
  cv::remap(raw_depth, depth, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0.0);
  cv::Mat out(depth.size(), CV_32F, cv::Scalar(kInvalidDisparity));
  const cv::Matx44d& q = q_;
  for (int v = 0; v < depth.rows; ++v) {
    const auto* z_raw = depth.ptr<float>(v);
    const auto* factor = depth_factor_.ptr<float>(v);
    auto* d = out.ptr<float>(v);
    for (int u = 0; u < depth.cols; ++u) {
      if (!(z_raw[u] > 0) || !std::isfinite(z_raw[u]) || factor[u] <= 0)
        continue;
      // Q·(u, v, d, 1) = (X, Y, Z', W) with Z'/W = Z: solved for d.
      const double z = static_cast<double>(z_raw[u]) * factor[u];
      const double numerator =
          q(2, 0) * u + q(2, 1) * v + q(2, 3) - z * (q(3, 0) * u + q(3, 1) * v + q(3, 3));
      const double denominator = z * q(3, 2) - q(2, 2);
      if (denominator == 0)
        continue;
      const double disparity = numerator / denominator;
      if (disparity > 0)
        d[u] = static_cast<float>(disparity);
    }
  }
  return out;
}

core::Result<cv::Mat> TruthDepthRectifier::rectifyMask(const cv::Mat& raw_mask) const {
  if (raw_mask.type() != CV_8UC1 || raw_mask.size() != camera_size_) {
    return core::Error{"truth mask is " + sizeText(raw_mask.size()) +
                       " but the calibration is for " + sizeText(camera_size_) + " 8-bit"};
  }
  cv::Mat out;
  cv::remap(raw_mask, out, map_x_, map_y_, cv::INTER_NEAREST, cv::BORDER_CONSTANT, 0);
  return out;
}

DisparityTruthScore TruthDepthRectifier::score(const cv::Mat& measured, const cv::Mat& truth,
                                               const cv::Mat& mask, double min_depth_m,
                                               double max_depth_m, double bad_threshold_px) const {
  CV_Assert(measured.type() == CV_32F && truth.type() == CV_32F && mask.type() == CV_8UC1 &&
            measured.size() == truth.size() && mask.size() == truth.size());
  const auto depthOf = [this](int u, int v, double d) { return rectifiedDepth(q_, u, v, d); };
  DisparityTruthScore out;
  std::size_t matched = 0, bad = 0;
  std::vector<double> errors, abs_errors;
  for (int v = 0; v < truth.rows; ++v) {
    const auto* t = truth.ptr<float>(v);
    const auto* m = measured.ptr<float>(v);
    const auto* in = mask.ptr<std::uint8_t>(v);
    for (int u = 0; u < truth.cols; ++u) {
      if (!in[u] || !(t[u] > 0))
        continue;
      const double truth_z = depthOf(u, v, t[u]);
      if (!(truth_z > min_depth_m && truth_z <= max_depth_m))
        continue;
      ++out.pixels;
      if (!(m[u] > 0))
        continue;
      ++matched;
      if (std::abs(m[u] - t[u]) > bad_threshold_px)
        ++bad;
      const double error = depthOf(u, v, m[u]) - truth_z;
      errors.push_back(error);
      abs_errors.push_back(std::abs(error));
    }
  }
  if (out.pixels)
    out.matched_fraction = static_cast<double>(matched) / static_cast<double>(out.pixels);
  if (matched)
    out.bad_fraction = static_cast<double>(bad) / static_cast<double>(matched);
  out.median_abs_depth_error_m = median(abs_errors);
  out.median_depth_error_m = median(errors);
  return out;
}

CloudTruthScore TruthDepthRectifier::scoreCloud(const cv::Mat& measured, const cv::Mat& truth,
                                                double min_depth_m, double max_depth_m,
                                                double tolerance_m) const {
  CV_Assert(measured.type() == CV_32F && truth.type() == CV_32F && measured.size() == truth.size());
  const auto depthOf = [this](int u, int v, double d) { return rectifiedDepth(q_, u, v, d); };
  CloudTruthScore out;
  std::size_t off = 0, sky = 0, nearer = 0, farther = 0, beyond_crop = 0;
  for (int v = 0; v < truth.rows; ++v) {
    const auto* m = measured.ptr<float>(v);
    for (int u = 0; u < truth.cols; ++u) {
      if (!(m[u] > 0))
        continue;
      const double z = depthOf(u, v, m[u]);
      if (!(z > min_depth_m && z <= max_depth_m))
        continue;
      ++out.points;
      // Near the surface if the truth on this ray or one up to `kRadius` pixels away (a few mm
      // across at the plants' range: a leaf's rim pixel whose centre ray passes beside the leaf,
      // or the matcher's block smearing a leaf's depth a pixel or two onto what is behind it) is
      // within tolerance.
      constexpr int kRadius = 2;
      bool any_surface = false;
      bool near = false;
      for (int dv = -kRadius; dv <= kRadius && !near; ++dv) {
        const int vv = v + dv;
        if (vv < 0 || vv >= truth.rows)
          continue;
        const auto* tn = truth.ptr<float>(vv);
        for (int du = -kRadius; du <= kRadius && !near; ++du) {
          const int uu = u + du;
          if (uu < 0 || uu >= truth.cols || !(tn[uu] > 0))
            continue;
          any_surface = true;
          near = std::abs(z - depthOf(uu, vv, tn[uu])) <= tolerance_m;
        }
      }
      if (!any_surface)
        ++sky;
      if (near)
        continue;
      ++off;
      const float own = truth.at<float>(v, u);
      if (!(own > 0))
        continue;
      const double own_z = depthOf(u, v, own);
      if (z < own_z) {
        ++nearer;
        if (own_z > max_depth_m)
          ++beyond_crop;
      } else {
        ++farther;
      }
    }
  }
  if (out.points) {
    out.off_surface_fraction = static_cast<double>(off) / static_cast<double>(out.points);
    out.on_sky_fraction = static_cast<double>(sky) / static_cast<double>(out.points);
    out.off_nearer_fraction = static_cast<double>(nearer) / static_cast<double>(out.points);
    out.off_farther_fraction = static_cast<double>(farther) / static_cast<double>(out.points);
    out.from_beyond_crop_fraction =
        static_cast<double>(beyond_crop) / static_cast<double>(out.points);
  }
  return out;
}

cv::Mat truthWhereMatched(const cv::Mat& measured, const cv::Mat& truth) {
  CV_Assert(measured.type() == CV_32F && truth.type() == CV_32F && measured.size() == truth.size());
  cv::Mat out(measured.size(), CV_32F, cv::Scalar(kInvalidDisparity));
  for (int v = 0; v < measured.rows; ++v) {
    const auto* m = measured.ptr<float>(v);
    const auto* t = truth.ptr<float>(v);
    auto* o = out.ptr<float>(v);
    for (int u = 0; u < measured.cols; ++u) {
      if (m[u] >= 0 && t[u] >= 0)
        o[u] = t[u];
    }
  }
  return out;
}

}  // namespace fieldrig::stereo
