#include "fieldrig/gps/nmea_parser.h"

#include <charconv>
#include <chrono>
#include <numeric>

namespace fieldrig::gps {
namespace {

constexpr double kMetresPerSecondPerKnot = 1852.0 / 3600.0;
constexpr std::size_t kMaxFields = 32;

struct Fields {
  std::array<std::string_view, kMaxFields> values{};
  std::size_t count = 0;

  std::string_view operator[](std::size_t i) const {
    return i < count ? values[i] : std::string_view{};
  }
};

Fields splitFields(std::string_view payload) {
  Fields fields;
  const char* const data = payload.data();
  std::size_t start = 0;
  // A plain loop: this runs for every sentence, and the fields are short.
  for (std::size_t i = 0; i < payload.size(); ++i) {
    if (data[i] != ',')
      continue;
    fields.values[fields.count++] = std::string_view(data + start, i - start);
    start = i + 1;
    if (fields.count == kMaxFields)
      return fields;
  }
  fields.values[fields.count++] = std::string_view(data + start, payload.size() - start);
  return fields;
}

bool isSentenceStart(char c) {
  return c == '$' || c == '!';
}

// Index of the next '$' or '!' at or after `from`, or npos. (string_view::find_first_of calls
// memchr once per byte, which made it the parser's hottest spot.)
std::size_t findSentenceStart(std::string_view line, std::size_t from) {
  for (std::size_t i = from; i < line.size(); ++i) {
    if (isSentenceStart(line[i]))
      return i;
  }
  return std::string_view::npos;
}

int hexValue(char c) {
  if (c >= '0' && c <= '9')
    return c - '0';
  if (c >= 'A' && c <= 'F')
    return c - 'A' + 10;
  if (c >= 'a' && c <= 'f')
    return c - 'a' + 10;
  return -1;
}

bool isDigits(std::string_view text) {
  for (char c : text) {
    if (c < '0' || c > '9')
      return false;
  }
  return true;
}

// Parses "[-]digits[.digits]" (what receivers send; from_chars alone would also take "nan",
// "inf" and exponents, which must not become a speed or a coordinate). With up to 15 significant
// digits the mantissa and the power of ten are exact doubles, so one division gives the correctly
// rounded value, the same as from_chars, in a fraction of its time; longer numbers go to it.
bool parseDecimal(std::string_view text, double& out) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  std::size_t i = 0;
  const bool negative = !text.empty() && text.front() == '-';
  if (negative)
    i = 1;
  std::uint64_t mantissa = 0;
  int digits = 0;
  int fraction_digits = 0;
  bool dot_seen = false;
  for (; i < text.size(); ++i) {
    const char c = text[i];
    if (c >= '0' && c <= '9') {
      if (digits < 19)
        mantissa = mantissa * 10 + static_cast<std::uint64_t>(c - '0');
      ++digits;
      if (dot_seen)
        ++fraction_digits;
    } else if (c == '.' && !dot_seen) {
      dot_seen = true;
    } else {
      return false;
    }
  }
  if (digits == 0)
    return false;
  if (digits <= 15) {
    const double value = static_cast<double>(mantissa) / kPow10[fraction_digits];
    out = negative ? -value : value;
    return true;
  }
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && ptr == text.data() + text.size();
}

// Field decoders: return false when the field is present but cannot be decoded (the sentence is
// then rejected as malformed); an empty field leaves the optional empty.
bool decodeDouble(std::string_view text, std::optional<double>& out) {
  if (text.empty())
    return true;
  double value = 0;
  // Some receivers send a leading '+'.
  if (text.front() == '+')
    text.remove_prefix(1);
  if (!parseDecimal(text, value))
    return false;
  out = value;
  return true;
}

bool decodeInt(std::string_view text, std::optional<int>& out) {
  if (text.empty())
    return true;
  int value = 0;
  const auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || ptr != text.data() + text.size())
    return false;
  out = value;
  return true;
}

// "ddmm.mmmmmmmm" / "dddmm.mmmm" with hemisphere: degrees and minutes are decoded separately so
// that the minutes keep every digit the receiver sent.
bool decodeCoordinate(std::string_view value, std::string_view hemisphere, int max_degrees,
                      std::optional<double>& out) {
  if (value.empty() && hemisphere.empty())
    return true;
  if (value.empty() || hemisphere.size() != 1)
    return false;
  const std::size_t dot = value.find('.');
  const std::size_t integer_digits = dot == std::string_view::npos ? value.size() : dot;
  if (integer_digits < 3 || integer_digits > 5)
    return false;
  const std::string_view degree_text = value.substr(0, integer_digits - 2);
  const std::string_view minute_text = value.substr(integer_digits - 2);
  if (!isDigits(degree_text) || !isDigits(minute_text.substr(0, 2)))
    return false;
  int degrees = 0;
  for (char c : degree_text)
    degrees = degrees * 10 + (c - '0');
  double minutes = 0;
  if (!parseDecimal(minute_text, minutes))
    return false;
  if (minutes >= 60.0 || degrees > max_degrees)
    return false;
  double decimal = degrees + minutes / 60.0;
  if (decimal > max_degrees)
    return false;
  switch (hemisphere.front()) {
    case 'N':
    case 'E':
      break;
    case 'S':
    case 'W':
      decimal = -decimal;
      break;
    default:
      return false;
  }
  out = decimal;
  return true;
}

// "hhmmss[.s…]" to nanoseconds since midnight, exact (no floating point).
bool decodeTimeOfDay(std::string_view text, std::optional<core::Nanoseconds>& out) {
  if (text.empty())
    return true;
  if (text.size() < 6 || !isDigits(text.substr(0, 6)))
    return false;
  const int hours = (text[0] - '0') * 10 + (text[1] - '0');
  const int minutes = (text[2] - '0') * 10 + (text[3] - '0');
  const int seconds = (text[4] - '0') * 10 + (text[5] - '0');
  if (hours > 23 || minutes > 59 || seconds > 60)
    return false;
  std::int64_t nanos = 0;
  if (text.size() > 6) {
    const std::string_view fraction = text.substr(7);
    if (text[6] != '.' || fraction.size() > 9 || !isDigits(fraction))
      return false;
    std::int64_t scale = 100'000'000;
    for (char c : fraction) {
      nanos += (c - '0') * scale;
      scale /= 10;
    }
  }
  out = std::chrono::hours{hours} + std::chrono::minutes{minutes} + std::chrono::seconds{seconds} +
        core::Nanoseconds{nanos};
  return true;
}

// "ddmmyy"; two-digit years 80-99 are 19xx, as in gpsd.
bool decodeDate(std::string_view text, std::optional<std::chrono::sys_days>& out) {
  if (text.empty())
    return true;
  if (text.size() != 6 || !isDigits(text))
    return false;
  const unsigned day = static_cast<unsigned>((text[0] - '0') * 10 + (text[1] - '0'));
  const unsigned month = static_cast<unsigned>((text[2] - '0') * 10 + (text[3] - '0'));
  const int two_digit_year = (text[4] - '0') * 10 + (text[5] - '0');
  const int year = two_digit_year < 80 ? 2000 + two_digit_year : 1900 + two_digit_year;
  const std::chrono::year_month_day ymd{std::chrono::year{year}, std::chrono::month{month},
                                        std::chrono::day{day}};
  if (!ymd.ok())
    return false;
  out = std::chrono::sys_days{ymd};
  return true;
}

Sentence rejected(std::string_view text, RejectReason reason, std::string_view detail = {}) {
  Sentence sentence;
  sentence.kind = SentenceKind::kRejected;
  sentence.reason = reason;
  sentence.detail = detail;
  sentence.text = text;
  return sentence;
}

bool decodeRmc(const Fields& f, RmcData& rmc, std::string_view& bad_field) {
  std::optional<std::chrono::sys_days> date;
  std::optional<double> speed_knots;
  std::optional<double> variation;
  if (!decodeTimeOfDay(f[1], rmc.time_of_day))
    return bad_field = "time", false;
  if (f[2].size() > 1)
    return bad_field = "status", false;
  rmc.status_active = f[2] == "A";
  if (!decodeCoordinate(f[3], f[4], 90, rmc.latitude_deg))
    return bad_field = "lat", false;
  if (!decodeCoordinate(f[5], f[6], 180, rmc.longitude_deg))
    return bad_field = "lon", false;
  // Half a position is no position: a sentence with only one of them is cut or corrupt.
  if (rmc.latitude_deg.has_value() != rmc.longitude_deg.has_value()) {
    return bad_field = "position", false;
  }
  if (!decodeDouble(f[7], speed_knots))
    return bad_field = "speed", false;
  if (!decodeDouble(f[8], rmc.course_deg))
    return bad_field = "course", false;
  if (!decodeDate(f[9], date))
    return bad_field = "date", false;
  if (!decodeDouble(f[10], variation))
    return bad_field = "magnetic_variation", false;
  if (f[12].size() > 1)
    return bad_field = "mode", false;
  if (f[12].size() == 1)
    rmc.mode = f[12].front();
  if (speed_knots)
    rmc.speed_mps = *speed_knots * kMetresPerSecondPerKnot;
  if (variation)
    rmc.magnetic_variation_deg = f[11] == "W" ? -*variation : *variation;
  if (date && rmc.time_of_day)
    rmc.time = core::UtcTime{*date} + *rmc.time_of_day;
  return true;
}

bool decodeGga(const Fields& f, GgaData& gga, std::string_view& bad_field) {
  std::optional<int> quality;
  if (!decodeTimeOfDay(f[1], gga.time_of_day))
    return bad_field = "time", false;
  if (!decodeCoordinate(f[2], f[3], 90, gga.latitude_deg))
    return bad_field = "lat", false;
  if (!decodeCoordinate(f[4], f[5], 180, gga.longitude_deg))
    return bad_field = "lon", false;
  if (gga.latitude_deg.has_value() != gga.longitude_deg.has_value()) {
    return bad_field = "position", false;
  }
  if (!decodeInt(f[6], quality) || (quality && (*quality < 0 || *quality > 9))) {
    return bad_field = "quality", false;
  }
  if (!decodeInt(f[7], gga.satellites))
    return bad_field = "satellites", false;
  if (!decodeDouble(f[8], gga.hdop))
    return bad_field = "hdop", false;
  if (!decodeDouble(f[9], gga.altitude_m))
    return bad_field = "altitude", false;
  if (!decodeDouble(f[11], gga.geoid_separation_m))
    return bad_field = "geoid_separation", false;
  if (!decodeDouble(f[13], gga.dgps_age_s))
    return bad_field = "dgps_age", false;
  gga.quality = quality.value_or(0);
  return true;
}

}  // namespace

std::string_view toString(RejectReason reason) {
  switch (reason) {
    case RejectReason::kGarbage:
      return "garbage";
    case RejectReason::kNoChecksum:
      return "no_checksum";
    case RejectReason::kBadChecksum:
      return "bad_checksum";
    case RejectReason::kTooLong:
      return "too_long";
    case RejectReason::kNonPrintable:
      return "non_printable";
    case RejectReason::kMalformed:
      return "malformed";
    case RejectReason::kCount_:
      break;
  }
  return "unknown";
}

std::uint64_t NmeaStats::rejectedTotal() const {
  return std::accumulate(rejected.begin(), rejected.end(), std::uint64_t{0});
}

NmeaParser::NmeaParser(Handler handler, std::size_t max_line_length)
    : NmeaParser(std::move(handler), NmeaParserOptions{max_line_length, false}) {}

NmeaParser::NmeaParser(Handler handler, const NmeaParserOptions& options)
    : handler_(std::move(handler)),
      max_line_length_(options.max_line_length),
      comment_lines_(options.comment_lines) {
  pending_.reserve(max_line_length_ + 1);
}

Sentence NmeaParser::parseLine(std::string_view line) {
  // Trailing blanks are transport noise, not part of the sentence.
  while (!line.empty() && line.back() == ' ')
    line.remove_suffix(1);
  if (line.empty() || (line.front() != '$' && line.front() != '!')) {
    return rejected(line, RejectReason::kGarbage);
  }
  const std::size_t star = line.rfind('*');
  // One pass for both the printable check and the checksum (XOR of the bytes between the start
  // character and '*').
  unsigned char checksum = 0;
  const std::size_t checksum_end = star == std::string_view::npos ? 0 : star;
  for (std::size_t i = 1; i < line.size(); ++i) {
    const auto c = static_cast<unsigned char>(line[i]);
    if (c < 0x20 || c > 0x7e)
      return rejected(line, RejectReason::kNonPrintable);
    if (i < checksum_end)
      checksum ^= c;
  }
  if (star == std::string_view::npos || star + 3 != line.size()) {
    return rejected(line, RejectReason::kNoChecksum);
  }
  const int high = hexValue(line[star + 1]);
  const int low = hexValue(line[star + 2]);
  if (high < 0 || low < 0)
    return rejected(line, RejectReason::kNoChecksum);
  if (checksum != static_cast<unsigned char>(high * 16 + low)) {
    return rejected(line, RejectReason::kBadChecksum);
  }

  const Fields fields = splitFields(line.substr(1, star - 1));
  const std::string_view address = fields[0];
  Sentence sentence;
  sentence.text = line;
  sentence.kind = SentenceKind::kOther;
  if (!address.empty() && address.front() == 'P') {
    sentence.type = address;  // proprietary: "PASHR", "PGRME"…
  } else if (address.size() >= 3) {
    sentence.talker = address.substr(0, 2);
    sentence.type = address.substr(2);
  } else {
    return rejected(line, RejectReason::kMalformed, "address");
  }

  // '!' starts encapsulated (AIS) sentences; and since the start character is outside the
  // checksum, a '$' turned into '!' by line noise must not pass as a fix.
  std::string_view bad_field;
  if (line.front() != '$')
    return sentence;
  if (sentence.type == "RMC") {
    if (!decodeRmc(fields, sentence.rmc, bad_field)) {
      return rejected(line, RejectReason::kMalformed, bad_field);
    }
    sentence.kind = SentenceKind::kRmc;
  } else if (sentence.type == "GGA") {
    if (!decodeGga(fields, sentence.gga, bad_field)) {
      return rejected(line, RejectReason::kMalformed, bad_field);
    }
    sentence.kind = SentenceKind::kGga;
  }
  return sentence;
}

void NmeaParser::emit(const Sentence& sentence) {
  switch (sentence.kind) {
    case SentenceKind::kRmc:
      ++stats_.sentences;
      ++stats_.rmc;
      break;
    case SentenceKind::kGga:
      ++stats_.sentences;
      ++stats_.gga;
      break;
    case SentenceKind::kOther:
      ++stats_.sentences;
      ++stats_.other;
      break;
    case SentenceKind::kRejected:
      ++stats_.rejected[static_cast<std::size_t>(sentence.reason)];
      break;
  }
  if (handler_)
    handler_(sentence);
}

void NmeaParser::overlong(std::string_view line) {
  ++stats_.lines;
  if (comment_lines_ && line.front() == '#') {
    ++stats_.comments;
  } else {
    emit(rejected(line.substr(0, max_line_length_), RejectReason::kTooLong));
  }
}

void NmeaParser::processLine(std::string_view line) {
  // Decided before the blank-line check so that a line's fate never depends on how it was split
  // into chunks: feed() must judge an over-long line before it has seen all of it.
  if (line.size() > max_line_length_) {
    overlong(line);
    return;
  }
  // Blank lines (the LF of a CR/LF pair, keep-alives) are not data.
  if (line.find_first_not_of(' ') == std::string_view::npos)
    return;
  ++stats_.lines;
  if (comment_lines_ && line.front() == '#') {
    ++stats_.comments;
    return;
  }
  // A sentence starts at each '$' or '!': text before the first is garbage (NUL runs, escape
  // codes), and a fragment cut short by the next start fails on its missing checksum.
  std::size_t start = findSentenceStart(line, 0);
  if (start == std::string_view::npos) {
    emit(rejected(line, RejectReason::kGarbage));
    return;
  }
  if (start > 0) {
    const std::string_view prefix = line.substr(0, start);
    if (prefix.find_first_not_of(' ') != std::string_view::npos) {
      emit(rejected(prefix, RejectReason::kGarbage));
    }
  }
  while (start != std::string_view::npos) {
    const std::size_t next = findSentenceStart(line, start + 1);
    emit(parseLine(line.substr(start, next == std::string_view::npos ? next : next - start)));
    start = next;
  }
}

void NmeaParser::feed(std::string_view bytes) {
  std::size_t pos = 0;
  while (pos < bytes.size()) {
    std::size_t end = pos;
    while (end < bytes.size() && bytes[end] != '\n' && bytes[end] != '\r')
      ++end;
    if (end == bytes.size()) {
      // No terminator yet: keep the partial line, bounded by the maximum length.
      if (discarding_)
        return;
      pending_.append(bytes.substr(pos));
      if (pending_.size() > max_line_length_) {
        overlong(pending_);
        pending_.clear();
        discarding_ = true;
      }
      return;
    }
    if (discarding_) {
      discarding_ = false;  // the over-long line ends here; it was already counted
    } else if (pending_.empty()) {
      processLine(bytes.substr(pos, end - pos));
    } else {
      pending_.append(bytes.substr(pos, end - pos));
      processLine(pending_);
      pending_.clear();
    }
    pos = end + 1;
  }
}

void NmeaParser::flush() {
  if (!pending_.empty())
    processLine(pending_);
  pending_.clear();
  discarding_ = false;
}

unsigned char nmeaChecksum(std::string_view body) {
  unsigned char checksum = 0;
  for (char c : body)
    checksum ^= static_cast<unsigned char>(c);
  return checksum;
}

std::string withChecksum(std::string_view body) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  const unsigned char checksum = nmeaChecksum(body);
  std::string sentence;
  sentence.reserve(body.size() + 4);
  sentence += '$';
  sentence += body;
  sentence += '*';
  sentence += kHex[checksum >> 4];
  sentence += kHex[checksum & 0x0f];
  return sentence;
}

}  // namespace fieldrig::gps
