#include "fieldrig/gps/trigger_replay.h"

#include <array>
#include <cmath>
#include <optional>
#include <random>
#include <vector>

#include "fieldrig/gps/fix_assembler.h"

namespace fieldrig::gps {

core::Result<ReplaySummary> replayTriggers(std::istream& nmea, const LocationMap& map,
                                           const TriggerChainOptions& options,
                                           const ReplayHandlers& handlers) {
  if (!std::isfinite(options.latency_jitter_s) || options.latency_jitter_s < 0 ||
      options.latency_jitter_s > options.latency_s) {
    return core::Error{
        "latency_jitter_s: " + std::to_string(options.latency_jitter_s) +
        " s must be finite and in [0, latency_s = " + std::to_string(options.latency_s) + " s]"};
  }
  core::Result<TriggerPlanner> created = TriggerPlanner::create(map, options.planner);
  if (!created)
    return created.error();
  TriggerPlanner& planner = *created;
  FixAssembler assembler;
  const core::Nanoseconds latency = core::fromSeconds(options.latency_s);
  std::optional<core::UtcTime> last_available;
  std::mt19937_64 jitter_random(options.latency_jitter_seed);
  std::uniform_real_distribution<double> jitter(-options.latency_jitter_s,
                                                options.latency_jitter_s);

  auto publish = [&](core::UtcTime until) {
    for (const core::TriggerEvent& event : planner.collectDue(until)) {
      if (handlers.on_trigger)
        handlers.on_trigger(event);
    }
    for (const PlannerAlarm& alarm : planner.takeAlarms()) {
      if (handlers.on_alarm)
        handlers.on_alarm(alarm);
    }
  };

  // Replayed files carry '#' comment headers (gpsd's format); they are not device data.
  NmeaParser parser(
      [&](const Sentence& sentence) {
        const std::optional<core::GpsFix> fix = assembler.add(sentence, core::ReceptionStamp{});
        if (!fix)
          return;
        core::UtcTime available = fix->time + latency;
        if (options.latency_jitter_s > 0) {
          // Never before the fix itself (a jitter of the whole latency would make it instant).
          available = std::max(fix->time + core::Nanoseconds{1},
                               available + core::fromSeconds(jitter(jitter_random)));
        }
        // Everything planned before this fix could be used fires first: causality.
        publish(available - core::Nanoseconds{1});
        planner.addFix(*fix, available);
        if (!last_available || available > *last_available)
          last_available = available;
        publish(available);
      },
      NmeaParserOptions{.max_line_length = NmeaParser::kDefaultMaxLineLength,
                        .comment_lines = true});

  // Whatever has arrived is parsed at once: a pipe fed as the drive goes (a logger, `<(…)`) is
  // not held back until a whole chunk is there, as read() of a full chunk would.
  std::array<char, 65536> chunk{};
  while (nmea.peek() != std::istream::traits_type::eof()) {
    std::streamsize got = nmea.readsome(chunk.data(), chunk.size());
    if (got == 0) {  // a stream without a buffer says nothing is available: one byte at a time
      nmea.read(chunk.data(), 1);
      got = nmea.gcount();
    }
    parser.feed(std::string_view(chunk.data(), static_cast<std::size_t>(got)));
  }
  parser.flush();
  // At the end of the capture the live daemon's timer would still fire what was planned.
  if (last_available)
    publish(*last_available + core::fromSeconds(options.planner.max_fix_age_s));
  return ReplaySummary{parser.stats(), planner.stats()};
}

}  // namespace fieldrig::gps
