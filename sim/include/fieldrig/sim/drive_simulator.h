// A tractor drive with a known trajectory, written out as the NMEA the auto-guidance receiver
// would send. Thread-compatible; deterministic for a given seed.
//
// The drive follows a field plan serpentine: each row from a headland run-in to a run-out,
// semicircular turns into the next row. The speed breathes as a tractor's does on auto-guidance
// (slope, soil, engine governor): a slow and a fast sinusoid around the mean, phases drawn from
// the seed. Positions are sampled at the receiver's rate, perturbed with white Gaussian noise and
// with first-order Gauss–Markov noise (RTK errors are correlated over seconds), and encoded as
// RMC + GGA with 8 decimals of minutes; RMC carries the true speed and course, perturbed by the
// velocity noise (receivers derive them from Doppler, not from the positions). The true position
// at any instant is known, so trigger accuracy can be measured along track.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "fieldrig/core/result.h"
#include "fieldrig/core/time.h"
#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/local_frame.h"

namespace fieldrig::sim {

struct DriveOptions {
  double speed_mps = 2.0;
  double rate_hz = 10.0;
  double position_noise_m = 0.01;  // standard deviation per horizontal axis
  double headland_m = 4.0;         // straight run-in and run-out beyond each row's ends
  // speed(t) = speed_mps · (1 + slow·sin(2πt/slow_period + φ1) + fast·sin(2πt/fast_period + φ2)):
  // amplitudes are fractions of the mean speed (0.15 = ±15 %), each at most 0.5.
  double speed_slow_amplitude = 0;
  double speed_slow_period_s = 18;
  double speed_fast_amplitude = 0;
  double speed_fast_period_s = 5;
  double velocity_noise_mps = 0;       // SD per axis of the velocity behind RMC speed and course
  double correlated_noise_m = 0;       // Gauss–Markov position noise: stationary SD per axis
  double correlated_noise_tau_s = 10;  // … and its correlation time
  std::uint32_t seed = 1;
  core::UtcTime start =
      core::UtcTime{std::chrono::sys_days{std::chrono::year{2026} / std::chrono::July / 14}} +
      std::chrono::hours{15} + std::chrono::minutes{30};
  std::string talker = "GN";
};

// Every option finite and in range; the error names the option.
core::Result<void> validate(const DriveOptions& options);

struct TruePose {
  gps::EnuPoint position;  // in frame()
  double unit_east = 0;    // direction of travel
  double unit_north = 0;
};

class DriveSimulator {
 public:
  // Options that fail validate() throw std::invalid_argument with its message.
  DriveSimulator(const gps::FieldPlan& plan, DriveOptions options);

  // The NMEA stream of the whole drive: RMC then GGA for each epoch, CR/LF terminated.
  std::string nmea() const;

  // The true pose at GPS time t (clamped to the drive's start and end).
  TruePose poseAt(core::UtcTime t) const;
  // The true speed at GPS time t, m/s.
  double speedAt(core::UtcTime t) const;

  // Along-track error of firing at time `fired` for the location at lat/lon: the distance,
  // along the true direction of travel, from the location to the true antenna position
  // (positive: the antenna was already past the location).
  double alongTrackError(core::UtcTime fired, double latitude_deg, double longitude_deg) const;

  core::UtcTime start() const { return options_.start; }
  core::UtcTime end() const { return end_; }
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
  double distanceAt(double seconds) const;  // since the start, along the drive

  double slow_phase_ = 0, fast_phase_ = 0;
  DriveOptions options_;
  gps::LocalFrame frame_;
  std::vector<Segment> segments_;
  double length_m_ = 0;
  core::UtcTime end_{};
};

}  // namespace fieldrig::sim
