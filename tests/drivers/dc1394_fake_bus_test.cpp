// The dc1394 driver end to end against a fake bus (drivers/dc1394/testing): what it asks of the
// camera, trigger → frame → metadata, missed and unexpected frames, and the ISO resources given
// back on every exit path. The real-library tests are in dc1394_camera_test.cpp.
//
// This is a mock, and deliberately so: no IEEE-1394 bus or Grasshopper can run on this machine
// (or in CI), so a stand-in for libdc1394's functions is the only way to exercise the capture
// path here. On a machine with the cameras, dc1394_camera_test's hardware tests run instead of
// skipping.
#include <gtest/gtest.h>

#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "fake_dc1394_bus.h"
#include "fieldrig/drivers/dc1394/dc1394_camera.h"
#include "support/collector.h"

namespace fieldrig::drivers {
namespace {

using namespace std::chrono_literals;
using testing::fakeDc1394Bus;

constexpr std::uint64_t kGuid = 0x00b09d01006fb1a2;
constexpr std::uint32_t kWidth = 1624;
constexpr std::uint32_t kHeight = 1224;

class Dc1394FakeBus : public ::testing::Test {
 protected:
  void SetUp() override {
    testing::resetFakeDc1394Bus();
    std::lock_guard lock(fakeDc1394Bus().mutex);
    fakeDc1394Bus().guids = {0x0800461000821fa2, kGuid};
  }
  void TearDown() override {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    // Whatever the test did, the driver gave everything back.
    EXPECT_EQ(fakeDc1394Bus().contexts_open, 0);
    EXPECT_EQ(fakeDc1394Bus().cameras_open, 0);
    EXPECT_FALSE(fakeDc1394Bus().capturing);
    EXPECT_FALSE(fakeDc1394Bus().transmitting);
    EXPECT_FALSE(fakeDc1394Bus().broadcast_left_on);
  }

  static CameraConfig config() {
    CameraConfig c;
    c.id = "00b09d01006fb1a2";
    c.exposure_us = 1500;
    c.gain_db = 3;
    c.options["camera_index"] = "4";
    return c;
  }

  std::unique_ptr<core::FramePool> pool_ =
      core::FramePool::create(8, std::size_t{kWidth} * kHeight).value();
  // Frames collected on the driver thread; the test thread waits (3 s at most) for a count.
  testing_support::Collector<core::Frame> frames_{3s};
};

TEST_F(Dc1394FakeBus, ConfiguresFormat7Raw8At1394bS800WithThePlannedPacket) {
  Dc1394Camera camera;
  const auto configured = camera.configure(config());
  ASSERT_TRUE(configured.ok()) << configured.error().message;
  std::lock_guard lock(fakeDc1394Bus().mutex);
  const auto& bus = fakeDc1394Bus();
  EXPECT_TRUE(bus.operation_mode_1394b);
  EXPECT_EQ(bus.iso_speed_mbps, 800);
  EXPECT_EQ(bus.packet_bytes, 1332u);  // six cameras share S800 (iso_bandwidth_test)
  EXPECT_EQ(camera.plan().packets_per_frame, 1493u);
  EXPECT_EQ(bus.trigger_mode, 0);
  EXPECT_TRUE(bus.software_source);
  EXPECT_TRUE(bus.trigger_on);
  EXPECT_FLOAT_EQ(bus.shutter_s, 0.0015f);
  EXPECT_FLOAT_EQ(bus.gain_db, 3.0f);
  EXPECT_EQ(bus.cameras_open, 1);
}

TEST_F(Dc1394FakeBus, FirstTakesTheFirstCameraAndAnUnknownGuidIsNamed) {
  Dc1394Camera camera;
  CameraConfig c = config();
  c.id = "first";
  ASSERT_TRUE(camera.configure(c).ok());
  c.id = "0000000000000001";
  const auto missing = camera.configure(c);
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find(
                "camera GUID 0000000000000001 is not on the bus (found: 0800461000821fa2, "
                "00b09d01006fb1a2)"),
            std::string::npos)
      << missing.error().message;
}

TEST_F(Dc1394FakeBus, AnImpossiblePlanIsRefusedWithItsNumbers) {
  Dc1394Camera camera;
  CameraConfig c = config();
  c.options["rate_hz"] = "10";
  const auto configured = camera.configure(c);
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find(
                "6 cameras × 1624×1224 RAW8 at 10 Hz need 14,928 bytes per 125 µs cycle; S800 "
                "allows 8,000 (5.36 Hz at most)"),
            std::string::npos)
      << configured.error().message;
}

TEST_F(Dc1394FakeBus, AWrongColourFilterOrAnOversizedRoiIsRefused) {
  {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    fakeDc1394Bus().color_filter = 1;  // GBRG
  }
  Dc1394Camera camera;
  auto configured = camera.configure(config());  // default BayerRG8
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find("colour filter is BayerGB8"), std::string::npos);
  CameraConfig c = config();
  c.format = core::PixelFormat::kBayerGB8;
  c.width = 2048;
  configured = camera.configure(c);
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find("exceeds the sensor's 1624×1224"), std::string::npos);
}

TEST_F(Dc1394FakeBus, TriggersBecomeFramesWithTheirIdsInOrder) {
  Dc1394Camera camera;
  ASSERT_TRUE(camera.configure(config()).ok());
  ASSERT_TRUE(camera.start(*pool_, frames_.sink()).ok());
  for (std::uint64_t id = 100; id < 105; ++id) {
    ASSERT_TRUE(camera.trigger(id));
    std::this_thread::sleep_for(2ms);
  }
  ASSERT_TRUE(frames_.waitFor(5));
  camera.stop();
  const auto frames = frames_.take();
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const core::FrameMetadata& m = frames[i].metadata;
    EXPECT_EQ(m.trigger_id, 100 + i);
    EXPECT_EQ(m.sequence, i);
    EXPECT_EQ(m.camera, 4u);
    EXPECT_EQ(m.status, core::FrameStatus::kOk);
    EXPECT_EQ(m.width, kWidth);
    EXPECT_EQ(m.stride, kWidth);
    EXPECT_EQ(m.format, core::PixelFormat::kBayerRG8);
    EXPECT_GT(m.device_timestamp_ns, 0);
    ASSERT_TRUE(frames[i].buffer);
    // The fake fills frame n with n: the pixels are this frame's, copied out of the DMA ring.
    EXPECT_EQ(frames[i].buffer.bytes()[0], i);
    EXPECT_EQ(frames[i].buffer.bytes()[std::size_t{kWidth} * kHeight - 1], i);
  }
  const Dc1394Stats stats = camera.stats();
  EXPECT_EQ(stats.frames, 5u);
  EXPECT_EQ(stats.triggers_fired, 5u);
  EXPECT_EQ(stats.triggers_missed, 0u);
  std::lock_guard lock(fakeDc1394Bus().mutex);
  EXPECT_EQ(fakeDc1394Bus().software_triggers, 5);
  EXPECT_EQ(fakeDc1394Bus().broadcast_triggers, 0);
  EXPECT_EQ(fakeDc1394Bus().capture_setups, 1);
  EXPECT_EQ(fakeDc1394Bus().capture_stops, 1);
  EXPECT_GE(fakeDc1394Bus().iso_release_alls, 1);
}

TEST_F(Dc1394FakeBus, AMissedTriggerIsCountedAndLaterFramesKeepTheirIds) {
  CameraConfig c = config();
  c.options["rate_hz"] = "5";  // a frame more than ~100 ms + transfer late is given up on
  Dc1394Camera camera;
  ASSERT_TRUE(camera.configure(c).ok());
  ASSERT_TRUE(camera.start(*pool_, frames_.sink()).ok());
  {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    fakeDc1394Bus().triggers_to_ignore = 1;
  }
  ASSERT_TRUE(camera.trigger(1));  // exposes nothing
  // The next trigger comes a whole frame period + latency later, as a 5 Hz plan allows.
  std::this_thread::sleep_for(std::chrono::microseconds{camera.plan().packets_per_frame * 125} +
                              std::chrono::milliseconds{110});
  ASSERT_TRUE(camera.trigger(2));
  ASSERT_TRUE(frames_.waitFor(1));
  camera.stop();
  const auto frames = frames_.take();
  ASSERT_EQ(frames.size(), 1u);
  EXPECT_EQ(frames[0].metadata.trigger_id, 2u);
  EXPECT_EQ(camera.stats().triggers_missed, 1u);
}

TEST_F(Dc1394FakeBus, UnexpectedCorruptAndPoolExhaustedFramesAreMarkedAndCounted) {
  const auto one_buffer = core::FramePool::create(1, std::size_t{kWidth} * kHeight).value();
  Dc1394Camera camera;
  ASSERT_TRUE(camera.configure(config()).ok());
  ASSERT_TRUE(camera.start(*one_buffer, frames_.sink()).ok());
  testing::fakeDc1394SpuriousFrame();  // no trigger: not delivered
  std::this_thread::sleep_for(100ms);
  EXPECT_EQ(camera.stats().unexpected, 1u);
  EXPECT_EQ(frames_.size(), 0u);
  {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    fakeDc1394Bus().corrupt_next = true;
  }
  ASSERT_TRUE(camera.trigger(1));
  ASSERT_TRUE(frames_.waitFor(1));
  ASSERT_TRUE(camera.trigger(2));  // the only pool buffer is still held by frame 1
  ASSERT_TRUE(frames_.waitFor(2));
  camera.stop();
  const auto frames = frames_.take();
  EXPECT_EQ(frames[0].metadata.status, core::FrameStatus::kCorrupt);
  EXPECT_EQ(frames[1].metadata.status, core::FrameStatus::kDropped);
  EXPECT_FALSE(frames[1].buffer);
  EXPECT_EQ(camera.stats().corrupt, 1u);
  EXPECT_EQ(camera.stats().pool_exhausted, 1u);
}

TEST_F(Dc1394FakeBus, ExternalTriggerAnnouncesIdsForThePulses) {
  CameraConfig c = config();
  c.trigger = TriggerSource::kExternal;
  Dc1394Camera camera;
  ASSERT_TRUE(camera.configure(c).ok());
  ASSERT_TRUE(camera.start(*pool_, frames_.sink()).ok());
  ASSERT_TRUE(camera.trigger(7));
  std::this_thread::sleep_for(20ms);
  testing::fakeDc1394Pulse();
  ASSERT_TRUE(frames_.waitFor(1));
  camera.stop();
  EXPECT_EQ(frames_.take()[0].metadata.trigger_id, 7u);
  std::lock_guard lock(fakeDc1394Bus().mutex);
  EXPECT_FALSE(fakeDc1394Bus().software_source);
  EXPECT_EQ(fakeDc1394Bus().software_triggers, 0);
}

TEST_F(Dc1394FakeBus, BroadcastSenderTriggersTheBusAndReceiversOnlyListen) {
  CameraConfig c = config();
  c.options["trigger_broadcast"] = "send";
  {
    Dc1394Camera sender;
    ASSERT_TRUE(sender.configure(c).ok());
    ASSERT_TRUE(sender.start(*pool_, frames_.sink()).ok());
    ASSERT_TRUE(sender.trigger(1));
    ASSERT_TRUE(frames_.waitFor(1));
  }  // destroyed while running: the destructor stops and releases
  {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    EXPECT_EQ(fakeDc1394Bus().broadcast_triggers, 1);
  }
  c.options["trigger_broadcast"] = "receive";
  Dc1394Camera receiver;
  ASSERT_TRUE(receiver.configure(c).ok());
  ASSERT_TRUE(receiver.start(*pool_, frames_.sink()).ok());
  ASSERT_TRUE(receiver.trigger(2));
  std::this_thread::sleep_for(50ms);
  receiver.stop();
  std::lock_guard lock(fakeDc1394Bus().mutex);
  EXPECT_EQ(fakeDc1394Bus().software_triggers, 1);  // the receiver wrote nothing
}

TEST_F(Dc1394FakeBus, BroadcastUnsupportedIsAConfigurationError) {
  {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    fakeDc1394Bus().broadcast_supported = false;
  }
  CameraConfig c = config();
  c.options["trigger_broadcast"] = "send";
  Dc1394Camera camera;
  const auto configured = camera.configure(c);
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find("use trigger_broadcast=off"), std::string::npos);
}

TEST_F(Dc1394FakeBus, IsoResourcesAreReleasedWhenCaptureSetupFails) {
  {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    fakeDc1394Bus().fail_capture_setup = true;
  }
  Dc1394Camera camera;
  ASSERT_TRUE(camera.configure(config()).ok());
  const auto started = camera.start(*pool_, frames_.sink());
  ASSERT_FALSE(started.ok());
  EXPECT_NE(started.error().message.find("capture setup"), std::string::npos);
  EXPECT_FALSE(camera.trigger(1));
  std::lock_guard lock(fakeDc1394Bus().mutex);
  EXPECT_EQ(fakeDc1394Bus().iso_release_alls, 1);
  EXPECT_EQ(fakeDc1394Bus().capture_stops, 0);  // nothing was set up to stop
}

TEST_F(Dc1394FakeBus, IsoResourcesAreReleasedWhenTransmissionFails) {
  {
    std::lock_guard lock(fakeDc1394Bus().mutex);
    fakeDc1394Bus().fail_transmission = true;
  }
  Dc1394Camera camera;
  ASSERT_TRUE(camera.configure(config()).ok());
  ASSERT_FALSE(camera.start(*pool_, frames_.sink()).ok());
  std::lock_guard lock(fakeDc1394Bus().mutex);
  EXPECT_EQ(fakeDc1394Bus().capture_stops, 1);
  EXPECT_EQ(fakeDc1394Bus().iso_release_alls, 1);
  EXPECT_FALSE(fakeDc1394Bus().capturing);
}

TEST_F(Dc1394FakeBus, RestartAfterStopSetsUpAgain) {
  Dc1394Camera camera;
  ASSERT_TRUE(camera.configure(config()).ok());
  for (int round = 0; round < 3; ++round) {
    ASSERT_TRUE(camera.start(*pool_, frames_.sink()).ok());
    ASSERT_TRUE(camera.trigger(static_cast<std::uint64_t>(round)));
    ASSERT_TRUE(frames_.waitFor(static_cast<std::size_t>(round) + 1));
    camera.stop();
  }
  std::lock_guard lock(fakeDc1394Bus().mutex);
  EXPECT_EQ(fakeDc1394Bus().capture_setups, 3);
  EXPECT_EQ(fakeDc1394Bus().capture_stops, 3);
}

}  // namespace
}  // namespace fieldrig::drivers
