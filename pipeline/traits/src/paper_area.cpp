// The paper's surface for VAI, kept as the baseline: MLS smoothing + greedy projection
// triangulation. Alone in this file because these PCL headers are the heaviest to compile.
#include <pcl/features/normal_3d.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <pcl/search/kdtree.h>
#include <pcl/surface/gp3.h>
#include <pcl/surface/mls.h>

#include <cmath>
#include <numbers>

#include "pcl_steps.h"

namespace fieldrig::traits::detail {

double paperMlsGptArea(const Points& points, double mls_radius, double gpt_radius, double mu,
                       int max_neighbors) {
  if (points.size() < 10)
    return 0.0;
  auto cloud = std::make_shared<pcl::PointCloud<pcl::PointXYZ>>();
  cloud->reserve(points.size());
  for (const Eigen::Vector3f& p : points)
    cloud->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));

  pcl::MovingLeastSquares<pcl::PointXYZ, pcl::PointNormal> mls;
  mls.setInputCloud(cloud);
  mls.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointXYZ>>());
  mls.setSearchRadius(mls_radius);
  mls.setComputeNormals(true);
  mls.setPolynomialOrder(2);
  auto smoothed = std::make_shared<pcl::PointCloud<pcl::PointNormal>>();
  mls.process(*smoothed);
  if (smoothed->size() < 3)
    return 0.0;

  pcl::GreedyProjectionTriangulation<pcl::PointNormal> gpt;
  gpt.setInputCloud(smoothed);
  gpt.setSearchMethod(std::make_shared<pcl::search::KdTree<pcl::PointNormal>>());
  gpt.setSearchRadius(gpt_radius);
  gpt.setMu(mu);
  gpt.setMaximumNearestNeighbors(max_neighbors);
  gpt.setMaximumSurfaceAngle(std::numbers::pi / 4.0);
  gpt.setMinimumAngle(std::numbers::pi / 18.0);
  gpt.setMaximumAngle(2.0 * std::numbers::pi / 3.0);
  gpt.setNormalConsistency(false);
  std::vector<pcl::Vertices> triangles;
  gpt.reconstruct(triangles);

  double area = 0.0;
  for (const pcl::Vertices& triangle : triangles) {
    if (triangle.vertices.size() != 3)
      continue;
    const Eigen::Vector3f a = (*smoothed)[triangle.vertices[0]].getVector3fMap();
    const Eigen::Vector3f b = (*smoothed)[triangle.vertices[1]].getVector3fMap();
    const Eigen::Vector3f c = (*smoothed)[triangle.vertices[2]].getVector3fMap();
    area += 0.5 * static_cast<double>((b - a).cross(c - a).norm());
  }
  return area;
}

}  // namespace fieldrig::traits::detail
