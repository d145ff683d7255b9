// The aravis driver against Aravis' own fakes, no mocks (STYLE.md item 2): the in-process Fake
// interface (camera "Fake_1") and arv-fake-gv-camera-0.8 speaking the real GigE Vision protocol
// over UDP on the loopback, with and without its packet-loss option. Every wait is bounded.
#include "fieldrig/drivers/aravis/aravis_camera.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstring>
#include <thread>
#include <vector>

#include "fieldrig/drivers/rig.h"
#include "support/aravis_fakes.h"
#include "support/collector.h"

namespace fieldrig::drivers {
namespace {

using namespace std::chrono_literals;
using testing_support::configureWhenUp;
using testing_support::FakeGvCamera;
using testing_support::triggerInStep;

constexpr std::uint32_t kWidth = 320;
constexpr std::uint32_t kHeight = 240;

CameraConfig cameraConfig(const std::string& id, std::uint32_t width = kWidth,
                          std::uint32_t height = kHeight) {
  CameraConfig config;
  config.id = id;
  config.format = core::PixelFormat::kMono8;  // the fake fills its test pattern in Mono8 only
  config.width = width;
  config.height = height;
  config.exposure_us = 10000;  // the fake scales its pattern by 1 + gain + log10(exposure / 10 ms)
  return config;
}

// A frame as the test keeps it: metadata plus a few pixels (not the pool buffer, so that the
// pool never runs dry however many frames the test collects).
struct Seen {
  core::FrameMetadata metadata;
  std::vector<std::uint8_t> head;  // the first row
};

Seen keepHead(const core::Frame& frame) {
  Seen seen{frame.metadata, {}};
  if (frame.buffer) {
    const auto bytes = frame.buffer.bytes();
    seen.head.assign(bytes.begin(), bytes.begin() + frame.metadata.width);
  }
  return seen;
}

// Frames from the driver's stream thread, as Seen: collector.sinkKeeping<core::Frame>(keepHead).
using Collector = testing_support::Collector<Seen>;

std::unique_ptr<Camera> createAravis() {
  auto camera = CameraRegistry::instance().create("aravis");
  EXPECT_TRUE(camera.ok()) << (camera.ok() ? "" : camera.error().message);
  return camera.ok() ? std::move(*camera) : nullptr;
}

TEST(AravisCameraTest, RegisteredByName) {
  const auto names = CameraRegistry::instance().names();
  EXPECT_NE(std::find(names.begin(), names.end(), "aravis"), names.end());
}

TEST(AravisCameraTest, InProcessFakeGivesOneFramePerTrigger) {
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  ASSERT_TRUE(camera->configure(cameraConfig("Fake_1")).ok());
  const auto pool = core::FramePool::create(8, std::size_t{kWidth} * kHeight).value();
  Collector collector;
  ASSERT_TRUE(camera->start(*pool, collector.sinkKeeping<core::Frame>(keepHead)).ok());
  constexpr int kTriggers = 10;
  const auto triggered = triggerInStep(*camera, collector, kTriggers, 1s);
  camera->stop();
  EXPECT_EQ(triggered.refused, 0);

  const auto frames = collector.items();
  ASSERT_EQ(frames.size(), std::size_t{kTriggers});
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const core::FrameMetadata& m = frames[i].metadata;
    EXPECT_EQ(m.trigger_id, i + 1);
    EXPECT_EQ(m.status, core::FrameStatus::kOk);
    EXPECT_EQ(m.width, kWidth);
    EXPECT_EQ(m.height, kHeight);
    EXPECT_EQ(m.stride, kWidth);
    EXPECT_EQ(m.format, core::PixelFormat::kMono8);
    EXPECT_GT(m.device_timestamp_ns, 0);
    if (i > 0) {
      EXPECT_GT(m.sequence, frames[i - 1].metadata.sequence);
      EXPECT_NE(frames[i].head, frames[i - 1].head) << "frame " << i << " repeats its pixels";
    }
  }
  const AravisStats stats = dynamic_cast<AravisCamera&>(*camera).stats();
  EXPECT_EQ(stats.triggers_accepted, std::uint64_t{kTriggers});
  EXPECT_EQ(stats.frames_delivered, std::uint64_t{kTriggers});
  EXPECT_EQ(stats.frames_lost, 0u);
  EXPECT_LT(triggered.slowest, 10ms) << "trigger() must only queue";
  // The in-process fake is no GigE Vision device: it has no packets to count.
  EXPECT_FALSE(camera->linkStats().has_packets);
}

TEST(AravisCameraTest, RigOfTwoInProcessFakes) {
  RigOptions options;
  options.driver = "aravis";
  for (int i = 0; i < 2; ++i) {
    CameraConfig config = cameraConfig("Fake_1", 64, 48);
    config.options["camera_index"] = std::to_string(i);
    options.cameras.push_back(config);
  }
  options.frame_timeout = 1s;
  options.max_skew = 50ms;  // two fakes free-run on their own 40 ms clocks
  auto rig = Rig::create(options, CameraRegistry::instance());
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  testing_support::Collector<core::FrameSet> collector;
  ASSERT_TRUE((*rig)->start(collector.sink()).ok());
  constexpr std::size_t kSets = 8;
  for (std::size_t i = 1; i <= kSets; ++i) {
    EXPECT_TRUE((*rig)->trigger(i));
    collector.waitFor(i, 2s);
  }
  (*rig)->stop();
  const auto sets = collector.take();
  ASSERT_EQ(sets.size(), kSets);
  for (std::size_t i = 0; i < kSets; ++i) {
    EXPECT_EQ(sets[i].trigger_id, i + 1);
    EXPECT_TRUE(sets[i].complete()) << "set " << i + 1;
    for (std::uint32_t c = 0; c < 2; ++c) {
      EXPECT_EQ(sets[i].frames[c].metadata.camera, c);
      EXPECT_EQ(sets[i].frames[c].metadata.width, 64u);
    }
  }
  EXPECT_EQ((*rig)->stats().frames_unexpected, 0u);
}

TEST(AravisCameraTest, UnknownIdIsNamed) {
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  const auto configured = camera->configure(cameraConfig("Fake_9"));
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find("'Fake_9'"), std::string::npos)
      << configured.error().message;
  const auto pool = core::FramePool::create(2, std::size_t{kWidth} * kHeight).value();
  EXPECT_FALSE(camera->start(*pool, [](core::Frame&&) {}).ok());
}

TEST(AravisCameraTest, UnsupportedPixelFormatNamesTheFeature) {
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  CameraConfig config = cameraConfig("Fake_1");
  config.options["genicam_pixel_format"] = "YUV422_8";
  const auto configured = camera->configure(config);
  ASSERT_FALSE(configured.ok());
  EXPECT_NE(configured.error().message.find("Fake_1"), std::string::npos);
  EXPECT_NE(configured.error().message.find("PixelFormat"), std::string::npos)
      << configured.error().message;
}

TEST(AravisCameraTest, ExternalTriggerRefusesSoftwareTriggers) {
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  CameraConfig config = cameraConfig("Fake_1");
  config.trigger = TriggerSource::kExternal;
  config.options["trigger_line"] = "Line7";
  const auto bad_line = camera->configure(config);
  ASSERT_FALSE(bad_line.ok());
  EXPECT_NE(bad_line.error().message.find("TriggerSource (Line7)"), std::string::npos)
      << bad_line.error().message;
  config.options.erase("trigger_line");
  ASSERT_TRUE(camera->configure(config).ok());
  const auto pool = core::FramePool::create(4, std::size_t{kWidth} * kHeight).value();
  ASSERT_TRUE(camera->start(*pool, [](core::Frame&&) {}).ok());
  EXPECT_FALSE(camera->trigger(1));
  camera->stop();
}

// True when every whole frame's camera frame id is as far from the first whole frame's as its
// trigger id is: each frame carries the id of the trigger that made it, losses included. (A
// damaged frame's id is the driver's inference.) GigE Vision block ids are 16 bits and skip 0
// when they wrap.
bool triggerIdsFollowFrameIds(const std::vector<Seen>& frames) {
  const Seen* first = nullptr;
  for (const Seen& frame : frames) {
    if (frame.metadata.status != core::FrameStatus::kOk)
      continue;
    if (first == nullptr)
      first = &frame;
    std::uint64_t expected =
        first->metadata.sequence + (frame.metadata.trigger_id - first->metadata.trigger_id);
    while (expected > 0xFFFF)
      expected -= 0xFFFF;
    if (frame.metadata.sequence != expected) {
      ADD_FAILURE() << "trigger " << frame.metadata.trigger_id << " has frame id "
                    << frame.metadata.sequence << ", expected " << expected;
      return false;
    }
  }
  return true;
}

class AravisGigETest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (std::strlen(FIELDRIG_ARV_FAKE_GV_CAMERA) == 0)
      GTEST_SKIP() << "arv-fake-gv-camera-0.8 not installed (package aravis-tools)";
  }
};

TEST_F(AravisGigETest, TwoHundredTriggeredFramesNoneLost) {
  FakeGvCamera fake;
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  const auto configured = configureWhenUp(*camera, cameraConfig(fake.address()), fake);
  ASSERT_TRUE(configured.ok()) << configured.error().message;
  const auto pool = core::FramePool::create(16, std::size_t{kWidth} * kHeight).value();
  Collector collector;
  ASSERT_TRUE(camera->start(*pool, collector.sinkKeeping<core::Frame>(keepHead)).ok());
  constexpr int kTriggers = 200;
  const auto triggered = triggerInStep(*camera, collector, kTriggers, 500ms);
  camera->stop();
  EXPECT_EQ(triggered.refused, 0);

  const auto frames = collector.items();
  const AravisStats stats = dynamic_cast<AravisCamera&>(*camera).stats();
  EXPECT_EQ(frames.size(), std::size_t{kTriggers});
  EXPECT_EQ(stats.frames_lost, 0u);
  EXPECT_EQ(stats.frames_corrupt, 0u);
  EXPECT_EQ(stats.stream_failures, 0u);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].metadata.trigger_id, i + 1);
    EXPECT_EQ(frames[i].metadata.status, core::FrameStatus::kOk);
    if (i > 0) {
      EXPECT_NE(frames[i].head, frames[i - 1].head);
    }
  }
  EXPECT_TRUE(triggerIdsFollowFrameIds(frames));
  EXPECT_LT(triggered.slowest, 10ms) << "trigger() must not wait for the network";
}

// Two triggers called back to back, as a busy host bunches evenly sent ones: the fake serves one
// trigger per 40 ms frame period, so without pacing the second would merge into the first's frame
// and every later frame would carry the trigger id before its own (measured: 1985 of 2000 sets
// missing under load before the pacing). The fake is a process of its own that a loaded VM can
// also starve past a frame period (and then it merges triggers however they were sent), so the
// test asserts what the driver did, the spacing of its commands, and prints what the fake made
// of them; the bench measures the losses.
TEST_F(AravisGigETest, BunchedTriggersEachGetTheirOwnFrame) {
  FakeGvCamera fake;
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  const auto configured = configureWhenUp(*camera, cameraConfig(fake.address()), fake);
  ASSERT_TRUE(configured.ok()) << configured.error().message;
  auto& aravis = dynamic_cast<AravisCamera&>(*camera);
  // The default pacing is one period of the camera's AcquisitionFrameRate: 25 Hz on the fake.
  EXPECT_EQ(aravis.stats().min_trigger_interval_us, 40'000);
  CameraConfig paced = cameraConfig(fake.address());
  paced.options["min_trigger_interval_us"] = "80000";
  ASSERT_TRUE(camera->configure(paced).ok());
  EXPECT_EQ(aravis.stats().min_trigger_interval_us, 80'000);
  const auto pool = core::FramePool::create(16, std::size_t{kWidth} * kHeight).value();
  Collector collector;
  ASSERT_TRUE(camera->start(*pool, collector.sinkKeeping<core::Frame>(keepHead)).ok());
  constexpr int kPairs = 20;
  for (int pair = 0; pair < kPairs; ++pair) {
    const std::size_t before = collector.size();
    EXPECT_TRUE(camera->trigger(static_cast<std::uint64_t>(2 * pair + 1)));
    EXPECT_TRUE(camera->trigger(static_cast<std::uint64_t>(2 * pair + 2)));
    collector.waitFor(before + 2, 1s);
  }
  camera->stop();

  const auto frames = collector.items();
  const AravisStats stats = aravis.stats();
  EXPECT_EQ(stats.triggers_accepted, std::uint64_t{2 * kPairs});
  EXPECT_GT(stats.triggers_paced, 0u) << "no second trigger of a pair was held back";
  EXPECT_LE(stats.triggers_paced, std::uint64_t{2 * kPairs});
  EXPECT_GE(stats.shortest_trigger_gap_us, 80'000) << "two commands inside the pacing interval";
  // Every trigger is a frame or a counted loss, and the frames keep trigger order.
  EXPECT_EQ(stats.frames_delivered + stats.frames_lost + stats.triggers_failed,
            std::uint64_t{2 * kPairs});
  EXPECT_EQ(frames.size(), stats.frames_delivered);
  for (std::size_t i = 1; i < frames.size(); ++i)
    EXPECT_GT(frames[i].metadata.trigger_id, frames[i - 1].metadata.trigger_id);
  std::printf("bunched triggers: %zu frames of %d, %llu lost, %llu paced, shortest gap %lld us\n",
              frames.size(), 2 * kPairs, static_cast<unsigned long long>(stats.frames_lost),
              static_cast<unsigned long long>(stats.triggers_paced),
              static_cast<long long>(stats.shortest_trigger_gap_us));
}

TEST_F(AravisGigETest, TriggerPacingIsConfigurable) {
  FakeGvCamera fake;
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  CameraConfig config = cameraConfig(fake.address());
  config.options["min_trigger_interval_us"] = "55000";
  const auto configured = configureWhenUp(*camera, config, fake);
  ASSERT_TRUE(configured.ok()) << configured.error().message;
  EXPECT_EQ(dynamic_cast<AravisCamera&>(*camera).stats().min_trigger_interval_us, 55'000);
  config.options["min_trigger_interval_us"] = "0";  // pacing off
  ASSERT_TRUE(camera->configure(config).ok());
  EXPECT_EQ(dynamic_cast<AravisCamera&>(*camera).stats().min_trigger_interval_us, 0);
  config.options["min_trigger_interval_us"] = "-1";
  const auto refused = camera->configure(config);
  ASSERT_FALSE(refused.ok());
  EXPECT_NE(refused.error().message.find("min_trigger_interval_us"), std::string::npos)
      << refused.error().message;
}

TEST_F(AravisGigETest, PacketLossIsCountedNeverBlocks) {
  FakeGvCamera fake("50");  // 50 packets in a thousand lost
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  CameraConfig config = cameraConfig(fake.address(), 64, 48);
  config.options["packet_resend"] = "never";  // each loss must show, not be repaired
  const auto configured = configureWhenUp(*camera, config, fake);
  ASSERT_TRUE(configured.ok()) << configured.error().message;
  const auto pool = core::FramePool::create(16, std::size_t{64} * 48).value();
  Collector collector;
  ASSERT_TRUE(camera->start(*pool, collector.sinkKeeping<core::Frame>(keepHead)).ok());
  constexpr int kTriggers = 200;
  const auto started = std::chrono::steady_clock::now();
  const auto triggered = triggerInStep(*camera, collector, kTriggers, 150ms);
  camera->stop();
  EXPECT_EQ(triggered.refused, 0);
  EXPECT_LT(std::chrono::steady_clock::now() - started, 40s);

  const auto frames = collector.items();
  const AravisStats stats = dynamic_cast<AravisCamera&>(*camera).stats();
  // Every trigger is a frame (whole or marked corrupt) or a counted loss.
  EXPECT_EQ(stats.triggers_accepted, std::uint64_t{kTriggers});
  EXPECT_EQ(stats.frames_delivered + stats.frames_lost + stats.triggers_failed,
            std::uint64_t{kTriggers});
  EXPECT_EQ(frames.size(), stats.frames_delivered);
  EXPECT_GT(stats.frames_corrupt + stats.frames_lost, 0u) << "5% packet loss went unnoticed";
  std::uint64_t corrupt = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    if (frames[i].metadata.status == core::FrameStatus::kCorrupt)
      ++corrupt;
    if (i > 0) {
      EXPECT_GT(frames[i].metadata.trigger_id, frames[i - 1].metadata.trigger_id);
    }
  }
  EXPECT_EQ(corrupt, stats.frames_corrupt);
  ASSERT_FALSE(frames.empty());
  EXPECT_TRUE(triggerIdsFollowFrameIds(frames));
  EXPECT_EQ(stats.frames_corrupt, stats.status_timeout + stats.status_missing_packets +
                                      stats.status_size_mismatch + stats.status_other);
  std::printf("packet loss 5%%: %zu frames (%llu corrupt), %llu lost, stream failures %llu\n",
              frames.size(), static_cast<unsigned long long>(stats.frames_corrupt),
              static_cast<unsigned long long>(stats.frames_lost),
              static_cast<unsigned long long>(stats.stream_failures));
}

// The generic link counters (Camera::linkStats, what `fieldrig acquire` and the daemon's status
// report) against the fake losing 1 % of its packets with Aravis' default resend: they are the
// GigE Vision stream's own counts, and reading them from another thread while the camera starts,
// runs and stops is safe (the status server does so).
TEST_F(AravisGigETest, LinkStatsCountPacketsAndAreReadableFromAnyThread) {
  FakeGvCamera fake("10");
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  const auto configured = configureWhenUp(*camera, cameraConfig(fake.address()), fake);
  ASSERT_TRUE(configured.ok()) << configured.error().message;
  EXPECT_TRUE(camera->linkStats().has_packets);
  std::atomic<bool> reading{true};
  std::atomic<std::uint64_t> reads{0};
  std::thread reader([&] {
    while (reading) {
      const CameraLinkStats link = camera->linkStats();
      EXPECT_TRUE(link.has_packets);
      reads.fetch_add(1);
    }
  });
  const auto pool = core::FramePool::create(16, std::size_t{kWidth} * kHeight).value();
  Collector collector;
  ASSERT_TRUE(camera->start(*pool, collector.sinkKeeping<core::Frame>(keepHead)).ok());
  constexpr int kTriggers = 60;
  const auto triggered = triggerInStep(*camera, collector, kTriggers, 500ms);
  camera->stop();
  reading = false;
  reader.join();
  EXPECT_EQ(triggered.refused, 0);
  EXPECT_GT(reads.load(), 0u);

  const AravisStats stats = dynamic_cast<AravisCamera&>(*camera).stats();
  const CameraLinkStats link = camera->linkStats();
  EXPECT_TRUE(link.has_packets);
  EXPECT_EQ(link.packets_resent, stats.packets_resent);
  EXPECT_EQ(link.packets_missing, stats.packets_missing);
  EXPECT_EQ(link.frames_missing_packets, stats.status_missing_packets);
  // 60 frames of ~55 packets at 1 %: about 33 packets lost, each resent or counted missing.
  EXPECT_GT(link.packets_resent + link.packets_missing, 0u);
  std::printf(
      "packet loss 1%%, resend on: %llu resent, %llu missing, %llu frames damaged, "
      "%llu lost, %zu delivered\n",
      static_cast<unsigned long long>(link.packets_resent),
      static_cast<unsigned long long>(link.packets_missing),
      static_cast<unsigned long long>(stats.frames_corrupt),
      static_cast<unsigned long long>(stats.frames_lost), collector.size());
}

// Triggers merged by the camera never shift later frames' ids. Pacing off, triggers go out in
// bursts of three back to back: the fake polls its trigger once per 40 ms, so a burst is mostly
// one exposure. Each burst waits for its frames, so every frame is exposed after its burst was
// sent and before the next one: the burst whose send time last precedes a frame's device
// timestamp (the fake stamps with the host's clock) is the truth, and the frame's trigger id must
// belong to it. Matched in order, the first merge would give every later frame an id of the
// burst before.
TEST_F(AravisGigETest, MergedTriggersNeverShiftLaterFramesIds) {
  FakeGvCamera fake;
  auto camera = createAravis();
  ASSERT_TRUE(camera);
  CameraConfig config = cameraConfig(fake.address());
  config.options["min_trigger_interval_us"] = "0";
  const auto configured = configureWhenUp(*camera, config, fake);
  ASSERT_TRUE(configured.ok()) << configured.error().message;
  auto& aravis = dynamic_cast<AravisCamera&>(*camera);
  const auto pool = core::FramePool::create(16, std::size_t{kWidth} * kHeight).value();
  Collector collector;
  ASSERT_TRUE(camera->start(*pool, collector.sinkKeeping<core::Frame>(keepHead)).ok());
  constexpr int kBursts = 15;
  constexpr int kPerBurst = 3;
  std::vector<std::int64_t> burst_sent_ns;
  for (int burst = 0; burst < kBursts; ++burst) {
    const std::size_t before = collector.size();
    burst_sent_ns.push_back(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                std::chrono::system_clock::now().time_since_epoch())
                                .count());
    for (int k = 1; k <= kPerBurst; ++k)
      EXPECT_TRUE(camera->trigger(static_cast<std::uint64_t>(burst * kPerBurst + k)));
    collector.waitFor(before + 1, 1s);
    // Room for a second exposure of the burst, if any, and a next burst far enough off that an
    // undecided trigger of this one is settled as merged even when a loaded host is slow.
    std::this_thread::sleep_for(300ms);
  }
  camera->stop();

  const auto frames = collector.items();
  const AravisStats stats = aravis.stats();
  EXPECT_EQ(stats.triggers_accepted, std::uint64_t{kBursts * kPerBurst});
  EXPECT_EQ(stats.frames_delivered + stats.frames_lost + stats.triggers_failed,
            std::uint64_t{kBursts * kPerBurst});
  EXPECT_EQ(frames.size(), stats.frames_delivered);
  EXPECT_LE(stats.triggers_merged, stats.frames_lost);
  EXPECT_GT(stats.triggers_merged, 0u) << "no burst was merged: the test provoked nothing";
  // The same count reaches the summaries and the status through the link stats.
  EXPECT_TRUE(camera->linkStats().counts_merged_triggers);
  EXPECT_EQ(camera->linkStats().triggers_merged, stats.triggers_merged);
  // Every whole frame of the fake carries the host's clock: all were matched by time.
  std::uint64_t whole = 0;
  for (const Seen& frame : frames)
    whole += frame.metadata.status == core::FrameStatus::kOk ? 1 : 0;
  EXPECT_EQ(stats.frames_matched_by_time, whole);
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const core::FrameMetadata& m = frames[i].metadata;
    if (i > 0) {
      EXPECT_GT(m.trigger_id, frames[i - 1].metadata.trigger_id);
    }
    const auto burst_of_id = static_cast<std::size_t>((m.trigger_id - 1) / kPerBurst);
    const auto next =
        std::upper_bound(burst_sent_ns.begin(), burst_sent_ns.end(), m.device_timestamp_ns);
    ASSERT_NE(next, burst_sent_ns.begin()) << "frame exposed before the first trigger";
    const auto burst_of_exposure = static_cast<std::size_t>(next - burst_sent_ns.begin() - 1);
    EXPECT_EQ(burst_of_id, burst_of_exposure)
        << "frame " << i << " (frame id " << m.sequence << ") carries trigger " << m.trigger_id
        << " of burst " << burst_of_id << " but was exposed in burst " << burst_of_exposure;
  }
  std::printf(
      "bursts of %d unpaced triggers: %zu frames of %d triggers, %llu merged, %llu lost, "
      "%llu unsolicited\n",
      kPerBurst, frames.size(), kBursts * kPerBurst,
      static_cast<unsigned long long>(stats.triggers_merged),
      static_cast<unsigned long long>(stats.frames_lost),
      static_cast<unsigned long long>(stats.frames_unsolicited));
}

}  // namespace
}  // namespace fieldrig::drivers
