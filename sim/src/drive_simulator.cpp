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

}  // namespace

DriveSimulator::DriveSimulator(const gps::FieldPlan& plan, DriveOptions options)
    : options_(std::move(options)),
      frame_(plan.row_start_latitude_deg, plan.row_start_longitude_deg) {
  if (options_.speed_mps <= 0 || options_.rate_hz <= 0) {
    throw std::invalid_argument("drive speed and rate must be positive");
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
}

core::UtcTime DriveSimulator::end() const {
  return options_.start + core::fromSeconds(length_m_ / options_.speed_mps);
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
  return poseAtDistance(core::toSeconds(t - options_.start) * options_.speed_mps);
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
  const auto period = core::fromSeconds(1.0 / options_.rate_hz);
  std::string out;
  for (core::UtcTime epoch = options_.start; epoch <= end(); epoch += period) {
    // The sentences carry centiseconds: the position is the one at the time they state.
    const core::UtcTime t =
        std::chrono::floor<std::chrono::duration<std::int64_t, std::centi>>(epoch);
    const TruePose pose = poseAt(t);
    const gps::GeodeticPoint geo =
        frame_.toGeodetic(add(pose.position, noise(random), noise(random)));
    const std::string lat = coordinateText(geo.latitude_deg, 2, 'N', 'S');
    const std::string lon = coordinateText(geo.longitude_deg, 3, 'E', 'W');
    char numbers[64];
    std::snprintf(numbers, sizeof numbers, "%.3f,%.2f",
                  options_.speed_mps * kKnotsPerMetrePerSecond,
                  gps::bearingDegrees(pose.unit_east, pose.unit_north));
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
