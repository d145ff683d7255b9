#include "fieldrig/sim/cylinder_stereo_renderer.h"

#include <array>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <vector>

namespace fieldrig::sim {
namespace {

// A band-limited procedural texture: a sum of plane waves with random directions, wavelengths
// and phases. Band-limited so that sampling each pixel once does not alias.
struct WaveTexture {
  struct Wave {
    double kx, ky, phase, amplitude;
  };
  std::vector<Wave> waves;

  WaveTexture(std::mt19937_64& rng, int count, double min_wavelength_m, double max_wavelength_m) {
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double amplitude = std::sqrt(2.0 * 0.25 / count);  // standard deviation ≈ 0.5
    for (int i = 0; i < count; ++i) {
      const double angle = unit(rng) * CV_PI;
      const double wavelength =
          min_wavelength_m * std::pow(max_wavelength_m / min_wavelength_m, unit(rng));
      const double k = 2.0 * CV_PI / wavelength;
      waves.push_back(
          {k * std::cos(angle), k * std::sin(angle), unit(rng) * 2.0 * CV_PI, amplitude});
    }
  }

  double operator()(double x, double y) const {
    double sum = 0.0;
    for (const Wave& wave : waves)
      sum += wave.amplitude * std::sin(wave.kx * x + wave.ky * y + wave.phase);
    return sum;
  }
};

cv::Matx33d cameraMatrix(const StereoRigGeometry& geometry, double cx_offset, double cy_offset) {
  return {geometry.focal_px,
          0.0,
          geometry.image_size.width / 2.0 + cx_offset,
          0.0,
          geometry.focal_px,
          geometry.image_size.height / 2.0 + cy_offset,
          0.0,
          0.0,
          1.0};
}

cv::Mat distortion(const StereoRigGeometry& geometry, double scale) {
  if (!geometry.distorted)
    return cv::Mat::zeros(1, 5, CV_64F);
  // A typical 6 mm lens on a 1/1.8" sensor: mild barrel distortion.
  return (cv::Mat_<double>(1, 5) << -0.11 * scale, 0.09 * scale, 0.0004, -0.0003, -0.01);
}

// The scene as seen from the cylinder's own frame, where its axis is vertical (y).
class SceneTracer {
 public:
  SceneTracer(const CylinderScene& scene)
      : scene_(scene),
        cos_tilt_(std::cos(scene.tilt_rad)),
        sin_tilt_(std::sin(scene.tilt_rad)),
        radius_(scene.diameter_m / 2.0),
        axis_x_(scene.axis_x_m * cos_tilt_),
        axis_z_(scene.depth_m),
        rng_(scene.seed),
        stem_texture_(rng_, 10, 0.004, 0.02),
        background_texture_(rng_, 8, 0.006, 0.06) {
    const cv::Vec3d light = cv::normalize(cv::Vec3d(-0.4, -0.3, -1.0));
    light_ = light;
  }

  // Grey level seen along the ray from `origin` in direction `dir` (left camera frame); sets
  // `on_stem` to whether the ray hits the stem.
  double trace(const cv::Vec3d& origin, const cv::Vec3d& dir, bool& on_stem) const {
    // Into the cylinder's frame: rotate about the optical axis by the tilt.
    const double ox = origin[0] * cos_tilt_ - origin[1] * sin_tilt_;
    const double oy = origin[0] * sin_tilt_ + origin[1] * cos_tilt_;
    const double dx = dir[0] * cos_tilt_ - dir[1] * sin_tilt_;
    const double dy = dir[0] * sin_tilt_ + dir[1] * cos_tilt_;
    const double px = ox - axis_x_;
    const double pz = origin[2] - axis_z_;
    const double a = dx * dx + dir[2] * dir[2];
    const double b = 2.0 * (px * dx + pz * dir[2]);
    const double c = px * px + pz * pz - radius_ * radius_;
    const double discriminant = b * b - 4.0 * a * c;
    if (discriminant > 0.0) {
      const double t = (-b - std::sqrt(discriminant)) / (2.0 * a);
      if (t > 0.0) {
        on_stem = true;
        const double hx = px + t * dx;
        const double hz = pz + t * dir[2];
        const double hy = oy + t * dy;
        const cv::Vec3d normal(hx / radius_, 0.0, hz / radius_);
        const double arc = radius_ * std::atan2(hx, -hz);
        const double albedo =
            scene_.stem_brightness * (1.0 + scene_.texture_contrast * stem_texture_(arc, hy));
        const double lambert = std::max(0.0, normal.dot(light_));
        return albedo * (1.0 - scene_.directional_light + scene_.directional_light * lambert);
      }
    }
    on_stem = false;
    const double t = (scene_.background_depth_m - origin[2]) / dir[2];
    const double bx = origin[0] + t * dir[0];
    const double by = origin[1] + t * dir[1];
    return scene_.background_brightness *
           (1.0 + scene_.texture_contrast * background_texture_(bx, by));
  }

 private:
  CylinderScene scene_;
  double cos_tilt_, sin_tilt_, radius_, axis_x_, axis_z_;
  std::mt19937_64 rng_;
  WaveTexture stem_texture_;
  WaveTexture background_texture_;
  cv::Vec3d light_;
};

// Renders one camera: `rays` holds each pixel's viewing direction in the left camera's frame.
cv::Mat renderView(const SceneTracer& tracer, const cv::Vec3d& origin, const cv::Mat& rays,
                   const CylinderScene& scene, std::uint64_t noise_seed) {
  const int rows = rays.rows;
  const int cols = rays.cols;
  cv::Mat image(rows, cols, CV_32F);
  cv::Mat on_stem(rows, cols, CV_8U);
  cv::parallel_for_(cv::Range(0, rows), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) {
      for (int x = 0; x < cols; ++x) {
        bool hit = false;
        image.at<float>(y, x) =
            static_cast<float>(tracer.trace(origin, rays.at<cv::Vec3d>(y, x), hit));
        on_stem.at<std::uint8_t>(y, x) = hit ? 1 : 0;
      }
    }
  });
  // Pixels the silhouette crosses: a neighbour's centre lies on the other side. They are
  // supersampled (8×8) so that their grey level is the covered area's mean.
  cv::Mat dilated, eroded;
  cv::dilate(on_stem, dilated, cv::Mat());
  cv::erode(on_stem, eroded, cv::Mat());
  constexpr int kSamples = 8;
  cv::parallel_for_(cv::Range(1, rows - 1), [&](const cv::Range& range) {
    for (int y = range.start; y < range.end; ++y) {
      for (int x = 1; x < cols - 1; ++x) {
        if (dilated.at<std::uint8_t>(y, x) == eroded.at<std::uint8_t>(y, x))
          continue;
        const cv::Vec3d centre = rays.at<cv::Vec3d>(y, x);
        const cv::Vec3d du = (rays.at<cv::Vec3d>(y, x + 1) - rays.at<cv::Vec3d>(y, x - 1)) * 0.5;
        const cv::Vec3d dv = (rays.at<cv::Vec3d>(y + 1, x) - rays.at<cv::Vec3d>(y - 1, x)) * 0.5;
        double sum = 0.0;
        for (int sy = 0; sy < kSamples; ++sy) {
          for (int sx = 0; sx < kSamples; ++sx) {
            const double fx = (sx + 0.5) / kSamples - 0.5;
            const double fy = (sy + 0.5) / kSamples - 0.5;
            bool hit = false;
            sum += tracer.trace(origin, centre + fx * du + fy * dv, hit);
          }
        }
        image.at<float>(y, x) = static_cast<float>(sum / (kSamples * kSamples));
      }
    }
  });
  if (scene.blur_sigma_px > 0.0)
    cv::GaussianBlur(image, image, cv::Size(0, 0), scene.blur_sigma_px);
  cv::Mat noise(rows, cols, CV_32F);
  cv::RNG rng(noise_seed);
  rng.fill(noise, cv::RNG::NORMAL, 0.0, scene.noise_sigma);
  image += noise;
  cv::Mat out;
  image.convertTo(out, CV_8U);  // rounds and saturates
  return out;
}

// Viewing direction of every pixel of a camera whose orientation w.r.t. the left camera is
// `rotation_to_left`, through its lens.
cv::Mat pixelRays(const cv::Size& size, const cv::Matx33d& camera, const cv::Mat& dist,
                  const cv::Matx33d& rotation_to_left) {
  cv::Mat rays(size, CV_64FC3);
  if (cv::countNonZero(dist) == 0) {
    // No lens distortion: the pinhole model, inverted directly.
    const cv::Matx33d inverse = rotation_to_left * camera.inv();
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x)
        rays.at<cv::Vec3d>(y, x) = inverse * cv::Vec3d(x, y, 1.0);
    }
    return rays;
  }
  std::vector<cv::Point2d> pixels;
  pixels.reserve(static_cast<std::size_t>(size.area()));
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x)
      pixels.emplace_back(x, y);
  std::vector<cv::Point2d> normalized;
  cv::undistortPoints(pixels, normalized, camera, dist, cv::noArray(), cv::noArray(),
                      cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 20, 1e-9));
  for (int y = 0; y < size.height; ++y) {
    for (int x = 0; x < size.width; ++x) {
      const cv::Point2d& n = normalized[static_cast<std::size_t>(y) * size.width + x];
      rays.at<cv::Vec3d>(y, x) = rotation_to_left * cv::Vec3d(n.x, n.y, 1.0);
    }
  }
  return rays;
}

}  // namespace

stereo::StereoCalibration makeCalibration(const StereoRigGeometry& geometry) {
  stereo::StereoCalibration calibration;
  calibration.image_size = geometry.image_size;
  calibration.M1 = cv::Mat(cameraMatrix(geometry, 3.2, -2.4));
  calibration.M2 = cv::Mat(cameraMatrix(geometry, -2.1, 1.7));
  calibration.D1 = distortion(geometry, 1.0);
  calibration.D2 = distortion(geometry, 0.95);
  cv::Mat rotation;
  cv::Rodrigues(geometry.right_rotation, rotation);
  // The right camera's centre is `baseline` to the right of the left one; X_r = R·X_l + T.
  const cv::Mat centre = (cv::Mat_<double>(3, 1) << geometry.baseline_m, 0.0, 0.0);
  calibration.R = rotation;
  calibration.T = -rotation * centre;
  cv::stereoRectify(calibration.M1, calibration.D1, calibration.M2, calibration.D2,
                    geometry.image_size, calibration.R, calibration.T, calibration.R1,
                    calibration.R2, calibration.P1, calibration.P2, calibration.Q,
                    cv::CALIB_ZERO_DISPARITY, 0.0);
  return calibration;
}

RenderedStereoPair renderCylinderPair(const StereoRigGeometry& geometry,
                                      const CylinderScene& scene) {
  RenderedStereoPair pair;
  pair.calibration = makeCalibration(geometry);
  pair.diameter_m = scene.diameter_m;
  pair.axis_depth_m = scene.depth_m;
  const SceneTracer tracer(scene);
  const cv::Mat left_rays = pixelRays(geometry.image_size, cv::Matx33d(pair.calibration.M1),
                                      pair.calibration.D1, cv::Matx33d::eye());
  const cv::Matx33d rotation(pair.calibration.R);
  const cv::Mat right_rays = pixelRays(geometry.image_size, cv::Matx33d(pair.calibration.M2),
                                       pair.calibration.D2, rotation.t());
  pair.left = renderView(tracer, cv::Vec3d(0, 0, 0), left_rays, scene, scene.seed * 2 + 1);
  pair.right = renderView(tracer, cv::Vec3d(geometry.baseline_m, 0, 0), right_rays, scene,
                          scene.seed * 2 + 2);
  return pair;
}

cv::Point2d silhouettePoint(const StereoRigGeometry& geometry, const CylinderScene& scene, int side,
                            double height_m) {
  const double cos_tilt = std::cos(scene.tilt_rad);
  const double sin_tilt = std::sin(scene.tilt_rad);
  // The axis in the cylinder's frame (rotated by the tilt about the optical axis).
  const double axis_x = scene.axis_x_m * cos_tilt;
  const double axis_y = scene.axis_x_m * sin_tilt;
  const double radius = scene.diameter_m / 2.0;
  const double rho = std::hypot(axis_x, scene.depth_m);
  const double half_angle = std::asin(radius / rho);
  const double direction = std::atan2(axis_x, scene.depth_m) + side * half_angle;
  const double reach = std::sqrt(rho * rho - radius * radius);
  const double tx = reach * std::sin(direction);
  const double tz = reach * std::cos(direction);
  const double ty = axis_y + height_m;
  // Back into the camera's frame.
  const cv::Point3d point(tx * cos_tilt + ty * sin_tilt, -tx * sin_tilt + ty * cos_tilt, tz);
  const stereo::StereoCalibration calibration = makeCalibration(geometry);
  std::vector<cv::Point2d> projected;
  cv::projectPoints(std::vector<cv::Point3d>{point}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    calibration.M1, calibration.D1, projected);
  return projected.front();
}

}  // namespace fieldrig::sim
