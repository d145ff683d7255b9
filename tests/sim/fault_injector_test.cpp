// Fault injection around a real frame source (the test pattern): dropped triggers never reach the
// source, corrupt frames keep their pixels, a dropped frame stays dropped, delays hold the frame
// until trigger + delay, clock offsets shift the device timestamp exactly, and no faults leave
// the source's frame as it is.
#include "fieldrig/sim/fault_injector.h"

#include <gtest/gtest.h>

#include <optional>
#include <thread>
#include <vector>

#include "fieldrig/sim/test_pattern_source.h"

namespace fieldrig::sim {
namespace {

using namespace std::chrono_literals;

constexpr std::uint32_t kFaultFrameWidth = 16;
constexpr std::uint32_t kFaultFrameHeight = 4;

FaultInjector patternWith(const FaultOptions& faults) {
  return FaultInjector(std::make_unique<TestPatternSource>(kFaultFrameWidth), faults);
}

SimTrigger faultTrigger(std::uint64_t id, core::SteadyTime issued = core::SteadyTime{1s}) {
  return {id, id - 1, issued};
}

core::Frame frameFor(const SimTrigger& trigger) {
  return stampedFrame(trigger, 2, kFaultFrameWidth, kFaultFrameHeight, core::PixelFormat::kMono8);
}

// The frame of one trigger through the pattern with `faults`, its buffer from `pool`; nullopt
// when nothing is delivered.
std::optional<core::Frame> fillOne(const FaultOptions& faults, const SimTrigger& trigger,
                                   core::FramePool& pool) {
  FaultInjector source = patternWith(faults);
  core::Frame frame = frameFor(trigger);
  if (!source.fill(trigger, pool, frame))
    return std::nullopt;
  return frame;
}

bool isPattern(const core::Frame& frame) {
  const std::uint8_t* pixels = frame.buffer.bytes().data();
  for (std::uint32_t y = 0; y < kFaultFrameHeight; ++y) {
    for (std::uint32_t x = 0; x < kFaultFrameWidth; ++x) {
      if (pixels[y * kFaultFrameWidth + x] !=
          TestPatternSource::patternAt(frame.metadata.camera, frame.metadata.trigger_id, x, y))
        return false;
    }
  }
  return true;
}

TEST(FaultInjectorTest, WithoutFaultsTheSourcesFrameComesThroughAsItIs) {
  const auto pool =
      core::FramePool::create(1, std::size_t{kFaultFrameWidth} * kFaultFrameHeight).value();
  const auto frame = fillOne({}, faultTrigger(6), *pool);
  ASSERT_TRUE(frame && frame->buffer);
  EXPECT_EQ(frame->metadata.status, core::FrameStatus::kOk);
  EXPECT_EQ(frame->metadata.device_timestamp_ns, 1'000'000'000);
  EXPECT_TRUE(isPattern(*frame));
}

TEST(FaultInjectorTest, DropEveryNDeliversNothingForIdsDivisibleByNAndTakesNoBuffer) {
  FaultOptions faults;
  faults.drop_every = 3;
  FaultInjector source = patternWith(faults);
  const auto pool =
      core::FramePool::create(8, std::size_t{kFaultFrameWidth} * kFaultFrameHeight).value();
  std::vector<core::Frame> delivered;
  for (std::uint64_t id = 1; id <= 7; ++id) {
    core::Frame frame = frameFor(faultTrigger(id));
    const bool filled = source.fill(faultTrigger(id), *pool, frame);
    EXPECT_EQ(filled, id % 3 != 0) << "trigger " << id;
    if (filled)
      delivered.push_back(std::move(frame));
  }
  ASSERT_EQ(delivered.size(), 5u);   // 1, 2, 4, 5, 7
  EXPECT_EQ(pool->available(), 3u);  // the dropped triggers never took a buffer
  for (const core::Frame& frame : delivered)
    EXPECT_TRUE(isPattern(frame)) << "trigger " << frame.metadata.trigger_id;
}

TEST(FaultInjectorTest, CorruptEveryNMarksThoseFramesAndKeepsTheirPixels) {
  FaultOptions faults;
  faults.corrupt_every = 2;
  FaultInjector source = patternWith(faults);
  const auto pool =
      core::FramePool::create(4, std::size_t{kFaultFrameWidth} * kFaultFrameHeight).value();
  for (std::uint64_t id = 1; id <= 4; ++id) {
    core::Frame frame = frameFor(faultTrigger(id));
    ASSERT_TRUE(source.fill(faultTrigger(id), *pool, frame));
    ASSERT_TRUE(frame.buffer);
    EXPECT_EQ(frame.metadata.status,
              id % 2 == 0 ? core::FrameStatus::kCorrupt : core::FrameStatus::kOk)
        << "trigger " << id;
    EXPECT_TRUE(isPattern(frame)) << "trigger " << id;  // kept for inspection
  }
}

TEST(FaultInjectorTest, AFrameDroppedForWantOfABufferStaysDroppedNotCorrupt) {
  FaultOptions faults;
  faults.corrupt_every = 1;
  const auto pool =
      core::FramePool::create(1, std::size_t{kFaultFrameWidth} * kFaultFrameHeight).value();
  const core::FrameBuffer held = pool->acquire();
  const auto frame = fillOne(faults, faultTrigger(5), *pool);
  ASSERT_TRUE(frame);
  EXPECT_FALSE(frame->buffer);
  EXPECT_EQ(frame->metadata.status, core::FrameStatus::kDropped);
}

TEST(FaultInjectorTest, ClockOffsetShiftsTheDeviceTimestampExactly) {
  FaultOptions faults;
  faults.clock_offset = 250us;
  const auto pool =
      core::FramePool::create(1, std::size_t{kFaultFrameWidth} * kFaultFrameHeight).value();
  const auto frame = fillOne(faults, faultTrigger(1), *pool);
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->metadata.device_timestamp_ns, 1'000'000'000 + 250'000);
  EXPECT_EQ(frame->metadata.status, core::FrameStatus::kOk);
}

TEST(FaultInjectorTest, DelayHoldsTheFrameUntilItsTriggerPlusTheDelay) {
  FaultOptions faults;
  faults.delay = 30ms;
  const auto pool =
      core::FramePool::create(1, std::size_t{kFaultFrameWidth} * kFaultFrameHeight).value();
  const core::SteadyTime issued = std::chrono::steady_clock::now();
  const auto frame = fillOne(faults, faultTrigger(1, issued), *pool);
  EXPECT_GE(std::chrono::steady_clock::now(), issued + 30ms);
  ASSERT_TRUE(frame);
  EXPECT_TRUE(isPattern(*frame));
  // The delay counts from the trigger, not from the call: the device timestamp is still the
  // trigger instant.
  EXPECT_EQ(
      frame->metadata.device_timestamp_ns,
      std::chrono::duration_cast<std::chrono::nanoseconds>(issued.time_since_epoch()).count());
}

}  // namespace
}  // namespace fieldrig::sim
