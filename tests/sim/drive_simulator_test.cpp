#include "fieldrig/sim/drive_simulator.h"

#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>
#include <cmath>
#include <sstream>

#include "fieldrig/gps/fix_assembler.h"
#include "fieldrig/gps/nmea_parser.h"
#include "support/field_plans.h"

namespace fieldrig::sim {
namespace {

// Three rows of 40 m due north, 8 plots each.
gps::FieldPlan smallPlan() {
  gps::FieldPlan plan =
      testing_support::fieldPlan({42.0, -93.6}, {42.0 + 40.0 / 111'034.6, -93.6}, 3);
  plan.plots_per_row = 8;
  return plan;
}

TEST(DriveSimulatorTest, NmeaDecodesToTheTrueTrackWithinTheNoise) {
  DriveOptions options;
  options.position_noise_m = 0.0;
  const DriveSimulator drive(smallPlan(), options);
  std::vector<core::GpsFix> fixes;
  gps::FixAssembler assembler;
  gps::NmeaParser parser([&](const gps::Sentence& s) {
    EXPECT_NE(s.kind, gps::SentenceKind::kRejected) << s.text;
    if (s.kind != gps::SentenceKind::kRmc)
      return;
    if (auto fix = assembler.add(s, {}))
      fixes.push_back(*fix);
  });
  parser.feed(drive.nmea());
  parser.flush();
  // 3 rows + 2 × 4 m headland each, 2 half turns of π·1.143 m, at 2 m/s and 10 Hz.
  double row = 0;
  const gps::FieldPlan plan = smallPlan();
  GeographicLib::Geodesic::WGS84().Inverse(plan.row_start_latitude_deg,
                                           plan.row_start_longitude_deg, plan.row_end_latitude_deg,
                                           plan.row_end_longitude_deg, row);
  const double length = 3 * (row + 8.0) + 2 * M_PI * 1.143;
  EXPECT_NEAR(drive.lengthM(), length, 0.001);
  EXPECT_EQ(fixes.size(), static_cast<std::size_t>(std::floor(length / 2.0 * 10)) + 1);
  double worst = 0;
  for (const core::GpsFix& fix : fixes) {
    ASSERT_TRUE(fix.valid);
    ASSERT_TRUE(fix.speed_mps);
    EXPECT_NEAR(*fix.speed_mps, 2.0, 1e-3);
    const TruePose pose = drive.poseAt(fix.time);
    const gps::EnuPoint p = drive.frame().toLocal(fix.latitude_deg, fix.longitude_deg);
    worst = std::max(
        worst, std::hypot(p.east_m - pose.position.east_m, p.north_m - pose.position.north_m));
  }
  EXPECT_LT(worst, 1e-4);  // 8 decimals of minutes: 0.02 mm
}

TEST(DriveSimulatorTest, SerpentineRowsAreDrivenInAlternateDirections) {
  const DriveSimulator drive(smallPlan(), DriveOptions{});
  // Mid-row 0 (driven north) and mid-row 1 (driven south, 2.286 m east).
  const double row_time = 48.0 / 2.0;
  const TruePose first = drive.poseAt(drive.start() + core::fromSeconds(row_time / 2));
  EXPECT_NEAR(first.unit_north, 1.0, 1e-9);
  EXPECT_NEAR(first.position.east_m, 0.0, 1e-6);
  const double turn_time = M_PI * 1.143 / 2.0;
  const TruePose second =
      drive.poseAt(drive.start() + core::fromSeconds(row_time + turn_time + row_time / 2));
  EXPECT_NEAR(second.unit_north, -1.0, 1e-9);
  EXPECT_NEAR(second.position.east_m, 2.286, 1e-3);
}

TEST(DriveSimulatorTest, NoiseHasTheRequestedSpread) {
  DriveOptions options;
  options.position_noise_m = 0.01;
  options.seed = 7;
  const DriveSimulator drive(smallPlan(), options);
  gps::FixAssembler assembler;
  double sum_squares = 0;
  int n = 0;
  gps::NmeaParser parser([&](const gps::Sentence& s) {
    if (s.kind != gps::SentenceKind::kRmc)
      return;
    const auto fix = assembler.add(s, {});
    const TruePose pose = drive.poseAt(fix->time);
    const gps::EnuPoint p = drive.frame().toLocal(fix->latitude_deg, fix->longitude_deg);
    sum_squares += std::pow(p.east_m - pose.position.east_m, 2) +
                   std::pow(p.north_m - pose.position.north_m, 2);
    ++n;
  });
  parser.feed(drive.nmea());
  const double per_axis_sd = std::sqrt(sum_squares / (2.0 * n));
  EXPECT_NEAR(per_axis_sd, 0.01, 0.001);
}

}  // namespace
}  // namespace fieldrig::sim
