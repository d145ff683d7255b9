// The doorbell with real threads: a ring is never lost between a consumer's look and its sleep,
// a sleeper wakes on a ring, and a deadline ends the wait when nobody rings.
#include "fieldrig/core/doorbell.h"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>

namespace fieldrig::core {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

TEST(DoorbellTest, ARingAfterTheTicketEndsTheWaitAtOnce) {
  Doorbell bell;
  const Doorbell::Ticket ticket = bell.ticket();
  bell.ring();  // between the consumer's look and its sleep
  const auto start = Clock::now();
  bell.waitUntil(ticket, std::nullopt);  // would sleep forever if the ring were lost
  EXPECT_LT(Clock::now() - start, 1s);
  EXPECT_NE(bell.ticket(), ticket);
}

TEST(DoorbellTest, TheDeadlineEndsTheWaitWhenNobodyRings) {
  Doorbell bell;
  const auto start = Clock::now();
  bell.waitUntil(bell.ticket(), start + 30ms);
  const auto waited = Clock::now() - start;
  EXPECT_GE(waited, 30ms);
  EXPECT_LT(waited, 5s);
  bell.waitUntil(bell.ticket(), start);  // a deadline already past returns
}

TEST(DoorbellTest, ASleeperWakesOnARingFromAnotherThread) {
  Doorbell bell;
  std::atomic<int> work{0};
  std::atomic<int> seen{0};
  std::thread consumer([&] {
    const auto give_up = Clock::now() + 10s;
    while (seen < 100 && Clock::now() < give_up) {
      const Doorbell::Ticket ticket = bell.ticket();
      if (work.load() > seen.load()) {
        seen = work.load();
        continue;
      }
      bell.waitUntil(ticket, give_up);
    }
  });
  const auto start = Clock::now();
  for (int i = 1; i <= 100; ++i) {
    work = i;
    bell.ring();
    if (i % 10 == 0)
      std::this_thread::sleep_for(1ms);  // let the consumer fall asleep now and then
  }
  consumer.join();
  EXPECT_EQ(seen.load(), 100);
  EXPECT_LT(Clock::now() - start, 5s);  // woken by the rings, not by its 10 s deadline
}

}  // namespace
}  // namespace fieldrig::core
