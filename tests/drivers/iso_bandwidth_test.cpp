// The bandwidth planner against numbers worked out by hand (frame = 1624 × 1224 = 1,987,776
// bytes of RAW8; 8,000 bus cycles a second).
#include "fieldrig/drivers/dc1394/iso_bandwidth.h"

#include <gtest/gtest.h>

#include <cmath>

namespace fieldrig::drivers {
namespace {

IsoRequest grasshoppers(double rate_hz) {
  IsoRequest r;  // defaults: 6 cameras, 1624×1224, RAW8, S800, unit 4
  r.rate_hz = rate_hz;
  return r;
}

TEST(IsoBandwidth, SixFullFramesAtFiveHertzFitS800) {
  const auto plan = requireIsoPlan(grasshoppers(5));
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  EXPECT_EQ(plan->frame_bytes, 1'987'776u);
  // Equal share of 8,000 bytes: 1,333, down to a multiple of 4.
  EXPECT_EQ(plan->packet_bytes, 1332u);
  EXPECT_EQ(plan->bytes_per_cycle, 7992u);
  // 1,332 × 1,492 = 1,987,344 < 1,987,776: one more packet for the last 432 bytes.
  EXPECT_EQ(plan->packets_per_frame, 1493u);
  EXPECT_NEAR(plan->max_rate_hz, 8000.0 / 1493, 1e-9);  // 5.358 Hz
  EXPECT_NEAR(plan->max_fitting_rate_hz, 5.358, 0.001);
  // 5 Hz leaves 1,600 cycles a frame: 1,987,776 / 1,600 = 1,242.36 → 1,243 → 1,244 bytes.
  EXPECT_EQ(plan->needed_packet_bytes, 1244u);
  EXPECT_EQ(plan->needed_bytes_per_cycle, 7464u);
  EXPECT_TRUE(plan->fits);
  EXPECT_TRUE(plan->message.empty());
}

TEST(IsoBandwidth, SixFullFramesAtTenHertzAreRefusedWithTheNumbers) {
  // 10 Hz leaves 800 cycles: 2,484.72 → 2,485 → 2,488 bytes a camera, 14,928 for six.
  const auto plan = planIsoBandwidth(grasshoppers(10));
  ASSERT_TRUE(plan.ok());
  EXPECT_FALSE(plan->fits);
  EXPECT_EQ(plan->needed_packet_bytes, 2488u);
  EXPECT_EQ(plan->needed_bytes_per_cycle, 14'928u);
  EXPECT_EQ(plan->message,
            "6 cameras × 1624×1224 RAW8 at 10 Hz need 14,928 bytes per 125 µs cycle; S800 "
            "allows 8,000 (5.36 Hz at most)");
  const auto refused = requireIsoPlan(grasshoppers(10));
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().message, plan->message);
}

TEST(IsoBandwidth, SevenSetsPerSecondNeedMoreThanTheS800Budget) {
  // The "near 7 sets/s": 1,142 cycles a frame → 1,740.6 → 1,744 bytes, ×6 = 10,464.
  const auto plan = planIsoBandwidth(grasshoppers(7));
  ASSERT_TRUE(plan.ok());
  EXPECT_FALSE(plan->fits);
  EXPECT_EQ(plan->needed_bytes_per_cycle, 10'464u);
  // With the whole isochronous share of an S800 cycle (80 % of 12,500 bytes = 10,000):
  // 1,666 → 1,664-byte packets, 1,195 a frame, 6.69 Hz: close to 7, still not 7.
  IsoRequest wide = grasshoppers(6.5);
  wide.bus.bytes_per_cycle = 10'000;
  const auto wide_plan = requireIsoPlan(wide);
  ASSERT_TRUE(wide_plan.ok()) << wide_plan.error().message;
  EXPECT_EQ(wide_plan->packet_bytes, 1664u);
  EXPECT_EQ(wide_plan->packets_per_frame, 1195u);
  EXPECT_NEAR(wide_plan->max_rate_hz, 6.694, 0.001);
  wide.rate_hz = 7;
  EXPECT_FALSE(requireIsoPlan(wide).ok());
}

TEST(IsoBandwidth, OneCameraAtThirtyHertz) {
  IsoRequest r = grasshoppers(30);
  r.cameras = 1;
  r.max_packet_bytes = 8192;  // the camera allows more than the bus: the bus decides
  const auto plan = requireIsoPlan(r);
  ASSERT_TRUE(plan.ok()) << plan.error().message;
  EXPECT_EQ(plan->packet_bytes, 8000u);
  EXPECT_EQ(plan->packets_per_frame, 249u);  // 248.47 → 249
  EXPECT_NEAR(plan->max_rate_hz, 8000.0 / 249, 1e-9);
  // 266 cycles a frame at 30 Hz: 7,472.84 → 7,473 → 7,476.
  EXPECT_EQ(plan->needed_packet_bytes, 7476u);
}

TEST(IsoBandwidth, S400HalvesTheRig) {
  IsoRequest r = grasshoppers(5);
  r.bus = IsoBus::s400();
  const auto plan = planIsoBandwidth(r);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->packet_bytes, 680u);        // 4,096 / 6 = 682 → 680
  EXPECT_EQ(plan->packets_per_frame, 2924u);  // 2,923.2 → 2,924
  EXPECT_NEAR(plan->max_rate_hz, 2.736, 0.001);
  EXPECT_FALSE(plan->fits);
  EXPECT_EQ(plan->message,
            "6 cameras × 1624×1224 RAW8 at 5 Hz need 7,464 bytes per 125 µs cycle; S400 allows "
            "4,096 (2.74 Hz at most)");
}

TEST(IsoBandwidth, TheCamerasMaximumPacketIsALimitToo) {
  IsoRequest r = grasshoppers(40);
  r.cameras = 1;
  r.max_packet_bytes = 4096;
  const auto plan = planIsoBandwidth(r);
  ASSERT_TRUE(plan.ok());
  EXPECT_FALSE(plan->fits);
  EXPECT_EQ(plan->packet_bytes, 4096u);
  EXPECT_EQ(plan->packets_per_frame, 486u);  // 485.3 → 486: 16.46 Hz
  // 200 cycles a frame at 40 Hz: 9,938.88 → 9,939 → 9,940.
  EXPECT_EQ(plan->message,
            "1 camera × 1624×1224 RAW8 at 40 Hz needs 9,940-byte packets per 125 µs cycle; the "
            "camera allows 4,096 (16.46 Hz at most)");
}

TEST(IsoBandwidth, PacketsAreWholeUnitsWithinTheLimits) {
  IsoRequest r = grasshoppers(5);
  r.unit_bytes = 8;
  const auto plan = requireIsoPlan(r);
  ASSERT_TRUE(plan.ok());
  EXPECT_EQ(plan->packet_bytes, 1328u);       // 1,333 → 1,328
  EXPECT_EQ(plan->packets_per_frame, 1497u);  // 1,496.8 → 1,497
  for (std::uint32_t cameras = 1; cameras <= 8; ++cameras) {
    for (std::uint32_t unit : {4u, 8u, 12u, 64u}) {
      IsoRequest sweep = grasshoppers(1);
      sweep.cameras = cameras;
      sweep.unit_bytes = unit;
      sweep.max_packet_bytes = 4096;
      const auto p = planIsoBandwidth(sweep);
      ASSERT_TRUE(p.ok());
      EXPECT_EQ(p->packet_bytes % unit, 0u);
      EXPECT_GE(p->packet_bytes, unit);
      EXPECT_LE(p->packet_bytes, 4096u);
      EXPECT_LE(p->bytes_per_cycle, 8000u);
      EXPECT_GE(std::uint64_t{p->packets_per_frame} * p->packet_bytes, p->frame_bytes);
    }
  }
}

TEST(IsoBandwidth, AShareBelowOneUnitIsRefused) {
  IsoRequest r = grasshoppers(1);
  r.cameras = 3;
  r.unit_bytes = 4096;
  const auto plan = planIsoBandwidth(r);
  ASSERT_TRUE(plan.ok());
  EXPECT_FALSE(plan->fits);
  EXPECT_NE(plan->message.find("below its packet unit of 4096 bytes"), std::string::npos)
      << plan->message;
}

TEST(IsoBandwidth, InvalidRequestsAreErrors) {
  IsoRequest r = grasshoppers(5);
  r.cameras = 0;
  EXPECT_FALSE(planIsoBandwidth(r).ok());
  r = grasshoppers(5);
  r.width = 0;
  EXPECT_FALSE(planIsoBandwidth(r).ok());
  r = grasshoppers(5);
  r.unit_bytes = 0;
  EXPECT_FALSE(planIsoBandwidth(r).ok());
  r = grasshoppers(5);
  r.unit_bytes = 8;
  r.max_packet_bytes = 4;
  EXPECT_FALSE(planIsoBandwidth(r).ok());
  for (double rate : {0.0, -1.0, std::nan("")}) {
    EXPECT_FALSE(planIsoBandwidth(grasshoppers(rate)).ok()) << rate;
  }
  r = grasshoppers(9000);  // faster than one frame per cycle
  const auto fast = planIsoBandwidth(r);
  ASSERT_TRUE(fast.ok());
  EXPECT_FALSE(fast->fits);
}

}  // namespace
}  // namespace fieldrig::drivers
