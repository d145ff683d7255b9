// The Rig with six sim cameras: one FrameSet per trigger, in order, whole or marked incomplete
// after the timeout, skew measured and flagged, buffers returned to the pool.
#include "fieldrig/drivers/rig.h"

#include <gtest/gtest.h>

#include <limits>
#include <mutex>
#include <thread>

#include "fieldrig/sim/test_pattern_source.h"
#include "support/collector.h"
#include "support/sim_cameras.h"

namespace fieldrig::drivers {
namespace {

using namespace std::chrono_literals;

RigOptions sixCameras(std::uint32_t width = 64, std::uint32_t height = 48) {
  return testing_support::sixSimCameras(width, height);
}

using Collector = testing_support::Collector<core::FrameSet>;

// Rig tests: most run a rig of sim cameras through a number of triggers and look at the sets.
class RigTest : public ::testing::Test {
 protected:
  // Stopped first, into the live collector (a failed run may leave it running); the sets kept
  // below then give their buffers back before the rig's pool goes.
  ~RigTest() override {
    if (rig_)
      rig_->stop();
  }

  enum class WaitForEachSet { kNo, kYes };
  // Starts a rig of `options` with the collector as its sink, triggers 1 … `triggers` (`pause`
  // after each, and when asked the trigger's set), waits for their sets, stops the rig and keeps
  // the sets in sets_. Its fatal failures end only this call: call it through
  // ASSERT_NO_FATAL_FAILURE.
  void run(const RigOptions& options, std::uint64_t triggers,
           std::chrono::milliseconds pause = std::chrono::milliseconds{0},
           WaitForEachSet wait_for_each_set = WaitForEachSet::kNo) {
    auto rig = Rig::create(options, testing_support::camerasWithSim());
    ASSERT_TRUE(rig.ok()) << rig.error().message;
    rig_ = std::move(*rig);
    ASSERT_TRUE(rig_->start(collector_.sink()).ok());
    for (std::uint64_t id = 1; id <= triggers; ++id) {
      ASSERT_TRUE(rig_->trigger(id));
      if (pause.count() > 0)
        std::this_thread::sleep_for(pause);
      if (wait_for_each_set == WaitForEachSet::kYes) {
        ASSERT_TRUE(collector_.waitFor(id));
      }
    }
    ASSERT_TRUE(collector_.waitFor(triggers));
    rig_->stop();
    sets_ = collector_.take();
  }

  std::unique_ptr<Rig> rig_;
  Collector collector_;  // keeps every set (and its buffers) until the test lets go
  std::vector<core::FrameSet> sets_;
};

bool patternMatches(const core::Frame& frame) {
  const auto& m = frame.metadata;
  const std::uint8_t* pixels = frame.buffer.bytes().data();
  for (std::uint32_t y = 0; y < m.height; y += 7) {
    for (std::uint32_t x = 0; x < m.width; x += 5) {
      if (pixels[y * m.stride + x] !=
          sim::TestPatternSource::patternAt(m.camera, m.trigger_id, x, y)) {
        return false;
      }
    }
  }
  return true;
}

TEST_F(RigTest, OneWholeSetPerTriggerInOrder) {
  RigOptions options = sixCameras();
  options.pool_sets = 64;  // the collector keeps every set (and its buffers) to the end
  ASSERT_NO_FATAL_FAILURE(run(options, 50, 1ms));
  const auto& sets = sets_;
  ASSERT_EQ(sets.size(), 50u);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    EXPECT_EQ(sets[i].trigger_id, i + 1);
    for (std::uint32_t c = 0; c < 6; ++c) {
      ASSERT_EQ(sets[i].frames[c].metadata.status, core::FrameStatus::kOk)
          << "set " << i << " camera " << c;
      EXPECT_EQ(sets[i].frames[c].metadata.camera, c);
      EXPECT_EQ(sets[i].frames[c].metadata.trigger_id, i + 1);
      EXPECT_TRUE(patternMatches(sets[i].frames[c])) << "set " << i << " camera " << c;
    }
  }
  for (const auto& set : sets)
    EXPECT_EQ(set.skew_ns, 0);  // one trigger instant for all six
  const RigStats stats = rig_->stats();
  EXPECT_EQ(stats.sets, 50u);
  EXPECT_EQ(stats.incomplete_sets, 0u);
  EXPECT_EQ(stats.frames_dropped, 0u);
}

TEST_F(RigTest, MissingFrameYieldsAnIncompleteSetAfterTheTimeoutWithoutReordering) {
  RigOptions options = sixCameras();
  options.cameras[3].options["drop_every"] = "5";
  ASSERT_NO_FATAL_FAILURE(run(options, 12));
  const auto& sets = sets_;
  ASSERT_EQ(sets.size(), 12u);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    const std::uint64_t id = i + 1;
    EXPECT_EQ(sets[i].trigger_id, id);  // 5 and 10 waited for their timeout; 6-9 waited for 5
    EXPECT_EQ(sets[i].complete(), id % 5 != 0);
    if (id % 5 == 0) {
      EXPECT_EQ(sets[i].frames[3].metadata.status, core::FrameStatus::kMissing);
      EXPECT_FALSE(sets[i].frames[3].buffer);
      EXPECT_EQ(sets[i].frames[2].metadata.status, core::FrameStatus::kOk);
    }
  }
  EXPECT_EQ(rig_->stats().frames_missing, 2u);
  EXPECT_EQ(rig_->stats().incomplete_sets, 2u);
}

TEST_F(RigTest, SkewAboveTheToleranceIsFlagged) {
  RigOptions options = sixCameras();
  options.cameras[5].options["clock_offset_us"] = "300";
  ASSERT_NO_FATAL_FAILURE(run(options, 3));
  // The rig's trigger is one instant for all sim cameras (a bus broadcast): the skew is exactly
  // the injected 300 µs clock offset.
  for (const auto& set : sets_)
    EXPECT_EQ(set.skew_ns, 300'000);
  EXPECT_EQ(rig_->stats().skew_flagged, 3u);
  EXPECT_EQ(rig_->stats().max_skew_ns, 300'000);
}

TEST_F(RigTest, CorruptFramesAreDeliveredMarked) {
  RigOptions options = sixCameras();
  options.cameras[0].options["corrupt_every"] = "2";
  ASSERT_NO_FATAL_FAILURE(run(options, 4));
  const auto& sets = sets_;
  EXPECT_EQ(sets[1].frames[0].metadata.status, core::FrameStatus::kCorrupt);
  EXPECT_TRUE(sets[1].frames[0].buffer);  // the pixels are kept for inspection
  EXPECT_FALSE(sets[1].complete());
  EXPECT_TRUE(sets[2].complete());
  EXPECT_EQ(rig_->stats().frames_corrupt, 2u);
}

TEST_F(RigTest, BuffersReturnToThePoolWhenConsumersLetGo) {
  RigOptions options = sixCameras();
  // Every frame must arrive for the count below: a sim worker starved for 100 ms on a loaded
  // 2-core machine (the test suite runs in parallel) would time its frame out as missing.
  options.frame_timeout = 2s;
  ASSERT_NO_FATAL_FAILURE(run(options, 5));
  EXPECT_EQ(rig_->pool().available(), rig_->pool().capacity() - 30);
  sets_.clear();
  EXPECT_EQ(rig_->pool().available(), rig_->pool().capacity());
}

TEST_F(RigTest, BuffersReturnEvenWhenTheSinkCopiesTheSet) {
  RigOptions options = sixCameras();
  options.pool_sets = 4;  // fewer buffers than triggers: they must come back to be reused
  auto rig = Rig::create(options, testing_support::camerasWithSim());
  ASSERT_TRUE(rig.ok());
  std::atomic<int> complete{0};
  ASSERT_TRUE((*rig)
                  ->start([&](core::FrameSet&& set) {
                    const core::FrameSet copy = set;  // copies, as queue pushes do
                    if (copy.complete())
                      ++complete;
                  })
                  .ok());
  // Paced by the sets that came back, not by the clock: at most three sets are out at once, so
  // every trigger finds a buffer however slowly a loaded machine runs the rig's threads, and the
  // test asserts reuse (40 sets through 4 buffers) rather than timing.
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  for (std::uint64_t id = 1; id <= 40; ++id) {
    while (std::chrono::steady_clock::now() < deadline && (*rig)->stats().sets + 3 < id)
      std::this_thread::sleep_for(1ms);
    ASSERT_TRUE((*rig)->trigger(id));
  }
  while (std::chrono::steady_clock::now() < deadline && (*rig)->stats().sets < 40)
    std::this_thread::sleep_for(1ms);
  (*rig)->stop();
  EXPECT_EQ(complete.load(), 40);
  EXPECT_EQ((*rig)->stats().frames_dropped, 0u);
  EXPECT_EQ((*rig)->pool().available(), (*rig)->pool().capacity());
}

TEST_F(RigTest, ExhaustedPoolShowsAsDroppedFrames) {
  RigOptions options = sixCameras();
  options.pool_sets = 2;  // 12 buffers; the collector keeps every set: nothing returns to the pool
  // Each trigger waits for the set before it, so the first two triggers take all 12 buffers
  // whatever the scheduling of the six camera threads (with a fixed pause, a late camera thread
  // lets a later trigger's frame take its buffer). Dropped frames are reported at once; the long
  // timeout only keeps a loaded machine from cutting the two whole sets short.
  options.frame_timeout = 2s;
  ASSERT_NO_FATAL_FAILURE(run(options, 4, std::chrono::milliseconds{0}, WaitForEachSet::kYes));
  const auto& sets = sets_;
  EXPECT_TRUE(sets[0].complete());
  EXPECT_TRUE(sets[1].complete());
  for (std::size_t i = 2; i < 4; ++i) {
    for (std::uint32_t c = 0; c < 6; ++c)
      EXPECT_EQ(sets[i].frames[c].metadata.status, core::FrameStatus::kDropped);
  }
  EXPECT_EQ(rig_->stats().frames_dropped, 12u);
  EXPECT_EQ(rig_->stats().incomplete_sets, 2u);
}

TEST_F(RigTest, ConfigurationErrorsNameTheCameraAndDriver) {
  RigOptions options = sixCameras();
  options.cameras[4].id = "left";
  auto rig = Rig::create(options, testing_support::camerasWithSim());
  ASSERT_FALSE(rig.ok());
  EXPECT_NE(rig.error().message.find("rig camera 4"), std::string::npos) << rig.error().message;
  options = sixCameras();
  options.driver = "gige";
  rig = Rig::create(options, testing_support::camerasWithSim());
  ASSERT_FALSE(rig.ok());
  EXPECT_NE(rig.error().message.find("unknown camera driver 'gige'"), std::string::npos);
  EXPECT_NE(rig.error().message.find("sim"), std::string::npos);
}

TEST_F(RigTest, PoolErrorsAreRefusedNotThrown) {
  RigOptions options = sixCameras();
  options.pool_sets = 0;
  auto rig = Rig::create(options, testing_support::camerasWithSim());
  ASSERT_FALSE(rig.ok());
  EXPECT_EQ(rig.error().message, "rig: frame pool: the buffer count must be positive");
  options.pool_sets = std::numeric_limits<std::size_t>::max();  // the product would wrap
  rig = Rig::create(options, testing_support::camerasWithSim());
  ASSERT_FALSE(rig.ok());
  EXPECT_NE(rig.error().message.find("cameras exceed the 65534 buffers a pool can hold"),
            std::string::npos)
      << rig.error().message;
}

// fieldrigd --check-config runs checkOptions alone: a pool this machine's memory cannot hold is
// refused there, without allocating, as it is by create().
TEST_F(RigTest, APoolLargerThanTheMachinesMemoryIsRefusedByTheCheckAlone) {
  RigOptions options = sixCameras();
  for (CameraConfig& camera : options.cameras) {
    camera.width = 16384;  // 256 MiB frames: 10,000 sets of six need 15 TiB
    camera.height = 16384;
  }
  options.pool_sets = 10000;
  const auto checked = Rig::checkOptions(options, testing_support::camerasWithSim());
  ASSERT_FALSE(checked.ok());
  EXPECT_NE(checked.error().message.find("need more than this machine's"), std::string::npos)
      << checked.error().message;
  options.pool_sets = 2;
  for (CameraConfig& camera : options.cameras)
    camera.width = camera.height = 64;
  EXPECT_TRUE(Rig::checkOptions(options, testing_support::camerasWithSim()).ok());
  options.driver = "gige";
  const auto unknown = Rig::checkOptions(options, testing_support::camerasWithSim());
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().message.find("unknown camera driver 'gige'"), std::string::npos);
}

}  // namespace
}  // namespace fieldrig::drivers

namespace fieldrig::drivers {
namespace {

TEST_F(RigTest, TooManyWaitingSetsLeaveOldestFirstIncomplete) {
  RigOptions options = sixCameras(16, 8);
  options.cameras[1].options["drop_every"] = "1";    // camera 1 never delivers
  options.frame_timeout = std::chrono::seconds{30};  // so only the ring's size lets sets go
  options.pool_sets = 300;
  auto rig = Rig::create(options, testing_support::camerasWithSim());
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  std::vector<std::uint64_t> order;
  std::mutex mutex;
  ASSERT_TRUE((*rig)
                  ->start([&](core::FrameSet&& set) {
                    std::lock_guard lock(mutex);
                    order.push_back(set.trigger_id);
                    EXPECT_EQ(set.frames[1].metadata.status, core::FrameStatus::kMissing);
                  })
                  .ok());
  for (std::uint64_t id = 1; id <= 300; ++id) {
    ASSERT_TRUE((*rig)->trigger(id));
    if (id % 50 == 0)
      std::this_thread::sleep_for(20ms);  // let the rig thread keep up with the trigger queue
  }
  const auto deadline = std::chrono::steady_clock::now() + 5s;
  while (std::chrono::steady_clock::now() < deadline && (*rig)->stats().sets_forced_out < 44)
    std::this_thread::sleep_for(1ms);
  EXPECT_EQ((*rig)->stats().sets_forced_out, 44u);  // 300 waiting sets, room for 256
  (*rig)->stop();                                   // the remaining 256 leave, incomplete, in order
  std::lock_guard lock(mutex);
  ASSERT_EQ(order.size(), 300u);
  for (std::size_t i = 0; i < order.size(); ++i)
    EXPECT_EQ(order[i], i + 1);
}

}  // namespace
}  // namespace fieldrig::drivers

namespace fieldrig::drivers {
namespace {

TEST_F(RigTest, FramesArrivingShuffledAcrossTriggersAreGroupedRight) {
  RigOptions options = sixCameras();
  // Each camera answers with its own delay: camera 3's frame of trigger 1 arrives after camera
  // 0's frames of triggers 2-6.
  const int delays_ms[] = {0, 15, 5, 25, 10, 20};
  for (int c = 0; c < 6; ++c)
    options.cameras[c].options["delay_ms"] = std::to_string(delays_ms[c]);
  options.pool_sets = 64;
  ASSERT_NO_FATAL_FAILURE(run(options, 30, 5ms));
  const auto& sets = sets_;
  ASSERT_EQ(sets.size(), 30u);
  for (std::size_t i = 0; i < sets.size(); ++i) {
    EXPECT_EQ(sets[i].trigger_id, i + 1);
    EXPECT_TRUE(sets[i].complete());
    for (std::uint32_t c = 0; c < 6; ++c)
      EXPECT_TRUE(patternMatches(sets[i].frames[c])) << "set " << i << " camera " << c;
  }
  EXPECT_EQ(rig_->stats().frames_unexpected, 0u);
}

}  // namespace
}  // namespace fieldrig::drivers
