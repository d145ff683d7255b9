// The user's four clicks on a stem segment as the paper's convex quadrangle (§2.4, Fig. 11):
// q1 top-left, q2 bottom-left, q3 top-right, q4 bottom-right, and its width, eq. (10)–(12).
#pragma once

#include <array>
#include <opencv2/core.hpp>

#include "fieldrig/core/result.h"

namespace fieldrig::stem {

using Points4 = std::array<cv::Point2d, 4>;

struct Quadrangle {
  cv::Point2d q1, q2, q3, q4;  // top-left, bottom-left, top-right, bottom-right
};

// Sorts four points picked in any order. The two stem edges are the pair of opposite sides
// whose midpoints lie side by side (across the stem) rather than one above the other; within
// an edge the upper point comes first. A pick that is not a convex quadrangle, or whose sides
// are shorter than `min_side_px`, is refused with a message saying why.
core::Result<Quadrangle> sortQuadrangle(const Points4& points, double min_side_px = 2.0);

struct QuadrangleWidth {
  double d12 = 0.0;  // eq. (10): midpoint of q1q2 to the line q3q4
  double d34 = 0.0;  // eq. (11): midpoint of q3q4 to the line q1q2
  double d = 0.0;    // eq. (12): their mean
};

QuadrangleWidth quadrangleWidth(const Quadrangle& quad);

Points4 toPoints(const Quadrangle& quad);

}  // namespace fieldrig::stem
