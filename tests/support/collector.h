// What a camera, a rig or any other producer hands to its sink on its own thread, kept for the
// test thread, which waits (bounded) for a count. Each delivery wakes the waiter through a
// condition variable: a wait ends as soon as the count is there, never on a polling tick.
//
//   testing_support::Collector<core::FrameSet> sets;    // Rig::SetSink: sets.sink()
//   testing_support::Collector<core::Frame> frames;     // Camera::FrameSink: frames.sink()
//   ASSERT_TRUE(sets.waitFor(12));
//   const auto kept = sets.take();
//
// Kept frames and sets hold their pool buffers: size the pool for what a test collects, or keep
// something smaller (sinkKeeping).
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <functional>
#include <mutex>
#include <utility>
#include <vector>

namespace fieldrig::testing_support {

template <typename T>
class Collector {
 public:
  // `default_timeout` bounds waitFor when a call gives none.
  explicit Collector(std::chrono::milliseconds default_timeout = std::chrono::seconds{10})
      : default_timeout_(default_timeout) {}
  Collector(const Collector&) = delete;
  Collector& operator=(const Collector&) = delete;

  // Keeps what it is given.
  std::function<void(T&&)> sink() {
    return [this](T&& item) { add(std::move(item)); };
  }

  // Keeps keep(what it is given): e.g. a frame's metadata and a few pixels instead of the frame,
  // so that the pool never runs dry however many frames a test collects.
  template <typename In, typename Keep>
  std::function<void(In&&)> sinkKeeping(Keep keep) {
    return [this, keep](In&& in) { add(keep(std::move(in))); };
  }

  void add(T item) {
    // Notified under the lock: a waiter that returns and destroys the collector cannot race it.
    std::lock_guard lock(mutex_);
    items_.push_back(std::move(item));
    changed_.notify_all();
  }

  std::size_t size() {
    std::lock_guard lock(mutex_);
    return items_.size();
  }

  // True once `count` items have come; false if the timeout passes first.
  bool waitFor(std::size_t count) { return waitFor(count, default_timeout_); }
  bool waitFor(std::size_t count, std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return items_.size() >= count; });
  }

  // What came so far, handed over (the collector starts again from none).
  std::vector<T> take() {
    std::lock_guard lock(mutex_);
    return std::exchange(items_, {});
  }

  // What came so far, copied (for copyable T), the collector keeping it.
  std::vector<T> items() {
    std::lock_guard lock(mutex_);
    return items_;
  }

 private:
  const std::chrono::milliseconds default_timeout_;
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<T> items_;  // guarded by mutex_
};

}  // namespace fieldrig::testing_support
