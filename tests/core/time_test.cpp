#include "fieldrig/core/time.h"

#include <gtest/gtest.h>

namespace fieldrig::core {
namespace {

using namespace std::chrono;

TEST(TimeTest, FormatsIsoWithRequestedFractionDigits) {
  const UtcTime t = sys_days{2026y / July / 14} + 15h + 30min + 0s + 100ms;
  EXPECT_EQ(formatIso8601(t, 2), "2026-07-14T15:30:00.10Z");
  EXPECT_EQ(formatIso8601(t, 3), "2026-07-14T15:30:00.100Z");
  EXPECT_EQ(formatIso8601(t, 0), "2026-07-14T15:30:00Z");
}

TEST(TimeTest, FormattingTruncatesInsteadOfRoundingPastTheSecond) {
  const UtcTime t = sys_days{2026y / December / 31} + 23h + 59min + 59s + 999'999'999ns;
  EXPECT_EQ(formatIso8601(t, 3), "2026-12-31T23:59:59.999Z");
}

TEST(TimeTest, ParsesWhatItFormats) {
  const UtcTime t = sys_days{2026y / February / 28} + 1h + 2min + 3s + 456789ns;
  const auto parsed = parseIso8601(formatIso8601(t, 9));
  ASSERT_TRUE(parsed);
  EXPECT_EQ(*parsed, t);
}

TEST(TimeTest, RejectsMalformedIso) {
  EXPECT_FALSE(parseIso8601("2026-02-30T00:00:00Z"));  // no such day
  EXPECT_FALSE(parseIso8601("2026-01-01 00:00:00Z"));
  EXPECT_FALSE(parseIso8601("2026-01-01T00:00:00"));
  EXPECT_FALSE(parseIso8601("2026-01-01T24:00:00Z"));
  EXPECT_FALSE(parseIso8601("2026-01-01T00:00:00.Z"));
  EXPECT_FALSE(parseIso8601("2026-07-14T-1:00:00Z"));
  EXPECT_FALSE(parseIso8601("2026-07-14T+1:00:00Z"));
}

// Found by the session index fuzzer: a year like 1012 overflowed the nanosecond count (UB).
TEST(TimeTest, RejectsYearsOutsideWhatNanosecondsFrom1970Hold) {
  EXPECT_FALSE(parseIso8601("1012-05-29T16:26:40.120456789Z"));
  EXPECT_FALSE(parseIso8601("1677-12-31T23:59:59Z"));
  EXPECT_FALSE(parseIso8601("2262-01-01T00:00:00Z"));
  EXPECT_FALSE(parseIso8601("9999-12-31T23:59:59Z"));
  for (const char* edge : {"1678-01-01T00:00:00.000000000Z", "2261-12-31T23:59:59.999999999Z"}) {
    const auto parsed = parseIso8601(edge);
    ASSERT_TRUE(parsed) << edge;
    EXPECT_EQ(formatIso8601(*parsed, 9), edge);
  }
}

TEST(TimeTest, TimeOfDay) {
  EXPECT_EQ(formatTimeOfDay(13h + 28min + 20s + 600ms, 2), "13:28:20.60");
}

TEST(TimeTest, SecondsRoundTrip) {
  EXPECT_DOUBLE_EQ(toSeconds(fromSeconds(0.123456789)), 0.123456789);
}

}  // namespace
}  // namespace fieldrig::core
