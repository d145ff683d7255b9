#include "pcl_steps.h"

#include <pcl/filters/statistical_outlier_removal.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/registration/icp.h>
#include <pcl/surface/convex_hull.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace fieldrig::traits::detail {
namespace {

pcl::PointCloud<pcl::PointXYZ>::Ptr toPcl(const Points& points) {
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(points.size());
  for (const Eigen::Vector3f& p : points)
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return cloud;
}

Points fromPcl(const pcl::PointCloud<pcl::PointXYZ>& cloud) {
  Points points;
  points.reserve(cloud.size());
  for (const pcl::PointXYZ& p : cloud)
    points.emplace_back(p.x, p.y, p.z);
  return points;
}

double tiltOf(const Eigen::Matrix4d& transform) {
  const Eigen::Vector3d up = transform.block<3, 3>(0, 0) * Eigen::Vector3d::UnitX();
  return std::acos(std::clamp(up.x(), -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace

Points voxelGrid(const Points& points, double leaf) {
  if (points.empty())
    return {};
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(toPcl(points));
  const auto l = static_cast<float>(leaf);
  grid.setLeafSize(l, l, l);
  pcl::PointCloud<pcl::PointXYZ> out;
  grid.filter(out);
  return fromPcl(out);
}

Points removeStatisticalOutliers(const Points& points, int mean_k, double stddev_mul,
                                 std::size_t& removed) {
  removed = 0;
  if (points.size() <= static_cast<std::size_t>(mean_k))
    return points;
  pcl::StatisticalOutlierRemoval<pcl::PointXYZ> sor;
  sor.setInputCloud(toPcl(points));
  sor.setMeanK(mean_k);
  sor.setStddevMulThresh(stddev_mul);
  pcl::PointCloud<pcl::PointXYZ> out;
  sor.filter(out);
  removed = points.size() - out.size();
  return fromPcl(out);
}

Eigen::Matrix4d limitTilt(const Eigen::Matrix4d& transform, const Eigen::Vector3d& pivot,
                          double limit_deg) {
  const Eigen::Matrix3d r = transform.block<3, 3>(0, 0);
  const Eigen::Vector3d up = r * Eigen::Vector3d::UnitX();
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitX().cross(up);
  const double tilt = std::atan2(axis.norm(), up.x());
  const double limit = limit_deg * std::numbers::pi / 180.0;
  if (!(tilt > limit) || axis.norm() < 1e-12)
    return transform;
  // r = tilt(θ) · turn, with turn a rotation about x; the result is tilt(limit) · turn.
  const Eigen::Vector3d unit_axis = axis.normalized();
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(-tilt, unit_axis).toRotationMatrix() * r;
  const Eigen::Matrix3d limited = Eigen::AngleAxisd(limit, unit_axis).toRotationMatrix() * turn;
  Eigen::Matrix4d out = Eigen::Matrix4d::Identity();
  out.block<3, 3>(0, 0) = limited;
  const Eigen::Vector3d pivot_to = r * pivot + transform.block<3, 1>(0, 3);
  out.block<3, 1>(0, 3) = pivot_to - limited * pivot;
  return out;
}

PlateFit registerPlate(const Points& plate, const Points& target, double coarse_distance,
                       double fine_distance, int iterations, double max_tilt_deg) {
  PlateFit fit;
  if (plate.empty() || target.size() < 10)
    return fit;
  const auto source_cloud = toPcl(plate);
  const auto target_cloud = toPcl(target);
  auto run = [&](double distance, const Eigen::Matrix4f& guess, double& fitness) {
    pcl::IterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> icp;
    icp.setInputSource(source_cloud);
    icp.setInputTarget(target_cloud);
    icp.setMaxCorrespondenceDistance(distance);
    icp.setMaximumIterations(iterations);
    icp.setTransformationEpsilon(1e-8);
    icp.setEuclideanFitnessEpsilon(1e-8);
    pcl::PointCloud<pcl::PointXYZ> aligned;
    icp.align(aligned, guess);
    // PCL compares squared distances with the range given here.
    fitness = icp.getFitnessScore(distance * distance);
    return std::make_pair(icp.hasConverged(), icp.getFinalTransformation());
  };
  const auto [coarse_ok, coarse] =
      run(coarse_distance, Eigen::Matrix4f::Identity(), fit.fitness_coarse);
  Eigen::Matrix4f start = coarse;
  if (!coarse_ok || tiltOf(coarse.cast<double>()) > max_tilt_deg) {
    start = Eigen::Matrix4f::Identity();
    fit.fell_back = true;
  }
  if (!(fine_distance > 0.0)) {
    // The paper's single stage.
    fit.converged = coarse_ok;
    fit.transform = coarse.cast<double>();
    fit.tilt_deg = tiltOf(fit.transform);
    return fit;
  }
  const auto [fine_ok, fine] = run(fine_distance, start, fit.fitness_fine);
  fit.converged = fine_ok;
  fit.transform = fine.cast<double>();
  fit.tilt_deg = tiltOf(fit.transform);
  return fit;
}

double convexHullVolume(const Points& points) {
  if (points.size() < 4)
    return 0.0;
  // Qhull fails on flat or collinear sets; a set whose bounding box has no thickness has no
  // volume, and skipping it keeps Qhull's error messages out of the log.
  Eigen::Vector3f lo = points.front();
  Eigen::Vector3f hi = points.front();
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  if ((hi - lo).minCoeff() < 1e-6F)
    return 0.0;
  // The volume is summed from the hull's triangles (tetrahedra to an interior point) rather than
  // asked of Qhull ("FA"), because that option makes Qhull print its statistics on stdout.
  pcl::ConvexHull<pcl::PointXYZ> hull;
  hull.setInputCloud(toPcl(points));
  hull.setDimension(3);
  pcl::PointCloud<pcl::PointXYZ> vertices;
  std::vector<pcl::Vertices> facets;
  hull.reconstruct(vertices, facets);
  if (vertices.size() < 4 || facets.empty())
    return 0.0;
  Eigen::Vector3d inside = Eigen::Vector3d::Zero();
  for (const pcl::PointXYZ& v : vertices)
    inside += v.getVector3fMap().cast<double>();
  inside /= static_cast<double>(vertices.size());
  double volume = 0.0;
  for (const pcl::Vertices& facet : facets) {
    if (facet.vertices.size() < 3)
      continue;
    const Eigen::Vector3d a = vertices[facet.vertices[0]].getVector3fMap().cast<double>() - inside;
    for (std::size_t k = 1; k + 1 < facet.vertices.size(); ++k) {
      const Eigen::Vector3d b =
          vertices[facet.vertices[k]].getVector3fMap().cast<double>() - inside;
      const Eigen::Vector3d c =
          vertices[facet.vertices[k + 1]].getVector3fMap().cast<double>() - inside;
      volume += std::abs(a.dot(b.cross(c))) / 6.0;
    }
  }
  return std::isfinite(volume) ? volume : 0.0;
}

}  // namespace fieldrig::traits::detail
