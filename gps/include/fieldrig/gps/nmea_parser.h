// NMEA 0183 parser: bytes in, sentences out. Pure (no I/O, no clock); thread-compatible.
//
// It accepts RMC and GGA from any talker, verifies the checksum, and survives what real serial
// lines deliver: garbage and NULs, truncated and run-together sentences, CR/LF variations and
// over-long lines. Every line that does not yield a sentence is counted by reason. Decoding keeps
// the full precision of RTK receivers (8+ decimals of minutes, sub-centisecond times).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>

#include "fieldrig/core/time.h"

namespace fieldrig::gps {

enum class RejectReason : std::uint8_t {
  kGarbage,       // bytes that are not a sentence (no '$'/'!' start), e.g. line noise
  kNoChecksum,    // no "*hh" at the end: truncated, or sent without checksum
  kBadChecksum,   // checksum does not match the payload
  kTooLong,       // longer than the maximum line length before any terminator
  kNonPrintable,  // control or 8-bit bytes inside the sentence
  kMalformed,     // intact checksum but a field of RMC/GGA cannot be decoded
  kCount_,
};
inline constexpr std::size_t kRejectReasonCount = static_cast<std::size_t>(RejectReason::kCount_);
std::string_view toString(RejectReason reason);

struct RmcData {
  std::optional<core::UtcTime> time;  // date and time when both are present
  std::optional<core::Nanoseconds> time_of_day;
  bool status_active = false;  // status 'A'
  char mode = 0;               // NMEA 2.3 mode indicator (A, D, E, N, F, R…), 0 if absent
  std::optional<double> latitude_deg;
  std::optional<double> longitude_deg;
  std::optional<double> speed_mps;
  std::optional<double> course_deg;
  std::optional<double> magnetic_variation_deg;  // east positive

  // Valid per NMEA: status A, a position, and the mode (when present) not 'N' (no fix).
  bool valid() const { return status_active && latitude_deg && longitude_deg && mode != 'N'; }
};

struct GgaData {
  std::optional<core::Nanoseconds> time_of_day;
  std::optional<double> latitude_deg;
  std::optional<double> longitude_deg;
  int quality = 0;  // 0 = invalid, 1 GPS, 2 DGPS, 4 RTK fixed, 5 RTK float…
  std::optional<int> satellites;
  std::optional<double> hdop;
  std::optional<double> altitude_m;  // above mean sea level
  std::optional<double> geoid_separation_m;
  std::optional<double> dgps_age_s;

  bool valid() const { return quality > 0 && latitude_deg && longitude_deg; }
};

enum class SentenceKind : std::uint8_t { kRmc, kGga, kOther, kRejected };

// One line's outcome. Views point into the parser's or the caller's buffer and are valid only
// during the callback.
struct Sentence {
  SentenceKind kind = SentenceKind::kRejected;
  RejectReason reason = RejectReason::kGarbage;  // when kRejected
  std::string_view detail;                       // when kRejected: the offending field, if any
  std::string_view text;                         // the line without CR/LF
  std::string_view talker;                       // "GP", "GN", "IN"… (empty for proprietary)
  std::string_view type;                         // "RMC", "GGA", "GSV"…
  RmcData rmc;                                   // when kRmc
  GgaData gga;                                   // when kGga
};

struct NmeaStats {
  std::uint64_t lines = 0;      // non-blank physical lines seen (run-together sentences: one line)
  std::uint64_t comments = 0;   // '#' lines, when NmeaParserOptions::comment_lines is on
  std::uint64_t sentences = 0;  // with a correct checksum
  std::uint64_t rmc = 0;
  std::uint64_t gga = 0;
  std::uint64_t other = 0;  // other sentence types with a correct checksum
  std::array<std::uint64_t, kRejectReasonCount> rejected{};

  std::uint64_t rejectedTotal() const;
};

struct NmeaParserOptions {
  // NMEA allows 82 characters; RTK receivers with many decimals exceed that, so the default
  // leaves room while still bounding memory against a line that never ends.
  std::size_t max_line_length = 200;
  // Captured files (gpsd logs, recordings) start with '#' header lines that are not device data:
  // when on, such lines are counted in NmeaStats::comments and not passed to the handler. Off by
  // default because on a live serial line a '#' is line noise like any other garbage.
  bool comment_lines = false;
};

class NmeaParser {
 public:
  using Handler = std::function<void(const Sentence&)>;

  static constexpr std::size_t kDefaultMaxLineLength = NmeaParserOptions{}.max_line_length;

  explicit NmeaParser(Handler handler, std::size_t max_line_length = kDefaultMaxLineLength);
  NmeaParser(Handler handler, const NmeaParserOptions& options);

  // Consumes a chunk of bytes in arrival order; calls the handler once per completed line
  // (blank lines are skipped silently). A line may span chunks.
  void feed(std::string_view bytes);

  // End of input: a last line without terminator is parsed as if terminated.
  void flush();

  const NmeaStats& stats() const { return stats_; }

  // Decodes one line (without CR/LF); no statistics. Useful for tests and tools.
  static Sentence parseLine(std::string_view line);

 private:
  void processLine(std::string_view line);
  void overlong(std::string_view line);
  void emit(const Sentence& sentence);

  Handler handler_;
  std::size_t max_line_length_;
  bool comment_lines_ = false;
  std::string pending_;      // a partial line carried over between chunks
  bool discarding_ = false;  // inside an over-long line, dropping bytes until its end
  NmeaStats stats_;
};

// The XOR checksum NMEA 0183 puts after '*': over the bytes between '$' and '*'.
unsigned char nmeaChecksum(std::string_view body);

// "$<body>*HH": a complete sentence (without CR/LF) for a body such as "GPRMC,…", for the
// simulator and tools that write NMEA.
std::string withChecksum(std::string_view body);

}  // namespace fieldrig::gps
