#include "fieldrig/gps/trigger_planner.h"

#include <fmt/format.h>

#include <algorithm>
#include <boost/geometry.hpp>
#include <boost/geometry/geometries/box.hpp>
#include <boost/geometry/geometries/point.hpp>
#include <boost/geometry/index/rtree.hpp>
#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace fieldrig::gps {
namespace {

namespace bg = boost::geometry;
namespace bgi = boost::geometry::index;
using IndexPoint = bg::model::point<double, 2, bg::cs::cartesian>;
using IndexBox = bg::model::box<IndexPoint>;
using IndexEntry = std::pair<IndexPoint, std::size_t>;
// R*-tree bulk-loaded once; a season's 100,000 locations answer a box query in microseconds.
using LocationIndex = bgi::rtree<IndexEntry, bgi::rstar<16>>;

constexpr double kDegreesPerRadian = 180.0 / std::numbers::pi;
// A fit needs this many fixes; three is the fewest that still averages some noise.
constexpr std::size_t kMinFitSamples = 3;
// How far back along the track a location passed without a plan is still reported missed.
constexpr double kMaxMissedSearchM = 30.0;
// No vehicle in a field moves faster (54 km/h); a track further from the last plan than this
// speed allows, plus a margin for the filter restarting on noisy fixes, is a jump of the
// receiver's solution, not travel.
constexpr double kMaxVehicleSpeedMps = 15.0;
constexpr double kJumpMarginM = 2.0;
// Fixes this far back in time are duplicates or stragglers; further back is a jump in time.
constexpr double kMaxBackwardStepS = 2.0;
// A position this many innovation standard deviations (squared, two axes) from the filter's
// prediction is not noise: chi-square with 2 degrees of freedom exceeds it once in 10^6.
constexpr double kFilterGateSquared = 27.6;
// Below this the speed is noise around a standstill: no direction, no crossing time.
constexpr double kMinPlanningSpeedMps = 0.01;
constexpr core::Nanoseconds kDecisionTime = std::chrono::microseconds{1};

struct Target {
  EnuPoint position;
  bool has_heading = false;
  double heading_east = 0;  // unit vector of the required direction of travel
  double heading_north = 0;
  bool armed = true;
};

struct Sample {
  double t = 0;  // seconds since the planner's time origin
  double east = 0;
  double north = 0;
};

struct Track {
  double t = 0;                // time of the newest fix the track was fitted to
  double east = 0, north = 0;  // fitted position at t
  double velocity_east = 0, velocity_north = 0;
  double speed = 0;
  double unit_east = 0, unit_north = 0;  // direction of travel
  double course_deg = 0;
  double acceleration_along = 0;  // along the direction of travel (0 for the constant-velocity fit)
  // Per-axis covariance of (position, velocity, acceleration) at t, and the white-jerk density
  // that widens it with the prediction horizon: the planner's own uncertainty.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  double jerk_density = 0;

  // 1-sigma of the along-track position predicted `horizon` seconds after t.
  double alongSigma(double horizon) const {
    const Eigen::Vector3d h(1.0, horizon, horizon * horizon / 2);
    const double h5 = std::pow(horizon, 5);
    return std::sqrt(std::max(0.0, h.dot(covariance * h) + jerk_density * h5 / 20));
  }

  // Seconds after t until the antenna has moved `along` metres ahead; nullopt when it stops first.
  std::optional<double> timeToCover(double along) const {
    if (acceleration_along == 0)
      return along / speed;
    const double discriminant = speed * speed + 2 * acceleration_along * along;
    if (discriminant < 0)
      return std::nullopt;
    // 2·along / (v + √(v² + 2·a·along)): the root of along = v·τ + a·τ²/2 that is stable for
    // small a and negative along alike.
    return 2 * along / (speed + std::sqrt(discriminant));
  }
};

void setDirection(Track& track) {
  track.speed = std::hypot(track.velocity_east, track.velocity_north);
  if (track.speed > 0) {
    track.unit_east = track.velocity_east / track.speed;
    track.unit_north = track.velocity_north / track.speed;
  }
  track.course_deg = bearingDegrees(track.velocity_east, track.velocity_north);
}

struct Plan {
  std::size_t target = 0;
  core::UtcTime time{};       // when to fire
  core::UtcTime predicted{};  // the predicted crossing
  core::TriggerStatus status = core::TriggerStatus::kOnTime;
  double speed = 0;
  double course_deg = 0;
  double cross_track = 0;
  double timing_sigma = 0;
  double along_sigma = 0;
  core::UtcTime last_fix_time{};
};

// Least-squares constant-velocity fit of the samples [first, end); nullopt when degenerate.
std::optional<Track> fitTrack(const std::deque<Sample>& samples, std::size_t first,
                              double* residual_rms) {
  const std::size_t n = samples.size() - first;
  if (n < kMinFitSamples)
    return std::nullopt;
  double mean_t = 0, mean_e = 0, mean_n = 0;
  for (std::size_t i = first; i < samples.size(); ++i) {
    mean_t += samples[i].t;
    mean_e += samples[i].east;
    mean_n += samples[i].north;
  }
  mean_t /= static_cast<double>(n);
  mean_e /= static_cast<double>(n);
  mean_n /= static_cast<double>(n);
  double stt = 0, ste = 0, stn = 0;
  for (std::size_t i = first; i < samples.size(); ++i) {
    const double dt = samples[i].t - mean_t;
    stt += dt * dt;
    ste += dt * (samples[i].east - mean_e);
    stn += dt * (samples[i].north - mean_n);
  }
  if (stt <= 0)
    return std::nullopt;
  Track track;
  track.velocity_east = ste / stt;
  track.velocity_north = stn / stt;
  double sum_squares = 0;
  for (std::size_t i = first; i < samples.size(); ++i) {
    const double dt = samples[i].t - mean_t;
    const double re = samples[i].east - (mean_e + track.velocity_east * dt);
    const double rn = samples[i].north - (mean_n + track.velocity_north * dt);
    sum_squares += re * re + rn * rn;
  }
  *residual_rms = std::sqrt(sum_squares / static_cast<double>(n));
  track.t = samples.back().t;
  track.east = mean_e + track.velocity_east * (track.t - mean_t);
  track.north = mean_n + track.velocity_north * (track.t - mean_t);
  setDirection(track);
  // The straight line's own uncertainty, per axis, from its residuals (two axes, two parameters
  // each): position at t and velocity, correlated through t's distance from the mean time.
  const double dof = std::max(1.0, 2.0 * static_cast<double>(n) - 4.0);
  const double variance = sum_squares / dof;
  const double lever = track.t - mean_t;
  track.covariance(0, 0) = variance * (1.0 / static_cast<double>(n) + lever * lever / stt);
  track.covariance(0, 1) = track.covariance(1, 0) = variance * lever / stt;
  track.covariance(1, 1) = variance / stt;
  return track;
}

// Kalman filter on (position, velocity, acceleration) per horizontal axis with white-jerk process
// noise. Both axes see the same measurements with the same noise at the same instants, so they
// share one covariance matrix: state columns are east and north.
class MotionFilter {
 public:
  MotionFilter(const TriggerOptions& options) : options_(options) {}

  bool initialised() const { return initialised_; }
  void reset() { initialised_ = false; }
  double t() const { return t_; }

  // Starts from a straight-line fit (position and velocity at its newest fix), acceleration 0.
  void initialise(const Track& fit) {
    t_ = fit.t;
    state_.setZero();
    state_(0, 0) = fit.east;
    state_(0, 1) = fit.north;
    state_(1, 0) = fit.velocity_east;
    state_(1, 1) = fit.velocity_north;
    const double position_variance = options_.kalman_position_sd_m * options_.kalman_position_sd_m;
    covariance_ = fit.covariance;
    covariance_(0, 0) = std::max(covariance_(0, 0), position_variance);
    covariance_(1, 1) = std::max(covariance_(1, 1), position_variance);
    covariance_(2, 2) = kInitialAccelerationSd * kInitialAccelerationSd;
    initialised_ = true;
  }

  void predict(double t) {
    const double dt = t - t_;
    if (dt <= 0)
      return;
    Eigen::Matrix3d transition;
    transition << 1, dt, dt * dt / 2, 0, 1, dt, 0, 0, 1;
    const double q = options_.kalman_jerk_density;
    const double dt2 = dt * dt, dt3 = dt2 * dt, dt4 = dt3 * dt, dt5 = dt4 * dt;
    Eigen::Matrix3d process;
    process << dt5 / 20, dt4 / 8, dt3 / 6, dt4 / 8, dt3 / 3, dt2 / 2, dt3 / 6, dt2 / 2, dt;
    state_ = transition * state_;
    covariance_ = transition * covariance_ * transition.transpose() + q * process;
    t_ = t;
  }

  // Squared distance of a position from the prediction, in units of its innovation variance.
  double normalisedInnovation(double east, double north) const {
    const double variance =
        covariance_(0, 0) + options_.kalman_position_sd_m * options_.kalman_position_sd_m;
    const double de = east - state_(0, 0), dn = north - state_(0, 1);
    return (de * de + dn * dn) / variance;
  }

  // Distance of a position from the prediction, metres.
  double innovation(double east, double north) const {
    return std::hypot(east - state_(0, 0), north - state_(0, 1));
  }

  void updatePosition(double east, double north) {
    update(0, east, north, options_.kalman_position_sd_m);
  }
  void updateVelocity(double east, double north) {
    update(1, east, north, options_.kalman_velocity_sd_mps);
  }

  Track track() const {
    Track track;
    track.t = t_;
    track.east = state_(0, 0);
    track.north = state_(0, 1);
    track.velocity_east = state_(1, 0);
    track.velocity_north = state_(1, 1);
    setDirection(track);
    track.acceleration_along = state_(2, 0) * track.unit_east + state_(2, 1) * track.unit_north;
    track.covariance = covariance_;
    track.jerk_density = options_.kalman_jerk_density;
    return track;
  }

 private:
  // Tractors change speed by tenths of m/s², turns aside.
  static constexpr double kInitialAccelerationSd = 0.5;

  // Scalar update of state row `row` (position or velocity) on both axes.
  void update(int row, double east, double north, double sd) {
    const double innovation_variance = covariance_(row, row) + sd * sd;
    const Eigen::Vector3d gain = covariance_.col(row) / innovation_variance;
    const double de = east - state_(row, 0), dn = north - state_(row, 1);
    state_.col(0) += gain * de;
    state_.col(1) += gain * dn;
    covariance_ -= gain * covariance_.row(row);
    covariance_ = (covariance_ + covariance_.transpose()) / 2;  // keep it symmetric
  }

  const TriggerOptions& options_;
  bool initialised_ = false;
  double t_ = 0;
  Eigen::Matrix<double, 3, 2> state_ = Eigen::Matrix<double, 3, 2>::Zero();
  Eigen::Matrix3d covariance_ = Eigen::Matrix3d::Zero();
};

}  // namespace

struct TriggerPlanner::State {
  State(const LocationMap& location_map, const TriggerOptions& planner_options)
      : map(location_map),
        options(planner_options),
        frame(location_map.locations().front().latitude_deg,
              location_map.locations().front().longitude_deg),
        filter(options) {}

  const LocationMap& map;
  TriggerOptions options;
  LocalFrame frame;  // anchored at the map's first location
  std::vector<Target> targets;
  LocationIndex index;
  std::vector<std::size_t> fired;  // targets waiting to be re-armed

  std::optional<core::UtcTime> origin;  // time zero of Sample::t
  std::optional<core::UtcTime> last_fix_time;
  std::optional<core::GpsFix> last_valid_fix;  // carried by the events planned on it
  std::deque<Sample> samples;
  MotionFilter filter;  // references `options`: State is never copied or moved
  std::optional<Track> track;
  std::optional<EnuPoint> last_planned_position;  // the track's position at the last plan
  double last_planned_t = 0;                      // and its time (Sample::t)
  std::vector<Plan> plans;                        // sorted by time
  std::optional<core::UtcTime> last_trigger_time;
  std::uint64_t next_trigger_id = 1;
  TriggerStats stats;
  std::vector<PlannerAlarm> alarms;

  double seconds(core::UtcTime t) const { return core::toSeconds(t - *origin); }
  core::UtcTime timeAt(double seconds_since_origin) const {
    return *origin + core::fromSeconds(seconds_since_origin);
  }

  void restartTrack() {
    if (!samples.empty())
      ++stats.track_restarts;
    samples.clear();
    filter.reset();
    track.reset();
    plans.clear();
  }

  void rearm(const EnuPoint& position) {
    std::erase_if(fired, [&](std::size_t i) {
      Target& target = targets[i];
      if (std::hypot(target.position.east_m - position.east_m,
                     target.position.north_m - position.north_m) > options.rearm_distance_m) {
        target.armed = true;
        return true;
      }
      return false;
    });
  }

  void markFired(std::size_t i) {
    targets[i].armed = false;
    fired.push_back(i);
  }

  void fitAdaptively() {
    track.reset();
    std::size_t first = 0;
    while (samples.size() - first >= kMinFitSamples) {
      double rms = 0;
      std::optional<Track> candidate = fitTrack(samples, first, &rms);
      if (!candidate)
        return;
      if (rms <= options.fit_residual_limit_m || samples.size() - first == kMinFitSamples) {
        // Accept the shortest window only when it also fits; otherwise the motion is not
        // straight enough (tight turn) to predict from.
        if (rms <= options.fit_residual_limit_m)
          track = candidate;
        return;
      }
      // Residuals too large: the older fixes belong to a turn. Keep the newer two thirds.
      const std::size_t remaining = samples.size() - first;
      first += std::max<std::size_t>(1, remaining / 3);
      if (samples.size() - first < kMinFitSamples)
        first = samples.size() - kMinFitSamples;
    }
  }

  // The Kalman track after the newest sample (and the fix's reported velocity, if any).
  void filterTrack(const core::GpsFix& fix) {
    track.reset();
    const Sample& newest = samples.back();
    if (filter.initialised()) {
      filter.predict(newest.t);
      // A fix far outside the prediction (a tight turn, a jump of the receiver's solution): the
      // motion is not what the filter models; start again from the fixes that follow.
      if (filter.normalisedInnovation(newest.east, newest.north) > kFilterGateSquared &&
          filter.innovation(newest.east, newest.north) > options.fit_residual_limit_m) {
        ++stats.filter_resets;
        filter.reset();
        samples.erase(samples.begin(), samples.end() - 1);
      }
    }
    if (!filter.initialised()) {
      // Started from a straight line through the recent fixes; the oldest give way until it
      // fits them (the one bad fix that reset the filter, the turn before the row).
      while (samples.size() >= kMinFitSamples) {
        double rms = 0;
        const std::optional<Track> fit = fitTrack(samples, 0, &rms);
        if (fit && rms <= options.fit_residual_limit_m) {
          filter.initialise(*fit);
          break;
        }
        samples.pop_front();
      }
      if (!filter.initialised())
        return;
    } else {
      filter.updatePosition(newest.east, newest.north);
    }
    if (fix.speed_mps && fix.course_deg) {
      const double course = *fix.course_deg / kDegreesPerRadian;
      filter.updateVelocity(*fix.speed_mps * std::sin(course), *fix.speed_mps * std::cos(course));
    }
    track = filter.track();
  }

  void plan(core::UtcTime now, double unplanned_distance) {
    plans.clear();
    const Track& tr = *track;
    const double right_east = tr.unit_north;  // clockwise normal of the direction of travel
    const double right_north = -tr.unit_east;
    const double tolerance = options.cross_track_tolerance_m;
    const double behind = options.late_tolerance_m + unplanned_distance + tolerance;
    const double ahead = tr.speed * (options.max_fix_gap_s + options.trigger_lead_s) + tolerance;
    const double cos_heading_tolerance =
        std::cos(options.heading_tolerance_deg / kDegreesPerRadian);

    const double back_e = tr.east - tr.unit_east * behind,
                 back_n = tr.north - tr.unit_north * behind;
    const double front_e = tr.east + tr.unit_east * ahead,
                 front_n = tr.north + tr.unit_north * ahead;
    const IndexBox box(
        IndexPoint(std::min(back_e, front_e) - tolerance, std::min(back_n, front_n) - tolerance),
        IndexPoint(std::max(back_e, front_e) + tolerance, std::max(back_n, front_n) + tolerance));
    candidates.clear();
    index.query(bgi::intersects(box), std::back_inserter(candidates));

    const core::UtcTime fix_time = timeAt(tr.t);
    for (const IndexEntry& entry : candidates) {
      const std::size_t i = entry.second;
      const Target& target = targets[i];
      if (!target.armed)
        continue;
      if (target.has_heading &&
          target.heading_east * tr.unit_east + target.heading_north * tr.unit_north <
              cos_heading_tolerance) {
        continue;
      }
      const double de = target.position.east_m - tr.east;
      const double dn = target.position.north_m - tr.north;
      const double along = de * tr.unit_east + dn * tr.unit_north;
      const double cross = de * right_east + dn * right_north;
      if (std::abs(cross) > tolerance)
        continue;
      if (along < -options.late_tolerance_m) {
        if (along >= -behind) {
          // Passed since the last plan (no usable track then): report it, never fire it.
          ++stats.missed;
          alarms.push_back({AlarmKind::kMissed, map.locations()[i].id, fix_time,
                            "location passed without a trigger (no usable track in time)"});
          markFired(i);
        }
        continue;
      }
      const std::optional<double> horizon = tr.timeToCover(along);
      if (!horizon)
        continue;  // slowing to a stop before the location: no crossing to plan yet
      Plan p;
      p.target = i;
      p.predicted = timeAt(tr.t + *horizon - options.trigger_lead_s);
      p.along_sigma = tr.alongSigma(std::max(0.0, *horizon));
      p.timing_sigma = p.along_sigma / tr.speed;
      p.time = p.predicted;
      if (p.time < now) {
        p.time = now;  // noticed after the moment: fire at once, flagged
        p.status = core::TriggerStatus::kLate;
      }
      // A decision cannot fire at the very instant of the fix it rests on (zero latency).
      p.time = std::max(p.time, fix_time + kDecisionTime);
      p.speed = tr.speed;
      p.course_deg = tr.course_deg;
      p.cross_track = cross;  // + = location to the right of travel
      p.last_fix_time = fix_time;
      plans.push_back(p);
    }
    std::sort(plans.begin(), plans.end(),
              [](const Plan& a, const Plan& b) { return a.time < b.time; });
  }

  std::vector<IndexEntry> candidates;  // reused across queries
};

std::string_view toString(MotionModel model) {
  return model == MotionModel::kKalman ? "kalman" : "constant_velocity_fit";
}

std::string_view toString(AlarmKind kind) {
  switch (kind) {
    case AlarmKind::kTooFast:
      return "too_fast";
    case AlarmKind::kMissed:
      return "missed";
    case AlarmKind::kPositionJump:
      return "position_jump";
    case AlarmKind::kTimeJump:
      return "time_jump";
  }
  return "unknown";
}

core::Result<TriggerPlanner> TriggerPlanner::create(const LocationMap& map,
                                                    TriggerOptions options) {
  if (map.empty())
    return core::Error{"the imaging-location map has no locations"};
  return TriggerPlanner(map, options);
}

TriggerPlanner::TriggerPlanner(const LocationMap& map, TriggerOptions options) {
  state_ = std::make_unique<State>(map, options);
  std::vector<IndexEntry> entries;
  entries.reserve(map.size());
  state_->targets.reserve(map.size());
  for (const ImagingLocation& location : map.locations()) {
    Target target;
    target.position = state_->frame.toLocal(location.latitude_deg, location.longitude_deg);
    if (location.heading_deg) {
      const double radians = *location.heading_deg / kDegreesPerRadian;
      target.has_heading = true;
      target.heading_east = std::sin(radians);
      target.heading_north = std::cos(radians);
    }
    entries.emplace_back(IndexPoint(target.position.east_m, target.position.north_m),
                         state_->targets.size());
    state_->targets.push_back(target);
  }
  state_->index = LocationIndex(entries.begin(), entries.end());
}

TriggerPlanner::~TriggerPlanner() = default;
TriggerPlanner::TriggerPlanner(TriggerPlanner&&) noexcept = default;
TriggerPlanner& TriggerPlanner::operator=(TriggerPlanner&&) noexcept = default;

void TriggerPlanner::addFix(const core::GpsFix& fix, core::UtcTime now) {
  State& s = *state_;
  ++s.stats.fixes;
  if (s.last_fix_time && fix.time <= *s.last_fix_time) {
    if (fix.time == *s.last_fix_time && !fix.valid) {
      // The epoch's other sentence vetoes it (RMC status V or GGA quality 0 after a valid
      // partner): what was planned from its first half must not fire.
      ++s.stats.fixes_invalid;
      if (s.last_valid_fix && s.last_valid_fix->time == fix.time && s.stats.valid_epochs > 0)
        --s.stats.valid_epochs;  // its first half was counted valid
      s.restartTrack();
      return;
    }
    if (*s.last_fix_time - fix.time <= core::fromSeconds(kMaxBackwardStepS)) {
      ++s.stats.fixes_out_of_order;
      return;
    }
    // A jump back in time (a receiver glitch with a future date before, a day boundary the
    // date could not follow): start over rather than wait for time to catch up.
    ++s.stats.time_jumps;
    s.alarms.push_back(
        {AlarmKind::kTimeJump, "", fix.time,
         fmt::format("GPS time went back by {:.1f} s (a receiver glitch or a day boundary): the "
                     "track restarts from this fix",
                     core::toSeconds(*s.last_fix_time - fix.time))});
    // The cameras' minimum interval is kept in GPS time: the trigger before the jump is moved
    // back with it. Left where it was, it lay ahead of every new plan and held each one (then
    // dropped it as stale) until GPS time caught up, every location meanwhile reported missed.
    if (s.last_trigger_time)
      *s.last_trigger_time -= *s.last_fix_time - fix.time;
    s.restartTrack();
    s.origin = fix.time;
    s.last_planned_position.reset();
  }
  s.last_fix_time = fix.time;
  if (!s.origin)
    s.origin = fix.time;
  if (!fix.valid) {
    ++s.stats.fixes_invalid;
    s.restartTrack();
    return;
  }
  s.last_valid_fix = fix;
  ++s.stats.valid_epochs;
  const double t = s.seconds(fix.time);
  if (!s.samples.empty() && t - s.samples.back().t > s.options.max_fix_gap_s)
    s.restartTrack();
  const EnuPoint position = s.frame.toLocal(fix.latitude_deg, fix.longitude_deg);
  s.samples.push_back({t, position.east_m, position.north_m});
  while (s.samples.size() > kMinFitSamples &&
         t - s.samples.front().t > s.options.fit_window_s + 1e-6) {
    s.samples.pop_front();
  }
  if (s.options.motion_model == MotionModel::kKalman)
    s.filterTrack(fix);
  else
    s.fitAdaptively();
  if (!s.track) {
    s.plans.clear();
    return;
  }
  if (s.track->speed < std::max(s.options.min_speed_mps, kMinPlanningSpeedMps)) {
    ++s.stats.fixes_too_slow;
    s.plans.clear();
    return;
  }
  // Distance covered since the last plan: locations passed on it (during invalid fixes, a gap,
  // a turn without a usable track) are reported missed. Capped so that re-entering the field far
  // away does not blame plots that were never on this pass.
  double unplanned_distance = 0;
  if (s.last_planned_position) {
    const double step = std::hypot(s.track->east - s.last_planned_position->east_m,
                                   s.track->north - s.last_planned_position->north_m);
    const double elapsed = s.track->t - s.last_planned_t;
    if (step > kMaxVehicleSpeedMps * elapsed + kJumpMarginM) {
      // Out to a far-away solution and back again would otherwise blame every location behind
      // the return (already triggered, and re-armed while the position was away) as missed.
      ++s.stats.position_jumps;
      s.alarms.push_back({AlarmKind::kPositionJump, "", fix.time,
                          fmt::format("position moved {:.0f} m in {:.1f} s (a receiver glitch?): "
                                      "locations in between are not judged",
                                      step, elapsed)});
    } else {
      unplanned_distance = std::min(kMaxMissedSearchM, step);
    }
  }
  s.plan(now, unplanned_distance);
  s.last_planned_position = EnuPoint{s.track->east, s.track->north};
  s.last_planned_t = s.track->t;
  // Re-armed only after planning, so that a location fired just before a gap is not taken for
  // one passed during it.
  s.rearm(position);
}

std::optional<core::UtcTime> TriggerPlanner::nextTriggerTime() const {
  const State& s = *state_;
  if (s.plans.empty())
    return std::nullopt;
  core::UtcTime next = s.plans.front().time;
  if (s.last_trigger_time) {
    next =
        std::max(next, *s.last_trigger_time + core::fromSeconds(s.options.min_trigger_interval_s));
  }
  return next;
}

std::vector<core::TriggerEvent> TriggerPlanner::collectDue(core::UtcTime now) {
  State& s = *state_;
  std::vector<core::TriggerEvent> events;
  if (s.plans.empty())
    return events;
  const core::Nanoseconds min_interval = core::fromSeconds(s.options.min_trigger_interval_s);
  const core::Nanoseconds max_fix_age = core::fromSeconds(s.options.max_fix_age_s);
  std::size_t done = 0;
  for (; done < s.plans.size(); ++done) {
    Plan& p = s.plans[done];
    core::UtcTime fire_at = p.time;
    if (s.last_trigger_time && fire_at < *s.last_trigger_time + min_interval) {
      fire_at = *s.last_trigger_time + min_interval;
    }
    if (fire_at > now)
      break;
    // Judged at the moment of firing, as the live timer would: a plan whose moment comes too
    // long after the fix it rests on is extrapolation over a stalled receiver.
    if (fire_at - *s.last_fix_time > max_fix_age) {
      ++s.stats.stale_plans_dropped;
      continue;
    }
    if (fire_at != p.time) {
      p.status = core::TriggerStatus::kLate;
      ++s.stats.too_fast;
      s.alarms.push_back({AlarmKind::kTooFast, s.map.locations()[p.target].id, fire_at,
                          "driving too fast for the cameras' trigger rate: trigger delayed"});
    }
    core::TriggerEvent event;
    event.trigger_id = s.next_trigger_id++;
    event.location_id = s.map.locations()[p.target].id;
    event.time = fire_at;
    event.planned_time = p.predicted;
    event.status = p.status;
    event.speed_mps = p.speed;
    event.course_deg = p.course_deg;
    event.cross_track_m = p.cross_track;
    event.timing_sigma_s = p.timing_sigma;
    event.along_track_sigma_m = p.along_sigma;
    event.last_fix_time = p.last_fix_time;
    if (s.last_valid_fix && s.last_valid_fix->time == p.last_fix_time)
      event.fix = s.last_valid_fix;
    ++s.stats.triggers;
    s.stats.last_timing_sigma_s = p.timing_sigma;
    s.stats.last_along_track_sigma_m = p.along_sigma;
    if (p.status == core::TriggerStatus::kLate)
      ++s.stats.triggers_late;
    s.last_trigger_time = fire_at;
    s.markFired(p.target);
    events.push_back(std::move(event));
  }
  s.plans.erase(s.plans.begin(), s.plans.begin() + static_cast<std::ptrdiff_t>(done));
  return events;
}

std::vector<PlannerAlarm> TriggerPlanner::takeAlarms() {
  return std::exchange(state_->alarms, {});
}

const TriggerStats& TriggerPlanner::stats() const {
  return state_->stats;
}

const LocalFrame& TriggerPlanner::frame() const {
  return state_->frame;
}

}  // namespace fieldrig::gps
