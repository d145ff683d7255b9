// FramePool, FrameBuffer and SpscQueue: buffers are shared and recycled, the pool never blocks,
// and steady-state frame flow allocates nothing (counted by replacing the global operator new).
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <limits>
#include <new>
#include <thread>
#include <vector>

#include "fieldrig/core/frame.h"
#include "fieldrig/core/spsc_queue.h"

namespace {
std::atomic<std::size_t> g_allocations{0};
}  // namespace

// GCC (with the sanitizers' inlining) takes the replaced operator delete's free() for freeing
// what `new` returned, but here `new` is this malloc: the pairing is right by construction.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t size) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(size == 0 ? 1 : size))
    return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#pragma GCC diagnostic pop

namespace fieldrig::core {
namespace {

TEST(FramePoolTest, HandsOutEveryBufferOnceThenRefusesWithoutBlocking) {
  const auto pool = FramePool::create(3, 16).value();
  std::vector<FrameBuffer> held;
  for (int i = 0; i < 3; ++i) {
    held.push_back(pool->acquire());
    ASSERT_TRUE(held.back());
    EXPECT_EQ(held.back().size(), 16u);
  }
  EXPECT_EQ(pool->available(), 0u);
  EXPECT_FALSE(pool->acquire());  // exhausted: empty, at once
  // Distinct memory for each buffer.
  EXPECT_NE(held[0].bytes().data(), held[1].bytes().data());
  EXPECT_NE(held[1].bytes().data(), held[2].bytes().data());
  held.pop_back();
  EXPECT_EQ(pool->available(), 1u);
  EXPECT_TRUE(pool->acquire());
}

TEST(FramePoolTest, BufferReturnsWhenTheLastCopyIsReleased) {
  const auto pool = FramePool::create(1, 8).value();
  FrameBuffer recorder = pool->acquire();
  recorder.bytes()[0] = 42;
  FrameBuffer pipeline = recorder;  // both consumers hold the frame
  EXPECT_EQ(recorder.useCount(), 2);
  EXPECT_EQ(pipeline.bytes()[0], 42);
  recorder.reset();
  EXPECT_EQ(pool->available(), 0u);  // still held by the pipeline
  FrameBuffer moved = std::move(pipeline);
  EXPECT_FALSE(pipeline);  // NOLINT(bugprone-use-after-move): moved-from is empty by contract
  EXPECT_EQ(moved.useCount(), 1);
  moved = FrameBuffer{};
  EXPECT_EQ(pool->available(), 1u);
}

TEST(FramePoolTest, RefusesNoBuffersAndEmptyBuffers) {
  const auto no_buffers = FramePool::create(0, 16);
  ASSERT_FALSE(no_buffers);
  EXPECT_EQ(no_buffers.error().message, "frame pool: the buffer count must be positive");
  const auto empty_buffers = FramePool::create(4, 0);
  ASSERT_FALSE(empty_buffers);
  EXPECT_EQ(empty_buffers.error().message, "frame pool: the buffer size must be positive");
}

TEST(FramePoolTest, HoldsUpToTheFreeListLimitAndRefusesOneMore) {
  const auto largest = FramePool::create(FramePool::kMaxBuffers, 1);
  ASSERT_TRUE(largest) << largest.error().message;
  EXPECT_EQ((*largest)->capacity(), FramePool::kMaxBuffers);
  std::vector<FrameBuffer> held;
  while (FrameBuffer buffer = (*largest)->acquire())
    held.push_back(std::move(buffer));
  EXPECT_EQ(held.size(), FramePool::kMaxBuffers);  // every index made it into the free list

  const auto too_many = FramePool::create(FramePool::kMaxBuffers + 1, 1);
  ASSERT_FALSE(too_many);
  EXPECT_EQ(too_many.error().message,
            "frame pool: 65535 buffers requested, at most 65534 (Boost.Lockfree's limit)");
}

TEST(FramePoolTest, RefusesATotalSizeThatOverflows) {
  const std::size_t half = std::numeric_limits<std::size_t>::max() / 2 + 1;
  const auto overflowing = FramePool::create(2, half);
  ASSERT_FALSE(overflowing);
  EXPECT_EQ(overflowing.error().message, "frame pool: 2 buffers of " + std::to_string(half) +
                                             " bytes overflow the addressable size");
}

TEST(FramePoolTest, ReportsAnAllocationThatFailsWithTheRequestedSize) {
  // 1 PiB in all: beyond any machine's memory and a 47-bit user address space alike.
  const std::size_t buffer_bytes = std::size_t{1} << 48;
  const auto unallocatable = FramePool::create(4, buffer_bytes);
  ASSERT_FALSE(unallocatable);
  EXPECT_EQ(unallocatable.error().message,
            "frame pool: cannot allocate 4 buffers of 281474976710656 bytes "
            "(1125899906842624 bytes in all)");
}

TEST(FrameSetTest, CompleteOnlyWhenEveryCameraDelivered) {
  FrameSet set;
  EXPECT_FALSE(set.complete());
  set.camera_count = 2;
  EXPECT_TRUE(set.complete());
  set.frames[1].metadata.status = FrameStatus::kMissing;
  EXPECT_FALSE(set.complete());
}

TEST(FrameFlowTest, SteadyStateAllocatesNothing) {
  const auto pool = FramePool::create(24, 1024).value();
  SpscQueue<FrameSet> queue(4);
  FrameSet set;
  set.camera_count = 6;
  const std::size_t before = g_allocations.load();
  for (int round = 0; round < 1000; ++round) {
    set.trigger_id = static_cast<std::uint64_t>(round);
    for (std::uint32_t c = 0; c < 6; ++c) {
      set.frames[c].buffer = pool->acquire();
      set.frames[c].metadata.camera = c;
    }
    ASSERT_TRUE(queue.tryPush(set));
    FrameSet out;
    ASSERT_TRUE(queue.tryPop(out));
    ASSERT_EQ(out.trigger_id, static_cast<std::uint64_t>(round));
  }
  EXPECT_EQ(g_allocations.load() - before, 0u);
}

TEST(FrameFlowTest, ProducerAndConsumerThreadsShareAndRecycleBuffers) {
  constexpr int kSets = 20000;
  const auto pool = FramePool::create(6 * 8, 64).value();
  SpscQueue<FrameSet> queue(4);
  std::atomic<int> dropped{0};
  std::thread producer([&] {
    for (int i = 0; i < kSets; ++i) {
      FrameSet set;
      set.trigger_id = static_cast<std::uint64_t>(i);
      set.camera_count = 6;
      for (std::uint32_t c = 0; c < 6; ++c) {
        set.frames[c].buffer = pool->acquire();
        if (!set.frames[c].buffer) {
          set.frames[c].metadata.status = FrameStatus::kDropped;
          continue;
        }
        set.frames[c].buffer.bytes()[0] = static_cast<std::uint8_t>(i);
      }
      while (!queue.tryPush(set))
        std::this_thread::yield();  // the test's consumer keeps up
    }
  });
  int received = 0;
  std::uint64_t expected = 0;
  while (received < kSets) {
    FrameSet set;
    if (!queue.tryPop(set)) {
      std::this_thread::yield();
      continue;
    }
    EXPECT_EQ(set.trigger_id, expected++);  // in order
    for (std::uint32_t c = 0; c < 6; ++c) {
      if (set.frames[c].buffer) {
        EXPECT_EQ(set.frames[c].buffer.bytes()[0], static_cast<std::uint8_t>(set.trigger_id));
      } else {
        ++dropped;
      }
    }
    ++received;
  }
  producer.join();
  EXPECT_EQ(pool->available(), pool->capacity());  // every buffer came back
  // 48 buffers for at most 4 queued + 1 in hand + 1 being filled sets of 6: never exhausted.
  EXPECT_EQ(dropped.load(), 0);
}

}  // namespace
}  // namespace fieldrig::core
