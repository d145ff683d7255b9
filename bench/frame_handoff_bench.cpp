// Cost of handing one FrameSet (six pooled buffers) from the rig thread to a consumer thread:
// the lock-free SpscQueue against a mutex + condition-variable queue, same run. Items processed
// = sets that crossed; the time per item is the hand-off cost with both threads busy.
#include <benchmark/benchmark.h>

#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "fieldrig/core/frame.h"
#include "fieldrig/core/spsc_queue.h"

namespace fieldrig::core {
namespace {

constexpr int kSetsPerIteration = 20000;
constexpr std::size_t kQueueCapacity = 16;

FrameSet makeSet(FramePool& pool, std::uint64_t trigger) {
  FrameSet set;
  set.trigger_id = trigger;
  set.camera_count = 6;
  for (std::uint32_t c = 0; c < 6; ++c)
    set.frames[c].buffer = pool.acquire();
  return set;
}

// The baseline: a bounded ring guarded by a mutex, consumers woken by a condition variable.
class MutexQueue {
 public:
  explicit MutexQueue(std::size_t capacity) : ring_(capacity) {}
  void push(const FrameSet& set) {
    std::unique_lock lock(mutex_);
    not_full_.wait(lock, [&] { return count_ < ring_.size(); });
    ring_[(head_ + count_) % ring_.size()] = set;
    ++count_;
    not_empty_.notify_one();
  }
  void pop(FrameSet& set) {
    std::unique_lock lock(mutex_);
    not_empty_.wait(lock, [&] { return count_ > 0; });
    set = std::move(ring_[head_]);
    head_ = (head_ + 1) % ring_.size();
    --count_;
    not_full_.notify_one();
  }

 private:
  std::mutex mutex_;
  std::condition_variable not_empty_, not_full_;
  std::vector<FrameSet> ring_;        // guarded by mutex_
  std::size_t head_ = 0, count_ = 0;  // guarded by mutex_
};

void BM_HandOff_LockFreeSpsc(benchmark::State& state) {
  auto created = FramePool::create(6 * (kQueueCapacity + 4), 64);
  if (!created) {
    state.SkipWithError(created.error().message.c_str());
    return;
  }
  FramePool& pool = **created;
  for (auto _ : state) {
    SpscQueue<FrameSet> queue(kQueueCapacity);
    std::thread consumer([&] {
      FrameSet set;
      for (int received = 0; received < kSetsPerIteration;) {
        if (queue.tryPop(set)) {
          ++received;
          set = FrameSet{};  // release the buffers as a consumer would
        }
      }
    });
    for (int i = 0; i < kSetsPerIteration; ++i) {
      const FrameSet set = makeSet(pool, static_cast<std::uint64_t>(i));
      while (!queue.tryPush(set)) {
      }
    }
    consumer.join();
  }
  state.SetItemsProcessed(state.iterations() * kSetsPerIteration);
}

void BM_HandOff_MutexConditionVariable(benchmark::State& state) {
  auto created = FramePool::create(6 * (kQueueCapacity + 4), 64);
  if (!created) {
    state.SkipWithError(created.error().message.c_str());
    return;
  }
  FramePool& pool = **created;
  for (auto _ : state) {
    MutexQueue queue(kQueueCapacity);
    std::thread consumer([&] {
      FrameSet set;
      for (int received = 0; received < kSetsPerIteration; ++received) {
        queue.pop(set);
        set = FrameSet{};
      }
    });
    for (int i = 0; i < kSetsPerIteration; ++i) {
      queue.push(makeSet(pool, static_cast<std::uint64_t>(i)));
    }
    consumer.join();
  }
  state.SetItemsProcessed(state.iterations() * kSetsPerIteration);
}

// The queues alone: a 32-bit handle per set, no pool traffic, so only the hand-off is timed.
void BM_QueueOnly_LockFreeSpsc(benchmark::State& state) {
  for (auto _ : state) {
    SpscQueue<std::uint32_t> queue(kQueueCapacity);
    std::thread consumer([&] {
      std::uint32_t handle = 0;
      for (int received = 0; received < kSetsPerIteration;) {
        if (queue.tryPop(handle))
          ++received;
      }
    });
    for (int i = 0; i < kSetsPerIteration; ++i) {
      while (!queue.tryPush(static_cast<std::uint32_t>(i))) {
      }
    }
    consumer.join();
  }
  state.SetItemsProcessed(state.iterations() * kSetsPerIteration);
}

void BM_QueueOnly_MutexConditionVariable(benchmark::State& state) {
  for (auto _ : state) {
    std::mutex mutex;
    std::condition_variable not_empty, not_full;
    std::vector<std::uint32_t> ring(kQueueCapacity);
    std::size_t head = 0, count = 0;
    std::thread consumer([&] {
      for (int received = 0; received < kSetsPerIteration; ++received) {
        std::unique_lock lock(mutex);
        not_empty.wait(lock, [&] { return count > 0; });
        head = (head + 1) % ring.size();
        --count;
        not_full.notify_one();
      }
    });
    for (int i = 0; i < kSetsPerIteration; ++i) {
      std::unique_lock lock(mutex);
      not_full.wait(lock, [&] { return count < ring.size(); });
      ring[(head + count) % ring.size()] = static_cast<std::uint32_t>(i);
      ++count;
      not_empty.notify_one();
    }
    consumer.join();
  }
  state.SetItemsProcessed(state.iterations() * kSetsPerIteration);
}

BENCHMARK(BM_QueueOnly_LockFreeSpsc)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_QueueOnly_MutexConditionVariable)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_HandOff_LockFreeSpsc)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_HandOff_MutexConditionVariable)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace fieldrig::core

BENCHMARK_MAIN();
