// Predictive camera triggering at imaging locations. Thread-compatible; pure: every method takes
// the current GPS time as an argument, so replay and tests drive it directly.
//
// Fixes arrive at 10 Hz; at 2 m/s the antenna moves 20 cm between them, so firing on the first
// fix past a location is 10 cm late on average. Instead the planner tracks the antenna's motion,
// predicts when it crosses each nearby location along the direction of travel, and schedules a
// trigger for that moment. The motion model is a Kalman filter on position, velocity and
// acceleration (per horizontal axis, white-jerk process noise) that takes the receiver's reported
// speed and course over ground (RMC, Doppler-derived: free of the position noise) as well as its
// positions: a tractor's speed breathes by ±10–15 % over tens of seconds, which a constant-velocity
// fit over the last second follows only with a lag of centimetres. The older constant-velocity
// least-squares fit stays selectable (MotionModel::kConstantVelocityFit) for comparison. The live
// daemon arms a steady_timer for nextTriggerTime(); replay calls collectDue() with the next fix's
// availability time.
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

enum class MotionModel {
  kKalman,               // position, velocity, acceleration; uses reported speed and course
  kConstantVelocityFit,  // least-squares straight line through the fixes of fit_window_s
};
std::string_view toString(MotionModel model);  // "kalman", "constant_velocity_fit"

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
  MotionModel motion_model = MotionModel::kKalman;
  // Kalman filter: how fast the acceleration may change (white-jerk spectral density, m²/s⁵;
  // larger follows speed changes sooner and averages less noise), and the measurement noise of a
  // fix's position (per axis) and of its velocity from speed and course (per axis).
  double kalman_jerk_density = 0.5;
  double kalman_position_sd_m = 0.015;
  double kalman_velocity_sd_mps = 0.05;
};

// The planner's options and the receiver-to-host latency: what replay (in GPS time) and the live
// chain (on a steady timer) both need.
struct TriggerChainOptions {
  TriggerOptions planner;
  // Receiver and serial latency: from the fix's time to its last byte reaching the host. RTK
  // receivers output 20-50 ms after the epoch, and two sentences take ~10 ms at 115200 baud.
  double latency_s = 0.05;
  // Replay only (the live chain sees the real arrivals): each fix becomes usable at its time +
  // latency_s + a uniform draw in ±latency_jitter_s (at most latency_s), seeded: the receiver's
  // computation and serial queueing vary the latency from fix to fix.
  double latency_jitter_s = 0;
  std::uint32_t latency_jitter_seed = 1;
};

enum class AlarmKind {
  kTooFast,  // two triggers closer than min_trigger_interval_s: one was delayed
  kMissed,   // a location was passed without a trigger (gap, invalid or stale fixes)
  // The position leapt further than a vehicle moves in the time (a receiver glitch): the
  // locations between the two positions are not blamed as missed, since nothing says they were
  // passed.
  kPositionJump,
  kTimeJump,  // fix time went back by more than 2 s: the track restarts
};
// "too_fast", "missed", "position_jump", "time_jump"
std::string_view toString(AlarmKind kind);

struct PlannerAlarm {
  AlarmKind kind = AlarmKind::kTooFast;
  std::string location_id;
  core::UtcTime time{};
  std::string message;
};

struct TriggerStats {
  std::uint64_t fixes = 0;
  std::uint64_t fixes_invalid = 0;  // RMC status V or GGA quality 0
  // Epochs with a valid fix, each counted once (not its second sentence) and not when the
  // epoch's other sentence vetoed it: what the planner had to work with.
  std::uint64_t valid_epochs = 0;
  std::uint64_t fixes_out_of_order = 0;  // not newer than the previous fix (duplicates of an epoch)
  std::uint64_t time_jumps = 0;          // fix time went back by more than 2 s: track restarted
  std::uint64_t fixes_too_slow = 0;      // below min_speed_mps
  std::uint64_t track_restarts = 0;      // gaps and invalid fixes
  std::uint64_t triggers = 0;
  std::uint64_t triggers_late = 0;
  std::uint64_t stale_plans_dropped = 0;
  std::uint64_t missed = 0;
  std::uint64_t too_fast = 0;
  std::uint64_t filter_resets = 0;   // a fix far outside the filter's prediction (a turn, a jump)
  std::uint64_t position_jumps = 0;  // see AlarmKind::kPositionJump
  // The planner's own 1-sigma estimate for the latest trigger: of the crossing time, and of the
  // antenna's along-track position at the moment of firing (0 before the first trigger).
  double last_timing_sigma_s = 0;
  double last_along_track_sigma_m = 0;
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
