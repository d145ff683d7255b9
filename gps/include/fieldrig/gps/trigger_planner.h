// Predictive camera triggering at imaging locations. Thread-compatible; pure: every method takes
// the current GPS time as an argument, so replay and tests drive it directly.
//
// Fixes arrive at 10 Hz; at 2 m/s the antenna moves 20 cm between them, so firing on the first
// fix past a location is 10 cm late on average. Instead the planner fits a constant-velocity
// track to the recent fixes (least squares, which also averages the 1–2 cm RTK noise), predicts
// when the antenna crosses each nearby location along the direction of travel, and schedules a
// trigger for that moment. The live daemon arms a steady_timer for nextTriggerTime(); replay
// calls collectDue() with the next fix's availability time.
//
// Time: all times are receiver UTC ("GPS time"). A fix is usable only once it has been received:
// its time plus the receiver-and-serial latency. addFix() is therefore given `now`, the GPS time
// at which the fix became available, and never plans a trigger before it.
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "fieldrig/core/gps_fix.h"
#include "fieldrig/core/result.h"
#include "fieldrig/core/trigger_event.h"
#include "fieldrig/gps/local_frame.h"
#include "fieldrig/gps/location_map.h"

namespace fieldrig::gps {

struct TriggerOptions {
  double cross_track_tolerance_m = 0.5;  // |lateral offset| allowed; rows are ≥ 0.76 m apart
  double heading_tolerance_deg = 60;     // course must be within ± this of a location's heading
  double min_speed_mps = 0.3;            // slower (or stopped) never triggers
  double max_fix_age_s = 0.5;            // a plan firing later than this after its fix never fires
  double max_fix_gap_s = 0.5;            // a longer gap between fixes restarts the track fit
  double min_trigger_interval_s = 0.25;  // the cameras' maximum rate
  double late_tolerance_m = 0.3;  // fire late if the crossing was missed by ≤ this; beyond: missed
  double rearm_distance_m = 3.0;  // a fired location re-arms when the antenna is this far
  double fit_window_s = 1.0;      // the track is fitted to fixes of this recent span
  double fit_residual_limit_m =
      0.05;                     // RMS residual above which the fit window is shortened (turns)
  double trigger_lead_s = 0.0;  // fire this much before the crossing (camera exposure delay)
};

// The planner's options and the receiver-to-host latency: what replay (in GPS time) and the live
// chain (on a steady timer) both need.
struct TriggerChainOptions {
  TriggerOptions planner;
  // Receiver and serial latency: from the fix's time to its last byte reaching the host. RTK
  // receivers output 20-50 ms after the epoch, and two sentences take ~10 ms at 115200 baud.
  double latency_s = 0.05;
};

enum class AlarmKind {
  kTooFast,  // two triggers closer than min_trigger_interval_s: one was delayed
  kMissed,   // a location was passed without a trigger (gap, invalid or stale fixes)
};
std::string_view toString(AlarmKind kind);  // "too_fast", "missed"

struct PlannerAlarm {
  AlarmKind kind = AlarmKind::kTooFast;
  std::string location_id;
  core::UtcTime time{};
  std::string message;
};

struct TriggerStats {
  std::uint64_t fixes = 0;
  std::uint64_t fixes_invalid = 0;       // RMC status V or GGA quality 0
  std::uint64_t fixes_out_of_order = 0;  // not newer than the previous fix (duplicates of an epoch)
  std::uint64_t time_jumps = 0;          // fix time went back by more than 2 s: track restarted
  std::uint64_t fixes_too_slow = 0;      // below min_speed_mps
  std::uint64_t track_restarts = 0;      // gaps and invalid fixes
  std::uint64_t triggers = 0;
  std::uint64_t triggers_late = 0;
  std::uint64_t stale_plans_dropped = 0;
  std::uint64_t missed = 0;
  std::uint64_t too_fast = 0;
};

class TriggerPlanner {
 public:
  // The map must outlive the planner; an empty map is an error.
  static core::Result<TriggerPlanner> create(const LocationMap& map, TriggerOptions options);
  ~TriggerPlanner();
  TriggerPlanner(TriggerPlanner&&) noexcept;
  TriggerPlanner& operator=(TriggerPlanner&&) noexcept;

  // A fix that became available at GPS time `now` (≥ fix.time). Re-plans every trigger; a
  // location found just passed (within late_tolerance_m) is planned for `now`, marked late.
  void addFix(const core::GpsFix& fix, core::UtcTime now);

  // The earliest planned trigger: the live daemon arms its timer for this.
  std::optional<core::UtcTime> nextTriggerTime() const;

  // Fires, in time order, every planned trigger due at or before `now`.
  std::vector<core::TriggerEvent> collectDue(core::UtcTime now);

  // Alarms raised since the last call.
  std::vector<PlannerAlarm> takeAlarms();

  const TriggerStats& stats() const;
  const LocalFrame& frame() const;

 private:
  TriggerPlanner(const LocationMap& map, TriggerOptions options);

  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace fieldrig::gps
