#include "fieldrig/core/time.h"

#include <charconv>
#include <cstdio>

namespace fieldrig::core {
namespace {

std::string fractionText(std::int64_t nanos, int digits) {
  if (digits <= 0)
    return {};
  if (digits > 9)
    digits = 9;
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, ".%09lld", static_cast<long long>(nanos));
  return std::string(buffer, static_cast<std::size_t>(digits) + 1);
}

constexpr int kFirstWholeYear = 1678;
constexpr int kLastWholeYear = 2261;

bool parseInt(std::string_view text, int& out) {
  // Digits only: from_chars would take a sign ("T-1:00:00").
  if (text.empty() || text.find_first_not_of("0123456789") != std::string_view::npos)
    return false;
  auto [ptr, ec] = std::from_chars(text.data(), text.data() + text.size(), out);
  return ec == std::errc() && ptr == text.data() + text.size();
}

}  // namespace

std::string formatIso8601(UtcTime t, int fraction_digits) {
  using namespace std::chrono;
  const auto day = floor<days>(t);
  const year_month_day ymd{day};
  const hh_mm_ss hms{t - day};
  char buffer[48];
  std::snprintf(buffer, sizeof buffer, "%04d-%02u-%02uT%02d:%02d:%02d",
                static_cast<int>(ymd.year()), static_cast<unsigned>(ymd.month()),
                static_cast<unsigned>(ymd.day()), static_cast<int>(hms.hours().count()),
                static_cast<int>(hms.minutes().count()), static_cast<int>(hms.seconds().count()));
  return std::string(buffer) + fractionText(hms.subseconds().count(), fraction_digits) + "Z";
}

std::string formatTimeOfDay(Nanoseconds since_midnight, int fraction_digits) {
  using namespace std::chrono;
  const hh_mm_ss hms{since_midnight};
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%02d:%02d:%02d", static_cast<int>(hms.hours().count()),
                static_cast<int>(hms.minutes().count()), static_cast<int>(hms.seconds().count()));
  return std::string(buffer) + fractionText(hms.subseconds().count(), fraction_digits);
}

std::optional<UtcTime> parseIso8601(std::string_view text) {
  using namespace std::chrono;
  // YYYY-MM-DDThh:mm:ss = 19 characters, then optional fraction, then 'Z'.
  if (text.size() < 20 || text.back() != 'Z' || text[4] != '-' || text[7] != '-' ||
      text[10] != 'T' || text[13] != ':' || text[16] != ':') {
    return std::nullopt;
  }
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0;
  if (!parseInt(text.substr(0, 4), y) || !parseInt(text.substr(5, 2), mo) ||
      !parseInt(text.substr(8, 2), d) || !parseInt(text.substr(11, 2), h) ||
      !parseInt(text.substr(14, 2), mi) || !parseInt(text.substr(17, 2), s)) {
    return std::nullopt;
  }
  const year_month_day ymd{year{y}, month{static_cast<unsigned>(mo)},
                           day{static_cast<unsigned>(d)}};
  if (!ymd.ok() || h > 23 || mi > 59 || s > 60)
    return std::nullopt;
  // UtcTime counts int64 nanoseconds from 1970: 1677-09-21 to 2262-04-11. Whole years inside that
  // span only, so that the sum below cannot overflow (a year like 1012 did, undefined behaviour).
  if (y < kFirstWholeYear || y > kLastWholeYear)
    return std::nullopt;
  std::int64_t nanos = 0;
  const std::string_view rest = text.substr(19, text.size() - 20);
  if (!rest.empty()) {
    if (rest.front() != '.' || rest.size() < 2 || rest.size() > 10)
      return std::nullopt;
    std::int64_t scale = 100'000'000;
    for (char c : rest.substr(1)) {
      if (c < '0' || c > '9')
        return std::nullopt;
      nanos += (c - '0') * scale;
      scale /= 10;
    }
  }
  return UtcTime{sys_days{ymd}} + hours{h} + minutes{mi} + seconds{s} + Nanoseconds{nanos};
}

}  // namespace fieldrig::core
