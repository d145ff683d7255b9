// The test pattern source: every pixel is patternAt(camera, trigger, x, y), a value worked out by
// hand here; frames of other cameras and triggers differ; a dry pool gives a dropped frame.
#include "fieldrig/sim/test_pattern_source.h"

#include <gtest/gtest.h>

namespace fieldrig::sim {
namespace {

constexpr std::uint32_t kWidth = 100;  // past 85: x * 3 wraps around 256 within a row
constexpr std::uint32_t kHeight = 5;

SimTrigger triggerNumber(std::uint64_t id) {
  return {id, 0, core::SteadyTime{std::chrono::milliseconds{id}}};
}

TEST(TestPatternSourceTest, PatternValuesWorkedOutByHand) {
  EXPECT_EQ(TestPatternSource::patternAt(0, 0, 0, 0), 0);
  EXPECT_EQ(TestPatternSource::patternAt(1, 2, 3, 4), 94);    // 3·3 + 4·7 + 1·31 + 2·13
  EXPECT_EQ(TestPatternSource::patternAt(0, 0, 99, 0), 41);   // 297 mod 256
  EXPECT_EQ(TestPatternSource::patternAt(5, 20, 0, 0), 159);  // 155 + 260 = 415 mod 256
}

TEST(TestPatternSourceTest, EveryPixelIsThePatternOfTheFramesCameraAndTrigger) {
  TestPatternSource source(kWidth);
  const auto pool = core::FramePool::create(2, std::size_t{kWidth} * kHeight).value();
  const SimTrigger trigger = triggerNumber(42);
  core::Frame frame = stampedFrame(trigger, 3, kWidth, kHeight, core::PixelFormat::kBayerRG8);
  ASSERT_TRUE(source.fill(trigger, *pool, frame));
  ASSERT_TRUE(frame.buffer);
  EXPECT_EQ(frame.metadata.status, core::FrameStatus::kOk);
  EXPECT_EQ(frame.metadata.format, core::PixelFormat::kBayerRG8);  // the configured one, kept
  const std::uint8_t* pixels = frame.buffer.bytes().data();
  for (std::uint32_t y = 0; y < kHeight; ++y) {
    for (std::uint32_t x = 0; x < kWidth; ++x) {
      ASSERT_EQ(pixels[y * kWidth + x], TestPatternSource::patternAt(3, 42, x, y))
          << "x " << x << " y " << y;
    }
  }
  EXPECT_EQ(pixels[0], 127);  // 3·31 + 42·13 = 639 mod 256
}

TEST(TestPatternSourceTest, OtherCamerasAndTriggersGetOtherPixels) {
  TestPatternSource source(kWidth);
  const auto pool = core::FramePool::create(3, std::size_t{kWidth} * kHeight).value();
  core::Frame a = stampedFrame(triggerNumber(7), 0, kWidth, kHeight, core::PixelFormat::kMono8);
  core::Frame b = stampedFrame(triggerNumber(7), 1, kWidth, kHeight, core::PixelFormat::kMono8);
  core::Frame c = stampedFrame(triggerNumber(8), 0, kWidth, kHeight, core::PixelFormat::kMono8);
  ASSERT_TRUE(source.fill(triggerNumber(7), *pool, a));
  ASSERT_TRUE(source.fill(triggerNumber(7), *pool, b));
  ASSERT_TRUE(source.fill(triggerNumber(8), *pool, c));
  const auto bytes = [](const core::Frame& frame) {
    const auto span = frame.buffer.bytes().first(std::size_t{kWidth} * kHeight);
    return std::vector<std::uint8_t>(span.begin(), span.end());
  };
  EXPECT_NE(bytes(a), bytes(b));
  EXPECT_NE(bytes(a), bytes(c));
}

TEST(TestPatternSourceTest, ADryPoolGivesADroppedFrameWithoutPixels) {
  TestPatternSource source(kWidth);
  const auto pool = core::FramePool::create(1, std::size_t{kWidth} * kHeight).value();
  const core::FrameBuffer held = pool->acquire();  // the pool's only buffer
  core::Frame frame = stampedFrame(triggerNumber(1), 0, kWidth, kHeight, core::PixelFormat::kMono8);
  ASSERT_TRUE(source.fill(triggerNumber(1), *pool, frame));  // delivered, as dropped
  EXPECT_FALSE(frame.buffer);
  EXPECT_EQ(frame.metadata.status, core::FrameStatus::kDropped);
}

}  // namespace
}  // namespace fieldrig::sim
