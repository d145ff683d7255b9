#include "fieldrig/stem/stem_measurer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

namespace fieldrig::stem {
namespace {

struct EdgeLine {
  cv::Point2d point;      // on the line
  cv::Point2d direction;  // unit
};

cv::Point2d projectOnto(const EdgeLine& line, const cv::Point2d& p) {
  return line.point + line.direction * (p - line.point).dot(line.direction);
}

// Vertex of the parabola through (−1, a), (0, b), (1, c), as an offset from the middle sample.
double parabolaOffset(double a, double b, double c) {
  const double denominator = a - 2.0 * b + c;
  if (std::abs(denominator) < 1e-12)
    return 0.0;
  return std::clamp(0.5 * (a - c) / denominator, -0.5, 0.5);
}

cv::Rect boundingRect(const Quadrangle& quad, double margin) {
  const Points4 points = toPoints(quad);
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const cv::Point2d& p : points) {
    x0 = std::min(x0, p.x);
    y0 = std::min(y0, p.y);
    x1 = std::max(x1, p.x);
    y1 = std::max(y1, p.y);
  }
  const int left = static_cast<int>(std::floor(x0 - margin));
  const int top = static_cast<int>(std::floor(y0 - margin));
  return {left, top, static_cast<int>(std::ceil(x1 + margin)) - left + 1,
          static_cast<int>(std::ceil(y1 + margin)) - top + 1};
}

// Finds the silhouette along the clicked edge a→b in `gx`, `gy` (gradients of the rectified
// region whose origin is `origin`): at every pixel along the edge the strongest gradient across
// it within ±search px, of the edge's dominant polarity, to sub-pixel; then a robust line.
// Returns false when too few edge points are found.
bool refineEdge(const cv::Mat& gx, const cv::Mat& gy, const cv::Point2d& origin,
                const cv::Point2d& a, const cv::Point2d& b, double search, EdgeLine& line,
                int& samples) {
  const double length = cv::norm(b - a);
  const cv::Point2d along = (b - a) / length;
  const cv::Point2d normal(-along.y, along.x);
  constexpr double kStep = 0.25;  // sampling step across the edge, px
  const int half = static_cast<int>(std::ceil(search / kStep));
  const int across = 2 * half + 1;
  const int positions = std::max(2, static_cast<int>(std::floor(length)) + 1);
  cv::Mat map_x(positions, across, CV_32F);
  cv::Mat map_y(positions, across, CV_32F);
  for (int i = 0; i < positions; ++i) {
    const cv::Point2d base = a + along * (length * i / (positions - 1)) - origin;
    for (int j = 0; j < across; ++j) {
      const cv::Point2d p = base + normal * ((j - half) * kStep);
      map_x.at<float>(i, j) = static_cast<float>(p.x);
      map_y.at<float>(i, j) = static_cast<float>(p.y);
    }
  }
  cv::Mat sx, sy;
  cv::remap(gx, sx, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  cv::remap(gy, sy, map_x, map_y, cv::INTER_CUBIC, cv::BORDER_REPLICATE);
  cv::Mat profile = sx * normal.x + sy * normal.y;  // derivative across the edge

  // The edge's polarity (stem brighter or darker than what lies beside it) is the sign of the
  // strongest response of the summed profiles.
  cv::Mat summed;
  cv::reduce(profile, summed, 0, cv::REDUCE_SUM);
  double min_value = 0.0, max_value = 0.0;
  cv::minMaxLoc(summed, &min_value, &max_value);
  const double polarity = std::abs(max_value) >= std::abs(min_value) ? 1.0 : -1.0;
  profile *= polarity;

  std::vector<cv::Point2f> found;
  std::vector<double> strengths;
  for (int i = 0; i < positions; ++i) {
    const float* row = profile.ptr<float>(i);
    int peak = 1;
    for (int j = 1; j < across - 1; ++j) {
      if (row[j] > row[peak])
        peak = j;
    }
    // A maximum at the window's border is not an edge inside it.
    if (peak <= 1 || peak >= across - 2 || row[peak] <= 0.0f)
      continue;
    const double offset =
        (peak - half + parabolaOffset(row[peak - 1], row[peak], row[peak + 1])) * kStep;
    const cv::Point2d base = a + along * (length * i / (positions - 1));
    found.emplace_back(base + normal * offset);
    strengths.push_back(row[peak]);
  }
  // Weak responses (texture, not silhouette) are dropped: below a third of the median.
  if (found.size() >= 3) {
    std::vector<double> sorted = strengths;
    std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
    const double floor = sorted[sorted.size() / 2] / 3.0;
    std::vector<cv::Point2f> kept;
    for (std::size_t i = 0; i < found.size(); ++i) {
      if (strengths[i] >= floor)
        kept.push_back(found[i]);
    }
    found.swap(kept);
  }
  samples = static_cast<int>(found.size());
  if (found.size() < 3)
    return false;
  cv::Vec4f fitted;
  cv::fitLine(found, fitted, cv::DIST_HUBER, 0, 0.01, 0.01);
  line.direction = cv::Point2d(fitted[0], fitted[1]);
  line.point = cv::Point2d(fitted[2], fitted[3]);
  // A fitted line far from the clicked direction means the edge found is not the one clicked.
  return std::abs(line.direction.dot(along)) > std::cos(15.0 * CV_PI / 180.0);
}

}  // namespace

std::string_view toString(MeasureStatus status) {
  switch (status) {
    case MeasureStatus::kOk:
      return "ok";
    case MeasureStatus::kBadPoints:
      return "bad_points";
    case MeasureStatus::kNoSearchRange:
      return "no_search_range";
    case MeasureStatus::kWeakMatch:
      return "weak_match";
  }
  return "unknown";
}

core::Result<StemMeasurer> StemMeasurer::create(const stereo::StereoCalibration& calibration,
                                                const cv::Mat& left, const cv::Mat& right) {
  if (left.empty() || right.empty())
    return core::Error{"stem: an image is empty"};
  if (left.type() != CV_8UC1 || right.type() != CV_8UC1)
    return core::Error{"stem: images must be 8-bit grey"};
  if (left.size() != right.size()) {
    return core::Error{"stem: left image is " + std::to_string(left.cols) + "x" +
                       std::to_string(left.rows) + ", right image is " +
                       std::to_string(right.cols) + "x" + std::to_string(right.rows)};
  }
  if (!calibration.image_size.empty() && calibration.image_size != left.size()) {
    return core::Error{"stem: images are " + std::to_string(left.cols) + "x" +
                       std::to_string(left.rows) + " but the calibration is for " +
                       std::to_string(calibration.image_size.width) + "x" +
                       std::to_string(calibration.image_size.height)};
  }
  if (calibration.P1.rows != 3 || calibration.P1.cols != 4 || calibration.P2.rows != 3 ||
      calibration.P2.cols != 4 || calibration.R1.rows != 3 || calibration.R2.rows != 3)
    return core::Error{"stem: calibration lacks the rectification (R1, R2, P1, P2)"};
  StemMeasurer measurer;
  measurer.calibration_ = calibration;
  measurer.left_ = left;
  measurer.right_ = right;
  const cv::Mat& p1 = calibration.P1;
  const cv::Mat& p2 = calibration.P2;
  measurer.focal_px_ = p1.at<double>(0, 0);
  // A horizontally rectified pair has its baseline in P2(0,3) = −f·b and none in P2(1,3).
  if (std::abs(p2.at<double>(1, 3)) > 1e-6 * std::abs(p2.at<double>(0, 3)) ||
      p2.at<double>(0, 3) >= 0.0) {
    return core::Error{
        "stem: extrinsics P2 is not a horizontal rectification with the right camera on the "
        "right (P2(0,3) must be negative, P2(1,3) zero)"};
  }
  measurer.baseline_m_ = -p2.at<double>(0, 3) / p2.at<double>(0, 0);
  measurer.disparity_offset_px_ = p1.at<double>(0, 2) - p2.at<double>(0, 2);
  return measurer;
}

Points4 StemMeasurer::rectifyLeft(const Points4& raw) const {
  std::vector<cv::Point2d> in(raw.begin(), raw.end());
  std::vector<cv::Point2d> out;
  cv::undistortPoints(in, out, calibration_.M1, calibration_.D1, calibration_.R1, calibration_.P1,
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-9));
  return {out[0], out[1], out[2], out[3]};
}

Points4 StemMeasurer::unrectifyRight(const Points4& rectified) const {
  const cv::Mat& p2 = calibration_.P2;
  std::vector<cv::Point3d> rays;
  for (const cv::Point2d& p : rectified) {
    rays.emplace_back((p.x - p2.at<double>(0, 2)) / p2.at<double>(0, 0),
                      (p.y - p2.at<double>(1, 2)) / p2.at<double>(1, 1), 1.0);
  }
  // Rays of the rectified right camera, turned back into the raw right camera (R2ᵀ).
  cv::Mat rotation_vector;
  cv::Rodrigues(calibration_.R2.t(), rotation_vector);
  std::vector<cv::Point2d> raw;
  cv::projectPoints(rays, rotation_vector, cv::Vec3d(0, 0, 0), calibration_.M2, calibration_.D2,
                    raw);
  return {raw[0], raw[1], raw[2], raw[3]};
}

cv::Mat StemMeasurer::rectifiedRegion(bool left_camera, const cv::Rect& rect) const {
  const stereo::StereoCalibration& c = calibration_;
  // The rectified camera matrix with its principal point moved so that pixel (0,0) of the map
  // is the region's corner: OpenCV's map then covers the region only.
  cv::Mat camera = (left_camera ? c.P1 : c.P2)(cv::Rect(0, 0, 3, 3)).clone();
  camera.at<double>(0, 2) -= rect.x;
  camera.at<double>(1, 2) -= rect.y;
  cv::Mat map_x, map_y;
  cv::initUndistortRectifyMap(left_camera ? c.M1 : c.M2, left_camera ? c.D1 : c.D2,
                              left_camera ? c.R1 : c.R2, camera, rect.size(), CV_32FC1, map_x,
                              map_y);
  cv::Mat region;
  cv::remap(left_camera ? left_ : right_, region, map_x, map_y, cv::INTER_LINEAR,
            cv::BORDER_REPLICATE);
  cv::Mat out;
  region.convertTo(out, CV_32F);
  return out;
}

StemMeasurement StemMeasurer::measure(const Points4& points, const MeasureOptions& options) const {
  const auto started = std::chrono::steady_clock::now();
  StemMeasurement m;
  const auto finish = [&](MeasureStatus status, std::string message) {
    m.status = status;
    m.message = std::move(message);
    m.elapsed_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - started)
            .count();
    return m;
  };
  const cv::Rect image_rect(0, 0, left_.cols, left_.rows);
  for (const cv::Point2d& p : points) {
    if (!(p.x >= 0.0 && p.y >= 0.0 && p.x <= left_.cols - 1 && p.y <= left_.rows - 1)) {
      return finish(MeasureStatus::kBadPoints, "points: (" + std::to_string(p.x) + ", " +
                                                   std::to_string(p.y) + ") is outside the " +
                                                   std::to_string(left_.cols) + "x" +
                                                   std::to_string(left_.rows) + " left image");
    }
  }
  core::Result<Quadrangle> sorted = sortQuadrangle(rectifyLeft(points));
  if (!sorted)
    return finish(MeasureStatus::kBadPoints, sorted.error().message);
  m.clicked = *sorted;
  m.refined = m.clicked;

  // The left region: the quadrangle, the edge search band and room for the gradient kernels.
  const double margin = options.edge_search_px + 4.0;
  const cv::Rect left_rect = boundingRect(m.clicked, margin) & image_rect;
  if (left_rect.width < 8 || left_rect.height < 8)
    return finish(MeasureStatus::kBadPoints, "points: the quadrangle lies outside the image");
  const cv::Mat left_region = rectifiedRegion(true, left_rect);
  const cv::Point2d origin(left_rect.x, left_rect.y);

  if (options.refine_edges) {
    cv::Mat smooth, gx, gy;
    cv::GaussianBlur(left_region, smooth, cv::Size(0, 0), 0.8);
    cv::Scharr(smooth, gx, CV_32F, 1, 0, 1.0 / 32.0);
    cv::Scharr(smooth, gy, CV_32F, 0, 1, 1.0 / 32.0);
    EdgeLine left_line, right_line;
    const bool left_ok = refineEdge(gx, gy, origin, m.clicked.q1, m.clicked.q2,
                                    options.edge_search_px, left_line, m.edge_samples_left);
    const bool right_ok = refineEdge(gx, gy, origin, m.clicked.q3, m.clicked.q4,
                                     options.edge_search_px, right_line, m.edge_samples_right);
    if (left_ok && right_ok) {
      m.refined = {projectOnto(left_line, m.clicked.q1), projectOnto(left_line, m.clicked.q2),
                   projectOnto(right_line, m.clicked.q3), projectOnto(right_line, m.clicked.q4)};
      m.edges_refined = true;
    }
  }
  m.width = quadrangleWidth(m.refined);

  // The patch: the quadrangle, its border pixels left out (they mix stem and background, whose
  // disparities differ).
  const cv::Rect patch_rect = boundingRect(m.refined, 0.0) & image_rect;
  if (patch_rect.width < 3 || patch_rect.height < 3)
    return finish(MeasureStatus::kBadPoints, "points: the quadrangle is too small to match");
  cv::Mat mask = cv::Mat::zeros(patch_rect.size(), CV_8U);
  std::vector<cv::Point> outline;
  for (const cv::Point2d& p : {m.refined.q1, m.refined.q2, m.refined.q4, m.refined.q3}) {
    outline.emplace_back(cv::saturate_cast<int>((p.x - patch_rect.x) * 16.0),
                         cv::saturate_cast<int>((p.y - patch_rect.y) * 16.0));
  }
  cv::fillConvexPoly(mask, outline, cv::Scalar(255), cv::LINE_8, 4);
  cv::erode(mask, mask, cv::Mat(), cv::Point(-1, -1), 2);
  if (cv::countNonZero(mask) < 16)
    return finish(MeasureStatus::kBadPoints, "points: the quadrangle is too narrow to match");
  const cv::Mat templ = left_region(cv::Rect(patch_rect.x - left_rect.x, patch_rect.y - left_rect.y,
                                             patch_rect.width, patch_rect.height))
                            .clone();

  // Eq. (14)'s ε: disparities of the depths the head is used at.
  const double fb = focal_px_ * baseline_m_;
  const int min_disparity =
      static_cast<int>(std::floor(fb / options.max_depth_m + disparity_offset_px_)) - 1;
  const int max_disparity =
      static_cast<int>(std::ceil(fb / options.min_depth_m + disparity_offset_px_)) + 1;
  const int strip_x0 = std::max(0, patch_rect.x - max_disparity);
  const int strip_x1 = std::min(right_.cols, patch_rect.x + patch_rect.width - min_disparity);
  if (strip_x1 - strip_x0 < patch_rect.width + 2) {
    return finish(MeasureStatus::kNoSearchRange,
                  "the disparity range for depths " + std::to_string(options.min_depth_m) + "-" +
                      std::to_string(options.max_depth_m) + " m falls outside the right image");
  }
  const cv::Mat strip = rectifiedRegion(
      false, cv::Rect(strip_x0, patch_rect.y, strip_x1 - strip_x0, patch_rect.height));
  cv::Mat scores;
  cv::matchTemplate(strip, templ, scores, cv::TM_CCOEFF_NORMED, mask);
  cv::patchNaNs(scores, -1.0);
  const float* s = scores.ptr<float>(0);
  const int count = scores.cols;
  int peak = 0;
  for (int j = 1; j < count; ++j) {
    if (s[j] > s[peak])
      peak = j;
  }
  // The second peak: the best score outside the main peak's lobe (where the scores fall
  // monotonically from the peak).
  int lobe_start = peak;
  while (lobe_start > 0 && s[lobe_start - 1] < s[lobe_start])
    --lobe_start;
  int lobe_end = peak;
  while (lobe_end < count - 1 && s[lobe_end + 1] < s[lobe_end])
    ++lobe_end;
  double second = -1.0;
  for (int j = 0; j < count; ++j) {
    if (j < lobe_start || j > lobe_end)
      second = std::max(second, static_cast<double>(s[j]));
  }
  double sub = 0.0;
  if (peak > 0 && peak < count - 1)
    sub = parabolaOffset(s[peak - 1], s[peak], s[peak + 1]);
  m.ncc = s[peak];
  m.ncc_second = second;
  m.distinctness = m.ncc - std::max(0.0, second);
  m.disparity_px = patch_rect.x - (strip_x0 + peak + sub);
  const Points4 refined_points = toPoints(m.refined);
  Points4 right_rectified;
  for (std::size_t i = 0; i < 4; ++i)
    right_rectified[i] = refined_points[i] - cv::Point2d(m.disparity_px, 0.0);
  m.right_patch_raw = unrectifyRight(right_rectified);
  if (!(m.ncc > options.min_ncc)) {
    return finish(MeasureStatus::kWeakMatch, "weak match: NCC peak " + std::to_string(m.ncc) +
                                                 " is not above " +
                                                 std::to_string(options.min_ncc));
  }
  const double disparity = m.disparity_px - disparity_offset_px_;
  if (disparity <= 0.0)
    return finish(MeasureStatus::kWeakMatch, "weak match: disparity is not positive");
  m.patch_depth_m = fb / disparity;
  m.diameter_plane_mm = 1000.0 * baseline_m_ * m.width.d / disparity;

  // The cylinder: the refined edges are the tangent rays, so the angle 2α between them at the
  // camera and the distance ρ to the axis give r = ρ·sin α; the patch's depth is that of the
  // near surface, ρ = ρ_patch + k·r.
  const cv::Mat& p1 = calibration_.P1;
  const auto ray = [&](const cv::Point2d& p) {
    return cv::normalize(cv::Vec3d((p.x - p1.at<double>(0, 2)) / p1.at<double>(0, 0),
                                   (p.y - p1.at<double>(1, 2)) / p1.at<double>(1, 1), 1.0));
  };
  const cv::Point2d centre = (m.refined.q1 + m.refined.q2 + m.refined.q3 + m.refined.q4) * 0.25;
  const EdgeLine left_edge{m.refined.q1,
                           (m.refined.q2 - m.refined.q1) / cv::norm(m.refined.q2 - m.refined.q1)};
  const EdgeLine right_edge{m.refined.q3,
                            (m.refined.q4 - m.refined.q3) / cv::norm(m.refined.q4 - m.refined.q3)};
  const cv::Vec3d left_ray = ray(projectOnto(left_edge, centre));
  const cv::Vec3d right_ray = ray(projectOnto(right_edge, centre));
  const double half_angle = 0.5 * std::acos(std::clamp(left_ray.dot(right_ray), -1.0, 1.0));
  const cv::Vec3d central = cv::normalize(left_ray + right_ray);
  const double patch_distance = m.patch_depth_m / central[2];
  const double sin_half = std::sin(half_angle);
  const double radius = patch_distance * sin_half / (1.0 - options.near_surface_radii * sin_half);
  const double diameter_cylinder_mm = 2000.0 * radius;
  m.diameter_mm = options.cylinder_model ? diameter_cylinder_mm : m.diameter_plane_mm;
  return finish(MeasureStatus::kOk, "");
}

}  // namespace fieldrig::stem
