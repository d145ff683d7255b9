// Pairs the frames a triggered camera delivers with the triggers that caused them, in order, and
// notices triggers the camera never answered (missed while busy, or frames lost when the DMA ring
// overflowed): without it one lost frame would shift every later frame onto the wrong trigger.
//
// Rules, on one clock (the frames' host timestamps, microseconds): a trigger still pending when a
// frame finishes more than `max_latency_us` after it was fired is missed; otherwise the oldest
// pending trigger fired no later than the frame belongs to it; a frame with no such trigger is
// unexpected. The driver sets max_latency from exposure + transfer time + half a trigger period.
//
// Pure (time is an argument) and allocation-free after construction. Thread-compatible: the
// driver's capture thread owns it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

namespace fieldrig::drivers {

class TriggerMatcher {
 public:
  struct Match {
    std::optional<std::uint64_t> trigger_id;  // nullopt: unexpected frame
    std::uint32_t missed = 0;                 // pending triggers given up on by this frame
  };

  TriggerMatcher(std::size_t capacity, std::int64_t max_latency_us);

  // False (and the trigger is not recorded) when `capacity` triggers are already pending.
  bool addTrigger(std::uint64_t trigger_id, std::int64_t fired_us);
  Match matchFrame(std::int64_t frame_us);
  // Gives up on triggers older than max_latency at `now_us`; returns how many were missed.
  std::uint32_t expire(std::int64_t now_us);

  std::size_t pending() const { return count_; }
  std::int64_t maxLatencyUs() const { return max_latency_us_; }

 private:
  struct Pending {
    std::uint64_t id = 0;
    std::int64_t fired_us = 0;
  };
  const Pending& oldest() const { return ring_[head_]; }
  void popOldest();

  std::vector<Pending> ring_;  // sized once; a FIFO of head_ and count_
  std::size_t head_ = 0;
  std::size_t count_ = 0;
  std::int64_t max_latency_us_;
};

}  // namespace fieldrig::drivers
