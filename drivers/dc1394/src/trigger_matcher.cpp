#include "fieldrig/drivers/dc1394/trigger_matcher.h"

namespace fieldrig::drivers {

TriggerMatcher::TriggerMatcher(std::size_t capacity, std::int64_t max_latency_us)
    : ring_(capacity == 0 ? 1 : capacity), max_latency_us_(max_latency_us) {}

bool TriggerMatcher::addTrigger(std::uint64_t trigger_id, std::int64_t fired_us) {
  if (count_ == ring_.size())
    return false;
  ring_[(head_ + count_) % ring_.size()] = {trigger_id, fired_us};
  ++count_;
  return true;
}

void TriggerMatcher::popOldest() {
  head_ = (head_ + 1) % ring_.size();
  --count_;
}

std::uint32_t TriggerMatcher::expire(std::int64_t now_us) {
  std::uint32_t missed = 0;
  while (count_ > 0 && now_us - oldest().fired_us > max_latency_us_) {
    popOldest();
    ++missed;
  }
  return missed;
}

TriggerMatcher::Match TriggerMatcher::matchFrame(std::int64_t frame_us) {
  Match match;
  match.missed = expire(frame_us);
  if (count_ > 0 && oldest().fired_us <= frame_us) {
    match.trigger_id = oldest().id;
    popOldest();
  }
  return match;
}

}  // namespace fieldrig::drivers
