// Replays an NMEA capture through parser, fix assembler and trigger planner in GPS time.
// Pure apart from reading the stream; thread-compatible.
//
// The replay is causal: a fix of time t becomes usable at t + latency, and every trigger is
// collected before the next fix becomes usable, so a trigger only ever rests on fixes whose time
// is earlier than the trigger.
#pragma once

#include <functional>
#include <istream>

#include "fieldrig/core/result.h"
#include "fieldrig/core/trigger_event.h"
#include "fieldrig/gps/nmea_parser.h"
#include "fieldrig/gps/trigger_planner.h"

namespace fieldrig::gps {

struct ReplaySummary {
  NmeaStats nmea;
  TriggerStats planner;
};

struct ReplayHandlers {
  std::function<void(const core::TriggerEvent&)> on_trigger;
  std::function<void(const PlannerAlarm&)> on_alarm;
};

// An empty map is an error.
core::Result<ReplaySummary> replayTriggers(std::istream& nmea, const LocationMap& map,
                                           const TriggerChainOptions& options,
                                           const ReplayHandlers& handlers);

}  // namespace fieldrig::gps
