// Synthetic stereo pairs of one stem: a textured, shaded cylinder in front of a textured plane,
// seen by a Grasshopper-like head (1624×1224, f ≈ 1350 px, 0.12 m baseline), with the
// calibration that describes the pair and the true diameter, distance and silhouette. Pixels at
// the silhouette are supersampled so that edges are anti-aliased as a real lens and sensor make
// them, which is what sub-pixel edge finding needs to be tested against.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>

#include "fieldrig/stereo/calibration.h"

namespace fieldrig::sim {

struct StereoRigGeometry {
  cv::Size image_size{1624, 1224};
  double focal_px = 1350.0;
  double baseline_m = 0.12;
  // Lens distortion (k1, k2, p1, p2, k3) of both cameras; zero for an ideal lens.
  bool distorted = false;
  // Small rotation of the right camera (radians, Rodrigues vector) so that rectification is
  // not the identity.
  cv::Vec3d right_rotation{0.0, 0.0, 0.0};
};

// The stem, in the left camera's frame (metres): its axis passes through (axis_x, ·, depth) and
// leans by `tilt_rad` in the image plane (0 = vertical).
struct CylinderScene {
  double diameter_m = 0.016;
  double axis_x_m = 0.0;
  double depth_m = 1.0;  // Z of the axis
  double tilt_rad = 0.0;
  double background_depth_m = 2.5;
  double stem_brightness = 150.0;       // mean grey level of the stem's albedo
  double background_brightness = 80.0;  // mean grey level of the background
  double texture_contrast = 0.25;       // relative amplitude of both textures
  // Share of the stem's light that comes from one direction (the rest is diffuse sky); the
  // directional part darkens one rim of the stem.
  double directional_light = 0.15;
  double noise_sigma = 1.5;    // grey levels, Gaussian, per pixel
  double blur_sigma_px = 0.6;  // optics and sensor
  std::uint64_t seed = 1;      // texture phases and noise
};

// One rendered pair with its truth.
struct RenderedStereoPair {
  cv::Mat left, right;  // CV_8UC1, raw (distorted when the geometry says so)
  stereo::StereoCalibration calibration;
  double diameter_m = 0.0;
  double axis_depth_m = 0.0;
};

stereo::StereoCalibration makeCalibration(const StereoRigGeometry& geometry);

RenderedStereoPair renderCylinderPair(const StereoRigGeometry& geometry,
                                      const CylinderScene& scene);

// A point on the stem's silhouette in the raw left image: side −1 = left edge, +1 = right edge;
// `height_m` is the position along the axis (0 = at the optical axis' height).
cv::Point2d silhouettePoint(const StereoRigGeometry& geometry, const CylinderScene& scene, int side,
                            double height_m);

}  // namespace fieldrig::sim
