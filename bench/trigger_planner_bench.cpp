// Cost of one planner update (addFix + collectDue) per 10 Hz fix against a season's map of
// 100,000 locations, next to a 100-location map and to a brute-force scan of every location
// (what the R*-tree index avoids), all measured in the same run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "fieldrig/gps/trigger_planner.h"

namespace fieldrig::gps {
namespace {

using namespace std::chrono_literals;

constexpr double kRowSpacing = 2.286;
constexpr double kPlotSpacing = 4.0;

struct Field {
  Field(int rows, int plots) : frame(42.0, -93.6) {
    for (int row = 0; row < rows; ++row) {
      for (int plot = 0; plot < plots; ++plot) {
        const GeodeticPoint p = frame.toGeodetic({row * kRowSpacing, plot * kPlotSpacing + 2.0});
        // By append, not "R" + std::string: GCC 12 -O3 gives a false-positive -Wrestrict.
        std::string id = "R";
        id.append(std::to_string(row)).append("P").append(std::to_string(plot));
        ImagingLocation location{std::move(id), p.latitude_deg, p.longitude_deg, 0.0, {}};
        (void)map.add(std::move(location));
      }
    }
  }
  LocalFrame frame;
  LocationMap map;
};

// Fixes along row 5, northward at 2 m/s, precomputed so only the planner is timed.
std::vector<core::GpsFix> driveFixes(const LocalFrame& frame, int count) {
  std::vector<core::GpsFix> fixes;
  const core::UtcTime start{std::chrono::sys_days{std::chrono::year{2026} / 7 / 14}};
  for (int k = 0; k < count; ++k) {
    core::GpsFix fix;
    fix.time = start + k * 100ms;
    const GeodeticPoint p = frame.toGeodetic({5 * kRowSpacing, -5.0 + 0.2 * k});
    fix.latitude_deg = p.latitude_deg;
    fix.longitude_deg = p.longitude_deg;
    fix.valid = true;
    fixes.push_back(fix);
  }
  return fixes;
}

void runPlanner(benchmark::State& state, int rows, int plots) {
  const Field field(rows, plots);
  const std::vector<core::GpsFix> fixes = driveFixes(field.frame, 4000);  // 800 m of row
  std::size_t triggers = 0;
  for (auto _ : state) {
    state.PauseTiming();
    TriggerPlanner planner = TriggerPlanner::create(field.map, {}).value();
    state.ResumeTiming();
    for (const core::GpsFix& fix : fixes) {
      planner.addFix(fix, fix.time);
      triggers += planner.collectDue(fix.time + 99ms).size();
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(fixes.size()));
  state.counters["seconds_per_fix"] =
      benchmark::Counter(static_cast<double>(state.iterations() * fixes.size()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["triggers"] =
      static_cast<double>(triggers) / static_cast<double>(state.iterations());
}

void BM_PlannerUpdate_100kLocations(benchmark::State& state) {
  runPlanner(state, 400, 250);
}
void BM_PlannerUpdate_100Locations(benchmark::State& state) {
  runPlanner(state, 10, 10);
}

// Baseline: the same geometric test against every location for every fix, no index.
void BM_BruteForceScan_100kLocations(benchmark::State& state) {
  const Field field(400, 250);
  std::vector<EnuPoint> points;
  for (const auto& location : field.map.locations()) {
    points.push_back(field.frame.toLocal(location.latitude_deg, location.longitude_deg));
  }
  const std::vector<core::GpsFix> fixes = driveFixes(field.frame, 200);
  std::size_t near = 0;
  for (auto _ : state) {
    for (const core::GpsFix& fix : fixes) {
      const EnuPoint p = field.frame.toLocal(fix.latitude_deg, fix.longitude_deg);
      for (const EnuPoint& q : points) {
        const double along = q.north_m - p.north_m;
        if (std::abs(q.east_m - p.east_m) < 0.5 && along > -0.3 && along < 1.5)
          ++near;
      }
    }
  }
  benchmark::DoNotOptimize(near);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(fixes.size()));
  state.counters["seconds_per_fix"] =
      benchmark::Counter(static_cast<double>(state.iterations() * fixes.size()),
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

BENCHMARK(BM_PlannerUpdate_100kLocations)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_PlannerUpdate_100Locations)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_BruteForceScan_100kLocations)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace fieldrig::gps

BENCHMARK_MAIN();
