// Outliers of a voxelised cloud on the voxel grid itself: by neighbour count, and by the size of
// the connected piece a point belongs to. The paper's StatisticalOutlierRemoval (PCL, kd-tree k-NN
// per point) costs ~250 ms for 76k points on the shared 2-core machine, most of the 300 ms budget;
// after a VoxelGrid the points sit one per cell, so the cells around a point are its neighbourhood
// and a hash lookup replaces the k-NN search. For the same reason the pieces are grown over the
// grid's 26-neighbourhood rather than with PCL's EuclideanClusterExtraction (a kd-tree radius
// search per point, for what is the same connectivity on a grid).
#include <cmath>
#include <cstdint>
#include <unordered_map>
#include <unordered_set>

#include "fieldrig/traits/plot_traits.h"

namespace fieldrig::traits {
namespace {

// The cell of p shifted by (dx, dy, dz) cells, as one integer: 21 bits an axis, so ±1e4 m at 1 cm.
std::int64_t cellKey(const Eigen::Vector3f& p, double cell, std::int64_t dx, std::int64_t dy,
                     std::int64_t dz) {
  const auto ix = static_cast<std::int64_t>(std::floor(p.x() / cell)) + dx + (1 << 20);
  const auto iy = static_cast<std::int64_t>(std::floor(p.y() / cell)) + dy + (1 << 20);
  const auto iz = static_cast<std::int64_t>(std::floor(p.z() / cell)) + dz + (1 << 20);
  return (ix << 42) | (iy << 21) | iz;
}

}  // namespace

std::vector<Eigen::Vector3f> removeSparseOutliers(const std::vector<Eigen::Vector3f>& points,
                                                  double cell, int min_neighbours,
                                                  std::size_t& removed) {
  removed = 0;
  if (points.empty() || !(cell > 0.0))
    return points;
  auto keyOf = [&](const Eigen::Vector3f& p, std::int64_t dx, std::int64_t dy, std::int64_t dz) {
    return cellKey(p, cell, dx, dy, dz);
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

std::vector<Eigen::Vector3f> removeSmallPieces(const std::vector<Eigen::Vector3f>& points,
                                               double cell, std::size_t min_cells,
                                               std::size_t& removed) {
  removed = 0;
  if (points.empty() || min_cells <= 1 || !(cell > 0.0))
    return points;
  // Cells, each with the points in it (one after a VoxelGrid, but any cloud works).
  std::unordered_map<std::int64_t, std::size_t> cell_index;
  cell_index.reserve(points.size() * 2);
  std::vector<std::size_t> cell_of_point(points.size());
  std::vector<std::size_t> first_point;  // a point of each cell, to find its neighbours
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto [it, added] =
        cell_index.emplace(cellKey(points[i], cell, 0, 0, 0), first_point.size());
    if (added)
      first_point.push_back(i);
    cell_of_point[i] = it->second;
  }
  // Pieces by breadth-first search over the 26 cells around each.
  constexpr std::size_t kUnseen = static_cast<std::size_t>(-1);
  std::vector<std::size_t> piece_of_cell(first_point.size(), kUnseen);
  std::vector<std::size_t> piece_cells;
  std::vector<std::size_t> frontier;
  for (std::size_t start = 0; start < first_point.size(); ++start) {
    if (piece_of_cell[start] != kUnseen)
      continue;
    const std::size_t piece = piece_cells.size();
    piece_cells.push_back(0);
    piece_of_cell[start] = piece;
    frontier.assign(1, start);
    while (!frontier.empty()) {
      const std::size_t current = frontier.back();
      frontier.pop_back();
      ++piece_cells[piece];
      const Eigen::Vector3f& p = points[first_point[current]];
      for (std::int64_t dx = -1; dx <= 1; ++dx)
        for (std::int64_t dy = -1; dy <= 1; ++dy)
          for (std::int64_t dz = -1; dz <= 1; ++dz) {
            const auto found = cell_index.find(cellKey(p, cell, dx, dy, dz));
            if (found != cell_index.end() && piece_of_cell[found->second] == kUnseen) {
              piece_of_cell[found->second] = piece;
              frontier.push_back(found->second);
            }
          }
    }
  }
  std::vector<Eigen::Vector3f> kept;
  kept.reserve(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (piece_cells[piece_of_cell[cell_of_point[i]]] >= min_cells) {
      kept.push_back(points[i]);
    } else {
      ++removed;
    }
  }
  return kept;
}

}  // namespace fieldrig::traits
