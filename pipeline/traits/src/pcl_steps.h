// The PCL steps of the traits pipeline behind plain types, so that PCL's heavy headers are
// compiled in few translation units (pcl_steps.cpp, paper_area.cpp).
#pragma once

#include <Eigen/Core>

#include <vector>

namespace fieldrig::traits::detail {

using Points = std::vector<Eigen::Vector3f>;

Points voxelGrid(const Points& points, double leaf);
Points removeStatisticalOutliers(const Points& points, int mean_k, double stddev_mul,
                                 std::size_t& removed);

struct PlateFit {
  Eigen::Matrix4d transform = Eigen::Matrix4d::Identity();
  double fitness_coarse = -1.0;
  double fitness_fine = -1.0;
  bool converged = false;
  bool fell_back = false;
  double tilt_deg = 0.0;
};

// Registers the plate template to the target: a coarse ICP with the paper's correspondence
// distance, then a fine one; when the coarse stage tilts the plate beyond max_tilt_deg the fine
// stage restarts from the data-driven pose (identity here: the template is already placed).
// fine_distance <= 0 runs the paper's single coarse stage.
// `transform` with its rotation's tilt (the angle it turns x by) reduced to `limit_deg`, about the
// axis it tilts around; its turn about the tilted x is kept, and `pivot` stays where it maps to.
Eigen::Matrix4d limitTilt(const Eigen::Matrix4d& transform, const Eigen::Vector3d& pivot,
                          double limit_deg);

PlateFit registerPlate(const Points& plate, const Points& target, double coarse_distance,
                       double fine_distance, int iterations, double max_tilt_deg);

// Volume of the 3D convex hull (Qhull through PCL); 0 for fewer than 4 points or a flat set.
double convexHullVolume(const Points& points);

// The paper's VAI surface: MovingLeastSquares smoothing, then GreedyProjectionTriangulation;
// returns the summed triangle area (equations 7, 8).
double paperMlsGptArea(const Points& points, double mls_radius, double gpt_radius, double mu,
                       int max_neighbors);

}  // namespace fieldrig::traits::detail
