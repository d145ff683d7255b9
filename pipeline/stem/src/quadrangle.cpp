#include "fieldrig/stem/quadrangle.h"

#include <cmath>
#include <string>
#include <utility>

namespace fieldrig::stem {
namespace {

double cross(const cv::Point2d& a, const cv::Point2d& b) {
  return a.x * b.y - a.y * b.x;
}

// Whether segments ab and cd cross (touching counts).
bool segmentsIntersect(const cv::Point2d& a, const cv::Point2d& b, const cv::Point2d& c,
                       const cv::Point2d& d) {
  const double d1 = cross(b - a, c - a);
  const double d2 = cross(b - a, d - a);
  const double d3 = cross(d - c, a - c);
  const double d4 = cross(d - c, b - c);
  return d1 * d2 <= 0.0 && d3 * d4 <= 0.0;
}

// Distance from `point` to the line through a and b.
double distanceToLine(const cv::Point2d& point, const cv::Point2d& a, const cv::Point2d& b) {
  return std::abs(cross(a - b, b - point)) / cv::norm(a - b);
}

}  // namespace

core::Result<Quadrangle> sortQuadrangle(const Points4& p, double min_side_px) {
  for (const cv::Point2d& point : p) {
    if (!std::isfinite(point.x) || !std::isfinite(point.y))
      return core::Error{"points: a coordinate is not a finite number"};
  }
  // The three ways to split four points into two segments; for a convex quadrangle one of them
  // is the crossing diagonals, the other two are pairs of opposite sides.
  const std::array<std::array<int, 4>, 3> pairings{{{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}}};
  double best_score = -1e300;
  int best = -1;
  for (int i = 0; i < 3; ++i) {
    const auto& k = pairings[static_cast<std::size_t>(i)];
    const cv::Point2d& a = p[static_cast<std::size_t>(k[0])];
    const cv::Point2d& b = p[static_cast<std::size_t>(k[1])];
    const cv::Point2d& c = p[static_cast<std::size_t>(k[2])];
    const cv::Point2d& d = p[static_cast<std::size_t>(k[3])];
    if (segmentsIntersect(a, b, c, d))
      continue;
    const cv::Point2d between = (a + b) * 0.5 - (c + d) * 0.5;
    const double score = std::abs(between.x) - std::abs(between.y);
    if (score > best_score) {
      best_score = score;
      best = i;
    }
  }
  if (best < 0)
    return core::Error{"points: the four points do not form a convex quadrangle"};
  const auto& k = pairings[static_cast<std::size_t>(best)];
  std::pair<cv::Point2d, cv::Point2d> edge_a{p[static_cast<std::size_t>(k[0])],
                                             p[static_cast<std::size_t>(k[1])]};
  std::pair<cv::Point2d, cv::Point2d> edge_b{p[static_cast<std::size_t>(k[2])],
                                             p[static_cast<std::size_t>(k[3])]};
  if (edge_a.first.x + edge_a.second.x > edge_b.first.x + edge_b.second.x)
    std::swap(edge_a, edge_b);
  if (edge_a.first.y > edge_a.second.y)
    std::swap(edge_a.first, edge_a.second);
  if (edge_b.first.y > edge_b.second.y)
    std::swap(edge_b.first, edge_b.second);
  const Quadrangle quad{edge_a.first, edge_a.second, edge_b.first, edge_b.second};

  // Walk the outline q1 → q2 → q4 → q3: a convex quadrangle turns the same way at every corner.
  const std::array<cv::Point2d, 4> outline{quad.q1, quad.q2, quad.q4, quad.q3};
  int positive = 0;
  int negative = 0;
  for (std::size_t i = 0; i < 4; ++i) {
    const cv::Point2d& prev = outline[(i + 3) % 4];
    const cv::Point2d& here = outline[i];
    const cv::Point2d& next = outline[(i + 1) % 4];
    const double side = cv::norm(next - here);
    if (side < min_side_px) {
      return core::Error{"points: degenerate quadrangle, a side is " + std::to_string(side) +
                         " px long (at least " + std::to_string(min_side_px) + " px needed)"};
    }
    const double turn = cross(here - prev, next - here);
    // Collinear corners (turn ≈ 0 relative to the sides) make a degenerate quadrangle.
    if (std::abs(turn) < 1e-6 * cv::norm(here - prev) * side)
      return core::Error{"points: degenerate quadrangle, three points are collinear"};
    (turn > 0 ? positive : negative)++;
  }
  if (positive != 0 && negative != 0)
    return core::Error{"points: the four points do not form a convex quadrangle"};
  return quad;
}

QuadrangleWidth quadrangleWidth(const Quadrangle& quad) {
  QuadrangleWidth width;
  const cv::Point2d q12 = (quad.q1 + quad.q2) * 0.5;
  const cv::Point2d q34 = (quad.q3 + quad.q4) * 0.5;
  width.d12 = distanceToLine(q12, quad.q3, quad.q4);
  width.d34 = distanceToLine(q34, quad.q1, quad.q2);
  width.d = (width.d12 + width.d34) / 2.0;
  return width;
}

Points4 toPoints(const Quadrangle& quad) {
  return {quad.q1, quad.q2, quad.q3, quad.q4};
}

}  // namespace fieldrig::stem
