// Outliers of a voxelised cloud by neighbour count on the voxel grid itself. The paper's
// StatisticalOutlierRemoval (PCL, kd-tree k-NN per point) costs ~250 ms for 76k points on the
// shared 2-core machine, most of the 300 ms budget; after a VoxelGrid the points sit one per cell,
// so the cells around a point are its neighbourhood and a hash lookup replaces the k-NN search.
#include <cmath>
#include <cstdint>
#include <unordered_set>

#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {

std::vector<Eigen::Vector3f> removeSparseOutliers(const std::vector<Eigen::Vector3f>& points,
                                                  double cell, int min_neighbours,
                                                  std::size_t& removed) {
  removed = 0;
  if (points.empty() || !(cell > 0.0))
    return points;
  auto keyOf = [&](const Eigen::Vector3f& p, std::int64_t dx, std::int64_t dy, std::int64_t dz) {
    const auto ix = static_cast<std::int64_t>(std::floor(p.x() / cell)) + dx + (1 << 20);
    const auto iy = static_cast<std::int64_t>(std::floor(p.y() / cell)) + dy + (1 << 20);
    const auto iz = static_cast<std::int64_t>(std::floor(p.z() / cell)) + dz + (1 << 20);
    return (ix << 42) | (iy << 21) | iz;
  };
  std::unordered_set<std::int64_t> occupied;
  occupied.reserve(points.size() * 2);
  for (const Eigen::Vector3f& p : points)
    occupied.insert(keyOf(p, 0, 0, 0));
  std::vector<Eigen::Vector3f> kept;
  kept.reserve(points.size());
  for (const Eigen::Vector3f& p : points) {
    int neighbours = 0;
    for (std::int64_t dx = -1; dx <= 1 && neighbours < min_neighbours; ++dx)
      for (std::int64_t dy = -1; dy <= 1 && neighbours < min_neighbours; ++dy)
        for (std::int64_t dz = -1; dz <= 1 && neighbours < min_neighbours; ++dz)
          if ((dx != 0 || dy != 0 || dz != 0) && occupied.count(keyOf(p, dx, dy, dz)) > 0)
            ++neighbours;
    if (neighbours >= min_neighbours) {
      kept.push_back(p);
    } else {
      ++removed;
    }
  }
  return kept;
}

}  // namespace fieldrig::traits
