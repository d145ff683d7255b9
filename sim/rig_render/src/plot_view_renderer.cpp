#include "fieldrig/sim/plot_view_renderer.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace fieldrig::sim {
namespace {

// A reproducible pseudo-random value in [0, 1) for an integer lattice point.
double latticeValue(std::int64_t i, std::int64_t j, std::int64_t k) {
  std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ULL ^
                    static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL ^
                    static_cast<std::uint64_t>(k) * 0x165667B19E3779F9ULL;
  h ^= h >> 31;
  h *= 0xD6E8FEB86659FD93ULL;
  h ^= h >> 32;
  return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0);
}

// Trilinear value noise in [0, 1): smooth at the lattice scale, so that neither camera aliases it.
double valueNoise(const Eigen::Vector3d& p) {
  const Eigen::Vector3d f = p.array().floor();
  const Eigen::Vector3d t = p - f;
  const auto i = static_cast<std::int64_t>(f.x());
  const auto j = static_cast<std::int64_t>(f.y());
  const auto k = static_cast<std::int64_t>(f.z());
  double value = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const int di = corner & 1;
    const int dj = (corner >> 1) & 1;
    const int dk = (corner >> 2) & 1;
    const double weight =
        (di ? t.x() : 1 - t.x()) * (dj ? t.y() : 1 - t.y()) * (dk ? t.z() : 1 - t.z());
    value += weight * latticeValue(i + di, j + dj, k + dk);
  }
  return value;
}

std::uint8_t toByte(double v) {
  return static_cast<std::uint8_t>(std::clamp(v, 0.0, 255.0));
}

}  // namespace

cv::Mat renderPlotView(const PlotCloud& plot, const PinholeView& view,
                       const RenderOptions& options) {
  const int width = view.size.width;
  const int height = view.size.height;
  const double cx = (width - 1) / 2.0;
  const double cy = (height - 1) / 2.0;
  const double f = view.focal_px;
  const Eigen::Matrix3d camera_from_plot = view.plot_from_camera.transpose();

  cv::Mat depth(view.size, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  cv::Mat base(view.size, CV_8UC3, cv::Scalar(0, 0, 0));
  for (std::size_t i = 0; i < plot.points.size(); ++i) {
    if (plot.labels[i] == SurfaceLabel::kOutlier)
      continue;  // noise of a measurement, not a surface
    const Eigen::Vector3d c = camera_from_plot * (plot.points[i].cast<double>() - view.position);
    if (c.z() < 0.05)
      continue;
    const double u = f * c.x() / c.z() + cx;
    const double v = f * c.y() / c.z() + cy;
    const double spacing = plot.labels[i] == SurfaceLabel::kSoil ? options.soil_sample_spacing_m
                                                                 : options.plant_sample_spacing_m;
    // Half the footprint, rounded up, so that neighbouring samples overlap and nothing behind
    // shows through the gaps of a surface.
    const int radius = static_cast<int>(std::ceil(0.5 * f * spacing / c.z()));
    const int u0 = std::max(0, static_cast<int>(std::floor(u)) - radius);
    const int u1 = std::min(width - 1, static_cast<int>(std::floor(u)) + radius);
    const int v0 = std::max(0, static_cast<int>(std::floor(v)) - radius);
    const int v1 = std::min(height - 1, static_cast<int>(std::floor(v)) + radius);
    const auto z = static_cast<float>(c.z());
    const auto& colour = plot.colors[i];
    for (int row = v0; row <= v1; ++row) {
      float* depth_row = depth.ptr<float>(row);
      cv::Vec3b* base_row = base.ptr<cv::Vec3b>(row);
      for (int col = u0; col <= u1; ++col) {
        if (z < depth_row[col]) {
          depth_row[col] = z;
          base_row[col] = cv::Vec3b(colour[2], colour[1], colour[0]);  // generator RGB → BGR
        }
      }
    }
  }

  cv::Mat image(view.size, CV_8UC3);
  const double inverse_cell = 1.0 / options.texture_cell_m;
  for (int row = 0; row < height; ++row) {
    const float* depth_row = depth.ptr<float>(row);
    const cv::Vec3b* base_row = base.ptr<cv::Vec3b>(row);
    cv::Vec3b* out = image.ptr<cv::Vec3b>(row);
    for (int col = 0; col < width; ++col) {
      const Eigen::Vector3d ray((col - cx) / f, (row - cy) / f, 1.0);
      if (std::isfinite(depth_row[col])) {
        const Eigen::Vector3d point =
            view.plot_from_camera * (ray * static_cast<double>(depth_row[col])) + view.position;
        const double shade = 0.45 + 1.1 * valueNoise(point * inverse_cell);
        const cv::Vec3b& b = base_row[col];
        out[col] = cv::Vec3b(toByte(b[0] * shade), toByte(b[1] * shade), toByte(b[2] * shade));
      } else {
        const Eigen::Vector3d point =
            view.plot_from_camera * (ray * options.backdrop_depth_m) + view.position;
        const double shade = 60 + 150 * valueNoise(point * 20.0);
        out[col] = cv::Vec3b(toByte(shade * 1.1), toByte(shade), toByte(shade * 0.9));
      }
    }
  }
  return image;
}

}  // namespace fieldrig::sim
