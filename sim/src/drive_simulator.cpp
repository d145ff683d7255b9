#include "fieldrig/sim/drive_simulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <stdexcept>

#include "fieldrig/gps/nmea_parser.h"

namespace fieldrig::sim {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kKnotsPerMetrePerSecond = 3600.0 / 1852.0;

// "ddmm.mmmmmmmm" / "dddmm.mmmmmmmm": 8 decimals of minutes (about 0.02 mm), as RTK receivers send.
std::string coordinateText(double degrees, int degree_digits, char positive, char negative) {
  const char hemisphere = degrees < 0 ? negative : positive;
  double magnitude = std::abs(degrees);
  int whole = static_cast<int>(magnitude);
  double minutes = (magnitude - whole) * 60.0;
  // Rounding at the 8th decimal may carry into a full minute or degree.
  minutes = std::round(minutes * 1e8) / 1e8;
  if (minutes >= 60.0) {
    minutes -= 60.0;
    ++whole;
  }
  char buffer[40];
  std::snprintf(buffer, sizeof buffer, "%0*d%011.8f,%c", degree_digits, whole, minutes, hemisphere);
  return buffer;
}

std::string timeText(core::UtcTime t) {
  using namespace std::chrono;
  const auto day = floor<days>(t);
  const hh_mm_ss hms{floor<milliseconds>(t - day)};
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%02d%02d%02d.%02d", static_cast<int>(hms.hours().count()),
                static_cast<int>(hms.minutes().count()), static_cast<int>(hms.seconds().count()),
                static_cast<int>(hms.subseconds().count() / 10));
  return buffer;
}

std::string dateText(core::UtcTime t) {
  using namespace std::chrono;
  const year_month_day ymd{floor<days>(t)};
  // The year of the century is never negative (a year before 0 would print "-5"), and the buffer
  // holds what the types allow, not only valid dates: GCC cannot see the ranges under the
  // sanitizers and rightly warns (-Wformat-truncation) about the 8 bytes this used to have.
  const auto year_of_century =
      static_cast<unsigned>((static_cast<int>(ymd.year()) % 100 + 100) % 100);
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "%02u%02u%02u", static_cast<unsigned>(ymd.day()),
                static_cast<unsigned>(ymd.month()), year_of_century);
  return buffer;
}

gps::EnuPoint add(const gps::EnuPoint& p, double e, double n) {
  return {p.east_m + e, p.north_m + n};
}

// The speed profile's phases and the extra noise streams come from their own generators, so that
// drives without them keep the white-noise stream they always had.
constexpr std::uint64_t kPhaseStream = 0x9e3779b97f4a7c15;
constexpr std::uint64_t kCorrelatedStream = 0xbf58476d1ce4e5b9;
constexpr std::uint64_t kVelocityStream = 0x94d049bb133111eb;

core::Result<void> checkRange(const char* name, double value, double min, double max) {
  if (!std::isfinite(value) || value < min || value > max) {
    return core::Error{std::string("drive option ") + name + ": " + std::to_string(value) +
                       " is not a finite number in [" + std::to_string(min) + ", " +
                       std::to_string(max) + "]"};
  }
  return {};
}

}  // namespace

core::Result<void> validate(const DriveOptions& o) {
  const struct {
    const char* name;
    double value, min, max;
  } checks[] = {
      {"speed_mps", o.speed_mps, 0.1, 30},
      {"rate_hz", o.rate_hz, 0.1, 100},
      {"position_noise_m", o.position_noise_m, 0, 100},
      {"headland_m", o.headland_m, 0, 1000},
      {"speed_slow_amplitude", o.speed_slow_amplitude, 0, 0.5},
      {"speed_slow_period_s", o.speed_slow_period_s, 0.5, 3600},
      {"speed_fast_amplitude", o.speed_fast_amplitude, 0, 0.5},
      {"speed_fast_period_s", o.speed_fast_period_s, 0.5, 3600},
      {"velocity_noise_mps", o.velocity_noise_mps, 0, 10},
      {"correlated_noise_m", o.correlated_noise_m, 0, 100},
      {"correlated_noise_tau_s", o.correlated_noise_tau_s, 0.01, 3600},
  };
  for (const auto& check : checks) {
    if (auto ok = checkRange(check.name, check.value, check.min, check.max); !ok)
      return ok;
  }
  return {};
}

DriveSimulator::DriveSimulator(const gps::FieldPlan& plan, DriveOptions options)
    : options_(std::move(options)),
      frame_(plan.row_start_latitude_deg, plan.row_start_longitude_deg) {
  if (const auto valid = validate(options_); !valid)
    throw std::invalid_argument(valid.error().message);
  {
    std::mt19937_64 phases(options_.seed ^ kPhaseStream);
    std::uniform_real_distribution<double> angle(0.0, 2 * kPi);
    slow_phase_ = angle(phases);
    fast_phase_ = angle(phases);
  }
  const gps::EnuPoint start{0, 0};
  const gps::EnuPoint end = frame_.toLocal(plan.row_end_latitude_deg, plan.row_end_longitude_deg);
  const double row_length = std::hypot(end.east_m, end.north_m);
  if (row_length <= 0)
    throw std::invalid_argument("row start and end coincide");
  const double ue = end.east_m / row_length, un = end.north_m / row_length;
  const double side = plan.rows_to_the_right ? 1.0 : -1.0;
  const double re = side * un, rn = -side * ue;  // toward the next row
  const double h = options_.headland_m;

  auto addLine = [&](gps::EnuPoint from, gps::EnuPoint to) {
    Segment segment;
    segment.from = from;
    segment.to = to;
    segment.length = std::hypot(to.east_m - from.east_m, to.north_m - from.north_m);
    segment.start_s = length_m_;
    length_m_ += segment.length;
    segments_.push_back(segment);
  };
  for (int row = 0; row < plan.rows; ++row) {
    const double offset = row * plan.row_spacing_m;
    const gps::EnuPoint row_start = add(start, re * offset - ue * h, rn * offset - un * h);
    const gps::EnuPoint row_end = add(end, re * offset + ue * h, rn * offset + un * h);
    const bool forward = row % 2 == 0;
    addLine(forward ? row_start : row_end, forward ? row_end : row_start);
    if (row + 1 == plan.rows)
      break;
    // Semicircle of diameter one row spacing from this row's far end into the next row.
    const gps::EnuPoint from = segments_.back().to;
    Segment arc;
    arc.is_arc = true;
    arc.radius = plan.row_spacing_m / 2.0;
    arc.centre = add(from, re * arc.radius, rn * arc.radius);
    arc.start_angle =
        std::atan2(from.north_m - arc.centre.north_m, from.east_m - arc.centre.east_m);
    // Travelling along (forward ? u : -u), turning toward r: clockwise when r is the right.
    const double travel_e = forward ? ue : -ue, travel_n = forward ? un : -un;
    const double turn_cross = travel_e * rn - travel_n * re;  // > 0: r is to the left
    arc.sweep = turn_cross > 0 ? kPi : -kPi;
    arc.length = kPi * arc.radius;
    arc.start_s = length_m_;
    length_m_ += arc.length;
    segments_.push_back(arc);
  }
  // The distance grows monotonically (the speed never falls below half the mean): bisect for the
  // moment it reaches the drive's length.
  const double mean_duration = length_m_ / options_.speed_mps;
  double low = 0, high = 2 * mean_duration + 1;
  for (int i = 0; i < 100 && high - low > 1e-9; ++i) {
    const double mid = (low + high) / 2;
    (distanceAt(mid) < length_m_ ? low : high) = mid;
  }
  end_ = options_.start + core::fromSeconds(high);
}

double DriveSimulator::distanceAt(double t) const {
  // The integral of the speed profile from 0 to t.
  auto breathing = [t](double amplitude, double period, double phase) {
    if (amplitude == 0)
      return 0.0;
    const double omega = 2 * kPi / period;
    return amplitude / omega * (std::cos(phase) - std::cos(omega * t + phase));
  };
  return options_.speed_mps *
         (t + breathing(options_.speed_slow_amplitude, options_.speed_slow_period_s, slow_phase_) +
          breathing(options_.speed_fast_amplitude, options_.speed_fast_period_s, fast_phase_));
}

double DriveSimulator::speedAt(core::UtcTime time) const {
  const double t = core::toSeconds(time - options_.start);
  return options_.speed_mps *
         (1 +
          options_.speed_slow_amplitude *
              std::sin(2 * kPi * t / options_.speed_slow_period_s + slow_phase_) +
          options_.speed_fast_amplitude *
              std::sin(2 * kPi * t / options_.speed_fast_period_s + fast_phase_));
}

TruePose DriveSimulator::poseAtDistance(double s) const {
  s = std::clamp(s, 0.0, length_m_);
  auto it = std::upper_bound(segments_.begin(), segments_.end(), s,
                             [](double value, const Segment& seg) { return value < seg.start_s; });
  const Segment& seg = *std::prev(it);
  const double local = std::min(s - seg.start_s, seg.length);
  TruePose pose;
  if (!seg.is_arc) {
    const double ue = (seg.to.east_m - seg.from.east_m) / seg.length;
    const double un = (seg.to.north_m - seg.from.north_m) / seg.length;
    pose.position = add(seg.from, ue * local, un * local);
    pose.unit_east = ue;
    pose.unit_north = un;
  } else {
    const double direction = seg.sweep > 0 ? 1.0 : -1.0;
    const double angle = seg.start_angle + direction * local / seg.radius;
    pose.position = add(seg.centre, seg.radius * std::cos(angle), seg.radius * std::sin(angle));
    pose.unit_east = -direction * std::sin(angle);
    pose.unit_north = direction * std::cos(angle);
  }
  return pose;
}

TruePose DriveSimulator::poseAt(core::UtcTime t) const {
  return poseAtDistance(distanceAt(core::toSeconds(t - options_.start)));
}

double DriveSimulator::alongTrackError(core::UtcTime fired, double latitude_deg,
                                       double longitude_deg) const {
  const TruePose pose = poseAt(fired);
  const gps::EnuPoint location = frame_.toLocal(latitude_deg, longitude_deg);
  return (pose.position.east_m - location.east_m) * pose.unit_east +
         (pose.position.north_m - location.north_m) * pose.unit_north;
}

std::string DriveSimulator::nmea() const {
  std::mt19937_64 random(options_.seed);
  std::normal_distribution<double> noise(0.0, options_.position_noise_m);
  std::mt19937_64 correlated_random(options_.seed ^ kCorrelatedStream);
  std::mt19937_64 velocity_random(options_.seed ^ kVelocityStream);
  std::normal_distribution<double> unit(0.0, 1.0);
  const auto period = core::fromSeconds(1.0 / options_.rate_hz);
  // First-order Gauss–Markov: x(k+1) = φ·x(k) + σ·√(1−φ²)·w, stationary from the first epoch.
  const double sigma = options_.correlated_noise_m;
  const double phi = std::exp(-core::toSeconds(period) / options_.correlated_noise_tau_s);
  double correlated_east = 0, correlated_north = 0;
  if (sigma > 0) {
    correlated_east = sigma * unit(correlated_random);
    correlated_north = sigma * unit(correlated_random);
  }
  std::string out;
  for (core::UtcTime epoch = options_.start; epoch <= end(); epoch += period) {
    // The sentences carry centiseconds: the position is the one at the time they state.
    const core::UtcTime t =
        std::chrono::floor<std::chrono::duration<std::int64_t, std::centi>>(epoch);
    const TruePose pose = poseAt(t);
    if (sigma > 0 && epoch != options_.start) {
      const double step = sigma * std::sqrt(1 - phi * phi);
      correlated_east = phi * correlated_east + step * unit(correlated_random);
      correlated_north = phi * correlated_north + step * unit(correlated_random);
    }
    // North is drawn first: the order GCC evaluated the draws in when they were two arguments of
    // one call, which the bundled demo drive (sim/data) was made with.
    const double white_north = noise(random);
    const double white_east = noise(random);
    const double noise_east = white_east + correlated_east;
    const double noise_north = white_north + correlated_north;
    const gps::GeodeticPoint geo = frame_.toGeodetic(add(pose.position, noise_east, noise_north));
    double velocity_east = speedAt(t) * pose.unit_east;
    double velocity_north = speedAt(t) * pose.unit_north;
    if (options_.velocity_noise_mps > 0) {
      velocity_east += options_.velocity_noise_mps * unit(velocity_random);
      velocity_north += options_.velocity_noise_mps * unit(velocity_random);
    }
    const std::string lat = coordinateText(geo.latitude_deg, 2, 'N', 'S');
    const std::string lon = coordinateText(geo.longitude_deg, 3, 'E', 'W');
    char numbers[64];
    std::snprintf(numbers, sizeof numbers, "%.3f,%.2f",
                  std::hypot(velocity_east, velocity_north) * kKnotsPerMetrePerSecond,
                  gps::bearingDegrees(velocity_east, velocity_north));
    out += gps::withChecksum(options_.talker + "RMC," + timeText(t) + ",A," + lat + "," + lon +
                             "," + numbers + "," + dateText(t) + ",,,R") +
           "\r\n";
    out += gps::withChecksum(options_.talker + "GGA," + timeText(t) + "," + lat + "," + lon +
                             ",4,14,0.7,285.000,M,-33.000,M,1.0,0001") +
           "\r\n";
  }
  return out;
}

}  // namespace fieldrig::sim
