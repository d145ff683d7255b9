// The quadrangle of four clicks: sorting from any order, refusal of bad picks, eq. (10)–(12)
// against values computed by hand.
#include <gtest/gtest.h>

#include <algorithm>

#include "fieldrig/stem/quadrangle.h"

namespace fieldrig::stem {
namespace {

void expectNear(const cv::Point2d& actual, const cv::Point2d& expected) {
  EXPECT_DOUBLE_EQ(actual.x, expected.x);
  EXPECT_DOUBLE_EQ(actual.y, expected.y);
}

TEST(StemQuadrangle, SortsEveryOrderIntoTopLeftBottomLeftTopRightBottomRight) {
  const cv::Point2d tl(100, 50), bl(102, 150), tr(120, 52), br(121, 149);
  Points4 points{br, tl, tr, bl};
  std::sort(points.begin(), points.end(), [](const cv::Point2d& a, const cv::Point2d& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
  });
  int orders = 0;
  do {
    core::Result<Quadrangle> quad = sortQuadrangle(points);
    ASSERT_TRUE(quad.ok()) << quad.error().message;
    expectNear(quad->q1, tl);
    expectNear(quad->q2, bl);
    expectNear(quad->q3, tr);
    expectNear(quad->q4, br);
    ++orders;
  } while (std::next_permutation(points.begin(), points.end(),
                                 [](const cv::Point2d& a, const cv::Point2d& b) {
                                   return a.x < b.x || (a.x == b.x && a.y < b.y);
                                 }));
  EXPECT_EQ(orders, 24);
}

TEST(StemQuadrangle, ShortSegmentOfAThickStemStillPairsTheEdges) {
  // 40 px wide, only 10 px tall: the edges are the short vertical sides.
  core::Result<Quadrangle> quad = sortQuadrangle(
      {cv::Point2d(0, 0), cv::Point2d(40, 10), cv::Point2d(0, 10), cv::Point2d(40, 0)});
  ASSERT_TRUE(quad.ok()) << quad.error().message;
  expectNear(quad->q1, {0, 0});
  expectNear(quad->q2, {0, 10});
  expectNear(quad->q3, {40, 0});
  expectNear(quad->q4, {40, 10});
}

TEST(StemQuadrangle, RefusesANonConvexPick) {
  // The fourth point lies inside the triangle of the other three.
  core::Result<Quadrangle> quad = sortQuadrangle(
      {cv::Point2d(0, 0), cv::Point2d(0, 100), cv::Point2d(40, 50), cv::Point2d(10, 50)});
  ASSERT_FALSE(quad.ok());
  EXPECT_NE(quad.error().message.find("convex"), std::string::npos) << quad.error().message;
}

TEST(StemQuadrangle, RefusesDegeneratePicks) {
  core::Result<Quadrangle> twice = sortQuadrangle(
      {cv::Point2d(0, 0), cv::Point2d(0, 0), cv::Point2d(20, 0), cv::Point2d(20, 50)});
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().message.find("degenerate"), std::string::npos) << twice.error().message;
  core::Result<Quadrangle> line = sortQuadrangle(
      {cv::Point2d(0, 0), cv::Point2d(0, 10), cv::Point2d(0, 20), cv::Point2d(0, 30)});
  EXPECT_FALSE(line.ok());
  core::Result<Quadrangle> nan = sortQuadrangle(
      {cv::Point2d(0, 0), cv::Point2d(0, std::nan("")), cv::Point2d(20, 0), cv::Point2d(20, 50)});
  ASSERT_FALSE(nan.ok());
  EXPECT_NE(nan.error().message.find("finite"), std::string::npos);
}

TEST(StemQuadrangle, WidthFollowsEquations10To12) {
  // Rectangle: both distances are the width.
  const QuadrangleWidth rectangle = quadrangleWidth(
      {cv::Point2d(0, 0), cv::Point2d(0, 20), cv::Point2d(10, 0), cv::Point2d(10, 20)});
  EXPECT_DOUBLE_EQ(rectangle.d12, 10.0);
  EXPECT_DOUBLE_EQ(rectangle.d34, 10.0);
  EXPECT_DOUBLE_EQ(rectangle.d, 10.0);
  // Trapezoid: q12 = (0,10) to the line (10,0)-(12,20): |(-2,-20) x (12,10)| / |(-2,-20)|
  // = 220 / sqrt(404); q34 = (11,10) to the line x = 0: 11.
  const QuadrangleWidth trapezoid = quadrangleWidth(
      {cv::Point2d(0, 0), cv::Point2d(0, 20), cv::Point2d(10, 0), cv::Point2d(12, 20)});
  EXPECT_NEAR(trapezoid.d12, 220.0 / std::sqrt(404.0), 1e-12);
  EXPECT_NEAR(trapezoid.d34, 11.0, 1e-12);
  EXPECT_NEAR(trapezoid.d, (220.0 / std::sqrt(404.0) + 11.0) / 2.0, 1e-12);
}

}  // namespace
}  // namespace fieldrig::stem
