#include "fieldrig/gps/trigger_planner.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>

namespace fieldrig::gps {
namespace {

using namespace std::chrono_literals;

// A point of the test field, anchored at an arbitrary place in Iowa.
constexpr double kAnchorLat = 42.0;
constexpr double kAnchorLon = -93.6;
const core::UtcTime kStart =
    core::UtcTime{std::chrono::sys_days{std::chrono::year{2026} / std::chrono::July / 14}} + 15h;

class Field {
 public:
  Field() : frame_(kAnchorLat, kAnchorLon) {}

  void addLocation(const std::string& id, double east, double north,
                   std::optional<double> heading = std::nullopt) {
    const GeodeticPoint p = frame_.toGeodetic({east, north});
    ImagingLocation location{id, p.latitude_deg, p.longitude_deg, heading, {}};
    ASSERT_TRUE(map_.add(location).ok());
  }

  core::GpsFix fixAt(core::UtcTime t, double east, double north, bool valid = true) const {
    core::GpsFix fix;
    fix.time = t;
    fix.has_date = true;
    const GeodeticPoint p = frame_.toGeodetic({east, north});
    fix.latitude_deg = p.latitude_deg;
    fix.longitude_deg = p.longitude_deg;
    fix.valid = valid;
    return fix;
  }

  const LocationMap& map() const { return map_; }

 private:
  LocalFrame frame_;
  LocationMap map_;
};

// Drives due north along east = `east` from north = n0 at `speed`, 10 Hz, calling the planner as
// the replay does; returns the triggers.
struct Drive {
  double east = 0;
  double north_start = -10;
  double speed = 2.0;
  double duration_s = 12;
  double direction = 1;  // +1 north, -1 south
  core::UtcTime start = kStart;
  std::function<bool(int)> valid = [](int) { return true; };
  std::function<bool(int)> present = [](int) { return true; };
  std::function<double(int)> east_offset = [](int) { return 0.0; };  // a receiver's glitch
  // The receiver's clock against the drive's (a jump in GPS time).
  std::function<core::Nanoseconds(int)> clock_offset = [](int) { return core::Nanoseconds{0}; };
};

std::vector<core::TriggerEvent> drive(const Field& field, TriggerPlanner& planner, const Drive& d) {
  std::vector<core::TriggerEvent> all;
  const int epochs = static_cast<int>(d.duration_s * 10);
  for (int k = 0; k <= epochs; ++k) {
    const core::UtcTime t = d.start + k * 100ms + d.clock_offset(k);
    for (auto& e : planner.collectDue(t - 1ns))
      all.push_back(e);
    if (!d.present(k))
      continue;
    const double north = d.north_start + d.direction * d.speed * 0.1 * k;
    planner.addFix(field.fixAt(t, d.east + d.east_offset(k), north, d.valid(k)), t);
    for (auto& e : planner.collectDue(t))
      all.push_back(e);
  }
  return all;
}

// Smallest difference between two bearings, degrees.
double angleBetween(double a, double b) {
  const double d = std::fmod(std::abs(a - b), 360.0);
  return std::min(d, 360.0 - d);
}

double crossingNorth(const core::TriggerEvent& e, const Drive& d) {
  return d.north_start + d.direction * d.speed * core::toSeconds(e.time - d.start);
}

TEST(TriggerPlannerTest, FiresOncePerLocationAtThePredictedCrossing) {
  Field field;
  for (int i = 0; i < 5; ++i)
    field.addLocation("P" + std::to_string(i), 0.0, 1.3 + 3.7 * i);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.duration_s = 15;  // north -10 … 20 m
  const auto events = drive(field, planner, d);
  ASSERT_EQ(events.size(), 5u);
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(events[i].location_id, "P" + std::to_string(i));
    // Noise-free straight drive: the prediction is exact to well under a millimetre.
    EXPECT_NEAR(crossingNorth(events[i], d), 1.3 + 3.7 * i, 1e-3);
    EXPECT_EQ(events[i].status, core::TriggerStatus::kOnTime);
    EXPECT_LT(events[i].last_fix_time, events[i].time);  // causal
    // The fix the plan rests on travels with the event, to the recording and the results.
    ASSERT_TRUE(events[i].fix.has_value());
    EXPECT_EQ(events[i].fix->time, events[i].last_fix_time);
    EXPECT_TRUE(events[i].fix->valid);
    EXPECT_NEAR(events[i].speed_mps, 2.0, 1e-6);
    EXPECT_LT(angleBetween(events[i].course_deg, 0.0), 1e-3);
  }
  EXPECT_EQ(planner.stats().triggers, 5u);
  EXPECT_EQ(planner.stats().missed, 0u);
}

TEST(TriggerPlannerTest, HeadingMustMatchTheDirectionOfTravel) {
  Field field;
  field.addLocation("north", 0.0, 2.0, 0.0);
  field.addLocation("south", 0.0, 4.0, 180.0);
  field.addLocation("north_east_59", 0.0, 6.0, 59.0);
  field.addLocation("east_61", 0.0, 8.0, 61.0);
  field.addLocation("wraps_350", 0.0, 10.0, 350.0);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  const auto events = drive(field, planner, Drive{});
  std::vector<std::string> ids;
  for (const auto& e : events)
    ids.push_back(e.location_id);
  EXPECT_EQ(ids, (std::vector<std::string>{"north", "north_east_59", "wraps_350"}));
}

TEST(TriggerPlannerTest, CrossTrackToleranceSeparatesNeighbouringRows) {
  Field field;
  field.addLocation("this_row_right", 0.4, 3.0);
  field.addLocation("this_row_left", -0.4, 5.0);
  field.addLocation("next_row", 0.76, 7.0);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  const auto events = drive(field, planner, Drive{});
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].location_id, "this_row_right");
  EXPECT_NEAR(events[0].cross_track_m, 0.4, 1e-3);
  EXPECT_EQ(events[1].location_id, "this_row_left");
  EXPECT_NEAR(events[1].cross_track_m, -0.4, 1e-3);
}

TEST(TriggerPlannerTest, InvalidFixesNeverTrigger) {
  Field field;
  field.addLocation("A", 0.0, 5.0);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.valid = [](int) { return false; };
  EXPECT_TRUE(drive(field, planner, d).empty());
  EXPECT_GT(planner.stats().fixes_invalid, 100u);
}

TEST(TriggerPlannerTest, InvalidFixJustBeforeTheLocationDropsThePlan) {
  Field field;
  field.addLocation("A", 0.0, 5.05);  // crossed at k = 75.25
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.valid = [](int k) { return k < 75 || k > 90; };
  const auto events = drive(field, planner, d);
  EXPECT_TRUE(events.empty());
}

TEST(TriggerPlannerTest, LocationPassedDuringInvalidFixesIsReportedMissed) {
  Field field;
  field.addLocation("A", 0.0, 5.0);   // crossed at k = 75, while the fix is invalid
  field.addLocation("B", 0.0, 12.0);  // crossed at k = 110, valid again
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.duration_s = 13;
  d.valid = [](int k) { return k < 70 || k > 85; };
  const auto events = drive(field, planner, d);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].location_id, "B");
  EXPECT_EQ(planner.stats().missed, 1u);
  const auto alarms = planner.takeAlarms();
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_EQ(alarms[0].kind, AlarmKind::kMissed);
  EXPECT_EQ(alarms[0].location_id, "A");
}

TEST(TriggerPlannerTest, StoppedOrCreepingNeverTriggers) {
  Field field;
  field.addLocation("A", 0.0, 0.05);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.speed = 0.1;  // 10 cm/s, below the 0.3 m/s minimum
  d.north_start = -0.5;
  EXPECT_TRUE(drive(field, planner, d).empty());
  EXPECT_GT(planner.stats().fixes_too_slow, 0u);
}

TEST(TriggerPlannerTest, StaleFixesDoNotFireOnExtrapolation) {
  Field field;
  field.addLocation("A", 0.0, 5.0);  // crossed at k = 75
  TriggerOptions options;
  options.max_fix_age_s = 0.15;
  TriggerPlanner planner = TriggerPlanner::create(field.map(), options).value();
  Drive d;
  // The receiver stalls after fix 72 (0.6 m before A): the crossing is planned for 7.5 s, within
  // the planning horizon, but 0.3 s after the last fix, more than a plan may rest on.
  d.present = [](int k) { return k <= 72; };
  EXPECT_TRUE(drive(field, planner, d).empty());
  EXPECT_EQ(planner.stats().stale_plans_dropped, 1u);
}

TEST(TriggerPlannerTest, StalenessIsJudgedAtTheMomentOfFiring) {
  Field field;
  field.addLocation("A", 0.0, 5.0);  // crossed at 7.5 s
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  // Only fix 72 plans it; the next call comes long after (as replay does after a gap), but the
  // trigger's own moment was 0.3 s after its fix, within max_fix_age_s: it fires, on time.
  for (int k = 0; k <= 72; ++k) {
    const core::UtcTime t = kStart + k * 100ms;
    planner.addFix(field.fixAt(t, 0.0, -10.0 + 0.2 * k), t);
  }
  const auto events = planner.collectDue(kStart + 9s);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].status, core::TriggerStatus::kOnTime);
  EXPECT_NEAR(core::toSeconds(events[0].time - kStart), 7.5, 1e-6);
}

TEST(TriggerPlannerTest, SameEpochVetoDropsThePlan) {
  Field field;
  field.addLocation("A", 0.0, 5.0);  // crossed at 7.5 s
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  std::vector<core::TriggerEvent> events;
  for (int k = 0; k <= 100; ++k) {
    const core::UtcTime t = kStart + k * 100ms;
    for (auto& e : planner.collectDue(t - 1ns))
      events.push_back(e);
    const core::GpsFix fix = field.fixAt(t, 0.0, -10.0 + 0.2 * k);
    planner.addFix(fix, t);  // the RMC half, valid
    if (k >= 70 && k <= 80) {
      core::GpsFix vetoed = fix;  // the GGA half of the same epoch says quality 0
      vetoed.valid = false;
      planner.addFix(vetoed, t);
    }
    for (auto& e : planner.collectDue(t))
      events.push_back(e);
  }
  EXPECT_TRUE(events.empty());
  // 101 epochs, 11 of them vetoed: a vetoed epoch's valid first half is not a valid epoch.
  EXPECT_EQ(planner.stats().valid_epochs, 90u);
}

TEST(TriggerPlannerTest, RecoversFromAJumpBackInTime) {
  Field field;
  field.addLocation("A", 0.0, 5.0);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  // One glitched fix dated a day ahead, then the receiver goes on as before.
  planner.addFix(field.fixAt(kStart + 24h, 0.0, -20.0), kStart + 24h);
  const auto events = drive(field, planner, Drive{});
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(planner.stats().time_jumps, 1u);
  // Said, not only counted: a crew sees why the track started over.
  const auto alarms = planner.takeAlarms();
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_EQ(alarms[0].kind, AlarmKind::kTimeJump);
  EXPECT_EQ(toString(alarms[0].kind), "time_jump");
}

// GPS time goes back 10 s mid-row and runs on from there: every location after the jump still
// fires. The trigger before the jump used to hold every later plan until GPS time caught up.
TEST(TriggerPlannerTest, TriggeringGoesOnAfterGpsTimeJumpsBack) {
  Field field;
  for (int i = 0; i < 8; ++i)
    field.addLocation("P" + std::to_string(i), 0.0, 1.3 + 3.7 * i);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.duration_s = 20;  // north -10 … 30 m at 2 m/s
  // From k = 90 (north 8 m, after P0–P2) the receiver's time is 10 s earlier.
  d.clock_offset = [](int k) { return k >= 90 ? core::Nanoseconds{-10s} : core::Nanoseconds{0}; };
  std::vector<std::string> fired;
  for (const core::TriggerEvent& e : drive(field, planner, d))
    fired.push_back(e.location_id);
  EXPECT_EQ(fired, (std::vector<std::string>{"P0", "P1", "P2", "P3", "P4", "P5", "P6", "P7"}));
  EXPECT_EQ(planner.stats().time_jumps, 1u);
  EXPECT_EQ(planner.stats().missed, 0u);
}

TEST(TriggerPlannerTest, APositionJumpAwayAndBackBlamesNoTriggeredLocation) {
  Field field;
  for (int i = 0; i < 5; ++i)
    field.addLocation("P" + std::to_string(i), 0.0, 1.3 + 3.7 * i);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  // North at 2 m/s from -10 m; for 0.8 s (north 6.0 to 7.6 m, after P0 and P1 fired, before P2)
  // the receiver reports a solution 2 km east, moving on as the tractor does.
  Drive d;
  d.duration_s = 15;
  d.east_offset = [](int k) { return (k >= 80 && k < 88) ? 2000.0 : 0.0; };
  const auto events = drive(field, planner, d);
  ASSERT_EQ(events.size(), 5u);
  for (int i = 0; i < 5; ++i)
    EXPECT_EQ(events[i].location_id, "P" + std::to_string(i));
  EXPECT_EQ(planner.stats().missed, 0u);
  const auto alarms = planner.takeAlarms();
  ASSERT_FALSE(alarms.empty());
  for (const PlannerAlarm& alarm : alarms) {
    EXPECT_EQ(alarm.kind, AlarmKind::kPositionJump) << alarm.message;
    EXPECT_TRUE(alarm.location_id.empty());
  }
  EXPECT_EQ(planner.stats().position_jumps, alarms.size());
}

TEST(TriggerPlannerTest, ALocationPassedDuringAGapAtDrivingSpeedIsStillMissedNotAJump) {
  Field field;
  field.addLocation("A", 0.0, 5.0);  // crossed at k = 75
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.speed = 12.0;  // fast, but a speed a vehicle can have: the gap is travel, not a jump
  d.north_start = -85.0;
  d.present = [](int k) { return k < 65 || k > 78; };
  const auto events = drive(field, planner, d);
  EXPECT_TRUE(events.empty());
  EXPECT_EQ(planner.stats().missed, 1u);
  EXPECT_EQ(planner.stats().position_jumps, 0u);
}

TEST(TriggerPlannerTest, LocationPassedDuringAGapIsReportedMissed) {
  Field field;
  field.addLocation("A", 0.0, 5.0);  // crossed at k = 75
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.present = [](int k) { return k < 65 || k > 76; };  // 1.2 s gap: the track restarts
  const auto events = drive(field, planner, d);
  EXPECT_TRUE(events.empty());
  EXPECT_EQ(planner.stats().missed, 1u);
  const auto alarms = planner.takeAlarms();
  ASSERT_EQ(alarms.size(), 1u);
  EXPECT_EQ(alarms[0].kind, AlarmKind::kMissed);
  EXPECT_EQ(alarms[0].location_id, "A");
}

TEST(TriggerPlannerTest, ShortGapIsBridgedLate) {
  Field field;
  field.addLocation("A", 0.0, 5.0);  // crossed at k = 75
  TriggerOptions options;
  options.late_tolerance_m = 0.5;
  options.max_fix_age_s = 0.15;  // a plan may rest on a fix at most 0.15 s old
  TriggerPlanner planner = TriggerPlanner::create(field.map(), options).value();
  Drive d;
  d.present = [](int k) { return k < 73 || k > 75; };  // fixes 73-75 lost
  const auto events = drive(field, planner, d);
  ASSERT_EQ(events.size(), 1u);
  // Fix 72 planned the crossing for 7.5 s, but by then its plan was 0.3 s old: dropped. Fix 76
  // finds the antenna 0.2 m past the location: fired at once, flagged late.
  EXPECT_EQ(events[0].status, core::TriggerStatus::kLate);
  // Zero latency here: "at once" is the planner's 1 µs decision time after the fix.
  EXPECT_EQ(events[0].time, kStart + 7600ms + 1us);
  EXPECT_EQ(planner.stats().stale_plans_dropped, 1u);
}

TEST(TriggerPlannerTest, ShortGapIsBridgedOnTimeByExtrapolation) {
  Field field;
  field.addLocation("A", 0.0, 5.0);  // crossed at k = 75
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.present = [](int k) { return k < 73 || k > 75; };
  const auto events = drive(field, planner, d);
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].status, core::TriggerStatus::kOnTime);
  EXPECT_NEAR(crossingNorth(events[0], d), 5.0, 1e-3);
}

TEST(TriggerPlannerTest, MinimumIntervalDelaysAndRaisesTooFast) {
  Field field;
  field.addLocation("A", 0.0, 5.0);
  field.addLocation("B", 0.0, 5.2);  // 0.1 s later at 2 m/s
  TriggerOptions options;
  options.min_trigger_interval_s = 0.25;
  options.late_tolerance_m = 1.0;
  TriggerPlanner planner = TriggerPlanner::create(field.map(), options).value();
  const auto events = drive(field, planner, Drive{});
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].status, core::TriggerStatus::kOnTime);
  EXPECT_EQ(events[1].status, core::TriggerStatus::kLate);
  EXPECT_EQ(events[1].time - events[0].time, 250ms);
  EXPECT_EQ(planner.stats().too_fast, 1u);
  const auto alarms = planner.takeAlarms();
  ASSERT_FALSE(alarms.empty());
  EXPECT_EQ(alarms[0].kind, AlarmKind::kTooFast);
}

TEST(TriggerPlannerTest, FiresAgainOnALaterPass) {
  Field field;
  field.addLocation("A", 0.0, 5.0);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive there;
  const auto first = drive(field, planner, there);
  Drive back;
  back.start = kStart + 20s;
  back.north_start = 15;
  back.direction = -1;
  const auto second = drive(field, planner, back);
  ASSERT_EQ(first.size(), 1u);
  ASSERT_EQ(second.size(), 1u);
  EXPECT_NEAR(crossingNorth(second[0], back), 5.0, 1e-3);
  EXPECT_LT(angleBetween(second[0].course_deg, 180.0), 1e-3);
}

TEST(TriggerPlannerTest, LatencyIsAccountedForCausally) {
  Field field;
  field.addLocation("A", 0.0, 5.01);  // crossed at 7.505 s, 5 ms after fix 75
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  std::vector<core::TriggerEvent> events;
  const auto latency = 50ms;
  for (int k = 0; k <= 120; ++k) {
    const core::UtcTime t = kStart + k * 100ms;
    for (auto& e : planner.collectDue(t + latency - 1ns))
      events.push_back(e);
    planner.addFix(field.fixAt(t, 0.0, -10.0 + 0.2 * k), t + latency);
    for (auto& e : planner.collectDue(t + latency))
      events.push_back(e);
  }
  ASSERT_EQ(events.size(), 1u);
  // Fix 75 (7.5 s) is usable only at 7.55 s, after the crossing: the trigger must come from
  // fix 74, usable at 7.45 s, and still fire at the crossing.
  EXPECT_EQ(events[0].status, core::TriggerStatus::kOnTime);
  EXPECT_EQ(events[0].last_fix_time, kStart + 7400ms);
  EXPECT_NEAR(core::toSeconds(events[0].time - kStart), 7.505, 1e-6);
}

TEST(TriggerPlannerTest, CrossingBeforeTheFixIsUsableFiresLate) {
  Field field;
  field.addLocation("A", 0.0, 5.0);
  TriggerOptions options;
  options.max_fix_gap_s = 0.05;  // no prediction beyond 50 ms + tolerance of the newest fix
  options.cross_track_tolerance_m = 0.01;
  TriggerPlanner planner = TriggerPlanner::create(field.map(), options).value();
  std::vector<core::TriggerEvent> events;
  // 20 Hz fixes, 80 ms latency: the crossing at 7.5 s is seen from fix 7.45 s (usable at
  // 7.53 s) only as 0.1 m ahead, beyond the tiny horizon; from fix 7.5 s, usable at 7.58 s, as
  // just reached: fired at 7.58 s, late.
  for (int k = 0; k <= 240; ++k) {
    const core::UtcTime t = kStart + k * 50ms;
    const core::UtcTime usable = t + 80ms;
    for (auto& e : planner.collectDue(usable - 1ns))
      events.push_back(e);
    planner.addFix(field.fixAt(t, 0.0, -10.0 + 0.1 * k), usable);
    for (auto& e : planner.collectDue(usable))
      events.push_back(e);
  }
  ASSERT_EQ(events.size(), 1u);
  EXPECT_EQ(events[0].status, core::TriggerStatus::kLate);
  EXPECT_EQ(events[0].time, kStart + 7580ms);
  EXPECT_EQ(events[0].last_fix_time, kStart + 7500ms);
}

TEST(TriggerPlannerTest, SeasonSizedMapOnlyFiresTheLocationsDriven) {
  Field field;
  // 100,000 locations: 400 rows 2.286 m apart, 250 plots 4 m apart.
  for (int row = 0; row < 400; ++row) {
    for (int plot = 0; plot < 250; ++plot) {
      // By append, not "R" + std::string: GCC 12 -O3 gives a false-positive -Wrestrict.
      std::string name = "R";
      name.append(std::to_string(row)).append("P").append(std::to_string(plot));
      field.addLocation(name, row * 2.286, plot * 4.0 + 2.0);
    }
  }
  ASSERT_EQ(field.map().size(), 100000u);
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.east = 10 * 2.286;  // row 10
  d.duration_s = 25;    // north -10 … 40 m: plots 0…9
  const auto events = drive(field, planner, d);
  ASSERT_EQ(events.size(), 10u);
  for (int plot = 0; plot < 10; ++plot) {
    EXPECT_EQ(events[plot].location_id, "R10P" + std::to_string(plot));
  }
}

// Accelerating due north from 1 m/s at 0.3 m/s² (noise-free, speed and course reported): each
// location's true crossing time solves north(t) = location. Returns |along-track error| of each
// trigger, metres, in location order.
std::vector<double> acceleratingErrors(MotionModel model, std::size_t* triggers) {
  Field field;
  for (int i = 0; i < 6; ++i)
    field.addLocation("P" + std::to_string(i), 0.0, 4.0 + 2.5 * i);
  TriggerOptions options;
  options.motion_model = model;
  TriggerPlanner planner = TriggerPlanner::create(field.map(), options).value();
  constexpr double kV0 = 1.0, kA = 0.3, kNorth0 = -2.0;
  auto northAt = [](double t) { return kNorth0 + kV0 * t + kA * t * t / 2; };
  std::vector<core::TriggerEvent> events;
  for (int k = 0; k <= 100; ++k) {
    const core::UtcTime t = kStart + k * 100ms;
    for (auto& e : planner.collectDue(t - 1ns))
      events.push_back(e);
    core::GpsFix fix = field.fixAt(t, 0.0, northAt(0.1 * k));
    fix.speed_mps = kV0 + kA * 0.1 * k;
    fix.course_deg = 0.0;
    planner.addFix(fix, t);
    for (auto& e : planner.collectDue(t))
      events.push_back(e);
  }
  *triggers = events.size();
  std::vector<double> errors;
  for (const auto& e : events)
    errors.push_back(std::abs(northAt(core::toSeconds(e.time - kStart)) -
                              (4.0 + 2.5 * std::stoi(e.location_id.substr(1)))));
  return errors;
}

TEST(TriggerPlannerTest, KalmanFollowsAccelerationThatTheStraightLineLags) {
  std::size_t kalman_triggers = 0, line_triggers = 0;
  const auto kalman = acceleratingErrors(MotionModel::kKalman, &kalman_triggers);
  const auto line = acceleratingErrors(MotionModel::kConstantVelocityFit, &line_triggers);
  ASSERT_EQ(kalman_triggers, 6u);
  ASSERT_EQ(line_triggers, 6u);
  // The first location comes 2 s in, while the filter still learns the acceleration; from the
  // second on it is tracked to a millimetre. The straight line through the last second of fixes
  // lags by a·T²/12 ≈ 2.5 cm at every one.
  for (std::size_t i = 1; i < kalman.size(); ++i) {
    EXPECT_LT(kalman[i], 0.002) << "location " << i;
    EXPECT_GT(line[i], 0.01) << "location " << i;
  }
}

TEST(TriggerPlannerTest, FixFarOffThePredictionRestartsTheFilter) {
  Field field;
  field.addLocation("before", 0.0, 3.0);
  field.addLocation("after", 0.0, 7.0);  // crossed 1 s after the jump
  TriggerPlanner planner = TriggerPlanner::create(field.map(), {}).value();
  Drive d;
  d.duration_s = 14;  // north -10 … 18 m
  // The receiver's solution jumps 0.5 m east for one epoch at 5 m north (a bad fix).
  std::vector<core::TriggerEvent> events;
  for (int k = 0; k <= 140; ++k) {
    const core::UtcTime t = kStart + k * 100ms;
    for (auto& e : planner.collectDue(t - 1ns))
      events.push_back(e);
    const double north = -10 + 0.2 * k;
    planner.addFix(field.fixAt(t, k == 75 ? 0.5 : 0.0, north), t);
    for (auto& e : planner.collectDue(t))
      events.push_back(e);
  }
  // The jump is far off what the filter predicted: it restarts, from the three good fixes after
  // the jump (the bad one dropped), in time for the next location.
  EXPECT_GE(planner.stats().filter_resets, 1u);
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[1].location_id, "after");
  EXPECT_EQ(events[1].status, core::TriggerStatus::kOnTime);
  EXPECT_NEAR(crossingNorth(events[1], d), 7.0, 1e-3);
}

TEST(TriggerPlannerTest, EmptyMapIsAStartUpError) {
  LocationMap empty;
  const auto planner = TriggerPlanner::create(empty, {});
  ASSERT_FALSE(planner.ok());
  EXPECT_EQ(planner.error().message, "the imaging-location map has no locations");
}

}  // namespace
}  // namespace fieldrig::gps
