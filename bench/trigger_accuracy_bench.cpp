// Whole-run benchmark: trigger accuracy along track on simulated serpentine drives (10 Hz, RTK
// noise), at 1, 2 and 3 m/s, at constant speed and with the speed changes, correlated noise and
// latency jitter of a real drive, for both of the planner's motion models and (at constant speed)
// the naive rule "fire on the first fix past the location", all in the same run on the same NMEA.
// Prints a Markdown table.
//
//   trigger_accuracy_bench [--seeds N] [--noise M] [--velocity-noise M/S] [--latency S]
//                          [--jerk-density Q] [--position-sd M] [--velocity-sd M/S]
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>

#include "fieldrig/gps/field_plan.h"
#include "fieldrig/gps/fix_assembler.h"
#include "fieldrig/gps/trigger_replay.h"
#include "fieldrig/sim/trigger_accuracy.h"
#include "support/field_plans.h"

namespace fieldrig {
namespace {

// Eight rows of about 70 m, slightly east of north.
gps::FieldPlan fieldPlan() {
  return testing_support::fieldPlan({42.0, -93.6}, {42.0006, -93.5998}, 8, 3.0, 0.5);
}

// The naive rule: fire at the first fix whose position is past the location along the row.
std::vector<core::TriggerEvent> naiveTriggers(const std::string& nmea, const gps::LocationMap& map,
                                              const gps::LocalFrame& frame) {
  std::vector<core::TriggerEvent> events;
  std::vector<gps::EnuPoint> targets;
  std::vector<bool> fired(map.size(), false);
  for (const auto& l : map.locations())
    targets.push_back(frame.toLocal(l.latitude_deg, l.longitude_deg));
  gps::FixAssembler assembler;
  gps::NmeaParser parser([&](const gps::Sentence& s) {
    if (s.kind != gps::SentenceKind::kRmc)
      return;
    const auto fix = assembler.add(s, {});
    if (!fix || !fix->valid || !fix->course_deg)
      return;
    const gps::EnuPoint p = frame.toLocal(fix->latitude_deg, fix->longitude_deg);
    const double course = *fix->course_deg * M_PI / 180.0;
    const double ue = std::sin(course), un = std::cos(course);
    for (std::size_t i = 0; i < targets.size(); ++i) {
      if (fired[i])
        continue;
      const double de = targets[i].east_m - p.east_m, dn = targets[i].north_m - p.north_m;
      const double along = de * ue + dn * un;
      const double cross = de * un - dn * ue;
      const double heading = *map.locations()[i].heading_deg * M_PI / 180.0;
      const bool same_direction = std::sin(heading) * ue + std::cos(heading) * un > 0.5;
      if (same_direction && std::abs(cross) < 0.5 && along <= 0 && along > -0.5) {
        fired[i] = true;
        core::TriggerEvent e;
        e.location_id = map.locations()[i].id;
        e.time = fix->time;
        events.push_back(e);
      }
    }
  });
  parser.feed(nmea);
  return events;
}

struct Scenario {
  const char* name;
  double slow_amplitude = 0;  // speed breathing, fractions of the mean speed
  double fast_amplitude = 0;
  double white_noise_m = 0;
  double correlated_noise_m = 0;  // Gauss-Markov, tau 10 s
  double latency_jitter_s = 0;
};

void printRow(const Scenario& scenario, const char* method, double speed,
              const sim::TriggerAccuracy& a, double mean_sigma_m, double ms_per_run) {
  char sigma[16] = "-";
  if (mean_sigma_m > 0)
    std::snprintf(sigma, sizeof sigma, "%.2f", mean_sigma_m * 100);
  std::printf(
      "| %-15s | %-21s | %3.1f | %4zu/%4zu | %5zu | %6.2f | %6.2f | %6.2f | %+6.2f | %7s | %6.1f "
      "|\n",
      scenario.name, method, speed, a.fired_once, a.locations,
      a.fired_more_than_once + a.never_fired, a.mean_abs_m * 100, a.p95_abs_m * 100,
      a.max_abs_m * 100, a.mean_signed_m * 100, sigma, ms_per_run);
}

sim::TriggerAccuracy pool(const std::vector<sim::TriggerAccuracy>& runs) {
  sim::TriggerAccuracy pooled;
  std::vector<double> magnitudes;
  for (const auto& r : runs) {
    pooled.locations += r.locations;
    pooled.fired_once += r.fired_once;
    pooled.never_fired += r.never_fired;
    pooled.fired_more_than_once += r.fired_more_than_once;
    for (double e : r.along_track_errors_m) {
      pooled.mean_signed_m += e;
      magnitudes.push_back(std::abs(e));
    }
  }
  if (magnitudes.empty())
    return pooled;
  std::sort(magnitudes.begin(), magnitudes.end());
  for (double m : magnitudes)
    pooled.mean_abs_m += m;
  const double n = static_cast<double>(magnitudes.size());
  pooled.mean_abs_m /= n;
  pooled.mean_signed_m /= n;
  pooled.p95_abs_m = magnitudes[static_cast<std::size_t>(std::ceil(0.95 * n)) - 1];
  pooled.max_abs_m = magnitudes.back();
  return pooled;
}

int run(int argc, char** argv) {
  int seeds = 10;
  double noise = 0.01;
  double velocity_noise = 0.02;
  double latency = gps::TriggerChainOptions{}.latency_s;
  gps::TriggerOptions planner;  // the Kalman filter's noise settings can be tried from here
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--jerk-density"))
      planner.kalman_jerk_density = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--position-sd"))
      planner.kalman_position_sd_m = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--velocity-sd"))
      planner.kalman_velocity_sd_mps = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--seeds"))
      seeds = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--noise"))
      noise = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--velocity-noise"))
      velocity_noise = std::atof(argv[i + 1]);
    if (!std::strcmp(argv[i], "--latency"))
      latency = std::atof(argv[i + 1]);
  }
  const auto map = gps::generateLocations(fieldPlan());
  if (!map) {
    std::fprintf(stderr, "%s\n", map.error().message.c_str());
    return 1;
  }
  // The drives: a tractor breathing ±15 % over 18 s and ±5 % over 5 s; RTK noise white,
  // or correlated (Gauss-Markov, tau 10 s, instead of white); the receiver-to-host latency
  // jittering by ±10 ms.
  const Scenario scenarios[] = {
      {"constant speed", 0, 0, noise, 0, 0},
      {"speed changes", 0.15, 0.05, noise, 0, 0},
      {"+ correlated", 0.15, 0.05, 0, noise, 0},
      {"+ jitter 10 ms", 0.15, 0.05, noise, 0, 0.010},
  };
  std::printf(
      "Trigger accuracy along track: %zu locations x %d seeds per row, 10 Hz, position noise "
      "%.1f cm per axis (white, or Gauss-Markov tau 10 s in '+ correlated'), velocity noise "
      "%.1f cm/s per axis, latency %.0f ms, serpentine rows; Kalman jerk density %g m2/s5, "
      "position SD %g m, velocity SD %g m/s\n\n",
      map->size(), seeds, noise * 100, velocity_noise * 100, latency * 1000,
      planner.kalman_jerk_density, planner.kalman_position_sd_m, planner.kalman_velocity_sd_mps);
  std::printf(
      "| %-15s | %-21s | m/s | once/total | wrong | mean cm | p95 cm | max cm | bias cm | "
      "sigma cm | ms/run |\n",
      "drive", "method");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  const struct {
    const char* name;
    gps::MotionModel model;
  } models[] = {{"constant-velocity fit", gps::MotionModel::kConstantVelocityFit},
                {"Kalman (default)", gps::MotionModel::kKalman}};
  for (const Scenario& scenario : scenarios) {
    for (double speed : {1.0, 2.0, 3.0}) {
      std::vector<std::vector<sim::TriggerAccuracy>> runs(std::size(models));
      std::vector<double> ms(std::size(models), 0), sigma_sum(std::size(models), 0);
      std::vector<std::size_t> sigma_count(std::size(models), 0);
      std::vector<sim::TriggerAccuracy> naive;
      double naive_ms = 0;
      for (int seed = 1; seed <= seeds; ++seed) {
        sim::DriveOptions options;
        options.speed_mps = speed;
        options.position_noise_m = scenario.white_noise_m;
        options.correlated_noise_m = scenario.correlated_noise_m;
        options.correlated_noise_tau_s = 10;
        options.speed_slow_amplitude = scenario.slow_amplitude;
        options.speed_slow_period_s = 18;
        options.speed_fast_amplitude = scenario.fast_amplitude;
        options.speed_fast_period_s = 5;
        options.velocity_noise_mps = velocity_noise;
        options.seed = static_cast<std::uint32_t>(seed);
        const sim::DriveSimulator drive(fieldPlan(), options);
        const std::string nmea = drive.nmea();
        for (std::size_t m = 0; m < std::size(models); ++m) {
          std::vector<core::TriggerEvent> events;
          gps::TriggerChainOptions replay;
          replay.planner = planner;
          replay.latency_s = latency;
          replay.latency_jitter_s = scenario.latency_jitter_s;
          replay.latency_jitter_seed = static_cast<std::uint32_t>(seed);
          replay.planner.motion_model = models[m].model;
          std::istringstream in(nmea);
          const auto t0 = std::chrono::steady_clock::now();
          gps::replayTriggers(in, *map, replay,
                              {[&](const core::TriggerEvent& e) { events.push_back(e); }, {}})
              .value();
          ms[m] += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                       .count();
          for (const core::TriggerEvent& e : events) {
            sigma_sum[m] += e.along_track_sigma_m;
            ++sigma_count[m];
          }
          runs[m].push_back(sim::scoreTriggers(drive, *map, events));
        }
        if (scenario.slow_amplitude == 0 && scenario.latency_jitter_s == 0) {
          const auto t0 = std::chrono::steady_clock::now();
          const auto naive_events = naiveTriggers(nmea, *map, drive.frame());
          naive_ms +=
              std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0)
                  .count();
          naive.push_back(sim::scoreTriggers(drive, *map, naive_events));
        }
      }
      for (std::size_t m = 0; m < std::size(models); ++m) {
        printRow(scenario, models[m].name, speed, pool(runs[m]),
                 sigma_count[m] ? sigma_sum[m] / static_cast<double>(sigma_count[m]) : 0,
                 ms[m] / seeds);
      }
      if (!naive.empty())
        printRow(scenario, "naive: first fix past", speed, pool(naive), 0, naive_ms / seeds);
    }
  }
  std::printf(
      "\nwrong = locations fired never or more than once; bias + = fired past the location; "
      "sigma = the planner's own mean 1-sigma estimate of its along-track error\n");
  return 0;
}

}  // namespace
}  // namespace fieldrig

int main(int argc, char** argv) {
  return fieldrig::run(argc, argv);
}
