#include "fieldrig/sim/drive_simulator.h"

#include <gtest/gtest.h>

#include <GeographicLib/Geodesic.hpp>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

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

// RMC fixes of a drive, decoded.
std::vector<core::GpsFix> rmcFixes(const DriveSimulator& drive) {
  std::vector<core::GpsFix> fixes;
  gps::FixAssembler assembler;
  gps::NmeaParser parser([&](const gps::Sentence& s) {
    if (s.kind != gps::SentenceKind::kRmc)
      return;
    if (auto fix = assembler.add(s, {}))
      fixes.push_back(*fix);
  });
  parser.feed(drive.nmea());
  parser.flush();
  return fixes;
}

TEST(DriveSimulatorTest, SpeedBreathesAndTheTrackIntegratesIt) {
  DriveOptions options;
  options.position_noise_m = 0.0;
  options.speed_slow_amplitude = 0.15;
  options.speed_slow_period_s = 18;
  options.speed_fast_amplitude = 0.05;
  options.speed_fast_period_s = 5;
  options.seed = 3;
  const DriveSimulator drive(smallPlan(), options);
  const std::vector<core::GpsFix> fixes = rmcFixes(drive);
  ASSERT_GT(fixes.size(), 500u);
  double slowest = 1e9, fastest = 0;
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    ASSERT_TRUE(fixes[i].speed_mps);
    // RMC says the true speed (3 decimals of knots)...
    EXPECT_NEAR(*fixes[i].speed_mps, drive.speedAt(fixes[i].time), 1e-3);
    slowest = std::min(slowest, *fixes[i].speed_mps);
    fastest = std::max(fastest, *fixes[i].speed_mps);
    // ...and the positions move by it: on straight rows the distance between fixes is the
    // mean of the speeds at both ends times the interval, to second order.
    if (i == 0)
      continue;
    const gps::EnuPoint a =
        drive.frame().toLocal(fixes[i - 1].latitude_deg, fixes[i - 1].longitude_deg);
    const gps::EnuPoint b = drive.frame().toLocal(fixes[i].latitude_deg, fixes[i].longitude_deg);
    const double dt = core::toSeconds(fixes[i].time - fixes[i - 1].time);
    const double moved = std::hypot(b.east_m - a.east_m, b.north_m - a.north_m);
    const double expected =
        (drive.speedAt(fixes[i - 1].time) + drive.speedAt(fixes[i].time)) / 2 * dt;
    // Chords of the turns are shorter than the arcs; rows are exact to the micrometre.
    EXPECT_LE(moved, expected + 1e-4);
    EXPECT_GT(moved, expected * 0.99);
  }
  // The ~75 s drive holds four slow periods: at their troughs and peaks the speed is at least
  // 10 % (15 % slow, less at most 5 % fast) from the 2 m/s mean, and never more than 20 %.
  EXPECT_LT(slowest, 2.0 * 0.9 + 0.01);
  EXPECT_GT(fastest, 2.0 * 1.1 - 0.01);
  EXPECT_GE(slowest, 2.0 * 0.8 - 1e-3);
  EXPECT_LE(fastest, 2.0 * 1.2 + 1e-3);
  // The end is where the integrated distance reaches the drive's length.
  const TruePose last = drive.poseAt(drive.end());
  const TruePose before = drive.poseAt(drive.end() - std::chrono::milliseconds{100});
  EXPECT_GT(std::hypot(last.position.east_m - before.position.east_m,
                       last.position.north_m - before.position.north_m),
            0.1 * 2.0 * 0.79);
}

TEST(DriveSimulatorTest, CorrelatedNoiseHasTheRequestedSpreadAndMemory) {
  DriveOptions options;
  options.position_noise_m = 0.0;
  options.correlated_noise_m = 0.01;
  options.correlated_noise_tau_s = 2.0;  // short enough that a 65 s drive holds ~30 of them
  // A long drive: many correlation times.
  gps::FieldPlan plan = smallPlan();
  plan.rows = 12;
  double sum_squares = 0, lag_products = 0;
  int n = 0, pairs = 0;
  for (std::uint32_t seed = 1; seed <= 4; ++seed) {
    options.seed = seed;
    const DriveSimulator drive(plan, options);
    const std::vector<core::GpsFix> fixes = rmcFixes(drive);
    std::vector<double> east_errors;
    for (const core::GpsFix& fix : fixes) {
      const gps::EnuPoint p = drive.frame().toLocal(fix.latitude_deg, fix.longitude_deg);
      east_errors.push_back(p.east_m - drive.poseAt(fix.time).position.east_m);
    }
    for (std::size_t i = 0; i < east_errors.size(); ++i) {
      sum_squares += east_errors[i] * east_errors[i];
      ++n;
      // Lag of one correlation time (20 epochs at 10 Hz): correlation e^-1.
      if (i >= 20) {
        lag_products += east_errors[i] * east_errors[i - 20];
        ++pairs;
      }
    }
  }
  const double variance = sum_squares / n;
  EXPECT_NEAR(std::sqrt(variance), 0.01, 0.0015);
  const double correlation = lag_products / pairs / variance;
  EXPECT_NEAR(correlation, std::exp(-1.0), 0.1);
}

TEST(DriveSimulatorTest, BadOptionsAreErrorsNamingTheOption) {
  const auto expectError = [](DriveOptions options, const std::string& name) {
    const auto valid = validate(options);
    ASSERT_FALSE(valid.ok()) << name;
    EXPECT_NE(valid.error().message.find(name), std::string::npos) << valid.error().message;
    EXPECT_THROW(DriveSimulator(smallPlan(), options), std::invalid_argument) << name;
  };
  EXPECT_TRUE(validate(DriveOptions{}).ok());
  DriveOptions o;
  o.speed_slow_amplitude = 0.6;  // the speed could reach zero
  expectError(o, "speed_slow_amplitude");
  o = {};
  o.speed_fast_amplitude = -0.1;
  expectError(o, "speed_fast_amplitude");
  o = {};
  o.speed_slow_period_s = std::numeric_limits<double>::quiet_NaN();
  expectError(o, "speed_slow_period_s");
  o = {};
  o.speed_fast_period_s = 0;
  expectError(o, "speed_fast_period_s");
  o = {};
  o.correlated_noise_m = std::numeric_limits<double>::infinity();
  expectError(o, "correlated_noise_m");
  o = {};
  o.correlated_noise_tau_s = 0;
  expectError(o, "correlated_noise_tau_s");
  o = {};
  o.velocity_noise_mps = -1;
  expectError(o, "velocity_noise_mps");
  o = {};
  o.speed_mps = 0;
  expectError(o, "speed_mps");
}

}  // namespace
}  // namespace fieldrig::sim
