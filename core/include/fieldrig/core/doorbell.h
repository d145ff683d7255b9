// How a consumer thread sleeps until there is work, without its producers ever waiting: producers
// put work where the consumer looks (an SpscQueue, an atomic) and ring(); the consumer takes a
// ticket, looks, and sleeps on that ticket until a ring or a deadline.
//
// A mutex + condition variable would make the GPS/trigger thread and the camera callbacks take
// the consumer's lock to notify it; here ring() is an atomic increment and a futex wake (Linux),
// which never waits. A ring between the consumer's look and its sleep is never lost: the futex
// sleeps only while the ring count still equals the ticket.
//
//   for (;;) {
//     const Doorbell::Ticket ticket = bell.ticket();
//     if (/* work found */) { ...; continue; }
//     bell.waitUntil(ticket, next_deadline);
//   }
//
// Thread contract: ring() from any thread, any number of them; ticket() and waitUntil() from the
// one consumer thread.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>

#include "fieldrig/core/time.h"

namespace fieldrig::core {

class Doorbell {
 public:
  using Ticket = std::uint32_t;

  // Read before looking for work: a ring after this wakes the wait that follows.
  Ticket ticket() const { return rings_.load(std::memory_order_acquire); }
  // Never blocks.
  void ring();
  // Returns when the bell rang since `ticket` (at once if it already did), at `deadline`, or
  // spuriously (callers look again, as with a condition variable). No deadline: until a ring.
  void waitUntil(Ticket ticket, std::optional<SteadyTime> deadline) const;

 private:
  std::atomic<std::uint32_t> rings_{0};  // the futex word; wraps around harmlessly
};

}  // namespace fieldrig::core
