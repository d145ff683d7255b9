// The rig's ordered merge without threads or clocks: frames handed in by the test in shuffled,
// incomplete, late and duplicated orders, time passed as an argument.
#include "fieldrig/drivers/frame_grouper.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

namespace fieldrig::drivers {
namespace {

using namespace std::chrono_literals;

constexpr std::uint32_t kCameras = 6;
const core::SteadyTime kStart{std::chrono::seconds{1000}};

class FrameGrouperTest : public ::testing::Test {
 protected:
  FrameGrouperOptions options() const {
    FrameGrouperOptions o;
    o.camera_count = kCameras;
    o.timeout = 500ms;
    o.max_skew = 125us;
    o.max_waiting_sets = 16;
    return o;
  }

  FrameGrouper::SetSink collect() {
    return [this](core::FrameSet&& set) { sets_.push_back(std::move(set)); };
  }

  core::TriggerEvent trigger(std::uint64_t id) const {
    core::TriggerEvent event;
    event.trigger_id = id;
    event.location_id = "plot-" + std::to_string(id);
    return event;
  }

  // A frame whose first pixel names its camera and trigger, so a test can tell where it went.
  core::Frame frame(std::uint32_t camera, std::uint64_t trigger_id,
                    std::int64_t device_timestamp_ns = 0) {
    core::Frame f;
    f.buffer = pool_->acquire();
    f.buffer.bytes()[0] = pixelFor(camera, trigger_id);
    f.metadata.camera = camera;
    f.metadata.trigger_id = trigger_id;
    f.metadata.device_timestamp_ns = device_timestamp_ns;
    return f;
  }

  static std::uint8_t pixelFor(std::uint32_t camera, std::uint64_t trigger_id) {
    return static_cast<std::uint8_t>(trigger_id * kCameras + camera);
  }

  std::unique_ptr<core::FramePool> pool_ = core::FramePool::create(256, 16).value();
  std::vector<core::FrameSet> sets_;
};

TEST_F(FrameGrouperTest, ShuffledFramesAcrossCamerasAndTriggersLeaveAsWholeSetsInTriggerOrder) {
  FrameGrouperOptions o = options();
  o.max_waiting_sets = 32;
  FrameGrouper grouper(o, collect());
  constexpr std::uint64_t kTriggers = 20;
  std::vector<core::Frame> frames;
  for (std::uint64_t id = 1; id <= kTriggers; ++id) {
    ASSERT_TRUE(grouper.addTrigger(trigger(id), kStart + id * 100ms));
    for (std::uint32_t c = 0; c < kCameras; ++c)
      frames.push_back(frame(c, id, static_cast<std::int64_t>(id) * 1'000'000'000));
  }
  std::mt19937 random(16);
  std::shuffle(frames.begin(), frames.end(), random);
  std::vector<std::uint32_t> arrived(kTriggers + 1, 0);
  for (core::Frame& f : frames) {
    const std::uint64_t id = f.metadata.trigger_id;
    ASSERT_EQ(grouper.addFrame(std::move(f)), FrameOutcome::kGrouped);
    ++arrived[id];
    // Out go exactly the triggers whose set and every older set are whole.
    std::size_t whole_prefix = 0;
    while (whole_prefix < kTriggers && arrived[whole_prefix + 1] == kCameras)
      ++whole_prefix;
    ASSERT_EQ(sets_.size(), whole_prefix);
  }
  ASSERT_EQ(sets_.size(), kTriggers);  // without any time passing: whole sets need no deadline
  for (std::size_t i = 0; i < sets_.size(); ++i) {
    const core::FrameSet& set = sets_[i];
    EXPECT_EQ(set.trigger_id, i + 1);
    EXPECT_EQ(set.trigger.location_id, "plot-" + std::to_string(i + 1));
    EXPECT_TRUE(set.complete());
    EXPECT_EQ(set.skew_ns, 0);
    for (std::uint32_t c = 0; c < kCameras; ++c) {
      EXPECT_EQ(set.frames[c].metadata.camera, c);
      EXPECT_EQ(set.frames[c].buffer.bytes()[0], pixelFor(c, i + 1)) << "set " << i << " cam " << c;
    }
  }
  EXPECT_EQ(grouper.waitingSets(), 0u);
  EXPECT_FALSE(grouper.nextDeadline());
  EXPECT_EQ(grouper.stats().sets, kTriggers);
  EXPECT_EQ(grouper.stats().incomplete_sets, 0u);
  EXPECT_EQ(grouper.stats().framesRejected(), 0u);
}

TEST_F(FrameGrouperTest, AWholeSetWaitsForTheOlderOnes) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(1), kStart));
  ASSERT_TRUE(grouper.addTrigger(trigger(2), kStart + 100ms));
  for (std::uint32_t c = 0; c < kCameras; ++c)
    grouper.addFrame(frame(c, 2));
  for (std::uint32_t c = 0; c + 1 < kCameras; ++c)
    grouper.addFrame(frame(c, 1));
  grouper.advance(kStart + 400ms);
  EXPECT_TRUE(sets_.empty());  // 2 is whole, but 1 still waits for its last camera
  grouper.addFrame(frame(kCameras - 1, 1));
  ASSERT_EQ(sets_.size(), 2u);
  EXPECT_EQ(sets_[0].trigger_id, 1u);
  EXPECT_EQ(sets_[1].trigger_id, 2u);
  EXPECT_TRUE(sets_[0].complete());
  EXPECT_TRUE(sets_[1].complete());
}

TEST_F(FrameGrouperTest, AMissingFrameLeavesAtTheDeadlineMarkedWithTheMissingCamera) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(1), kStart));
  ASSERT_TRUE(grouper.addTrigger(trigger(2), kStart + 100ms));
  for (std::uint32_t c = 0; c < kCameras; ++c) {
    if (c != 4)
      grouper.addFrame(frame(c, 1));
    grouper.addFrame(frame(c, 2));
  }
  ASSERT_EQ(grouper.nextDeadline(), kStart + 500ms);
  grouper.advance(kStart + 499ms);
  EXPECT_TRUE(sets_.empty());
  grouper.advance(kStart + 500ms);
  ASSERT_EQ(sets_.size(), 2u);  // 1 incomplete at its deadline, then 2 (whole) behind it
  EXPECT_EQ(sets_[0].trigger_id, 1u);
  EXPECT_FALSE(sets_[0].complete());
  EXPECT_EQ(sets_[0].frames[4].metadata.status, core::FrameStatus::kMissing);
  EXPECT_EQ(sets_[0].frames[4].metadata.camera, 4u);
  EXPECT_EQ(sets_[0].frames[4].metadata.trigger_id, 1u);
  EXPECT_FALSE(sets_[0].frames[4].buffer);
  for (std::uint32_t c = 0; c < kCameras; ++c) {
    if (c != 4) {
      EXPECT_EQ(sets_[0].frames[c].metadata.status, core::FrameStatus::kOk) << c;
    }
  }
  EXPECT_TRUE(sets_[1].complete());
  EXPECT_EQ(grouper.stats().incomplete_sets, 1u);
  EXPECT_EQ(grouper.stats().frames_missing, 1u);
}

TEST_F(FrameGrouperTest, ALateFrameAfterItsSetLeftIsReleasedAndCounted) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(1), kStart));
  ASSERT_TRUE(grouper.addTrigger(trigger(2), kStart + 100ms));
  for (std::uint32_t c = 0; c + 1 < kCameras; ++c)
    grouper.addFrame(frame(c, 1));
  grouper.advance(kStart + 500ms);
  ASSERT_EQ(sets_.size(), 1u);
  const std::size_t available = pool_->available();
  EXPECT_EQ(grouper.addFrame(frame(kCameras - 1, 1)), FrameOutcome::kLate);
  EXPECT_EQ(pool_->available(), available);  // its buffer went straight back
  EXPECT_EQ(sets_.size(), 1u);
  EXPECT_EQ(sets_[0].frames[kCameras - 1].metadata.status, core::FrameStatus::kMissing);
  // Trigger 2's set is not disturbed: it still waits for all six.
  EXPECT_EQ(grouper.waitingSets(), 1u);
  for (std::uint32_t c = 0; c < kCameras; ++c)
    EXPECT_EQ(grouper.addFrame(frame(c, 2)), FrameOutcome::kGrouped);
  ASSERT_EQ(sets_.size(), 2u);
  EXPECT_TRUE(sets_[1].complete());
  EXPECT_EQ(grouper.stats().frames_late, 1u);
  EXPECT_EQ(grouper.stats().framesRejected(), 1u);
}

TEST_F(FrameGrouperTest, ADuplicateIsRejectedAndTheFirstFrameKept) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(1), kStart));
  ASSERT_EQ(grouper.addFrame(frame(2, 1)), FrameOutcome::kGrouped);
  core::Frame second = frame(2, 1);
  second.buffer.bytes()[0] = 0xEE;
  const std::size_t available = pool_->available();
  EXPECT_EQ(grouper.addFrame(std::move(second)), FrameOutcome::kDuplicate);
  EXPECT_EQ(pool_->available(), available + 1);
  for (std::uint32_t c = 0; c < kCameras; ++c) {
    if (c != 2)
      grouper.addFrame(frame(c, 1));
  }
  ASSERT_EQ(sets_.size(), 1u);
  EXPECT_TRUE(sets_[0].complete());
  EXPECT_EQ(sets_[0].frames[2].buffer.bytes()[0], pixelFor(2, 1));
  EXPECT_EQ(grouper.stats().frames_duplicate, 1u);
}

TEST_F(FrameGrouperTest, FramesOfUnknownCamerasAndTriggersAreRejected) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(1), kStart));
  ASSERT_TRUE(grouper.addTrigger(trigger(3), kStart));
  EXPECT_EQ(grouper.addFrame(frame(kCameras, 1)), FrameOutcome::kUnknownCamera);
  EXPECT_FALSE(grouper.announced(9));
  EXPECT_EQ(grouper.addFrame(frame(0, 9)), FrameOutcome::kUnknownTrigger);  // not yet triggered
  EXPECT_TRUE(grouper.announced(2));
  EXPECT_EQ(grouper.addFrame(frame(0, 2)), FrameOutcome::kUnknownTrigger);  // an id skipped
  EXPECT_EQ(grouper.stats().frames_unknown_camera, 1u);
  EXPECT_EQ(grouper.stats().frames_unknown_trigger, 2u);
  EXPECT_EQ(pool_->available(), pool_->capacity());
  grouper.flush();
  ASSERT_EQ(sets_.size(), 2u);
  for (const core::FrameSet& set : sets_) {  // nothing of the rejected frames got in
    for (std::uint32_t c = 0; c < kCameras; ++c)
      EXPECT_EQ(set.frames[c].metadata.status, core::FrameStatus::kMissing);
  }
}

TEST_F(FrameGrouperTest, TriggersOutOfOrderAreRefusedAndSetsKeepTriggerOrder) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(5), kStart));
  EXPECT_FALSE(grouper.addTrigger(trigger(3), kStart + 10ms));  // older than the newest
  EXPECT_FALSE(grouper.addTrigger(trigger(5), kStart + 20ms));  // the same id again
  ASSERT_TRUE(grouper.addTrigger(trigger(7), kStart + 30ms));
  EXPECT_EQ(grouper.stats().triggers_refused, 2u);
  for (std::uint32_t c = 0; c < kCameras; ++c)
    grouper.addFrame(frame(c, 7));
  EXPECT_EQ(grouper.addFrame(frame(0, 3)), FrameOutcome::kUnknownTrigger);
  EXPECT_TRUE(sets_.empty());  // 7 is whole but waits for 5
  for (std::uint32_t c = 0; c < kCameras; ++c)
    grouper.addFrame(frame(c, 5));
  ASSERT_EQ(sets_.size(), 2u);
  EXPECT_EQ(sets_[0].trigger_id, 5u);
  EXPECT_EQ(sets_[1].trigger_id, 7u);
  EXPECT_EQ(grouper.stats().sets, 2u);
}

TEST_F(FrameGrouperTest, TooManyWaitingSetsLetTheOldestGoFirstIncomplete) {
  FrameGrouperOptions o = options();
  o.max_waiting_sets = 4;
  FrameGrouper grouper(o, collect());
  for (std::uint64_t id = 1; id <= 6; ++id)
    ASSERT_TRUE(grouper.addTrigger(trigger(id), kStart));
  ASSERT_EQ(sets_.size(), 2u);
  EXPECT_EQ(sets_[0].trigger_id, 1u);
  EXPECT_EQ(sets_[1].trigger_id, 2u);
  EXPECT_FALSE(sets_[0].complete());
  EXPECT_EQ(grouper.stats().sets_forced_out, 2u);
  EXPECT_EQ(grouper.waitingSets(), 4u);
  EXPECT_EQ(grouper.addFrame(frame(0, 1)), FrameOutcome::kLate);
  grouper.flush();
  ASSERT_EQ(sets_.size(), 6u);
  for (std::size_t i = 0; i < sets_.size(); ++i)
    EXPECT_EQ(sets_[i].trigger_id, i + 1);
  EXPECT_EQ(grouper.stats().frames_missing, 6u * kCameras);
}

TEST_F(FrameGrouperTest, SkewOfThePresentFramesIsMeasuredAndFlaggedAboveTheTolerance) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(1), kStart));
  ASSERT_TRUE(grouper.addTrigger(trigger(2), kStart));
  for (std::uint32_t c = 0; c < kCameras; ++c)  // camera 5 fires 300 µs after the others
    grouper.addFrame(frame(c, 1, 5'000'000 + (c == 5 ? 300'000 : 0)));
  for (std::uint32_t c = 1; c < kCameras; ++c)  // camera 0 missing: not in the spread
    grouper.addFrame(frame(c, 2, 9'000'000 + c * 10'000));
  grouper.advance(kStart + 1s);
  ASSERT_EQ(sets_.size(), 2u);
  EXPECT_EQ(sets_[0].skew_ns, 300'000);
  EXPECT_EQ(sets_[1].skew_ns, 40'000);
  EXPECT_EQ(grouper.stats().skew_flagged, 1u);
  EXPECT_EQ(grouper.stats().max_skew_ns, 300'000);
}

TEST_F(FrameGrouperTest, CorruptAndDroppedFramesArriveMarkedAndAreCounted) {
  FrameGrouper grouper(options(), collect());
  ASSERT_TRUE(grouper.addTrigger(trigger(1), kStart));
  for (std::uint32_t c = 0; c < kCameras; ++c) {
    core::Frame f = frame(c, 1);
    if (c == 1)
      f.metadata.status = core::FrameStatus::kCorrupt;
    if (c == 2) {
      f.buffer.reset();  // what a driver delivers when the pool ran dry
      f.metadata.status = core::FrameStatus::kDropped;
    }
    ASSERT_EQ(grouper.addFrame(std::move(f)), FrameOutcome::kGrouped);
  }
  ASSERT_EQ(sets_.size(), 1u);  // every camera answered: no deadline to wait for
  EXPECT_FALSE(sets_[0].complete());
  EXPECT_EQ(sets_[0].frames[1].metadata.status, core::FrameStatus::kCorrupt);
  EXPECT_TRUE(sets_[0].frames[1].buffer);
  EXPECT_EQ(sets_[0].frames[2].metadata.status, core::FrameStatus::kDropped);
  EXPECT_EQ(grouper.stats().frames_corrupt, 1u);
  EXPECT_EQ(grouper.stats().frames_dropped, 1u);
  EXPECT_EQ(grouper.stats().frames_missing, 0u);
  EXPECT_EQ(grouper.stats().incomplete_sets, 1u);
}

TEST_F(FrameGrouperTest, BuffersReturnWhenTheSinkCopiesTheSet) {
  std::size_t complete = 0;
  FrameGrouper grouper(options(), [&](core::FrameSet&& set) {
    const core::FrameSet copy = set;  // copies, as the acquisition's queue pushes do
    complete += copy.complete() ? 1 : 0;
  });
  for (std::uint64_t id = 1; id <= 3; ++id) {
    ASSERT_TRUE(grouper.addTrigger(trigger(id), kStart));
    for (std::uint32_t c = 0; c < kCameras; ++c)
      grouper.addFrame(frame(c, id));
  }
  EXPECT_EQ(complete, 3u);
  EXPECT_EQ(pool_->available(), pool_->capacity());
}

}  // namespace
}  // namespace fieldrig::drivers
