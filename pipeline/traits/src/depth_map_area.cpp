// Surface area of a side-view cloud as a 2.5D depth map: the camera sees the plants roughly as
// a height field z(x, y), possibly several layers deep. Each occupied cell's layer contributes its
// slope-corrected area, weighted like a triangulation of cell centres (a cell missing a neighbour
// on one side counts half along that axis), so that a cell grid neither inflates thin structures
// nor loses their rims on average.
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <unordered_map>
#include <vector>

#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {
namespace {

// Whether a surface of another view continues at grid cell (ix, iy) near depth z: a cell whose
// neighbour went to another depth map is not the rim of the surface.
using OtherView = std::function<bool(std::int64_t ix, std::int64_t iy, float z)>;

struct AreaSum {
  double area = 0.0;
  double weight = 0.0;  // sum of the centre-triangulation weights
  double layers = 0.0;  // cell layers seen
};

AreaSum depthMapAreaWith(const std::vector<Eigen::Vector3f>& points, double cell, double max_step,
                         const OtherView& other) {
  AreaSum sum;
  if (points.empty() || !(cell > 0.0) || !(max_step > 0.0))
    return sum;
  Eigen::Vector3f lo = points.front();
  Eigen::Vector3f hi = points.front();
  for (const Eigen::Vector3f& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double extent_x = static_cast<double>(hi.x() - lo.x());
  const double extent_y = static_cast<double>(hi.y() - lo.y());
  // Cells on the global grid (multiples of `cell`), like PCL's VoxelGrid, so that cells and
  // voxel columns coincide when the cloud was voxelised with the same size.
  const auto x0 = static_cast<std::int64_t>(std::floor(lo.x() / cell));
  const auto y0 = static_cast<std::int64_t>(std::floor(lo.y() / cell));
  const std::int64_t nx = static_cast<std::int64_t>(std::floor(hi.x() / cell)) - x0 + 1;
  const std::int64_t ny = static_cast<std::int64_t>(std::floor(hi.y() / cell)) - y0 + 1;
  if (nx * ny > 50'000'000 || !std::isfinite(extent_x) || !std::isfinite(extent_y))
    return sum;
  const auto cells = static_cast<std::size_t>(nx * ny);
  auto cellOf = [&](const Eigen::Vector3f& p) {
    const std::int64_t ix = static_cast<std::int64_t>(std::floor(p.x() / cell)) - x0;
    const std::int64_t iy = static_cast<std::int64_t>(std::floor(p.y() / cell)) - y0;
    return static_cast<std::size_t>(std::clamp<std::int64_t>(ix, 0, nx - 1) * ny +
                                    std::clamp<std::int64_t>(iy, 0, ny - 1));
  };
  // Bucket depths per cell (counting sort), then split each bucket into layers at depth gaps.
  std::vector<std::uint32_t> start(cells + 1, 0);
  for (const Eigen::Vector3f& p : points)
    ++start[cellOf(p) + 1];
  for (std::size_t c = 0; c < cells; ++c)
    start[c + 1] += start[c];
  std::vector<float> depth(points.size());
  {
    std::vector<std::uint32_t> fill(start.begin(), start.end() - 1);
    for (const Eigen::Vector3f& p : points)
      depth[fill[cellOf(p)]++] = p.z();
  }
  std::vector<std::uint32_t> layer_start(cells + 1, 0);
  std::vector<float> layers;
  layers.reserve(points.size() / 2 + 1);
  for (std::size_t c = 0; c < cells; ++c) {
    layer_start[c] = static_cast<std::uint32_t>(layers.size());
    auto first = depth.begin() + start[c];
    auto last = depth.begin() + start[c + 1];
    if (first == last)
      continue;
    std::sort(first, last);
    double depth_sum = *first;
    int count = 1;
    for (auto it = first + 1; it != last; ++it) {
      if (*it - *(it - 1) > max_step) {
        layers.push_back(static_cast<float>(depth_sum / count));
        depth_sum = 0.0;
        count = 0;
      }
      depth_sum += *it;
      ++count;
    }
    layers.push_back(static_cast<float>(depth_sum / count));
  }
  layer_start[cells] = static_cast<std::uint32_t>(layers.size());

  // The layer of a neighbouring cell that continues the surface at depth z, if any.
  auto neighbour = [&](std::int64_t ix, std::int64_t iy, float z, float& found) {
    if (ix < 0 || ix >= nx || iy < 0 || iy >= ny)
      return false;
    const auto c = static_cast<std::size_t>(ix * ny + iy);
    float best = 0.0F;
    float best_gap = static_cast<float>(max_step);
    bool any = false;
    for (std::uint32_t l = layer_start[c]; l < layer_start[c + 1]; ++l) {
      const float gap = std::abs(layers[l] - z);
      if (gap <= best_gap) {
        best_gap = gap;
        best = layers[l];
        any = true;
      }
    }
    found = best;
    return any;
  };
  // Slope along one axis from the neighbours found, and the centre-triangulation weight.
  auto axis = [&](bool has_minus, float z_minus, bool has_plus, float z_plus, float z,
                  double& slope) {
    if (has_minus && has_plus) {
      slope = (z_plus - z_minus) / (2.0 * cell);
    } else if (has_plus) {
      slope = (z_plus - z) / cell;
    } else if (has_minus) {
      slope = (z - z_minus) / cell;
    } else {
      slope = 0.0;
    }
  };
  auto weight = [](bool minus, bool plus) {
    return 0.5 * (minus ? 1.0 : 0.0) + 0.5 * (plus ? 1.0 : 0.0);
  };
  auto present = [&](bool here, std::int64_t ix, std::int64_t iy, float z) {
    return here || (other && other(ix + x0, iy + y0, z));
  };
  for (std::int64_t ix = 0; ix < nx; ++ix) {
    for (std::int64_t iy = 0; iy < ny; ++iy) {
      const auto c = static_cast<std::size_t>(ix * ny + iy);
      for (std::uint32_t l = layer_start[c]; l < layer_start[c + 1]; ++l) {
        const float z = layers[l];
        float xm = 0.0F, xp = 0.0F, ym = 0.0F, yp = 0.0F;
        const bool has_xm = neighbour(ix - 1, iy, z, xm);
        const bool has_xp = neighbour(ix + 1, iy, z, xp);
        const bool has_ym = neighbour(ix, iy - 1, z, ym);
        const bool has_yp = neighbour(ix, iy + 1, z, yp);
        double gx = 0.0;
        double gy = 0.0;
        axis(has_xm, xm, has_xp, xp, z, gx);
        axis(has_ym, ym, has_yp, yp, z, gy);
        const double wx = weight(present(has_xm, ix - 1, iy, z), present(has_xp, ix + 1, iy, z));
        const double wy = weight(present(has_ym, ix, iy - 1, z), present(has_yp, ix, iy + 1, z));
        sum.area += wx * wy * cell * cell * std::sqrt(1.0 + gx * gx + gy * gy);
        sum.weight += wx * wy;
        sum.layers += 1.0;
      }
    }
  }
  return sum;
}

}  // namespace

double depthMapArea(const std::vector<Eigen::Vector3f>& points, double cell, double max_step) {
  return depthMapAreaWith(points, cell, max_step, nullptr).area;
}

SurfaceArea multiViewDepthMapArea(const std::vector<Eigen::Vector3f>& points, double cell,
                                  double max_step) {
  SurfaceArea result;
  result.cell_m = cell;
  if (points.empty() || !(cell > 0.0))
    return result;
  // Cells of the voxel grid and their centroids (one point per cell after a VoxelGrid).
  auto keyOf = [&](const Eigen::Vector3f& p) {
    const auto ix = static_cast<std::int64_t>(std::floor(p.x() / cell)) + (1 << 20);
    const auto iy = static_cast<std::int64_t>(std::floor(p.y() / cell)) + (1 << 20);
    const auto iz = static_cast<std::int64_t>(std::floor(p.z() / cell)) + (1 << 20);
    return (ix << 42) | (iy << 21) | iz;
  };
  std::unordered_map<std::int64_t, std::uint32_t> cells;
  cells.reserve(points.size() * 2);
  std::vector<Eigen::Vector3d> sums;
  std::vector<int> counts;
  std::vector<std::uint32_t> cell_of(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto [it, inserted] =
        cells.emplace(keyOf(points[i]), static_cast<std::uint32_t>(sums.size()));
    if (inserted) {
      sums.emplace_back(Eigen::Vector3d::Zero());
      counts.push_back(0);
    }
    cell_of[i] = it->second;
    sums[it->second] += points[i].cast<double>();
    ++counts[it->second];
  }
  std::vector<Eigen::Vector3d> centroids(sums.size());
  for (std::size_t c = 0; c < sums.size(); ++c)
    centroids[c] = sums[c] / counts[c];
  // Normal of each cell: the least principal axis of the centroids within two cells (a 3-cell
  // neighbourhood lets depth noise of 3-4 mm tip the normals and split one surface over views).
  std::vector<int> axis_of(sums.size(), 2);
  for (const auto& [key, c] : cells) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
    int n = 0;
    for (std::int64_t dx = -2; dx <= 2; ++dx) {
      for (std::int64_t dy = -2; dy <= 2; ++dy) {
        for (std::int64_t dz = -2; dz <= 2; ++dz) {
          if (std::abs(dx) + std::abs(dy) + std::abs(dz) > 3)
            continue;  // a rounded 5-cell neighbourhood: half the lookups of the full cube
          const auto found = cells.find(key + (dx << 42) + (dy << 21) + dz);
          if (found == cells.end())
            continue;
          const Eigen::Vector3d& q = centroids[found->second];
          mean += q;
          second += q * q.transpose();
          ++n;
        }
      }
    }
    if (n < 3)
      continue;
    mean /= n;
    const Eigen::Matrix3d covariance = second / n - mean * mean.transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> solver;
    solver.computeDirect(covariance);
    const Eigen::Vector3d normal = solver.eigenvectors().col(0).cwiseAbs();
    normal.maxCoeff(&axis_of[c]);
  }
  // One depth map per axis, each holding the surfaces that face it most.
  std::array<std::vector<Eigen::Vector3f>, 3> views;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3f& p = points[i];
    switch (axis_of[cell_of[i]]) {
      case 0:
        views[0].emplace_back(p.y(), p.z(), p.x());
        break;
      case 1:
        views[1].emplace_back(p.x(), p.z(), p.y());
        break;
      default:
        views[2].push_back(p);
        break;
    }
  }
  // A view's neighbour cell counts as present when any voxel of another view lies there within
  // max_step in depth, so the seams between views are not counted as rims.
  const auto depth_cells = static_cast<std::int64_t>(std::ceil(max_step / cell));
  auto occupied = [&](std::int64_t ix, std::int64_t iy, std::int64_t iz) {
    return cells.count(((ix + (1 << 20)) << 42) | ((iy + (1 << 20)) << 21) | (iz + (1 << 20))) > 0;
  };
  double weight = 0.0;
  double layers = 0.0;
  for (int view = 0; view < 3; ++view) {
    const OtherView other = [&, view](std::int64_t iu, std::int64_t iv, float z) {
      const auto iw = static_cast<std::int64_t>(std::floor(z / cell));
      for (std::int64_t d = -depth_cells; d <= depth_cells; ++d) {
        const bool hit = view == 0   ? occupied(iw + d, iu, iv)
                         : view == 1 ? occupied(iu, iw + d, iv)
                                     : occupied(iu, iv, iw + d);
        if (hit)
          return true;
      }
      return false;
    };
    const AreaSum sum =
        depthMapAreaWith(views[static_cast<std::size_t>(view)], cell, max_step, other);
    result.area_m2 += sum.area;
    weight += sum.weight;
    layers += sum.layers;
  }
  result.fill = layers > 0.0 ? weight / layers : 0.0;
  return result;
}

}  // namespace fieldrig::traits
