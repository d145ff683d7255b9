// The six cameras of a calibrated rig placed in the scene (plot) frame, as the calibration files
// describe them: each camera's own matrix and distortion (OpenCV's k1 k2 p1 p2 [k3 …] model),
// the right camera where R and T put it, each head where its transform into the bottom head puts
// it. The renderer traces one ray per pixel sample through the inverse of the distortion model.
#pragma once

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include <string>
#include <vector>

#include "fieldrig/cloud/rig_calibration.h"

namespace fieldrig::sim {

struct MeshCamera {
  std::string name;  // the rig layout's camera name ("bottom_left", …)
  cv::Matx33d camera_matrix;
  cv::Mat distortion;  // 1×N CV_64F, OpenCV's order
  cv::Size size;
  Eigen::Matrix3d plot_from_camera = Eigen::Matrix3d::Identity();  // camera x right, y down, z fwd
  Eigen::Vector3d position = Eigen::Vector3d::Zero();              // centre in the plot frame
  // Largest undistorted normalised radius (x/z, y/z) any pixel of the image looks along, with a
  // margin: beyond it the distortion polynomial folds back, and points far outside the view
  // would project into the image. 0: not known (no limit).
  double max_normalised_radius = 0.0;

  // The pixel (distortion applied) where a plot-frame point images; false behind the camera or
  // outside the lens' field (max_normalised_radius).
  bool project(const Eigen::Vector3d& plot_point, Eigen::Vector2d& pixel) const;
  // Depth of a plot-frame point along this camera's optical axis (its z).
  double depth(const Eigen::Vector3d& plot_point) const;
};

// The cameras of `rig` in the rig layout's order (bottom_left, bottom_right, middle_left, …),
// with the bottom head's rectified left camera (the frame the pipeline's plot frame is turned
// from) centred at `bottom_position` in the scene.
//
// The pipeline's plot frame is plot_rotation · (bottom head frame), with its origin at that
// camera; the scene frame is the same frame moved by `bottom_position`, so the truth computed in
// the scene is the pipeline's up to that shift (heights and widths do not see it).
std::vector<MeshCamera> rigCameras(const cloud::RigCalibration& rig,
                                   const Eigen::Vector3d& bottom_position);

// Per pixel centre, the undistorted normalised image coordinates (x/z, y/z in the camera frame)
// of the ray through it: cv::undistortPoints over the whole pixel grid, iterated to convergence
// (CV_32FC2, the camera's size). Computed once per camera and reused for every frame.
cv::Mat pixelRayMap(const MeshCamera& camera);

}  // namespace fieldrig::sim
