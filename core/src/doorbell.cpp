#include "fieldrig/core/doorbell.h"

#include <linux/futex.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <ctime>

namespace fieldrig::core {
namespace {

// The kernel reads the atomic's storage as a plain 32-bit word.
static_assert(sizeof(std::atomic<std::uint32_t>) == sizeof(std::uint32_t));
static_assert(std::atomic<std::uint32_t>::is_always_lock_free);

std::uint32_t* futexWord(const std::atomic<std::uint32_t>& word) {
  return const_cast<std::uint32_t*>(reinterpret_cast<const std::uint32_t*>(&word));
}

}  // namespace

void Doorbell::ring() {
  rings_.fetch_add(1, std::memory_order_release);
  // No waiter is cheap to wake: the kernel finds an empty bucket and returns.
  ::syscall(SYS_futex, futexWord(rings_), FUTEX_WAKE_PRIVATE, 1, nullptr, nullptr, 0);
}

void Doorbell::waitUntil(Ticket ticket, std::optional<SteadyTime> deadline) const {
  if (rings_.load(std::memory_order_acquire) != ticket)
    return;
  timespec until{};
  if (deadline) {
    // FUTEX_WAIT_BITSET takes an absolute CLOCK_MONOTONIC time: steady_clock's clock on Linux.
    const auto since_epoch = deadline->time_since_epoch();
    if (since_epoch.count() <= 0)
      return;
    const auto seconds = std::chrono::duration_cast<std::chrono::seconds>(since_epoch);
    until.tv_sec = static_cast<time_t>(seconds.count());
    until.tv_nsec = static_cast<long>(
        std::chrono::duration_cast<std::chrono::nanoseconds>(since_epoch - seconds).count());
  }
  // Sleeps only while the word still equals the ticket; EAGAIN (it rang), EINTR and ETIMEDOUT
  // all return to the caller, who looks again.
  ::syscall(SYS_futex, futexWord(rings_), FUTEX_WAIT_BITSET_PRIVATE, ticket,
            deadline ? &until : nullptr, nullptr, FUTEX_BITSET_MATCH_ANY);
}

}  // namespace fieldrig::core
