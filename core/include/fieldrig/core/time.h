// Clocks and time helpers shared by every component.
//
// Three time axes meet in fieldrig: the UTC time the GPS receiver reports (GPS time), the host's
// steady clock (for timers and intervals) and the host's system clock (for logs and file names).
// They are kept as distinct types so that one cannot be passed where another is expected.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace fieldrig::core {

using Nanoseconds = std::chrono::nanoseconds;
// UTC as reported by the GPS receiver, nanosecond resolution (RTK receivers report 10 ms or
// finer; the planner interpolates between fixes).
using UtcTime = std::chrono::sys_time<Nanoseconds>;
using SteadyTime = std::chrono::steady_clock::time_point;
using SystemTime = std::chrono::system_clock::time_point;

// When a piece of data reached the host, on both host clocks.
struct ReceptionStamp {
  SteadyTime steady{};
  SystemTime system{};

  static ReceptionStamp now() {
    return {std::chrono::steady_clock::now(), std::chrono::system_clock::now()};
  }
};

// Milliseconds on the steady clock since `start`, as a double: the stage timings of the pipeline
// and its benchmarks.
inline double millisecondsSince(SteadyTime start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Seconds as a double, for arithmetic on short intervals (sub-nanosecond error up to days).
inline double toSeconds(Nanoseconds d) {
  return std::chrono::duration<double>(d).count();
}
inline Nanoseconds fromSeconds(double seconds) {
  return std::chrono::round<Nanoseconds>(std::chrono::duration<double>(seconds));
}

// ISO-8601 UTC, e.g. "2026-07-14T15:30:00.100Z", with `fraction_digits` (0-9) digits after
// the seconds' point (truncated, not rounded, so a time never moves past the next second).
std::string formatIso8601(UtcTime t, int fraction_digits = 3);

// Parses "YYYY-MM-DDThh:mm:ss[.fff…]Z"; nullopt when malformed.
std::optional<UtcTime> parseIso8601(std::string_view text);

// Time of day "hh:mm:ss.ff" (used for GGA, which carries no date).
std::string formatTimeOfDay(Nanoseconds since_midnight, int fraction_digits = 2);

}  // namespace fieldrig::core
