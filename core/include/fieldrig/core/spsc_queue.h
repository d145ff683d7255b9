// The hand-off between one producer thread and one consumer thread: a bounded, lock-free,
// wait-free queue (boost::lockfree::spsc_queue) whose storage is allocated at construction.
//
// Thread contract: exactly one thread calls tryPush, exactly one (other) thread calls tryPop.
// Neither ever blocks; a full queue refuses the item, and the producer decides what that means
// (the recorder must size its queue not to lose sets; live processing counts a skip).
#pragma once

#include <boost/lockfree/spsc_queue.hpp>
#include <cstddef>
#include <utility>

namespace fieldrig::core {

template <typename T>
class SpscQueue {
 public:
  explicit SpscQueue(std::size_t capacity) : queue_(capacity) {}

  bool tryPush(const T& item) { return queue_.push(item); }
  bool tryPop(T& item) { return queue_.pop(item); }
  // Items waiting, as seen by the consumer.
  std::size_t size() const { return queue_.read_available(); }
  bool empty() const { return queue_.read_available() == 0; }

 private:
  boost::lockfree::spsc_queue<T> queue_;
};

}  // namespace fieldrig::core
