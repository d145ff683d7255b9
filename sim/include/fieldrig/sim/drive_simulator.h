// A tractor drive with a known trajectory, written out as the NMEA the auto-guidance receiver
// would send. Thread-compatible; deterministic for a given seed.
//
// The drive follows a field plan serpentine: each row from a headland run-in to a run-out,
// semicircular turns into the next row, at constant speed. Positions are sampled at the
// receiver's rate, perturbed with Gaussian noise (RTK scatter), and encoded as RMC + GGA with
// 8 decimals of minutes. The true position at any instant is known, so trigger accuracy can be
// measured along track.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fieldrig/core/time.h"
#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/local_frame.h"

namespace fieldrig::sim {

struct DriveOptions {
  double speed_mps = 2.0;
  double rate_hz = 10.0;
  double position_noise_m = 0.01;  // standard deviation per horizontal axis
  double headland_m = 4.0;         // straight run-in and run-out beyond each row's ends
  std::uint32_t seed = 1;
  core::UtcTime start =
      core::UtcTime{std::chrono::sys_days{std::chrono::year{2026} / std::chrono::July / 14}} +
      std::chrono::hours{15} + std::chrono::minutes{30};
  std::string talker = "GN";
};

struct TruePose {
  gps::EnuPoint position;  // in frame()
  double unit_east = 0;    // direction of travel
  double unit_north = 0;
};

class DriveSimulator {
 public:
  DriveSimulator(const gps::FieldPlan& plan, DriveOptions options);

  // The NMEA stream of the whole drive: RMC then GGA for each epoch, CR/LF terminated.
  std::string nmea() const;

  // The true pose at GPS time t (clamped to the drive's start and end).
  TruePose poseAt(core::UtcTime t) const;

  // Along-track error of firing at time `fired` for the location at lat/lon: the distance,
  // along the true direction of travel, from the location to the true antenna position
  // (positive: the antenna was already past the location).
  double alongTrackError(core::UtcTime fired, double latitude_deg, double longitude_deg) const;

  core::UtcTime start() const { return options_.start; }
  core::UtcTime end() const;
  double lengthM() const { return length_m_; }
  const gps::LocalFrame& frame() const { return frame_; }

 private:
  struct Segment {
    bool is_arc = false;
    gps::EnuPoint from, to;                         // line
    gps::EnuPoint centre;                           // arc
    double radius = 0, start_angle = 0, sweep = 0;  // angles in radians from east, counterclockwise
    double length = 0;
    double start_s = 0;  // distance from the start of the drive
  };

  TruePose poseAtDistance(double s) const;

  DriveOptions options_;
  gps::LocalFrame frame_;
  std::vector<Segment> segments_;
  double length_m_ = 0;
};

}  // namespace fieldrig::sim
