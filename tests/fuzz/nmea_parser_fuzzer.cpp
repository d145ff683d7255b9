// libFuzzer target for gps::NmeaParser and gps::FixAssembler (built by scripts/fuzz-nmea.sh).
//
// Besides crashes and sanitizer reports it checks the parser's promises: the same bytes give the
// same outcomes whether fed at once or in pieces, the statistics add up, and every RMC/GGA it
// reports has an intact checksum and in-range values.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/gps/fix_assembler.h"
#include "fieldrig/gps/nmea_parser.h"

namespace {

using fieldrig::gps::FixAssembler;
using fieldrig::gps::NmeaParser;
using fieldrig::gps::NmeaParserOptions;
using fieldrig::gps::NmeaStats;
using fieldrig::gps::Sentence;
using fieldrig::gps::SentenceKind;

void check(bool condition) {
  if (!condition)
    std::abort();
}

bool checksumIntact(std::string_view text) {
  const std::size_t star = text.rfind('*');
  if (star == std::string_view::npos || star + 3 != text.size())
    return false;
  unsigned sum = 0;
  for (std::size_t i = 1; i < star; ++i)
    sum ^= static_cast<unsigned char>(text[i]);
  return std::strtoul(std::string(text.substr(star + 1)).c_str(), nullptr, 16) == sum;
}

void checkCoordinates(const std::optional<double>& lat, const std::optional<double>& lon) {
  check(lat.has_value() == lon.has_value());
  if (lat)
    check(std::isfinite(*lat) && std::fabs(*lat) <= 90.0);
  if (lon)
    check(std::isfinite(*lon) && std::fabs(*lon) <= 180.0);
}

struct Result {
  std::vector<std::string> outcomes;  // kind, reason and text of each outcome, in order
  NmeaStats stats;
};

Result run(std::string_view data, const std::vector<std::size_t>& cuts, bool comments) {
  Result result;
  FixAssembler assembler;
  NmeaParser parser(
      [&](const Sentence& s) {
        result.outcomes.push_back(std::to_string(static_cast<int>(s.kind)) + ":" +
                                  std::to_string(static_cast<int>(s.reason)) + ":" +
                                  std::string(s.text));
        check(s.text.size() <= NmeaParserOptions{}.max_line_length);
        if (s.kind == SentenceKind::kRmc || s.kind == SentenceKind::kGga) {
          check(s.text.front() == '$' && checksumIntact(s.text));
          check(s.text.find_first_of("\r\n") == std::string_view::npos);
        }
        if (s.kind == SentenceKind::kRmc) {
          checkCoordinates(s.rmc.latitude_deg, s.rmc.longitude_deg);
          if (s.rmc.speed_mps)
            check(std::isfinite(*s.rmc.speed_mps));
          if (s.rmc.time_of_day) {
            check(s.rmc.time_of_day->count() >= 0 &&
                  *s.rmc.time_of_day <= std::chrono::hours{24} + std::chrono::seconds{1});
          }
        } else if (s.kind == SentenceKind::kGga) {
          checkCoordinates(s.gga.latitude_deg, s.gga.longitude_deg);
          check(s.gga.quality >= 0 && s.gga.quality <= 9);
          if (s.gga.altitude_m)
            check(std::isfinite(*s.gga.altitude_m));
        }
        const auto fix = assembler.add(s, fieldrig::core::ReceptionStamp{});
        if (fix)
          check(s.kind == SentenceKind::kRmc || s.kind == SentenceKind::kGga);
        if (fix && fix->valid) {
          check(std::fabs(fix->latitude_deg) <= 90.0 && std::fabs(fix->longitude_deg) <= 180.0);
        }
      },
      NmeaParserOptions{.comment_lines = comments});
  std::size_t begin = 0;
  for (std::size_t cut : cuts) {
    parser.feed(data.substr(begin, cut - begin));
    begin = cut;
  }
  parser.feed(data.substr(begin));
  parser.flush();
  result.stats = parser.stats();
  const NmeaStats& st = result.stats;
  check(st.sentences == st.rmc + st.gga + st.other);
  check(st.sentences + st.rejectedTotal() == result.outcomes.size());
  // Every counted line gives at least one outcome, or is a comment.
  check(st.lines <= result.outcomes.size() + st.comments);
  if (!comments)
    check(st.comments == 0);
  return result;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* bytes, std::size_t size) {
  const std::string_view data(reinterpret_cast<const char*>(bytes), size);
  const bool comments = size > 0 && (bytes[0] & 1) != 0;
  const Result whole = run(data, {}, comments);

  // The same bytes in pieces whose sizes come from the data itself (1..16 bytes).
  std::vector<std::size_t> cuts;
  for (std::size_t at = 0, i = 0; size > 0;) {
    at += 1 + (bytes[i++ % size] & 15);
    if (at >= size)
      break;
    cuts.push_back(at);
  }
  const Result pieces = run(data, cuts, comments);
  check(pieces.outcomes == whole.outcomes);
  check(pieces.stats.lines == whole.stats.lines && pieces.stats.comments == whole.stats.comments &&
        pieces.stats.rejected == whole.stats.rejected);
  return 0;
}
