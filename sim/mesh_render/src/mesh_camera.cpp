#include "fieldrig/sim/mesh_camera.h"

#include <algorithm>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>

#include "fieldrig/core/rig_layout.h"

namespace fieldrig::sim {
namespace {

Eigen::Matrix3d toEigen(const cv::Matx33d& m) {
  Eigen::Matrix3d e;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      e(r, c) = m(r, c);
  return e;
}

Eigen::Matrix3d toEigen3(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  Eigen::Matrix3d e;
  cv::cv2eigen(d.reshape(1, 3), e);
  return e;
}

Eigen::Vector3d toEigenVector(const cv::Mat& m) {
  cv::Mat d;
  m.convertTo(d, CV_64F);
  d = d.reshape(1, 3);
  return {d.at<double>(0), d.at<double>(1), d.at<double>(2)};
}

double coefficient(const cv::Mat& d, int i) {
  return i < static_cast<int>(d.total()) ? d.at<double>(i) : 0.0;
}

// The undistorted normalised radius of the image's corners and edge midpoints, 5 % wider.
double fieldRadius(const MeshCamera& camera) {
  const double w = camera.size.width - 1.0;
  const double h = camera.size.height - 1.0;
  std::vector<cv::Point2d> border{{0, 0}, {w / 2, 0}, {w, 0}, {w, h / 2},
                                  {w, h}, {w / 2, h}, {0, h}, {0, h / 2}};
  std::vector<cv::Point2d> normalised;
  cv::undistortPoints(border, normalised, camera.camera_matrix, camera.distortion, cv::noArray(),
                      cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-9));
  double radius = 0.0;
  for (const cv::Point2d& p : normalised)
    radius = std::max(radius, std::hypot(p.x, p.y));
  return 1.05 * radius;
}

}  // namespace

bool MeshCamera::project(const Eigen::Vector3d& plot_point, Eigen::Vector2d& pixel) const {
  const Eigen::Vector3d c = plot_from_camera.transpose() * (plot_point - position);
  if (c.z() <= 1e-9)
    return false;
  const cv::Mat& d = distortion;
  const int n = static_cast<int>(d.total());
  if (n > 12 && (coefficient(d, 12) != 0.0 || coefficient(d, 13) != 0.0)) {
    // A tilted sensor: OpenCV's own projection.
    std::vector<cv::Point3d> object{{c.x(), c.y(), c.z()}};
    std::vector<cv::Point2d> image;
    cv::projectPoints(object, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), camera_matrix, d, image);
    pixel = {image[0].x, image[0].y};
    return true;
  }
  const double x = c.x() / c.z();
  const double y = c.y() / c.z();
  const double r2 = x * x + y * y;
  if (max_normalised_radius > 0.0 && r2 > max_normalised_radius * max_normalised_radius)
    return false;
  const double r4 = r2 * r2;
  const double r6 = r4 * r2;
  const double radial =
      (1.0 + coefficient(d, 0) * r2 + coefficient(d, 1) * r4 + coefficient(d, 4) * r6) /
      (1.0 + coefficient(d, 5) * r2 + coefficient(d, 6) * r4 + coefficient(d, 7) * r6);
  const double p1 = coefficient(d, 2);
  const double p2 = coefficient(d, 3);
  const double xd = x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x) +
                    coefficient(d, 8) * r2 + coefficient(d, 9) * r4;
  const double yd = y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y +
                    coefficient(d, 10) * r2 + coefficient(d, 11) * r4;
  const cv::Matx33d& k = camera_matrix;
  pixel = {k(0, 0) * xd + k(0, 1) * yd + k(0, 2), k(1, 1) * yd + k(1, 2)};
  return true;
}

double MeshCamera::depth(const Eigen::Vector3d& plot_point) const {
  return (plot_from_camera.transpose() * (plot_point - position)).z();
}

std::vector<MeshCamera> rigCameras(const cloud::RigCalibration& rig,
                                   const Eigen::Vector3d& bottom_position) {
  const Eigen::Matrix3d plot = toEigen(rig.plot_rotation);
  std::vector<MeshCamera> cameras;
  for (const cloud::HeadCalibration& head : rig.heads) {
    Eigen::Matrix3d to_bottom_rotation;
    Eigen::Vector3d to_bottom_translation;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c)
        to_bottom_rotation(r, c) = head.to_bottom(r, c);
      to_bottom_translation(r) = head.to_bottom(r, 3);
    }
    const stereo::StereoCalibration& s = head.stereo;
    // The head frame is its rectified left camera; R1 takes the physical left camera's
    // coordinates into it, and the right camera's are R·left + T.
    const Eigen::Matrix3d plot_from_rectified = plot * to_bottom_rotation;
    const Eigen::Vector3d centre = bottom_position + plot * to_bottom_translation;
    const Eigen::Matrix3d plot_from_left = plot_from_rectified * toEigen3(s.R1);
    const Eigen::Matrix3d r = toEigen3(s.R);
    const Eigen::Vector3d t = toEigenVector(s.T);

    MeshCamera left;
    left.name = head.leftCamera();
    left.camera_matrix = cv::Matx33d(s.M1);
    s.D1.convertTo(left.distortion, CV_64F);
    left.size = s.image_size;
    left.plot_from_camera = plot_from_left;
    left.position = centre;

    MeshCamera right;
    right.name = head.rightCamera();
    right.camera_matrix = cv::Matx33d(s.M2);
    s.D2.convertTo(right.distortion, CV_64F);
    right.size = s.image_size;
    right.plot_from_camera = plot_from_left * r.transpose();
    right.position = centre + plot_from_left * (-r.transpose() * t);

    left.max_normalised_radius = fieldRadius(left);
    right.max_normalised_radius = fieldRadius(right);
    cameras.push_back(std::move(left));
    cameras.push_back(std::move(right));
  }
  return cameras;
}

cv::Mat pixelRayMap(const MeshCamera& camera) {
  const cv::Size size = camera.size;
  cv::Mat rays(size, CV_32FC2);
  cv::parallel_for_(cv::Range(0, size.height), [&](const cv::Range& range) {
    cv::Mat pixels(1, size.width, CV_64FC2);
    cv::Mat undistorted;
    for (int row = range.start; row < range.end; ++row) {
      auto* p = pixels.ptr<cv::Vec2d>(0);
      for (int col = 0; col < size.width; ++col)
        p[col] = cv::Vec2d(col, row);
      // Iterated until the point reprojects within 1e-6 px: the default five iterations leave
      // ~0.1 px at the corners of a k1 = -0.12 lens.
      cv::undistortPoints(
          pixels, undistorted, camera.camera_matrix, camera.distortion, cv::noArray(),
          cv::noArray(),
          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 200, 1e-6));
      const auto* u = undistorted.ptr<cv::Vec2d>(0);
      auto* out = rays.ptr<cv::Vec2f>(row);
      for (int col = 0; col < size.width; ++col)
        out[col] = cv::Vec2f(static_cast<float>(u[col][0]), static_cast<float>(u[col][1]));
    }
  });
  return rays;
}

}  // namespace fieldrig::sim
