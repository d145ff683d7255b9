// Collects a Rig's FrameSets on the rig thread; the test thread waits for a count (bounded).
#pragma once

#include <chrono>
#include <mutex>
#include <thread>
#include <vector>

#include "fieldrig/drivers/rig.h"

namespace fieldrig::testing_support {

class FrameSetCollector {
 public:
  drivers::Rig::SetSink sink() {
    return [this](core::FrameSet&& set) {
      std::lock_guard lock(mutex_);
      sets_.push_back(std::move(set));  // keeps the buffers: size the pool for it
    };
  }

  bool waitFor(std::size_t count,
               std::chrono::milliseconds timeout = std::chrono::milliseconds{10000}) {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    while (std::chrono::steady_clock::now() < deadline) {
      {
        std::lock_guard lock(mutex_);
        if (sets_.size() >= count)
          return true;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds{1});
    }
    return false;
  }

  std::vector<core::FrameSet> take() {
    std::lock_guard lock(mutex_);
    return std::move(sets_);
  }

 private:
  std::mutex mutex_;
  std::vector<core::FrameSet> sets_;  // guarded by mutex_
};

}  // namespace fieldrig::testing_support
