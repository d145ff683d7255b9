// FixAssembler: merging the RMC and GGA of one epoch, dating GGAs from the last RMC (also across
// midnight) and the validity veto of either sentence.
#include <gtest/gtest.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

#include "fieldrig/gps/fix_assembler.h"
#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::gps {
namespace {

using std::chrono::sys_days;
using namespace std::chrono_literals;

std::string rmc(const std::string& time, const std::string& date, char status = 'A') {
  return withChecksum("GNRMC," + time + "," + status +
                      ",4004.92740741,N,08813.16074074,W,3.888,90.0," + date + ",,,R");
}

std::string gga(const std::string& time, int quality = 4) {
  return withChecksum("GNGGA," + time + ",4004.92740741,N,08813.16074074,W," +
                      std::to_string(quality) + ",17,0.7,221.5,M,-33.4,M,1.0,0000");
}

// Feeds one sentence; the fix the assembler returned for it.
std::optional<core::GpsFix> add(FixAssembler& assembler, const std::string& line) {
  std::optional<core::GpsFix> result;
  const Sentence sentence = NmeaParser::parseLine(line);
  EXPECT_NE(sentence.kind, SentenceKind::kRejected) << line;
  return assembler.add(sentence, core::ReceptionStamp{});
}

void expectMerged(const core::GpsFix& fix) {
  // 40 + 4.92740741 / 60 = 40.0821234568; -(88 + 13.16074074 / 60) = -88.2193456790.
  EXPECT_NEAR(fix.latitude_deg, 40.08212345683, 1e-10);
  EXPECT_NEAR(fix.longitude_deg, -88.21934567900, 1e-10);
  ASSERT_TRUE(fix.speed_mps);
  EXPECT_NEAR(*fix.speed_mps, 3.888 * 1852 / 3600, 1e-12);
  EXPECT_EQ(fix.course_deg, 90.0);
  EXPECT_EQ(fix.quality, core::FixQuality::kRtkFixed);
  EXPECT_EQ(fix.satellites, 17);
  EXPECT_EQ(fix.altitude_m, 221.5);
  EXPECT_EQ(fix.hdop, 0.7);
  EXPECT_TRUE(fix.valid);
  EXPECT_TRUE(fix.has_date);
  EXPECT_EQ(fix.talker, "GN");
}

TEST(FixAssembler, MergesRmcThenGgaOfOneEpoch) {
  FixAssembler assembler;
  const auto first = add(assembler, rmc("152959.90", "140726"));
  ASSERT_TRUE(first);
  EXPECT_FALSE(first->altitude_m.has_value());  // not known until the GGA
  const auto merged = add(assembler, gga("152959.90"));
  ASSERT_TRUE(merged);
  expectMerged(*merged);
  EXPECT_EQ(merged->time, sys_days{2026y / 7 / 14} + 15h + 29min + 59s + 900ms);
}

TEST(FixAssembler, MergesGgaThenRmcOfOneEpoch) {
  FixAssembler assembler;
  ASSERT_TRUE(add(assembler, rmc("152959.80", "140726")));  // dates the GGA that follows
  const auto gga_first = add(assembler, gga("152959.90"));
  ASSERT_TRUE(gga_first);
  EXPECT_FALSE(gga_first->speed_mps.has_value());  // the previous epoch's speed is not carried
  const auto merged = add(assembler, rmc("152959.90", "140726"));
  ASSERT_TRUE(merged);
  expectMerged(*merged);
  EXPECT_EQ(merged->time, sys_days{2026y / 7 / 14} + 15h + 29min + 59s + 900ms);
}

TEST(FixAssembler, NewEpochStartsAFreshFix) {
  FixAssembler assembler;
  add(assembler, rmc("152959.90", "140726"));
  add(assembler, gga("152959.90"));
  const auto next = add(assembler, rmc("153000.00", "140726"));
  ASSERT_TRUE(next);
  EXPECT_FALSE(next->altitude_m.has_value());
  EXPECT_FALSE(next->quality.has_value());
  EXPECT_EQ(next->time, sys_days{2026y / 7 / 14} + 15h + 30min);
}

TEST(FixAssembler, GgaTakesTheDateOfTheLastRmc) {
  FixAssembler assembler(sys_days{2000y / 1 / 1});
  // Before any RMC: the fallback date, and the fix says the date is borrowed.
  const auto alone = add(assembler, gga("101010.00"));
  ASSERT_TRUE(alone);
  EXPECT_FALSE(alone->has_date);
  EXPECT_EQ(alone->time, sys_days{2000y / 1 / 1} + 10h + 10min + 10s);

  add(assembler, rmc("101010.10", "050399"));
  const auto dated = add(assembler, gga("101010.20"));
  ASSERT_TRUE(dated);
  EXPECT_TRUE(dated->has_date);
  EXPECT_EQ(dated->time, sys_days{1999y / 3 / 5} + 10h + 10min + 10s + 200ms);
}

TEST(FixAssembler, GgaAfterMidnightBelongsToTheNextDay) {
  FixAssembler assembler;
  add(assembler, rmc("235959.90", "311226"));
  const auto after = add(assembler, gga("000000.00"));
  ASSERT_TRUE(after);
  EXPECT_EQ(after->time, sys_days{2027y / 1 / 1});
  // And the RMC of that epoch, dated by the receiver, merges with it.
  const auto merged = add(assembler, rmc("000000.00", "010127"));
  ASSERT_TRUE(merged);
  EXPECT_EQ(merged->time, sys_days{2027y / 1 / 1});
  EXPECT_EQ(merged->altitude_m, 221.5);
}

TEST(FixAssembler, GgaBeforeMidnightAfterANewDaysRmcBelongsToThePreviousDay) {
  FixAssembler assembler;
  add(assembler, rmc("000000.00", "010127"));
  const auto late = add(assembler, gga("235959.90"));  // delayed sentence of the old day
  ASSERT_TRUE(late);
  EXPECT_EQ(late->time, sys_days{2026y / 12 / 31} + 23h + 59min + 59s + 900ms);
}

TEST(FixAssembler, GgaOnlyStreamRollsOverToTheNextDayAtMidnight) {
  FixAssembler assembler(sys_days{std::chrono::year{2026} / 7 / 14});
  const auto before = add(assembler, gga("235959.90"));
  const auto after = add(assembler, gga("000000.00"));
  ASSERT_TRUE(before && after);
  EXPECT_FALSE(after->has_date);
  EXPECT_EQ(after->time - before->time, 100ms);
  EXPECT_EQ(after->time, sys_days{std::chrono::year{2026} / 7 / 15});
}

TEST(FixAssembler, RmcVoidVetoesTheEpoch) {
  for (const bool gga_first : {false, true}) {
    FixAssembler assembler;
    add(assembler, rmc("120000.00", "140726"));
    std::optional<core::GpsFix> fix;
    if (gga_first) {
      EXPECT_TRUE(add(assembler, gga("120000.10"))->valid);
      fix = add(assembler, rmc("120000.10", "140726", 'V'));
    } else {
      EXPECT_FALSE(add(assembler, rmc("120000.10", "140726", 'V'))->valid);
      fix = add(assembler, gga("120000.10"));
    }
    ASSERT_TRUE(fix);
    EXPECT_FALSE(fix->valid) << "gga first: " << gga_first;
  }
}

TEST(FixAssembler, GgaQualityZeroVetoesTheEpoch) {
  for (const bool gga_first : {false, true}) {
    FixAssembler assembler;
    add(assembler, rmc("120000.00", "140726"));
    std::optional<core::GpsFix> fix;
    if (gga_first) {
      EXPECT_FALSE(add(assembler, gga("120000.10", 0))->valid);
      fix = add(assembler, rmc("120000.10", "140726"));
    } else {
      EXPECT_TRUE(add(assembler, rmc("120000.10", "140726"))->valid);
      fix = add(assembler, gga("120000.10", 0));
    }
    ASSERT_TRUE(fix);
    EXPECT_FALSE(fix->valid) << "gga first: " << gga_first;
  }
}

TEST(FixAssembler, IgnoresOtherSentencesAndSentencesWithoutTime) {
  FixAssembler assembler;
  EXPECT_FALSE(add(assembler, withChecksum("GPGLL,2638.1727,N,08011.3892,W,030130.000,A,A")));
  EXPECT_FALSE(add(assembler, withChecksum("GPGGA,,,,,,0,00,,,M,,M,,")));
  EXPECT_FALSE(assembler.add(NmeaParser::parseLine("garbage"), core::ReceptionStamp{}));
}

}  // namespace
}  // namespace fieldrig::gps
