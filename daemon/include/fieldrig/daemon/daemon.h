// fieldrigd: the on-vehicle daemon. One run joins the parts along DESIGN.md's data flow:
//
//   NMEA (serial port, a pty, or a file) → planner → trigger events
//        → Acquisition (rig → recorder, never dropped; → processing queue, skips counted)
//        → PlotProcessor (stereo → fused cloud → traits) → ResultsWriter (JSONL, CSV, GeoJSON)
//
// Modes:
//   run     live: the receiver on the configured serial port, the configured camera driver;
//           triggers fire on a steady timer at the predicted crossings.
//   replay  the sim cameras replay a recorded (or synthetic) session; NMEA comes from
//           replay.nmea: a pty or serial device is read as in the field (real time), a file is
//           played through a pty of the daemon's own at its own pace when replay.realtime is
//           set, and otherwise replayed in virtual time — the planner runs in GPS time as fast as
//           the machine allows, each trigger waiting until the rig, the recorder and processing
//           have room, so no set is ever skipped and the same inputs give identical results.
//
// Threads: the GPS/trigger thread (serial, parser, planner, timers, signals) only posts trigger
// events to lock-free queues; cameras, recording, processing and the status server run on
// threads of their own, and a slow stdout reader stalls only the processing thread.
#pragma once

#include <cstdint>
#include <map>
#include <string>

#include "fieldrig/config/config.h"

namespace fieldrig::daemon {

enum class Mode { kRun, kReplay };

struct DaemonOptions {
  config::Config config;
  Mode mode = Mode::kRun;
  bool print_results = true;  // one JSON line per plot on stdout (the summary line always)
  // --check-config: run the start's checks of the configuration and what it names, print
  // "SOURCE: ok" or the error, write nothing.
  bool check_only = false;
  // Keys whose value a command-line flag set, and the flag ("replay.nmea" -> "--nmea"): an error
  // about such a value names the flag, not the configuration file.
  std::map<std::string, std::string> flags_for_keys;
};

// Exit codes: 0 done (signal or end of replay), 2 bad configuration, option or input at start
// (nothing written), or a replayed NMEA input that gave no valid fix (its empty session stays),
// 3 a failure while running, 4 an internal error (an exception nothing handled, out of memory:
// fieldrigd_main logs it; the session was closed while unwinding).
inline constexpr int kExitOk = 0;
inline constexpr int kExitBadInput = 2;
inline constexpr int kExitRuntime = 3;
inline constexpr int kExitInternal = 4;

int runDaemon(const DaemonOptions& options);

}  // namespace fieldrig::daemon
