// NmeaParser: framing (garbage, NULs, truncation, run-together sentences, terminators, long
// lines, chunk boundaries), checksums, talkers and field decoding. Expected values are computed
// by hand from the sentence text (degrees + minutes / 60, knots × 1852 / 3600).
#include <gtest/gtest.h>

#include <cctype>
#include <chrono>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::gps {
namespace {

using std::chrono::sys_days;
using namespace std::chrono_literals;

const std::string kRmc = withChecksum(
    "GPRMC,113938.50,A,3842.86006889,N,11705.43645510,W,0.011,46.405,231122,999.9000,E,D");
const std::string kGga = withChecksum(
    "GPGGA,113938.50,3842.86006889,N,11705.43645510,W,2,09,1.5,1864.182,M,-44.296,M,1.4,0000");

// The one independent check of the checksum writer every test here builds its sentences with:
// sentences copied verbatim from a receiver's log (gpsd's regression data) must come out of
// withChecksum identically, hex digits in upper case with a leading zero kept.
TEST(NmeaChecksum, WithChecksumReproducesSentencesFromAReceiverLog) {
  const std::string log_path = FIELDRIG_SHARED_DATA_DIR "/nmea/gpsd/nmea-rtk.log";
  std::ifstream in(log_path, std::ios::binary);
  ASSERT_TRUE(in) << "cannot open " << log_path;
  const std::string log{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
  struct Known {
    std::string sentence;
    unsigned char checksum;
  };
  const std::vector<Known> known = {
      {"$GNRMC,132820.40,A,4134.49821522,N,09345.03375619,W,2.627,91.414,180320,11.5985,E,D*05",
       0x05},
      {"$GNRMC,132827.00,A,4134.49941381,N,09345.03496613,W,0.379,15.324,180320,11.5985,E,D*0A",
       0x0A},
      {"$GNGGA,132819.60,4134.49795459,N,09345.03431408,W,2,10,0.9,278.161,M,-31.442,M,6.6,0133*6A",
       0x6A},
  };
  for (const Known& k : known) {
    SCOPED_TRACE(k.sentence);
    // Guards against a typo in the copy: the sentence is in the log as written here.
    ASSERT_NE(log.find(k.sentence + "\r\n"), std::string::npos);
    const std::string body = k.sentence.substr(1, k.sentence.size() - 4);
    EXPECT_EQ(nmeaChecksum(body), k.checksum);
    EXPECT_EQ(withChecksum(body), k.sentence);
  }
}

// What one outcome looked like, copied out of the callback (views die with it).
struct Outcome {
  SentenceKind kind;
  RejectReason reason;
  std::string text;
  std::string talker;
  std::string type;
  RmcData rmc;
  GgaData gga;

  bool operator==(const Outcome& o) const {
    return kind == o.kind && reason == o.reason && text == o.text && talker == o.talker &&
           type == o.type && rmc.latitude_deg == o.rmc.latitude_deg && rmc.time == o.rmc.time &&
           gga.latitude_deg == o.gga.latitude_deg && gga.altitude_m == o.gga.altitude_m;
  }
};

struct ParseRun {
  std::vector<Outcome> outcomes;
  NmeaStats stats;

  std::vector<Outcome> fixes() const {
    std::vector<Outcome> out;
    for (const Outcome& o : outcomes) {
      if (o.kind == SentenceKind::kRmc || o.kind == SentenceKind::kGga)
        out.push_back(o);
    }
    return out;
  }
};

// Feeds `chunks` in order, then flushes.
ParseRun parse(const std::vector<std::string>& chunks, NmeaParserOptions options = {}) {
  ParseRun run;
  NmeaParser parser(
      [&run](const Sentence& s) {
        run.outcomes.push_back({s.kind, s.reason, std::string(s.text), std::string(s.talker),
                                std::string(s.type), s.rmc, s.gga});
      },
      options);
  for (const std::string& chunk : chunks)
    parser.feed(chunk);
  parser.flush();
  run.stats = parser.stats();
  return run;
}
ParseRun parse(const std::string& bytes, NmeaParserOptions options = {}) {
  return parse(std::vector<std::string>{bytes}, options);
}

std::uint64_t rejected(const NmeaStats& stats, RejectReason reason) {
  return stats.rejected[static_cast<std::size_t>(reason)];
}

TEST(NmeaParser, DecodesRtkRmcToFullPrecision) {
  const ParseRun run = parse(kRmc + "\r\n");
  ASSERT_EQ(run.outcomes.size(), 1u);
  const Outcome& o = run.outcomes[0];
  ASSERT_EQ(o.kind, SentenceKind::kRmc);
  EXPECT_EQ(o.talker, "GP");
  EXPECT_EQ(o.type, "RMC");
  // 38 + 42.86006889 / 60 = 38.7143344815; -(117 + 5.43645510 / 60) = -117.090607585.
  EXPECT_NEAR(*o.rmc.latitude_deg, 38.7143344815, 1e-11);
  EXPECT_NEAR(*o.rmc.longitude_deg, -117.090607585, 1e-11);
  // 0.011 kn × 1852 m / 3600 s = 0.005658888… m/s.
  EXPECT_NEAR(*o.rmc.speed_mps, 0.0056588888889, 1e-13);
  EXPECT_DOUBLE_EQ(*o.rmc.course_deg, 46.405);
  EXPECT_NEAR(*o.rmc.magnetic_variation_deg, 999.9, 1e-9);
  EXPECT_TRUE(o.rmc.status_active);
  EXPECT_EQ(o.rmc.mode, 'D');
  EXPECT_TRUE(o.rmc.valid());
  EXPECT_EQ(*o.rmc.time, sys_days{2022y / 11 / 23} + 11h + 39min + 38s + 500ms);
  EXPECT_EQ(*o.rmc.time_of_day, 11h + 39min + 38s + 500ms);
}

TEST(NmeaParser, DecodesGgaFields) {
  const ParseRun run = parse(kGga + "\r\n");
  ASSERT_EQ(run.outcomes.size(), 1u);
  const GgaData& gga = run.outcomes[0].gga;
  ASSERT_EQ(run.outcomes[0].kind, SentenceKind::kGga);
  EXPECT_NEAR(*gga.latitude_deg, 38.7143344815, 1e-11);
  EXPECT_NEAR(*gga.longitude_deg, -117.090607585, 1e-11);
  EXPECT_EQ(gga.quality, 2);
  EXPECT_EQ(gga.satellites, 9);
  EXPECT_DOUBLE_EQ(*gga.hdop, 1.5);
  EXPECT_DOUBLE_EQ(*gga.altitude_m, 1864.182);
  EXPECT_DOUBLE_EQ(*gga.geoid_separation_m, -44.296);
  EXPECT_DOUBLE_EQ(*gga.dgps_age_s, 1.4);
  EXPECT_EQ(*gga.time_of_day, 11h + 39min + 38s + 500ms);
  EXPECT_TRUE(gga.valid());
}

TEST(NmeaParser, KeepsTenDecimalsOfMinutes) {
  // 48 + 08.1234567891/60 = 48.135390946485; 011 + 35.0000000001/60 = 11.583333333335.
  const ParseRun run = parse(
      withChecksum("GNGGA,000000.00,4808.1234567891,S,01135.0000000001,E,4,20,0.5,1.0,M,,M,,") +
      "\n");
  ASSERT_EQ(run.outcomes.size(), 1u);
  EXPECT_NEAR(*run.outcomes[0].gga.latitude_deg, -48.135390946485, 2e-12);
  EXPECT_NEAR(*run.outcomes[0].gga.longitude_deg, 11.583333333335, 2e-12);
  // Distinct in the tenth decimal of minutes: 1e-10 min = 1.7e-12 deg must not be lost.
  const ParseRun next = parse(
      withChecksum("GNGGA,000000.00,4808.1234567892,S,01135.0000000001,E,4,20,0.5,1.0,M,,M,,") +
      "\n");
  EXPECT_LT(*next.outcomes[0].gga.latitude_deg, *run.outcomes[0].gga.latitude_deg);
}

TEST(NmeaParser, SouthAndWestAreNegative) {
  const ParseRun run =
      parse(withChecksum("GPRMC,010203,A,1930.0000,S,02415.0000,W,10.0,0.0,010203,,") + "\n" +
            withChecksum("GPRMC,010203,A,1930.0000,N,02415.0000,E,10.0,0.0,010203,,") + "\n");
  ASSERT_EQ(run.outcomes.size(), 2u);
  EXPECT_DOUBLE_EQ(*run.outcomes[0].rmc.latitude_deg, -19.5);
  EXPECT_DOUBLE_EQ(*run.outcomes[0].rmc.longitude_deg, -24.25);
  EXPECT_DOUBLE_EQ(*run.outcomes[1].rmc.latitude_deg, 19.5);
  EXPECT_DOUBLE_EQ(*run.outcomes[1].rmc.longitude_deg, 24.25);
  // 10 kn = 18520 m / 3600 s = 5.1444… m/s.
  EXPECT_NEAR(*run.outcomes[0].rmc.speed_mps, 5.144444444444, 1e-12);
}

TEST(NmeaParser, TwoDigitYearsSplitAt1980) {
  const ParseRun run = parse(withChecksum("GPRMC,235959,A,0000.0,N,00000.0,E,,,311299,,") + "\n" +
                             withChecksum("GPRMC,000000,A,0000.0,N,00000.0,E,,,010100,,") + "\n" +
                             withChecksum("GPRMC,120000,A,0000.0,N,00000.0,E,,,311279,,") + "\n" +
                             withChecksum("GPRMC,120000,A,0000.0,N,00000.0,E,,,010180,,") + "\n");
  ASSERT_EQ(run.fixes().size(), 4u);
  EXPECT_EQ(*run.outcomes[0].rmc.time, sys_days{1999y / 12 / 31} + 23h + 59min + 59s);
  EXPECT_EQ(*run.outcomes[1].rmc.time, sys_days{2000y / 1 / 1});
  EXPECT_EQ(*run.outcomes[2].rmc.time, sys_days{2079y / 12 / 31} + 12h);
  EXPECT_EQ(*run.outcomes[3].rmc.time, sys_days{1980y / 1 / 1} + 12h);
}

TEST(NmeaParser, TimeOfDayFractionIsExactToTheNanosecond) {
  const ParseRun run = parse(withChecksum("GNGGA,235959.123456789,,,,,0,,,,,,,,") + "\n" +
                             withChecksum("GNGGA,000000.1,,,,,0,,,,,,,,") + "\n" +
                             withChecksum("GNGGA,120000.0000000001,,,,,0,,,,,,,,") + "\n");
  ASSERT_EQ(run.outcomes.size(), 3u);
  EXPECT_EQ(*run.outcomes[0].gga.time_of_day,
            23h + 59min + 59s + std::chrono::nanoseconds{123'456'789});
  EXPECT_EQ(*run.outcomes[1].gga.time_of_day, 100ms);
  // Finer than a nanosecond cannot be represented exactly: rejected rather than rounded.
  EXPECT_EQ(run.outcomes[2].kind, SentenceKind::kRejected);
  EXPECT_EQ(run.outcomes[2].reason, RejectReason::kMalformed);
}

TEST(NmeaParser, AcceptsEveryTalker) {
  std::string bytes;
  const std::vector<std::string> talkers = {"GP", "GN", "GL", "GA", "GB", "IN", "BD", "GQ"};
  for (const std::string& talker : talkers) {
    bytes += withChecksum(talker + "RMC,120000,A,4000.0,N,08000.0,W,0.0,0.0,010124,,,A") + "\r\n";
    bytes += withChecksum(talker + "GGA,120000,4000.0,N,08000.0,W,1,05,1.0,10.0,M,,M,,") + "\r\n";
  }
  const ParseRun run = parse(bytes);
  ASSERT_EQ(run.outcomes.size(), 2 * talkers.size());
  for (std::size_t i = 0; i < talkers.size(); ++i) {
    EXPECT_EQ(run.outcomes[2 * i].kind, SentenceKind::kRmc);
    EXPECT_EQ(run.outcomes[2 * i].talker, talkers[i]);
    EXPECT_EQ(run.outcomes[2 * i + 1].kind, SentenceKind::kGga);
    EXPECT_EQ(run.outcomes[2 * i + 1].talker, talkers[i]);
  }
  EXPECT_EQ(run.stats.rmc, talkers.size());
  EXPECT_EQ(run.stats.gga, talkers.size());
}

TEST(NmeaParser, AllTerminatorsAndAMissingFinalOne) {
  for (const std::string terminator : {"\r\n", "\n", "\r", "\n\r"}) {
    const ParseRun run = parse(kRmc + terminator + kGga + terminator + kRmc);
    EXPECT_EQ(run.stats.rmc, 2u) << "terminator size " << terminator.size();
    EXPECT_EQ(run.stats.gga, 1u);
    EXPECT_EQ(run.stats.lines, 3u);
    EXPECT_EQ(run.stats.rejectedTotal(), 0u);
  }
}

TEST(NmeaParser, UnterminatedLineWaitsForFlush) {
  NmeaParser parser([](const Sentence&) {});
  parser.feed(kRmc);
  EXPECT_EQ(parser.stats().rmc, 0u);
  parser.flush();
  EXPECT_EQ(parser.stats().rmc, 1u);
}

TEST(NmeaParser, SurvivesGarbageAndNulRuns) {
  const std::string nuls(40, '\0');
  const ParseRun run = parse("foobar\r\n" + nuls + "\r\n" + nuls + kRmc + "\r\n" + "\x1b[2J" +
                             kGga + "\r\n" + "\xff\xfe\x01\r\n" + kGga + "\r\n");
  EXPECT_EQ(run.stats.rmc, 1u);
  EXPECT_EQ(run.stats.gga, 2u);
  // foobar, the NUL line, the NULs before the RMC, the escape code, the 8-bit line.
  EXPECT_EQ(rejected(run.stats, RejectReason::kGarbage), 5u);
  EXPECT_EQ(run.stats.lines, 6u);
}

TEST(NmeaParser, NulsInsideASentenceRejectIt) {
  std::string broken = kRmc;
  broken.replace(20, 10, std::string(10, '\0'));
  const ParseRun run = parse(broken + "\r\n" + kGga + "\r\n");
  EXPECT_EQ(run.stats.rmc, 0u);
  EXPECT_EQ(run.stats.gga, 1u);
  EXPECT_EQ(rejected(run.stats, RejectReason::kNonPrintable), 1u);
}

TEST(NmeaParser, TruncatedSentencesAreRejected) {
  std::string bytes;
  for (std::size_t length = 1; length < kRmc.size(); ++length) {
    bytes += kRmc.substr(0, length) + "\r\n";
  }
  const ParseRun run = parse(bytes);
  EXPECT_TRUE(run.fixes().empty());
  EXPECT_EQ(run.stats.rejectedTotal(), kRmc.size() - 1);
}

TEST(NmeaParser, RunTogetherSentencesAreSplitAtTheNextStart) {
  // Triton 400 log: a GGA cut short by the next sentence on the same line.
  const std::string gll = withChecksum("GPGLL,2638.1728,N,08011.3893,W,030131.000,A,A");
  const ParseRun run = parse("$GPGGA,030130" + gll + "\r\n" + kRmc + kGga + "\r\n");
  ASSERT_EQ(run.outcomes.size(), 4u);
  EXPECT_EQ(run.outcomes[0].kind, SentenceKind::kRejected);
  EXPECT_EQ(run.outcomes[0].reason, RejectReason::kNoChecksum);
  EXPECT_EQ(run.outcomes[0].text, "$GPGGA,030130");
  EXPECT_EQ(run.outcomes[1].kind, SentenceKind::kOther);
  EXPECT_EQ(run.outcomes[1].type, "GLL");
  EXPECT_EQ(run.outcomes[2].kind, SentenceKind::kRmc);
  EXPECT_EQ(run.outcomes[3].kind, SentenceKind::kGga);
  EXPECT_EQ(run.stats.lines, 2u);
}

TEST(NmeaParser, OverLongLinesAreRejectedAndTheNextLineSurvives) {
  const std::string long_line = "$GPTXT," + std::string(300, 'x');
  const ParseRun whole = parse(long_line + "\r\n" + kRmc + "\r\n");
  EXPECT_EQ(rejected(whole.stats, RejectReason::kTooLong), 1u);
  EXPECT_EQ(whole.stats.rmc, 1u);

  // The same line arriving in small pieces: pending data stays bounded, same outcome.
  std::vector<std::string> chunks;
  for (std::size_t i = 0; i < long_line.size(); i += 7)
    chunks.push_back(long_line.substr(i, 7));
  chunks.push_back("\r\n" + kRmc + "\r\n");
  const ParseRun pieces = parse(chunks);
  EXPECT_EQ(pieces.outcomes, whole.outcomes);
  EXPECT_EQ(pieces.stats.lines, whole.stats.lines);

  // A line exactly at the limit is not too long.
  const ParseRun limit = parse(kRmc + std::string(200 - kRmc.size(), ' ') + "\n",
                               NmeaParserOptions{.max_line_length = 200});
  EXPECT_EQ(limit.stats.rmc, 1u);
  const ParseRun over = parse(kRmc + std::string(201 - kRmc.size(), ' ') + "\n",
                              NmeaParserOptions{.max_line_length = 200});
  EXPECT_EQ(rejected(over.stats, RejectReason::kTooLong), 1u);
}

// A messy stream that touches every framing path.
std::string messyStream() {
  std::string s = "# header\r\n";
  s += kRmc + "\r\n" + kGga + "\n";
  s += std::string(12, '\0') + kRmc + "\r";
  s += "\n\rgarbage\n";
  s += "$GPGGA,030130" + kRmc + "\r\n";
  s += "$GPTXT," + std::string(250, 'y') + "\r\n";
  s += kGga.substr(0, 30) + "\r\n";
  s += withChecksum("GPGSV,3,1,12,20,76,058,40") + kGga + "\n";
  s += "   \r\n";
  s += kRmc;  // no final terminator
  return s;
}

TEST(NmeaParser, EverySplitPointGivesTheSameResult) {
  const std::string stream = messyStream();
  const ParseRun whole = parse(stream);
  ASSERT_EQ(whole.stats.rmc, 4u);
  ASSERT_EQ(whole.stats.gga, 2u);
  for (std::size_t cut = 0; cut <= stream.size(); ++cut) {
    const ParseRun two = parse({stream.substr(0, cut), stream.substr(cut)});
    ASSERT_EQ(two.outcomes, whole.outcomes) << "cut at " << cut;
    ASSERT_EQ(two.stats.lines, whole.stats.lines) << "cut at " << cut;
    ASSERT_EQ(two.stats.rejected, whole.stats.rejected) << "cut at " << cut;
  }
  std::vector<std::string> bytes;
  for (char c : stream)
    bytes.emplace_back(1, c);
  const ParseRun single = parse(bytes);
  EXPECT_EQ(single.outcomes, whole.outcomes);
  EXPECT_EQ(single.stats.rejected, whole.stats.rejected);
}

TEST(NmeaParser, CountsEachRejectReason) {
  std::string bad_checksum = kRmc;
  bad_checksum.back() = bad_checksum.back() == '0' ? '1' : '0';
  const ParseRun run = parse(
      "garbage\n" + kRmc.substr(0, kRmc.size() - 3) + "\n" + bad_checksum + "\n" + "$GPTXT," +
      std::string(300, 'z') + "\n" + "$GPRMC,\x01" + "\n" +
      withChecksum("GPRMC,113938.50,A,3842.8600,X,11705.4364,W,0,0,231122,,") + "\n" + kGga + "\n");
  EXPECT_EQ(rejected(run.stats, RejectReason::kGarbage), 1u);
  EXPECT_EQ(rejected(run.stats, RejectReason::kNoChecksum), 1u);
  EXPECT_EQ(rejected(run.stats, RejectReason::kBadChecksum), 1u);
  EXPECT_EQ(rejected(run.stats, RejectReason::kTooLong), 1u);
  EXPECT_EQ(rejected(run.stats, RejectReason::kNonPrintable), 1u);
  EXPECT_EQ(rejected(run.stats, RejectReason::kMalformed), 1u);
  EXPECT_EQ(run.stats.rejectedTotal(), 6u);
  EXPECT_EQ(run.stats.sentences, 1u);
  EXPECT_EQ(run.stats.lines, 7u);
  for (std::size_t i = 0; i < kRejectReasonCount; ++i) {
    EXPECT_NE(toString(static_cast<RejectReason>(i)), "unknown");
  }
}

TEST(NmeaParser, MalformedFieldsWithAValidChecksumAreRejected) {
  const std::vector<std::string> bodies = {
      "GPRMC,116938.50,A,3842.86,N,11705.43,W,0,0,231122,,",  // minute 69
      "GPRMC,113938.50,A,3862.86,N,11705.43,W,0,0,231122,,",  // 62 minutes of arc
      "GPRMC,113938.50,A,9100.00,N,11705.43,W,0,0,231122,,",  // latitude 91
      "GPRMC,113938.50,A,3842.86,N,18105.43,W,0,0,231122,,",  // longitude 181
      "GPRMC,113938.50,A,3842.86,N,11705.43,W,nan,0,231122,,",
      "GPRMC,113938.50,A,3842.86,N,11705.43,W,1e3,0,231122,,",
      "GPRMC,113938.50,A,3842.86,N,11705.43,W,0,0,311122,,",  // 31 November
      "GPRMC,113938.50,A,3842.86,N,11705.43,W,0,0,23112,,",
      "GPRMC,113938.50,A,38a2.86,N,11705.43,W,0,0,231122,,",
      "GPRMC,113938.50,A,3842.86,N,,,0,0,231122,,",  // latitude without longitude
      "GPGGA,113938.50,,,11705.43,W,2,09,1.5,1864.182,M,,M,,",
      "GPGGA,113938.50,3842.86,N,11705.43,W,x,09,1.5,1864.182,M,,M,,",
      "GPGGA,113938.50,3842.86,N,11705.43,W,2,09,1.5,inf,M,,M,,",
      "GPGGA,113938.50,3842.86,,11705.43,W,2,09,1.5,1864.182,M,,M,,",
  };
  for (const std::string& body : bodies) {
    const ParseRun run = parse(withChecksum(body) + "\n");
    ASSERT_EQ(run.outcomes.size(), 1u);
    EXPECT_EQ(run.outcomes[0].kind, SentenceKind::kRejected) << body;
    EXPECT_EQ(run.outcomes[0].reason, RejectReason::kMalformed) << body;
  }
}

TEST(NmeaParser, NoSingleByteCorruptionYieldsAFix) {
  for (const std::string& sentence : {kRmc, kGga}) {
    for (std::size_t i = 0; i < sentence.size(); ++i) {
      for (int value = 0; value < 256; ++value) {
        if (static_cast<char>(value) == sentence[i])
          continue;
        // The checksum's hex digits in lower case are the same number, not a corruption.
        if (i + 2 >= sentence.size() && std::tolower(value) == std::tolower(sentence[i]))
          continue;
        std::string corrupt = sentence;
        corrupt[i] = static_cast<char>(value);
        const ParseRun run = parse(corrupt + "\r\n");
        // A changed '$' may split the line or end it (CR/LF): still no RMC/GGA.
        ASSERT_TRUE(run.fixes().empty())
            << "byte " << i << " set to " << value << ": " << run.fixes()[0].text;
      }
    }
  }
}

TEST(NmeaParser, CommentLinesAreCountedOnlyWhenAskedFor) {
  const std::string bytes = "# Name: test\n#  $GPGSV,3,3,12,2,40,16,00,090,*72\n" + kRmc + "\n";
  const ParseRun live = parse(bytes);
  EXPECT_EQ(live.stats.comments, 0u);
  EXPECT_EQ(rejected(live.stats, RejectReason::kGarbage), 2u);
  EXPECT_EQ(live.stats.other, 1u);  // the GSV quoted in the comment

  const ParseRun file = parse(bytes, NmeaParserOptions{.comment_lines = true});
  EXPECT_EQ(file.stats.comments, 2u);
  EXPECT_EQ(file.stats.rejectedTotal(), 0u);
  EXPECT_EQ(file.stats.other, 0u);
  EXPECT_EQ(file.stats.rmc, 1u);
  EXPECT_EQ(file.outcomes.size(), 1u);  // comments do not reach the handler
}

TEST(NmeaParser, StatusVoidIsDecodedButNotValid) {
  const ParseRun run =
      parse(withChecksum("GPRMC,235948.00,V,0000.0000,N,00000.0000,E,,,161206,,,N") + "\n" +
            withChecksum("GPGGA,235952.00,0000.0000,N,00000.0000,E,0,00,0.0,,M,,M,,") + "\n");
  ASSERT_EQ(run.fixes().size(), 2u);
  EXPECT_FALSE(run.outcomes[0].rmc.valid());
  EXPECT_FALSE(run.outcomes[1].gga.valid());
  EXPECT_FALSE(run.outcomes[0].rmc.speed_mps.has_value());
  EXPECT_FALSE(run.outcomes[1].gga.altitude_m.has_value());
}

}  // namespace
}  // namespace fieldrig::gps
